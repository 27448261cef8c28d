/* jobs_redis.c - batches of shared jobs: take one (XREADGROUP, or
 * XAUTOCLAIM from a silent consumer), render its frames, store them by
 * index, assemble the result when the last one is in, hand the batch back
 * on a graceful stop (see jobs_redis.h). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "jobs_redis_internal.h"
#include "util.h"

/* Seconds between two looks at a job's state from inside a frame. */
static const double STATE_POLL = 0.2;
/* Seconds between two XAUTOCLAIM tries of this instance. */
static const double CLAIM_EVERY = 1.0;

srv_rjobs *srv_rjobs_create(srv_redis *rd, const srv_rjobs_config *cfg) {
  srv_rjobs *j = calloc(1, sizeof *j);
  if (j == NULL) return NULL;
  j->rd = rd;
  j->cfg = *cfg;
  char host[64] = "host", hex[9];
  gethostname(host, sizeof host - 1);
  srv_random_hex(hex, 8);
  snprintf(j->consumer, sizeof j->consumer, "%s-%ld-%s", host, (long)getpid(),
           hex);
  snprintf(j->local, sizeof j->local, "%s:%s", RJ_STREAM, j->consumer);
  pthread_mutex_init(&j->mu, NULL);
  atomic_init(&j->stopping, false);
  atomic_init(&j->group_ok, false);
  atomic_init(&j->busy, 0);
  atomic_init(&j->frames, 0);
  atomic_init(&j->reclaimed, 0);
  atomic_init(&j->handed, 0);
  atomic_init(&j->assembled, 0);
  atomic_init(&j->prepared, 0);
  atomic_init(&j->next_claim, 0.0);
  return j;
}

/* ---------------------------------------------------------- batches */

typedef struct batch {
  char stream[RJ_KEY_MAX];     /* where it was read */
  char eid[64];                /* the stream entry */
  char id[SRV_JOB_ID_LEN + 1]; /* the job */
  size_t from, to;             /* frames [from, to) */
  bool again;                  /* delivered before (claimed) */
} batch;

/* An entry [eid, [field, value, ...]] into *b; false if malformed. */
static bool parse_entry(const redisReply *e, const char *stream, batch *b) {
  if (e->type != REDIS_REPLY_ARRAY || e->elements != 2 ||
      e->element[0]->type != REDIS_REPLY_STRING)
    return false;
  memset(b, 0, sizeof *b);
  snprintf(b->stream, sizeof b->stream, "%s", stream);
  snprintf(b->eid, sizeof b->eid, "%s", e->element[0]->str);
  const redisReply *f = e->element[1];
  if (f->type != REDIS_REPLY_ARRAY) return true; /* deleted: acked below */
  bool have_id = false;
  for (size_t k = 0; k + 1 < f->elements; k += 2) {
    const char *name = f->element[k]->str, *val = f->element[k + 1]->str;
    if (name == NULL || val == NULL) continue;
    if (strcmp(name, "id") == 0 && strlen(val) == SRV_JOB_ID_LEN) {
      memcpy(b->id, val, SRV_JOB_ID_LEN + 1);
      have_id = true;
    } else if (strcmp(name, "from") == 0) {
      b->from = strtoull(val, NULL, 10);
    } else if (strcmp(name, "to") == 0) {
      b->to = strtoull(val, NULL, 10);
    }
  }
  if (!have_id) b->from = b->to = 0;
  return true;
}

/* The group on stream (made with it if need be), the stream listed. */
static bool make_group(redisContext *c, bool *broken, const char *stream) {
  redisReply *rep = srv__rj_cmd(c, broken, "XGROUP CREATE %s %s 0 MKSTREAM",
                                stream, RJ_GROUP);
  bool ok = rep &&
            (rep->type == REDIS_REPLY_STATUS ||
             (rep->type == REDIS_REPLY_ERROR && strstr(rep->str, "BUSYGROUP")));
  if (rep) freeReplyObject(rep);
  rep =
      *broken ? NULL : srv__rj_cmd(c, broken, "SADD %s %s", RJ_STREAMS, stream);
  if (rep) freeReplyObject(rep);
  return ok && !*broken;
}

static void ensure_group(srv_rjobs *j, redisContext *c, bool *broken) {
  if (make_group(c, broken, RJ_STREAM) && make_group(c, broken, j->local))
    atomic_store(&j->group_ok, true);
}

/* Read RJ_STREAMS into j->streams (the shared and the local stream
 * always among them). */
