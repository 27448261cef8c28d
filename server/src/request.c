/* request.c - a request from its raw target to its complete body, then
 * answered or handed off (see request.h).
 */
#include "request.h"

#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "compute.h"
#include "endpoints.h"
#include "framing.h"
#include "problems.h"
#include "reply.h"
#include "route.h"
#include "util.h"

/* ------------------------------------------------------- body budget */

void srv__body_release(srv_req *r) {
  free(r->body);
  r->body = NULL;
  r->len = r->cap = 0;
  atomic_fetch_sub(&r->srv->body_bytes, r->held);
  r->held = 0;
}

/* Count a body buffer of cap bytes in the budget of bodies in flight
 * (the whole daemon's): false, with nothing counted, if it does not fit. */
static bool hold_body_bytes(srv_req *r, size_t cap) {
  srv_server *s = r->srv;
  size_t extra = cap > r->held ? cap - r->held : 0;
  size_t cur = atomic_load(&s->body_bytes);
  do {
    if (cur + extra > s->cfg.body_memory) return false;
  } while (!atomic_compare_exchange_weak(&s->body_bytes, &cur, cur + extra));
  r->held += extra;
  return true;
}

/* ---------------------------------------------------------- dispatch */

/* The request is complete (headers and body): answer or hand it off. */
static enum MHD_Result dispatch(srv_req *r) {
  srv_server *s = r->srv;
  if (r->too_large) {
    char detail[160];
    snprintf(detail, sizeof detail,
             "the body has %zu bytes; the limit is %zu (KMORPH_MAX_BODY)",
             r->seen, s->cfg.max_body);
    return srv__problem(r, 413, "/problems/body-too-large", "Body too large",
                        detail, NULL, NULL);
  }
  if (r->no_memory) {
    srv_metrics_reject(s->metrics, "body_memory");
    return srv__problem(r, 503, "/problems/overloaded", "Overloaded",
                        "the request bodies being received fill the memory "
                        "kept for them (KMORPH_BODY_MEMORY); retry after the "
                        "time in Retry-After",
                        NULL, NULL);
  }
  switch (r->route) {
  case SRV_R_INDEX: return srv__serve_file(r, "index.html");
  case SRV_R_STATIC: return srv__serve_file(r, r->static_name);
  case SRV_R_HEALTHZ:
    return srv__answer(r, 200, SRV_JSON_TYPE, (char *)"{\"status\":\"ok\"}", 15,
                       false);
  case SRV_R_READYZ:
    if (atomic_load(&s->draining))
      return srv__problem(r, 503, "/problems/shutting-down", "Shutting down",
                          "the service is stopping", NULL, NULL);
    if (s->rjobs != NULL && !srv_rjobs_ready(s->rjobs))
      return srv__problem(r, 503, "/problems/job-store-unavailable",
                          "Job store unavailable",
                          "the job store (Redis, KMORPH_JOBS) cannot be "
                          "reached",
                          NULL, NULL);
    return srv__answer(r, 200, SRV_JSON_TYPE, (char *)"{\"status\":\"ready\"}",
                       18, false);
  case SRV_R_METRICS: return srv__serve_metrics(r);
  case SRV_R_OPENAPI: return srv__serve_openapi(r);
  case SRV_R_PROBLEM: return srv__serve_problem(r);
  case SRV_R_JOB: return srv__serve_job(r);
  case SRV_R_JOB_RESULT: return srv__serve_result(r);
  case SRV_R_SIGNATURE:
  case SRV_R_RECONSTRUCT:
  case SRV_R_MORPH:
  case SRV_R_JOBS: return srv__hand_off(r);
  case SRV_R_OTHER:
  case SRV_R_COUNT: break;
  }
  return srv__problem(r, 404, "/problems/not-found", "Not found",
                      "no such resource", NULL, NULL);
}

/* ----------------------------------------------------------- headers */

static bool json_content_type(const char *ct) {
  /* application/json, or any application/<x>+json, parameters allowed. */
  size_t n = strcspn(ct, ";");
  while (n > 0 && (ct[n - 1] == ' ' || ct[n - 1] == '\t')) n--;
  if (n == 16 && strncasecmp(ct, "application/json", 16) == 0) return true;
  return n > 17 && strncasecmp(ct, "application/", 12) == 0 &&
         strncasecmp(ct + n - 5, "+json", 5) == 0;
}

