/* route_morph.c - POST /v1/morph and the prepared morph behind jobs:
 * validate the whole request and build the core plan once, render frames
 * (on any thread), then assemble the JSON or SVG result.
 *
 * DESIGN: api_handle(API_ROUTE_MORPH) is prepare + result on one thread, so
 * the synchronous route and asynchronous jobs run exactly the same code.
 * Each frame has its own slot in the plan; api_morph_render_frame(i) writes
 * slot i only, which is what makes distinct frames safe to render
 * concurrently. Errors found while rendering stay in their slot until
 * api_morph_result reports the first one.
 *
 * The inputs' signatures are computed here (not inside km_morph_create) for
 * curvature morphs, so that a cusp or a degenerate curve is reported under
 * the input it belongs to ("/from" or "/to").
 */
#include <ctype.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "svg.h"

/* Frames when neither "frames" nor "times" is given. */
#define DEFAULT_FRAMES 11

#define COLOUR_MAX 64

typedef struct frame_slot {
  double t;
  int state; /* 0 not rendered, 1 done, -1 failed */
  km_curve curve;
  km_frame_metrics metrics;
  km_signature sig; /* only for curvature plots */
  km_status st;
  km_error err;
} frame_slot;

struct api_morph_plan {
  api_config cfg;
  char *request_id;
  api_input from, to;
  km_morph *morph;
  km_morph_options opt;
  double *matches;
  bool times_given;
  size_t nframes;
  frame_slot *frames;
  bool metrics;
  bool svg;
  bool want_sig;
  api_include inc;
  double tol;
  api_svg_options svgopt;
  char stroke[COLOUR_MAX], from_color[COLOUR_MAX], to_color[COLOUR_MAX];
  size_t predicted; /* upper bound on the result's bytes */
};

static const char *const method_names[] = {"curvature", "linear"};
static const char *const blend_names[] = {"turning", "paper"};
static const char *const closure_names[] = {"auto", "lsq", "c0",
                                            "c1",   "g2",  "none"};
static const char *const anchor_names[] = {"fit", "start", "centroid"};
static const char *const orient_names[] = {"auto", "keep"};
static const char *const format_names[] = {"json", "svg"};
static const char *const layout_names[] = {"filmstrip", "overlay", "animate",
                                           "curvature_plot"};

/* Enum arrays above are in the order of the core's enums; these check it
 * at compile time so a reordering there cannot silently swap meanings. */
_Static_assert(KM_METHOD_CURVATURE == 0 && KM_METHOD_LINEAR == 1,
               "method order");
_Static_assert(KM_BLEND_TURNING == 0 && KM_BLEND_PAPER == 1, "blend order");
_Static_assert(KM_CLOSURE_AUTO == 0 && KM_CLOSURE_LSQ == 1 &&
                   KM_CLOSURE_C0 == 2 && KM_CLOSURE_C1 == 3 &&
                   KM_CLOSURE_G2 == 4 && KM_CLOSURE_NONE == 5,
               "closure order");
_Static_assert(KM_ANCHOR_FIT == 0 && KM_ANCHOR_START == 1 &&
                   KM_ANCHOR_CENTROID == 2,
               "anchor order");
_Static_assert(KM_ORIENT_AUTO == 0 && KM_ORIENT_KEEP == 1, "orient order");
_Static_assert(API_SVG_FILMSTRIP == 0 && API_SVG_OVERLAY == 1 &&
                   API_SVG_ANIMATE == 2 && API_SVG_CURVATURE_PLOT == 3,
               "layout order");

#define NAMES(a) a, sizeof a / sizeof a[0]

/* ---------------------------------------------------------------- helpers */

static bool ascii_prefix_ci(const char *s, const char *prefix, size_t n) {
  for (size_t i = 0; i < n; i++)
    if (s[i] == '\0' || tolower((unsigned char)s[i]) != prefix[i])
      return false;
  return true;
}

/* q value of one media range's parameters ("; q=0.5"); 1 when absent. */
static double accept_q(const char *p, const char *end) {
  while (p < end) {
    while (p < end && (*p == ';' || *p == ' ' || *p == '\t'))
      p++;
    if (end - p >= 2 && (p[0] == 'q' || p[0] == 'Q') && p[1] == '=') {
      double q = strtod(p + 2, NULL);
      return isfinite(q) ? q : 0;
    }
    while (p < end && *p != ';')
      p++;
  }
  return 1;
}

/* Does the Accept header prefer SVG to JSON? JSON wins ties and is what
 * "* / *" and absent headers get. */
