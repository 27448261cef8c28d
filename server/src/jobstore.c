/* jobstore.c - the in-memory job store (see jobstore.h).
 *
 * DESIGN: a doubly linked list in creation order under one mutex. The job
 * count is bounded by the daemon's admission limit plus `keep`, so linear
 * lookups stay cheap; expiry is lazy (done on every access) so no timer
 * thread is needed. Result memory is one counter: bytes reserved by live
 * jobs (their predicted result size) plus bytes of results kept. Ids of
 * forgotten jobs go to a ring of fixed size with the reason they went.
 */
#include "jobstore.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct srv_result {
  atomic_size_t refs;
  api_response res;
};

srv_result *srv_result_wrap(api_response *res) {
  srv_result *r = malloc(sizeof *r);
  if (r == NULL) {
    api_response_free(res);
    return NULL;
  }
  atomic_init(&r->refs, 1);
  r->res = *res;
  api_response_init(res);
  return r;
}

srv_result *srv_result_ref(srv_result *r) {
  if (r != NULL) atomic_fetch_add(&r->refs, 1);
  return r;
}

void srv_result_unref(srv_result *r) {
  if (r == NULL || atomic_fetch_sub(&r->refs, 1) != 1) return;
  api_response_free(&r->res);
  free(r);
}

const char *srv_result_body(const srv_result *r) {
  return r->res.body;
}
size_t srv_result_length(const srv_result *r) {
  return r->res.length;
}
int srv_result_status(const srv_result *r) {
  return r->res.status;
}
const char *srv_result_type(const srv_result *r) {
  return r->res.content_type;
}

typedef struct rec {
  struct rec *prev, *next;
  char id[SRV_JOB_ID_LEN + 1];
  srv_job_state state;
  size_t frames_done, frames_total;
  int error_status;
  char error[256];
  double created, finished;
  size_t reserved;    /* result bytes promised while the job is live */
  srv_result *result; /* done and kept */
  bool evicted;       /* done, but its result made room for others */
} rec;

/* A job no longer kept: its id and why it went. */
typedef struct gone {
  char id[SRV_JOB_ID_LEN + 1];
  char why[160];
} gone;

#define GONE_RING_MAX 65536

typedef struct memstore {
  srv_jobstore base;
  pthread_mutex_t mu;
  rec *first, *last;
  double ttl;
  size_t keep;
  size_t budget, used; /* result bytes: the limit, reserved + kept */
  gone *ring;
  size_t ring_cap, ring_next;
} memstore;

static const char *const STATE_NAMES[SRV_JOB_NSTATES] = {
    "queued", "running", "done", "failed", "cancelled"};

const char *srv_job_state_name(srv_job_state s) {
  return (unsigned)s < SRV_JOB_NSTATES ? STATE_NAMES[s] : "unknown";
}

bool srv_job_state_final(srv_job_state s) {
  return s == SRV_JOB_DONE || s == SRV_JOB_FAILED || s == SRV_JOB_CANCELLED;
}

static void remember_gone(memstore *m, const char *id, const char *why) {
  gone *g = &m->ring[m->ring_next];
  m->ring_next = (m->ring_next + 1) % m->ring_cap;
  snprintf(g->id, sizeof g->id, "%s", id);
  snprintf(g->why, sizeof g->why, "%s", why);
}

static const gone *find_gone(const memstore *m, const char *id) {
  for (size_t i = 0; i < m->ring_cap; i++)
    if (m->ring[i].id[0] != '\0' && strcmp(m->ring[i].id, id) == 0)
      return &m->ring[i];
  return NULL;
}

static void drop_result(memstore *m, rec *r) {
  if (r->result != NULL) {
    m->used -= srv_result_length(r->result);
    srv_result_unref(r->result);
    r->result = NULL;
  }
  m->used -= r->reserved;
  r->reserved = 0;
}

/* Unlink and free r; why (may be NULL) is remembered for its id. */
static void unlink_free(memstore *m, rec *r, const char *why) {
  if (why != NULL) remember_gone(m, r->id, why);
  if (r->prev)
    r->prev->next = r->next;
  else
    m->first = r->next;
  if (r->next)
    r->next->prev = r->prev;
  else
    m->last = r->prev;
  drop_result(m, r);
  free(r);
}

