/* internal.h - shared machinery of the contract layer: the per-request
 * context that carries the first error found (as a JSON pointer and a
 * message), typed JSON readers that validate while they read, JSON writers
 * that refuse non-finite numbers, and the mapping of core statuses to
 * problem types. Nothing here is visible above api/.
 *
 * DESIGN: every reader takes the JSON pointer of the value it reads, so an
 * error names the exact field ("/from/knots/4") without any parsing of
 * messages afterwards. The first error wins: later failures in the same
 * request do not overwrite it, which keeps the report about the root cause.
 *
 * Where each part lives: api.c (the context, problems, dispatch),
 * json_parse.c with json_scan.c and json_tree.c (bodies to trees),
 * json_read.c (typed readers), json_members.c (the members an object may
 * have), curve_in.c and signature_in.c (inputs), core_problem.c (core
 * failures), json_out.c (writers and their byte bounds), morph_*.c (the
 * morph route), svg_*.c (SVG in and out).
 */
#ifndef KMAPI_INTERNAL_H
#define KMAPI_INTERNAL_H

#include <stdbool.h>
#include <stddef.h>

#include <cJSON.h>

#include "kmapi/api.h"
#include "km/kmorph.h"
#include "km/shape.h"

#define API_POINTER_MAX 256
#define API_TEXT_MAX 512

#define API_CT_JSON "application/json"
#define API_CT_PROBLEM "application/problem+json"
#define API_CT_SVG "image/svg+xml"

/* Problem types (RFC 9457 "type" members, relative URIs). */
/* A problem's instance: the request id as a URN (api_problem). */
#define API_INSTANCE_PREFIX "urn:kmorph:request:"
#define API_P_MALFORMED "/problems/malformed-json"
#define API_P_INVALID_REQUEST "/problems/invalid-request"
#define API_P_INVALID_CURVE "/problems/invalid-curve"
#define API_P_INVALID_SIGNATURE "/problems/invalid-signature"
#define API_P_NOT_MORPHABLE "/problems/not-morphable"
#define API_P_LIMIT "/problems/limit-exceeded"
#define API_P_NO_CONVERGE "/problems/no-convergence"
#define API_P_NO_MEMORY "/problems/out-of-memory"
#define API_P_TOO_LARGE "/problems/body-too-large"
#define API_P_NOT_FOUND "/problems/not-found"
#define API_P_INTERNAL "/problems/internal"
#define API_P_STOPPED "/problems/stopped"

/* Make cJSON allocate through the km/alloc.h hook; once per process, safe
 * from any thread. Every entry point that builds a cJSON tree calls it
 * first (api.c). A normal build's hook is libc's heap, cJSON's own
 * default, so there is nothing to install. */
#if defined(KM_ALLOC_HOOKED)
void api__init(void);
#else
static inline void api__init(void) {}
#endif

/* The request being handled and the first error found in it. */
typedef struct api_ctx {
  const api_config *cfg;
  api_status status; /* 0 while no error */
  const char *type;
  const char *title;
  char detail[API_POINTER_MAX + API_TEXT_MAX + 4];
  bool has_pointer;
  char pointer[API_POINTER_MAX];
  char message[API_TEXT_MAX];
} api_ctx;

void api__ctx_init(api_ctx *ctx, const api_config *cfg);

/* Record an error unless one is recorded already. pointer may be NULL (no
 * errors[] entry); the message is also used as the detail when detail_fmt
 * is NULL. Returns false so callers can `return api__fail(...)`. */
bool api__fail(api_ctx *ctx, api_status status, const char *type,
               const char *title, const char *pointer, const char *message);
/* Same with a formatted message (printf-style). */
bool api__failf(api_ctx *ctx, api_status status, const char *type,
                const char *title, const char *pointer, const char *fmt, ...)
    __attribute__((format(printf, 6, 7)));