static bool accept_prefers_svg(const char *accept) {
  double q_svg = -1, q_json = -1;
  const char *p = accept;
  if (accept == NULL)
    return false;
  while (*p != '\0') {
    const char *end = strchr(p, ',');
    const char *semi;
    size_t n;
    if (end == NULL)
      end = p + strlen(p);
    while (p < end && (*p == ' ' || *p == '\t'))
      p++;
    semi = memchr(p, ';', (size_t)(end - p));
    if (semi == NULL)
      semi = end;
    n = (size_t)(semi - p);
    while (n > 0 && (p[n - 1] == ' ' || p[n - 1] == '\t'))
      n--;
    double q = accept_q(semi, end);
    if (n == 13 && ascii_prefix_ci(p, "image/svg+xml", 13))
      q_svg = fmax(q_svg, q);
    else if ((n == 16 && ascii_prefix_ci(p, "application/json", 16)) ||
             (n == 3 && ascii_prefix_ci(p, "*/*", 3)) ||
             (n == 13 && ascii_prefix_ci(p, "application/*", 13)))
      q_json = fmax(q_json, q);
    p = *end == ',' ? end + 1 : end;
  }
  return q_svg > 0 && q_svg > q_json;
}

/* A colour is copied into the SVG document: allow only what CSS colour
 * syntax needs (names, #hex, rgb()/hsl() with numbers), so nothing can
 * close an attribute or open markup. */
static bool parse_colour(api_ctx *ctx, const cJSON *svg, const char *key,
                         char *dst, const char **out) {
  char p[API_POINTER_MAX];
  const cJSON *v = cJSON_GetObjectItemCaseSensitive(svg, key);
  size_t n;
  if (v == NULL)
    return true;
  api__ptr_key(p, "/svg", key);
  if (!cJSON_IsString(v))
    return api__invalid(ctx, p, "must be a colour string");
  n = strlen(v->valuestring);
  if (n == 0 || n >= COLOUR_MAX)
    return api__invalid(ctx, p, "must be a colour of 1 to %d characters",
                        COLOUR_MAX - 1);
  for (size_t i = 0; i < n; i++) {
    unsigned char c = (unsigned char)v->valuestring[i];
    if (!isalnum(c) && strchr("#(),.% -", c) == NULL)
      return api__invalid(ctx, p,
                          "must be a CSS colour (a name, #rgb, #rrggbb, "
                          "rgb(...) or hsl(...))");
  }
  memcpy(dst, v->valuestring, n + 1);
  *out = dst;
  return true;
}

static bool positive_member(api_ctx *ctx, const cJSON *obj, const char *key,
                            double max, double *out) {
  char p[API_POINTER_MAX];
  bool present = false;
  double v = 0;
  if (!api__member_num(ctx, obj, "/svg", key, false, &v, &present))
    return false;
  if (!present)
    return true;
  api__ptr_key(p, "/svg", key);
  if (!(v > 0) || v > max)
    return api__invalid(ctx, p, "must be > 0 and <= %g", max);
  *out = v;
  return true;
}

static bool parse_svg_options(api_ctx *ctx, const cJSON *root,
                              api_morph_plan *pl) {
  const cJSON *svg = cJSON_GetObjectItemCaseSensitive(root, "svg");
  int layout = 0;
  memset(&pl->svgopt, 0, sizeof pl->svgopt);
  pl->svgopt.layout = API_SVG_FILMSTRIP;
  if (svg == NULL)
    return true;
  if (!cJSON_IsObject(svg))
    return api__invalid(ctx, "/svg", "must be an object");
  if (!api__member_enum(ctx, svg, "/svg", "layout", NAMES(layout_names),
                        &layout, NULL))
    return false;
  pl->svgopt.layout = (api_svg_layout)layout;
  return positive_member(ctx, svg, "width", 1e5, &pl->svgopt.width) &&
         positive_member(ctx, svg, "height", 1e5, &pl->svgopt.height) &&
         positive_member(ctx, svg, "stroke_width", 1e4,
                         &pl->svgopt.stroke_width) &&
         positive_member(ctx, svg, "duration", 86400, &pl->svgopt.duration) &&
         parse_colour(ctx, svg, "stroke", pl->stroke, &pl->svgopt.stroke) &&
         parse_colour(ctx, svg, "from_color", pl->from_color,
                      &pl->svgopt.from_color) &&
         parse_colour(ctx, svg, "to_color", pl->to_color,
                      &pl->svgopt.to_color);
}

/* "matches": "auto" or [[r_from, r_to], ...] strictly increasing in (0,1)
 * on both sides. */
