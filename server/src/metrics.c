/* metrics.c - counters and histograms behind GET /metrics.
 *
 * DESIGN: fixed arrays indexed by route and by a small status table, under
 * one mutex held for a few increments; rendering copies nothing big. The
 * status table names every status the daemon can answer; anything else
 * is counted as "other" so the label set stays finite.
 */
#include "metrics.h"

#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The build passes the tree's VERSION; a stray compile without it still
 * says something true. */
#ifndef KMORPH_VERSION
#define KMORPH_VERSION "unknown"
#endif

static const char *const ROUTE_NAMES[SRV_R_COUNT] = {
    "index",      "healthz",     "readyz",  "metrics", "openapi",
    "signature",  "reconstruct", "morph",   "jobs",    "job",
    "job_result", "static",      "problem", "other"};

static const int STATUSES[] = {200, 202, 204, 304, 400, 404, 405, 406, 408, 409,
                               410, 413, 415, 422, 429, 431, 500, 501, 503, 0};
#define NSTATUS (sizeof STATUSES / sizeof STATUSES[0])

static const double BUCKETS[] = {0.0005, 0.001, 0.0025, 0.005, 0.01,
                                 0.025,  0.05,  0.1,    0.25,  0.5,
                                 1,      2.5,   5,      10,    30};
#define NBUCKET (sizeof BUCKETS / sizeof BUCKETS[0])

/* Why requests are refused to protect the daemon; an unknown reason counts
 * as the first. */
static const char *const REASONS[] = {
    "queue_full",  "jobs_full",     "morph_time",      "compute_time",
    "body_memory", "result_memory", "connections_full"};
#define NREASON (sizeof REASONS / sizeof REASONS[0])

/* Methods as labels; the last counts every other method. */
static const char *const METHODS[] = {"GET",    "HEAD",    "POST",
                                      "DELETE", "OPTIONS", "other"};
#define NMETHOD (sizeof METHODS / sizeof METHODS[0])

struct srv_metrics {
  pthread_mutex_t mu;
  bool (*is_allowed)(srv_route route, const char *method);
  unsigned long long count[SRV_R_COUNT][NMETHOD][NSTATUS];
  unsigned long long bucket[SRV_R_COUNT][NBUCKET];
  unsigned long long observed[SRV_R_COUNT];
  double sum[SRV_R_COUNT];
  unsigned long long rejected[NREASON];
};

const char *srv_route_name(srv_route r) {
  return (unsigned)r < SRV_R_COUNT ? ROUTE_NAMES[r] : "other";
}

srv_metrics *srv_metrics_create(bool (*is_allowed)(srv_route route,
                                                   const char *method)) {
  srv_metrics *m = calloc(1, sizeof *m);
  if (m == NULL) return NULL;
  pthread_mutex_init(&m->mu, NULL);
  m->is_allowed = is_allowed;
  return m;
}

void srv_metrics_destroy(srv_metrics *m) {
  if (m == NULL) return;
  pthread_mutex_destroy(&m->mu);
  free(m);
}

void srv_metrics_observe(srv_metrics *m, srv_route route, const char *method,
                         int status, double seconds) {
  if ((unsigned)route >= SRV_R_COUNT) route = SRV_R_OTHER;
  size_t k = NMETHOD - 1;
  for (size_t i = 0; i + 1 < NMETHOD; i++)
    if (method != NULL && strcmp(method, METHODS[i]) == 0) k = i;
  size_t s = NSTATUS - 1;
  for (size_t i = 0; i + 1 < NSTATUS; i++)
    if (STATUSES[i] == status) s = i;
  pthread_mutex_lock(&m->mu);
  m->count[route][k][s]++;
  for (size_t b = 0; b < NBUCKET; b++)
    if (seconds <= BUCKETS[b]) m->bucket[route][b]++;
  m->observed[route]++;
  m->sum[route] += seconds;
  pthread_mutex_unlock(&m->mu);
}

