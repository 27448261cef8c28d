/* reply.c - queueing kmorphd's answers with their common headers (see
 * reply.h). */
#include "reply.h"

#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include "conneg.h"
#include "gzip.h"
#include "route.h"
#include "util.h"

/* Seconds a client is told to wait before polling a job again. */
#define POLL_SECONDS "1"

/* ------------------------------------------------ content negotiation */

/* The media types a route answers with when they do not depend on what
 * it finds (files, job results: checked where they are found); *n = 0
 * for those. */
static const char *const *route_types(srv_route route, size_t *n) {
  static const char *const JSON[] = {SRV_JSON_TYPE};
  static const char *const MORPH[] = {SRV_JSON_TYPE, "image/svg+xml"};
  static const char *const METRICS[] = {"text/plain"};
  switch (route) {
  case SRV_R_HEALTHZ:
  case SRV_R_READYZ:
  case SRV_R_OPENAPI:
  case SRV_R_SIGNATURE:
  case SRV_R_RECONSTRUCT:
  case SRV_R_JOBS:
  case SRV_R_JOB: *n = 1; return JSON;
  case SRV_R_MORPH: *n = 2; return MORPH;
  case SRV_R_METRICS: *n = 1; return METRICS;
  default: *n = 0; return NULL;
  }
}

/* True when answers on the route may be sent gzip-compressed. */
static bool route_compressible(srv_route route) {
  switch (route) {
  case SRV_R_INDEX:
  case SRV_R_STATIC:
  case SRV_R_OPENAPI:
  case SRV_R_METRICS:
  case SRV_R_SIGNATURE:
  case SRV_R_RECONSTRUCT:
  case SRV_R_MORPH:
  case SRV_R_JOB_RESULT: return true;
  default: return false;
  }
}

static const char *header(const srv_req *r, const char *name) {
  return MHD_lookup_connection_value(r->conn, MHD_HEADER_KIND, name);
}

bool srv__acceptable(srv_req *r) {
  size_t n = 0;
  const char *const *types = route_types(r->route, &n);
  if (n == 0 || strcmp(r->method, "DELETE") == 0) return true;
  return srv_accept_pick(header(r, MHD_HTTP_HEADER_ACCEPT), types, n) >= 0;
}

bool srv__accepts_type(srv_req *r, const char *ctype) {
  char t[128];
  size_t n = strcspn(ctype, "; ");
  snprintf(t, sizeof t, "%.*s", (int)(n < sizeof t ? n : sizeof t - 1), ctype);
  return srv_accept_q(header(r, MHD_HTTP_HEADER_ACCEPT), t) > 0;
}

enum MHD_Result srv__not_acceptable(srv_req *r, const char *offered) {
  char list[160] = "";
  if (offered == NULL) {
    size_t n = 0;
    const char *const *types = route_types(r->route, &n);
    for (size_t i = 0; i < n; i++)
      snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s",
               i ? ", " : "", types[i]);
    offered = list;
  }
  char detail[300];
  snprintf(detail, sizeof detail,
           "the Accept header allows none of the media types this path "
           "answers with: %s",
           offered);
  return srv__problem(r, 406, "/problems/not-acceptable", "Not acceptable",
                      detail, NULL, NULL);
}

/* The Vary header of r's answers: what, besides the target, chose it. */
static void add_vary(srv_req *r, struct MHD_Response *resp, bool by_origin) {
  char vary[64] = "";
  if (r->route != SRV_R_OTHER) snprintf(vary, sizeof vary, "Accept");
  if (route_compressible(r->route))
    snprintf(vary + strlen(vary), sizeof vary - strlen(vary), "%s",
             vary[0] ? ", Accept-Encoding" : "Accept-Encoding");
  if (by_origin)
    snprintf(vary + strlen(vary), sizeof vary - strlen(vary), "%s",
             vary[0] ? ", Origin" : "Origin");
  if (vary[0]) MHD_add_response_header(resp, MHD_HTTP_HEADER_VARY, vary);
}

/* A gzip-coded answer names its decoded length, which a client showing
 * download progress counts (fetch hands it decoded bytes) and which
 * neither Content-Length (the coded bytes) nor a chunked answer give. */
static void add_uncompressed_length(struct MHD_Response *resp, size_t len) {
  char n[24];
  snprintf(n, sizeof n, "%zu", len);
  MHD_add_response_header(resp, "X-Uncompressed-Length", n);
}

bool srv__wants_gzip(srv_req *r) {
  return srv_coding_q(header(r, MHD_HTTP_HEADER_ACCEPT_ENCODING), "gzip") > 0;
}

/* A body compressed as it is sent has no length to announce: a HEAD
 * request (no body) is answered with the identity form's. */