static bool parse_matches(api_ctx *ctx, const cJSON *root,
                          api_morph_plan *pl) {
  const cJSON *v = cJSON_GetObjectItemCaseSensitive(root, "matches");
  api_elems it;
  char p[API_POINTER_MAX], q[API_POINTER_MAX];
  size_t n, i = 0;
  if (v == NULL || cJSON_IsNull(v))
    return true;
  if (cJSON_IsString(v)) {
    if (strcmp(v->valuestring, "auto") != 0)
      return api__invalid(ctx, "/matches",
                          "must be \"auto\" or an array of [r_from, r_to] "
                          "pairs");
    pl->opt.auto_matches = true;
    return true;
  }
  if (!cJSON_IsArray(v))
    return api__invalid(ctx, "/matches",
                        "must be \"auto\" or an array of [r_from, r_to] "
                        "pairs");
  n = api__array_len(v);
  if (n == 0)
    return true;
  if (n > pl->cfg.max_control_points)
    return api__failf(ctx, 422, API_P_LIMIT, "Limit exceeded", "/matches",
                      "has %zu pairs; the limit is %zu", n,
                      pl->cfg.max_control_points);
  pl->matches = malloc(2 * n * sizeof *pl->matches);
  if (pl->matches == NULL)
    return api__oom(ctx);
  api__elems_start(&it, v);
  for (; i < n; i++, api__elems_next(&it)) {
    double *m = &pl->matches[2 * i];
    api__ptr_idx(p, "/matches", i);
    if (!api__elems_point(ctx, &it, "/matches", m))
      return false;
    for (int k = 0; k < 2; k++) {
      api__ptr_idx(q, p, (size_t)k);
      if (!(m[k] > 0 && m[k] < 1))
        return api__invalid(ctx, q,
                            "must be an arc-length fraction strictly "
                            "between 0 and 1");
      if (i > 0 && !(m[k] > m[k - 2]))
        return api__invalid(ctx, q,
                            "must be greater than the previous pair's (matches "
                            "are strictly increasing)");
    }
  }
  pl->opt.matches = pl->matches;
  pl->opt.nmatches = n;
  return true;
}

static bool parse_times(api_ctx *ctx, const cJSON *root, size_t max_frames,
                        api_morph_plan *pl) {
  const cJSON *jt = cJSON_GetObjectItemCaseSensitive(root, "times");
  const cJSON *jf = cJSON_GetObjectItemCaseSensitive(root, "frames");
  size_t n;
  if (jt != NULL && jf != NULL)
    return api__invalid(ctx, "/times",
                        "give either \"frames\" or \"times\", not both");
  if (jt != NULL) {
    double *t = NULL;
    char p[API_POINTER_MAX];
    if (!api__num_array(ctx, jt, "/times", max_frames, &t, &n))
      return false;
    for (size_t i = 0; i < n; i++) {
      if (!(t[i] >= 0 && t[i] <= 1)) {
        free(t);
        api__ptr_idx(p, "/times", i);
        return api__invalid(ctx, p, "must be between 0 and 1");
      }
    }
    pl->frames = calloc(n, sizeof *pl->frames);
    if (pl->frames == NULL) {
      free(t);
      return api__oom(ctx);
    }
    for (size_t i = 0; i < n; i++)
      pl->frames[i].t = t[i];
    free(t);
    pl->times_given = true;
  } else {
    long frames = DEFAULT_FRAMES;
    bool present = false;
    if (!api__member_int(ctx, root, "", "frames", false, LONG_MIN / 2,
                         LONG_MAX / 2, &frames, &present))
      return false;
    if (frames < 2)
      return api__invalid(ctx, "/frames", "must be at least 2");
    if ((unsigned long)frames > max_frames)
      return api__failf(ctx, 422, API_P_LIMIT, "Limit exceeded", "/frames",
                        "%ld frames asked for; the limit is %zu", frames,
                        max_frames);
    n = (size_t)frames;
    pl->frames = calloc(n, sizeof *pl->frames);
    if (pl->frames == NULL)
      return api__oom(ctx);
    for (size_t i = 0; i < n; i++)
      pl->frames[i].t = i + 1 == n ? 1.0 : (double)i / (double)(n - 1);
  }
  pl->nframes = n;
  for (size_t i = 0; i < n; i++) {
    km_curve_init(&pl->frames[i].curve);
    km_signature_init(&pl->frames[i].sig);
  }
  return true;
}