static void refresh_streams(srv_rjobs *j, redisContext *c, bool *broken) {
  redisReply *rep = srv__rj_cmd(c, broken, "SMEMBERS %s", RJ_STREAMS);
  pthread_mutex_lock(&j->mu);
  size_t n = 0;
  snprintf(j->streams[n++], RJ_KEY_MAX, "%s", j->local);
  snprintf(j->streams[n++], RJ_KEY_MAX, "%s", RJ_STREAM);
  if (rep && rep->type == REDIS_REPLY_ARRAY)
    for (size_t k = 0; k < rep->elements && n < RJ_STREAMS_MAX; k++) {
      const char *name = rep->element[k]->str;
      if (name == NULL || strcmp(name, j->local) == 0 ||
          strcmp(name, RJ_STREAM) == 0 || strlen(name) >= RJ_KEY_MAX)
        continue;
      snprintf(j->streams[n++], RJ_KEY_MAX, "%s", name);
    }
  j->nstreams = n;
  pthread_mutex_unlock(&j->mu);
  if (rep) freeReplyObject(rep);
}

/* A copy of the streams known (out holds RJ_STREAMS_MAX). */
static size_t known_streams(srv_rjobs *j, char (*out)[RJ_KEY_MAX]) {
  pthread_mutex_lock(&j->mu);
  size_t n = j->nstreams;
  memcpy(out, j->streams, n * sizeof *out);
  pthread_mutex_unlock(&j->mu);
  return n;
}

/* One new batch of stream for this consumer; false if none. */
static bool read_from(srv_rjobs *j, redisContext *c, bool *broken,
                      const char *stream, batch *b) {
  redisReply *rep =
      srv__rj_cmd(c, broken, "XREADGROUP GROUP %s %s COUNT 1 STREAMS %s >",
                  RJ_GROUP, j->consumer, stream);
  if (rep == NULL) return false;
  bool got = false;
  if (rep->type == REDIS_REPLY_ARRAY && rep->elements == 1) {
    const redisReply *s = rep->element[0];
    if (s->type == REDIS_REPLY_ARRAY && s->elements == 2 &&
        s->element[1]->type == REDIS_REPLY_ARRAY &&
        s->element[1]->elements == 1)
      got = parse_entry(s->element[1]->element[0], stream, b);
  } else if (rep->type == REDIS_REPLY_ERROR && strstr(rep->str, "NOGROUP")) {
    /* A Redis restarted without its data, or a stream made again by
     * XADD after it was dropped empty: the group is made again - on
     * another instance's stream only if the stream exists (no
     * MKSTREAM: one just dropped is not made again from here). */
    if (strcmp(stream, RJ_STREAM) == 0 || strcmp(stream, j->local) == 0) {
      atomic_store(&j->group_ok, false);
    } else {
      redisReply *g =
          srv__rj_cmd(c, broken, "XGROUP CREATE %s %s 0", stream, RJ_GROUP);
      if (g) freeReplyObject(g);
    }
  }
  freeReplyObject(rep);
  return got;
}

/* The next batch: this instance's own first (the jobs it accepted and
 * prepared), then the shared stream, then, being idle, another
 * instance's own. */
static bool read_one(srv_rjobs *j, redisContext *c, bool *broken, batch *b) {
  if (read_from(j, c, broken, j->local, b)) return true;
  if (*broken || read_from(j, c, broken, RJ_STREAM, b)) return !*broken;
  char(*names)[RJ_KEY_MAX] = malloc(RJ_STREAMS_MAX * sizeof *names);
  if (names == NULL) return false;
  size_t n = known_streams(j, names);
  bool got = false;
  for (size_t k = 2; k < n && !got && !*broken; k++)
    got = read_from(j, c, broken, names[k], b);
  free(names);
  return got;
}

/* After an error reply on the shared or the local stream: a Redis that
 * lost the group (restarted without its data) gets it on the next try. */
static void check_error(srv_rjobs *j, const redisReply *rep) {
  if (rep->type == REDIS_REPLY_ERROR && strstr(rep->str, "NOGROUP"))
    atomic_store(&j->group_ok, false);
}

/* KEYS: a stream of another instance, RJ_STREAMS, that instance's
 * "alive" key. Drop the stream if it is empty and its instance has not
 * said it is alive for two visibility timeouts: it is gone and left
 * nothing to read there (an instance wrongly taken for gone makes the
 * stream and its group again with its next job). */
static const char DROP_EMPTY_LUA[] =
    "if redis.call('EXISTS', KEYS[3]) == 1 then return 0 end "
    "if redis.call('XLEN', KEYS[1]) > 0 then return 0 end "
    "redis.call('DEL', KEYS[1]) redis.call('SREM', KEYS[2], KEYS[1]) "
    "return 1";

/* The "alive" key of the instance whose own stream is stream. */
static void alive_key(char *buf, size_t cap, const char *stream) {
  size_t skip = strlen(RJ_STREAM) + 1;
  const char *consumer = strlen(stream) > skip ? stream + skip : stream;
  snprintf(buf, cap, "kmorph:alive:%s", consumer);
}

