/* api.h - the kmorph v1 contract as a library: JSON request in, HTTP-shaped
 * response out. The daemon, the CLI, the fuzzers and the tests all drive
 * exactly this code. No sockets here, no geometry above here.
 *
 * Thread-safety: every function may be called from many threads at once;
 * a prepared morph plan may render distinct frames on distinct threads.
 * Ownership: api_response bodies are malloc'd; free with
 * api_response_free() (or libc free() on .body).
 */
#ifndef KMAPI_API_H
#define KMAPI_API_H

#include <stdbool.h>
#include <stddef.h>

/* Limits enforced before any work starts; see api_config_default(). */
typedef struct api_config {
  size_t max_body_bytes;          /* 8 MiB: bigger bodies are 413 */
  size_t max_control_points;      /* 100,000 per curve */
  size_t max_frames_sync;         /* 1,000 per POST /v1/morph */
  size_t max_frames_job;          /* 10,000 per POST /v1/jobs */
  size_t max_samples;             /* 100,000 kappa samples per request */
  size_t max_json_depth;          /* 64: deeper JSON is 400 */
  size_t max_output_bytes;        /* 64 MiB: a morph or reconstruction
                                     whose answer is predicted larger (an
                                     upper bound, from its frames' control
                                     points, before any frame is rendered)
                                     is 422 limit-exceeded naming /frames,
                                     /times or /tolerance */
} api_config;

void api_config_default(api_config *cfg);

typedef struct api_response {
  int status;               /* HTTP status code */
  const char *content_type; /* static string */
  char *body;               /* malloc'd, NUL-terminated */
  size_t length;            /* bytes in body, without the NUL */
} api_response;

void api_response_init(api_response *r);
void api_response_free(api_response *r);

typedef enum api_route {
  API_ROUTE_SIGNATURE,   /* POST /v1/signature */
  API_ROUTE_RECONSTRUCT, /* POST /v1/reconstruct */
  API_ROUTE_MORPH        /* POST /v1/morph */
} api_route;

/* A caller's stop condition: true when the computation must end now (time
 * limit, client gone, shutdown). Called from the computing thread only,
 * at bounded intervals of work (some 0.02 to 0.1 ms); it must be cheap
 * and, if it reads state other threads write, read it atomically. */
typedef bool (*api_stop_fn)(void *ctx);

typedef struct api_request {
  api_route route;
  const char *body; /* need not be NUL-terminated */
  size_t length;
  const char *accept;     /* Accept header or NULL */
  const char *request_id; /* echoed in problem bodies, or NULL */
  api_stop_fn stop;       /* NULL (a zeroed request): never stops */
  void *stop_ctx;         /* passed to stop, borrowed for the call */
} api_request;

/* Handle one request completely. Always fills *out (a 2xx result or a
 * problem+json); returns out->status. When req->stop says stop, the answer
 * is 503 problem+json of type "/problems/stopped" (title "Stopped", detail
 * "the computation was stopped before it finished"): the caller knows why
 * and may replace it. */
int api_handle(const api_config *cfg, const api_request *req,
               api_response *out);

/* A problem+json response (RFC 9457) for errors found above this layer
 * (404, 405, 413, 415, 429, 503...). pointer/message may be NULL. */
void api_problem(api_response *out, int status, const char *type,
                 const char *title, const char *detail, const char *pointer,
                 const char *message, const char *request_id);

/* Prepared whole-sequence morph (for asynchronous jobs): validate and plan
 * once, render frames on any thread, then assemble the result.
 * api_morph_prepare returns 0 and *plan on success, else the HTTP status
 * with the problem in *error. max_frames bounds the frame count, and
 * cfg->max_output_bytes the predicted result (422 limit-exceeded). It
 * polls req->stop while it plans (503 "/problems/stopped"); the plan keeps
 * no reference to it. */
typedef struct api_morph_plan api_morph_plan;

int api_morph_prepare(const api_config *cfg, const api_request *req,
                      size_t max_frames, api_morph_plan **plan,
                      api_response *error);
size_t api_morph_frame_count(const api_morph_plan *plan);
/* The JSON pointer of the request member that chose the frames: "/times"
 * if the request listed its times, else "/frames" (also when it relied on
 * the default count). For limits found above this layer that depend on
 * how many frames were asked for, e.g. compute time. Static string. */
const char *api_morph_frames_pointer(const api_morph_plan *plan);
/* Render frame i (0 <= i < count); distinct i may run concurrently.
 * Returns 0, or an HTTP status (422) if the frame cannot be built. */
int api_morph_render_frame(api_morph_plan *plan, size_t i);
/* The same, ending early when stop (NULL: never) says so: then 503 and
 * the frame is marked stopped, so that api_morph_result answers 503
 * "/problems/stopped" unless it is rendered again first. */
int api_morph_render_frame_until(api_morph_plan *plan, size_t i,
                                 api_stop_fn stop, void *ctx);
/* Upper bound on the bytes of the result (JSON or SVG, as requested), as
 * checked against max_output_bytes by api_morph_prepare: for reserving
 * result memory before the frames are rendered. */
size_t api_morph_predicted_bytes(const api_morph_plan *plan);
/* After every frame rendered: the full result (JSON or SVG as requested). */
int api_morph_result(api_morph_plan *plan, api_response *out);
void api_morph_plan_free(api_morph_plan *plan);

/* The contract itself, as JSON (GET /openapi.json); static string. */
const char *api_openapi_json(void);

#endif
