/* curvedist.h - distances between curves and polylines shared by the
 * morph tests (a header of static functions, like testutil.h). */
#ifndef KM_TEST_CURVEDIST_H
#define KM_TEST_CURVEDIST_H

#include <math.h>
#include <stddef.h>

#include "km/curve.h"

/* The largest distance between a curve and the chords of its own samples
 * (checked at the chords' parameter midpoints): how far the polyline of
 * curve_points may be from the curve. */
static double chord_error(const km_curve *c, size_t per) {
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
      double dist = len > 0 ? fabs((pm[0][0] - p0[0][0]) * dy - (pm[0][1] - p0[0][1]) * dx) / len
                            : hypot(pm[0][0] - p0[0][0], pm[0][1] - p0[0][1]);
      if (dist > worst) worst = dist;
    }
  }
  return worst;
}

static double seg_dist(const double *p, const double *a, const double *b) {
  double dx = b[0] - a[0], dy = b[1] - a[1], l2 = dx * dx + dy * dy;
  double u = l2 > 0 ? ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / l2 : 0.0;
  if (u < 0) u = 0;
  if (u > 1) u = 1;
  return hypot(p[0] - a[0] - u * dx, p[1] - a[1] - u * dy);
}

/* max over points of P of the distance to the polyline Q */
static double directed_dist(const double *P, size_t np, const double *Q,
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

#endif
