/* shape_frame.c - frames of a compound morph: each pair's curve, the
 * unpaired contours scaled toward their points, the nesting adjustment
 * and the frame's metrics (mutual crossings, nesting).
 */
#include <math.h>
#include <string.h>

#include "km/alloc.h"
#include "km/shape.h"
#include "shape_internal.h"
#include "status_internal.h"

void km_shape_frame_init(km_shape_frame *f) {
  if (f) memset(f, 0, sizeof *f);
}

void km_shape_frame_free(km_shape_frame *f) {
  if (!f) return;
  for (size_t k = 0; f->contours && k < f->ncontours; k++)
    km_curve_free(&f->contours[k]);
  km__free(f->contours);
  km__free(f->metrics);
  km__free(f->present);
  km__free(f->parent);
  km_shape_frame_init(f);
}

/* x -> g + s (x - g) + d on the control points (affine maps are exact on
 * NURBS: the weights stay). */
static void move_curve(km_curve *c, const double g[2], double s,
                       const double d[2]) {
  for (size_t i = 0; i < c->n; i++) {
    c->cp[2 * i] = g[0] + s * (c->cp[2 * i] - g[0]) + d[0];
    c->cp[2 * i + 1] = g[1] + s * (c->cp[2 * i + 1] - g[1]) + d[1];
  }
}

/* The curve of slot k at t (present false for a collapsed contour). */
static km_status contour_at(const km_shape_morph *m, size_t k, double t,
                            const km_stop *stop, km_shape_frame *f,
                            km_error *err) {
  km__pair_kind kind = m->kind[k];
  double s = kind == KM__VANISH ? 1.0 - t : kind == KM__APPEAR ? t : 1.0;
  if (!(s > 0.0)) return KM_OK; /* collapsed: omitted, slot kept */
  km_frame_metrics *mt = &f->metrics[k];
  km_status st = km_morph_frame_until(m->morphs[k], t, stop, &f->contours[k],
                                      mt, NULL, err);
  if (st != KM_OK) {
    if (err && st != KM_ECANCELLED) err->index = (long)k;
    return st;
  }
  f->present[k] = true;
  if (kind == KM__PAIRED) return KM_OK;
  double a, g[2], d[2];
  km__curve_area(&f->contours[k], &a, g);
  const double *c = m->centre + 2 * k, *p = m->point + 2 * k;
  /* the centroid on the line from the contour's centroid to its point */
  double u = kind == KM__VANISH ? t : 1.0 - t;
  d[0] = (1 - u) * c[0] + u * p[0] - g[0];
  d[1] = (1 - u) * c[1] + u * p[1] - g[1];
  move_curve(&f->contours[k], g, s, d);
  mt->length *= s;
  mt->max_abs_kappa /= s;
  mt->bending_energy /= s;
  mt->closure_gap *= s;
  return KM_OK;
}

void km__ref_sample(const km_curve *c, double *out) {
  double t0, t1;
  km_curve_domain(c, &t0, &t1);
  for (int i = 0; i < KM__REF_POINTS; i++) {
    double d[1][2];
    km_curve_eval(c, t0 + (t1 - t0) * i / KM__REF_POINTS, 0, d);
    out[2 * i] = d[0][0];
    out[2 * i + 1] = d[0][1];
  }
}

/* The similarity x -> g + z (x - h) (z complex: rotation and scale) that
 * maps the points X onto the points Y best in weighted least squares
 * (w NULL: equal weights), applied to c (in place). */
static void similar_map(const double *X, const double *Y, const double *w,
                        double c[2]) {
  double hx = 0, hy = 0, gx = 0, gy = 0, ws = 0;
  for (int i = 0; i < KM__REF_POINTS; i++) {
    double wi = w ? w[i] : 1.0;
    hx += wi * X[2 * i];
    hy += wi * X[2 * i + 1];
    gx += wi * Y[2 * i];
    gy += wi * Y[2 * i + 1];
    ws += wi;
  }
  hx /= ws;
  hy /= ws;
  gx /= ws;
  gy /= ws;
  double re = 0, im = 0, nn = 0;
  for (int i = 0; i < KM__REF_POINTS; i++) {
    double wi = w ? w[i] : 1.0;
    double ax = X[2 * i] - hx, ay = X[2 * i + 1] - hy;
    double bx = Y[2 * i] - gx, by = Y[2 * i + 1] - gy;
    re += wi * (bx * ax + by * ay); /* (b) conj(a) */
    im += wi * (by * ax - bx * ay);
    nn += wi * (ax * ax + ay * ay);
  }
  double zr = nn > 0 ? re / nn : 1.0, zi = nn > 0 ? im / nn : 0.0;
  double dx = c[0] - hx, dy = c[1] - hy;
  c[0] = gx + zr * dx - zi * dy;
  c[1] = gy + zi * dx + zr * dy;
}