/* The headers are in: refuse what can be refused before the body. Returns
 * MHD_YES with nothing queued to receive the body. */
static enum MHD_Result on_headers(srv_req *r) {
  srv_server *s = r->srv;
  if (r->route == SRV_R_OTHER)
    return srv__problem(r, 404, "/problems/not-found", "Not found",
                        "no such resource", NULL, NULL);
  if (strcmp(r->method, "OPTIONS") == 0) return srv__answer_preflight(r);
  if (!srv__route_method_allowed(r->route, r->method)) {
    char detail[128];
    snprintf(detail, sizeof detail, "%s is not allowed here; allowed: %s",
             r->method, srv__route_allowed_methods(r->route));
    return srv__problem(r, 405, "/problems/method-not-allowed",
                        "Method not allowed", detail, NULL, NULL);
  }
  if (!srv__acceptable(r)) return srv__not_acceptable(r, NULL);
  if (srv__route_is_compute(r->route)) {
    const char *ct = MHD_lookup_connection_value(r->conn, MHD_HEADER_KIND,
                                                 MHD_HTTP_HEADER_CONTENT_TYPE);
    if (ct != NULL && !json_content_type(ct)) {
      char detail[200];
      snprintf(detail, sizeof detail,
               "the body must be application/json, not %.120s", ct);
      return srv__problem(r, 415, "/problems/unsupported-media-type",
                          "Unsupported media type", detail, NULL, NULL);
    }
    const char *accept = MHD_lookup_connection_value(r->conn, MHD_HEADER_KIND,
                                                     MHD_HTTP_HEADER_ACCEPT);
    if (accept != NULL && (r->accept = strdup(accept)) == NULL) return MHD_NO;
  }
  const char *cl = MHD_lookup_connection_value(r->conn, MHD_HEADER_KIND,
                                               MHD_HTTP_HEADER_CONTENT_LENGTH);
  if (cl != NULL) {
    char *end = NULL;
    unsigned long long n = strtoull(cl, &end, 10);
    if (end != cl && n > s->cfg.max_body) {
      r->seen = (size_t)n;
      r->too_large = true;
      return dispatch(r); /* 413 at once; the body is never read */
    }
    /* A declared body is counted in the budget of bodies in flight before
     * any of it is read: when it does not fit, the client hears so at once
     * (503) instead of sending it to be dropped. */
    if (end != cl && srv__route_is_compute(r->route) &&
        !hold_body_bytes(r, (size_t)n + 1)) {
      r->no_memory = true;
      return dispatch(r);
    }
  }
  return MHD_YES;
}

/* -------------------------------------------------------------- body */

