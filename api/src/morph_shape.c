/* morph_shape.c - the morph of compound shapes: the request's contour
 * pairing, the shapes built from the inputs, their frames rendered, the
 * answer's size bounded and its frames printed.
 *
 * DESIGN: a compound morph runs through the same plan as a single one
 * (api_morph_prepare, render_frame_until, result), with the shapes and
 * their km_shape_morph in place of the km_morph and a km_shape_frame in
 * each slot. A single curve on one side is a shape of one contour. Every
 * failure names the contour it is about: "/from/contours/2" for a JSON
 * shape, "/from/d" with the subpath's offset for SVG, since a pointer
 * cannot reach inside a string.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "json_write.h"
#include "km/alloc.h"
#include "morph_plan.h"

/* A contour index of "contour_matches": null, or an integer in
 * [0, KM_SHAPE_MAX_CONTOURS). */
static bool match_index(api_ctx *ctx, const cJSON *item, const double *num,
                        const char *ptr, long *out) {
  double v;
  if (num == NULL && cJSON_IsNull(item)) {
    *out = -1;
    return true;
  }
  if (num == NULL && !cJSON_IsNumber(item))
    return api__invalid(ctx, ptr, "must be a contour index or null");
  v = num != NULL ? *num : item->valuedouble;
  if (!(v >= 0 && v < KM_SHAPE_MAX_CONTOURS) || v != floor(v))
    return api__invalid(ctx, ptr,
                        "must be a contour index (an integer >= 0) or null");
  *out = (long)v;
  return true;
}

/* Pair k of "contour_matches" (an element, packed or not) into *pr. */
static bool match_pair(api_ctx *ctx, const api_elems *it, const char *ptr,
                       km_shape_pair *pr) {
  char p[API_POINTER_MAX], q[API_POINTER_MAX];
  long idx[2];
  api__ptr_idx(p, ptr, it->index);
  if (it->packed != NULL && it->width != 2)
    return api__invalid(ctx, p, "must be a pair [i, j] of contour indices");
  if (it->packed == NULL &&
      (!cJSON_IsArray(it->item) || api__array_len(it->item) != 2))
    return api__invalid(ctx, p,
                        "must be a pair [i, j] (contour indices, or null "
                        "for an unpaired contour)");
  size_t w = 0;
  const double *nums = it->packed != NULL ? it->packed + 2 * it->index
                                          : api__array_packed(it->item, &w);
  if (w != 0)
    return api__invalid(ctx, p, "must be a pair [i, j] of contour indices");
  for (int k = 0; k < 2; k++) {
    const cJSON *e = nums == NULL ? cJSON_GetArrayItem(it->item, k) : NULL;
    api__ptr_idx(q, p, (size_t)k);
    if (!match_index(ctx, e, nums != NULL ? nums + k : NULL, q, &idx[k]))
      return false;
  }
  if (idx[0] < 0 && idx[1] < 0)
    return api__invalid(ctx, p, "must name a contour on at least one side");
  pr->from = idx[0];
  pr->to = idx[1];
  return true;
}

bool api__shape_read_matches(api_ctx *ctx, const cJSON *root,
                             api_morph_plan *pl) {
  const cJSON *v = cJSON_GetObjectItemCaseSensitive(root, "contour_matches");
  size_t n, max = 2 * api__max_contours(&pl->cfg);
  api_elems it;
  if (v == NULL || cJSON_IsNull(v)) return true;
  if (!cJSON_IsArray(v) || (n = api__array_len(v)) == 0)
    return api__invalid(ctx, "/contour_matches",
                        "must be a non-empty array of [i, j] pairs (null "
                        "for an unpaired contour)");
  if (n > max)
    return api__failf(ctx, 422, API_P_LIMIT, "Limit exceeded",
                      "/contour_matches", "has %zu pairs; the limit is %zu", n,
                      max);
  if ((pl->cmatches = km__malloc(n * sizeof *pl->cmatches)) == NULL)
    return api__oom(ctx);
  api__elems_start(&it, v);
  for (size_t i = 0; i < n; i++) {
    if (i > 0) api__elems_next(&it);
    if (!match_pair(ctx, &it, "/contour_matches", &pl->cmatches[i]))
      return false;
  }
  pl->ncmatches = n;
  return true;
}