/* 422 invalid-request at pointer with a formatted message. */
bool api__invalid(api_ctx *ctx, const char *pointer, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* Map a core failure to the context. base is the JSON pointer of the
 * object the core was working on (a bspline/points curve object, or a
 * signature object); fields are appended to it. kind says which names the
 * fields have there. */
typedef enum api_kind {
  API_KIND_CURVE,     /* degree, knots, control_points, weights, closed */
  API_KIND_POINTS,    /* points, closed */
  API_KIND_SIGNATURE, /* length, start, kappa, corners */
  API_KIND_SVG,       /* d */
  API_KIND_REQUEST    /* the request itself (tolerance, matches, times) */
} api_kind;
bool api__core_fail(api_ctx *ctx, km_status st, const km_error *err,
                    const char *base, api_kind kind);

/* Out-of-memory in the api layer itself (503). */
bool api__oom(api_ctx *ctx);

/* The caller's stop said stop (503 /problems/stopped; the server puts its
 * own reason in its place). */
static inline bool api__stopped(api_ctx *ctx) {
  return api__fail(ctx, 503, API_P_STOPPED, "Stopped", NULL,
                   "the computation was stopped before it finished");
}

/* The value of the hexadecimal digit c, or -1 when c is none. */
static inline int api__hexval(int c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

/* A request's stop as the core takes it; NULL when it has none. */
static inline const km_stop *api__km_stop(const api_request *req,
                                          km_stop *buf) {
  if (req->stop == NULL) return NULL;
  buf->requested = req->stop;
  buf->ctx = req->stop_ctx;
  return buf;
}

/* A number as api__number prints it, with its comma: %.17g is at most 24
 * characters (sign, 17 digits, point, "e-308"). */
#define API_JSON_NUM_BYTES 25
/* A number of an SVG path as api_svg_path_d prints it (the shorter of its
 * %e and %f forms, at most 26 characters) with its separator. */
#define API_SVG_NUM_BYTES 27
/* Numbers in the SVG path of a curve of n control points of the given
 * degree, at most; hermite for curvature frames (json_out.c says why). */
size_t api__path_numbers(size_t n, int degree, bool hermite);
/* Bytes a curve takes in the JSON answer, at most: n control points of
 * the given degree (weights if rational), plus its "svg_d" when asked. */
size_t api__curve_json_bytes(size_t n, int degree, bool rational, bool svg_d);
/* The same bound for a signature as api__signature_json prints it. */
size_t api__signature_json_bytes(const km_signature *sig);

/* Write "<base>/<key>" or "<base>/<index>" into buf (API_POINTER_MAX). */
void api__ptr_key(char *buf, const char *base, const char *key);
void api__ptr_idx(char *buf, const char *base, size_t index);

/* Fill *out from the context's error (a problem+json response). */
void api__ctx_problem(const api_ctx *ctx, api_response *out,
                      const char *request_id);

/* Parse a request body (json_parse.c): more than cfg->max_body_bytes, or
 * a tree that would take more than api__tree_budget(length) bytes, is 413
 * /problems/body-too-large; syntax, invalid UTF-8, nesting deeper than
 * cfg->max_json_depth and a member name repeated in one object are 400
 * /problems/malformed-json (the detail gives the byte offset, and for a
 * repeat the name and its object's pointer); an array longer than any
 * field may be is 422 /problems/limit-exceeded; a top level that is not an
 * object is 422. NULL with the error in ctx; otherwise the caller frees
 * the tree with cJSON_Delete. Arrays of numbers in it are packed: read
 * them with api__array_* and api__elems_* below. Thread-safe. */
cJSON *api__parse_body(api_ctx *ctx, const char *body, size_t length);

/* The tree of a body may take at most API_TREE_FACTOR times the body's
 * bytes plus API_TREE_SLACK. Packed numbers cost at most 4 times their
 * text (`0,` becomes 8 bytes) and strings about once, while a cJSON item
 * is 80 bytes of heap: a body of short strings or small objects is refused
 * rather than let 8 MiB become hundreds of megabytes. The slack lets small
 * bodies be anything. */
#define API_TREE_FACTOR 8
#define API_TREE_SLACK ((size_t)1 << 20)
size_t api__tree_budget(size_t length);

/* ---- arrays of a parsed body. An array whose elements are all numbers,
 * or all arrays of the same count (1..API_PACK_WIDTH_MAX) of numbers, is
 * one packed item without children: cJSON_ArrayForEach and
 * cJSON_GetArraySize see it as empty, so readers use these. ---- */
#define API_PACK_WIDTH_MAX 4

/* Elements of an array, packed or not; 0 for anything else. */
size_t api__array_len(const cJSON *a);
/* The numbers of a packed array, row-major (borrowed from a), with
 * *width (optional) the numbers per element, 0 when each element is a
 * number; NULL when a is not a packed array. */
const double *api__array_packed(const cJSON *a, size_t *width);

/* A walk over an array's elements in order, packed or not. */
typedef struct api_elems {
  const cJSON *item;    /* the current element; NULL when packed */
  const double *packed; /* the array's numbers when packed, else NULL */
  size_t width;         /* numbers per packed element; 0: each a number */
  size_t index;         /* the current element */
} api_elems;
/* Start at element 0 of a (an array with api__array_len(a) elements). */
void api__elems_start(api_elems *it, const cJSON *a);
/* Step to the next element; only while index + 1 < the length. */
void api__elems_next(api_elems *it);
/* The current element as a finite number or a point [x, y]; ptr names the
 * array, errors name the element (ptr/index) or its coordinate. */
bool api__elems_num(api_ctx *ctx, const api_elems *it, const char *ptr,
                    double *out);
bool api__elems_point(api_ctx *ctx, const api_elems *it, const char *ptr,
                      double out[2]);

/* ---- typed readers. Each returns true on success; on failure the error
 * is recorded in ctx (with `ptr` naming the value) and false returned.
 * `present`, where given, is set to whether the member exists; absent
 * optional members leave *out untouched. ---- */

/* A finite number. */
bool api__num(api_ctx *ctx, const cJSON *v, const char *ptr, double *out);
/* Member `key` of obj as a finite number; required or optional. */
bool api__member_num(api_ctx *ctx, const cJSON *obj, const char *base,
                     const char *key, bool required, double *out,
                     bool *present);
/* An integral number in [lo, hi]. */
bool api__member_int(api_ctx *ctx, const cJSON *obj, const char *base,
                     const char *key, bool required, long lo, long hi,
                     long *out, bool *present);
bool api__member_bool(api_ctx *ctx, const cJSON *obj, const char *base,
                      const char *key, bool required, bool *out, bool *present);
/* A string member that must be one of names[0..n); *out = its index. */
bool api__member_enum(api_ctx *ctx, const cJSON *obj, const char *base,
                      const char *key, const char *const *names, size_t n,
                      int *out, bool *present);
/* An array of finite numbers (length 1..max); *out malloc'd, caller frees. */
bool api__num_array(api_ctx *ctx, const cJSON *v, const char *ptr, size_t max,
                    double **out, size_t *n);
/* An array of [x, y] pairs (length 1..max) into 2n doubles; malloc'd. */
bool api__point_array(api_ctx *ctx, const cJSON *v, const char *ptr, size_t max,
                      double **out, size_t *n);
/* A single [x, y]. */
bool api__point(api_ctx *ctx, const cJSON *v, const char *ptr, double out[2]);
/* Every member of obj (at base) is one of names[0..n), else 422 naming
 * the first that is not by its pointer, with the nearest of names as a
 * suggestion when one is close (json_members.c). Not an object: true (its
 * reader reports the type). */
bool api__known_members(api_ctx *ctx, const cJSON *obj, const char *base,
                        const char *const *names, size_t n);
/* The one of names[0..n) close enough to key to suggest, or NULL. */
const char *api__nearest_name(const char *key, const char *const *names,
                              size_t n);
#define API_NAMES(a) (a), (sizeof(a) / sizeof(a)[0])
/* Member must exist (422 "is required" otherwise). */
const cJSON *api__require(api_ctx *ctx, const cJSON *obj, const char *base,
                          const char *key);
/* "a number", "an array"... for messages; "nothing" for NULL. */
const char *api__type_name(const cJSON *v);
/* The "knots" member of obj (at base) of a curve (kind API_KIND_CURVE) or
 * a kappa function (API_KIND_SIGNATURE) of ncoef control points or
 * coefficients: present, numbers, ncoef + degree + 1 of them, never
 * decreasing, the problem naming the knot at fault; *knots malloc'd,
 * caller frees. */
bool api__read_knots(api_ctx *ctx, const cJSON *obj, const char *base,
                     size_t ncoef, long degree, api_kind kind, double **knots,
                     size_t *nk);

/* ---- curves and signatures from JSON ---- */

/* An input curve as given: a curve, a signature (type "signature"), or a
 * compound shape (type "shape", or an "svg" whose d has several
 * subpaths). A shape's contours are kept as given (closed, not yet
 * reoriented); its nesting is built where it is morphed. */
typedef struct api_input {
  bool is_signature;
  api_kind kind; /* how it was given, for mapping core errors */
  km_curve curve;
  km_signature sig;
  double length; /* arc length of the input (all contours of a shape) */
  bool is_shape;
  size_t ncontours;
  km_curve *contours; /* is_shape: ncontours closed curves */
  size_t *offsets;    /* svg shapes: each subpath's offset in d; else NULL */
  km_fill_rule fill;
} api_input;

void api__input_init(api_input *in);
void api__input_free(api_input *in);

/* Parse a Curve object at ptr. tol > 0 is the request tolerance, or <= 0
 * when none was given (the SVG parser then uses a small absolute one).
 * A shape (out->is_shape) comes back with every contour closed and at
 * most cfg->max_contours of them; callers that take no shapes refuse it
 * with api__refuse_shape. */
bool api__parse_curve(api_ctx *ctx, const cJSON *v, const char *ptr, double tol,
                      api_input *out);
/* The pointer naming contour i of a shape input at ptr: "<ptr>/contours/i"
 * for a JSON shape, "<ptr>/d" for SVG (whose messages give the subpath's
 * offset, api__contour_where). */
void api__contour_ptr(char *buf, const api_input *in, const char *ptr,
                      size_t i);
/* "contour i" or "subpath i (at offset N of d)" for messages. */
void api__contour_where(char *buf, size_t cap, const api_input *in, size_t i);
/* 422 at ptr: a shape where only one curve is taken. */
bool api__refuse_shape(api_ctx *ctx, const char *ptr);
/* The contours limit of a context (its default for 0). */
size_t api__max_contours(const api_config *cfg);
/* Parse a Signature object at ptr. */
bool api__parse_signature(api_ctx *ctx, const cJSON *v, const char *ptr,
                          km_signature *out);
/* The optional "tolerance" member: positive finite; *tol = 0 if absent. */
bool api__parse_tolerance(api_ctx *ctx, const cJSON *root, double *tol);
/* The optional "include" member: array of known names. */
typedef struct api_include {
  bool svg_d;
  bool animate_d;
} api_include;
bool api__parse_include(api_ctx *ctx, const cJSON *root, bool allow_animate,
                        api_include *inc);
/* The optional "precision": "exact" (default: shortest round-trip
 * numbers) or "tolerance" (control points on a decimal grid of at most a
 * tenth of the tolerance, json_write.h). */
typedef enum api_precision {
  API_PRECISION_EXACT,
  API_PRECISION_TOLERANCE
} api_precision;
bool api__parse_precision(api_ctx *ctx, const cJSON *root, api_precision *out);

/* ---- writers. A writer that meets a non-finite number records a 422
 * no-convergence error (the core produced something it cannot stand
 * behind) and returns false; allocation failures record 503. ---- */
bool api__add_num(api_ctx *ctx, cJSON *obj, const char *key, double v);
/* item as obj's member key; takes ownership of item (deleted, and 503
 * recorded, when the member cannot be added). */
bool api__add_item(api_ctx *ctx, cJSON *obj, const char *key, cJSON *item);
/* A finite number as a cJSON item that prints exactly (round-trips). */
cJSON *api__number(double v);
cJSON *api__num_array_json(api_ctx *ctx, const double *v, size_t n,
                           size_t stride);
cJSON *api__signature_json(api_ctx *ctx, const km_signature *sig);

/* Render root into a 2xx JSON response; takes ownership of root. */
api_status api__respond_json(api_ctx *ctx, cJSON *root, api_status status,
                             api_response *out, const char *request_id);

/* Routes. */
/* Routes: the answer into *out, its status returned (as api_handle). */
api_status api__route_signature(api_ctx *ctx, const api_request *req,
                                api_response *out);
api_status api__route_reconstruct(api_ctx *ctx, const api_request *req,
                                  api_response *out);

#endif