static bool parse_options(api_ctx *ctx, const cJSON *root,
                          api_morph_plan *pl) {
  int method = 0, blend = 0, closure = 0, anchor = 0, orient = 0;
  int format = 0;
  long degree = 3;
  bool fmt_present = false;
  km_morph_options_default(&pl->opt);
  method = (int)pl->opt.method;
  blend = (int)pl->opt.blend;
  closure = (int)pl->opt.closure;
  anchor = (int)pl->opt.anchor;
  orient = (int)pl->opt.orient;
  pl->metrics = true;
  if (!api__member_enum(ctx, root, "", "method", NAMES(method_names), &method,
                        NULL) ||
      !api__member_enum(ctx, root, "", "blend", NAMES(blend_names), &blend,
                        NULL) ||
      !api__member_enum(ctx, root, "", "closure", NAMES(closure_names),
                        &closure, NULL) ||
      !api__member_enum(ctx, root, "", "anchor", NAMES(anchor_names),
                        &anchor, NULL) ||
      !api__member_enum(ctx, root, "", "orient", NAMES(orient_names), &orient,
                        NULL) ||
      !api__member_enum(ctx, root, "", "format", NAMES(format_names), &format,
                        &fmt_present) ||
      !api__member_int(ctx, root, "", "degree", false, -1000000, 1000000,
                       &degree, NULL) ||
      !api__member_bool(ctx, root, "", "metrics", false, &pl->metrics,
                        NULL) ||
      !api__parse_include(ctx, root, true, &pl->inc) ||
      !api__parse_tolerance(ctx, root, &pl->tol))
    return false;
  if (degree != 3 && degree != 5)
    return api__invalid(ctx, "/degree", "must be 3 or 5");
  pl->opt.method = (km_morph_method)method;
  pl->opt.blend = (km_blend)blend;
  pl->opt.closure = (km_closure)closure;
  pl->opt.anchor = (km_anchor)anchor;
  pl->opt.orient = (km_orient)orient;
  pl->opt.degree = (int)degree;
  /* An explicit "format" wins over the Accept header. */
  pl->svg = fmt_present ? format == 1 : false;
  return parse_svg_options(ctx, root, pl) && parse_matches(ctx, root, pl);
}

/* The signature of a curve input, so that its failures name the input. */
static bool input_signature(api_ctx *ctx, api_input *in, const char *ptr,
                            double tol, const km_stop *stop) {
  km_error err;
  km_status st;
  if (in->is_signature)
    return true;
  st = km_signature_compute_until(&in->curve, tol, stop, &in->sig, &err);
  if (st == KM_ECANCELLED)
    return api__stopped(ctx);
  if (st != KM_OK)
    return api__core_fail(ctx, st, &err, ptr, in->kind);
  return true;
}

static km_morph_input morph_input(const api_input *in) {
  km_morph_input mi;
  mi.curve = in->is_signature ? NULL : &in->curve;
  /* For curve inputs the signature is there only if computed above. */
  mi.sig = in->is_signature || in->sig.length > 0 ? &in->sig : NULL;
  return mi;
}

/* -------------------------------------------------- predicted output size */

/* A number as api__number prints it, with its comma: %.17g is at most 24
 * characters (sign, 17 digits, point, "e-308"). */
#define JSON_NUM_BYTES 25
/* A number of an SVG path as api_svg_path_d prints it (the shorter of its
 * %e and %f forms, at most 26 characters) with its separator. */
#define SVG_NUM_BYTES 27
/* A pixel coordinate of an SVG document (canvases of at most 1e5 px, to
 * PX_BUDGET: "-100000.005") with its separator. */
#define PX_NUM_BYTES 12
/* Members, keys and punctuation of a frame besides its numbers (its
 * metrics' five numbers included), and of the document around them. */
#define FRAME_FIXED_BYTES 400
#define DOC_FIXED_BYTES 4096

/* Numbers of cubic pieces' points a curve of n control points puts in a
 * path. Curvature frames are Hermite splines: a cubic's knots are double
 * (a span per two control points, three Bezier points a span), a
 * quintic's at least triple, each span drawn as up to four cubics (halved
 * until within the tolerance). Other curves (linear frames) have a span
 * per control point. */
static size_t path_numbers(size_t n, int degree, bool hermite) {
  if (hermite)
    return (degree <= 3 ? 3 : 8) * n + 2;
  return (degree <= 3 ? 6 : 24) * n + 2;
}

/* Bytes of a path number of magnitude up to M printed within budget (the
 * shorter of its fixed and scientific forms, at most SVG_NUM_BYTES),
 * with its separator. */
static size_t svg_num_bytes(double M, double budget) {
  if (!(M > 0) || !(budget > 0) || !isfinite(M / budget))
    return SVG_NUM_BYTES;
  double ints = fmax(1.0, floor(log10(M)) + 1);
  double decs = fmax(0.0, ceil(log10(0.5 / budget)));
  double b = 3 + ints + decs; /* sign, point, separator */
  return b < SVG_NUM_BYTES ? (size_t)b : SVG_NUM_BYTES;
}

/* Largest coordinate a frame may have: frames lie within a length of the
 * inputs' points (placement keeps them there), so the inputs' largest
 * coordinate plus both lengths. */
static double frames_extent(const api_morph_plan *pl) {
  double m = 0;
  const api_input *in[2] = {&pl->from, &pl->to};
  for (int k = 0; k < 2; k++) {
    if (in[k]->is_signature || in[k]->curve.cp == NULL) {
      m = fmax(m, fabs(in[k]->sig.start[0]) + fabs(in[k]->sig.start[1]));
      continue;
    }
    for (size_t i = 0; i < 2 * in[k]->curve.n; i++)
      m = fmax(m, fabs(in[k]->curve.cp[i]));
  }
  return m + pl->from.length + pl->to.length;
}