static bool may_stream_gzip(srv_req *r) {
  return strcmp(r->method, "HEAD") != 0 && srv__wants_gzip(r);
}

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
    MHD_add_response_header(resp, "Access-Control-Expose-Headers",
                            "Location, Retry-After, X-Request-Id, ETag, "
                            "X-Uncompressed-Length");
  }
  add_vary(r, resp, origin != NULL && strcmp(origin, "*") != 0);
  if (status == 429 || status == 503) {
    char ra[16];
    snprintf(ra, sizeof ra, "%u", s->cfg.retry_after);
    MHD_add_response_header(resp, MHD_HTTP_HEADER_RETRY_AFTER, ra);
  } else if (status == 202 || r->poll_hint) {
    MHD_add_response_header(resp, MHD_HTTP_HEADER_RETRY_AFTER, POLL_SECONDS);
  }
  if (status == 405)
    MHD_add_response_header(resp, MHD_HTTP_HEADER_ALLOW,
                            srv__route_allowed_methods(r->route));
  if ((r->route == SRV_R_JOB || r->route == SRV_R_JOBS ||
       r->route == SRV_R_JOB_RESULT || r->route == SRV_R_METRICS ||
       r->route == SRV_R_HEALTHZ || r->route == SRV_R_READYZ) &&
      MHD_get_response_header(resp, MHD_HTTP_HEADER_CACHE_CONTROL) == NULL)
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
  if (owned && status == 200 && srv_gzip_worth(ctype, len) &&
      route_compressible(r->route) && may_stream_gzip(r)) {
    struct MHD_Response *gz =
        srv_gzip_stream(body, len, free, body, &r->srv->gz_streams);
    if (gz != NULL) {
      MHD_add_response_header(gz, MHD_HTTP_HEADER_CONTENT_TYPE, ctype);
      add_uncompressed_length(gz, len);
      return srv__queue(r, status, gz, len);
    }
  }
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
                            "Content-Type, Accept, X-Request-Id, "
                            "If-None-Match");
    MHD_add_response_header(resp, "Access-Control-Max-Age", "600");
  }
  enum MHD_Result ok = MHD_queue_response(r->conn, 204, resp);
  MHD_destroy_response(resp);
  r->status = 204;
  atomic_store(&r->phase, PH_ANSWERED);
  return ok;
}

enum MHD_Result srv__answer_body(srv_req *r, int status, const srv_body *b) {
  bool gz = b->gz != NULL && srv__wants_gzip(r);
  bool stream = !gz && b->stream_gzip && srv_gzip_worth(b->type, b->len) &&
                may_stream_gzip(r);
  const char *etag = gz || stream ? b->gz_etag : b->etag;
  struct MHD_Response *resp = NULL;
  size_t len = 0;
  bool fresh = etag != NULL &&
               srv_etag_match(header(r, MHD_HTTP_HEADER_IF_NONE_MATCH), etag);
  if (fresh) { /* RFC 9110 13.1.2: the client's copy is current */
    status = 304;
    resp =
        MHD_create_response_from_buffer(0, (void *)"", MHD_RESPMEM_PERSISTENT);
    if (b->release != NULL) b->release(b->cls);
  } else if (gz) {
    len = b->gz_len;
    resp = MHD_create_response_from_buffer_with_free_callback_cls(
        len, (void *)b->gz, b->release, b->cls);
    if (resp != NULL) {
      MHD_add_response_header(resp, MHD_HTTP_HEADER_CONTENT_ENCODING, "gzip");
      add_uncompressed_length(resp, b->len);
    }
  } else {
    len = b->len;
    if (stream && (resp = srv_gzip_stream(b->data, len, b->release, b->cls,
                                          &r->srv->gz_streams)) != NULL)
      add_uncompressed_length(resp, len);
    if (resp == NULL) { /* too many streams: the identity form */
      etag = b->etag;
      resp = MHD_create_response_from_buffer_with_free_callback_cls(
          len, (void *)b->data, b->release, b->cls);
    }
  }
  if (resp == NULL) {
    if (!fresh && b->release != NULL) b->release(b->cls);
    r->cut = "out of memory";
    return MHD_NO;
  }
  if (!fresh)
    MHD_add_response_header(resp, MHD_HTTP_HEADER_CONTENT_TYPE, b->type);
  if (etag != NULL) MHD_add_response_header(resp, MHD_HTTP_HEADER_ETAG, etag);
  if (b->cache_control != NULL)
    MHD_add_response_header(resp, MHD_HTTP_HEADER_CACHE_CONTROL,
                            b->cache_control);
  return srv__queue(r, status, resp, len);
}
