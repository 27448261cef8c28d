/* server.c - kmorphd's HTTP layer over libmicrohttpd (see server.h).
 *
 * DESIGN: MHD runs a small pool of I/O threads (auto-selected poll/epoll)
 * with suspend/resume allowed. The access handler is called several times
 * per request: first with the headers (route, method, content type and
 * Content-Length are checked here so bad requests are refused before any
 * body is read), then with body chunks (collected up to the limit, counted
 * and discarded beyond it), then once more with no data: the request is
 * complete. Requests that need geometry reserve a slot in the compute
 * queue (none free: 503 + Retry-After at once), suspend the connection and
 * hand the request to a worker; the worker stores the api_response and
 * resumes the connection, and the handler, called again, queues it.
 * I/O threads never compute. Every answer carries X-Request-Id and, for
 * allowed origins, CORS headers; every finished request leaves one access
 * log line and is counted in the metrics.
 */
#include "server.h"

#include <arpa/inet.h>
#include <errno.h>
#include <microhttpd.h>
#include <netinet/in.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include "http_guard.h"
#include "jobs.h"
#include "jobstore.h"
#include "kmapi/api.h"
#include "log.h"
#include "metrics.h"
#include "pool.h"
#include "util.h"
#include "watch.h"

struct srv_server {
  srv_config cfg;
  api_config api;
  FILE *log;        /* srv_log_stream(logger): the same FILE for life */
  srv_log *logger;  /* rate-limits libmicrohttpd's messages */
  struct MHD_Daemon *daemon;
  MHD_socket quiesced_fd;
  unsigned port;
  srv_pool *pool;
  srv_jobstore *store;
  srv_jobs *jobs;
  srv_metrics *metrics;
  srv_watch *watch;
  atomic_bool draining;
  atomic_bool abort_compute; /* grace over: every computation stops now */
  atomic_size_t suspended; /* connections waiting for a worker */
  atomic_size_t inflight;  /* requests begun and not yet completed */
  atomic_size_t body_bytes; /* buffers of request bodies held now */
};

typedef enum phase {
  PH_BODY,   /* headers seen, body arriving */
  PH_WAIT,   /* suspended, a worker owns the request */
  PH_READY,  /* the worker filled resp and resumed the connection */
  PH_ANSWERED
} phase;

typedef struct srv_req {
  srv_server *srv;
  struct MHD_Connection *conn;
  srv_route route;
  char method[12];
  char path[160];
  char rid[65];
  char job_id[SRV_JOB_ID_LEN + 1];
  char static_name[104];
  char *accept;
  char *body;
  size_t len, cap, seen;
  size_t held;       /* bytes of body buffer counted in srv->body_bytes */
  bool no_memory;    /* the body did not fit the budget of bodies */
  bool too_large, is_head;
  double t0;
  atomic_int phase;
  api_response resp; /* written by the worker before resuming */
  bool location;     /* add Location for a created job */
  bool counted;      /* included in srv->suspended */
  double deadline;   /* compute stops here (srv_now() seconds) */
  double next_gone_check;
  int stopped;       /* why the compute stop condition fired: STOP_* */
  int status;
  size_t bytes;
  const char *cut; /* why the connection was closed without an answer */
  srv_http_target target; /* the raw request target (URI log callback) */
  bool begun;        /* req_new has run: the handler saw the headers */
  bool must_close;   /* the framing was refused: no keep-alive */
  bool http11;       /* the client may be sent an interim 1xx */
  bool probed;       /* a FIN was seen and answered with a probe */
} srv_req;

static const char *const ALLOW_GET = "GET, HEAD, OPTIONS";
static const char *const ALLOW_POST = "POST, OPTIONS";
static const char *const ALLOW_JOB = "GET, DELETE, OPTIONS";
static const char *const ALLOW_RESULT = "GET, OPTIONS";
static const char *const JSON = "application/json";

/* ---------------------------------------------------------------- routes */

static bool static_name_ok(const char *n)
{
  size_t k = 0;
  if (n[0] == '\0' || n[0] == '.')
    return false;
  for (; n[k]; k++) {
    char c = n[k];
    if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
          (c >= '0' && c <= '9') || c == '.' || c == '_' || c == '-') ||
        k >= 100)
      return false;
  }
  return true;
}

static srv_route parse_route(srv_req *r, const char *url)
{
  static const struct {
    const char *path;
    srv_route route;
  } FIXED[] = {{"/", SRV_R_INDEX},
               {"/healthz", SRV_R_HEALTHZ},
               {"/readyz", SRV_R_READYZ},
               {"/metrics", SRV_R_METRICS},
               {"/openapi.json", SRV_R_OPENAPI},
               {"/v1/signature", SRV_R_SIGNATURE},
               {"/v1/reconstruct", SRV_R_RECONSTRUCT},
               {"/v1/morph", SRV_R_MORPH},
               {"/v1/jobs", SRV_R_JOBS}};
  /* The absolute form (RFC 9112 3.2.2) names this origin's resource by
   * the path after the authority; an empty path is "/". */
  if (strncasecmp(url, "http://", 7) == 0 ||
      strncasecmp(url, "https://", 8) == 0) {
    const char *path = strchr(strstr(url, "//") + 2, '/');
    url = path != NULL ? path : "/";
  }
  for (size_t i = 0; i < sizeof FIXED / sizeof FIXED[0]; i++)
    if (strcmp(url, FIXED[i].path) == 0)
      return FIXED[i].route;
  const char *prefix = "/v1/jobs/";
  if (strncmp(url, prefix, strlen(prefix)) == 0) {
    const char *id = url + strlen(prefix);
    const char *slash = strchr(id, '/');
    size_t n = slash ? (size_t)(slash - id) : strlen(id);
    if (n == 0 || n > SRV_JOB_ID_LEN)
      return SRV_R_OTHER; /* cannot name a job: plain 404 */
    memcpy(r->job_id, id, n);
    r->job_id[n] = '\0';
    if (slash == NULL)
      return SRV_R_JOB;
    if (strcmp(slash, "/result") == 0)
      return SRV_R_JOB_RESULT;
    return SRV_R_OTHER;
  }
  if (url[0] == '/' && strchr(url + 1, '/') == NULL &&
      static_name_ok(url + 1)) {
    snprintf(r->static_name, sizeof r->static_name, "%s", url + 1);
    return SRV_R_STATIC;
  }
  return SRV_R_OTHER;
}

static const char *allowed_methods(srv_route route)
{
  switch (route) {
  case SRV_R_SIGNATURE:
  case SRV_R_RECONSTRUCT:
  case SRV_R_MORPH:
  case SRV_R_JOBS:
    return ALLOW_POST;
  case SRV_R_JOB:
    return ALLOW_JOB;
  case SRV_R_JOB_RESULT:
    return ALLOW_RESULT;
  default:
    return ALLOW_GET;
  }
}

static bool method_allowed(srv_route route, const char *method)
{
  switch (route) {
  case SRV_R_SIGNATURE:
  case SRV_R_RECONSTRUCT:
  case SRV_R_MORPH:
  case SRV_R_JOBS:
    return strcmp(method, "POST") == 0;
  case SRV_R_JOB:
    return strcmp(method, "GET") == 0 || strcmp(method, "DELETE") == 0;
  case SRV_R_JOB_RESULT:
    return strcmp(method, "GET") == 0;
  default:
    return strcmp(method, "GET") == 0 || strcmp(method, "HEAD") == 0;
  }
}

static bool is_compute(srv_route route)
{
  return route == SRV_R_SIGNATURE || route == SRV_R_RECONSTRUCT ||
         route == SRV_R_MORPH || route == SRV_R_JOBS;
}