/* Collect a body chunk (for compute routes) or count it (others). */
static enum MHD_Result on_body(srv_req *r, const char *data, size_t size) {
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
    srv__body_release(r);
    return MHD_YES;
  }
  if (!srv__route_is_compute(r->route) || r->no_memory) return MHD_YES;
  if (r->len + size + 1 > r->cap) {
    size_t ncap = r->cap ? r->cap : 4096;
    while (ncap < r->len + size + 1) ncap *= 2;
    if (ncap > s->cfg.max_body + 1) ncap = s->cfg.max_body + 1;
    if (r->held >= r->len + size + 1 && ncap > r->held)
      ncap = r->held; /* the declared length, counted already */
    if (!hold_body_bytes(r, ncap)) {
      /* Counted and dropped like a body over the size limit; answered
       * 503 when it has arrived. */
      srv__body_release(r);
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

/* ------------------------------------------------------- first call */

/* The record of a request whose headers are in: r is the one the URI log
 * callback started (NULL if it ran out of memory). */
static srv_req *req_new(srv_server *s, struct MHD_Connection *c,
                        const char *url, const char *method, srv_req *r) {
  if (r == NULL && (r = calloc(1, sizeof *r)) == NULL) return NULL;
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
  const char *rid =
      MHD_lookup_connection_value(c, MHD_HEADER_KIND, "X-Request-Id");
  if (srv_request_id_ok(rid))
    snprintf(r->rid, sizeof r->rid, "%s", rid);
  else
    srv_random_hex(r->rid, 16);
  r->route = srv__route_parse(r, url);
  atomic_fetch_add(&s->inflight, 1);
  return r;
}

/* A request other than a probe on a reserved slot: every ordinary slot is
 * taken. */
static enum MHD_Result reserved_refusal(srv_req *r) {
  srv_metrics_reject(r->srv->metrics, "connections_full");
  return srv__problem(r, 503, "/problems/overloaded", "Overloaded",
                      "every connection slot is taken "
                      "(KMORPH_MAX_CONNECTIONS); the slots beyond it serve "
                      "/healthz, /readyz and /metrics only; retry after the "
                      "time in Retry-After",
                      NULL, NULL);
}

/* The handler's first call: the headers are in. Makes the record (*req_cls
 * is the URI callback's, or NULL) and refuses bad framing, ordinary
 * requests on reserved slots and what on_headers refuses. */
static enum MHD_Result on_first_call(srv_server *s, struct MHD_Connection *c,
                                     const char *url, const char *method,
                                     const char *version, void **req_cls) {
  srv_req *r = req_new(s, c, url, method, *req_cls);
  if (r == NULL) return MHD_NO;
  *req_cls = r;
  r->http11 = version != NULL && strcmp(version, "HTTP/1.1") == 0;
  srv_watch_header_done(srv__req_conn(r), r->t0);
  /* Framing first: a request framed one way here and another way by a
   * proxy must not be answered as if it were understood. */
  srv_http_verdict v;
  srv_http_check(c, method, version, r->target.raw ? &r->target : NULL, &v);
  if (v.status != 0) {
    r->must_close = true;
    return v.status == 501
               ? srv__problem(r, 501, "/problems/not-implemented",
                              "Not implemented", v.detail, NULL, NULL)
               : srv__problem(r, 400, "/problems/bad-request", "Bad request",
                              v.detail, NULL, NULL);
  }
  if (srv_conn_reserved(srv__req_conn(r)) && !srv__route_is_probe(r->route))
    return reserved_refusal(r);
  return on_headers(r);
}

/* The body is in. A chunked body the front refused inside (framing.h)
 * ends with a trailer field carrying why: that is the answer. */
static enum MHD_Result body_done(srv_req *r) {
  const char *refused = MHD_lookup_connection_value(r->conn, MHD_FOOTER_KIND,
                                                    SRV_FRAMING_REFUSED_FIELD);
  if (refused == NULL) return dispatch(r);
  r->must_close = true;
  return srv__problem(r, 400, "/problems/bad-request", "Bad request", refused,
                      NULL, NULL);
}

enum MHD_Result srv__on_request(void *cls, struct MHD_Connection *c,
                                const char *url, const char *method,
                                const char *version, const char *upload,
                                size_t *upload_size, void **req_cls) {
  srv_server *s = cls;
  srv_req *r = *req_cls;
  if (r == NULL || !r->begun)
    return on_first_call(s, c, url, method, version, req_cls);
  if (*upload_size > 0) {
    size_t n = *upload_size;
    *upload_size = 0;
    if (atomic_load(&r->phase) == PH_ANSWERED)
      return MHD_YES; /* answered on the headers: drop the rest */
    return on_body(r, upload, n);
  }
  switch (atomic_load(&r->phase)) {
  case PH_BODY: return body_done(r);
  case PH_READY:
    atomic_fetch_sub(&s->suspended, 1);
    r->counted = false;
    return srv__answer_api(r, &r->resp);
  case PH_WAIT: /* not reached: MHD does not call while suspended */
  case PH_ANSWERED: /* already queued */ break;
  }
  return MHD_YES;
}

void *srv__on_uri(void *cls, const char *uri, struct MHD_Connection *c) {
  (void)c;
  srv_req *r = calloc(1, sizeof *r);
  if (r == NULL) return NULL;
  r->srv = cls;
  srv_http_target_scan(&r->target, uri);
  return r;
}
