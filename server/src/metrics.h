/* metrics.h - request counters and latency histograms for GET /metrics
 * (Prometheus text exposition format 0.0.4).
 *
 * Thread-safety: srv_metrics_observe and srv_metrics_render may run on
 * any threads at once.
 */
#ifndef SRV_METRICS_H
#define SRV_METRICS_H

#include <stdbool.h>
#include <stddef.h>

/* Routes as metric labels; a fixed set keeps label cardinality bounded
 * whatever paths clients send. */
typedef enum srv_route {
  SRV_R_INDEX,
  SRV_R_HEALTHZ,
  SRV_R_READYZ,
  SRV_R_METRICS,
  SRV_R_OPENAPI,
  SRV_R_SIGNATURE,
  SRV_R_RECONSTRUCT,
  SRV_R_MORPH,
  SRV_R_JOBS,
  SRV_R_JOB,
  SRV_R_JOB_RESULT,
  SRV_R_STATIC,
  SRV_R_PROBLEM,
  SRV_R_OTHER,
  SRV_R_COUNT
} srv_route;

const char *srv_route_name(srv_route r);

typedef struct srv_metrics srv_metrics;

/* is_allowed(route, method) says which methods a route answers; their
 * request counters are rendered from the start, at zero, for every
 * status in the table (others appear once counted). */
srv_metrics *srv_metrics_create(bool (*is_allowed)(srv_route route,
                                                   const char *method));
void srv_metrics_destroy(srv_metrics *m);

/* Count one answered request: its route, method (GET, HEAD, POST,
 * DELETE, OPTIONS; any other counts as "other") and status. */
void srv_metrics_observe(srv_metrics *m, srv_route route, const char *method,
                         int status, double seconds);

/* Count a request refused to protect the daemon. reason is one of
 * "queue_full", "jobs_full", "body_memory", "result_memory",
 * "connections_full" (admission control), "morph_time", "compute_time"
 * (a synchronous computation stopped at its time limit); any other
 * string counts as "queue_full". */
void srv_metrics_reject(srv_metrics *m, const char *reason);

/* Gauges supplied by the caller at render time. */
typedef struct srv_gauges {
  size_t queue_depth, queue_capacity;
  size_t workers_busy, workers;
  size_t connections;
  size_t body_bytes, result_bytes;  /* memory held in the two budgets */
  size_t late_requests, late_sends; /* connections cut by their deadlines */
  size_t jobs[5];                   /* by srv_job_state */
  const char *const *job_state_names;
  size_t frames_rendered; /* frames of jobs this process rendered */
  const char *extra;      /* more lines in the exposition format, or NULL */
} srv_gauges;

/* Render everything as text; malloc'd, NUL-terminated, caller frees.
 * *len receives the length. NULL if out of memory. */
char *srv_metrics_render(srv_metrics *m, const srv_gauges *g, size_t *len);

#endif