/* Probes a load balancer or an operator sends: answered from a reserved
 * slot when every ordinary one is taken. */
static bool is_probe(srv_route route)
{
  return route == SRV_R_HEALTHZ || route == SRV_R_READYZ ||
         route == SRV_R_METRICS;
}

/* The watch record of r's connection (NULL if it is not watched). */
static srv_conn *conn_of(const srv_req *r)
{
  const union MHD_ConnectionInfo *ci =
      MHD_get_connection_info(r->conn, MHD_CONNECTION_INFO_SOCKET_CONTEXT);
  return ci ? ci->socket_context : NULL;
}

/* ------------------------------------------------------------- answering */

/* The origin to allow for this request, or NULL for no CORS headers. */
static const char *cors_origin(const srv_req *r)
{
  const char *origin = MHD_lookup_connection_value(r->conn, MHD_HEADER_KIND,
                                                   "Origin");
  const char *list = r->srv->cfg.cors_origins;
  if (origin == NULL || list[0] == '\0')
    return NULL;
  size_t olen = strlen(origin);
  const char *p = list;
  while (*p) {
    while (*p == ' ' || *p == ',')
      p++;
    const char *e = p;
    while (*e && *e != ',')
      e++;
    const char *t = e;
    while (t > p && t[-1] == ' ')
      t--;
    size_t n = (size_t)(t - p);
    if (n == 1 && *p == '*')
      return "*";
    if (n > 0 && n == olen && strncmp(p, origin, n) == 0)
      return origin;
    p = e;
  }
  return NULL;
}

static void add_common_headers(srv_req *r, struct MHD_Response *resp,
                               int status)
{
  srv_server *s = r->srv;
  MHD_add_response_header(resp, "X-Request-Id", r->rid);
  const char *origin = cors_origin(r);
  if (origin != NULL) {
    MHD_add_response_header(resp, "Access-Control-Allow-Origin", origin);
    if (strcmp(origin, "*") != 0)
      MHD_add_response_header(resp, "Vary", "Origin");
    MHD_add_response_header(resp, "Access-Control-Expose-Headers",
                            "Location, Retry-After, X-Request-Id");
  }
  if (status == 429 || status == 503) {
    char ra[16];
    snprintf(ra, sizeof ra, "%u", s->cfg.retry_after);
    MHD_add_response_header(resp, MHD_HTTP_HEADER_RETRY_AFTER, ra);
  }
  if (status == 405)
    MHD_add_response_header(resp, MHD_HTTP_HEADER_ALLOW,
                            allowed_methods(r->route));
  if (r->route == SRV_R_JOB || r->route == SRV_R_JOBS ||
      r->route == SRV_R_JOB_RESULT || r->route == SRV_R_METRICS ||
      r->route == SRV_R_HEALTHZ || r->route == SRV_R_READYZ)
    MHD_add_response_header(resp, MHD_HTTP_HEADER_CACHE_CONTROL, "no-store");
  if (atomic_load(&s->draining) || r->must_close)
    MHD_add_response_header(resp, MHD_HTTP_HEADER_CONNECTION, "close");
}

/* Add the common headers to resp and queue it (resp is released). */
static enum MHD_Result queue(srv_req *r, int status,
                             struct MHD_Response *resp, size_t len)
{
  add_common_headers(r, resp, status);
  if (r->location) {
    char loc[64];
    snprintf(loc, sizeof loc, "/v1/jobs/%s", r->job_id);
    MHD_add_response_header(resp, MHD_HTTP_HEADER_LOCATION, loc);
  }
  enum MHD_Result ok = MHD_queue_response(r->conn, (unsigned)status, resp);
  MHD_destroy_response(resp);
  r->status = status;
  r->bytes = len;
  atomic_store(&r->phase, PH_ANSWERED);
  srv_watch_answer_queued(conn_of(r), srv_now());
  return ok;
}

/* Queue an answer. body is malloc'd (freed by MHD) when owned, else
 * static. Never fails to record the status for the log. */
static enum MHD_Result answer(srv_req *r, int status, const char *ctype,
                              char *body, size_t len, bool owned)
{
  struct MHD_Response *resp = MHD_create_response_from_buffer(
      len, body, owned ? MHD_RESPMEM_MUST_FREE : MHD_RESPMEM_PERSISTENT);
  if (resp == NULL) {
    if (owned)
      free(body);
    r->cut = "out of memory";
    return MHD_NO;
  }
  if (ctype != NULL)
    MHD_add_response_header(resp, MHD_HTTP_HEADER_CONTENT_TYPE, ctype);
  return queue(r, status, resp, len);
}

static enum MHD_Result answer_api(srv_req *r, api_response *res)
{
  if (res->body == NULL) {
    static const char oom[] =
        "{\"type\":\"/problems/internal\",\"title\":\"Out of memory\","
        "\"status\":500}";
    api_response_free(res);
    return answer(r, 500, "application/problem+json", (char *)oom,
                  sizeof oom - 1, false);
  }
  char *body = res->body;
  res->body = NULL;
  return answer(r, res->status, res->content_type, body, res->length, true);
}

static enum MHD_Result problem(srv_req *r, int status, const char *type,
                               const char *title, const char *detail,
                               const char *pointer, const char *message)
{
  api_response res;
  api_response_init(&res);
  api_problem(&res, status, type, title, detail, pointer, message, r->rid);
  return answer_api(r, &res);
}

/* A request other than a probe on a reserved slot: every ordinary slot is
 * taken. */
static enum MHD_Result reserved_refusal(srv_req *r)
{
  srv_metrics_reject(r->srv->metrics, "connections_full");
  return problem(r, 503, "/problems/overloaded", "Overloaded",
                 "every connection slot is taken (KMORPH_MAX_CONNECTIONS); "
                 "the slots beyond it serve /healthz, /readyz and /metrics "
                 "only; retry after the time in Retry-After",
                 NULL, NULL);
}

static enum MHD_Result answer_json(srv_req *r, int status, const char *fmt,
                                   ...) __attribute__((format(printf, 3, 4)));

static enum MHD_Result answer_json(srv_req *r, int status, const char *fmt,
                                   ...)
{
  char tmp[1024];
  va_list ap;
  va_start(ap, fmt);
  int n = vsnprintf(tmp, sizeof tmp, fmt, ap);
  va_end(ap);
  if (n < 0 || (size_t)n >= sizeof tmp)
    return problem(r, 500, "/problems/internal", "Internal error",
                   "response too long", NULL, NULL);
  char *body = malloc((size_t)n + 1);
  if (body == NULL)
    return MHD_NO;
  memcpy(body, tmp, (size_t)n + 1);
  return answer(r, status, JSON, body, (size_t)n, true);
}

/* ---------------------------------------------------------------- compute */

static int job_created_body(api_response *out, const char *id, size_t total)
{
  char tmp[512];
  int n = snprintf(tmp, sizeof tmp,
                   "{\"id\":\"%s\",\"state\":\"queued\",\"progress\":0,"
                   "\"frames_done\":0,\"frames_total\":%zu,"
                   "\"links\":{\"self\":\"/v1/jobs/%s\","
                   "\"result\":\"/v1/jobs/%s/result\"}}",
                   id, total, id, id);
  char *body = malloc((size_t)n + 1);
  if (body == NULL)
    return -1;
  memcpy(body, tmp, (size_t)n + 1);
  out->status = 202;
  out->content_type = JSON;
  out->body = body;
  out->length = (size_t)n;
  return 0;
}

/* Free the request's body and give its bytes back to the budget of
 * bodies in flight. */