/* Weights of the points X near c: a Gaussian of the distance whose width
 * is the distance to the nearest point plus a quarter of X's radius, so
 * that a child is placed by the part of its parent around it. */
static void local_weights(const double *X, const double c[2], double *w) {
  double hx = 0, hy = 0, rr = 0, dmin = INFINITY;
  for (int i = 0; i < KM__REF_POINTS; i++) {
    hx += X[2 * i] / KM__REF_POINTS;
    hy += X[2 * i + 1] / KM__REF_POINTS;
  }
  for (int i = 0; i < KM__REF_POINTS; i++) {
    rr += (pow(X[2 * i] - hx, 2) + pow(X[2 * i + 1] - hy, 2)) / KM__REF_POINTS;
    w[i] = hypot(X[2 * i] - c[0], X[2 * i + 1] - c[1]);
    dmin = fmin(dmin, w[i]);
  }
  double sig = dmin + 0.25 * sqrt(rr);
  for (int i = 0; i < KM__REF_POINTS; i++)
    w[i] = sig > 0 ? exp(-(w[i] / sig) * (w[i] / sig)) + 1e-9 : 1.0;
}

bool km__follow_parent(const km_shape_morph *m, size_t k, long parent,
                       const km_curve *parent_now, double t, double out[2]) {
  long pf = m->parent_from[k], pt = m->parent_to[k];
  if (parent < 0 || !m->has_ref[parent]) return false;
  if (m->pairs[k].from >= 0 && pf != parent) return false;
  if (m->pairs[k].to >= 0 && pt != parent) return false;
  double now[2 * KM__REF_POINTS], c0[2], c1[2];
  km__ref_sample(parent_now, now);
  const double *an = m->anchor + 4 * k;
  const double *r = m->ref + 4 * (size_t)parent * KM__REF_POINTS;
  memcpy(c0, an, sizeof c0);
  memcpy(c1, an + 2, sizeof c1);
  double w0[KM__REF_POINTS], w1[KM__REF_POINTS];
  if (m->local_follow) {
    local_weights(r, c0, w0);
    local_weights(r + 2 * KM__REF_POINTS, c1, w1);
  }
  similar_map(r, now, m->local_follow ? w0 : NULL, c0);
  similar_map(r + 2 * KM__REF_POINTS, now, m->local_follow ? w1 : NULL, c1);
  out[0] = (1 - t) * c0[0] + t * c1[0];
  out[1] = (1 - t) * c0[1] + t * c1[1];
  return true;
}

/* The flattenings of a frame's slots, and the band index of each (built
 * when a contour is first asked about, dropped when it moves); whether
 * each lies inside its parent (INSIDE_UNKNOWN until asked, again when it
 * or its parent moves): placing a hole asks at most three times where
 * nothing moved between, and each answer is a winding query per point. */
typedef struct flats {
  double **pt;
  size_t *n;
  km__poly_index *ix;
  bool *indexed;
  signed char *inside;
} flats;

enum { INSIDE_UNKNOWN = 0, INSIDE_YES = 1, INSIDE_NO = 2 };

static km_status flats_alloc(flats *fs, size_t n) {
  fs->pt = km__calloc(n, sizeof *fs->pt);
  fs->n = km__calloc(n, sizeof *fs->n);
  fs->ix = km__calloc(n, sizeof *fs->ix);
  fs->indexed = km__calloc(n, sizeof *fs->indexed);
  fs->inside = km__calloc(n, sizeof *fs->inside);
  return fs->pt && fs->n && fs->ix && fs->indexed && fs->inside ? KM_OK
                                                                : KM_ENOMEM;
}

static void flats_free(flats *fs, size_t n) {
  for (size_t k = 0; fs->pt && k < n; k++) km__free(fs->pt[k]);
  for (size_t k = 0; fs->ix && k < n; k++) km__poly_index_free(&fs->ix[k]);
  km__free(fs->pt);
  km__free(fs->n);
  km__free(fs->ix);
  km__free(fs->indexed);
  km__free(fs->inside);
}

/* Slot k's index, NULL when out of memory. */
static km__poly_index *index_of(flats *fs, size_t k) {
  if (!fs->indexed[k]) {
    if (km__poly_index_build(&fs->ix[k], fs->pt[k], fs->n[k]) != KM_OK)
      return NULL;
    fs->indexed[k] = true;
  }
  return &fs->ix[k];
}

