/* jobs.h - runs asynchronous whole-sequence morphs over the compute pool.
 *
 * DESIGN: a job is a prepared morph plan (api_morph_prepare, done on a
 * worker by the request that created it) plus a frame cursor. Idle workers
 * call srv_jobs_work, which takes the next frame of the oldest live job
 * and renders it, so the frames of one job spread over all workers and
 * progress is frames done / frames total. Cancellation and the wall-time
 * limit are checked between frames and, through the frame's stop
 * callback, inside a frame's computation; the last frame to finish assembles
 * the result (api_morph_result) and hands it to the job store.
 *
 * Thread-safety: all functions may be called from any thread.
 */
#ifndef SRV_JOBS_H
#define SRV_JOBS_H

#include <stdbool.h>
#include <stddef.h>

#include "jobstore.h"
#include "kmapi/api.h"

typedef struct srv_jobs srv_jobs;

/* store is borrowed (must outlive the runner). max_active bounds queued +
 * running jobs; job_time is the wall-time limit per job in seconds. */
srv_jobs *srv_jobs_create(srv_jobstore *store, size_t max_active,
                          double job_time);

/* True when no further job would be admitted now. */
bool srv_jobs_full(srv_jobs *j);

/* Admit a prepared plan: on success (0) the runner owns plan and id
 * (SRV_JOB_ID_LEN hex digits + NUL) names the new queued job. deadline
 * (srv_now() seconds) is when the job fails for lack of time: the
 * request's start plus the job time limit, so that preparing counts.
 * result_bytes is the predicted size of its result, reserved in the
 * store. Returns -1 when max_active jobs are live, -2 when out of
 * memory, -3 after srv_jobs_cancel_all (shutting down), -4 when the
 * store cannot reserve result_bytes; then the caller still owns plan.
 * The caller kicks the pool afterwards. */
int srv_jobs_start(srv_jobs *j, api_morph_plan *plan, double deadline,
                   size_t result_bytes, char id[SRV_JOB_ID_LEN + 1]);

/* Seconds a job may take (the limit srv_jobs_create was given). */
double srv_jobs_time_limit(const srv_jobs *j);

/* Render one frame of some live job. Returns false when there is no frame
 * to render (the pool's srv_idle_fn; ctx is the srv_jobs). */
bool srv_jobs_work(void *ctx);

/* Cancel a live job: it is recorded as cancelled at once and no further
 * frame starts. Returns 0, or -1 if the job is not live (unknown or
 * already final). */
int srv_jobs_cancel(srv_jobs *j, const char *id);

/* Cancel every live job and admit no more (shutdown). */
void srv_jobs_cancel_all(srv_jobs *j);

/* Frames rendered so far (for /metrics). */
size_t srv_jobs_frames_rendered(srv_jobs *j);

/* Jobs whose plan is still held (live, or finishing in-flight frames). */
size_t srv_jobs_live(srv_jobs *j);

/* Free the runner and any plans still held; workers must be stopped.
 * Accepts NULL. */
void srv_jobs_destroy(srv_jobs *j);

#endif