/* One batch left pending by a consumer silent for the visibility
 * timeout, on any stream, claimed for this one; false if none. Empty
 * streams of other instances are dropped on the way. */
static bool claim_one(srv_rjobs *j, redisContext *c, bool *broken, batch *b) {
  long long idle_ms = (long long)(j->cfg.visibility * 1000.0);
  /* This instance is alive (its own stream is not dropped). */
  char alive[RJ_KEY_MAX + 16];
  alive_key(alive, sizeof alive, j->local);
  long long ttl_ms = (long long)(2000.0 * j->cfg.visibility);
  redisReply *a = srv__rj_cmd(c, broken, "SET %s 1 PX %lld", alive, ttl_ms);
  if (a) freeReplyObject(a);
  refresh_streams(j, c, broken);
  char(*names)[RJ_KEY_MAX] = malloc(RJ_STREAMS_MAX * sizeof *names);
  if (names == NULL) return false;
  size_t n = known_streams(j, names);
  bool got = false;
  for (size_t k = 0; k < n && !got && !*broken; k++) {
    redisReply *rep =
        srv__rj_cmd(c, broken, "XAUTOCLAIM %s %s %s %lld 0-0 COUNT 1", names[k],
                    RJ_GROUP, j->consumer, idle_ms);
    if (rep && rep->type == REDIS_REPLY_ARRAY && rep->elements >= 2 &&
        rep->element[1]->type == REDIS_REPLY_ARRAY &&
        rep->element[1]->elements >= 1) {
      got = parse_entry(rep->element[1]->element[0], names[k], b);
      b->again = true;
    } else if (rep && rep->type == REDIS_REPLY_ERROR) {
      if (k < 2) check_error(j, rep);
    } else if (rep && k >= 2) {
      char theirs[RJ_KEY_MAX + 16];
      alive_key(theirs, sizeof theirs, names[k]);
      redisReply *d = srv__rj_cmd(c, broken, "EVAL %s 3 %s %s %s",
                                  DROP_EMPTY_LUA, names[k], RJ_STREAMS, theirs);
      if (d) freeReplyObject(d);
    }
    if (rep) freeReplyObject(rep);
  }
  free(names);
  return got;
}

static const char ACK_LUA[] = "redis.call('XACK', KEYS[1], ARGV[1], ARGV[2]) "
                              "redis.call('XDEL', KEYS[1], ARGV[2]) return 0";

static void ack(redisContext *c, bool *broken, const batch *b) {
  redisReply *rep = srv__rj_cmd(c, broken, "EVAL %s 1 %s %s %s", ACK_LUA,
                                b->stream, RJ_GROUP, b->eid);
  if (rep) freeReplyObject(rep);
}

/* The frames [from, to) of b as a new entry of the shared stream,
 * delivered at once to any consumer, and b acknowledged where it was
 * read: in one script, so that the frames are neither lost nor pending
 * twice. KEYS: b's stream, the shared stream. */
static const char HAND_BACK_LUA[] =
    "redis.call('XADD', KEYS[2], '*', 'id', ARGV[3], 'from', ARGV[4], "
    "'to', ARGV[5]) "
    "redis.call('XACK', KEYS[1], ARGV[1], ARGV[2]) "
    "redis.call('XDEL', KEYS[1], ARGV[2]) return 0";

static void hand_back(srv_rjobs *j, redisContext *c, bool *broken,
                      const batch *b, size_t from) {
  redisReply *rep =
      srv__rj_cmd(c, broken, "EVAL %s 2 %s %s %s %s %s %llu %llu",
                  HAND_BACK_LUA, b->stream, RJ_STREAM, RJ_GROUP, b->eid, b->id,
                  (unsigned long long)from, (unsigned long long)b->to);
  if (rep) freeReplyObject(rep);
  if (!*broken) atomic_fetch_add(&j->handed, 1);
}

/* Why a frame's computation was stopped. */
enum { WHY_NONE, WHY_SHUTDOWN, WHY_TIME, WHY_FINAL, WHY_BROKEN, WHY_TAKEN };

typedef struct run_ctx {
  srv_rjobs *j;
  redisContext *c;
  bool *broken;
  char key[80];    /* the job's record */
  double deadline; /* Unix seconds */
  double next_look;
  const batch *b;   /* the batch being rendered */
  double next_keep; /* srv_now(): when to claim it again */
  int why;
} run_ctx;

/* KEYS: stream. ARGV: group, entry, consumer. Claim the entry again
 * (its idle time back to 0) if it is still this consumer's: 1, else 0. */
static const char KEEP_LUA[] =
    "local p = redis.call('XPENDING', KEYS[1], ARGV[1], ARGV[2], ARGV[2], 1) "
    "if #p == 0 or p[1][2] ~= ARGV[3] then return 0 end "
    "redis.call('XCLAIM', KEYS[1], ARGV[1], ARGV[3], 0, ARGV[2], 'JUSTID') "
    "return 1";