size_t api__curve_json_bytes(size_t n, int degree, bool rational,
                             bool svg_d) {
  size_t knots = n + (size_t)degree + 1;
  size_t b = 128 + JSON_NUM_BYTES * (knots + 2 * n + (rational ? n : 0)) +
             3 * n;
  if (svg_d)
    b += 16 + SVG_NUM_BYTES * path_numbers(n, degree, false);
  return b;
}

size_t api__signature_json_bytes(const km_signature *sig) {
  size_t knots = sig->kappa.n + (size_t)sig->kappa.degree + 1;
  return 256 + (JSON_NUM_BYTES + 1) * (knots + sig->kappa.n) +
         (2 * JSON_NUM_BYTES + 16) * sig->ncorners;
}

/* Control points of the frames at most: the frames of a planned morph
 * share one count, known exactly; others are counted at the first, middle
 * and last requested times (without building the curves) and given a
 * quarter more, as the count moves smoothly with t. */
static km_status frame_points(const api_morph_plan *pl, const km_stop *stop,
                              size_t *points, km_error *err) {
  km_frame_parts parts = pl->metrics || pl->want_sig ? KM_FRAME_WITH_METRICS
                                                     : KM_FRAME_CURVE;
  size_t idx[3] = {0, pl->nframes / 2, pl->nframes - 1}, most = 0;
  size_t first = 0, last = 0;
  for (int k = 0; k < 3; k++) {
    size_t n = 0;
    km_status st = km_morph_frame_points(pl->morph, pl->frames[idx[k]].t,
                                         parts, stop, &n, err);
    if (st != KM_OK)
      return st;
    if (k == 0)
      first = n;
    if (k == 2)
      last = n;
    most = n > most ? n : most;
  }
  /* equal counts at both ends and the middle: a planned (constant) count */
  *points = most == first && most == last ? most : most + most / 4 + 8;
  return KM_OK;
}

/* Upper bound on the result's bytes for frames of `points` control
 * points. */
static size_t predict_bytes(const api_morph_plan *pl, size_t points) {
  int degree = pl->opt.degree;
  bool rational = false;
  size_t per, n = pl->nframes;
  if (pl->opt.method == KM_METHOD_LINEAR) {
    degree = pl->from.curve.degree > pl->to.curve.degree
                 ? pl->from.curve.degree
                 : pl->to.curve.degree;
    rational = pl->from.curve.w != NULL || pl->to.curve.w != NULL;
  }
  bool hermite = pl->opt.method == KM_METHOD_CURVATURE;
  size_t numbers = path_numbers(points, degree, hermite);
  if (pl->svg) {
    /* one path a frame, the animation's values repeat every frame's */
    size_t per_path = 64 + PX_NUM_BYTES * numbers;
    per = FRAME_FIXED_BYTES + per_path;
    if (pl->svgopt.layout == API_SVG_ANIMATE)
      per += per_path;
    if (pl->want_sig) {
      /* kappa samples as svg_render.c takes them: a budget per frame
       * shared by the spans of kappa (fewer than the control points), at
       * least three a span, at most 4,002 */
      size_t budget = n > 0 ? 400000 / n : 1600;
      budget = budget > 1600 ? 1600 : budget < 100 ? 100 : budget;
      size_t samples = budget + points > 3 * points ? budget + points
                                                    : 3 * points;
      samples = samples + 2 > 4002 ? 4002 : samples + 2;
      per += samples * 2 * PX_NUM_BYTES;
    }
  } else {
    double M = frames_extent(pl);
    per = FRAME_FIXED_BYTES +
          api__curve_json_bytes(points, degree, rational, false);
    if (pl->inc.svg_d) /* printed within a quarter of the tolerance */
      per += 16 + svg_num_bytes(M, 0.25 * pl->tol) * numbers;
    if (pl->inc.animate_d) /* to 1e-6 of the frame's extent */
      per += 16 + svg_num_bytes(M, 1e-6 * M) * numbers;
  }
  /* matches_used: at most max_control_points pairs */
  size_t matches = pl->opt.auto_matches ? 64 : pl->opt.nmatches;
  size_t fixed = DOC_FIXED_BYTES + (2 * JSON_NUM_BYTES + 3) * matches;
  if (n > 0 && per > (SIZE_MAX - fixed) / n)
    return SIZE_MAX;
  return fixed + per * n;
}

/* Refuse, before any frame is rendered, a result larger than
 * max_output_bytes: naming the tolerance when even the fewest frames (2)
 * would not fit, else the frames. */
