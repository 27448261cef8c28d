/* curvedist.h - curves measured as point sets in the morph tests: dense
 * samples, their chord error, distances between curves and polylines, the
 * arc-length centroid (a header of static functions, like testutil.h).
 * Everything is computed here from km_curve_eval alone, so the distances
 * do not trust the morph code they check. */
#ifndef KM_TEST_CURVEDIST_H
#define KM_TEST_CURVEDIST_H

#include <math.h>
#include <stddef.h>
#include <stdlib.h>

#include "km/curve.h"
#include "testutil.h"

/* knot spans of non-zero length */
static inline size_t spans_of(const km_curve *c) {
  size_t spans = 0;
  for (size_t i = (size_t)c->degree; i < c->n; i++)
    if (c->knots[i + 1] > c->knots[i]) spans++;
  return spans;
}

/* samples per span for about `total` in all, at least 4 */
static inline size_t per_span(const km_curve *c, size_t total) {
  size_t s = spans_of(c), per = total / (s ? s : 1);
  return per < 4 ? 4 : per;
}

/* Dense samples of a curve: `per` points per knot span, uniform in the
 * parameter, span ends included (corners sit on knots), plus the end;
 * malloc'd (2 doubles a point, *np points), the caller frees. */
static inline double *curve_points(const km_curve *c, size_t per, size_t *np) {
  double *p = malloc(2 * (spans_of(c) * per + 1) * sizeof *p);
  assert_non_null(p);
  size_t k = 0;
  for (size_t i = (size_t)c->degree; i < c->n; i++) {
    double a = c->knots[i], b = c->knots[i + 1];
    if (!(b > a)) continue;
    for (size_t j = 0; j < per; j++) {
      double d[1][2];
      km_curve_eval(c, a + (b - a) * (double)j / (double)per, 0, d);
      p[2 * k] = d[0][0];
      p[2 * k + 1] = d[0][1];
      k++;
    }
  }
  double t0, t1, d[1][2];
  km_curve_domain(c, &t0, &t1);
  km_curve_eval(c, t1, 0, d);
  p[2 * k] = d[0][0];
  p[2 * k + 1] = d[0][1];
  *np = k + 1;
  return p;
}

/* The largest distance between a curve and the chords of its own samples
 * (checked at the chords' parameter midpoints): how far the polyline of
 * curve_points may be from the curve. */
static inline double chord_error(const km_curve *c, size_t per) {
  double worst = 0.0;
  for (size_t i = (size_t)c->degree; i < c->n; i++) {
    double a = c->knots[i], b = c->knots[i + 1];
    if (!(b > a)) continue;
    for (size_t j = 0; j < per; j++) {
      double u0 = a + (b - a) * (double)j / (double)per;
      double u1 = a + (b - a) * (double)(j + 1) / (double)per;
      double p0[1][2], p1[1][2], pm[1][2];
      km_curve_eval_side(c, u0, 1, 0, p0);
      km_curve_eval_side(c, u1, -1, 0, p1);
      km_curve_eval(c, 0.5 * (u0 + u1), 0, pm);
      double dx = p1[0][0] - p0[0][0], dy = p1[0][1] - p0[0][1];
      double len = hypot(dx, dy);
      double dist =
          len > 0
              ? fabs((pm[0][0] - p0[0][0]) * dy - (pm[0][1] - p0[0][1]) * dx) /
                    len
              : hypot(pm[0][0] - p0[0][0], pm[0][1] - p0[0][1]);
      if (dist > worst) worst = dist;
    }
  }
  return worst;
}

static inline double seg_dist(const double *p, const double *a,
                              const double *b) {
  double dx = b[0] - a[0], dy = b[1] - a[1], l2 = dx * dx + dy * dy;
  double u = l2 > 0 ? ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / l2 : 0.0;
  if (u < 0) u = 0;
  if (u > 1) u = 1;
  return hypot(p[0] - a[0] - u * dx, p[1] - a[1] - u * dy);
}

/* max over points of P of the distance to the polyline Q */
static inline double directed_dist(const double *P, size_t np, const double *Q,
                                   size_t nq) {
  double worst = 0.0;
  for (size_t i = 0; i < np; i++) {
    double best = INFINITY;
    for (size_t j = 0; j + 1 < nq; j++) {
      double d = seg_dist(P + 2 * i, Q + 2 * j, Q + 2 * j + 2);
      if (d < best) best = d;
    }
    if (best > worst) worst = best;
  }
  return worst;
}

/* Distance between the traces of two curves, as point sets: each one's
 * samples (about `total` of them) against the other's polyline, less that
 * polyline's measured chord error. */
static inline double curves_distance(const km_curve *a, const km_curve *b,
                                     size_t total) {
  size_t pa = per_span(a, total), pb = per_span(b, total), na, nb;
  double *A = curve_points(a, pa, &na), *B = curve_points(b, pb, &nb);
  double d1 = directed_dist(A, na, B, nb) - chord_error(b, pb);
  double d2 = directed_dist(B, nb, A, na) - chord_error(a, pa);
  free(A);
  free(B);
  return d1 > d2 ? d1 : d2;
}

/* Arc-length centroid of a curve by 20-point Gauss-Legendre on 8 panels per
 * knot span, weighted by the speed. */
static inline void curve_centroid(const km_curve *c, double out[2]) {
  double x[20], w[20], L = 0.0, cx = 0.0, cy = 0.0;
  tu_gauss_legendre(20, x, w);
  for (size_t i = (size_t)c->degree; i < c->n; i++) {
    double a = c->knots[i], b = c->knots[i + 1];
    if (!(b > a)) continue;
    for (int p = 0; p < 8; p++) {
      double lo = a + (b - a) * p / 8.0, h = (b - a) / 8.0;
      for (int k = 0; k < 20; k++) {
        double d[2][2];
        km_curve_eval(c, lo + 0.5 * h * (x[k] + 1.0), 1, d);
        double ds = 0.5 * h * w[k] * hypot(d[1][0], d[1][1]);
        L += ds;
        cx += ds * d[0][0];
        cy += ds * d[0][1];
      }
    }
  }
  out[0] = cx / L;
  out[1] = cy / L;
}

#endif
