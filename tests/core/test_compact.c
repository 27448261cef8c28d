/* test_compact.c - reconstructions that spend few control points: the unit
 * circle within the counts of issue 17 (20 / 48 / 140 control points at
 * 1e-3 / 1e-6 / 1e-9, degree 3) and within tolerance, and the reported
 * bound never below the true error.
 *
 * The exact curve is the circle of radius 1 about the origin: a point's
 * distance to it is | |p| - 1 |, and every point of the circle is near
 * the reconstruction when the reconstruction runs round it once, in
 * order, with its knots on it (checked: the angle of r(s) increases and
 * r at its knots lies on the circle at angle s). Nothing here comes from
 * the code under test but the curve. No cubic does much better: the best
 * cubic arc turning phi is off by about phi^6 / 56000, so 1e-9 takes 34
 * arcs at least, 70 control points. */
#include <stdio.h>

#include "km/curve.h"
#include "km/reconstruct.h"
#include "km/signature.h"
#include "testutil.h"
#include "testmain.h"

#define SAMPLES 200000

static void unit_circle(km_signature *sig) {
  km_error err;
  km_fn kappa;
  km_fn_init(&kappa);
  assert_status(km_fn_constant(&kappa, 0.0, 2 * M_PI, 1.0, &err), KM_OK);
  const double start[2] = {1, 0};
  assert_status(km_signature_create(sig, 2 * M_PI, start, M_PI / 2, &kappa,
                                    NULL, 0, true, &err),
                KM_OK);
  km_fn_free(&kappa);
}

/* Largest | |r(s)| - 1 | over dense samples, checking on the way that the
 * angle of r(s) increases (the curve runs round the circle once). */
static double radial_error(const km_curve *r) {
  double t0, t1, worst = 0.0, prev = -1.0, turned = 0.0;
  km_curve_domain(r, &t0, &t1);
  for (int j = 0; j <= SAMPLES; j++) {
    double d[1][2];
    km_curve_eval(r, t0 + (t1 - t0) * j / SAMPLES, 0, d);
    worst = fmax(worst, fabs(hypot(d[0][0], d[0][1]) - 1.0));
    double a = atan2(d[0][1], d[0][0]);
    if (j > 0) {
      double step = remainder(a - prev, 2 * M_PI);
      assert_true(step > 0.0 && step < 1e-3);
      turned += step;
    }
    prev = a;
  }
  assert_close(turned, 2 * M_PI, 1e-9);
  return worst;
}

static void unit_circle_takes_few_control_points(void **state) {
  (void)state;
  static const struct {
    double tol;
    size_t most;
  } cases[] = {{1e-3, 20}, {1e-6, 48}, {1e-9, 140}};
  km_signature sig;
  unit_circle(&sig);
  for (size_t k = 0; k < sizeof cases / sizeof *cases; k++) {
    km_curve r;
    km_error err;
    double bound = -1.0;
    km_curve_init(&r);
    assert_status(km_reconstruct(&sig, 3, cases[k].tol, &r, &bound, &err),
                  KM_OK);
    double m = radial_error(&r);
    print_message("tol %.0e: %zu control points, bound %.3g, measured %.3g\n",
                  cases[k].tol, r.n, bound, m);
    assert_true(r.n <= cases[k].most);
    assert_true(r.n >= 13); /* four quarter arcs at the loosest */
    assert_le(m, cases[k].tol);
    assert_le(m, bound);
    assert_le(bound, cases[k].tol);
    /* the knots on the circle at their arc length */
    for (size_t i = 0; i < r.n + 4; i++) {
      double s = r.knots[i], d[1][2];
      km_curve_eval(&r, s, 0, d);
      assert_close(d[0][0], cos(s), 1e-9 + cases[k].tol);
      assert_close(d[0][1], sin(s), 1e-9 + cases[k].tol);
    }
    assert_true(r.closed);
    km_curve_free(&r);
  }
  km_signature_free(&sig);
}

/* The bound covers the true error at every tolerance between, however the
 * pieces fall, and is not wildly pessimistic (within 100x). */
static void unit_circle_bound_covers_the_true_error(void **state) {
  (void)state;
  km_signature sig;
  unit_circle(&sig);
  for (int e = 2; e <= 20; e++) {
    double tol = pow(10.0, -e / 2.0);
    km_curve r;
    km_error err;
    double bound = -1.0;
    km_curve_init(&r);
    assert_status(km_reconstruct(&sig, 3, tol, &r, &bound, &err), KM_OK);
    double m = radial_error(&r);
    assert_le(m, bound);
    assert_le(bound, tol);
    assert_le(bound, 100.0 * m + 1e-14);
    km_curve_free(&r);
  }
  km_signature_free(&sig);
}

static const struct CMUnitTest tests[] = {
    cmocka_unit_test(unit_circle_takes_few_control_points),
    cmocka_unit_test(unit_circle_bound_covers_the_true_error),
};

TM_SUITE("compact", tests, NULL, NULL);