void srv_metrics_reject(srv_metrics *m, const char *reason) {
  size_t k = 0;
  for (size_t i = 0; i < NREASON; i++)
    if (strcmp(reason, REASONS[i]) == 0) k = i;
  pthread_mutex_lock(&m->mu);
  m->rejected[k]++;
  pthread_mutex_unlock(&m->mu);
}

typedef struct buf {
  char *p;
  size_t len, cap;
  int oom;
} buf;

static void put(buf *b, const char *fmt, ...) {
  if (b->oom) return;
  for (;;) {
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(b->p + b->len, b->cap - b->len, fmt, ap);
    va_end(ap);
    if (n < 0) {
      b->oom = 1;
      return;
    }
    if ((size_t)n < b->cap - b->len) {
      b->len += (size_t)n;
      return;
    }
    size_t ncap = b->cap * 2 + (size_t)n;
    char *np = realloc(b->p, ncap);
    if (np == NULL) {
      b->oom = 1;
      return;
    }
    b->p = np;
    b->cap = ncap;
  }
}

/* Requests answered, by route, method and status code, with
 * Prometheus' own label names (code, method); a route's allowed methods
 * are rendered at zero from the start, so rate() and absent() work
 * before the first request (m->mu held). */
static void put_requests(buf *b, const srv_metrics *m) {
  put(b, "# HELP kmorph_http_requests_total HTTP requests answered, by "
         "route, method and status code.\n"
         "# TYPE kmorph_http_requests_total counter\n");
  for (int r = 0; r < SRV_R_COUNT; r++)
    for (size_t k = 0; k < NMETHOD; k++) {
      bool known = r != SRV_R_OTHER && k + 1 < NMETHOD &&
                   m->is_allowed != NULL &&
                   m->is_allowed((srv_route)r, METHODS[k]);
      for (size_t s = 0; s < NSTATUS; s++) {
        if (m->count[r][k][s] == 0 && !(known && STATUSES[s] != 0)) continue;
        char code[8];
        if (STATUSES[s] == 0)
          snprintf(code, sizeof code, "other");
        else
          snprintf(code, sizeof code, "%d", STATUSES[s]);
        put(b,
            "kmorph_http_requests_total{route=\"%s\",method=\"%s\","
            "code=\"%s\"} %llu\n",
            ROUTE_NAMES[r], METHODS[k], code, m->count[r][k][s]);
      }
    }
}

/* The duration histogram of every route seen (m->mu held). */
static void put_durations(buf *b, const srv_metrics *m) {
  put(b, "# HELP kmorph_http_request_duration_seconds Time from request "
         "headers to response, by route.\n"
         "# TYPE kmorph_http_request_duration_seconds histogram\n");
  for (int r = 0; r < SRV_R_COUNT; r++) {
    if (m->observed[r] == 0) continue;
    for (size_t k = 0; k < NBUCKET; k++)
      put(b,
          "kmorph_http_request_duration_seconds_bucket{route=\"%s\","
          "le=\"%g\"} %llu\n",
          ROUTE_NAMES[r], BUCKETS[k], m->bucket[r][k]);
    put(b,
        "kmorph_http_request_duration_seconds_bucket{route=\"%s\","
        "le=\"+Inf\"} %llu\n"
        "kmorph_http_request_duration_seconds_sum{route=\"%s\"} %.9g\n"
        "kmorph_http_request_duration_seconds_count{route=\"%s\"} %llu\n",
        ROUTE_NAMES[r], m->observed[r], ROUTE_NAMES[r], m->sum[r],
        ROUTE_NAMES[r], m->observed[r]);
  }
}

