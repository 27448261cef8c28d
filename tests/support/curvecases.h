/* curvecases.h - making curves and signatures in the tests: make_curve,
 * the signature of an analytic fixture, and curves that more than one test
 * file needs, each with the geometry that makes its expected values exact.
 */
#ifndef TESTS_CURVECASES_H
#define TESTS_CURVECASES_H

#include <stdbool.h>

#include "fixtures.h"
#include "km/curve.h"
#include "km/fn.h"
#include "km/signature.h"
#include "testutil.h"

/* km_curve_create or fail the test: c is initialised first, so the caller
 * frees it with km_curve_free whatever happened. */
static inline void make_curve(km_curve *c, int p, size_t n, const double *knots,
                              const double *cp, const double *w, bool closed) {
  km_error err;
  km_curve_init(c);
  assert_status(km_curve_create(c, p, n, knots, cp, w, closed, &err), KM_OK);
}

/* The signature an analytic.json case states (its kappa, length, start
 * and closedness), or fail the test; sig is initialised first, so the
 * caller frees it with km_signature_free. */
static inline void signature_of_analytic(const tf_analytic *a,
                                         km_signature *sig) {
  km_fn kappa;
  km_error err;
  km_fn_init(&kappa);
  km_signature_init(sig);
  assert_status(km_fn_create(&kappa, a->kappa_degree, a->kappa_n,
                             a->kappa_knots, a->kappa_coef, &err),
                KM_OK);
  assert_status(km_signature_create(sig, a->length, a->start, a->angle, &kappa,
                                    NULL, 0, a->closed, &err),
                KM_OK);
  km_fn_free(&kappa);
}

/* A rational Bezier of degree 9 on the segment from (1e6, 1e6) to
 * (1e6 + 1, 1e6 + 0.5), its first point doubled (a degenerate leg) and its
 * weights jumping from 0.1 to w1 (100 in the first of these tests) there:
 * the curve leaves its start within about 0.1 / (9 w1) of the parameter,
 * where its speed is rounding noise at 1e6, then runs on. Collinear points
 * in order with positive weights trace the segment once (variation
 * diminishing), so its length is sqrt(1.25), the point at half of it the
 * segment's middle and its end the last point. The 16-point rule and its
 * halves both stepped over that start and agreed on a length some 7e-6
 * too long (w1 = 100), 7.7e-7 too short (w1 = 300); the rounding of the
 * speed there, 8 p ulps of 1e6 times the weights' factor, integrates to
 * about 1e-8. With w1 = 1000 its directions, a thousand times their
 * polynomial rounding there, spun three turns within 1e-10 of the
 * parameter and were refused as a cusp at tolerances below 1e-6. */
static inline void tc_rational_segment_leaving_a_degenerate_leg(km_curve *c,
                                                                double w1) {
  const double xs[10] = {0, 0, 0.05, 0.15, 0.3, 0.45, 0.6, 0.75, 0.9, 1};
  const double w[10] = {0.1, w1, 30, 10, 3, 1, 1, 1, 1, 1};
  double kn[20], cp[20];
  for (int i = 0; i < 10; i++) {
    kn[i] = 0;
    kn[i + 10] = 1;
    cp[2 * i] = 1e6 + xs[i];
    cp[2 * i + 1] = 1e6 + 0.5 * xs[i];
  }
  make_curve(c, 9, 10, kn, cp, w, false);
}

/* A parabola traced through its vertex as a hairpin: C'(u) = (u - U, E)
 * on u in [0, 1], so C(u) = (((u - U)^2 - U^2) / 2, E u), moved to
 * (ox, oy). With U = 1e-3 and E = 1e-6 the curve runs back by U^2 / 2,
 * turns by pi - 2e-3 within about 1e-6 of the parameter at u = U, and
 * runs on: its speed sqrt((u - U)^2 + E^2) has a V-shaped dip of that
 * width, and every Gauss-Legendre node of [0, 1], of its halves and of
 * their halves lies beyond it, where the speed is the polynomial u - U:
 * the rules agree on a length U^2 (1e-6) short, the run into the tip and
 * back lost. The exact length is tc_hairpin_length(0, 1). Written as a
 * Bezier of degree 2 or, elevated, 3; weight > 0 makes every weight that
 * (the same curve, through the rational code). */
#define TC_HAIRPIN_U 1e-3
#define TC_HAIRPIN_E 1e-6
/* integral of sqrt(x^2 + E^2) from 0 to x */
static inline double tc_hairpin_primitive(double x) {
  const double E = TC_HAIRPIN_E;
  return 0.5 * x * sqrt(x * x + E * E) + 0.5 * E * E * asinh(x / E);
}
/* its arc length between u0 and u1 */
static inline double tc_hairpin_length(double u0, double u1) {
  return tc_hairpin_primitive(u1 - TC_HAIRPIN_U) -
         tc_hairpin_primitive(u0 - TC_HAIRPIN_U);
}
static inline void tc_hairpin(km_curve *c, int degree, double weight, double ox,
                              double oy) {
  const double U = TC_HAIRPIN_U, E = TC_HAIRPIN_E;
  /* quadratic Bezier: P1 = P0 + C'(0) / 2 */
  const double q[3][2] = {{0, 0}, {-0.5 * U, 0.5 * E}, {0.5 - U, E}};
  double cp[8], kn[8], w[4];
  int n = degree + 1;
  for (int k = 0; k < 2; k++) {
    if (degree == 2) {
      for (int i = 0; i < 3; i++) cp[2 * i + k] = q[i][k];
    } else {
      cp[k] = q[0][k];
      cp[2 + k] = (q[0][k] + 2 * q[1][k]) / 3;
      cp[4 + k] = (2 * q[1][k] + q[2][k]) / 3;
      cp[6 + k] = q[2][k];
    }
  }
  for (int i = 0; i < n; i++) {
    cp[2 * i] += ox;
    cp[2 * i + 1] += oy;
    kn[i] = 0;
    kn[i + n] = 1;
    w[i] = weight;
  }
  make_curve(c, degree, (size_t)n, kn, cp, weight > 0 ? w : NULL, false);
}

#endif