/* Every point of P moved by d lies inside Q. */
static bool all_inside(const double *P, size_t np, const km__poly_index *Q,
                       const double d[2]) {
  for (size_t i = 0; i < np; i++) {
    double q[2] = {P[2 * i] + d[0], P[2 * i + 1] + d[1]};
    if (km__poly_index_winding(Q, q) == 0) return false;
  }
  return true;
}

/* Slot k's points as they stand lie inside its parent's index Q. */
static bool inside_parent(flats *fs, size_t k, const km__poly_index *Q) {
  const double zero[2] = {0, 0};
  if (fs->inside[k] == INSIDE_UNKNOWN)
    fs->inside[k] =
        all_inside(fs->pt[k], fs->n[k], Q, zero) ? INSIDE_YES : INSIDE_NO;
  return fs->inside[k] == INSIDE_YES;
}

/* Slot k moved: its index and what was known of it and its children. */
static void slot_moved(const km_shape_frame *f, flats *fs, size_t k) {
  fs->indexed[k] = false;
  fs->inside[k] = INSIDE_UNKNOWN;
  for (size_t c = 0; c < f->ncontours; c++)
    if (f->parent[c] == (long)k) fs->inside[c] = INSIDE_UNKNOWN;
}

static void centroid_of(const double *P, size_t np, double g[2]) {
  g[0] = g[1] = 0.0;
  for (size_t i = 0; i + 1 < np; i++) {
    g[0] += P[2 * i];
    g[1] += P[2 * i + 1];
  }
  g[0] /= (double)(np - 1);
  g[1] /= (double)(np - 1);
}

static void translate(km_shape_frame *f, size_t k, flats *fs,
                      const double d[2]) {
  const double zero[2] = {0, 0};
  move_curve(&f->contours[k], zero, 1.0, d);
  for (size_t i = 0; i < fs->n[k]; i++) {
    fs->pt[k][2 * i] += d[0];
    fs->pt[k][2 * i + 1] += d[1];
  }
  slot_moved(f, fs, k);
}

/* Translate slot k toward the point inside its parent nearest its
 * centroid by the smallest fraction (to 1/1024) that puts all its points
 * inside the parent; *moved says whether it did. */
static km_status adjust(km_shape_frame *f, size_t k, flats *fs, bool *moved) {
  size_t p = (size_t)f->parent[k];
  const km__poly_index *Q = index_of(fs, p);
  *moved = false;
  if (!Q) return KM_ENOMEM;
  const double *P = fs->pt[k];
  size_t np = fs->n[k];
  if (inside_parent(fs, k, Q)) return KM_OK;
  double gk[2], gp[2], d[2];
  centroid_of(P, np, gk);
  km__poly_interior_point(Q, gk, gp);
  double full[2] = {gp[0] - gk[0], gp[1] - gk[1]};
  if (!all_inside(P, np, Q, full)) return KM_OK;
  double lo = 0.0, hi = 1.0;
  for (int it = 0; it < 10; it++) {
    double mid = 0.5 * (lo + hi);
    d[0] = mid * full[0];
    d[1] = mid * full[1];
    if (all_inside(P, np, Q, d))
      hi = mid;
    else
      lo = mid;
  }
  d[0] = hi * full[0];
  d[1] = hi * full[1];
  translate(f, k, fs, d);
  /* the very sums all_inside tested at hi */
  fs->inside[k] = INSIDE_YES;
  *moved = true;
  return KM_OK;
}

static int frame_depth(const km_shape_frame *f, size_t k) {
  int d = 0;
  for (long p = f->parent[k]; p >= 0 && (size_t)d <= f->ncontours;
       p = f->parent[p])
    d++;
  return d;
}

/* Slot k follows its parent's motion (km__follow_parent) where it has one
 * paired parent: the parts move as one shape, turning with it. */
static void follow(const km_shape_morph *m, km_shape_frame *f, size_t k,
                   double t, flats *fs) {
  double at[2], a, g[2];
  long p = f->parent[k];
  if (!km__follow_parent(m, k, p, &f->contours[p], t, at)) return;
  km__curve_area(&f->contours[k], &a, g);
  double d[2] = {at[0] - g[0], at[1] - g[1]};
  translate(f, k, fs, d);
}

/* The schedule's scale of slot k at t as a fraction of its nominal size
 * (1 when not scheduled). */
static double scheduled_ratio(const km_shape_morph *m, size_t k, double t) {
  double s = m->kind[k] == KM__VANISH ? 1.0 - t : t;
  if (!m->scheduled || !(s > 0)) return 1.0;
  const double *S = m->sched + (KM__SCHED + 1) * k;
  double x = t * KM__SCHED;
  int j = (int)floor(x);
  if (j >= KM__SCHED) j = KM__SCHED - 1;
  double u = x - j, v = (1 - u) * S[j] + u * S[j + 1];
  return fmin(1.0, v / s);
}

