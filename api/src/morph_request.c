/* morph_request.c - the morph request read into a plan: its options, its
 * frames or times, its matches, its SVG options, the answer's format and
 * both input curves, each failure naming the member at fault.
 */
#include <ctype.h>
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "km/alloc.h"
#include "morph_plan.h"

/* "intersections" when the request does not say: avoid, which keeps the
 * frames of morphs that do not cross and costs them about 1% (bench/
 * RESULTS.md, "Crossing avoidance"). */
#define API_DEFAULT_INTERSECTIONS KM_INTERSECTIONS_AVOID
/* Frames when neither "frames" nor "times" is given. */
#define DEFAULT_FRAMES 11

const char *const api__morph_method_names[2] = {"curvature", "linear"};
static const char *const blend_names[] = {"turning", "paper"};
static const char *const closure_names[] = {"auto", "lsq", "c0",
                                            "c1",   "g2",  "none"};
static const char *const anchor_names[] = {"fit", "start", "centroid"};
static const char *const orient_names[] = {"auto", "keep"};
static const char *const intersections_names[] = {"allow", "avoid"};
static const char *const format_names[] = {"json", "svg"};
static const char *const layout_names[] = {"filmstrip", "overlay", "animate",
                                           "curvature_plot"};
/* The members of a morph request (and of a job's) and of its "svg". */
static const char *const morph_members[] = {
    "from",      "to",      "frames",
    "times",     "method",  "blend",
    "matches",   "closure", "contour_matches",
    "anchor",    "orient",  "intersections",
    "tolerance", "degree",  "metrics",
    "precision", "include", "format",
    "svg"};
static const char *const svg_option_members[] = {
    "layout",   "width",  "height",     "stroke_width",
    "duration", "stroke", "from_color", "to_color"};

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
_Static_assert(KM_INTERSECTIONS_ALLOW == 0 && KM_INTERSECTIONS_AVOID == 1,
               "intersections order");
_Static_assert(API_SVG_FILMSTRIP == 0 && API_SVG_OVERLAY == 1 &&
                   API_SVG_ANIMATE == 2 && API_SVG_CURVATURE_PLOT == 3,
               "layout order");

#define NAMES(a) a, sizeof a / sizeof a[0]

/* ---------------------------------------------------- the Accept header */

static bool ascii_prefix_ci(const char *s, const char *prefix, size_t n) {
  for (size_t i = 0; i < n; i++)
    if (s[i] == '\0' || tolower((unsigned char)s[i]) != prefix[i]) return false;
  return true;
}

/* q value of one media range's parameters ("; q=0.5"); 1 when absent. */
static double accept_q(const char *p, const char *end) {
  while (p < end) {
    while (p < end && (*p == ';' || *p == ' ' || *p == '\t')) p++;
    if (end - p >= 2 && (p[0] == 'q' || p[0] == 'Q') && p[1] == '=') {
      double q = strtod(p + 2, NULL);
      return isfinite(q) ? q : 0;
    }
    while (p < end && *p != ';') p++;
  }
  return 1;
}

/* Does the Accept header prefer SVG to JSON? JSON wins ties and is what
 * "* / *" and absent headers get. */