static void release_body(srv_req *r)
{
  free(r->body);
  r->body = NULL;
  r->len = r->cap = 0;
  atomic_fetch_sub(&r->srv->body_bytes, r->held);
  r->held = 0;
}

enum { STOP_NONE, STOP_TIME, STOP_GONE, STOP_SHUTDOWN };

static bool client_gone(srv_req *r);

/* The stop condition of a request's computation, polled by the core at
 * short intervals of work (api_request.stop): the shutdown's grace ran
 * out, the compute time limit passed, or the client left (looked at every
 * 20 ms: a recv on the socket). Runs on the worker that owns r. */
static bool request_should_stop(void *ctx)
{
  srv_req *r = ctx;
  if (r->stopped != STOP_NONE)
    return true;
  if (atomic_load(&r->srv->abort_compute))
    r->stopped = STOP_SHUTDOWN;
  double now = srv_now();
  if (r->stopped == STOP_NONE && now > r->deadline)
    r->stopped = STOP_TIME;
  if (r->stopped == STOP_NONE && now >= r->next_gone_check) {
    r->next_gone_check = now + 0.02;
    if (client_gone(r))
      r->stopped = STOP_GONE;
  }
  return r->stopped != STOP_NONE;
}

/* The answer to a computation stopped by request_should_stop. limit and
 * name describe the time limit; pointer is the member that makes the
 * request long (a time limit is a limit like the frame limit: 422). */
static void stopped_problem(srv_req *r, double limit, const char *name,
                            const char *pointer, const char *message,
                            const char *progress)
{
  api_response_free(&r->resp);
  if (r->stopped == STOP_GONE) {
    api_problem(&r->resp, 503, "/problems/client-gone", "Client gone",
                "the client closed the connection during the work", NULL,
                NULL, r->rid);
    return;
  }
  if (r->stopped == STOP_SHUTDOWN) {
    api_problem(&r->resp, 503, "/problems/shutting-down", "Shutting down",
                "the service stopped this computation at the end of its "
                "shutdown grace; retry on another instance",
                NULL, NULL, r->rid);
    return;
  }
  char detail[400];
  snprintf(detail, sizeof detail,
           "%s: the computation ran past its time limit of %g s (%s)%s%s",
           pointer, limit, name, progress,
           r->route == SRV_R_MORPH
               ? "; POST /v1/jobs computes long morphs asynchronously"
               : "");
  srv_metrics_reject(r->srv->metrics, r->route == SRV_R_MORPH
                                          ? "morph_time"
                                          : "compute_time");
  api_problem(&r->resp, 422, "/problems/limit-exceeded", "Limit exceeded",
              detail, pointer, message, r->rid);
}

/* POST /v1/jobs on a worker: validate and plan (within the job's time),
 * then admit the job with the rest of that time. */
static void create_job(srv_req *r, api_request *req)
{
  srv_server *s = r->srv;
  api_morph_plan *plan = NULL;
  api_response err;
  api_response_init(&err);
  double limit = srv_jobs_time_limit(s->jobs);
  r->deadline = r->t0 + limit;
  int rc = api_morph_prepare(&s->api, req, s->cfg.max_job_frames, &plan, &err);
  if (rc != 0 || plan == NULL) {
    r->resp = err;
    if (r->stopped != STOP_NONE) {
      char message[160];
      snprintf(message, sizeof message,
               "preparing the morph takes longer than the %g s a job may "
               "take", limit);
      stopped_problem(r, limit, "KMORPH_JOB_TIME", "/tolerance", message,
                      " while preparing the morph");
    } else if (r->resp.body == NULL) {
      api_problem(&r->resp, rc >= 400 ? rc : 500, "/problems/internal",
                  "Internal error", "the morph could not be prepared", NULL,
                  NULL, r->rid);
    }
    return;
  }
  api_response_free(&err);
  size_t total = api_morph_frame_count(plan);
  size_t predicted = api_morph_predicted_bytes(plan);
  if (predicted > s->cfg.result_memory) {
    /* It could never be kept: a limit of the request, like its frames. */
    const char *ptr = api_morph_frames_pointer(plan);
    char message[200], detail[400];
    snprintf(message, sizeof message,
             "the result would take up to %zu bytes; job results are kept "
             "within %zu", predicted, s->cfg.result_memory);
    snprintf(detail, sizeof detail,
             "%s: the result would take up to %zu bytes, more than the %zu "
             "kept for job results (KMORPH_RESULT_MEMORY); ask for fewer "
             "frames or a looser tolerance",
             ptr, predicted, s->cfg.result_memory);
    api_morph_plan_free(plan);
    api_problem(&r->resp, 422, "/problems/limit-exceeded", "Limit exceeded",
                detail, ptr, message, r->rid);
    return;
  }
  int st = srv_jobs_start(s->jobs, plan, r->deadline, predicted, r->job_id);
  if (st != 0)
    api_morph_plan_free(plan);
  if (st == -1) {
    srv_metrics_reject(s->metrics, "jobs_full");
    api_problem(&r->resp, 429, "/problems/too-many-jobs", "Too many jobs",
                "the job limit (KMORPH_MAX_JOBS) is reached; retry later",
                NULL, NULL, r->rid);
    return;
  }
  if (st == -4) {
    srv_metrics_reject(s->metrics, "result_memory");
    api_problem(&r->resp, 503, "/problems/overloaded", "Overloaded",
                "the results of the jobs running now would fill the memory "
                "kept for job results (KMORPH_RESULT_MEMORY); retry later",
                NULL, NULL, r->rid);
    return;
  }
  if (st == -3) {
    api_problem(&r->resp, 503, "/problems/shutting-down", "Shutting down",
                "the service is stopping; retry on another instance", NULL,
                NULL, r->rid);
    return;
  }
  if (st != 0 || job_created_body(&r->resp, r->job_id, total) != 0) {
    api_problem(&r->resp, 500, "/problems/internal", "Out of memory", NULL,
                NULL, NULL, r->rid);
    return;
  }
  r->location = true;
  srv_pool_kick(s->pool);
}

/* True if the client has reset its connection, or closed it, while its
 * request waited: its answer could not be delivered, so no work is done
 * for it. A FIN alone is not enough: a client that half-closed its
 * sending side still reads its answer; srv_http_fin_probe tells the two
 * apart (the probe goes out once; a closed peer's reset is then seen
 * here as an error). */
static bool client_gone(srv_req *r)
{
  const union MHD_ConnectionInfo *ci =
      MHD_get_connection_info(r->conn, MHD_CONNECTION_INFO_CONNECTION_FD);
  if (ci == NULL)
    return false;
  char b;
  ssize_t n = recv(ci->connect_fd, &b, 1, MSG_PEEK | MSG_DONTWAIT);
  if (n == 0)
    return srv_http_fin_probe(ci->connect_fd, r->http11, &r->probed);
  return n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR;
}

/* POST /v1/morph on a worker, frame by frame the way api_handle does it,
 * so that the work stops when the client leaves or the compute time limit
 * passes - between frames, and inside preparing and each frame through
 * the stop condition. The time counts from the start of the work. */
