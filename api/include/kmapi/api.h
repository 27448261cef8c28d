/* api.h - the kmorph v1 contract as a library: JSON request in, HTTP-shaped
 * response out. The daemon, the CLI, the fuzzers and the tests all drive
 * exactly this code. No sockets here, no geometry above here.
 *
 * Thread-safety: every function may be called from many threads at once
 * on distinct arguments; a prepared morph plan may render distinct frames
 * on distinct threads (api_morph_render_frame*), while its other calls
 * (result, free) need the plan to themselves.
 * Ownership: inputs are borrowed for the call; api_response bodies are
 * malloc'd and freed with api_response_free() (or libc free() on .body).
 */
#ifndef KMAPI_API_H
#define KMAPI_API_H

#include <stdbool.h>
#include <stddef.h>

/* What every fallible call here returns: an HTTP status code (200..599)
 * that the response it filled carries, or API_STEP_DONE (0) from the
 * steps of a prepared morph, which answer nothing by themselves. Each
 * function below lists the values it returns. */
typedef int api_status;
#define API_STEP_DONE 0

/* Limits enforced before any work starts; see api_config_default(). */
typedef struct api_config {
  size_t max_body_bytes;     /* 8 MiB: bigger bodies are 413 */
  size_t max_control_points; /* 100,000 per curve */
  size_t max_frames_sync;    /* 1,000 per POST /v1/morph */
  size_t max_frames_job;     /* 10,000 per POST /v1/jobs */
  size_t max_samples;        /* 100,000 kappa samples per request */
  size_t max_json_depth;     /* 64: deeper JSON is 400 */
  size_t max_output_bytes;   /* 64 MiB: an answer predicted larger
                                     (an upper bound, from the control
                                     points or coefficients it will hold,
                                     before it is rendered) is 422
                                     limit-exceeded naming /frames,
                                     /times, /samples or /tolerance */
  size_t max_contours;       /* 64 contours (subpaths) per shape; 0
                                     asks for the default; more is 422
                                     limit-exceeded naming the contour */
} api_config;

/* Fill *cfg (out, not read) with the defaults listed above. */
void api_config_default(api_config *cfg);

typedef struct api_response {
  api_status status;        /* HTTP status code; 0 until filled */
  const char *content_type; /* static string; NULL until filled */
  char *body;               /* malloc'd, NUL-terminated; NULL if none */
  size_t length;            /* bytes in body, without the NUL */
} api_response;

/* An empty response (*r out): freeing it is a no-op. */
void api_response_init(api_response *r);
/* Free r->body and leave *r empty; r may be NULL or empty. */
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

/* One request; every pointer is borrowed for the call that takes it. */
typedef struct api_request {
  api_route route;
  const char *body; /* need not be NUL-terminated */
  size_t length;
  const char *accept;     /* Accept header or NULL */
  const char *request_id; /* echoed in problem bodies, or NULL */
  api_stop_fn stop;       /* NULL (a zeroed request): never stops */
  void *stop_ctx;         /* passed to stop, borrowed for the call */
} api_request;

/* Handle one request completely.
 * cfg (in, may be NULL: the defaults) bounds the work; req (in) is the
 * request; *out (out, need not be initialised) always receives an answer,
 * a 2xx result or a problem+json, which the caller frees.
 * Returns out->status:
 *   200 the result (JSON, or SVG for a morph that asked for it);
 *   400 malformed JSON, nesting deeper than cfg->max_json_depth or a
 *       member name repeated in one object (/problems/malformed-json);
 *   404 an unknown route;
 *   413 a body over cfg->max_body_bytes or too costly to parse;
 *   422 an invalid field, named by the problem's errors[0].pointer
 *       (invalid-request, invalid-curve, invalid-signature, not-morphable,
 *       no-convergence, limit-exceeded);
 *   500 a failure the contract has no name for (/problems/internal);
 *   503 out of memory, or req->stop said stop: then the problem's type is
 *       "/problems/stopped" (title "Stopped", detail "the computation was
 *       stopped before it finished"), which the caller may replace with
 *       its own reason. */
api_status api_handle(const api_config *cfg, const api_request *req,
                      api_response *out);

/* A problem+json response (RFC 9457) for errors found above this layer
 * (404, 405, 413, 415, 429, 503...) into *out (out, need not be
 * initialised; the caller frees it). status is the HTTP status to answer;
 * type and title (NULL: the status's defaults), detail, pointer (NULL: no
 * errors[] member), message (NULL: the detail) and request_id (echoed
 * only if short printable ASCII; may be NULL) are copied. Out of memory
 * still gives a fixed body of type, title and status when that fits. */
void api_problem(api_response *out, api_status status, const char *type,
                 const char *title, const char *detail, const char *pointer,
                 const char *message, const char *request_id);

/* ---- prepared whole-sequence morph (for asynchronous jobs): validate and
 * plan once, render frames on any thread, then assemble the result.
 * api_handle(API_ROUTE_MORPH) runs exactly these steps on one thread. */
typedef struct api_morph_plan api_morph_plan;

