/* reply.c - queueing kmorphd's answers with their common headers (see
 * reply.h). */
#include "reply.h"

#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include "route.h"
#include "util.h"

srv_conn *srv__req_conn(const srv_req *r) {
  const union MHD_ConnectionInfo *ci =
      MHD_get_connection_info(r->conn, MHD_CONNECTION_INFO_SOCKET_CONTEXT);
  return ci ? ci->socket_context : NULL;
}

/* The origin to allow for this request, or NULL for no CORS headers. */
static const char *cors_origin(const srv_req *r) {
  const char *origin =
      MHD_lookup_connection_value(r->conn, MHD_HEADER_KIND, "Origin");
  const char *list = r->srv->cfg.cors_origins;
  if (origin == NULL || list[0] == '\0') return NULL;
  size_t olen = strlen(origin);
  const char *p = list;
  while (*p) {
    while (*p == ' ' || *p == ',') p++;
    const char *e = p;
    while (*e && *e != ',') e++;
    const char *t = e;
    while (t > p && t[-1] == ' ') t--;
    size_t n = (size_t)(t - p);
    if (n == 1 && *p == '*') return "*";
    if (n > 0 && n == olen && strncmp(p, origin, n) == 0) return origin;
    p = e;
  }
  return NULL;
}

static void add_common_headers(srv_req *r, struct MHD_Response *resp,
                               int status) {
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
                            srv__route_allowed_methods(r->route));
  if (r->route == SRV_R_JOB || r->route == SRV_R_JOBS ||
      r->route == SRV_R_JOB_RESULT || r->route == SRV_R_METRICS ||
      r->route == SRV_R_HEALTHZ || r->route == SRV_R_READYZ)
    MHD_add_response_header(resp, MHD_HTTP_HEADER_CACHE_CONTROL, "no-store");
  if (atomic_load(&s->draining) || r->must_close)
    MHD_add_response_header(resp, MHD_HTTP_HEADER_CONNECTION, "close");
}

enum MHD_Result srv__queue(srv_req *r, int status, struct MHD_Response *resp,
                           size_t len) {
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
  srv_watch_answer_queued(srv__req_conn(r), srv_now());
  return ok;
}

enum MHD_Result srv__answer(srv_req *r, int status, const char *ctype,
                            char *body, size_t len, bool owned) {
  struct MHD_Response *resp = MHD_create_response_from_buffer(
      len, body, owned ? MHD_RESPMEM_MUST_FREE : MHD_RESPMEM_PERSISTENT);
  if (resp == NULL) {
    if (owned) free(body);
    r->cut = "out of memory";
    return MHD_NO;
  }
  if (ctype != NULL)
    MHD_add_response_header(resp, MHD_HTTP_HEADER_CONTENT_TYPE, ctype);
  return srv__queue(r, status, resp, len);
}

enum MHD_Result srv__answer_api(srv_req *r, api_response *res) {
  if (res->body == NULL) {
    static const char oom[] =
        "{\"type\":\"/problems/internal\",\"title\":\"Out of memory\","
        "\"status\":500}";
    api_response_free(res);
    return srv__answer(r, 500, "application/problem+json", (char *)oom,
                       sizeof oom - 1, false);
  }
  char *body = res->body;
  res->body = NULL;
  return srv__answer(r, res->status, res->content_type, body, res->length,
                     true);
}

enum MHD_Result srv__problem(srv_req *r, int status, const char *type,
                             const char *title, const char *detail,
                             const char *pointer, const char *message) {
  api_response res;
  api_response_init(&res);
  api_problem(&res, status, type, title, detail, pointer, message, r->rid);
  return srv__answer_api(r, &res);
}

enum MHD_Result srv__answer_json(srv_req *r, int status, const char *fmt, ...) {
  char tmp[1024];
  va_list ap;
  va_start(ap, fmt);
  int n = vsnprintf(tmp, sizeof tmp, fmt, ap);
  va_end(ap);
  if (n < 0 || (size_t)n >= sizeof tmp)
    return srv__problem(r, 500, "/problems/internal", "Internal error",
                        "response too long", NULL, NULL);
  char *body = malloc((size_t)n + 1);
  if (body == NULL) return MHD_NO;
  memcpy(body, tmp, (size_t)n + 1);
  return srv__answer(r, status, SRV_JSON_TYPE, body, (size_t)n, true);
}

enum MHD_Result srv__answer_preflight(srv_req *r) {
  struct MHD_Response *resp =
      MHD_create_response_from_buffer(0, (void *)"", MHD_RESPMEM_PERSISTENT);
  if (resp == NULL) return MHD_NO;
  add_common_headers(r, resp, 204);
  const char *allow = srv__route_allowed_methods(r->route);
  MHD_add_response_header(resp, MHD_HTTP_HEADER_ALLOW, allow);
  if (cors_origin(r) != NULL) {
    MHD_add_response_header(resp, "Access-Control-Allow-Methods", allow);
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