/* Claim x's batch again, so that a batch of slow frames (or one whose
 * plan took long to prepare) is not taken over while this instance still
 * renders it: the visibility timeout counts from the last claim. False,
 * with x->why = WHY_TAKEN, if another instance has taken it over
 * meanwhile: then it renders the batch, and this one lets it go. */
static bool keep_batch(run_ctx *x) {
  double now = srv_now();
  if (now < x->next_keep) return true;
  x->next_keep = now + x->j->cfg.visibility / 4;
  redisReply *rep =
      srv__rj_cmd(x->c, x->broken, "EVAL %s 1 %s %s %s %s", KEEP_LUA,
                  x->b->stream, RJ_GROUP, x->b->eid, x->j->consumer);
  bool ours =
      rep == NULL || rep->type != REDIS_REPLY_INTEGER || rep->integer == 1;
  if (rep) freeReplyObject(rep);
  if (!ours) x->why = WHY_TAKEN;
  return ours;
}

/* The job is still queued or running (false on a broken connection). */
static bool still_live(run_ctx *x) {
  if (!keep_batch(x)) return false;
  redisReply *rep =
      *x->broken ? NULL : srv__rj_cmd(x->c, x->broken, "HGET %s st", x->key);
  if (rep == NULL) {
    x->why = WHY_BROKEN;
    return false;
  }
  bool live =
      rep->type == REDIS_REPLY_STRING &&
      (strcmp(rep->str, "queued") == 0 || strcmp(rep->str, "running") == 0);
  freeReplyObject(rep);
  if (!live) x->why = WHY_FINAL;
  return live;
}

/* A frame's stop condition: shutdown, out of time, or (looked up at most
 * every STATE_POLL seconds) the job cancelled or failed elsewhere. */
static bool run_should_stop(void *ctx) {
  run_ctx *x = ctx;
  if (atomic_load(&x->j->stopping)) return x->why = WHY_SHUTDOWN, true;
  if (srv__rj_wall() > x->deadline) return x->why = WHY_TIME, true;
  double now = srv_now();
  if (now < x->next_look) return false;
  x->next_look = now + STATE_POLL;
  return !still_live(x);
}

/* KEYS: job, frames, stream. ARGV: group, entry, frames of the job, then
 * index, text, index, text... {new, done}: frames this call stored,
 * frames stored in all (-1 if the job is no longer live). The entry is
 * acknowledged here too unless every frame is now stored: then it stays
 * pending until the result is, so that a consumer dying in between
 * leaves it to be claimed and the result assembled by another. An
 * empty entry stores the frames only (a batch being handed back). */
static const char FRAMES_LUA[] =
    "local function ack() if ARGV[2] ~= '' then "
    "redis.call('XACK', KEYS[3], ARGV[1], ARGV[2]) "
    "redis.call('XDEL', KEYS[3], ARGV[2]) end end "
    "local st = redis.call('HGET', KEYS[1], 'st') "
    "if st ~= 'queued' and st ~= 'running' then ack() return {0, -1} end "
    "if st == 'queued' then redis.call('HSET', KEYS[1], 'st', 'running') end "
    "local new = 0 "
    "for k = 4, #ARGV, 2 do "
    "new = new + redis.call('HSETNX', KEYS[2], ARGV[k], ARGV[k + 1]) end "
    "local d = redis.call('HINCRBY', KEYS[1], 'd', new) "
    "if d < tonumber(ARGV[3]) then ack() end "
    "return {new, d}";

/* Store the texts of frames [first, first + n) in one script (one round
 * trip a batch, not one a frame); *done receives the frames stored in
 * all, -1 if the job is no longer live. Returns how many this call
 * stored (0 on a broken connection). */