/* The single-curve side of a compound morph must be a closed curve. */
static bool check_single(api_ctx *ctx, const api_input *in, const char *ptr) {
  if (in->is_shape) return true;
  if (in->is_signature)
    return api__invalid(ctx, ptr,
                        "a signature cannot be morphed with a shape: give "
                        "the contour as a curve");
  if (!in->curve.closed)
    return api__invalid(ctx, ptr,
                        "an open curve cannot be morphed with a shape: "
                        "every contour of a shape is closed");
  return true;
}

bool api__shape_check_request(api_ctx *ctx, api_morph_plan *pl) {
  if (!pl->from.is_shape && !pl->to.is_shape) {
    if (pl->cmatches != NULL)
      return api__invalid(ctx, "/contour_matches",
                          "pairs the contours of shapes: neither input "
                          "has several contours");
    return true;
  }
  pl->shapes = true;
  if (!check_single(ctx, &pl->from, "/from") ||
      !check_single(ctx, &pl->to, "/to"))
    return false;
  if (pl->opt.nmatches > 0)
    return api__invalid(ctx, "/matches",
                        "arc-length matches pair points of two single "
                        "curves; pair the contours of shapes with "
                        "\"contour_matches\"");
  return true;
}

/* ------------------------------------------------------------ building */

/* The failure st of contour i of in (at ptr): the core's problem under the
 * contour's pointer, its place ahead of the message. */
static bool contour_fail(api_ctx *ctx, const api_input *in, const char *ptr,
                         long i, km_status st, const km_error *err) {
  char p[API_POINTER_MAX], where[96], msg[API_TEXT_MAX];
  km_error e = *err;
  if (st == KM_ENOMEM) return api__oom(ctx);
  if (st == KM_ECANCELLED) return api__stopped(ctx);
  e.field = KM_FIELD_NONE;
  if (!in->is_shape || i < 0 || (size_t)i >= in->ncontours)
    return api__core_fail(ctx, st, &e, ptr, API_KIND_REQUEST);
  api__contour_ptr(p, in, ptr, (size_t)i);
  api__contour_where(where, sizeof where, in, (size_t)i);
  api__core_fail(ctx, st, &e, p, API_KIND_CURVE);
  if (ctx->message[0] != '\0' &&
      strncmp(ctx->message, where, strlen(where)) != 0) {
    snprintf(msg, sizeof msg, "%s: ", where);
    strncat(msg, ctx->message, sizeof msg - strlen(msg) - 1);
    memcpy(ctx->message, msg, sizeof msg);
    memcpy(ctx->detail, msg, sizeof msg);
  }
  return false;
}

static bool shape_of(api_ctx *ctx, const api_input *in, const char *ptr,
                     const api_config *cfg, km_shape *out) {
  km_shape_limits lim = {api__max_contours(cfg), cfg->max_control_points};
  const km_curve *c = in->is_shape ? in->contours : &in->curve;
  size_t n = in->is_shape ? in->ncontours : 1;
  km_error err;
  km_status st = km_shape_create(out, c, n, in->fill, &lim, &err);
  if (st != KM_OK) return contour_fail(ctx, in, ptr, err.index, st, &err);
  return true;
}

/* A pairing's failure: the pair of "contour_matches" at fault. */
static bool matches_fail(api_ctx *ctx, const api_morph_plan *pl,
                         const km_error *err) {
  char p[API_POINTER_MAX];
  if (err->index >= 0 && (size_t)err->index < pl->ncmatches)
    api__ptr_idx(p, "/contour_matches", (size_t)err->index);
  else
    snprintf(p, sizeof p, "/contour_matches");
  return api__fail(ctx, 422, API_P_INVALID_REQUEST, "Invalid request", p,
                   err->message[0] != '\0' ? err->message
                                           : km_status_message(KM_EMATCH));
}

/* A pair's morph failed: name the contour of its from side (its to side
 * when it has none). */
static bool pair_fail(api_ctx *ctx, const api_morph_plan *pl,
                      const km_shape_pair *pairs, size_t npairs, km_status st,
                      const km_error *err) {
  if (err->index >= 0 && (size_t)err->index < npairs) {
    const km_shape_pair *pr = &pairs[err->index];
    if (pr->from >= 0)
      return contour_fail(ctx, &pl->from, "/from", pr->from, st, err);
    return contour_fail(ctx, &pl->to, "/to", pr->to, st, err);
  }
  return contour_fail(ctx, &pl->from, "", -1, st, err);
}

