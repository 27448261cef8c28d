/* curve_in.c - input curves of a request: a Curve object of type
 * "bspline", "points" (fitted), "svg" (path data), "signature" or "shape"
 * (closed contours, each a Curve), checked member by member, each failure
 * named by its JSON pointer, then built by the core. An "svg" whose d has
 * several subpaths is a shape too; with one it is the curve it always was.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "internal.h"
#include "km/alloc.h"
#include "svg.h"

void api__input_init(api_input *in) {
  in->is_signature = false;
  in->kind = API_KIND_CURVE;
  km_curve_init(&in->curve);
  km_signature_init(&in->sig);
  in->length = 0;
  in->is_shape = false;
  in->ncontours = 0;
  in->contours = NULL;
  in->offsets = NULL;
  in->fill = KM_FILL_NONZERO;
}

void api__input_free(api_input *in) {
  if (in == NULL) return;
  km_curve_free(&in->curve);
  km_signature_free(&in->sig);
  for (size_t i = 0; in->contours != NULL && i < in->ncontours; i++)
    km_curve_free(&in->contours[i]);
  km__free(in->contours);
  km__free(in->offsets);
  api__input_init(in);
}

size_t api__max_contours(const api_config *cfg) {
  size_t m = cfg->max_contours;
  if (m == 0) return KM_SHAPE_DEFAULT_MAX_CONTOURS;
  return m > KM_SHAPE_MAX_CONTOURS ? KM_SHAPE_MAX_CONTOURS : m;
}

void api__contour_ptr(char *buf, const api_input *in, const char *ptr,
                      size_t i) {
  char p[API_POINTER_MAX];
  if (in->offsets != NULL) {
    api__ptr_key(buf, ptr, "d");
    return;
  }
  api__ptr_key(p, ptr, "contours");
  api__ptr_idx(buf, p, i);
}

void api__contour_where(char *buf, size_t cap, const api_input *in, size_t i) {
  if (in->offsets != NULL)
    snprintf(buf, cap, "subpath %zu (at offset %zu of d)", i, in->offsets[i]);
  else
    snprintf(buf, cap, "contour %zu", i);
}

bool api__refuse_shape(api_ctx *ctx, const char *ptr) {
  return api__invalid(ctx, ptr,
                      "is a shape of several contours; this route takes "
                      "one curve");
}

/* The optional "weights" of a curve of n control points at ptr: one per
 * point, each > 0. *w (the caller frees it) stays NULL when they are
 * absent or null. */
static bool read_weights(api_ctx *ctx, const cJSON *v, const char *ptr,
                         size_t n, double **w) {
  char p[API_POINTER_MAX];
  size_t nw = 0;
  const cJSON *jw = cJSON_GetObjectItemCaseSensitive(v, "weights");
  if (jw == NULL || cJSON_IsNull(jw)) return true;
  api__ptr_key(p, ptr, "weights");
  if (!api__num_array(ctx, jw, p, ctx->cfg->max_control_points, w, &nw))
    return false;
  if (nw != n)
    return api__failf(ctx, 422, API_P_INVALID_CURVE, "Invalid curve", p,
                      "must have one weight per control point (%zu), not "
                      "%zu",
                      n, nw);
  for (size_t i = 0; i < nw; i++) {
    if (!((*w)[i] > 0)) {
      char q[API_POINTER_MAX];
      api__ptr_idx(q, p, i);
      return api__fail(ctx, 422, API_P_INVALID_CURVE, "Invalid curve", q,
                       "weights must be > 0");
    }
  }
  return true;
}

/* The optional "closed" of a curve of n control points cp at ptr. */
static bool read_closed(api_ctx *ctx, const cJSON *v, const char *ptr,
                        const double *cp, size_t n, bool *closed) {
  char p[API_POINTER_MAX];
  double span = 0;
  if (!api__member_bool(ctx, v, ptr, "closed", false, closed, NULL))
    return false;
  if (!*closed) return true;
  /* Scale-relative, so that rounding in a client's output does not turn
   * a closed curve into an error; the core has the final word. */
  for (size_t i = 0; i < 2 * n; i++) span = fmax(span, fabs(cp[i]));
  if (hypot(cp[0] - cp[2 * n - 2], cp[1] - cp[2 * n - 1]) >
      1e-12 * fmax(span, 1.0)) {
    api__ptr_key(p, ptr, "closed");
    return api__fail(ctx, 422, API_P_INVALID_CURVE, "Invalid curve", p,
                     "a closed curve needs its first and last control "
                     "points equal");
  }
  return true;
}

