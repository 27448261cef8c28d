/* jobstore.h - where asynchronous job records live (state, progress,
 * result), behind a small interface.
 *
 * DESIGN: the store holds records only; running a job (its prepared plan,
 * which worker renders which frame) belongs to jobs.c. A store shared by
 * several daemons (e.g. over Redis Streams) can implement the same ops;
 * the in-memory store is the embedded default. Finished records are kept
 * for `ttl` seconds and at most `keep` of them (oldest first out), and
 * their results within a byte budget: a job's predicted result size is
 * reserved when it is created, and finished results are evicted oldest
 * first to make room. A forgotten job (expired, pushed out, evicted) is
 * remembered by id with the reason, so that a client asking for it learns
 * it is gone (410) rather than unknown (404), which would invite it to
 * resubmit blindly. Results are immutable and reference-counted: an answer
 * being sent holds a reference, so neither a slow reader nor an eviction
 * copies or frees a result under another.
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
  int error_status; /* HTTP-style status of the failure, 0 if none */
  char error[256];  /* why it failed, or why it is gone; "" if neither */
  double age;       /* seconds since it was created */
} srv_job_view;

/* An immutable job result shared by the store and the answers being sent
 * from it. */
typedef struct srv_result srv_result;

/* Take over res's body (res is reset). NULL if out of memory (res is
 * then freed). */
srv_result *srv_result_wrap(api_response *res);
/* Another reference / drop one (the last frees it). Accept NULL. */
srv_result *srv_result_ref(srv_result *r);
void srv_result_unref(srv_result *r);
const char *srv_result_body(const srv_result *r);
size_t srv_result_length(const srv_result *r);
int srv_result_status(const srv_result *r);
const char *srv_result_type(const srv_result *r);

/* Lookups of a record that is no longer kept (SRV_STORE_GONE) fill the
 * view's id and error (the reason) only. */
enum {
  SRV_STORE_OK = 0,
  SRV_STORE_UNKNOWN = -1,
  SRV_STORE_GONE = -2,
  SRV_STORE_FULL = -3
};

typedef struct srv_jobstore srv_jobstore;

typedef struct srv_jobstore_ops {
  /* Create a queued record whose result will take at most result_bytes.
   * Returns SRV_STORE_OK, SRV_STORE_FULL when that many bytes cannot be
   * reserved even after evicting every finished result, or -1 if out of
   * memory. */
  int (*create)(srv_jobstore *s, const char *id, size_t frames_total,
                size_t result_bytes, double now);
  /* Copy a record into *out. Returns SRV_STORE_OK, SRV_STORE_UNKNOWN or
   * SRV_STORE_GONE. */
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
  /* Copy the record into *view and, if it is done, give a reference to
   * its result in *out (the caller drops it with srv_result_unref; NULL
   * when not done). Returns as get does. */
  int (*result)(srv_jobstore *s, const char *id, double now, srv_job_view *view,
                srv_result **out);
  /* Forget a record. Returns 0, or -1 if it was unknown. */
  int (*remove)(srv_jobstore *s, const char *id);
  /* Records per state (expired ones dropped first). */
  void (*counts)(srv_jobstore *s, double now, size_t out[SRV_JOB_NSTATES]);
  /* Bytes of results kept and reserved. */
  size_t (*result_bytes)(srv_jobstore *s);
  void (*destroy)(srv_jobstore *s);
} srv_jobstore_ops;

struct srv_jobstore {
  const srv_jobstore_ops *ops;
};

/* The in-memory store: finished records for ttl seconds, at most keep of
 * them, results within result_budget bytes. NULL if out of memory. Free
 * with s->ops->destroy(s). */
srv_jobstore *srv_jobstore_memory_create(double ttl, size_t keep,
                                         size_t result_budget);

#endif
