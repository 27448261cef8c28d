/* morph_size.c - an upper bound on the bytes of a morph's answer, found
 * before any frame is rendered, and the refusal of answers above
 * max_output_bytes.
 *
 * DESIGN: the bound comes from the frames' control points (counted by the
 * core without building the curves) and the largest number each part of
 * the answer prints; it must never be below the true size, since
 * callers reserve result memory from it.
 */
#include <math.h>
#include <stdint.h>

#include "morph_plan.h"

/* A pixel coordinate of an SVG document (canvases of at most 1e5 px, to
 * PX_BUDGET: "-100000.005") with its separator. */
#define PX_NUM_BYTES 12
/* Members, keys and punctuation of a frame besides its numbers (its
 * metrics' five numbers included), and of the document around them. */
#define FRAME_FIXED_BYTES 400
#define DOC_FIXED_BYTES 4096

/* Bytes of a path number of magnitude up to M printed within budget (the
 * shorter of its fixed and scientific forms, at most API_SVG_NUM_BYTES),
 * with its separator. */
static size_t svg_num_bytes(double M, double budget) {
  if (!(M > 0) || !(budget > 0) || !isfinite(M / budget))
    return API_SVG_NUM_BYTES;
  double ints = fmax(1.0, floor(log10(M)) + 1);
  double decs = fmax(0.0, ceil(log10(0.5 / budget)));
  double b = 3 + ints + decs; /* sign, point, separator */
  return b < API_SVG_NUM_BYTES ? (size_t)b : API_SVG_NUM_BYTES;
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

/* Control points of the frames at most: the frames of a morph are counted at the first, middle
 * and last requested times (without building the curves) and given a
 * quarter more, as the count moves smoothly with t. */
static km_status frame_points(const api_morph_plan *pl, const km_stop *stop,
                              size_t *points, km_error *err) {
  km_frame_parts parts = pl->want_sig  ? KM_FRAME_WITH_SIGNATURE
                         : pl->metrics ? KM_FRAME_WITH_METRICS
                                       : KM_FRAME_CURVE;
  size_t idx[3] = {0, pl->nframes / 2, pl->nframes - 1}, most = 0;
  size_t first = 0, last = 0;
  for (int k = 0; k < 3; k++) {
    size_t n = 0;
    km_status st = km_morph_frame_points(pl->morph, pl->frames[idx[k]].t, parts,
                                         stop, &n, err);
    if (st != KM_OK) return st;
    if (k == 0) first = n;
    if (k == 2) last = n;
    most = n > most ? n : most;
  }
  /* equal counts at both ends and the middle: a constant count */
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
    degree = pl->from.curve.degree > pl->to.curve.degree ? pl->from.curve.degree
                                                         : pl->to.curve.degree;
    rational = pl->from.curve.w != NULL || pl->to.curve.w != NULL;
  }
  bool hermite = pl->opt.method == KM_METHOD_CURVATURE;
  size_t numbers = api__path_numbers(points, degree, hermite);
  if (pl->svg) {
    /* one path a frame, the animation's values repeat every frame's; a
     * curvature plot draws kappa only, not the frames' paths */
    size_t per_path = 64 + PX_NUM_BYTES * numbers;
    per = FRAME_FIXED_BYTES + (pl->want_sig ? 0 : per_path);
    if (pl->svgopt.layout == API_SVG_ANIMATE) per += per_path;
    if (pl->want_sig) {
      /* kappa samples as svg_curvature_plot.c takes them: a budget per
       * frame shared by the spans of kappa (fewer than the control
       * points), at least three a span, at most 4,002 */
      size_t budget = n > 0 ? 400000 / n : 1600;
      budget = budget > 1600 ? 1600 : budget < 100 ? 100 : budget;
      size_t samples =
          budget + points > 3 * points ? budget + points : 3 * points;
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
    if (pl->opt.intersections == KM_INTERSECTIONS_AVOID)
      per += 24; /* the frame's index in intersections/crossing_frames */
  }
  /* matches_used: at most max_control_points pairs */
  size_t matches = pl->opt.auto_matches ? 64 : pl->opt.nmatches;
  size_t fixed = DOC_FIXED_BYTES + (2 * API_JSON_NUM_BYTES + 3) * matches;
  if (n > 0 && per > (SIZE_MAX - fixed) / n) return SIZE_MAX;
  return fixed + per * n;
}

/* Refuse, before any frame is rendered, a result larger than
 * max_output_bytes: naming the tolerance when even the fewest frames (2)
 * would not fit, else the frames. */
bool api__morph_check_size(api_ctx *ctx, api_morph_plan *pl,
                           const km_stop *stop) {
  size_t points = 0, limit = pl->cfg.max_output_bytes;
  km_error err;
  km_status st = frame_points(pl, stop, &points, &err);
  if (st == KM_ECANCELLED) return api__stopped(ctx);
  if (st != KM_OK) return api__core_fail(ctx, st, &err, "", API_KIND_REQUEST);
  pl->predicted = predict_bytes(pl, points);
  if (limit == 0 || pl->predicted <= limit) return true;
  size_t nframes = pl->nframes;
  pl->nframes = 2;
  bool tol_dominates = predict_bytes(pl, points) > limit;
  pl->nframes = nframes;
  return api__failf(ctx, 422, API_P_LIMIT, "Limit exceeded",
                    tol_dominates ? "/tolerance" : api_morph_frames_pointer(pl),
                    "the answer would take up to %zu bytes (%zu frames of "
                    "up to %zu control points); the limit is %zu bytes: "
                    "%s",
                    pl->predicted, nframes, points, limit,
                    tol_dominates ? "loosen the tolerance"
                                  : "ask for fewer frames");
}