bool api__shape_build(api_ctx *ctx, api_morph_plan *pl, const km_stop *stop) {
  km_shape_morph_options so;
  km_shape_pair *pairs = NULL;
  size_t npairs = 0;
  km_error err;
  km_status st;
  bool ok = false;
  if (!shape_of(ctx, &pl->from, "/from", &pl->cfg, &pl->sfrom) ||
      !shape_of(ctx, &pl->to, "/to", &pl->cfg, &pl->sto))
    return false;
  if (pl->cmatches != NULL) {
    st = km_shape_pair_check(&pl->sfrom, &pl->sto, pl->cmatches, pl->ncmatches,
                             &err);
    if (st != KM_OK)
      return st == KM_EMATCH ? matches_fail(ctx, pl, &err)
                             : contour_fail(ctx, &pl->from, "", -1, st, &err);
    pairs = pl->cmatches;
    npairs = pl->ncmatches;
  } else {
    /* paired here, not inside the morph, so that a pair's failure can
     * name its contours */
    st = km_shape_pair_auto(&pl->sfrom, &pl->sto, NULL, stop, &pairs, &npairs,
                            &err);
    if (st != KM_OK) return contour_fail(ctx, &pl->from, "", -1, st, &err);
  }
  km_shape_morph_options_default(&so);
  so.morph = pl->opt;
  so.morph.stop = NULL;
  so.pairs = pairs;
  so.npairs = npairs;
  so.pairs_free = pl->cmatches == NULL; /* not a person's pairing */
  st =
      km_shape_morph_create(&pl->smorph, &pl->sfrom, &pl->sto, &so, stop, &err);
  if (st == KM_EMATCH && pl->cmatches != NULL)
    matches_fail(ctx, pl, &err);
  else if (st != KM_OK)
    pair_fail(ctx, pl, pairs, npairs, st, &err);
  else
    ok = true;
  if (pairs != pl->cmatches) km_shape_pairs_free(pairs);
  return ok;
}

void api__shape_render(api_morph_plan *pl, api_frame_slot *f,
                       const km_stop *stop) {
  km_shape_frame_free(&f->shape);
  memset(&f->err, 0, sizeof f->err);
  f->st =
      km_shape_morph_frame_until(pl->smorph, f->t, stop, &f->shape, &f->err);
  f->state = f->st == KM_OK ? API_FRAME_DONE : API_FRAME_FAILED;
}

/* -------------------------------------------------------- the answer's size */

/* Members, keys and punctuation of a frame, and of one contour's slot (its
 * metrics' numbers included), besides the curves' numbers. */
#define SHAPE_FRAME_FIXED 200
#define SHAPE_SLOT_FIXED 400
#define SHAPE_DOC_FIXED 4096
/* A curvature plot's number (px, within API_SVG_PX_BUDGET), a corner's
 * tick with its title, a legend line, and a panel's axes, ticks, labels
 * and clip path. */
#define API_PX_NUM_BYTES 12
#define SHAPE_CORNER_BYTES 240
#define SHAPE_LEGEND_BYTES 240
#define SHAPE_PANEL_FIXED 4096

/* Degree and rationality of the frames' curves: the method's degree for
 * curvature morphs, the inputs' highest for linear ones. */
static void frame_kind(const api_morph_plan *pl, int *degree, bool *rational) {
  const km_shape *sh[2] = {&pl->sfrom, &pl->sto};
  *degree = pl->opt.degree;
  *rational = false;
  if (pl->opt.method != KM_METHOD_LINEAR) return;
  *degree = 1;
  for (int k = 0; k < 2; k++)
    for (size_t i = 0; i < sh[k]->ncontours; i++) {
      const km_curve *c = &sh[k]->contours[i];
      *degree = c->degree > *degree ? c->degree : *degree;
      *rational = *rational || c->w != NULL;
    }
}

/* Control points of each slot at most (points[npairs], zeroed): frames
 * at the first, middle and last times are built and counted; a slot's
 * count is taken as exact when every frame is among them or its count
 * agrees at two or more of them (a planned pair's count does not move with
 * t), else given a quarter more. */
