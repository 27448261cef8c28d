/* reply.h - queueing kmorphd's answers: the headers every answer carries
 * (X-Request-Id, CORS, Retry-After, Allow, Cache-Control, Connection),
 * problem+json bodies, and the CORS preflight.
 *
 * Every function here runs on the I/O thread that owns the request (the
 * handler's call), records the status and length in r for the access log
 * and marks r PH_ANSWERED. Each returns libmicrohttpd's verdict: MHD_NO
 * closes the connection without an answer (then r->cut says why when
 * memory was short).
 */
#ifndef SRV_REPLY_H
#define SRV_REPLY_H

#include <stdbool.h>
#include <stddef.h>

#include "server_internal.h"

/* The media type of kmorphd's own JSON answers. */
#define SRV_JSON_TYPE "application/json"

/* Add the common headers (and Location for a created job) to resp and
 * queue it with status; len is the body's length for the log. resp is
 * released either way. */
enum MHD_Result srv__queue(srv_req *r, int status, struct MHD_Response *resp,
                           size_t len);

/* Queue body (len bytes) with status and, unless NULL, Content-Type
 * ctype. body is malloc'd and freed by libmicrohttpd when owned (also on
 * failure), else static. */
enum MHD_Result srv__answer(srv_req *r, int status, const char *ctype,
                            char *body, size_t len, bool owned);

/* Queue an api_response, taking its body; res is left without one. A
 * response without a body (the api layer was out of memory) becomes a
 * static 500 problem. */
enum MHD_Result srv__answer_api(srv_req *r, api_response *res);

/* Queue an RFC 9457 problem carrying r's request id; the strings are
 * borrowed (pointer and message may be NULL: see api_problem). */
enum MHD_Result srv__problem(srv_req *r, int status, const char *type,
                             const char *title, const char *detail,
                             const char *pointer, const char *message);

/* Queue a JSON body formatted from fmt (at most 1023 bytes: longer is a
 * 500 problem). */
enum MHD_Result srv__answer_json(srv_req *r, int status, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* A body the answer borrows and releases when sent, with its entity tags
 * and caching rule (srv__answer_body). */
typedef struct srv_body {
  const char *type; /* Content-Type */
  const char *data; /* len bytes, the identity form */
  size_t len;
  const char *gz; /* gz_len bytes of its gzip form, or NULL */
  size_t gz_len;
  bool stream_gzip;           /* without gz: compress as sent if worth it */
  const char *etag;           /* strong tag of the identity form, or NULL */
  const char *gz_etag;        /* strong tag of the gzip form, or NULL */
  const char *cache_control;  /* Cache-Control, or NULL */
  void (*release)(void *cls); /* called once when data and gz are free */
  void *cls;
} srv_body;

/* Queue b with status (200): gzip-coded when the client accepts gzip
 * (Accept-Encoding, q > 0) and a gzip form exists or may be streamed;
 * 304 without a body when If-None-Match names the chosen form's tag.
 * b->release(b->cls) is called exactly once, whatever happens. */
enum MHD_Result srv__answer_body(srv_req *r, int status, const srv_body *b);

/* True when the Accept header allows one of the media types r's route
 * answers with (always for routes whose type is found later, and for
 * DELETE). */
bool srv__acceptable(srv_req *r);

/* True when the Accept header allows ctype (parameters ignored). */
bool srv__accepts_type(srv_req *r, const char *ctype);

/* True when the client accepts gzip (Accept-Encoding, q > 0). */
bool srv__wants_gzip(srv_req *r);

/* 406 problem naming the media types offered (NULL: the route's). */
enum MHD_Result srv__not_acceptable(srv_req *r, const char *offered);

/* Answer an OPTIONS request on a known route: 204 with Allow and, for an
 * allowed origin, the CORS preflight headers. The connection's watch
 * record is left in its body phase, bounded by the request time. */
enum MHD_Result srv__answer_preflight(srv_req *r);

#endif
