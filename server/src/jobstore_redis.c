/* jobstore_redis.c - job records in Redis: create (with its batches),
 * read, result, cancel or forget, finish (see jobs_redis.h). Every
 * change of state is one Lua script, so two instances never both move a
 * job out of a live state. */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "jobs_redis_internal.h"
#include "util.h"

double srv__rj_wall(void) {
  struct timespec ts;
  clock_gettime(CLOCK_REALTIME, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void srv__rj_key(char *buf, size_t cap, const char *kind, const char *id) {
  snprintf(buf, cap, "kmorph:%s:%s", kind, id);
}

redisReply *srv__rj_cmd(redisContext *c, bool *broken, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  redisReply *rep = redisvCommand(c, fmt, ap);
  va_end(ap);
  if (rep == NULL || c->err) {
    if (rep) freeReplyObject(rep);
    *broken = true;
    return NULL;
  }
  return rep;
}

/* KEYS: job, live, stream, the set of streams. ARGV: id, max live,
 * total, created, deadline, body, accept, batch frames. -1 when max live
 * jobs exist. */
static const char CREATE_LUA[] =
    "if redis.call('SCARD', KEYS[2]) >= tonumber(ARGV[2]) then return -1 end "
    "redis.call('HSET', KEYS[1], 'st', 'queued', 'n', ARGV[3], 'd', 0, "
    "'c', ARGV[4], 'dl', ARGV[5], 'b', ARGV[6], 'a', ARGV[7]) "
    "redis.call('SADD', KEYS[2], ARGV[1]) redis.call('SADD', KEYS[4], KEYS[3]) "
    "local n, b, i = tonumber(ARGV[3]), tonumber(ARGV[8]), 0 "
    "while i < n do local k = math.min(n, i + b) "
    "redis.call('XADD', KEYS[3], '*', 'id', ARGV[1], 'from', i, 'to', k) "
    "i = k end return 0";

/* Frames per batch: about 16 batches a job, so that two or more
 * instances share a long one; at least 16 frames, so that the three
 * round trips of a batch are spread over many frames; at most 64, so
 * that a batch takes far less than the visibility timeout. */
static size_t batch_frames(size_t total, bool apart) {
  /* Up to 64 frames is one batch, rendered and assembled by one
   * instance with no frame stored apart: split, a mid-size job would be
   * prepared by several instances and its frames written to Redis and
   * read back, for little parallel work. */
  if (!apart || total <= 64) return total > 0 ? total : 1;
  size_t b = (total + 15) / 16;
  return b < 16 ? 16 : b > 64 ? 64 : b;
}

int srv_rjobs_start(srv_rjobs *j, const char *body, size_t len,
                    const char *accept, api_morph_plan *plan,
                    char id[SRV_JOB_ID_LEN + 1]) {
  char nid[SRV_JOB_ID_LEN + 1], key[80];
  srv_random_hex(nid, SRV_JOB_ID_LEN);
  srv__rj_key(key, sizeof key, "job", nid);
  size_t total = api_morph_frame_count(plan);
  size_t batch = batch_frames(total, api_morph_frames_apart(plan));
  double now = srv__rj_wall();
  redisContext *c = srv_redis_acquire(j->rd);
  if (c == NULL) {
    api_morph_plan_free(plan);
    return SRV_RJOBS_DOWN;
  }
  bool broken = false;
  /* Cached first: a worker may take the first batch before we return.
   * A solo batch goes to this instance's own stream, so that the plan
   * prepared here is the one that renders it unless another instance is
   * idle. */
  srv__rj_cache_put(j, nid, plan);
  redisReply *rep = srv__rj_cmd(
      c, &broken, "EVAL %s 4 %s %s %s %s %s %llu %llu %.3f %.3f %b %s %llu",
      CREATE_LUA, key, RJ_LIVE, batch >= total ? j->local : RJ_STREAM,
      RJ_STREAMS, nid, (unsigned long long)j->cfg.max_jobs,
      (unsigned long long)total, now, now + j->cfg.job_time, body, len,
      accept ? accept : "", (unsigned long long)batch);
  int rc = SRV_RJOBS_DOWN;
  if (rep != NULL && rep->type == REDIS_REPLY_INTEGER)
    rc = rep->integer == 0 ? 0 : SRV_RJOBS_FULL;
  if (rep) freeReplyObject(rep);
  srv_redis_release(j->rd, c, broken || rc == SRV_RJOBS_DOWN);
  if (rc != 0)
    srv__rj_cache_drop(j, nid);
  else
    memcpy(id, nid, sizeof nid);
  return rc;
}

static srv_job_state state_of(const char *s) {
  static const char *const names[] = {"queued", "running", "done", "failed",
                                      "cancelled"};
  for (int i = 0; i < 5; i++)
    if (s && strcmp(s, names[i]) == 0) return (srv_job_state)i;
  return SRV_JOB_FAILED;
}

static const char *str_at(const redisReply *rep, size_t i) {
  if (i >= rep->elements || rep->element[i]->type != REDIS_REPLY_STRING)
    return NULL;
  return rep->element[i]->str;
}

/* HMGET of the record into *out (and the content type into ct, cap
 * bytes, if ct is not NULL). */
static int read_record(srv_rjobs *j, redisContext *c, bool *broken,
                       const char *id, srv_job_view *out, char *ct,
                       size_t ctcap) {
  char key[80];
  srv__rj_key(key, sizeof key, "job", id);
  redisReply *rep = srv__rj_cmd(c, broken, "HMGET %s st n d es e c ct", key);
  (void)j;
  if (rep == NULL) return SRV_RJOBS_DOWN;
  int rc = SRV_STORE_UNKNOWN;
  if (rep->type == REDIS_REPLY_ARRAY && rep->elements == 7 &&
      str_at(rep, 0) != NULL) {
    memset(out, 0, sizeof *out);
    snprintf(out->id, sizeof out->id, "%s", id);
    out->state = state_of(str_at(rep, 0));
    out->frames_total = str_at(rep, 1) ? strtoull(str_at(rep, 1), NULL, 10) : 0;
    out->frames_done = str_at(rep, 2) ? strtoull(str_at(rep, 2), NULL, 10) : 0;
    out->error_status = str_at(rep, 3) ? atoi(str_at(rep, 3)) : 0;
    snprintf(out->error, sizeof out->error, "%s",
             str_at(rep, 4) ? str_at(rep, 4) : "");
    double created = str_at(rep, 5) ? strtod(str_at(rep, 5), NULL) : 0;
    out->age = srv__rj_wall() - created;
    if (out->age < 0) out->age = 0;
    if (ct) snprintf(ct, ctcap, "%s", str_at(rep, 6) ? str_at(rep, 6) : "");
    rc = SRV_STORE_OK;
  } else if (rep->type == REDIS_REPLY_ERROR) {
    rc = SRV_RJOBS_DOWN;
  }
  freeReplyObject(rep);
  return rc;
}

int srv_rjobs_get(srv_rjobs *j, const char *id, srv_job_view *out) {
  redisContext *c = srv_redis_acquire(j->rd);
  if (c == NULL) return SRV_RJOBS_DOWN;
  bool broken = false;
  int rc = read_record(j, c, &broken, id, out, NULL, 0);
  srv_redis_release(j->rd, c, broken);
  return rc;
}

/* The static content type a stored one names. */
static const char *static_type(const char *ct) {
  static const char *const known[] = {"application/json", "image/svg+xml",
                                      "application/problem+json"};
  for (size_t i = 0; i < 3; i++)
    if (strcmp(ct, known[i]) == 0) return known[i];
  return known[0];
}

int srv_rjobs_result(srv_rjobs *j, const char *id, srv_job_view *view,
                     srv_result **out) {
  *out = NULL;
  redisContext *c = srv_redis_acquire(j->rd);
  if (c == NULL) return SRV_RJOBS_DOWN;
  bool broken = false;
  char ct[64] = "", key[80];
  int rc = read_record(j, c, &broken, id, view, ct, sizeof ct);
  if (rc == SRV_STORE_OK && view->state == SRV_JOB_DONE) {
    srv__rj_key(key, sizeof key, "result", id);
    redisReply *rep = srv__rj_cmd(c, &broken, "GET %s", key);
    if (rep == NULL) {
      rc = SRV_RJOBS_DOWN;
    } else if (rep->type != REDIS_REPLY_STRING) {
      rc = SRV_STORE_GONE;
      snprintf(view->error, sizeof view->error,
               "its result expired (KMORPH_JOB_TTL)");
    } else {
      api_response res;
      api_response_init(&res);
      res.body = malloc(rep->len + 1);
      if (res.body != NULL) {
        memcpy(res.body, rep->str, rep->len);
        res.body[rep->len] = '\0';
        res.length = rep->len;
        res.status = 200;
        res.content_type = static_type(ct);
        *out = srv_result_wrap(&res);
      }
      if (*out == NULL) rc = SRV_RJOBS_NOMEM;
    }
    if (rep) freeReplyObject(rep);
  }
  srv_redis_release(j->rd, c, broken);
  return rc;
}

/* KEYS: job, live, frames, result. ARGV: id, state, error status, error,
 * content type, ttl seconds. 1 if the job was live, else 0. A done job's
 * result is SET just before, in the same pipeline but outside the
 * script (a 337 KB result: SET 1.5 ms, through a script 2-4.5 ms); a job
 * found no longer live drops it. */
static const char FINISH_LUA[] =
    "local st = redis.call('HGET', KEYS[1], 'st') "
    "if st ~= 'queued' and st ~= 'running' then "
    "if ARGV[2] == 'done' then redis.call('DEL', KEYS[4]) end return 0 end "
    "redis.call('HSET', KEYS[1], 'st', ARGV[2], 'es', ARGV[3], 'e', ARGV[4]) "
    "if ARGV[2] == 'done' then "
    "redis.call('HSET', KEYS[1], 'd', redis.call('HGET', KEYS[1], 'n'), "
    "'ct', ARGV[5]) end "
    "redis.call('HDEL', KEYS[1], 'b', 'a') "
    "redis.call('EXPIRE', KEYS[1], ARGV[6]) "
    "redis.call('DEL', KEYS[3]) redis.call('SREM', KEYS[2], ARGV[1]) "
    "return 1";

/* The next reply of a pipeline; NULL if the connection failed. */
static redisReply *next_reply(redisContext *c) {
  void *r = NULL;
  if (redisGetReply(c, &r) != REDIS_OK || r == NULL) return NULL;
  return r;
}

int srv__rj_finish(srv_rjobs *j, redisContext *c, const char *id,
                   srv_job_state state, const api_response *result,
                   int error_status, const char *error) {
  char kj[80], kf[80], kr[80];
  srv__rj_key(kj, sizeof kj, "job", id);
  srv__rj_key(kf, sizeof kf, "frames", id);
  srv__rj_key(kr, sizeof kr, "result", id);
  long ttl = (long)(j->cfg.job_ttl + 0.999);
  if (ttl < 1) ttl = 1;
  bool done = state == SRV_JOB_DONE && result != NULL && result->body != NULL;
  if (done && redisAppendCommand(c, "SET %s %b EX %ld", kr, result->body,
                                 result->length, ttl) != REDIS_OK)
    return -1;
  if (redisAppendCommand(
          c, "EVAL %s 4 %s %s %s %s %s %s %d %s %s %ld", FINISH_LUA, kj,
          RJ_LIVE, kf, kr, id, done ? "done" : srv_job_state_name(state),
          error_status, error ? error : "",
          done && result->content_type ? result->content_type : "",
          ttl) != REDIS_OK)
    return -1;
  redisReply *rep = done ? next_reply(c) : NULL;
  bool set_ok = !done || (rep && rep->type == REDIS_REPLY_STATUS);
  if (rep) freeReplyObject(rep);
  if (done && rep == NULL) return -1;
  rep = next_reply(c);
  if (rep == NULL) return -1;
  int rc = rep->type == REDIS_REPLY_INTEGER ? (int)rep->integer : -1;
  freeReplyObject(rep);
  /* A result Redis refused (out of memory) leaves the job done without
   * one (its result answers 410); the caller hears of it as a failure. */
  return set_ok ? rc : -1;
}

/* KEYS: job, frames, result. Forget a final job: 1, or 0 if unknown. */
static const char FORGET_LUA[] =
    "if redis.call('EXISTS', KEYS[1]) == 0 then return 0 end "
    "redis.call('DEL', KEYS[1], KEYS[2], KEYS[3]) return 1";

int srv_rjobs_delete(srv_rjobs *j, const char *id) {
  redisContext *c = srv_redis_acquire(j->rd);
  if (c == NULL) return SRV_RJOBS_DOWN;
  int rc = srv__rj_finish(j, c, id, SRV_JOB_CANCELLED, NULL, 0, NULL);
  bool broken = rc < 0;
  if (rc == 0) {
    char kj[80], kf[80], kr[80];
    srv__rj_key(kj, sizeof kj, "job", id);
    srv__rj_key(kf, sizeof kf, "frames", id);
    srv__rj_key(kr, sizeof kr, "result", id);
    redisReply *rep =
        srv__rj_cmd(c, &broken, "EVAL %s 3 %s %s %s", FORGET_LUA, kj, kf, kr);
    rc = rep && rep->type == REDIS_REPLY_INTEGER && rep->integer == 1 ? 1 : 0;
    if (rep) freeReplyObject(rep);
  }
  srv_redis_release(j->rd, c, broken);
  if (broken) return SRV_RJOBS_DOWN;
  return rc == 1 ? 0 : SRV_STORE_UNKNOWN;
}
