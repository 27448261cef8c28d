/* jobs.c - frame scheduling, cancellation and wall time of asynchronous
 * jobs (see jobs.h). */
#include "jobs.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "log.h"
#include "util.h"

typedef struct job {
  struct job *next;
  char id[SRV_JOB_ID_LEN + 1];
  api_morph_plan *plan;
  size_t total, next_frame, done, in_flight;
  bool started, cancelled, failed, finishing;
  atomic_bool stop; /* cancelled or failed: frames in flight give up */
  int fail_status;
  char fail_msg[200];
  double deadline;
} job;

struct srv_jobs {
  pthread_mutex_t mu;
  job *first; /* creation order: the oldest live job is served first */
  size_t live;
  size_t max_active;
  double job_time;
  bool closed;          /* shutting down: no new jobs */
  atomic_size_t frames; /* frames rendered, for /metrics */
  srv_jobstore *store;
};

srv_jobs *srv_jobs_create(srv_jobstore *store, size_t max_active,
                          double job_time) {
  srv_jobs *j = calloc(1, sizeof *j);
  if (j == NULL) return NULL;
  pthread_mutex_init(&j->mu, NULL);
  atomic_init(&j->frames, 0);
  j->store = store;
  j->max_active = max_active;
  j->job_time = job_time;
  return j;
}

/* Live = admitted and not yet final (cancelled or failed jobs that still
 * have frames in flight no longer count against the admission limit). */
static size_t count_active(const srv_jobs *j) {
  size_t n = 0;
  for (const job *p = j->first; p; p = p->next)
    if (!p->cancelled && !p->failed) n++;
  return n;
}

bool srv_jobs_full(srv_jobs *j) {
  pthread_mutex_lock(&j->mu);
  bool full = count_active(j) >= j->max_active;
  pthread_mutex_unlock(&j->mu);
  return full;
}

double srv_jobs_time_limit(const srv_jobs *j) {
  return j->job_time;
}

int srv_jobs_start(srv_jobs *j, api_morph_plan *plan, double deadline,
                   size_t result_bytes, char id[SRV_JOB_ID_LEN + 1]) {
  job *nj = calloc(1, sizeof *nj);
  if (nj == NULL) return -2;
  srv_random_hex(nj->id, SRV_JOB_ID_LEN);
  nj->plan = plan;
  nj->total = api_morph_frame_count(plan);
  atomic_init(&nj->stop, false);
  double now = srv_now();
  nj->deadline = deadline;
  pthread_mutex_lock(&j->mu);
  if (j->closed || count_active(j) >= j->max_active) {
    int rc = j->closed ? -3 : -1;
    pthread_mutex_unlock(&j->mu);
    free(nj);
    return rc;
  }
  int st =
      j->store->ops->create(j->store, nj->id, nj->total, result_bytes, now);
  if (st != SRV_STORE_OK) {
    pthread_mutex_unlock(&j->mu);
    free(nj);
    return st == SRV_STORE_FULL ? -4 : -2;
  }
  job **tail = &j->first;
  while (*tail) tail = &(*tail)->next;
  *tail = nj;
  j->live++;
  /* Copied under the lock: once it is released a worker may render every
   * frame, finalize the job and free nj before this thread runs again. */
  memcpy(id, nj->id, SRV_JOB_ID_LEN + 1);
  pthread_mutex_unlock(&j->mu);
  return 0;
}

static void unlink_job(srv_jobs *j, job *x) {
  for (job **pp = &j->first; *pp; pp = &(*pp)->next)
    if (*pp == x) {
      *pp = x->next;
      break;
    }
  j->live--;
}

/* Mark a job failed (lock held); the store learns at once. */
static void fail_locked(srv_jobs *j, job *x, int status, const char *msg,
                        double now) {
  if (x->failed || x->cancelled) return;
  x->failed = true;
  atomic_store(&x->stop, true);
  x->fail_status = status;
  snprintf(x->fail_msg, sizeof x->fail_msg, "%s", msg);
  j->store->ops->finish(j->store, x->id, SRV_JOB_FAILED, x->done, NULL, status,
                        x->fail_msg, now);
}

static void out_of_time_locked(srv_jobs *j, job *x, double now) {
  char msg[160];
  snprintf(msg, sizeof msg,
           "the job ran out of time: wall-time limit %g s "
           "(KMORPH_JOB_TIME) reached after %zu of %zu frames",
           j->job_time, x->done, x->total);
  fail_locked(j, x, 503, msg, now);
}

/* A frame's stop condition, polled inside its computation: the job was
 * cancelled or failed, or its time is up. Reads no lock-guarded field. */
static bool job_should_stop(void *ctx) {
  job *x = ctx;
  return atomic_load(&x->stop) || srv_now() > x->deadline;
}

/* If nothing of x is in flight and it needs no more frames, take it off
 * the list (lock held); the caller then calls finalize outside the lock. */
static bool take_if_over(srv_jobs *j, job *x) {
  if (x->finishing || x->in_flight > 0) return false;
  if (!(x->cancelled || x->failed || x->done == x->total)) return false;
  x->finishing = true;
  unlink_job(j, x);
  return true;
}

/* Assemble the result of a completed job, or just drop a cancelled or
 * failed one (its final record was written when it stopped). */