static void morph_sync(srv_req *r, api_request *req)
{
  srv_server *s = r->srv;
  api_morph_plan *plan = NULL;
  double limit = s->cfg.morph_time;
  r->deadline = srv_now() + limit;
  char message[160];
  if (api_morph_prepare(&s->api, req, s->api.max_frames_sync, &plan,
                        &r->resp) != 0) {
    if (r->stopped != STOP_NONE) {
      snprintf(message, sizeof message,
               "preparing the morph takes longer than the %g s a "
               "synchronous morph may compute", limit);
      stopped_problem(r, limit, "KMORPH_MORPH_TIME", "/tolerance", message,
                      " while preparing the morph");
    }
    return;
  }
  size_t n = api_morph_frame_count(plan);
  size_t done = 0;
  /* A frame that fails for its own reason leaves its problem in the plan
   * for api_morph_result; one that was stopped ends the work. */
  while (done < n && !request_should_stop(r)) {
    api_morph_render_frame_until(plan, done, request_should_stop, r);
    if (r->stopped == STOP_NONE)
      done++;
  }
  if (r->stopped != STOP_NONE) {
    char progress[80];
    snprintf(message, sizeof message,
             "%zu frames take longer than the %g s a synchronous morph may "
             "compute", n, limit);
    snprintf(progress, sizeof progress, " with %zu of %zu frames done", done,
             n);
    stopped_problem(r, limit, "KMORPH_MORPH_TIME",
                    api_morph_frames_pointer(plan), message, progress);
  } else {
    api_morph_result(plan, &r->resp);
  }
  api_morph_plan_free(plan);
}

/* POST /v1/signature or /v1/reconstruct on a worker, within the compute
 * time limit. */
static void compute_sync(srv_req *r, api_request *req)
{
  double limit = r->srv->cfg.compute_time;
  r->deadline = srv_now() + limit;
  api_handle(&r->srv->api, req, &r->resp);
  if (r->stopped != STOP_NONE) {
    char message[160];
    snprintf(message, sizeof message,
             "the computation takes longer than the %g s a request may "
             "compute", limit);
    stopped_problem(r, limit, "KMORPH_COMPUTE_TIME", "/tolerance", message,
                    "");
  }
}

static void compute_task(void *arg, bool cancelled)
{
  srv_req *r = arg;
  api_response_init(&r->resp);
  if (!cancelled && client_gone(r)) {
    api_problem(&r->resp, 503, "/problems/client-gone", "Client gone",
                "the client closed the connection before the work started",
                NULL, NULL, r->rid);
  } else if (cancelled) {
    api_problem(&r->resp, 503, "/problems/shutting-down", "Shutting down",
                "the service is stopping; retry on another instance",
                NULL, NULL, r->rid);
  } else {
    api_request req;
    memset(&req, 0, sizeof req);
    req.body = r->body ? r->body : "";
    req.length = r->len;
    req.accept = r->accept;
    req.request_id = r->rid;
    req.stop = request_should_stop;
    req.stop_ctx = r;
    r->next_gone_check = srv_now() + 0.02;
    if (r->route == SRV_R_JOBS) {
      req.route = API_ROUTE_MORPH;
      create_job(r, &req);
    } else if (r->route == SRV_R_SIGNATURE || r->route == SRV_R_RECONSTRUCT) {
      req.route = r->route == SRV_R_SIGNATURE ? API_ROUTE_SIGNATURE
                                              : API_ROUTE_RECONSTRUCT;
      compute_sync(r, &req);
    } else {
      req.route = API_ROUTE_MORPH;
      morph_sync(r, &req);
    }
  }
  /* The body is no longer needed: give its memory back to the budget of
   * bodies in flight before the answer is sent. */
  release_body(r);
  atomic_store(&r->phase, PH_READY);
  MHD_resume_connection(r->conn);
}

static enum MHD_Result hand_off(srv_req *r)
{
  srv_server *s = r->srv;
  if (atomic_load(&s->draining))
    return problem(r, 503, "/problems/shutting-down", "Shutting down",
                   "the service is stopping; retry on another instance",
                   NULL, NULL);
  if (r->route == SRV_R_JOBS && srv_jobs_full(s->jobs)) {
    srv_metrics_reject(s->metrics, "jobs_full");
    return problem(r, 429, "/problems/too-many-jobs", "Too many jobs",
                   "the job limit (KMORPH_MAX_JOBS) is reached; retry later",
                   NULL, NULL);
  }
  if (!srv_pool_reserve(s->pool)) {
    srv_metrics_reject(s->metrics, "queue_full");
    return problem(r, 503, "/problems/overloaded", "Overloaded",
                   "every compute worker is busy and the queue is full; "
                   "retry after the time in Retry-After",
                   NULL, NULL);
  }
  /* Suspend before submitting so the worker's resume always comes after. */
  atomic_store(&r->phase, PH_WAIT);
  atomic_fetch_add(&s->suspended, 1);
  r->counted = true;
  srv_watch_body_done(conn_of(r));
  MHD_suspend_connection(r->conn);
  srv_pool_submit(s->pool, compute_task, r);
  return MHD_YES;
}

/* ------------------------------------------------------------- endpoints */

static char *read_file(const char *path, size_t max, size_t *len)
{
  FILE *f = fopen(path, "rb");
  if (f == NULL)
    return NULL;
  char *buf = malloc(max + 1);
  size_t n = buf ? fread(buf, 1, max + 1, f) : 0;
  fclose(f);
  if (buf == NULL || n > max) {
    free(buf);
    return NULL;
  }
  buf[n] = '\0';
  *len = n;
  return buf;
}

static const char *type_of(const char *name)
{
  static const struct {
    const char *ext, *type;
  } T[] = {{".html", "text/html; charset=utf-8"},
           {".js", "text/javascript; charset=utf-8"},
           {".mjs", "text/javascript; charset=utf-8"},
           {".css", "text/css; charset=utf-8"},
           {".svg", "image/svg+xml"},
           {".json", "application/json"},
           {".png", "image/png"},
           {".ico", "image/x-icon"},
           {".txt", "text/plain; charset=utf-8"}};
  const char *dot = strrchr(name, '.');
  if (dot != NULL)
    for (size_t i = 0; i < sizeof T / sizeof T[0]; i++)
      if (strcmp(dot, T[i].ext) == 0)
        return T[i].type;
  return NULL;
}

static const char INDEX_HTML[] =
    "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
    "<title>kmorph</title></head><body>\n"
    "<h1>kmorph</h1>\n<p>Morphs planar curves by blending their curvature."
    "</p>\n<ul>\n"
    "<li>POST <code>/v1/signature</code> &mdash; curvature signature of a "
    "curve</li>\n"
    "<li>POST <code>/v1/reconstruct</code> &mdash; curve from a signature"
    "</li>\n"
    "<li>POST <code>/v1/morph</code> &mdash; a morph sequence, "
    "synchronously</li>\n"
    "<li>POST <code>/v1/jobs</code>, GET/DELETE <code>/v1/jobs/{id}</code>, "
    "GET <code>/v1/jobs/{id}/result</code> &mdash; asynchronous morphs</li>\n"
    "<li>GET <a href=\"/openapi.json\"><code>/openapi.json</code></a> "
    "&mdash; the contract</li>\n"
    "<li>GET <a href=\"/healthz\"><code>/healthz</code></a>, "
    "<a href=\"/readyz\"><code>/readyz</code></a>, "
    "<a href=\"/metrics\"><code>/metrics</code></a></li>\n"
    "</ul>\n</body></html>\n";

static enum MHD_Result serve_file(srv_req *r, const char *name)
{
  const char *type = type_of(name);
  char path[1024];
  size_t len = 0;
  char *body = NULL;
  if (type != NULL &&
      (size_t)snprintf(path, sizeof path, "%s/%s", r->srv->cfg.web_root,
                       name) < sizeof path)
    body = read_file(path, (size_t)16 << 20, &len);
  if (body != NULL)
    return answer(r, 200, type, body, len, true);
  if (r->route == SRV_R_INDEX)
    return answer(r, 200, "text/html; charset=utf-8", (char *)INDEX_HTML,
                  sizeof INDEX_HTML - 1, false);
  return problem(r, 404, "/problems/not-found", "Not found",
                 "no such resource", NULL, NULL);
}