/* Validate and plan a morph request.
 * cfg (in, may be NULL: the defaults) is copied into the plan; req (in) is
 * read during the call only, its stop polled while planning, and the plan
 * keeps no reference to it; max_frames bounds the frame count (422 naming
 * /frames or /times beyond it); cfg->max_output_bytes bounds the
 * predicted result (422 limit-exceeded naming /frames, /times or
 * /tolerance). *plan (out) is written on success only; the caller frees
 * it with api_morph_plan_free. *error (out) is always initialised and on
 * failure holds the problem, which the caller frees.
 * Returns API_STEP_DONE (0) with *plan, or the problem's status as
 * api_handle lists them: 400, 404 (req->route is not API_ROUTE_MORPH),
 * 413, 422, 500, 503 (out of memory, or "/problems/stopped"). */
api_status api_morph_prepare(const api_config *cfg, const api_request *req,
                             size_t max_frames, api_morph_plan **plan,
                             api_response *error);
/* Frames the plan will render; 0 for a NULL plan. */
size_t api_morph_frame_count(const api_morph_plan *plan);
/* The JSON pointer of the request member that chose the frames: "/times"
 * if the request listed its times, else "/frames" (also when it relied on
 * the default count). For limits found above this layer that depend on
 * how many frames were asked for, e.g. compute time. Static string. */
const char *api_morph_frames_pointer(const api_morph_plan *plan);
/* Render frame i (0 <= i < count) into the plan's slot i; distinct i may
 * run concurrently, the same i may not.
 * Returns API_STEP_DONE (0) (also when the frame was rendered before),
 * 404 for a NULL plan or i out of range, 422 if the frame cannot be built
 * (api_morph_result gives the problem), 503 out of memory. */
api_status api_morph_render_frame(api_morph_plan *plan, size_t i);
/* The same, ending early when stop (NULL: never; ctx passed to it,
 * borrowed for the call) says so: then 503 and the frame is marked
 * stopped, so that api_morph_result answers 503 "/problems/stopped"
 * unless it is rendered again first. */
api_status api_morph_render_frame_until(api_morph_plan *plan, size_t i,
                                        api_stop_fn stop, void *ctx);
/* Have each frame print its part of a JSON answer on the thread that
 * renders it (call before rendering), so that frames rendered on several
 * threads are printed on them too and api_morph_result only copies: the
 * same bytes. The printed frames hold up to the answer's size again until
 * the answer is assembled, so this is taken only when the predicted
 * answer is at most limit bytes, and not for SVG or "animate_d" answers,
 * which are written from every frame at once. Returns whether it was
 * taken; false for a NULL plan. */
bool api_morph_print_while_rendering(api_morph_plan *plan, size_t limit);
/* Upper bound on the bytes of the result (JSON or SVG, as requested), as
 * checked against max_output_bytes by api_morph_prepare: for reserving
 * result memory before the frames are rendered. 0 for a NULL plan. */
size_t api_morph_predicted_bytes(const api_morph_plan *plan);
/* The full result (JSON or SVG as requested) into *out (out, need not be
 * initialised; the caller frees it), rendering first any frame not yet
 * rendered. Not concurrent with rendering frames of the same plan.
 * Returns 200 with the result; 422 (or 500) naming the first frame that
 * failed, by its entry of /times when the request listed them; 503 out
 * of memory, or "/problems/stopped" for a frame stopped and not rendered
 * again; 500 for a NULL plan. */
api_status api_morph_result(api_morph_plan *plan, api_response *out);
/* Free a plan and its frames; plan may be NULL. */
void api_morph_plan_free(api_morph_plan *plan);

/* The contract itself, as JSON (GET /openapi.json); static string. */
const char *api_openapi_json(void);

/* ---- a prepared morph's frames apart (for daemons sharing one job's
 * frames between processes; api/src/morph_frames.c). */

/* True when the plan's answer can be assembled from its frames' texts
 * (a JSON answer without "animate_d"); false for a NULL plan. The others need every frame of one plan: render them all
 * there and call api_morph_result. */
bool api_morph_frames_apart(const api_morph_plan *plan);
/* Render frame i (if not rendered yet) and write its text into *out
 * (out; body malloc'd, the caller frees): its object of the answer's
 * "frames" and what the answer's "intersections" needs of it, in a form
 * only api_morph_result_from_texts reads. Same threading as api_morph_render_frame.
 * Returns 200; 404 for a NULL plan, i out of range or a plan not
 * api_morph_frames_apart; 422 if the frame cannot be built; 503 out of
 * memory; 500 if the answer could not be cut apart. */
api_status api_morph_frame_text(api_morph_plan *plan, size_t i,
                                api_response *out);
/* The whole answer into *out (out; the caller frees) from the texts of
 * every frame in order (texts[i] of lengths[i] bytes, borrowed), as
 * api_morph_frame_text wrote them, possibly in another process: equal to
 * what api_morph_result would answer. Not concurrent with rendering.
 * Returns 200; 404 for a NULL plan or one not api_morph_frames_apart;
 * 503 out of memory (a problem in *out); 500 otherwise. */
api_status api_morph_result_from_texts(api_morph_plan *plan,
                                       const char *const *texts,
                                       const size_t *lengths,
                                       api_response *out);

#endif