static void scale_about(km_shape_frame *f, size_t k, flats *fs,
                        const double g[2], double r) {
  const double zero[2] = {0, 0};
  move_curve(&f->contours[k], g, r, zero);
  double *P = fs->pt[k];
  for (size_t i = 0; i < fs->n[k]; i++) {
    P[2 * i] = g[0] + r * (P[2 * i] - g[0]);
    P[2 * i + 1] = g[1] + r * (P[2 * i + 1] - g[1]);
  }
  slot_moved(f, fs, k);
  km_frame_metrics *mt = &f->metrics[k];
  mt->length *= r;
  mt->closure_gap *= r;
  if (r > 0) {
    mt->max_abs_kappa /= r;
    mt->bending_energy /= r;
  }
}

/* An unpaired slot takes its scheduled size; where it does not fit in
 * its parent its centroid moves to the nearest point inside the parent
 * when it lies outside, and (only while the schedule is measured) it
 * shrinks about that to the largest fraction (to 1/1024) that fits: it
 * vanishes sooner rather than cross. *ratio: its size as a fraction of
 * its nominal. */
static km_status shrink_to_fit(const km_shape_morph *m, double t,
                               km_shape_frame *f, size_t k, flats *fs,
                               double *ratio) {
  size_t p = (size_t)f->parent[k];
  const double zero[2] = {0, 0};
  if (m->kind[k] == KM__PAIRED) return KM_OK;
  const km__poly_index *Q = index_of(fs, p);
  if (!Q) return KM_ENOMEM;
  double a, g[2], cap = scheduled_ratio(m, k, t);
  km__curve_area(&f->contours[k], &a, g);
  if (cap < 1.0) scale_about(f, k, fs, g, cap);
  *ratio = cap;
  if (inside_parent(fs, k, Q)) return KM_OK;
  if (km__poly_index_winding(Q, g) == 0) {
    /* its centre first to the nearest point well inside the parent */
    double q[2];
    km__poly_interior_point(Q, g, q);
    if (km__poly_index_winding(Q, q) == 0) return KM_OK;
    double d[2] = {q[0] - g[0], q[1] - g[1]};
    translate(f, k, fs, d);
    g[0] = q[0];
    g[1] = q[1];
  }
  /* a scheduled size is kept even where it does not fit: shrinking more
   * here and less at the next frame would make it grow */
  if (m->scheduled) return KM_OK;
  double lo = 0.0, hi = 1.0, *cur = fs->pt[k];
  size_t np = fs->n[k];
  double *buf = km__malloc(2 * np * sizeof *buf);
  if (!buf) return KM_ENOMEM;
  for (int it = 0; it < 10; it++) {
    double mid = 0.5 * (lo + hi);
    for (size_t i = 0; i < np; i++) {
      buf[2 * i] = g[0] + mid * (cur[2 * i] - g[0]);
      buf[2 * i + 1] = g[1] + mid * (cur[2 * i + 1] - g[1]);
    }
    if (all_inside(buf, np, Q, zero))
      lo = mid;
    else
      hi = mid;
  }
  km__free(buf);
  scale_about(f, k, fs, g, lo);
  *ratio = cap * lo;
  return KM_OK;
}

/* Slot k's correction (km__shape_fix_at), scaled about the centroid of
 * its flattening and then translated. */
static void apply_fix(const km_shape_morph *m, double t, km_shape_frame *f,
                      size_t k, flats *fs) {
  double d[2], r, g[2];
  if (!km__shape_fix_at(m, k, t, d, &r)) return;
  /* an unpaired contour outside any parent takes its schedule here */
  long p = f->parent[k];
  if (m->kind[k] != KM__PAIRED && (p < 0 || !f->present[p]))
    r = scheduled_ratio(m, k, t);
  if (r != 1.0) {
    centroid_of(fs->pt[k], fs->n[k], g);
    scale_about(f, k, fs, g, r);
  }
  if (d[0] != 0.0 || d[1] != 0.0) translate(f, k, fs, d);
}

/* Placement and nesting adjustment parents first, then the metrics
 * unless only the sizes are asked for (ratio not NULL). */
