/* jobstore.h - where asynchronous job records live (state, progress,
 * result), behind a small interface.
 *
 * DESIGN: the store holds records only; running a job (its prepared plan,
 * which worker renders which frame) belongs to jobs.c. A store shared by
 * several daemons (e.g. over Redis Streams) can implement the same ops;
 * the in-memory store is the embedded default. Finished records are kept
 * for `ttl` seconds and at most `keep` of them (oldest first out); after
 * that they are forgotten and lookups say "not found".
 *
 * Thread-safety: every op may be called from any thread at once.
 * Times are srv_now() seconds.
 */
#ifndef SRV_JOBSTORE_H
#define SRV_JOBSTORE_H

#include <stdbool.h>
#include <stddef.h>

#include "kmapi/api.h"

typedef enum srv_job_state {
  SRV_JOB_QUEUED,
  SRV_JOB_RUNNING,
  SRV_JOB_DONE,
  SRV_JOB_FAILED,
  SRV_JOB_CANCELLED,
  SRV_JOB_NSTATES
} srv_job_state;

#define SRV_JOB_ID_LEN 32

/* "queued", "running", ... as in the API. */
const char *srv_job_state_name(srv_job_state s);
bool srv_job_state_final(srv_job_state s);

/* A copy of one record (no pointers into the store). */
typedef struct srv_job_view {
  char id[SRV_JOB_ID_LEN + 1];
  srv_job_state state;
  size_t frames_done, frames_total;
  int error_status;  /* HTTP-style status of the failure, 0 if none */
  char error[256];   /* why it failed, "" if it did not */
  double age;        /* seconds since it was created */
} srv_job_view;

typedef struct srv_jobstore srv_jobstore;

typedef struct srv_jobstore_ops {
  /* Create a queued record. Returns 0, or -1 if out of memory. */
  int (*create)(srv_jobstore *s, const char *id, size_t frames_total,
                double now);
  /* Copy a record into *out. Returns 0, or -1 if unknown or expired. */
  int (*get)(srv_jobstore *s, const char *id, double now, srv_job_view *out);
  /* Record progress of a live job (queued -> running). Ignored once the
   * record is final. */
  void (*progress)(srv_jobstore *s, const char *id, srv_job_state state,
                   size_t frames_done, double now);
  /* Make the record final. For SRV_JOB_DONE, *result is moved into the
   * store (its body is owned by the store afterwards; *result is reset).
   * error may be NULL. Ignored (result freed) if already final. */
  void (*finish)(srv_jobstore *s, const char *id, srv_job_state state,
                 size_t frames_done, api_response *result, int error_status,
                 const char *error, double now);
  /* Copy the record into *view and, if it is done, its result into *out
   * (a malloc'd copy the caller frees with api_response_free). Returns 0,
   * or -1 if unknown/expired or out of memory. */
  int (*result)(srv_jobstore *s, const char *id, double now,
                srv_job_view *view, api_response *out);
  /* Forget a record. Returns 0, or -1 if it was unknown. */
  int (*remove)(srv_jobstore *s, const char *id);
  /* Records per state (expired ones dropped first). */
  void (*counts)(srv_jobstore *s, double now, size_t out[SRV_JOB_NSTATES]);
  void (*destroy)(srv_jobstore *s);
} srv_jobstore_ops;

struct srv_jobstore {
  const srv_jobstore_ops *ops;
};

/* The in-memory store. NULL if out of memory. Free with
 * s->ops->destroy(s). */
srv_jobstore *srv_jobstore_memory_create(double ttl, size_t keep);

#endif