/* Drop finished records older than ttl, then the oldest finished ones
 * beyond keep. Called with the lock held. */
static void expire(memstore *m, double now) {
  size_t finished = 0;
  rec *next;
  char why[160];
  for (rec *r = m->first; r; r = next) {
    next = r->next;
    if (!srv_job_state_final(r->state)) continue;
    if (now - r->finished >= m->ttl) {
      snprintf(why, sizeof why,
               "the job finished %.0f s ago; finished jobs are kept for "
               "%g s (KMORPH_JOB_TTL)",
               now - r->finished, m->ttl);
      unlink_free(m, r, why);
    } else {
      finished++;
    }
  }
  snprintf(why, sizeof why,
           "at most %zu finished jobs are kept (KMORPH_JOB_KEEP) and newer "
           "ones took its place",
           m->keep);
  for (rec *r = m->first; r && finished > m->keep; r = next) {
    next = r->next;
    if (srv_job_state_final(r->state)) {
      unlink_free(m, r, why);
      finished--;
    }
  }
}

/* Evict kept results, oldest first, until need more bytes fit. Returns
 * false if they cannot (live reservations fill the budget). */
static bool make_room(memstore *m, size_t need) {
  for (rec *r = m->first; r && m->used + need > m->budget; r = r->next)
    if (r->result != NULL) {
      drop_result(m, r);
      r->evicted = true;
    }
  return m->used + need <= m->budget;
}

static rec *find(memstore *m, const char *id) {
  for (rec *r = m->first; r; r = r->next)
    if (strcmp(r->id, id) == 0) return r;
  return NULL;
}

static void view_of(const rec *r, double now, srv_job_view *v) {
  memcpy(v->id, r->id, sizeof v->id);
  v->state = r->state;
  v->frames_done = r->frames_done;
  v->frames_total = r->frames_total;
  v->error_status = r->error_status;
  memcpy(v->error, r->error, sizeof v->error);
  v->age = now - r->created;
}

/* Fill a view for a forgotten job. Returns SRV_STORE_GONE or
 * SRV_STORE_UNKNOWN. */
static int lookup_gone(const memstore *m, const char *id, srv_job_view *v) {
  const gone *g = find_gone(m, id);
  if (g == NULL) return SRV_STORE_UNKNOWN;
  memset(v, 0, sizeof *v);
  memcpy(v->id, g->id, sizeof v->id);
  snprintf(v->error, sizeof v->error, "%s", g->why);
  return SRV_STORE_GONE;
}

static int m_create(srv_jobstore *s, const char *id, size_t total,
                    size_t result_bytes, double now) {
  memstore *m = (memstore *)s;
  rec *r = calloc(1, sizeof *r);
  if (r == NULL) return -1;
  snprintf(r->id, sizeof r->id, "%s", id);
  r->state = SRV_JOB_QUEUED;
  r->frames_total = total;
  r->created = now;
  pthread_mutex_lock(&m->mu);
  expire(m, now);
  if (!make_room(m, result_bytes)) {
    pthread_mutex_unlock(&m->mu);
    free(r);
    return SRV_STORE_FULL;
  }
  r->reserved = result_bytes;
  m->used += result_bytes;
  r->prev = m->last;
  if (m->last)
    m->last->next = r;
  else
    m->first = r;
  m->last = r;
  pthread_mutex_unlock(&m->mu);
  return SRV_STORE_OK;
}

static int m_get(srv_jobstore *s, const char *id, double now,
                 srv_job_view *out) {
  memstore *m = (memstore *)s;
  int rc = SRV_STORE_OK;
  pthread_mutex_lock(&m->mu);
  expire(m, now);
  rec *r = find(m, id);
  if (r)
    view_of(r, now, out);
  else
    rc = lookup_gone(m, id, out);
  pthread_mutex_unlock(&m->mu);
  return rc;
}

static void m_progress(srv_jobstore *s, const char *id, srv_job_state state,
                       size_t done, double now) {
  memstore *m = (memstore *)s;
  (void)now;
  pthread_mutex_lock(&m->mu);
  rec *r = find(m, id);
  if (r && !srv_job_state_final(r->state)) {
    r->state = state;
    r->frames_done = done;
  }
  pthread_mutex_unlock(&m->mu);
}

/* Keep a finished job's result in place of its reservation (lock held).
 * The prediction is an upper bound, so the result fits its own
 * reservation; should it not, older results make room, and a result
 * that fits in no way is not kept. */