static bool accept_prefers_svg(const char *accept) {
  double q_svg = -1, q_json = -1;
  const char *p = accept;
  if (accept == NULL) return false;
  while (*p != '\0') {
    const char *end = strchr(p, ',');
    const char *semi;
    size_t n;
    if (end == NULL) end = p + strlen(p);
    while (p < end && (*p == ' ' || *p == '\t')) p++;
    semi = memchr(p, ';', (size_t)(end - p));
    if (semi == NULL) semi = end;
    n = (size_t)(semi - p);
    while (n > 0 && (p[n - 1] == ' ' || p[n - 1] == '\t')) n--;
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

  /* ------------------------------------------------------------ the options */
}

/* A colour is copied into the SVG document: allow only what CSS colour
 * syntax needs (names, #hex, rgb()/hsl() with numbers), so nothing can
 * close an attribute or open markup. */
static bool parse_colour(api_ctx *ctx, const cJSON *svg, const char *key,
                         char *dst, const char **out) {
  char p[API_POINTER_MAX];
  const cJSON *v = cJSON_GetObjectItemCaseSensitive(svg, key);
  size_t n;
  if (v == NULL) return true;
  api__ptr_key(p, "/svg", key);
  if (!cJSON_IsString(v))
    return api__invalid(ctx, p, "must be a colour string");
  n = strlen(v->valuestring);
  if (n == 0 || n >= API_COLOUR_MAX)
    return api__invalid(ctx, p, "must be a colour of 1 to %d characters",
                        API_COLOUR_MAX - 1);
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
  if (!present) return true;
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
  if (svg == NULL) return true;
  if (!cJSON_IsObject(svg))
    return api__invalid(ctx, "/svg", "must be an object");
  if (!api__known_members(ctx, svg, "/svg", API_NAMES(svg_option_members)))
    return false;
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
         parse_colour(ctx, svg, "to_color", pl->to_color, &pl->svgopt.to_color);
}

/* "matches": "auto" or [[r_from, r_to], ...] strictly increasing in (0,1)
 * on both sides. */
static bool parse_matches(api_ctx *ctx, const cJSON *root, api_morph_plan *pl) {
  const cJSON *v = cJSON_GetObjectItemCaseSensitive(root, "matches");
  api_elems it;
  char p[API_POINTER_MAX], q[API_POINTER_MAX];
  size_t n, i = 0;
  if (v == NULL || cJSON_IsNull(v)) return true;
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
  if (n == 0) return true;
  if (n > pl->cfg.max_control_points)
    return api__failf(ctx, 422, API_P_LIMIT, "Limit exceeded", "/matches",
                      "has %zu pairs; the limit is %zu", n,
                      pl->cfg.max_control_points);
  pl->matches = km__malloc(2 * n * sizeof *pl->matches);
  if (pl->matches == NULL) return api__oom(ctx);
  api__elems_start(&it, v);
  for (; i < n; i++, api__elems_next(&it)) {
    double *m = &pl->matches[2 * i];
    api__ptr_idx(p, "/matches", i);
    if (!api__elems_point(ctx, &it, "/matches", m)) return false;
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
    if (!api__num_array(ctx, jt, "/times", max_frames, &t, &n)) return false;
    for (size_t i = 0; i < n; i++) {
      if (!(t[i] >= 0 && t[i] <= 1)) {
        km__free(t);
        api__ptr_idx(p, "/times", i);
        return api__invalid(ctx, p, "must be between 0 and 1");
      }
    }
    pl->frames = km__calloc(n, sizeof *pl->frames);
    if (pl->frames == NULL) {
      km__free(t);
      return api__oom(ctx);
    }
    for (size_t i = 0; i < n; i++) pl->frames[i].t = t[i];
    km__free(t);
    pl->times_given = true;
  } else {
    long frames = DEFAULT_FRAMES;
    bool present = false;
    if (!api__member_int(ctx, root, "", "frames", false, LONG_MIN / 2,
                         LONG_MAX / 2, &frames, &present))
      return false;
    if (frames < 2) return api__invalid(ctx, "/frames", "must be at least 2");
    if ((unsigned long)frames > max_frames)
      return api__failf(ctx, 422, API_P_LIMIT, "Limit exceeded", "/frames",
                        "%ld frames asked for; the limit is %zu", frames,
                        max_frames);
    n = (size_t)frames;
    pl->frames = km__calloc(n, sizeof *pl->frames);
    if (pl->frames == NULL) return api__oom(ctx);
    for (size_t i = 0; i < n; i++)
      pl->frames[i].t = i + 1 == n ? 1.0 : (double)i / (double)(n - 1);
  }
  pl->nframes = n;
  for (size_t i = 0; i < n; i++) {
    km_curve_init(&pl->frames[i].curve);
    km_signature_init(&pl->frames[i].sig);
    km_shape_frame_init(&pl->frames[i].shape);
  }
  return true;
}

static bool parse_options(api_ctx *ctx, const cJSON *root, api_morph_plan *pl) {
  int method = 0, blend = 0, closure = 0, anchor = 0, orient = 0;
  int crossings = API_DEFAULT_INTERSECTIONS;
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
  if (!api__member_enum(ctx, root, "", "method", NAMES(api__morph_method_names),
                        &method, NULL) ||
      !api__member_enum(ctx, root, "", "blend", NAMES(blend_names), &blend,
                        NULL) ||
      !api__member_enum(ctx, root, "", "closure", NAMES(closure_names),
                        &closure, NULL) ||
      !api__member_enum(ctx, root, "", "anchor", NAMES(anchor_names), &anchor,
                        NULL) ||
      !api__member_enum(ctx, root, "", "orient", NAMES(orient_names), &orient,
                        NULL) ||
      !api__member_enum(ctx, root, "", "intersections",
                        NAMES(intersections_names), &crossings, NULL) ||
      !api__member_enum(ctx, root, "", "format", NAMES(format_names), &format,
                        &fmt_present) ||
      !api__member_int(ctx, root, "", "degree", false, -1000000, 1000000,
                       &degree, NULL) ||
      !api__member_bool(ctx, root, "", "metrics", false, &pl->metrics, NULL) ||
      !api__parse_include(ctx, root, true, &pl->inc) ||
      !api__parse_precision(ctx, root, &pl->precision) ||
      !api__parse_tolerance(ctx, root, &pl->tol))
    return false;
  if (degree != 3 && degree != 5)
    return api__invalid(ctx, "/degree", "must be 3 or 5");
  pl->opt.method = (km_morph_method)method;
  pl->opt.blend = (km_blend)blend;
  pl->opt.closure = (km_closure)closure;
  pl->opt.anchor = (km_anchor)anchor;
  pl->opt.orient = (km_orient)orient;
  pl->opt.intersections = (km_intersections)crossings;
  pl->opt.degree = (int)degree;
  /* An explicit "format" wins over the Accept header. */
  pl->svg = fmt_present ? format == 1 : false;
  return parse_svg_options(ctx, root, pl) && parse_matches(ctx, root, pl) &&
         api__shape_read_matches(ctx, root, pl);
}

bool api__morph_read_request(api_ctx *ctx, const cJSON *root,
                             const char *accept, size_t max_frames,
                             api_morph_plan *pl) {
  if (!api__known_members(ctx, root, "", API_NAMES(morph_members)) ||
      !parse_options(ctx, root, pl) || !parse_times(ctx, root, max_frames, pl))
    return false;
  if (!pl->svg && cJSON_GetObjectItemCaseSensitive(root, "format") == NULL)
    pl->svg = accept_prefers_svg(accept);
  pl->want_sig = pl->svg && pl->svgopt.layout == API_SVG_CURVATURE_PLOT;
  return api__parse_curve(ctx, cJSON_GetObjectItemCaseSensitive(root, "from"),
                          "/from", pl->tol, &pl->from) &&
         api__parse_curve(ctx, cJSON_GetObjectItemCaseSensitive(root, "to"),
                          "/to", pl->tol, &pl->to) &&
         api__shape_check_request(ctx, pl);
}