static bool parse_bspline(api_ctx *ctx, const cJSON *v, const char *ptr,
                          km_curve *out) {
  char p[API_POINTER_MAX];
  long degree = 0;
  double *cp = NULL, *knots = NULL, *w = NULL;
  size_t n = 0, nk = 0;
  bool closed = false, ok = false;
  const cJSON *jcp;
  km_error err;
  km_status st;

  if (!api__member_int(ctx, v, ptr, "degree", true, KM_MIN_DEGREE,
                       KM_MAX_DEGREE, &degree, NULL) ||
      (jcp = api__require(ctx, v, ptr, "control_points")) == NULL)
    goto done;
  api__ptr_key(p, ptr, "control_points");
  if (!api__point_array(ctx, jcp, p, ctx->cfg->max_control_points, &cp, &n))
    goto done;
  if (n < (size_t)degree + 1) {
    api__failf(ctx, 422, API_P_INVALID_CURVE, "Invalid curve", p,
               "a degree %ld curve needs at least %ld control points, not "
               "%zu",
               degree, degree + 1, n);
    goto done;
  }
  if (!api__read_knots(ctx, v, ptr, n, degree, API_KIND_CURVE, &knots, &nk) ||
      !read_weights(ctx, v, ptr, n, &w) ||
      !read_closed(ctx, v, ptr, cp, n, &closed))
    goto done;
  st = km_curve_create(out, (int)degree, n, knots, cp, w, closed, &err);
  if (st != KM_OK) {
    api__core_fail(ctx, st, &err, ptr, API_KIND_CURVE);
    goto done;
  }
  ok = true;
done:
  km__free(cp);
  km__free(knots);
  km__free(w);
  return ok;
}

static bool parse_points(api_ctx *ctx, const cJSON *v, const char *ptr,
                         double tol, km_curve *out) {
  char p[API_POINTER_MAX];
  double *pts = NULL;
  size_t n = 0;
  bool closed = false, ok = false;
  const cJSON *jp;
  km_error err;
  km_status st;
  if ((jp = api__require(ctx, v, ptr, "points")) == NULL) return false;
  api__ptr_key(p, ptr, "points");
  if (!api__point_array(ctx, jp, p, ctx->cfg->max_control_points, &pts, &n))
    return false;
  if (n < 2) {
    api__invalid(ctx, p, "needs at least 2 points");
    goto done;
  }
  if (!api__member_bool(ctx, v, ptr, "closed", false, &closed, NULL)) goto done;
  {
    /* fitted within half the tolerance (the request's, else the default
     * 1e-5 of the length) so the rest of the work keeps the other half */
    double len = 0.0;
    for (size_t i = 1; i < n; i++)
      len +=
          hypot(pts[2 * i] - pts[2 * i - 2], pts[2 * i + 1] - pts[2 * i - 1]);
    double fit_tol = 0.5 * (tol > 0 ? tol : 1e-5 * len);
    st = km_curve_fit_points(out, pts, n, closed, fit_tol, &err);
  }
  if (st != KM_OK) {
    api__core_fail(ctx, st, &err, ptr, API_KIND_POINTS);
    goto done;
  }
  ok = true;
done:
  km__free(pts);
  return ok;
}

/* Contour i of in, closed, else 422 naming it. */
static bool check_closed(api_ctx *ctx, const api_input *in, const char *ptr,
                         size_t i) {
  char p[API_POINTER_MAX], where[96];
  if (in->contours[i].closed) return true;
  api__contour_ptr(p, in, ptr, i);
  api__contour_where(where, sizeof where, in, i);
  return api__failf(ctx, 422, API_P_INVALID_CURVE, "Invalid curve", p,
                    "%s is open: every contour of a shape must be closed "
                    "(end it with Z, or give \"closed\": true)",
                    where);
}

