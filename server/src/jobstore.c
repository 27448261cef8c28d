/* jobstore.c - the in-memory job store (see jobstore.h).
 *
 * DESIGN: a doubly linked list in creation order under one mutex. The job
 * count is bounded by the daemon's admission limit plus `keep`, so linear
 * lookups stay cheap; expiry is lazy (done on every access) so no timer
 * thread is needed.
 */
#include "jobstore.h"

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct rec {
  struct rec *prev, *next;
  char id[SRV_JOB_ID_LEN + 1];
  srv_job_state state;
  size_t frames_done, frames_total;
  int error_status;
  char error[256];
  double created, finished;
  api_response result;
} rec;

typedef struct memstore {
  srv_jobstore base;
  pthread_mutex_t mu;
  rec *first, *last;
  double ttl;
  size_t keep;
} memstore;

static const char *const STATE_NAMES[SRV_JOB_NSTATES] = {
    "queued", "running", "done", "failed", "cancelled"};

const char *srv_job_state_name(srv_job_state s)
{
  return (unsigned)s < SRV_JOB_NSTATES ? STATE_NAMES[s] : "unknown";
}

bool srv_job_state_final(srv_job_state s)
{
  return s == SRV_JOB_DONE || s == SRV_JOB_FAILED || s == SRV_JOB_CANCELLED;
}

static void unlink_free(memstore *m, rec *r)
{
  if (r->prev)
    r->prev->next = r->next;
  else
    m->first = r->next;
  if (r->next)
    r->next->prev = r->prev;
  else
    m->last = r->prev;
  api_response_free(&r->result);
  free(r);
}

/* Drop finished records older than ttl, then the oldest finished ones
 * beyond keep. Called with the lock held. */
static void expire(memstore *m, double now)
{
  size_t finished = 0;
  rec *next;
  for (rec *r = m->first; r; r = next) {
    next = r->next;
    if (!srv_job_state_final(r->state))
      continue;
    if (now - r->finished >= m->ttl)
      unlink_free(m, r);
    else
      finished++;
  }
  for (rec *r = m->first; r && finished > m->keep; r = next) {
    next = r->next;
    if (srv_job_state_final(r->state)) {
      unlink_free(m, r);
      finished--;
    }
  }
}

static rec *find(memstore *m, const char *id)
{
  for (rec *r = m->first; r; r = r->next)
    if (strcmp(r->id, id) == 0)
      return r;
  return NULL;
}

static void view_of(const rec *r, double now, srv_job_view *v)
{
  memcpy(v->id, r->id, sizeof v->id);
  v->state = r->state;
  v->frames_done = r->frames_done;
  v->frames_total = r->frames_total;
  v->error_status = r->error_status;
  memcpy(v->error, r->error, sizeof v->error);
  v->age = now - r->created;
}

static int m_create(srv_jobstore *s, const char *id, size_t total, double now)
{
  memstore *m = (memstore *)s;
  rec *r = calloc(1, sizeof *r);
  if (r == NULL)
    return -1;
  snprintf(r->id, sizeof r->id, "%s", id);
  r->state = SRV_JOB_QUEUED;
  r->frames_total = total;
  r->created = now;
  api_response_init(&r->result);
  pthread_mutex_lock(&m->mu);
  expire(m, now);
  r->prev = m->last;
  if (m->last)
    m->last->next = r;
  else
    m->first = r;
  m->last = r;
  pthread_mutex_unlock(&m->mu);
  return 0;
}

static int m_get(srv_jobstore *s, const char *id, double now,
                 srv_job_view *out)
{
  memstore *m = (memstore *)s;
  pthread_mutex_lock(&m->mu);
  expire(m, now);
  rec *r = find(m, id);
  if (r)
    view_of(r, now, out);
  pthread_mutex_unlock(&m->mu);
  return r ? 0 : -1;
}

static void m_progress(srv_jobstore *s, const char *id, srv_job_state state,
                       size_t done, double now)
{
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

static void m_finish(srv_jobstore *s, const char *id, srv_job_state state,
                     size_t done, api_response *result, int error_status,
                     const char *error, double now)
{
  memstore *m = (memstore *)s;
  pthread_mutex_lock(&m->mu);
  rec *r = find(m, id);
  if (r && !srv_job_state_final(r->state)) {
    r->state = state;
    r->frames_done = done;
    r->finished = now;
    r->error_status = error_status;
    snprintf(r->error, sizeof r->error, "%s", error ? error : "");
    if (result != NULL && state == SRV_JOB_DONE) {
      r->result = *result;
      api_response_init(result);
    }
  }
  expire(m, now);
  pthread_mutex_unlock(&m->mu);
  if (result != NULL)
    api_response_free(result);
}

static int m_result(srv_jobstore *s, const char *id, double now,
                    srv_job_view *view, api_response *out)
{
  memstore *m = (memstore *)s;
  int rc = -1;
  pthread_mutex_lock(&m->mu);
  expire(m, now);
  rec *r = find(m, id);
  if (r) {
    view_of(r, now, view);
    rc = 0;
    if (r->state == SRV_JOB_DONE && r->result.body != NULL) {
      char *copy = malloc(r->result.length + 1);
      if (copy == NULL) {
        rc = -1;
      } else {
        memcpy(copy, r->result.body, r->result.length + 1);
        out->status = r->result.status;
        out->content_type = r->result.content_type;
        out->body = copy;
        out->length = r->result.length;
      }
    }
  }
  pthread_mutex_unlock(&m->mu);
  return rc;
}

static int m_remove(srv_jobstore *s, const char *id)
{
  memstore *m = (memstore *)s;
  pthread_mutex_lock(&m->mu);
  rec *r = find(m, id);
  if (r)
    unlink_free(m, r);
  pthread_mutex_unlock(&m->mu);
  return r ? 0 : -1;
}

static void m_counts(srv_jobstore *s, double now,
                     size_t out[SRV_JOB_NSTATES])
{
  memstore *m = (memstore *)s;
  for (int i = 0; i < SRV_JOB_NSTATES; i++)
    out[i] = 0;
  pthread_mutex_lock(&m->mu);
  expire(m, now);
  for (rec *r = m->first; r; r = r->next)
    out[r->state]++;
  pthread_mutex_unlock(&m->mu);
}

static void m_destroy(srv_jobstore *s)
{
  memstore *m = (memstore *)s;
  if (m == NULL)
    return;
  while (m->first)
    unlink_free(m, m->first);
  pthread_mutex_destroy(&m->mu);
  free(m);
}

static const srv_jobstore_ops MEM_OPS = {
    m_create, m_get,    m_progress, m_finish,
    m_result, m_remove, m_counts,   m_destroy};

srv_jobstore *srv_jobstore_memory_create(double ttl, size_t keep)
{
  memstore *m = calloc(1, sizeof *m);
  if (m == NULL)
    return NULL;
  m->base.ops = &MEM_OPS;
  m->ttl = ttl;
  m->keep = keep;
  pthread_mutex_init(&m->mu, NULL);
  return &m->base;
}
