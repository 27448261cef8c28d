/* problems.c - GET /problems/{name}: what each problem type means (see
 * problems.h).
 */
#include "problems.h"

#include <stdlib.h>
#include <string.h>

#include "conneg.h"
#include "reply.h"
#include "util.h"

typedef struct problem_doc {
  const char *name;  /* after /problems/ */
  const char *title; /* as in the problem bodies */
  int status;        /* the status it comes with */
  const char *text;  /* what it means and what to do */
} problem_doc;

static const problem_doc DOCS[] = {
    {"bad-request", "Bad request", 400,
     "The request's framing or syntax was refused before it was read "
     "(RFC 9112): fix the request; the connection is closed."},
    {"body-too-large", "Body too large", 413,
     "The body is larger than KMORPH_MAX_BODY; send a smaller request."},
    {"cancelled", "Cancelled", 409,
     "The job was cancelled (DELETE) before it finished."},
    {"client-gone", "Client gone", 503,
     "The client closed its connection while its request computed; no "
     "one read this answer."},
    {"header-too-large", "Request header too large", 431,
     "The request's header is larger than the daemon accepts."},
    {"internal", "Internal error", 500,
     "The daemon failed in a way it did not foresee, or ran out of "
     "memory; retry, and report it with the request id if it repeats."},
    {"invalid-curve", "Invalid curve", 422,
     "A curve in the request is not usable (degenerate, self-contradictory "
     "or unparseable SVG); `errors` points at it."},
    {"invalid-request", "Invalid request", 422,
     "The request is well-formed JSON but breaks the contract (a type, "
     "range or unknown member); `errors` holds a JSON pointer per fault."},
    {"invalid-signature", "Invalid signature", 422,
     "The curvature signature given to /v1/reconstruct is not usable."},
    {"job-gone", "Job gone", 410,
     "The job was known but is no longer kept (expired after "
     "KMORPH_JOB_TTL, pushed out, or its result evicted); resubmit it."},
    {"job-not-done", "Result not ready", 409,
     "The job has not finished, failed or was cancelled; poll its "
     "status."},
    {"job-not-found", "Job not found", 404, "No job has this id."},
    {"job-store-unavailable", "Job store unavailable", 503,
     "The shared job store (Redis, KMORPH_JOBS) cannot be reached now; "
     "synchronous routes still answer; retry after Retry-After."},
    {"limit-exceeded", "Limit exceeded", 422,
     "The request asks for more than a limit of the daemon allows (frames, "
     "points, samples, output size or compute time); the pointer names "
     "the member."},
    {"malformed-json", "Malformed JSON", 400,
     "The body is not JSON (RFC 8259)."},
    {"method-not-allowed", "Method not allowed", 405,
     "The method is not allowed on this path; Allow lists those that are."},
    {"no-convergence", "No convergence", 422,
     "A numerical step did not converge within its iteration cap."},
    {"not-acceptable", "Not acceptable", 406,
     "The Accept header allows none of the media types this path answers "
     "with; the detail lists them."},
    {"not-found", "Not found", 404, "Nothing is served at this path."},
    {"not-implemented", "Not implemented", 501,
     "The request uses a feature of HTTP the daemon does not implement "
     "(a transfer coding, a method)."},
    {"not-morphable", "Not morphable", 422,
     "The two curves cannot be morphed into each other (an open curve and "
     "a closed one, or shapes of different structure)."},
    {"not-ready", "Result not ready", 409, "The resource is not ready yet."},
    {"out-of-memory", "Out of memory", 503,
     "The daemon could not allocate memory for this request; retry later."},
    {"overloaded", "Overloaded", 503,
     "The daemon is full (queue, memory for bodies or results, connection "
     "slots); retry after Retry-After."},
    {"request-timeout", "Request timeout", 408,
     "The request did not arrive within the time allowed to send it."},
    {"shutting-down", "Shutting down", 503,
     "The daemon is stopping; retry on another instance."},
    {"stopped", "Stopped", 422,
     "The computation was stopped before it finished."},
    {"too-many-jobs", "Too many jobs", 429,
     "KMORPH_MAX_JOBS jobs are queued or running; retry after "
     "Retry-After."},
    {"too-many-requests", "Too many requests", 429,
     "Too many requests at once; retry after Retry-After."},
    {"unavailable", "Service unavailable", 503,
     "The service cannot answer now; retry after Retry-After."},
    {"unsupported-media-type", "Unsupported media type", 415,
     "The body must be application/json."},
};
#define NDOCS (sizeof DOCS / sizeof DOCS[0])

static const problem_doc *find_doc(const char *name) {
  for (size_t i = 0; i < NDOCS; i++)
    if (strcmp(DOCS[i].name, name) == 0) return &DOCS[i];
  return NULL;
}

/* Queue the n bytes formatted in tmp (n < 0 or too long: out of room). */
static enum MHD_Result answer_copy(srv_req *r, const char *type,
                                   const char *tmp, int n, size_t cap) {
  if (n < 0 || (size_t)n >= cap)
    return srv__problem(r, 500, "/problems/internal", "Internal error",
                        "problem description too long", NULL, NULL);
  char *body = malloc((size_t)n + 1);
  if (body == NULL) return MHD_NO;
  memcpy(body, tmp, (size_t)n + 1);
  return srv__answer(r, 200, type, body, (size_t)n, true);
}

enum MHD_Result srv__serve_problem(srv_req *r) {
  static const char *const TYPES[] = {SRV_JSON_TYPE, "application/problem+json",
                                      "text/html"};
  const char *accept =
      MHD_lookup_connection_value(r->conn, MHD_HEADER_KIND, "Accept");
  int pick = srv_accept_pick(accept, TYPES, 3);
  if (pick < 0) return srv__not_acceptable(r, "application/json, text/html");
  const problem_doc *d = find_doc(r->static_name);
  if (d == NULL)
    return srv__problem(r, 404, "/problems/not-found", "Not found",
                        "no such problem type", NULL, NULL);
  char tmp[2048];
  int n;
  if (pick == 2) {
    n = snprintf(tmp, sizeof tmp,
                 "<!doctype html>\n<html lang=\"en\"><head><meta "
                 "charset=\"utf-8\"><title>%s</title></head><body>\n"
                 "<h1>%s</h1>\n<p><code>/problems/%s</code>, HTTP status "
                 "%d</p>\n<p>%s</p>\n</body></html>\n",
                 d->title, d->title, d->name, d->status, d->text);
    return answer_copy(r, "text/html; charset=utf-8", tmp, n, sizeof tmp);
  }
  n = snprintf(tmp, sizeof tmp,
               "{\"type\":\"/problems/%s\",\"title\":\"%s\","
               "\"status\":%d,\"description\":\"%s\"}",
               d->name, d->title, d->status, d->text);
  return answer_copy(r, TYPES[pick], tmp, n, sizeof tmp);
}