static bool check_output_size(api_ctx *ctx, api_morph_plan *pl,
                              const km_stop *stop) {
  size_t points = 0, limit = pl->cfg.max_output_bytes;
  km_error err;
  km_status st = frame_points(pl, stop, &points, &err);
  if (st == KM_ECANCELLED)
    return api__stopped(ctx);
  if (st != KM_OK)
    return api__core_fail(ctx, st, &err, "", API_KIND_REQUEST);
  pl->predicted = predict_bytes(pl, points);
  if (limit == 0 || pl->predicted <= limit)
    return true;
  size_t nframes = pl->nframes;
  pl->nframes = 2;
  bool tol_dominates = predict_bytes(pl, points) > limit;
  pl->nframes = nframes;
  return api__failf(ctx, 422, API_P_LIMIT, "Limit exceeded",
                    tol_dominates ? "/tolerance"
                                  : api_morph_frames_pointer(pl),
                    "the answer would take up to %zu bytes (%zu frames of "
                    "up to %zu control points); the limit is %zu bytes: "
                    "%s",
                    pl->predicted, nframes, points, limit,
                    tol_dominates ? "loosen the tolerance"
                                  : "ask for fewer frames");
}

/* ----------------------------------------------------------------- public */

void api_morph_plan_free(api_morph_plan *plan) {
  if (plan == NULL)
    return;
  km_morph_free(plan->morph);
  for (size_t i = 0; plan->frames != NULL && i < plan->nframes; i++) {
    km_curve_free(&plan->frames[i].curve);
    km_signature_free(&plan->frames[i].sig);
  }
  free(plan->frames);
  free(plan->matches);
  free(plan->request_id);
  api__input_free(&plan->from);
  api__input_free(&plan->to);
  free(plan);
}

api_status api_morph_prepare(const api_config *cfg, const api_request *req,
                             size_t max_frames, api_morph_plan **plan,
                             api_response *error) {
  api_config defaults;
  api_ctx ctx;
  api_morph_plan *pl;
  cJSON *root = NULL;
  km_morph_input fi, ti;
  km_error err;
  km_status st;
  km_stop stop_buf;
  const km_stop *stop = api__km_stop(req, &stop_buf);

  if (cfg == NULL) {
    api_config_default(&defaults);
    cfg = &defaults;
  }
  api_response_init(error);
  api__ctx_init(&ctx, cfg);
  pl = calloc(1, sizeof *pl);
  if (pl == NULL) {
    api__oom(&ctx);
    goto fail;
  }
  pl->cfg = *cfg;
  api__input_init(&pl->from);
  api__input_init(&pl->to);
  if (req->request_id != NULL) {
    size_t n = strlen(req->request_id);
    pl->request_id = malloc(n + 1);
    if (pl->request_id == NULL) {
      api__oom(&ctx);
      goto fail;
    }
    memcpy(pl->request_id, req->request_id, n + 1);
  }
  if (req->route != API_ROUTE_MORPH) {
    api__fail(&ctx, 404, API_P_NOT_FOUND, "Not found", NULL,
              "a morph plan needs a morph request");
    goto fail;
  }
  if ((root = api__parse_body(&ctx, req->body, req->length)) == NULL)
    goto fail;
  /* Cheap checks first: a request with a bad option fails before any
   * curve is fitted. */
  if (!parse_options(&ctx, root, pl) ||
      !parse_times(&ctx, root, max_frames, pl))
    goto fail;
  if (!pl->svg && cJSON_GetObjectItemCaseSensitive(root, "format") == NULL)
    pl->svg = accept_prefers_svg(req->accept);
  pl->want_sig = pl->svg && pl->svgopt.layout == API_SVG_CURVATURE_PLOT;
  if (!api__parse_curve(&ctx, cJSON_GetObjectItemCaseSensitive(root, "from"),
                        "/from", pl->tol, &pl->from) ||
      !api__parse_curve(&ctx, cJSON_GetObjectItemCaseSensitive(root, "to"),
                        "/to", pl->tol, &pl->to))
    goto fail;
  cJSON_Delete(root);
  root = NULL;
  if (pl->tol <= 0)
    pl->tol = 1e-5 * fmax(pl->from.length, pl->to.length);
  pl->opt.tolerance = pl->tol;
  /* frames are curves of the answer: held to the limit on curves */
  pl->opt.max_points = pl->cfg.max_control_points;
  if (pl->opt.method == KM_METHOD_CURVATURE &&
      (!input_signature(&ctx, &pl->from, "/from", pl->tol, stop) ||
       !input_signature(&ctx, &pl->to, "/to", pl->tol, stop)))
    goto fail;
  fi = morph_input(&pl->from);
  ti = morph_input(&pl->to);
  pl->opt.stop = stop;
  st = km_morph_create(&pl->morph, &fi, &ti, &pl->opt, &err);
  pl->opt.stop = NULL;
  if (st == KM_ECANCELLED) {
    api__stopped(&ctx);
    goto fail;
  }
  if (st != KM_OK) {
    api__core_fail(&ctx, st, &err, "", API_KIND_REQUEST);
    goto fail;
  }
  if (!check_output_size(&ctx, pl, stop))
    goto fail;
  *plan = pl;
  return API_STEP_DONE;
fail:
  cJSON_Delete(root);
  api__ctx_problem(&ctx, error, req->request_id);
  api_morph_plan_free(pl);
  return error->status;
}