static km_status slot_points(const api_morph_plan *pl, const km_stop *stop,
                             size_t npairs, size_t *points, km_error *err) {
  size_t idx[3] = {0, pl->nframes / 2, pl->nframes - 1};
  size_t *seen = km__calloc(npairs ? 2 * npairs : 1, sizeof *seen);
  km_shape_frame f;
  km_status st = KM_OK;
  if (seen == NULL) return KM_ENOMEM;
  km_shape_frame_init(&f);
  for (int k = 0; k < 3 && st == KM_OK; k++) {
    st = km_shape_morph_frame_until(pl->smorph, pl->frames[idx[k]].t, stop, &f,
                                    err);
    for (size_t j = 0; st == KM_OK && j < npairs && j < f.ncontours; j++) {
      size_t n = f.present[j] ? f.contours[j].n : 0;
      if (n == 0) continue;
      if (seen[2 * j] > 0 && n != points[j])
        seen[2 * j + 1] = 1; /* counts differ */
      points[j] = n > points[j] ? n : points[j];
      seen[2 * j]++;
    }
    km_shape_frame_free(&f);
  }
  for (size_t j = 0; st == KM_OK && j < npairs; j++)
    if (pl->nframes > 3 && (seen[2 * j] < 2 || seen[2 * j + 1]))
      points[j] += points[j] / 4 + 8;
  km__free(seen);
  return st;
}

/* Bytes an SVG layout adds to a slot of `points` control points, per
 * frame (*once: per document), beyond its one path a frame: the
 * animation's value of at most 400 pieces (its first frame once more as
 * the path's d), the curvature plot's trace (samples as
 * svg_curvature_plot.c takes them: a budget per trace shared by the spans
 * of kappa, fewer than the control points, at least three a span, at most
 * 4,002), its corner ticks and legend line, and its panel's axes. */
static size_t layout_bytes(const api_morph_plan *pl, size_t points,
                           size_t npairs, size_t *once) {
  *once = 0;
  if (pl->svgopt.layout == API_SVG_ANIMATE) {
    size_t pieces = 2 * points < 16 ? 16 : 2 * points > 400 ? 400 : 2 * points;
    size_t value = 16 + API_SVG_NUM_BYTES * (2 + 6 * pieces);
    *once = value;
    return value;
  }
  if (pl->svgopt.layout != API_SVG_CURVATURE_PLOT) return 0;
  size_t traces = pl->nframes * (npairs ? npairs : 1);
  size_t budget = traces > 0 ? 400000 / traces : 1600;
  budget = budget > 1600 ? 1600 : budget < 100 ? 100 : budget;
  size_t samples = budget + points > 3 * points ? budget + points : 3 * points;
  samples = samples + 2 > 4002 ? 4002 : samples + 2;
  *once = SHAPE_PANEL_FIXED;
  return samples * 2 * API_PX_NUM_BYTES + SHAPE_CORNER_BYTES * points +
         SHAPE_LEGEND_BYTES;
}

/* Upper bound on the answer's bytes for slots of points[] control
 * points. */
static size_t predict_bytes(const api_morph_plan *pl, const size_t *points,
                            size_t npairs) {
  int degree;
  bool rational;
  bool hermite = pl->opt.method == KM_METHOD_CURVATURE;
  size_t per = SHAPE_FRAME_FIXED, once_all = 0;
  if (pl->opt.intersections == KM_INTERSECTIONS_AVOID)
    per += 24; /* the frame's index in intersections/crossing_frames */
  frame_kind(pl, &degree, &rational);
  for (size_t j = 0; j < npairs; j++) {
    size_t paths = (pl->inc.svg_d ? 1 : 0) + (pl->inc.animate_d ? 1 : 0);
    size_t numbers = api__path_numbers(points[j], degree, hermite), once = 0;
    /* an SVG document holds each slot's path once a frame, and what its
     * layout adds */
    size_t slot =
        pl->svg ? 64
                : SHAPE_SLOT_FIXED +
                      api__curve_json_bytes(points[j], degree, rational, false);
    if (pl->svg) {
      paths = 1;
      if (points[j] > SIZE_MAX / 4096) return SIZE_MAX;
      slot += layout_bytes(pl, points[j], npairs, &once);
      once_all += once;
    }
    if (numbers > (SIZE_MAX / 4 - slot) / (API_SVG_NUM_BYTES + 1))
      return SIZE_MAX;
    slot += paths * (16 + API_SVG_NUM_BYTES * numbers);
    if (slot > SIZE_MAX / 4 - per) return SIZE_MAX;
    per += slot;
  }
  size_t fixed =
      SHAPE_DOC_FIXED + once_all + (2 * API_JSON_NUM_BYTES + 3) * npairs;
  if (pl->nframes > 0 && per > (SIZE_MAX - fixed) / pl->nframes)
    return SIZE_MAX;
  return fixed + per * pl->nframes;
}

