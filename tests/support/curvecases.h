/* curvecases.h - curves that more than one test file needs, each with the
 * geometry that makes its expected values exact.
 */
#ifndef TESTS_CURVECASES_H
#define TESTS_CURVECASES_H

#include "km/curve.h"
#include "testutil.h"

/* A rational Bezier of degree 9 on the segment from (1e6, 1e6) to
 * (1e6 + 1, 1e6 + 0.5), its first point doubled (a degenerate leg) and its
 * weights jumping from 0.1 to 100 there: the curve leaves its start within
 * about 1e-4 of the parameter, where its speed is rounding noise at 1e6,
 * then runs on. Collinear points in order with positive weights trace the
 * segment once (variation diminishing), so its length is sqrt(1.25), the
 * point at half of it the segment's middle and its end the last point. The
 * 16-point rule and its halves both stepped over that start and agreed on
 * a length some 7e-6 too long; the rounding of the speed there, 8 p ulps
 * of 1e6 times the weights' factor, integrates to about 1e-8. */
static inline void tc_rational_segment_leaving_a_degenerate_leg(km_curve *c) {
  const double xs[10] = {0, 0, 0.05, 0.15, 0.3, 0.45, 0.6, 0.75, 0.9, 1};
  const double w[10] = {0.1, 100, 30, 10, 3, 1, 1, 1, 1, 1};
  double kn[20], cp[20];
  for (int i = 0; i < 10; i++) {
    kn[i] = 0;
    kn[i + 10] = 1;
    cp[2 * i] = 1e6 + xs[i];
    cp[2 * i + 1] = 1e6 + 0.5 * xs[i];
  }
  km_error err;
  km_curve_init(c);
  assert_status(km_curve_create(c, 9, 10, kn, cp, w, false, &err), KM_OK);
}

#endif