static enum MHD_Result serve_metrics(srv_req *r)
{
  srv_server *s = r->srv;
  static const char *const names[5] = {"queued", "running", "done", "failed",
                                       "cancelled"};
  srv_gauges g;
  memset(&g, 0, sizeof g);
  g.queue_depth = srv_pool_depth(s->pool);
  g.queue_capacity = srv_pool_capacity(s->pool);
  g.workers_busy = srv_pool_busy(s->pool);
  g.workers = srv_pool_workers(s->pool);
  /* The daemon pointer comes from the connection: s->daemon is written by
   * the main thread after the I/O threads have started. */
  const union MHD_ConnectionInfo *ci =
      MHD_get_connection_info(r->conn, MHD_CONNECTION_INFO_DAEMON);
  const union MHD_DaemonInfo *info =
      ci ? MHD_get_daemon_info(ci->daemon,
                               MHD_DAEMON_INFO_CURRENT_CONNECTIONS)
         : NULL;
  g.connections = info ? info->num_connections : 0;
  s->store->ops->counts(s->store, srv_now(), g.jobs);
  g.body_bytes = atomic_load(&s->body_bytes);
  g.result_bytes = s->store->ops->result_bytes(s->store);
  srv_watch_counts(s->watch, &g.late_requests, &g.late_sends);
  g.job_state_names = names;
  size_t len = 0;
  char *text = srv_metrics_render(s->metrics, &g, &len);
  if (text == NULL)
    return MHD_NO;
  return answer(r, 200, "text/plain; version=0.0.4; charset=utf-8", text, len,
                true);
}

/* 404 for a job never known (or deleted), 410 for one that was known and
 * is no longer kept, with why: a client must not take an expired or
 * evicted job for a mistyped id, nor resubmit blindly. */
static enum MHD_Result job_missing(srv_req *r, int rc, const srv_job_view *v)
{
  if (rc == SRV_STORE_GONE) {
    char detail[400];
    snprintf(detail, sizeof detail, "job %s is no longer kept: %s", r->job_id,
             v->error);
    return problem(r, 410, "/problems/job-gone", "Job gone", detail, NULL,
                   NULL);
  }
  return problem(r, 404, "/problems/job-not-found", "Job not found",
                 "no such job", NULL, NULL);
}

static enum MHD_Result serve_job(srv_req *r)
{
  srv_server *s = r->srv;
  srv_job_view v;
  double now = srv_now();
  if (strcmp(r->method, "DELETE") == 0) {
    if (srv_jobs_cancel(s->jobs, r->job_id) == 0)
      return answer(r, 204, NULL, (char *)"", 0, false);
    /* Not live: a final job is forgotten; an unknown one is 404. */
    if (s->store->ops->remove(s->store, r->job_id) == 0)
      return answer(r, 204, NULL, (char *)"", 0, false);
    return problem(r, 404, "/problems/job-not-found", "Job not found",
                   "no such job (finished jobs are forgotten after a while)",
                   NULL, NULL);
  }
  int rc = s->store->ops->get(s->store, r->job_id, now, &v);
  if (rc != SRV_STORE_OK)
    return job_missing(r, rc, &v);
  double progress =
      v.frames_total ? (double)v.frames_done / (double)v.frames_total : 0.0;
  if (v.state == SRV_JOB_DONE)
    progress = 1.0;
  char err[600] = "";
  if (v.state == SRV_JOB_FAILED) {
    char esc[520];
    srv_json_escape(esc, sizeof esc, v.error);
    snprintf(err, sizeof err, ",\"error\":{\"status\":%d,\"detail\":\"%s\"}",
             v.error_status, esc);
  }
  return answer_json(
      r, 200,
      "{\"id\":\"%s\",\"state\":\"%s\",\"progress\":%.6g,"
      "\"frames_done\":%zu,\"frames_total\":%zu,\"age_seconds\":%.3f,"
      "\"links\":{\"self\":\"/v1/jobs/%s\",\"result\":\"/v1/jobs/%s/result\"}"
      "%s}",
      v.id, srv_job_state_name(v.state), progress, v.frames_done,
      v.frames_total, v.age, v.id, v.id, err);
}

static void drop_result_ref(void *cls) { srv_result_unref(cls); }

/* A job's result, sent from the store's own copy: the answer holds a
 * reference until libmicrohttpd has sent it, so a slow reader costs no
 * memory of its own and an eviction meanwhile frees nothing under it. */
static enum MHD_Result answer_result(srv_req *r, srv_result *res)
{
  size_t len = srv_result_length(res);
  struct MHD_Response *resp =
      MHD_create_response_from_buffer_with_free_callback_cls(
          len, (void *)srv_result_body(res), drop_result_ref, res);
  if (resp == NULL) {
    srv_result_unref(res);
    r->cut = "out of memory";
    return MHD_NO;
  }
  MHD_add_response_header(resp, MHD_HTTP_HEADER_CONTENT_TYPE,
                          srv_result_type(res));
  int status = srv_result_status(res);
  return queue(r, status, resp, len);
}

static enum MHD_Result serve_result(srv_req *r)
{
  srv_server *s = r->srv;
  srv_job_view v;
  srv_result *res = NULL;
  int rc = s->store->ops->result(s->store, r->job_id, srv_now(), &v, &res);
  if (rc != SRV_STORE_OK)
    return job_missing(r, rc, &v);
  if (v.state == SRV_JOB_DONE && res != NULL)
    return answer_result(r, res);
  srv_result_unref(res);
  char detail[400];
  if (v.state == SRV_JOB_FAILED)
    snprintf(detail, sizeof detail, "the job failed: %s", v.error);
  else if (v.state == SRV_JOB_CANCELLED)
    snprintf(detail, sizeof detail, "the job was cancelled");
  else
    snprintf(detail, sizeof detail,
             "the job is %s (%zu of %zu frames done); poll /v1/jobs/%s",
             srv_job_state_name(v.state), v.frames_done, v.frames_total,
             v.id);
  return problem(r, 409, "/problems/job-not-done", "Result not ready", detail,
                 NULL, NULL);
}

/* The request is complete (headers and body): answer or hand it off. */
static enum MHD_Result dispatch(srv_req *r)
{
  srv_server *s = r->srv;
  if (r->too_large) {
    char detail[160];
    snprintf(detail, sizeof detail,
             "the body has %zu bytes; the limit is %zu (KMORPH_MAX_BODY)",
             r->seen, s->cfg.max_body);
    return problem(r, 413, "/problems/body-too-large", "Body too large",
                   detail, NULL, NULL);
  }
  if (r->no_memory) {
    srv_metrics_reject(s->metrics, "body_memory");
    return problem(r, 503, "/problems/overloaded", "Overloaded",
                   "the request bodies being received fill the memory kept "
                   "for them (KMORPH_BODY_MEMORY); retry after the time in "
                   "Retry-After",
                   NULL, NULL);
  }
  switch (r->route) {
  case SRV_R_INDEX:
    return serve_file(r, "index.html");
  case SRV_R_STATIC:
    return serve_file(r, r->static_name);
  case SRV_R_HEALTHZ:
    return answer(r, 200, JSON, (char *)"{\"status\":\"ok\"}", 15, false);
  case SRV_R_READYZ:
    if (atomic_load(&s->draining))
      return problem(r, 503, "/problems/shutting-down", "Shutting down",
                     "the service is stopping", NULL, NULL);
    return answer(r, 200, JSON, (char *)"{\"status\":\"ready\"}", 18, false);
  case SRV_R_METRICS:
    return serve_metrics(r);
  case SRV_R_OPENAPI: {
    const char *doc = api_openapi_json();
    return answer(r, 200, JSON, (char *)doc, strlen(doc), false);
  }
  case SRV_R_JOB:
    return serve_job(r);
  case SRV_R_JOB_RESULT:
    return serve_result(r);
  case SRV_R_SIGNATURE:
  case SRV_R_RECONSTRUCT:
  case SRV_R_MORPH:
  case SRV_R_JOBS:
    return hand_off(r);
  case SRV_R_OTHER:
  case SRV_R_COUNT:
    break;
  }
  return problem(r, 404, "/problems/not-found", "Not found",
                 "no such resource", NULL, NULL);
}