static km_status finish(const km_shape_morph *m, double t, km_shape_frame *f,
                        flats *fs, km__poll *poll, double *ratio) {
  int maxd = 0;
  for (size_t k = 0; k < f->ncontours; k++)
    if (frame_depth(f, k) > maxd) maxd = frame_depth(f, k);
  for (int d = 0; d <= maxd; d++)
    for (size_t k = 0; k < f->ncontours; k++) {
      if (!f->present[k] || frame_depth(f, k) != d) continue;
      if (f->parent[k] < 0 || !f->present[f->parent[k]]) {
        apply_fix(m, t, f, k, fs);
        continue;
      }
      follow(m, f, k, t, fs);
      double r = 1.0;
      bool moved;
      km_status st = shrink_to_fit(m, t, f, k, fs, &r);
      apply_fix(m, t, f, k, fs);
      moved = false;
      if (st == KM_OK && !m->no_adjust) st = adjust(f, k, fs, &moved);
      if (st != KM_OK) return st;
      if (ratio) ratio[k] = r;
      if (moved) f->adjusted++;
    }
  /* the sizes alone (km__shape_frame_ratios) need no frame metrics */
  if (ratio) return KM_OK;
  f->nesting_ok = true;
  for (size_t k = 0; k < f->ncontours; k++) {
    long p = f->parent[k];
    if (!f->present[k] || p < 0 || !f->present[p]) continue;
    const km__poly_index *Q = index_of(fs, (size_t)p);
    if (!Q) return KM_ENOMEM;
    if (!inside_parent(fs, k, Q)) f->nesting_ok = false;
  }
  f->mutual_intersections = 0;
  for (size_t k = 0; k < f->ncontours; k++)
    for (size_t l = k + 1; f->present[k] && l < f->ncontours; l++) {
      if (!f->present[l]) continue;
      km__poly_index *Q = index_of(fs, l);
      if (!Q) return KM_ENOMEM;
      long c = km__poly_index_crossings(fs->pt[k], fs->n[k], Q, poll);
      if (c < 0) return KM_ECANCELLED;
      f->mutual_intersections += c;
    }
  return KM_OK;
}

static km_status frame_alloc(km_shape_frame *f, size_t n) {
  f->ncontours = n;
  f->contours = km__calloc(n, sizeof *f->contours);
  f->metrics = km__calloc(n, sizeof *f->metrics);
  f->present = km__calloc(n, sizeof *f->present);
  f->parent = km__calloc(n, sizeof *f->parent);
  return f->contours && f->metrics && f->present && f->parent ? KM_OK
                                                              : KM_ENOMEM;
}

static km_status frame_at(const km_shape_morph *m, double t,
                          const km_stop *stop, km_shape_frame *out,
                          double *ratio, km_error *err) {
  if (!m || !out)
    return km__fail(err, KM_EINVAL, KM_FIELD_NONE, -1, NAN, "no morph");
  if (!(t >= 0.0 && t <= 1.0))
    return km__fail(err, KM_ERANGE, KM_FIELD_TIMES, -1, t,
                    "t = %g is outside [0, 1]", t);
  km_shape_frame f;
  km_shape_frame_init(&f);
  size_t n = m->npairs;
  flats fs = {0};
  km__poll poll;
  km__poll_init(&poll, stop);
  km_status st = flats_alloc(&fs, n);
  if (st == KM_OK) st = frame_alloc(&f, n);
  for (size_t k = 0; st == KM_OK && k < n; k++) {
    bool near_from = (t < 0.5 && m->pairs[k].from >= 0) || m->pairs[k].to < 0;
    f.parent[k] = near_from ? m->parent_from[k] : m->parent_to[k];
    st = contour_at(m, k, t, stop, &f, err);
    if (st == KM_OK && f.present[k])
      st = km__shape_flatten(&f.contours[k], &fs.pt[k], &fs.n[k]);
  }
  if (st == KM_OK) st = finish(m, t, &f, &fs, &poll, ratio);
  if (st == KM_ENOMEM)
    km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, "out of memory");
  if (st == KM_ECANCELLED) km__stopped(err);
  if (st != KM_OK) goto cleanup;
  *out = f;
  km_shape_frame_init(&f);
cleanup:
  flats_free(&fs, n);
  km_shape_frame_free(&f);
  return st;
}

km_status km_shape_morph_frame_until(const km_shape_morph *m, double t,
                                     const km_stop *stop, km_shape_frame *out,
                                     km_error *err) {
  return frame_at(m, t, stop, out, NULL, err);
}

km_status km__shape_frame_ratios(const km_shape_morph *m, double t,
                                 const km_stop *stop, double *ratio,
                                 km_error *err) {
  km_shape_frame f;
  km_shape_frame_init(&f);
  km_status st = frame_at(m, t, stop, &f, ratio, err);
  km_shape_frame_free(&f);
  return st;
}