static void finalize(srv_jobs *j, job *x) {
  if (!x->cancelled && !x->failed) {
    api_response res;
    api_response_init(&res);
    int rc = api_morph_result(x->plan, &res);
    double now = srv_now();
    if (rc >= 200 && rc < 300 && res.body != NULL) {
      j->store->ops->finish(j->store, x->id, SRV_JOB_DONE, x->done, &res, 0,
                            NULL, now);
    } else {
      api_response_free(&res);
      char msg[96];
      snprintf(msg, sizeof msg, "the result could not be assembled (%d)", rc);
      j->store->ops->finish(j->store, x->id, SRV_JOB_FAILED, x->done, NULL,
                            rc >= 400 ? rc : 500, msg, now);
    }
  }
  api_morph_plan_free(x->plan);
  free(x);
}

bool srv_jobs_work(void *ctx) {
  srv_jobs *j = ctx;
  job *x = NULL, *over = NULL;
  size_t i = 0;
  double now = srv_now();
  pthread_mutex_lock(&j->mu);
  for (job *p = j->first; p; p = p->next) {
    if (p->cancelled || p->failed || p->next_frame >= p->total) continue;
    if (now > p->deadline) {
      out_of_time_locked(j, p, now);
      if (take_if_over(j, p)) {
        over = p;
        break;
      }
      continue;
    }
    x = p;
    break;
  }
  if (x != NULL) {
    i = x->next_frame++;
    x->in_flight++;
    if (!x->started) {
      x->started = true;
      j->store->ops->progress(j->store, x->id, SRV_JOB_RUNNING, x->done, now);
    }
  }
  pthread_mutex_unlock(&j->mu);
  if (over != NULL) {
    finalize(j, over);
    return true;
  }
  if (x == NULL) return false;

  int rc = api_morph_render_frame_until(x->plan, i, job_should_stop, x);

  now = srv_now();
  pthread_mutex_lock(&j->mu);
  x->in_flight--;
  if (rc == 0) {
    atomic_fetch_add_explicit(&j->frames, 1, memory_order_relaxed);
    x->done++;
    if (!x->cancelled && !x->failed)
      j->store->ops->progress(j->store, x->id, SRV_JOB_RUNNING, x->done, now);
  } else if (x->cancelled || x->failed) {
    /* stopped because it was cancelled or failed meanwhile */
  } else if (now > x->deadline) {
    out_of_time_locked(j, x, now);
  } else {
    char msg[96];
    snprintf(msg, sizeof msg, "frame %zu could not be built", i);
    fail_locked(j, x, rc >= 400 ? rc : 422, msg, now);
  }
  bool take = take_if_over(j, x);
  pthread_mutex_unlock(&j->mu);
  if (take) finalize(j, x);
  return true;
}

static void cancel_locked(srv_jobs *j, job *x, double now) {
  if (x->cancelled || x->failed || x->finishing) return;
  x->cancelled = true;
  atomic_store(&x->stop, true);
  j->store->ops->finish(j->store, x->id, SRV_JOB_CANCELLED, x->done, NULL, 0,
                        NULL, now);
}

int srv_jobs_cancel(srv_jobs *j, const char *id) {
  job *take = NULL;
  int rc = -1;
  pthread_mutex_lock(&j->mu);
  for (job *p = j->first; p; p = p->next) {
    if (strcmp(p->id, id) != 0) continue;
    if (!p->cancelled && !p->failed && !p->finishing && p->done < p->total) {
      cancel_locked(j, p, srv_now());
      rc = 0;
      if (take_if_over(j, p)) take = p;
    }
    break;
  }
  pthread_mutex_unlock(&j->mu);
  if (take) finalize(j, take);
  return rc;
}

void srv_jobs_cancel_all(srv_jobs *j) {
  job *done_list = NULL;
  double now = srv_now();
  pthread_mutex_lock(&j->mu);
  j->closed = true;
  job *next;
  for (job *p = j->first; p; p = next) {
    next = p->next;
    if (p->done < p->total && !p->cancelled && !p->failed && !p->finishing) {
      /* one line per job, so every accepted job is accounted for */
      srv_log_notice(stderr,
                     "kmorphd: job %s cancelled by shutdown (%zu/%zu frames)\n",
                     p->id, p->done, p->total);
      cancel_locked(j, p, now);
    }
    if (take_if_over(j, p)) {
      p->next = done_list;
      done_list = p;
    }
  }
  pthread_mutex_unlock(&j->mu);
  while (done_list) {
    job *p = done_list;
    done_list = p->next;
    finalize(j, p);
  }
}

size_t srv_jobs_frames_rendered(srv_jobs *j) {
  return atomic_load_explicit(&j->frames, memory_order_relaxed);
}

size_t srv_jobs_live(srv_jobs *j) {
  pthread_mutex_lock(&j->mu);
  size_t n = j->live;
  pthread_mutex_unlock(&j->mu);
  return n;
}

void srv_jobs_destroy(srv_jobs *j) {
  if (j == NULL) return;
  while (j->first) {
    job *p = j->first;
    j->first = p->next;
    api_morph_plan_free(p->plan);
    free(p);
  }
  pthread_mutex_destroy(&j->mu);
  free(j);
}