bool api__shape_check_size(api_ctx *ctx, api_morph_plan *pl,
                           const km_stop *stop) {
  size_t npairs = km_shape_morph_pairs(pl->smorph, NULL, 0), total = 0;
  size_t limit = pl->cfg.max_output_bytes;
  size_t *points = km__calloc(npairs ? npairs : 1, sizeof *points);
  km_error err;
  km_status st;
  bool ok = false;
  if (points == NULL) return api__oom(ctx);
  st = slot_points(pl, stop, npairs, points, &err);
  if (st != KM_OK) {
    contour_fail(ctx, &pl->from, "", -1, st, &err);
    goto done;
  }
  pl->predicted = predict_bytes(pl, points, npairs);
  for (size_t j = 0; j < npairs; j++) total += points[j];
  if (limit == 0 || pl->predicted <= limit) {
    ok = true;
    goto done;
  }
  size_t nframes = pl->nframes;
  pl->nframes = 2;
  bool tol_dominates = predict_bytes(pl, points, npairs) > limit;
  pl->nframes = nframes;
  api__failf(ctx, 422, API_P_LIMIT, "Limit exceeded",
             tol_dominates ? "/tolerance" : api_morph_frames_pointer(pl),
             "the answer would take up to %zu bytes (%zu frames of %zu "
             "contours, up to %zu control points in all); the limit is %zu "
             "bytes: %s",
             pl->predicted, nframes, npairs, total, limit,
             tol_dominates ? "loosen the tolerance" : "ask for fewer frames");
done:
  km__free(points);
  return ok;
}

/* ------------------------------------------------------------- printing */

/* The paths of the frame's present contours joined into one "d", as a
 * JSON string. */
static bool joined_d_write(api_ctx *ctx, api_svg_buf *b,
                           const km_shape_frame *sf, double tol) {
  api_svg_buf all;
  api__svg_buf_init(&all);
  for (size_t k = 0; k < sf->ncontours; k++) {
    if (!sf->present[k]) continue;
    char *d = api_svg_path_d(&sf->contours[k], tol, NULL);
    if (d == NULL) {
      api__svg_buf_free(&all);
      return api__oom(ctx);
    }
    if (all.len > 0) api__svg_buf_put(&all, " ");
    api__svg_buf_put(&all, d);
    km__free(d);
  }
  char *s = api__svg_buf_take(&all);
  if (s == NULL) return api__oom(ctx);
  api__json_string(b, s);
  km__free(s);
  return true;
}

/* {"contours": [Metrics | null], "mutual_intersections", "nesting_ok"} */
static bool shape_metrics_write(api_ctx *ctx, api_svg_buf *b,
                                const km_shape_frame *sf) {
  API_JSON_LIT(b, "{\"contours\":[");
  for (size_t k = 0; k < sf->ncontours; k++) {
    if (k > 0) API_JSON_LIT(b, ",");
    if (!sf->present[k])
      API_JSON_LIT(b, "null");
    else if (!api__json_metrics(ctx, b, &sf->metrics[k]))
      return false;
  }
  API_JSON_LIT(b, "],\"mutual_intersections\":");
  if (!api__json_num(ctx, b, (double)sf->mutual_intersections,
                     "mutual_intersections"))
    return false;
  if (sf->nesting_ok)
    API_JSON_LIT(b, ",\"nesting_ok\":true}");
  else
    API_JSON_LIT(b, ",\"nesting_ok\":false}");
  return true;
}

bool api__shape_frame_write(api_ctx *ctx, api_svg_buf *b,
                            const api_morph_plan *pl, const api_frame_slot *f,
                            const api_grid *grid) {
  const km_shape_frame *sf = &f->shape;
  API_JSON_LIT(b, "{\"t\":");
  if (!api__json_num(ctx, b, f->t, "t")) return false;
  API_JSON_LIT(b, ",\"contours\":[");
  for (size_t k = 0; k < sf->ncontours; k++) {
    if (k > 0) API_JSON_LIT(b, ",");
    if (!sf->present[k])
      API_JSON_LIT(b, "null");
    else if (!api__json_curve(ctx, b, &sf->contours[k], false, pl->tol, grid,
                              NAN, NULL))
      return false;
  }
  API_JSON_LIT(b, "]");
  if (pl->inc.svg_d) {
    API_JSON_LIT(b, ",\"svg_d\":");
    if (!joined_d_write(ctx, b, sf, pl->tol)) return false;
  }
  if (pl->metrics) {
    API_JSON_LIT(b, ",\"metrics\":");
    if (!shape_metrics_write(ctx, b, sf)) return false;
  }
  API_JSON_LIT(b, "}");
  return true;
}