static long long store_frames(run_ctx *x, const batch *b, size_t total,
                              size_t n, const api_response *texts,
                              long long *done) {
  char kf[80], script_keys[] = "3", tot[24];
  srv__rj_key(kf, sizeof kf, "frames", b->id);
  snprintf(tot, sizeof tot, "%zu", total);
  size_t first = b->from;
  size_t argc = 9 + 2 * n;
  const char **argv = malloc(argc * sizeof *argv);
  size_t *lens = malloc(argc * sizeof *lens);
  char(*nums)[24] = malloc((n ? n : 1) * sizeof *nums);
  *done = -1;
  if (argv == NULL || lens == NULL || nums == NULL) {
    free(argv);
    free(lens);
    free(nums);
    *x->broken = true; /* the batch stays pending and is retried */
    return 0;
  }
  const char *head[9] = {"EVAL",    FRAMES_LUA, script_keys, x->key, kf,
                         b->stream, RJ_GROUP,   b->eid,      tot};
  for (size_t k = 0; k < 9; k++) {
    argv[k] = head[k];
    lens[k] = strlen(head[k]);
  }
  for (size_t k = 0; k < n; k++) {
    snprintf(nums[k], sizeof nums[k], "%zu", first + k);
    argv[9 + 2 * k] = nums[k];
    lens[9 + 2 * k] = strlen(nums[k]);
    argv[10 + 2 * k] = texts[k].body ? texts[k].body : "";
    lens[10 + 2 * k] = texts[k].body ? texts[k].length : 0;
  }
  redisReply *rep = redisCommandArgv(x->c, (int)argc, argv, lens);
  free(argv);
  free(lens);
  free(nums);
  if (rep == NULL || x->c->err) {
    if (rep) freeReplyObject(rep);
    *x->broken = true;
    return 0;
  }
  long long fresh = 0;
  if (rep->type == REDIS_REPLY_ARRAY && rep->elements == 2) {
    fresh = rep->element[0]->integer;
    *done = rep->element[1]->integer;
  }
  freeReplyObject(rep);
  return fresh;
}

static void fail_job(run_ctx *x, const char *id, int status, const char *msg) {
  if (srv__rj_finish(x->j, x->c, id, SRV_JOB_FAILED, NULL, status, msg) < 0)
    *x->broken = true;
}

/* Every frame is stored: the result, in frame order, into the record. */
static void assemble(run_ctx *x, const char *id, api_morph_plan *plan,
                     size_t total) {
  api_response res;
  api_response_init(&res);
  int rc = 500;
  if (!api_morph_frames_apart(plan)) {
    rc = api_morph_result(plan, &res);
  } else {
    char kf[80];
    srv__rj_key(kf, sizeof kf, "frames", id);
    redisReply *rep = srv__rj_cmd(x->c, x->broken, "HGETALL %s", kf);
    if (rep == NULL) return;
    const char **texts = calloc(total ? total : 1, sizeof *texts);
    size_t *lens = calloc(total ? total : 1, sizeof *lens);
    size_t have = 0;
    if (texts && lens && rep->type == REDIS_REPLY_ARRAY)
      for (size_t k = 0; k + 1 < rep->elements; k += 2) {
        size_t i = strtoull(rep->element[k]->str, NULL, 10);
        if (i < total && texts[i] == NULL) {
          texts[i] = rep->element[k + 1]->str;
          lens[i] = rep->element[k + 1]->len;
          have++;
        }
      }
    if (have == total)
      rc = api_morph_result_from_texts(plan, texts, lens, &res);
    free(texts);
    free(lens);
    freeReplyObject(rep);
    if (have != total && texts && lens) {
      /* The count says all are in, the hash does not: a job cancelled
       * and forgotten meanwhile. Nothing to assemble. */
      return;
    }
  }
  if (rc == 200 && res.body != NULL) {
    if (srv__rj_finish(x->j, x->c, id, SRV_JOB_DONE, &res, 0, NULL) < 0)
      *x->broken = true;
    else
      atomic_fetch_add(&x->j->assembled, 1);
  } else {
    char msg[96];
    snprintf(msg, sizeof msg, "the result could not be assembled (%d)", rc);
    fail_job(x, id, rc >= 400 ? rc : 500, msg);
  }
  api_response_free(&res);
}

static void out_of_time(run_ctx *x, const char *id, long long done,
                        size_t total) {
  char msg[200];
  snprintf(msg, sizeof msg,
           "the job ran out of time: wall-time limit %g s (KMORPH_JOB_TIME) "
           "reached after %lld of %zu frames",
           x->j->cfg.job_time, done > 0 ? done : 0, total);
  fail_job(x, id, 503, msg);
}

/* What the record says a batch should do. */
typedef struct record {
  bool live;
  size_t total;
  double deadline;
  long long done;
} record;

/* The job's plan: this instance's, else prepared from the request in
 * the record (read only then: it is the record's largest part). NULL,
 * with the job recorded as failed, if it cannot be prepared. */
static rj_plan *job_plan(run_ctx *x, const char *id) {
  rj_plan *p = srv__rj_cache_ref(x->j, id);
  if (p != NULL) return p;
  redisReply *rep = srv__rj_cmd(x->c, x->broken, "HMGET %s b a", x->key);
  if (rep == NULL) return NULL;
  int status = 500;
  char why[160] = "the job's request is no longer stored";
  if (rep->type == REDIS_REPLY_ARRAY && rep->elements == 2 &&
      rep->element[0]->type == REDIS_REPLY_STRING) {
    const char *acc = rep->element[1]->str ? rep->element[1]->str : "";
    p = srv__rj_cache_prepare(x->j, id, rep->element[0]->str,
                              rep->element[0]->len, acc, &status, why,
                              sizeof why);
  }
  freeReplyObject(rep);
  if (p == NULL && !*x->broken) fail_job(x, id, status, why);
  return p;
}

