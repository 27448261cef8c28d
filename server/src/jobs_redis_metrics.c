/* jobs_redis_metrics.c - the Prometheus lines of the shared job runner
 * (see jobs_redis.h): frames rendered, Redis reachable, stream lag,
 * pending, reclaimed and handed-back batches. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "jobs_redis_internal.h"

/* Add stream's length, its group's pending count and this consumer's
 * to the sums. */
static void count_stream(srv_rjobs *j, redisContext *c, bool *broken,
                         const char *stream, long long *len, long long *pending,
                         long long *mine) {
  redisReply *rep = srv__rj_cmd(c, broken, "XLEN %s", stream);
  if (rep && rep->type == REDIS_REPLY_INTEGER) *len += rep->integer;
  if (rep) freeReplyObject(rep);
  rep = *broken ? NULL
                : srv__rj_cmd(c, broken, "XPENDING %s %s", stream, RJ_GROUP);
  if (rep && rep->type == REDIS_REPLY_ARRAY && rep->elements == 4) {
    *pending += rep->element[0]->integer;
    const redisReply *per = rep->element[3];
    if (per->type == REDIS_REPLY_ARRAY)
      for (size_t k = 0; k < per->elements; k++) {
        const redisReply *e = per->element[k];
        if (e->type == REDIS_REPLY_ARRAY && e->elements == 2 &&
            strcmp(e->element[0]->str, j->consumer) == 0)
          *mine += strtoll(e->element[1]->str, NULL, 10);
      }
  }
  if (rep) freeReplyObject(rep);
}

/* Over every work stream known (the shared one and each instance's):
 * entries, pending ones, pending for this consumer. False if Redis did
 * not answer. */
static bool stream_counts(srv_rjobs *j, long long *len, long long *pending,
                          long long *mine) {
  char(*names)[RJ_KEY_MAX] = malloc(RJ_STREAMS_MAX * sizeof *names);
  if (names == NULL) return false;
  pthread_mutex_lock(&j->mu);
  size_t n = j->nstreams;
  memcpy(names, j->streams, n * sizeof *names);
  pthread_mutex_unlock(&j->mu);
  if (n == 0) {
    snprintf(names[0], RJ_KEY_MAX, "%s", RJ_STREAM);
    snprintf(names[1], RJ_KEY_MAX, "%s", j->local);
    n = 2;
  }
  redisContext *c = srv_redis_acquire(j->rd);
  bool broken = c == NULL;
  *len = *pending = *mine = 0;
  for (size_t k = 0; k < n && !broken; k++)
    count_stream(j, c, &broken, names[k], len, pending, mine);
  srv_redis_release(j->rd, c, broken);
  free(names);
  return !broken;
}

void srv_rjobs_metrics(srv_rjobs *j, char *buf, size_t cap) {
  long long len = 0, pending = 0, mine = 0;
  bool up = stream_counts(j, &len, &pending, &mine);
  /* Acknowledged batches are deleted, so the stream holds the batches
   * not yet delivered plus the pending ones. */
  long long lag = len - pending > 0 ? len - pending : 0;
  snprintf(buf, cap,
           "# HELP kmorph_job_frames_rendered_total Frames of jobs rendered by "
           "this instance.\n"
           "# TYPE kmorph_job_frames_rendered_total counter\n"
           "kmorph_job_frames_rendered_total %zu\n"
           "# HELP kmorph_redis_up Whether Redis (--jobs) answered now.\n"
           "# TYPE kmorph_redis_up gauge\n"
           "kmorph_redis_up %d\n"
           "# HELP kmorph_jobs_stream_lag Batches in the work stream not yet "
           "delivered to any instance.\n"
           "# TYPE kmorph_jobs_stream_lag gauge\n"
           "kmorph_jobs_stream_lag %lld\n"
           "# HELP kmorph_jobs_pending_batches Batches delivered and not yet "
           "acknowledged: by every instance, by this one.\n"
           "# TYPE kmorph_jobs_pending_batches gauge\n"
           "kmorph_jobs_pending_batches{consumer=\"all\"} %lld\n"
           "kmorph_jobs_pending_batches{consumer=\"self\"} %lld\n"
           "# HELP kmorph_jobs_reclaimed_batches_total Batches this instance "
           "claimed from an instance silent past the visibility timeout.\n"
           "# TYPE kmorph_jobs_reclaimed_batches_total counter\n"
           "kmorph_jobs_reclaimed_batches_total %zu\n"
           "# HELP kmorph_jobs_handed_back_batches_total Batches this instance "
           "handed back unfinished when stopping.\n"
           "# TYPE kmorph_jobs_handed_back_batches_total counter\n"
           "kmorph_jobs_handed_back_batches_total %zu\n"
           "# HELP kmorph_jobs_assembled_total Job results this instance "
           "assembled.\n"
           "# TYPE kmorph_jobs_assembled_total counter\n"
           "kmorph_jobs_assembled_total %zu\n"
           "# HELP kmorph_jobs_plans_prepared_total Plans this instance "
           "prepared again from a job's stored request (it had none).\n"
           "# TYPE kmorph_jobs_plans_prepared_total counter\n"
           "kmorph_jobs_plans_prepared_total %zu\n",
           (size_t)atomic_load(&j->frames), up ? 1 : 0, lag, pending, mine,
           (size_t)atomic_load(&j->reclaimed), (size_t)atomic_load(&j->handed),
           (size_t)atomic_load(&j->assembled),
           (size_t)atomic_load(&j->prepared));
}