size_t api_morph_frame_count(const api_morph_plan *plan) {
  return plan != NULL ? plan->nframes : 0;
}

const char *api_morph_frames_pointer(const api_morph_plan *plan) {
  return plan != NULL && plan->times_given ? "/times" : "/frames";
}

api_status api_morph_render_frame(api_morph_plan *plan, size_t i) {
  return api_morph_render_frame_until(plan, i, NULL, NULL);
}

size_t api_morph_predicted_bytes(const api_morph_plan *plan) {
  return plan != NULL ? plan->predicted : 0;
}

api_status api_morph_render_frame_until(api_morph_plan *plan, size_t i,
                                        api_stop_fn stop, void *ctx) {
  frame_slot *f;
  km_stop ks = {stop, ctx};
  if (plan == NULL || i >= plan->nframes)
    return 404;
  f = &plan->frames[i];
  if (f->state == 1)
    return API_STEP_DONE;
  km_curve_free(&f->curve);
  km_signature_free(&f->sig);
  memset(&f->err, 0, sizeof f->err);
  f->st = km_morph_frame_until(plan->morph, f->t, stop != NULL ? &ks : NULL,
                               &f->curve, plan->metrics ? &f->metrics : NULL,
                               plan->want_sig ? &f->sig : NULL, &f->err);
  if (f->st != KM_OK) {
    f->state = -1;
    return f->st == KM_ENOMEM || f->st == KM_ECANCELLED ? 503 : 422;
  }
  f->state = 1;
  return API_STEP_DONE;
}

/* Number of cubic pieces in an SVG path written as "M x y C ..." with the
 * C command not repeated: six numbers a piece after the two of the moveto. */
static size_t count_pieces(const char *d) {
  size_t numbers = 0;
  while (*d != '\0') {
    char *end;
    if ((*d >= '0' && *d <= '9') || *d == '-' || *d == '+' || *d == '.') {
      strtod(d, &end);
      if (end == d) {
        d++;
        continue;
      }
      numbers++;
      d = end;
    } else {
      d++;
    }
  }
  return numbers > 2 ? (numbers - 2) / 6 : 1;
}

static cJSON *metrics_json(api_ctx *ctx, const km_frame_metrics *m) {
  cJSON *o = cJSON_CreateObject();
  if (o == NULL) {
    api__oom(ctx);
    return NULL;
  }
  if (!api__add_num(ctx, o, "length", m->length) ||
      !api__add_num(ctx, o, "max_abs_kappa", m->max_abs_kappa) ||
      !api__add_num(ctx, o, "bending_energy", m->bending_energy) ||
      !api__add_num(ctx, o, "self_intersections",
                    (double)m->self_intersections) ||
      !api__add_num(ctx, o, "closure_gap", m->closure_gap)) {
    cJSON_Delete(o);
    return NULL;
  }
  return o;
}

/* "animate_d": every frame as a path with one common number of cubic
 * pieces, the most any frame needs at the tolerance, so that SMIL or CSS
 * can interpolate between them. */
static cJSON *animate_json(api_ctx *ctx, const api_morph_plan *pl) {
  size_t pieces = 1;
  cJSON *a;
  for (size_t i = 0; i < pl->nframes; i++) {
    char *d = api_svg_path_d(&pl->frames[i].curve, pl->tol, NULL);
    if (d == NULL) {
      api__oom(ctx);
      return NULL;
    }
    pieces = count_pieces(d) > pieces ? count_pieces(d) : pieces;
    free(d);
  }
  a = cJSON_CreateArray();
  if (a == NULL) {
    api__oom(ctx);
    return NULL;
  }
  for (size_t i = 0; i < pl->nframes; i++) {
    char *d = api_svg_path_d_fixed(&pl->frames[i].curve, pieces);
    cJSON *s = d != NULL ? cJSON_CreateString(d) : NULL;
    free(d);
    if (s == NULL) {
      cJSON_Delete(a);
      api__oom(ctx);
      return NULL;
    }
    cJSON_AddItemToArray(a, s);
  }
  return a;
}