static bool json_content_type(const char *ct)
{
  /* application/json, or any application/<x>+json, parameters allowed. */
  size_t n = strcspn(ct, ";");
  while (n > 0 && (ct[n - 1] == ' ' || ct[n - 1] == '\t'))
    n--;
  if (n == 16 && strncasecmp(ct, "application/json", 16) == 0)
    return true;
  return n > 17 && strncasecmp(ct, "application/", 12) == 0 &&
         strncasecmp(ct + n - 5, "+json", 5) == 0;
}

/* The headers are in: refuse what can be refused before the body. Returns
 * MHD_YES with nothing queued to receive the body. */
static enum MHD_Result on_headers(srv_req *r)
{
  srv_server *s = r->srv;
  if (strcmp(r->method, "OPTIONS") == 0) {
    if (r->route == SRV_R_OTHER)
      return problem(r, 404, "/problems/not-found", "Not found",
                     "no such resource", NULL, NULL);
    struct MHD_Response *resp =
        MHD_create_response_from_buffer(0, (void *)"", MHD_RESPMEM_PERSISTENT);
    if (resp == NULL)
      return MHD_NO;
    add_common_headers(r, resp, 204);
    MHD_add_response_header(resp, MHD_HTTP_HEADER_ALLOW,
                            allowed_methods(r->route));
    if (cors_origin(r) != NULL) {
      MHD_add_response_header(resp, "Access-Control-Allow-Methods",
                              allowed_methods(r->route));
      MHD_add_response_header(resp, "Access-Control-Allow-Headers",
                              "Content-Type, Accept, X-Request-Id");
      MHD_add_response_header(resp, "Access-Control-Max-Age", "600");
    }
    enum MHD_Result ok = MHD_queue_response(r->conn, 204, resp);
    MHD_destroy_response(resp);
    r->status = 204;
    atomic_store(&r->phase, PH_ANSWERED);
    return ok;
  }
  if (r->route == SRV_R_OTHER)
    return problem(r, 404, "/problems/not-found", "Not found",
                   "no such resource", NULL, NULL);
  if (!method_allowed(r->route, r->method)) {
    char detail[128];
    snprintf(detail, sizeof detail, "%s is not allowed here; allowed: %s",
             r->method, allowed_methods(r->route));
    return problem(r, 405, "/problems/method-not-allowed",
                   "Method not allowed", detail, NULL, NULL);
  }
  if (is_compute(r->route)) {
    const char *ct = MHD_lookup_connection_value(r->conn, MHD_HEADER_KIND,
                                                 MHD_HTTP_HEADER_CONTENT_TYPE);
    if (ct != NULL && !json_content_type(ct)) {
      char detail[200];
      snprintf(detail, sizeof detail,
               "the body must be application/json, not %.120s", ct);
      return problem(r, 415, "/problems/unsupported-media-type",
                     "Unsupported media type", detail, NULL, NULL);
    }
    const char *accept = MHD_lookup_connection_value(r->conn, MHD_HEADER_KIND,
                                                     MHD_HTTP_HEADER_ACCEPT);
    if (accept != NULL && (r->accept = strdup(accept)) == NULL)
      return MHD_NO;
  }
  const char *cl = MHD_lookup_connection_value(
      r->conn, MHD_HEADER_KIND, MHD_HTTP_HEADER_CONTENT_LENGTH);
  if (cl != NULL) {
    char *end = NULL;
    unsigned long long n = strtoull(cl, &end, 10);
    if (end != cl && n > s->cfg.max_body) {
      r->seen = (size_t)n;
      r->too_large = true;
      return dispatch(r); /* 413 at once; the body is never read */
    }
  }
  return MHD_YES;
}

/* Count a body buffer of cap bytes in the budget of bodies in flight
 * (the whole daemon's): false, with nothing counted, if it does not fit. */
static bool hold_body_bytes(srv_req *r, size_t cap)
{
  srv_server *s = r->srv;
  size_t extra = cap > r->held ? cap - r->held : 0;
  size_t cur = atomic_load(&s->body_bytes);
  do {
    if (cur + extra > s->cfg.body_memory)
      return false;
  } while (!atomic_compare_exchange_weak(&s->body_bytes, &cur, cur + extra));
  r->held += extra;
  return true;
}

/* Collect a body chunk (for compute routes) or count it (others). */
static enum MHD_Result on_body(srv_req *r, const char *data, size_t size)
{
  srv_server *s = r->srv;
  if (srv_now() - r->t0 > s->cfg.request_time) {
    /* A client trickling its body cannot hold the connection: MHD's idle
     * timeout would never fire while bytes keep coming. */
    r->cut = "request time limit";
    return MHD_NO;
  }
  r->seen += size;
  if (r->too_large || r->seen > s->cfg.max_body) {
    r->too_large = true;
    release_body(r);
    return MHD_YES;
  }
  if (!is_compute(r->route) || r->no_memory)
    return MHD_YES;
  if (r->len + size + 1 > r->cap) {
    size_t ncap = r->cap ? r->cap : 4096;
    while (ncap < r->len + size + 1)
      ncap *= 2;
    if (ncap > s->cfg.max_body + 1)
      ncap = s->cfg.max_body + 1;
    if (!hold_body_bytes(r, ncap)) {
      /* Counted and dropped like a body over the size limit; answered
       * 503 when it has arrived. */
      release_body(r);
      r->no_memory = true;
      return MHD_YES;
    }
    char *nb = realloc(r->body, ncap);
    if (nb == NULL) {
      r->cut = "out of memory";
      return MHD_NO;
    }
    r->body = nb;
    r->cap = ncap;
  }
  memcpy(r->body + r->len, data, size);
  r->len += size;
  r->body[r->len] = '\0';
  return MHD_YES;
}

/* The record of a request whose headers are in: r is the one the URI log
 * callback started (NULL if it ran out of memory). */
static srv_req *req_new(srv_server *s, struct MHD_Connection *c,
                        const char *url, const char *method, srv_req *r)
{
  if (r == NULL && (r = calloc(1, sizeof *r)) == NULL)
    return NULL;
  r->begun = true;
  r->srv = s;
  r->conn = c;
  r->t0 = srv_now();
  atomic_init(&r->phase, PH_BODY);
  api_response_init(&r->resp);
  snprintf(r->method, sizeof r->method, "%s", method);
  snprintf(r->path, sizeof r->path, "%s", url);
  for (char *p = r->path; *p; p++)
    if ((unsigned char)*p < 0x21 || (unsigned char)*p > 0x7e || *p == '"' ||
        *p == '\\')
      *p = '?';
  r->is_head = strcmp(method, "HEAD") == 0;
  const char *rid =
      MHD_lookup_connection_value(c, MHD_HEADER_KIND, "X-Request-Id");
  if (srv_request_id_ok(rid))
    snprintf(r->rid, sizeof r->rid, "%s", rid);
  else
    srv_random_hex(r->rid, 16);
  r->route = parse_route(r, url);
  atomic_fetch_add(&s->inflight, 1);
  return r;
}