/* Requests refused, by reason (m->mu held). */
static void put_rejections(buf *b, const srv_metrics *m) {
  put(b, "# HELP kmorph_rejected_total Requests refused to protect the daemon: "
         "at once because it was full (queue, jobs, memory for bodies or "
         "results, connection slots), or a computation stopped at its time "
         "limit.\n"
         "# TYPE kmorph_rejected_total counter\n");
  for (size_t i = 0; i < NREASON; i++)
    put(b, "kmorph_rejected_total{reason=\"%s\"} %llu\n", REASONS[i],
        m->rejected[i]);
}

/* The caller's gauges, read at render time. */
static void put_gauges(buf *b, const srv_gauges *g) {
  put(b,
      "# HELP kmorph_queue_depth Compute requests waiting for a worker.\n"
      "# TYPE kmorph_queue_depth gauge\n"
      "kmorph_queue_depth %zu\n"
      "# HELP kmorph_queue_capacity Compute requests that may wait.\n"
      "# TYPE kmorph_queue_capacity gauge\n"
      "kmorph_queue_capacity %zu\n"
      "# HELP kmorph_workers_busy Compute workers running a request or a "
      "job frame.\n"
      "# TYPE kmorph_workers_busy gauge\n"
      "kmorph_workers_busy %zu\n"
      "# HELP kmorph_workers Compute workers.\n"
      "# TYPE kmorph_workers gauge\n"
      "kmorph_workers %zu\n"
      "# HELP kmorph_connections Open HTTP connections.\n"
      "# TYPE kmorph_connections gauge\n"
      "kmorph_connections %zu\n"
      "# HELP kmorph_body_bytes Bytes of request bodies held now "
      "(KMORPH_BODY_MEMORY bounds it).\n"
      "# TYPE kmorph_body_bytes gauge\n"
      "kmorph_body_bytes %zu\n"
      "# HELP kmorph_result_bytes Bytes of job results kept or reserved "
      "(KMORPH_RESULT_MEMORY bounds it).\n"
      "# TYPE kmorph_result_bytes gauge\n"
      "kmorph_result_bytes %zu\n"
      "# HELP kmorph_connections_cut_total Connections cut at a deadline: "
      "a request that did not arrive in time (answered 408), an answer not "
      "read in time.\n"
      "# TYPE kmorph_connections_cut_total counter\n"
      "kmorph_connections_cut_total{reason=\"late_request\"} %zu\n"
      "kmorph_connections_cut_total{reason=\"late_send\"} %zu\n"
      "# HELP kmorph_jobs Jobs known to the job store, by state.\n"
      "# TYPE kmorph_jobs gauge\n",
      g->queue_depth, g->queue_capacity, g->workers_busy, g->workers,
      g->connections, g->body_bytes, g->result_bytes, g->late_requests,
      g->late_sends);
  for (int s = 0; s < 5; s++)
    put(b, "kmorph_jobs{state=\"%s\"} %zu\n", g->job_state_names[s],
        g->jobs[s]);
}

char *srv_metrics_render(srv_metrics *m, const srv_gauges *g, size_t *len) {
  buf b = {malloc(16384), 0, 16384, 0};
  if (b.p == NULL) return NULL;
  b.p[0] = '\0';
  pthread_mutex_lock(&m->mu);
  put(&b,
      "# HELP kmorph_build_info The daemon's version (always 1).\n"
      "# TYPE kmorph_build_info gauge\n"
      "kmorph_build_info{version=\"%s\"} 1\n",
      KMORPH_VERSION);
  put_requests(&b, m);
  put_durations(&b, m);
  put_rejections(&b, m);
  pthread_mutex_unlock(&m->mu);
  put_gauges(&b, g);
  if (g->extra != NULL)
    put(&b, "%s", g->extra);
  else
    put(&b,
        "# HELP kmorph_job_frames_rendered_total Frames of jobs rendered by "
        "this instance.\n"
        "# TYPE kmorph_job_frames_rendered_total counter\n"
        "kmorph_job_frames_rendered_total %zu\n",
        g->frames_rendered);
  if (b.oom) {
    free(b.p);
    return NULL;
  }
  *len = b.len;
  return b.p;
}