/* Read the record; *p receives the job's plan (NULL if the job is not
 * live or its plan failed, then recorded as failed). */
static record open_job(run_ctx *x, const batch *b, rj_plan **p) {
  record r = {false, 0, 0, 0};
  *p = NULL;
  redisReply *rep = srv__rj_cmd(x->c, x->broken, "HMGET %s st n dl d", x->key);
  if (rep == NULL) return r;
  const char *st = NULL;
  if (rep->type == REDIS_REPLY_ARRAY && rep->elements == 4 &&
      rep->element[0]->type == REDIS_REPLY_STRING)
    st = rep->element[0]->str;
  if (st && (strcmp(st, "queued") == 0 || strcmp(st, "running") == 0)) {
    r.live = true;
    r.total =
        strtoull(rep->element[1]->str ? rep->element[1]->str : "0", NULL, 10);
    r.deadline =
        strtod(rep->element[2]->str ? rep->element[2]->str : "0", NULL);
    r.done =
        strtoll(rep->element[3]->str ? rep->element[3]->str : "0", NULL, 10);
  }
  freeReplyObject(rep);
  if (!r.live) return r;
  x->deadline = r.deadline;
  if (srv__rj_wall() > r.deadline) {
    out_of_time(x, b->id, r.done, r.total);
    r.live = false;
    return r;
  }
  *p = job_plan(x, b->id);
  if (*p == NULL) {
    r.live = false;
  } else if (api_morph_frame_count((*p)->plan) != r.total) {
    srv__rj_cache_release(x->j, *p);
    *p = NULL;
    fail_job(x, b->id, 500,
             "the stored request plans another count of "
             "frames");
    r.live = false;
  }
  return r;
}

/* Before frame i of a batch: run waiting requests (as in-memory jobs
 * do between frames), look at the job's state (at most every STATE_POLL
 * seconds, as the stop callback does inside a frame), then render it.
 * False when the batch must end: x->why says why (WHY_NONE after a
 * failure, recorded in the job). */
static bool render_step(srv_rjobs *j, run_ctx *x, rj_plan *p, const batch *b,
                        const record *r, size_t i) {
  if (atomic_load(&j->stopping)) {
    x->why = WHY_SHUTDOWN;
    return false;
  }
  if (i > b->from && j->yield != NULL)
    while (j->yield(j->yield_ctx)) {
    }
  if (srv_now() >= x->next_look) {
    x->next_look = srv_now() + STATE_POLL;
    if (!still_live(x)) return false;
  }
  int rc = api_morph_render_frame_until(p->plan, i, run_should_stop, x);
  if (rc == 0) {
    atomic_fetch_add(&j->frames, 1);
    return true;
  }
  if (x->why == WHY_NONE && srv__rj_wall() > r->deadline) x->why = WHY_TIME;
  if (x->why == WHY_TIME)
    out_of_time(x, b->id, (long long)(i - b->from), r->total);
  if (x->why == WHY_NONE) {
    char msg[96];
    snprintf(msg, sizeof msg, "frame %zu could not be built", i);
    fail_job(x, b->id, rc >= 400 ? rc : 422, msg);
  }
  return false;
}

/* KEYS: job. ARGV: frames rendered. The job's progress raised to it
 * (never lowered: a batch delivered again starts from 0); -1 if the job
 * is no longer live. */
static const char PROGRESS_LUA[] =
    "local st = redis.call('HGET', KEYS[1], 'st') "
    "if st ~= 'queued' and st ~= 'running' then return -1 end "
    "if st == 'queued' then redis.call('HSET', KEYS[1], 'st', 'running') end "
    "local d = tonumber(redis.call('HGET', KEYS[1], 'd')) "
    "if tonumber(ARGV[1]) > d then d = tonumber(ARGV[1]) "
    "redis.call('HSET', KEYS[1], 'd', d) end return d";

/* Record that n frames of a solo batch are rendered; false if the job is
 * no longer live (or the connection broke). */
static bool solo_progress(run_ctx *x, size_t n) {
  redisReply *rep = srv__rj_cmd(x->c, x->broken, "EVAL %s 1 %s %llu",
                                PROGRESS_LUA, x->key, (unsigned long long)n);
  bool live = rep && rep->type == REDIS_REPLY_INTEGER && rep->integer >= 0;
  if (rep) freeReplyObject(rep);
  if (!live && !*x->broken) x->why = WHY_FINAL;
  return live;
}

/* A batch of every frame of its job: rendered here and assembled from
 * this plan alone, no frame text stored (progress is recorded every
 * STATE_POLL seconds). Stopped gracefully, it is handed back whole: the
 * frames rendered here are not kept anywhere else. */
