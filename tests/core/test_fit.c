/* test_fit.c - cubic fits through many points: within the tolerance, with
 * few control points where the points are smooth, exact where not. */
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdlib.h>

#include <cmocka.h>

#include "km/curve.h"
#include "testmain.h"

/* distance from p to the curve: best of a dense sampling, then refined by
 * golden-section search around it */
static double dist_to_curve(const km_curve *c, const double p[2]) {
  double t0, t1, best = INFINITY, tb = 0;
  km_curve_domain(c, &t0, &t1);
  const int M = 4000;
  for (int k = 0; k <= M; k++) {
    double t = t0 + (t1 - t0) * k / M, d[1][2];
    km_curve_eval(c, t, 0, d);
    double e = hypot(d[0][0] - p[0], d[0][1] - p[1]);
    if (e < best) {
      best = e;
      tb = t;
    }
  }
  double a = fmax(t0, tb - (t1 - t0) / M), b = fmin(t1, tb + (t1 - t0) / M);
  const double g = 0.5 * (sqrt(5.0) - 1);
  for (int it = 0; it < 80; it++) {
    double x1 = b - g * (b - a), x2 = a + g * (b - a), d1[1][2], d2[1][2];
    km_curve_eval(c, x1, 0, d1);
    km_curve_eval(c, x2, 0, d2);
    if (hypot(d1[0][0] - p[0], d1[0][1] - p[1]) <
        hypot(d2[0][0] - p[0], d2[0][1] - p[1]))
      b = x2;
    else
      a = x1;
  }
  double d[1][2];
  km_curve_eval(c, 0.5 * (a + b), 0, d);
  return fmin(best, hypot(d[0][0] - p[0], d[0][1] - p[1]));
}

static double max_dist(const km_curve *c, const double *pts, size_t n) {
  double m = 0;
  for (size_t i = 0; i < n; i++) m = fmax(m, dist_to_curve(c, pts + 2 * i));
  return m;
}

static void dense_smooth_samples_need_few_control_points(void **state) {
  (void)state;
  /* 1500 points on an ellipse arc with a ripple: smooth, so a few dozen
   * control points must do at a tolerance of 1e-4 of the length */
  size_t n = 1500;
  double *p = malloc(2 * n * sizeof(double)), L = 0;
  for (size_t i = 0; i < n; i++) {
    double a = 3.0 * (double)i / (double)(n - 1);
    p[2 * i] = 100 * cos(a);
    p[2 * i + 1] = 60 * sin(a) + 5 * sin(5 * a);
    if (i) L += hypot(p[2 * i] - p[2 * i - 2], p[2 * i + 1] - p[2 * i - 1]);
  }
  double tol = 1e-4 * L;
  km_curve c;
  km_error err;
  assert_int_equal(km_curve_fit_points(&c, p, n, false, tol, &err), KM_OK);
  assert_true(c.n < n / 20);
  assert_true(max_dist(&c, p, n) <= tol * (1 + 1e-9));
  /* the ends are the first and last point */
  double d[1][2], t0, t1;
  km_curve_domain(&c, &t0, &t1);
  km_curve_eval(&c, t0, 0, d);
  assert_true(hypot(d[0][0] - p[0], d[0][1] - p[1]) < 1e-9);
  km_curve_eval(&c, t1, 0, d);
  assert_true(hypot(d[0][0] - p[2 * n - 2], d[0][1] - p[2 * n - 1]) < 1e-9);
  km_curve_free(&c);
  free(p);
}

static void
points_on_a_cubic_need_a_small_fraction_of_the_points(void **state) {
  (void)state;
  /* points of x = u, y = u^3 - u with uniform u: one cubic traces them,
   * though not in chord-length parameter, so a fit at 1e-3 needs a few
   * spans - far fewer control points than the interpolant's n + 2 */
  size_t n = 400;
  double *p = malloc(2 * n * sizeof(double));
  for (size_t i = 0; i < n; i++) {
    double u = -1.5 + 3.0 * (double)i / (double)(n - 1);
    p[2 * i] = u;
    p[2 * i + 1] = u * u * u - u;
  }
  km_curve c;
  km_error err;
  assert_int_equal(km_curve_fit_points(&c, p, n, false, 1e-3, &err), KM_OK);
  assert_true(c.n <= n / 16);
  assert_true(max_dist(&c, p, n) <= 1e-3 * (1 + 1e-9));
  km_curve_free(&c);
  free(p);
}

static void noisy_points_are_interpolated(void **state) {
  (void)state;
  size_t n = 60;
  double *p = malloc(2 * n * sizeof(double));
  uint64_t seed = 7;
  for (size_t i = 0; i < n; i++) {
    seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
    double noise = ((double)(seed >> 11) / 9007199254740992.0 - 0.5);
    p[2 * i] = (double)i;
    p[2 * i + 1] = noise; /* noise far above the tolerance */
  }
  km_curve c;
  km_error err;
  assert_int_equal(km_curve_fit_points(&c, p, n, false, 1e-9, &err), KM_OK);
  assert_true(max_dist(&c, p, n) <= 1e-9);
  km_curve_free(&c);
  free(p);
}

static void closed_points_are_fitted_with_a_smooth_seam(void **state) {
  (void)state;
  /* 300 points round an ellipse: a closed fit with few control points,
   * within the tolerance, whose tangent does not turn at the seam */
  size_t n = 300;
  double *p = malloc(2 * n * sizeof(double));
  for (size_t i = 0; i < n; i++) {
    double a = 6.283185307179586 * (double)i / (double)n;
    p[2 * i] = 3 * cos(a);
    p[2 * i + 1] = 2 * sin(a);
  }
  km_curve c;
  km_error err;
  assert_int_equal(km_curve_fit_points(&c, p, n, true, 1e-4, &err), KM_OK);
  assert_true(c.closed);
  assert_true(c.n < n / 5);
  assert_true(max_dist(&c, p, n) <= 1e-4 * (1 + 1e-9));
  double t0, t1, a[2][2], b[2][2];
  km_curve_domain(&c, &t0, &t1);
  km_curve_eval(&c, t0, 1, a);
  km_curve_eval_side(&c, t1, -1, 1, b);
  double cross = a[1][0] * b[1][1] - a[1][1] * b[1][0];
  double dot = a[1][0] * b[1][0] + a[1][1] * b[1][1];
  assert_true(dot > 0);
  assert_true(fabs(cross) <=
              1e-12 * hypot(a[1][0], a[1][1]) * hypot(b[1][0], b[1][1]));
  km_curve_free(&c);
  free(p);
}

static const struct CMUnitTest tests[] = {
    cmocka_unit_test(dense_smooth_samples_need_few_control_points),
    cmocka_unit_test(points_on_a_cubic_need_a_small_fraction_of_the_points),
    cmocka_unit_test(noisy_points_are_interpolated),
    cmocka_unit_test(closed_points_are_fitted_with_a_smooth_seam),
};

TM_SUITE("fit", tests, NULL, NULL);
