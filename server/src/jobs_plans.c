/* jobs_plans.c - the prepared plans of shared jobs kept per instance
 * (see jobs_redis.h): prepared once from the stored request, shared by
 * this instance's workers, freed least recently used first. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "jobs_redis_internal.h"
#include "util.h"

/* Plans kept per instance; unused ones beyond this are freed, oldest
 * first (a later batch of the job prepares it again). An instance keeps
 * the plan of every job it accepted until it renders it (the job's solo
 * batch waits in its own stream), so this is about the backlog of jobs
 * one instance holds: 16 made 3 in 4 of 200 queued jobs be prepared
 * twice. A plan not rendered yet is small; rendered frames are freed
 * with the plan when this instance sees its job end. */
#define PLANS_MAX 256

/* Free unused plans beyond PLANS_MAX, least recently used first (mu
 * held). */
static void evict_locked(srv_rjobs *j) {
  while (j->nplans > PLANS_MAX) {
    rj_plan **victim = NULL;
    for (rj_plan **pp = &j->plans; *pp; pp = &(*pp)->next)
      if ((*pp)->refs == 0 && (victim == NULL || (*pp)->used < (*victim)->used))
        victim = pp;
    if (victim == NULL) return;
    rj_plan *v = *victim;
    *victim = v->next;
    j->nplans--;
    api_morph_plan_free(v->plan);
    free(v);
  }
}

void srv__rj_cache_put(srv_rjobs *j, const char *id, api_morph_plan *plan) {
  rj_plan *e = calloc(1, sizeof *e);
  if (e == NULL) {
    api_morph_plan_free(plan);
    return;
  }
  memcpy(e->id, id, SRV_JOB_ID_LEN + 1);
  e->plan = plan;
  e->used = srv_now();
  pthread_mutex_lock(&j->mu);
  e->next = j->plans;
  j->plans = e;
  j->nplans++;
  evict_locked(j);
  pthread_mutex_unlock(&j->mu);
}

void srv__rj_cache_drop(srv_rjobs *j, const char *id) {
  rj_plan *v = NULL;
  pthread_mutex_lock(&j->mu);
  for (rj_plan **pp = &j->plans; *pp; pp = &(*pp)->next)
    if (strcmp((*pp)->id, id) == 0) {
      if ((*pp)->refs == 0) {
        v = *pp;
        *pp = v->next;
        j->nplans--;
      }
      break;
    }
  pthread_mutex_unlock(&j->mu);
  if (v) {
    api_morph_plan_free(v->plan);
    free(v);
  }
}

static rj_plan *cache_find_locked(srv_rjobs *j, const char *id) {
  for (rj_plan *p = j->plans; p; p = p->next)
    if (strcmp(p->id, id) == 0) return p;
  return NULL;
}

/* Job id's cached plan with a reference held, or NULL. */
rj_plan *srv__rj_cache_ref(srv_rjobs *j, const char *id) {
  pthread_mutex_lock(&j->mu);
  rj_plan *p = cache_find_locked(j, id);
  if (p) {
    p->refs++;
    p->used = srv_now();
  }
  pthread_mutex_unlock(&j->mu);
  return p;
}

/* Job id's plan prepared from its stored request (body of len bytes,
 * accept "" for none), cached, with a reference held. NULL with the
 * problem's status in *status and the reason in why if it cannot be
 * prepared. */
rj_plan *srv__rj_cache_prepare(srv_rjobs *j, const char *id, const char *body,
                               size_t len, const char *accept, int *status,
                               char *why, size_t whycap) {
  api_request req = {.route = API_ROUTE_MORPH,
                     .body = body,
                     .length = len,
                     .accept = accept[0] ? accept : NULL};
  api_morph_plan *plan = NULL;
  api_response err;
  int rc =
      api_morph_prepare(&j->cfg.api, &req, j->cfg.max_job_frames, &plan, &err);
  api_response_free(&err);
  if (rc != 0 || plan == NULL) {
    *status = rc >= 400 ? rc : 500;
    snprintf(why, whycap, "the stored request could not be prepared again (%d)",
             rc);
    return NULL;
  }
  atomic_fetch_add(&j->prepared, 1);
  srv__rj_cache_put(j, id, plan);
  rj_plan *p = srv__rj_cache_ref(j, id);
  if (p == NULL) *status = 503, snprintf(why, whycap, "out of memory");
  return p;
}

void srv__rj_cache_release(srv_rjobs *j, rj_plan *p) {
  pthread_mutex_lock(&j->mu);
  p->refs--;
  evict_locked(j);
  pthread_mutex_unlock(&j->mu);
}