static void run_solo(srv_rjobs *j, run_ctx *x, rj_plan *p, const batch *b,
                     const record *r) {
  size_t i = 0;
  double next_progress = srv_now() + STATE_POLL;
  for (; i < r->total; i++) {
    if (!render_step(j, x, p, b, r, i)) break;
    if (srv_now() >= next_progress && i + 1 < r->total) {
      next_progress = srv_now() + STATE_POLL;
      if (!solo_progress(x, i + 1)) break;
    }
  }
  /* Broken: pending, claimed after the timeout; taken: another renders
   * it. */
  if (*x->broken || x->why == WHY_TAKEN) return;
  if (x->why == WHY_SHUTDOWN) {
    hand_back(j, x->c, x->broken, b, 0);
    return;
  }
  if (i == r->total) {
    api_response res;
    api_response_init(&res);
    int rc = api_morph_result(p->plan, &res);
    if (rc == 200 && res.body != NULL) {
      if (srv__rj_finish(j, x->c, b->id, SRV_JOB_DONE, &res, 0, NULL) < 0)
        *x->broken = true;
      else
        atomic_fetch_add(&j->assembled, 1);
    } else {
      char msg[96];
      snprintf(msg, sizeof msg, "the result could not be assembled (%d)", rc);
      fail_job(x, b->id, rc >= 400 ? rc : 500, msg);
    }
    api_response_free(&res);
  }
  if (!*x->broken) ack(x->c, x->broken, b);
}

/* A batch of some frames of a job shared between instances: each frame's
 * text is stored (one script for the batch, which also acknowledges it
 * unless the job is then complete); the batch that completes the job, or
 * one delivered again that finds every frame stored, assembles the
 * result from the texts. Returns the frames stored in all, -1 if the job
 * is no longer live or unknown. */
static long long run_shared(srv_rjobs *j, run_ctx *x, rj_plan *p,
                            const batch *b, const record *r) {
  size_t span = b->to - b->from, i = b->from;
  long long done = r->done;
  api_response *texts = calloc(span, sizeof *texts);
  if (texts == NULL) return -1; /* pending: retried after the timeout */
  for (; i < b->to && i < r->total; i++) {
    if (!render_step(j, x, p, b, r, i)) break;
    int rc = api_morph_frame_text(p->plan, i, &texts[i - b->from]);
    if (rc != 200) {
      char msg[96];
      snprintf(msg, sizeof msg, "frame %zu could not be written (%d)", i, rc);
      fail_job(x, b->id, rc >= 400 ? rc : 500, msg);
      break;
    }
  }
  bool last = false, acked = false;
  if (!*x->broken && i > b->from && x->why == WHY_SHUTDOWN) {
    /* Stored without the entry, whose rest is handed back below. */
    batch part = *b;
    part.eid[0] = '\0';
    store_frames(x, &part, r->total, i - b->from, texts, &done);
  } else if (!*x->broken && i > b->from && i == b->to) {
    long long fresh = store_frames(x, b, r->total, span, texts, &done);
    last = fresh > 0 && done >= 0 && (size_t)done == r->total;
    acked = done < 0 || (size_t)done < r->total;
  }
  for (size_t k = 0; k < span; k++) api_response_free(&texts[k]);
  free(texts);
  if (*x->broken || x->why == WHY_TAKEN) return done;
  if (x->why == WHY_SHUTDOWN && i < b->to) {
    hand_back(j, x->c, x->broken, b, i);
    return done;
  }
  /* A consumer may have died after storing the last frame and before
   * assembling the result: a batch delivered again does it. */
  if (done >= 0 && (size_t)done == r->total &&
      (last || b->again || r->done == (long long)r->total))
    assemble(x, b->id, p->plan, r->total);
  if (!*x->broken && !acked) ack(x->c, x->broken, b);
  return done;
}

/* Render batch b and acknowledge it, hand it back, or leave it pending
 * (Redis went away). */
static void run_batch(srv_rjobs *j, redisContext *c, bool *broken,
                      const batch *b) {
  run_ctx x = {.j = j,
               .c = c,
               .broken = broken,
               .why = WHY_NONE,
               .next_look = srv_now() + STATE_POLL,
               .b = b,
               .next_keep = srv_now() + j->cfg.visibility / 4};
  srv__rj_key(x.key, sizeof x.key, "job", b->id);
  rj_plan *p = NULL;
  bool over = false;
  record r = b->from < b->to ? open_job(&x, b, &p) : (record){0};
  /* Preparing the plan may have taken a while: claimed again if so. */
  if (r.live && !keep_batch(&x)) goto out;
  if (*broken) goto out;
  if (!r.live) {
    ack(c, broken, b); /* final, unknown or empty: nothing to render */
    goto out;
  }
  if (b->from == 0 && b->to >= r.total) {
    run_solo(j, &x, p, b, &r);
    over = x.why != WHY_SHUTDOWN;
  } else {
    long long done = run_shared(j, &x, p, b, &r);
    over = done < 0 || (size_t)done == r.total || x.why == WHY_FINAL;
  }
out:
  if (p) {
    srv__rj_cache_release(j, p);
    if (over && !*broken) srv__rj_cache_drop(j, b->id);
  }
}