static enum MHD_Result on_request(void *cls, struct MHD_Connection *c,
                                  const char *url, const char *method,
                                  const char *version, const char *upload,
                                  size_t *upload_size, void **req_cls)
{
  srv_server *s = cls;
  srv_req *r = *req_cls;
  if (r == NULL || !r->begun) {
    r = req_new(s, c, url, method, r);
    if (r == NULL)
      return MHD_NO;
    *req_cls = r;
    r->http11 = version != NULL && strcmp(version, "HTTP/1.1") == 0;
    srv_watch_header_done(conn_of(r), r->t0);
    /* Framing first: a request framed one way here and another way by a
     * proxy must not be answered as if it were understood. */
    srv_http_verdict v;
    srv_http_check(c, method, version, r->target.raw ? &r->target : NULL,
                   &v);
    if (v.status != 0) {
      r->must_close = true;
      return v.status == 501
                 ? problem(r, 501, "/problems/not-implemented",
                           "Not implemented", v.detail, NULL, NULL)
                 : problem(r, 400, "/problems/bad-request", "Bad request",
                           v.detail, NULL, NULL);
    }
    if (srv_conn_reserved(conn_of(r)) && !is_probe(r->route))
      return reserved_refusal(r);
    return on_headers(r);
  }
  if (*upload_size > 0) {
    size_t n = *upload_size;
    *upload_size = 0;
    if (atomic_load(&r->phase) == PH_ANSWERED)
      return MHD_YES; /* answered on the headers: drop the rest */
    return on_body(r, upload, n);
  }
  switch (atomic_load(&r->phase)) {
  case PH_BODY:
    return dispatch(r);
  case PH_READY:
    atomic_fetch_sub(&s->suspended, 1);
    r->counted = false;
    return answer_api(r, &r->resp);
  case PH_WAIT:     /* not reached: MHD does not call while suspended */
  case PH_ANSWERED: /* already queued */
    break;
  }
  return MHD_YES;
}

/* The raw request target, before libmicrohttpd splits and decodes it;
 * the request's record starts here (the value returned is the handler's
 * first *req_cls). */
static void *on_uri(void *cls, const char *uri, struct MHD_Connection *c)
{
  (void)c;
  srv_req *r = calloc(1, sizeof *r);
  if (r == NULL)
    return NULL;
  r->srv = cls;
  srv_http_target_scan(&r->target, uri);
  return r;
}

/* --------------------------------------------------------- log and stats */

/* Connections open and close: their watch records (watch.h). */
static void on_connection(void *cls, struct MHD_Connection *c,
                          void **socket_context,
                          enum MHD_ConnectionNotificationCode code)
{
  srv_server *s = cls;
  if (code == MHD_CONNECTION_NOTIFY_STARTED) {
    const union MHD_ConnectionInfo *ci =
        MHD_get_connection_info(c, MHD_CONNECTION_INFO_CONNECTION_FD);
    *socket_context =
        ci ? srv_watch_open(s->watch, ci->connect_fd, srv_now()) : NULL;
  } else if (code == MHD_CONNECTION_NOTIFY_CLOSED) {
    srv_watch_close(s->watch, *socket_context);
    *socket_context = NULL;
  }
}

static void on_completed(void *cls, struct MHD_Connection *c, void **req_cls,
                         enum MHD_RequestTerminationCode toe)
{
  srv_server *s = cls;
  srv_req *r = *req_cls;
  (void)c;
  if (r == NULL)
    return;
  *req_cls = NULL;
  if (!r->begun) { /* refused by libmicrohttpd before the handler ran */
    free(r);
    return;
  }
  /* A client that left while its request computed: MHD completes the
   * resumed connection without calling the handler again. (Completion
   * never happens while a worker still owns the request: MHD does not
   * process suspended connections.) */
  if (r->counted)
    atomic_fetch_sub(&s->suspended, 1);
  srv_watch_request_done(conn_of(r), srv_now());
  double dt = srv_now() - r->t0;
  const char *why = r->cut;
  if (why == NULL && toe != MHD_REQUEST_TERMINATED_COMPLETED_OK)
    why = toe == MHD_REQUEST_TERMINATED_TIMEOUT_REACHED    ? "idle timeout"
          : toe == MHD_REQUEST_TERMINATED_DAEMON_SHUTDOWN ? "shutdown"
          : toe == MHD_REQUEST_TERMINATED_CLIENT_ABORT    ? "client closed"
                                                          : "connection error";
  srv_metrics_observe(s->metrics, r->route, r->status ? r->status : 0, dt);
  if (s->cfg.access_log) {
    char when[32];
    time_t now = time(NULL);
    struct tm tm;
    gmtime_r(&now, &tm);
    strftime(when, sizeof when, "%Y-%m-%dT%H:%M:%SZ", &tm);
    char method[sizeof r->method];
    srv_http_log_token(method, sizeof method, r->method);
    fprintf(s->log,
            "%s access method=%s path=\"%s\" status=%d bytes=%zu "
            "duration_ms=%.3f request_id=%s%s%s%s\n",
            when, method, r->path, r->status, r->bytes, dt * 1e3, r->rid,
            why ? " closed=\"" : "", why ? why : "", why ? "\"" : "");
  }
  api_response_free(&r->resp);
  release_body(r);
  free(r->accept);
  free(r);
  atomic_fetch_sub(&s->inflight, 1);
}

/* Seconds an I/O thread with no connection waits after accept failed for
 * want of descriptors (nginx pauses 500 ms). */
static const double ACCEPT_PAUSE = 0.25;

/* libmicrohttpd's messages, one line a second per kind (its format
 * string): accept failing with EMFILE repeats as fast as the loop spins.
 * With connections open, libmicrohttpd stops accepting by itself until one
 * closes; an I/O thread without any would retry at once for ever ("at
 * FIRST connection"), so that thread, having nothing else to serve,
 * pauses here. */
static void mhd_log(void *cls, const char *fmt, va_list ap)
{
  srv_server *s = cls;
  char msg[512];
  vsnprintf(msg, sizeof msg, fmt, ap);
  size_t n = strlen(msg);
  while (n > 0 && msg[n - 1] == '\n')
    msg[--n] = '\0';
  unsigned long more = 0;
  if (srv_log_admit(s->logger, fmt, msg, &more)) {
    if (more > 0)
      fprintf(s->log, "kmorphd: http: %s (%lu more suppressed)\n", msg, more);
    else
      fprintf(s->log, "kmorphd: http: %s\n", msg);
  }
  if (strstr(fmt, "resource limit at FIRST") != NULL)
    srv_sleep(ACCEPT_PAUSE);
}

/* ------------------------------------------------------------- lifecycle */

