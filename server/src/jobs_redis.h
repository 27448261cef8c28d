/* jobs_redis.h - asynchronous jobs shared by several kmorphd through Redis
 * (kmorphd --jobs redis://HOST:PORT/DB): records, work and results.
 *
 * DESIGN: a job is a Redis hash kmorph:job:{id} (state, frames done and
 * total, creation and deadline in Unix seconds, the error, the request
 * body and Accept header it was created from), a hash kmorph:frames:{id}
 * of frame texts by frame index, and, once done, kmorph:result:{id}
 * (expires after --job-ttl, as does the record). The set kmorph:live
 * holds the ids of queued and running jobs: its size is the --max-jobs
 * count of every instance together.
 *
 * Work is the stream kmorph:work read through the consumer group
 * "workers": creating a job adds its frames in batches (entries of id,
 * from, to), so the idle workers of every instance take batches of one
 * long job at once (XREADGROUP, one entry per read). A worker prepares
 * the job's plan from the stored request (kept per job id in the
 * instance, so one instance prepares a job once), renders its frames
 * and stores their texts in one script that writes each with HSETNX (a
 * frame written twice counts once), bumps the done count and
 * acknowledges the entry (XACK, XDEL); the worker whose frames make the
 * count reach the total assembles the result in frame order and only
 * then acknowledges its entry. So delivery is at least once: the batches
 * of an instance that dies stay pending and are claimed by another after
 * the visibility timeout (XAUTOCLAIM, tried once a second per instance).
 * An instance that stops gracefully hands the rest of its batches back
 * at once: it adds their unrendered frames as a new entry and
 * acknowledges the old one in one script, so the frames are delivered to
 * another consumer immediately rather than after the timeout (XCLAIM to
 * another consumer would need one that is alive and idle), and never
 * both ways.
 *
 * A job of at most 64 frames, and one whose answer needs every frame of
 * one plan (SVG, animate_d), is a single "solo" batch: one instance
 * renders it and assembles the result from its own plan, storing no
 * frame texts (its progress is written every 0.2 s); stopped gracefully
 * it is handed back whole. Splitting a mid-size job would cost more in
 * preparing it on several instances and moving its frames through Redis
 * than the parallel rendering saves.
 *
 * Cancellation is the record's state: workers read it between frames and
 * at most every 0.2 s from inside a frame (its stop callback), so a
 * DELETE on any instance stops the others within a second.
 *
 * Thread-safety: every function may be called from any thread.
 */
#ifndef SRV_JOBS_REDIS_H
#define SRV_JOBS_REDIS_H

#include <stdbool.h>
#include <stddef.h>

#include "jobstore.h"
#include "kmapi/api.h"
#include "redis_conn.h"

typedef struct srv_rjobs srv_rjobs;

typedef struct srv_rjobs_config {
  api_config api;        /* limits for preparing stored requests */
  size_t max_job_frames; /* frames per job */
  size_t max_jobs;       /* queued + running jobs of all instances */
  double job_time;       /* wall seconds per job */
  double job_ttl;        /* seconds a finished job and result are kept */
  double visibility;     /* seconds before a pending batch is reclaimed */
} srv_rjobs_config;

/* What srv_rjobs_* answer besides SRV_STORE_OK/UNKNOWN/GONE. */
enum { SRV_RJOBS_FULL = -10, SRV_RJOBS_DOWN = -11, SRV_RJOBS_NOMEM = -12 };

/* A runner over rd (borrowed, must outlive it). NULL if out of memory. */
srv_rjobs *srv_rjobs_create(srv_redis *rd, const srv_rjobs_config *cfg);

/* Store a queued job made from body (len bytes) and accept (may be NULL),
 * which plan (prepared from them; taken in every case) renders, and add
 * its batches. id (out, SRV_JOB_ID_LEN hex + NUL) on success. Returns 0,
 * SRV_RJOBS_FULL (max_jobs live), SRV_RJOBS_DOWN (Redis unreachable) or
 * SRV_RJOBS_NOMEM. */
int srv_rjobs_start(srv_rjobs *j, const char *body, size_t len,
                    const char *accept, api_morph_plan *plan,
                    char id[SRV_JOB_ID_LEN + 1]);

/* The record of id into *out. Returns SRV_STORE_OK, SRV_STORE_UNKNOWN or
 * SRV_RJOBS_DOWN. */
int srv_rjobs_get(srv_rjobs *j, const char *id, srv_job_view *out);

/* As srv_rjobs_get, and for a done job its result in *out (the caller
 * drops it with srv_result_unref; NULL when not done). SRV_STORE_GONE if
 * the result expired. */
int srv_rjobs_result(srv_rjobs *j, const char *id, srv_job_view *view,
                     srv_result **out);

/* DELETE: cancel a live job, or forget a final one. Returns 0,
 * SRV_STORE_UNKNOWN or SRV_RJOBS_DOWN. */
int srv_rjobs_delete(srv_rjobs *j, const char *id);

/* Render one batch (the pool's srv_idle_fn; ctx is the runner). False
 * when there is none or Redis is unreachable. */
bool srv_rjobs_work(void *ctx);

/* Between two frames of a batch, workers call yield(ctx) until it
 * returns false (e.g. srv_pool_run_queued: requests waiting for a worker
 * are not held back by a batch). Set before the workers start. */
void srv_rjobs_set_yield(srv_rjobs *j, bool (*yield)(void *), void *ctx);

/* Graceful stop: workers take no more batches and hand back the frames
 * of the ones they hold at their next frame boundary. */
void srv_rjobs_stop(srv_rjobs *j);

/* Batches being rendered by this instance now. */
size_t srv_rjobs_busy(srv_rjobs *j);

/* After the workers have stopped: hand back every batch still pending
 * for this instance. Returns how many. */
size_t srv_rjobs_hand_back_all(srv_rjobs *j);

/* True if Redis answers now (for /readyz). */
bool srv_rjobs_ready(srv_rjobs *j);
/* True if Redis answered the last command (cheap). */
bool srv_rjobs_up(srv_rjobs *j);

/* Prometheus lines of the runner (frames rendered, stream lag, pending
 * and reclaimed batches) appended to buf (cap bytes, NUL-terminated). */
void srv_rjobs_metrics(srv_rjobs *j, char *buf, size_t cap);

/* Free the runner and its cached plans; workers must be stopped.
 * Accepts NULL. */
void srv_rjobs_destroy(srv_rjobs *j);

#endif