/* The subpaths of d: one is the curve itself, several a shape. */
static bool parse_svg(api_ctx *ctx, const cJSON *v, const char *ptr, double tol,
                      api_input *out) {
  char p[API_POINTER_MAX];
  char msg[API_TEXT_MAX];
  const cJSON *jd;
  size_t off = 0, n = 0, *offs = NULL, points = 0;
  km_curve *subs = NULL;
  km_status st;
  if ((jd = api__require(ctx, v, ptr, "d")) == NULL) return false;
  api__ptr_key(p, ptr, "d");
  if (!cJSON_IsString(jd))
    return api__invalid(ctx, p, "must be a string, not %s", api__type_name(jd));
  msg[0] = '\0';
  /* Without a request tolerance nothing is known of the drawing's scale
   * yet; a tiny absolute tolerance only lets exact repairs happen. */
  st = api_svg_parse_subpaths(jd->valuestring, strlen(jd->valuestring),
                              tol > 0 ? tol : 1e-9, api__max_contours(ctx->cfg),
                              &subs, &offs, &n, &off, msg, sizeof msg);
  if (st == KM_ENOMEM) return api__oom(ctx);
  if (st == KM_ELIMIT)
    return api__failf(ctx, 422, API_P_LIMIT, "Limit exceeded", p,
                      "too many subpaths at offset %zu: %s", off, msg);
  if (st != KM_OK)
    return api__failf(ctx, 422, API_P_INVALID_CURVE, "Invalid curve", p,
                      "invalid path data at offset %zu: %s", off,
                      msg[0] != '\0' ? msg : km_status_message(st));
  for (size_t i = 0; i < n; i++) points += subs[i].n;
  if (n == 1) {
    out->curve = subs[0];
    km__free(subs);
    km__free(offs);
  } else {
    out->is_shape = true;
    out->contours = subs;
    out->offsets = offs;
    out->ncontours = n;
  }
  if (points > ctx->cfg->max_control_points)
    return api__failf(ctx, 422, API_P_LIMIT, "Limit exceeded", p,
                      "the path makes %zu control points; the limit is %zu",
                      points, ctx->cfg->max_control_points);
  for (size_t i = 0; i < out->ncontours; i++)
    if (!check_closed(ctx, out, ptr, i)) return false;
  return true;
}

/* A "shape": contours (each a closed curve, not a signature or a shape)
 * and a fill rule. */
static bool parse_shape(api_ctx *ctx, const cJSON *v, const char *ptr,
                        double tol, api_input *out) {
  static const char *const fills[] = {"nonzero", "evenodd"};
  char p[API_POINTER_MAX], q[API_POINTER_MAX];
  const cJSON *jc, *item;
  size_t n, i = 0, max = api__max_contours(ctx->cfg), points = 0;
  int fill = 0;
  if (!api__member_enum(ctx, v, ptr, "fill_rule", fills, 2, &fill, NULL) ||
      (jc = api__require(ctx, v, ptr, "contours")) == NULL)
    return false;
  api__ptr_key(p, ptr, "contours");
  if (!cJSON_IsArray(jc) || api__array_packed(jc, NULL) != NULL ||
      (n = api__array_len(jc)) == 0)
    return api__invalid(ctx, p, "must be a non-empty array of curves");
  if (n > max) {
    api__ptr_idx(q, p, max);
    return api__failf(ctx, 422, API_P_LIMIT, "Limit exceeded", q,
                      "a shape has at most %zu contours, not %zu", max, n);
  }
  out->fill = fill == 1 ? KM_FILL_EVENODD : KM_FILL_NONZERO;
  if ((out->contours = km__calloc(n, sizeof *out->contours)) == NULL)
    return api__oom(ctx);
  out->is_shape = true;
  cJSON_ArrayForEach(item, jc) {
    api_input c;
    api__input_init(&c);
    api__ptr_idx(q, p, i);
    bool ok = api__parse_curve(ctx, item, q, tol, &c);
    if (ok && (c.is_signature || c.is_shape))
      ok = api__invalid(ctx, q,
                        "a contour must be one curve (bspline, points or "
                        "svg of one subpath)");
    if (!ok) {
      api__input_free(&c);
      return false;
    }
    out->contours[i] = c.curve;
    km_curve_init(&c.curve);
    api__input_free(&c);
    out->ncontours = ++i;
    points += out->contours[i - 1].n;
    if (!check_closed(ctx, out, ptr, i - 1)) return false;
    if (points > ctx->cfg->max_control_points)
      return api__failf(ctx, 422, API_P_LIMIT, "Limit exceeded", q,
                        "the contours up to this one have %zu control "
                        "points; the limit is %zu",
                        points, ctx->cfg->max_control_points);
  }
  return true;
}