srv_server *srv_server_create(const srv_config *cfg, srv_log *logger)
{
  srv_server *s = calloc(1, sizeof *s);
  if (s == NULL)
    return NULL;
  s->cfg = *cfg;
  s->logger = logger;
  s->log = srv_log_stream(logger);
  s->quiesced_fd = MHD_INVALID_SOCKET;
  atomic_init(&s->draining, false);
  atomic_init(&s->abort_compute, false);
  atomic_init(&s->suspended, 0);
  atomic_init(&s->inflight, 0);
  atomic_init(&s->body_bytes, 0);
  api_config_default(&s->api);
  s->api.max_body_bytes = cfg->max_body;
  s->api.max_control_points = cfg->max_points;
  s->api.max_frames_sync = cfg->max_frames;
  s->api.max_frames_job = cfg->max_job_frames;
  s->api.max_samples = cfg->max_samples;
  s->api.max_output_bytes = cfg->max_output;
  s->metrics = srv_metrics_create();
  srv_watch_limits wl = {
      .header_time = cfg->header_time,
      .request_time = cfg->request_time,
      .send_time = cfg->send_time,
      .idle_time = (double)cfg->timeout,
      /* a probe sends its few header bytes at once */
      .reserved_header_time = cfg->header_time < 1.0 ? cfg->header_time : 1.0,
      .normal = cfg->max_connections};
  s->watch = srv_watch_create(&wl, s->log);
  s->store = srv_jobstore_memory_create(cfg->job_ttl, cfg->job_keep,
                                        cfg->result_memory);
  s->jobs = s->store ? srv_jobs_create(s->store, cfg->max_jobs, cfg->job_time)
                     : NULL;
  s->pool = s->jobs ? srv_pool_create(cfg->workers, cfg->queue,
                                      srv_jobs_work, s->jobs)
                    : NULL;
  if (s->metrics == NULL || s->pool == NULL || s->watch == NULL) {
    fprintf(s->log, "kmorphd: cannot create the compute pool (%u workers)\n",
            cfg->workers);
    srv_server_destroy(s);
    return NULL;
  }
  return s;
}

int srv_server_start(srv_server *s)
{
  struct sockaddr_storage ss;
  memset(&ss, 0, sizeof ss);
  unsigned flags = MHD_USE_AUTO_INTERNAL_THREAD | MHD_ALLOW_SUSPEND_RESUME |
                   MHD_USE_ERROR_LOG;
  struct sockaddr_in *v4 = (struct sockaddr_in *)&ss;
  struct sockaddr_in6 *v6 = (struct sockaddr_in6 *)&ss;
  if (inet_pton(AF_INET, s->cfg.bind, &v4->sin_addr) == 1) {
    v4->sin_family = AF_INET;
    v4->sin_port = htons((uint16_t)s->cfg.port);
  } else if (inet_pton(AF_INET6, s->cfg.bind, &v6->sin6_addr) == 1) {
    v6->sin6_family = AF_INET6;
    v6->sin6_port = htons((uint16_t)s->cfg.port);
    flags |= MHD_USE_IPv6;
  } else {
    fprintf(s->log, "kmorphd: --bind \"%s\" is not an IPv4 or IPv6 address\n",
            s->cfg.bind);
    return -1;
  }
  s->daemon = MHD_start_daemon(
      flags, (uint16_t)s->cfg.port, NULL, NULL, &on_request, s,
      MHD_OPTION_EXTERNAL_LOGGER, &mhd_log, s, MHD_OPTION_SOCK_ADDR, (struct sockaddr *)&ss,
      MHD_OPTION_THREAD_POOL_SIZE, (unsigned int)s->cfg.io_threads,
      MHD_OPTION_CONNECTION_LIMIT,
      (unsigned int)(s->cfg.max_connections + s->cfg.reserved),
      MHD_OPTION_PER_IP_CONNECTION_LIMIT, (unsigned int)s->cfg.per_ip,
      MHD_OPTION_CONNECTION_TIMEOUT, (unsigned int)s->cfg.timeout,
      MHD_OPTION_NOTIFY_CONNECTION, &on_connection, s,
      MHD_OPTION_NOTIFY_COMPLETED, &on_completed, s,
      MHD_OPTION_URI_LOG_CALLBACK, &on_uri, s, MHD_OPTION_END);
  if (s->daemon == NULL) {
    fprintf(s->log, "kmorphd: cannot listen on %s port %u (in use?)\n",
            s->cfg.bind, s->cfg.port);
    return -1;
  }
  const union MHD_DaemonInfo *info =
      MHD_get_daemon_info(s->daemon, MHD_DAEMON_INFO_BIND_PORT);
  s->port = info ? info->port : s->cfg.port;
  return 0;
}

unsigned srv_server_port(const srv_server *s) { return s->port; }

/* Wait until cond(s) holds or the deadline passes; true if it held. */
static bool wait_until(srv_server *s, bool (*cond)(srv_server *),
                       double deadline)
{
  for (;;) {
    if (cond(s))
      return true;
    if (srv_now() >= deadline)
      return false;
    srv_sleep(0.01);
  }
}

static bool compute_idle(srv_server *s)
{
  return atomic_load(&s->suspended) == 0 && srv_jobs_live(s->jobs) == 0 &&
         srv_pool_depth(s->pool) == 0;
}

static bool requests_done(srv_server *s)
{
  return atomic_load(&s->inflight) == 0;
}

/* Seconds the computations still running when the grace ends get, once
 * told to stop (abort_compute), to answer 503 and resume their
 * connection: they check the flag between frames and within their long
 * loops, far more often than this. */
static const double ABORT_WAIT = 2.0;

/* Refuse new connections at once, so that load balancers and clients
 * move on: libmicrohttpd stops polling the listening socket, and
 * shutdown() takes it out of the LISTEN state (connect gets ECONNREFUSED,
 * connections not yet accepted are reset). The descriptor itself stays
 * open until the HTTP daemon stops, as libmicrohttpd's threads may still
 * hold its number. */
static void stop_listening(srv_server *s)
{
  s->quiesced_fd = MHD_quiesce_daemon(s->daemon);
  if (s->quiesced_fd != MHD_INVALID_SOCKET)
    shutdown(s->quiesced_fd, SHUT_RDWR);
}

int srv_server_shutdown(srv_server *s)
{
  double deadline = srv_now() + s->cfg.shutdown_grace;
  atomic_store(&s->draining, true);
  if (s->daemon == NULL)
    return 0;
  stop_listening(s);
  /* Jobs stop between frames; queued requests are answered 503 by the
   * workers; requests already computing have the grace to finish. */
  srv_jobs_cancel_all(s->jobs);
  srv_pool_stop(s->pool);
  if (!wait_until(s, compute_idle, deadline)) {
    fprintf(s->log,
            "kmorphd: shutdown grace of %g s passed with %zu requests still "
            "computing: stopping them\n",
            s->cfg.shutdown_grace, (size_t)atomic_load(&s->suspended));
    atomic_store(&s->abort_compute, true);
    deadline = srv_now() + ABORT_WAIT;
    if (!wait_until(s, compute_idle, deadline)) {
      fprintf(s->log,
              "kmorphd: %zu requests still computing %g s after being "
              "stopped\n",
              (size_t)atomic_load(&s->suspended), ABORT_WAIT);
      return -1;
    }
  }
  /* Give answers already queued (or bodies still arriving) until the
   * deadline to complete; idle keep-alive connections do not count. */
  if (!wait_until(s, requests_done, deadline))
    fprintf(s->log, "kmorphd: closing %zu unfinished requests\n",
            (size_t)atomic_load(&s->inflight));
  MHD_stop_daemon(s->daemon);
  s->daemon = NULL;
  if (s->quiesced_fd != MHD_INVALID_SOCKET)
    close(s->quiesced_fd);
  s->quiesced_fd = MHD_INVALID_SOCKET;
  return 0;
}

void srv_server_destroy(srv_server *s)
{
  if (s == NULL)
    return;
  if (s->daemon != NULL)
    MHD_stop_daemon(s->daemon);
  srv_pool_destroy(s->pool);
  srv_jobs_destroy(s->jobs);
  if (s->store)
    s->store->ops->destroy(s->store);
  srv_metrics_destroy(s->metrics);
  srv_watch_destroy(s->watch); /* after the HTTP daemon: it closes records */
  free(s);
}