bool srv_rjobs_work(void *ctx) {
  srv_rjobs *j = ctx;
  if (atomic_load(&j->stopping)) return false;
  redisContext *c = srv_redis_acquire(j->rd);
  if (c == NULL) return false;
  bool broken = false, got = false;
  batch b;
  if (!atomic_load(&j->group_ok)) ensure_group(j, c, &broken);
  double now = srv_now();
  double next = atomic_load(&j->next_claim);
  if (!broken && now >= next &&
      atomic_compare_exchange_strong(&j->next_claim, &next,
                                     now + CLAIM_EVERY)) {
    got = claim_one(j, c, &broken, &b);
    if (got) atomic_fetch_add(&j->reclaimed, 1);
  }
  if (!got && !broken) got = read_one(j, c, &broken, &b);
  if (got && !broken) {
    atomic_fetch_add(&j->busy, 1);
    run_batch(j, c, &broken, &b);
    atomic_fetch_sub(&j->busy, 1);
  }
  srv_redis_release(j->rd, c, broken);
  return got && !broken;
}

void srv_rjobs_set_yield(srv_rjobs *j, bool (*yield)(void *), void *ctx) {
  j->yield = yield;
  j->yield_ctx = ctx;
}

void srv_rjobs_stop(srv_rjobs *j) {
  atomic_store(&j->stopping, true);
}

size_t srv_rjobs_busy(srv_rjobs *j) {
  return atomic_load(&j->busy);
}

/* Hand back every batch of stream pending for this consumer; how many. */
static size_t hand_back_stream(srv_rjobs *j, redisContext *c, bool *broken,
                               const char *stream) {
  size_t n = 0;
  redisReply *rep = srv__rj_cmd(c, broken, "XPENDING %s %s - + 100 %s", stream,
                                RJ_GROUP, j->consumer);
  for (size_t k = 0;
       rep && rep->type == REDIS_REPLY_ARRAY && k < rep->elements && !*broken;
       k++) {
    const redisReply *e = rep->element[k];
    if (e->type != REDIS_REPLY_ARRAY || e->elements < 1) continue;
    /* Claimed by this consumer (idle 0) so that XCLAIM gives the fields. */
    redisReply *cl = srv__rj_cmd(c, broken, "XCLAIM %s %s %s 0 %s", stream,
                                 RJ_GROUP, j->consumer, e->element[0]->str);
    batch b;
    if (cl && cl->type == REDIS_REPLY_ARRAY && cl->elements == 1 &&
        parse_entry(cl->element[0], stream, &b)) {
      if (b.from < b.to)
        hand_back(j, c, broken, &b, b.from);
      else
        ack(c, broken, &b);
      n++;
    }
    if (cl) freeReplyObject(cl);
  }
  if (rep) freeReplyObject(rep);
  return n;
}

size_t srv_rjobs_hand_back_all(srv_rjobs *j) {
  redisContext *c = srv_redis_acquire(j->rd);
  if (c == NULL) return 0;
  bool broken = false;
  size_t n = 0;
  refresh_streams(j, c, &broken);
  char(*names)[RJ_KEY_MAX] = malloc(RJ_STREAMS_MAX * sizeof *names);
  size_t ns = names ? known_streams(j, names) : 0;
  for (size_t k = 0; k < ns && !broken; k++)
    n += hand_back_stream(j, c, &broken, names[k]);
  free(names);
  /* Batches left in this instance's own stream go to the shared one, so
   * that no instance has to be idle to see them. */
  batch b;
  while (!broken && read_from(j, c, &broken, j->local, &b)) {
    if (b.from < b.to)
      hand_back(j, c, &broken, &b, b.from);
    else
      ack(c, &broken, &b);
    n++;
  }
  srv_redis_release(j->rd, c, broken);
  return n;
}

bool srv_rjobs_ready(srv_rjobs *j) {
  return srv_redis_ping(j->rd);
}

bool srv_rjobs_up(srv_rjobs *j) {
  return srv_redis_up(j->rd);
}

void srv_rjobs_destroy(srv_rjobs *j) {
  if (j == NULL) return;
  while (j->plans) {
    rj_plan *p = j->plans;
    j->plans = p->next;
    api_morph_plan_free(p->plan);
    free(p);
  }
  pthread_mutex_destroy(&j->mu);
  free(j);
}