/* The members of each type of curve, in the order of types[] below. */
static const char *const bspline_members[] = {
    "type", "degree", "knots", "weights", "control_points", "closed"};
static const char *const points_members[] = {"type", "points", "closed"};
static const char *const signature_members[] = {"type", "signature"};
static const char *const svg_members[] = {"type", "d"};
static const char *const shape_members[] = {"type", "contours", "fill_rule"};
static const char *const *const curve_members[] = {
    bspline_members, points_members, signature_members, svg_members,
    shape_members};
static const size_t curve_member_counts[] = {
    sizeof bspline_members / sizeof *bspline_members,
    sizeof points_members / sizeof *points_members,
    sizeof signature_members / sizeof *signature_members,
    sizeof svg_members / sizeof *svg_members,
    sizeof shape_members / sizeof *shape_members};

bool api__parse_curve(api_ctx *ctx, const cJSON *v, const char *ptr, double tol,
                      api_input *out) {
  static const char *const types[] = {"bspline", "points", "signature", "svg",
                                      "shape"};
  int type = -1;
  bool present = false;
  char p[API_POINTER_MAX];
  if (v == NULL) return api__invalid(ctx, ptr, "is required");
  if (!cJSON_IsObject(v))
    return api__invalid(ctx, ptr, "must be a curve object, not %s",
                        api__type_name(v));
  if (!api__member_enum(ctx, v, ptr, "type", types, 5, &type, &present))
    return false;
  if (!present) {
    api__ptr_key(p, ptr, "type");
    return api__invalid(ctx, p,
                        "is required: \"bspline\", \"points\", \"signature\", "
                        "\"svg\" or \"shape\"");
  }
  if (!api__known_members(ctx, v, ptr, curve_members[type],
                          curve_member_counts[type]))
    return false;
  switch (type) {
  case 0:
    if (!parse_bspline(ctx, v, ptr, &out->curve)) return false;
    out->kind = API_KIND_CURVE;
    break;
  case 1:
    if (!parse_points(ctx, v, ptr, tol, &out->curve)) return false;
    out->kind = API_KIND_POINTS;
    break;
  case 2: {
    const cJSON *js = api__require(ctx, v, ptr, "signature");
    if (js == NULL) return false;
    api__ptr_key(p, ptr, "signature");
    if (!api__parse_signature(ctx, js, p, &out->sig)) return false;
    out->is_signature = true;
    out->kind = API_KIND_SIGNATURE;
    out->length = out->sig.length;
    return true;
  }
  case 3:
    if (!parse_svg(ctx, v, ptr, tol, out)) return false;
    out->kind = API_KIND_SVG;
    break;
  default:
    if (!parse_shape(ctx, v, ptr, tol, out)) return false;
    out->kind = API_KIND_CURVE;
    break;
  }
  out->is_signature = false;
  if (out->is_shape) {
    out->length = 0;
    for (size_t i = 0; i < out->ncontours; i++)
      out->length += km_curve_length(&out->contours[i]);
    return true;
  }
  out->length = km_curve_length(&out->curve);
  if (!isfinite(out->length) || !(out->length > 0))
    return api__fail(ctx, 422, API_P_INVALID_CURVE, "Invalid curve", ptr,
                     "the curve has zero length");
  return true;
}