static api_status result_json(api_ctx *ctx, api_morph_plan *pl,
                              api_response *out) {
  cJSON *root = cJSON_CreateObject(), *frames, *mu;
  double *pairs = NULL;
  size_t npairs;
  if (root == NULL) {
    api__oom(ctx);
    goto fail;
  }
  if (cJSON_AddStringToObject(root, "method",
                              method_names[pl->opt.method]) == NULL ||
      (frames = cJSON_AddArrayToObject(root, "frames")) == NULL) {
    api__oom(ctx);
    goto fail;
  }
  for (size_t i = 0; i < pl->nframes; i++) {
    frame_slot *f = &pl->frames[i];
    cJSON *fo = cJSON_CreateObject(), *c;
    if (fo == NULL) {
      api__oom(ctx);
      goto fail;
    }
    cJSON_AddItemToArray(frames, fo);
    if (!api__add_num(ctx, fo, "t", f->t))
      goto fail;
    if ((c = api__curve_json(ctx, &f->curve, pl->inc.svg_d, pl->tol)) == NULL)
      goto fail;
    cJSON_AddItemToObject(fo, "curve", c);
    if (pl->metrics) {
      if ((c = metrics_json(ctx, &f->metrics)) == NULL)
        goto fail;
      cJSON_AddItemToObject(fo, "metrics", c);
    }
  }
  npairs = km_morph_matches_used(pl->morph, NULL, 0);
  pairs = malloc((npairs > 0 ? 2 * npairs : 1) * sizeof *pairs);
  if (pairs == NULL) {
    api__oom(ctx);
    goto fail;
  }
  npairs = km_morph_matches_used(pl->morph, pairs, npairs);
  if (npairs > 0) {
    if ((mu = api__num_array_json(ctx, pairs, npairs, 2)) == NULL)
      goto fail;
  } else if ((mu = cJSON_CreateArray()) == NULL) {
    api__oom(ctx);
    goto fail;
  }
  cJSON_AddItemToObject(root, "matches_used", mu);
  if (pl->inc.animate_d) {
    cJSON *a = animate_json(ctx, pl);
    if (a == NULL)
      goto fail;
    cJSON_AddItemToObject(root, "animate_d", a);
  }
  free(pairs);
  return api__respond_json(ctx, root, 200, out, pl->request_id);
fail:
  free(pairs);
  cJSON_Delete(root);
  api__ctx_problem(ctx, out, pl->request_id);
  return out->status;
}

static api_status result_svg(api_ctx *ctx, api_morph_plan *pl,
                             api_response *out) {
  api_svg_frame *fr = malloc(pl->nframes * sizeof *fr);
  char *doc;
  if (fr == NULL) {
    api__oom(ctx);
    api__ctx_problem(ctx, out, pl->request_id);
    return out->status;
  }
  for (size_t i = 0; i < pl->nframes; i++) {
    fr[i].t = pl->frames[i].t;
    fr[i].curve = &pl->frames[i].curve;
    fr[i].sig = pl->want_sig ? &pl->frames[i].sig : NULL;
  }
  doc = api_svg_morph_document(fr, pl->nframes, &pl->svgopt);
  free(fr);
  if (doc == NULL) {
    api__oom(ctx);
    api__ctx_problem(ctx, out, pl->request_id);
    return out->status;
  }
  out->status = 200;
  out->content_type = API_CT_SVG;
  out->body = doc;
  out->length = strlen(doc);
  return 200;
}

api_status api_morph_result(api_morph_plan *plan, api_response *out) {
  api_ctx ctx;
  api_response_init(out);
  if (plan == NULL) {
    api_problem(out, 500, API_P_INTERNAL, "Internal error", "no morph plan",
                NULL, NULL, NULL);
    return out->status;
  }
  api__ctx_init(&ctx, &plan->cfg);
  for (size_t i = 0; i < plan->nframes; i++) {
    frame_slot *f = &plan->frames[i];
    char base[API_POINTER_MAX];
    if (f->state == 0)
      api_morph_render_frame(plan, i);
    if (f->state == 1)
      continue;
    if (f->st == KM_ECANCELLED) {
      api__stopped(&ctx);
      api__ctx_problem(&ctx, out, plan->request_id);
      return out->status;
    }
    /* Name the frame: its entry of "times", or the request as a whole. */
    if (plan->times_given)
      api__ptr_idx(base, "/times", i);
    else
      snprintf(base, sizeof base, "%s", "");
    {
      km_error e = f->err;
      char msg[API_TEXT_MAX];
      e.field = KM_FIELD_NONE;
      api__core_fail(&ctx, f->st, &e, base, API_KIND_REQUEST);
      snprintf(msg, sizeof msg, "frame %zu (t = %.17g): ", i, f->t);
      strncat(msg, ctx.message, sizeof msg - strlen(msg) - 1);
      memcpy(ctx.message, msg, sizeof msg);
      memcpy(ctx.detail, msg, sizeof msg);
    }
    api__ctx_problem(&ctx, out, plan->request_id);
    return out->status;
  }
  return plan->svg ? result_svg(&ctx, plan, out)
                   : result_json(&ctx, plan, out);
}