static void keep_result(memstore *m, rec *r, api_response *result) {
  size_t len = result->length;
  m->used -= r->reserved;
  r->reserved = 0;
  if (!make_room(m, len)) {
    api_response_free(result);
    r->evicted = true;
    return;
  }
  r->result = srv_result_wrap(result);
  if (r->result == NULL)
    r->evicted = true;
  else
    m->used += len;
}

static void m_finish(srv_jobstore *s, const char *id, srv_job_state state,
                     size_t done, api_response *result, int error_status,
                     const char *error, double now) {
  memstore *m = (memstore *)s;
  pthread_mutex_lock(&m->mu);
  rec *r = find(m, id);
  if (r && !srv_job_state_final(r->state)) {
    r->state = state;
    r->frames_done = done;
    r->finished = now;
    r->error_status = error_status;
    snprintf(r->error, sizeof r->error, "%s", error ? error : "");
    if (result != NULL && state == SRV_JOB_DONE)
      keep_result(m, r, result);
    else
      drop_result(m, r);
  }
  expire(m, now);
  pthread_mutex_unlock(&m->mu);
  if (result != NULL) api_response_free(result);
}

static int m_result(srv_jobstore *s, const char *id, double now,
                    srv_job_view *view, srv_result **out) {
  memstore *m = (memstore *)s;
  int rc = SRV_STORE_OK;
  *out = NULL;
  pthread_mutex_lock(&m->mu);
  expire(m, now);
  rec *r = find(m, id);
  if (r == NULL) {
    rc = lookup_gone(m, id, view);
  } else {
    view_of(r, now, view);
    if (r->evicted) {
      snprintf(view->error, sizeof view->error,
               "the result was evicted to keep job results within "
               "%zu bytes (KMORPH_RESULT_MEMORY); submit the job again",
               m->budget);
      rc = SRV_STORE_GONE;
    } else {
      *out = srv_result_ref(r->result);
    }
  }
  pthread_mutex_unlock(&m->mu);
  return rc;
}

static int m_remove(srv_jobstore *s, const char *id) {
  memstore *m = (memstore *)s;
  pthread_mutex_lock(&m->mu);
  rec *r = find(m, id);
  if (r) unlink_free(m, r, NULL);
  pthread_mutex_unlock(&m->mu);
  return r ? 0 : -1;
}

static void m_counts(srv_jobstore *s, double now, size_t out[SRV_JOB_NSTATES]) {
  memstore *m = (memstore *)s;
  for (int i = 0; i < SRV_JOB_NSTATES; i++) out[i] = 0;
  pthread_mutex_lock(&m->mu);
  expire(m, now);
  for (rec *r = m->first; r; r = r->next) out[r->state]++;
  pthread_mutex_unlock(&m->mu);
}

static size_t m_result_bytes(srv_jobstore *s) {
  memstore *m = (memstore *)s;
  pthread_mutex_lock(&m->mu);
  size_t n = m->used;
  pthread_mutex_unlock(&m->mu);
  return n;
}

static void m_destroy(srv_jobstore *s) {
  memstore *m = (memstore *)s;
  if (m == NULL) return;
  while (m->first) unlink_free(m, m->first, NULL);
  pthread_mutex_destroy(&m->mu);
  free(m->ring);
  free(m);
}

static const srv_jobstore_ops MEM_OPS = {m_create, m_get,          m_progress,
                                         m_finish, m_result,       m_remove,
                                         m_counts, m_result_bytes, m_destroy};

srv_jobstore *srv_jobstore_memory_create(double ttl, size_t keep,
                                         size_t result_budget) {
  memstore *m = calloc(1, sizeof *m);
  if (m == NULL) return NULL;
  /* Room to remember the forgotten for a few generations of kept jobs. */
  m->ring_cap = keep < GONE_RING_MAX / 4 ? 4 * keep + 16 : GONE_RING_MAX;
  m->ring = calloc(m->ring_cap, sizeof *m->ring);
  if (m->ring == NULL) {
    free(m);
    return NULL;
  }
  m->base.ops = &MEM_OPS;
  m->ttl = ttl;
  m->keep = keep;
  m->budget = result_budget;
  pthread_mutex_init(&m->mu, NULL);
  return &m->base;
}