/* A contour index of a pair, or null. */
static void index_write(api_ctx *ctx, api_svg_buf *b, long i) {
  if (i < 0)
    API_JSON_LIT(b, "null");
  else
    api__json_num(ctx, b, (double)i, "contour index");
}

bool api__shape_pairs_write(api_ctx *ctx, api_svg_buf *b,
                            const api_morph_plan *pl) {
  size_t n = km_shape_morph_pairs(pl->smorph, NULL, 0);
  km_shape_pair *pairs = km__malloc((n ? n : 1) * sizeof *pairs);
  if (pairs == NULL) return api__oom(ctx);
  n = km_shape_morph_pairs(pl->smorph, pairs, n);
  API_JSON_LIT(b, "[");
  for (size_t k = 0; k < n; k++) {
    if (k > 0) API_JSON_LIT(b, ",");
    API_JSON_LIT(b, "[");
    index_write(ctx, b, pairs[k].from);
    API_JSON_LIT(b, ",");
    index_write(ctx, b, pairs[k].to);
    API_JSON_LIT(b, "]");
  }
  API_JSON_LIT(b, "]");
  km__free(pairs);
  return true;
}

/* Where each slot's contour is a point while collapsed, 2 doubles a slot
 * (NaN for a paired slot); NULL when out of memory. */
static double *collapse_points(const km_shape_morph *m, size_t n) {
  double *p = km__malloc((n ? 2 * n : 1) * sizeof *p);
  for (size_t k = 0; p != NULL && k < n; k++)
    if (!km_shape_morph_collapse_point(m, k, p + 2 * k))
      p[2 * k] = p[2 * k + 1] = NAN;
  return p;
}

bool api__shape_animate_write(api_ctx *ctx, api_svg_buf *b,
                              const api_morph_plan *pl) {
  size_t n = km_shape_morph_pairs(pl->smorph, NULL, 0);
  size_t *pieces = km__malloc((n ? n : 1) * sizeof *pieces);
  double *collapse = collapse_points(pl->smorph, n);
  bool ok = false;
  if (pieces == NULL || collapse == NULL) goto done;
  for (size_t k = 0; k < n; k++) pieces[k] = 1;
  /* one piece count per slot, the most any frame needs, and a collapsed
   * contour drawn as a point with its slot's pieces: then every frame
   * writes every slot with the same commands */
  for (size_t i = 0; i < pl->nframes; i++) {
    const km_shape_frame *sf = &pl->frames[i].shape;
    for (size_t k = 0; k < n && k < sf->ncontours; k++) {
      if (!sf->present[k]) continue;
      char *d = api_svg_path_d(&sf->contours[k], pl->tol, NULL);
      if (d == NULL) goto done;
      size_t p = api__count_pieces(d);
      pieces[k] = p > pieces[k] ? p : pieces[k];
      km__free(d);
    }
  }
  API_JSON_LIT(b, "[");
  for (size_t i = 0; i < pl->nframes; i++) {
    char *d = api_svg_shape_frame_d(&pl->frames[i].shape, pieces, collapse);
    if (d == NULL) goto done;
    if (i > 0) API_JSON_LIT(b, ",");
    api__json_string(b, d);
    km__free(d);
  }
  API_JSON_LIT(b, "]");
  ok = true;
done:
  if (!ok) api__oom(ctx);
  km__free(pieces);
  km__free(collapse);
  return ok;
}

char *api__shape_svg(const api_morph_plan *pl) {
  size_t n = km_shape_morph_pairs(pl->smorph, NULL, 0);
  api_svg_shape_frame *fr = km__malloc(pl->nframes * sizeof *fr);
  km_shape_pair *pairs = km__malloc((n ? n : 1) * sizeof *pairs);
  double *collapse = collapse_points(pl->smorph, n);
  char *doc = NULL;
  if (fr == NULL || pairs == NULL || collapse == NULL) goto done;
  km_shape_morph_pairs(pl->smorph, pairs, n);
  for (size_t i = 0; i < pl->nframes; i++) {
    fr[i].t = pl->frames[i].t;
    fr[i].shape = &pl->frames[i].shape;
    fr[i].fill = fr[i].t < 0.5 ? pl->sfrom.fill : pl->sto.fill;
  }
  api_svg_shape_morph m = {fr, pl->nframes, n, pairs, collapse};
  doc = api_svg_shape_document(&m, &pl->svgopt);
done:
  km__free(fr);
  km__free(pairs);
  km__free(collapse);
  return doc;
}
