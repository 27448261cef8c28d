/* test_interp.c - cubic interpolation through points: passes through every
 * point at its chord-length parameter, is C2, reproduces straight lines and
 * parabolas, closes C2 across the seam, and converges to a sampled circle
 * like h^4.
 */
#include "testutil.h"

#include <string.h>

#include "km/curve.h"
#include "testmain.h"

/* Chord-length parameters of pts (closed adds the closing chord), written
 * here from the definition so the test does not trust the code. */
static void chord_params(const double *pts, size_t n, bool closed, double *u) {
  size_t spans = closed ? n : n - 1;
  double total = 0.0;
  u[0] = 0.0;
  for (size_t k = 0; k < spans; k++) {
    size_t k1 = (k + 1) % n;
    total += hypot(pts[2 * k1] - pts[2 * k], pts[2 * k1 + 1] - pts[2 * k + 1]);
    u[k + 1] = total;
  }
  for (size_t k = 0; k <= spans; k++) u[k] /= total;
}

static void random_points(double *pts, size_t n, uint64_t seed) {
  uint64_t s = seed;
  for (size_t i = 0; i < n; i++) {
    /* a wandering walk so that neighbours are distinct */
    double a = tu_uniform(&s, 0, 2 * M_PI), r = tu_uniform(&s, 0.2, 3);
    pts[2 * i] = (i ? pts[2 * i - 2] : 0) + r * cos(a);
    pts[2 * i + 1] = (i ? pts[2 * i - 1] : 0) + r * sin(a);
  }
}

static void assert_passes_through(const km_curve *c, const double *pts,
                                  size_t n, bool closed) {
  double u[512];
  chord_params(pts, n, closed, u);
  double scale = 0;
  for (size_t i = 0; i < 2 * n; i++) scale = fmax(scale, fabs(pts[i]));
  for (size_t k = 0; k < n; k++) {
    double p[1][2];
    km_curve_eval(c, u[k], 0, p);
    assert_close(p[0][0], pts[2 * k], 1e-12 * scale);
    assert_close(p[0][1], pts[2 * k + 1], 1e-12 * scale);
  }
  if (closed) {
    double p[1][2];
    km_curve_eval(c, 1.0, 0, p);
    assert_close(p[0][0], pts[0], 1e-12 * scale);
    assert_close(p[0][1], pts[1], 1e-12 * scale);
  }
}

/* Derivatives 0..2 from both sides agree at every interior knot. */
static void assert_c2(const km_curve *c) {
  double scale = 0;
  for (size_t i = 0; i < 2 * c->n; i++) scale = fmax(scale, fabs(c->cp[i]));
  for (size_t i = 4; i < c->n; i++) {
    double t = c->knots[i], l[3][2], r[3][2];
    km_curve_eval_side(c, t, -1, 2, l);
    km_curve_eval_side(c, t, 1, 2, r);
    for (int k = 0; k <= 2; k++) {
      double mag = fmax(hypot(l[k][0], l[k][1]), scale);
      assert_close(l[k][0], r[k][0], 1e-9 * mag);
      assert_close(l[k][1], r[k][1], 1e-9 * mag);
    }
  }
}

static void open_interpolant_passes_through_every_point(void **state) {
  (void)state;
  const size_t sizes[] = {4, 5, 7, 12, 60, 300};
  for (int s = 0; s < 6; s++) {
    size_t n = sizes[s];
    double pts[600];
    random_points(pts, n, 1000 + (uint64_t)s);
    km_curve c;
    km_error e;
    assert_status(km_curve_interpolate(&c, pts, n, false, &e), KM_OK);
    assert_int_equal(c.degree, 3);
    assert_null(c.w);
    assert_false(c.closed);
    assert_int_equal(c.n, n);
    assert_passes_through(&c, pts, n, false);
    assert_c2(&c);
    km_curve_free(&c);
  }
}

static void open_interpolant_is_not_a_knot(void **state) {
  (void)state;
  double pts[20];
  random_points(pts, 10, 9);
  double u[16];
  chord_params(pts, 10, false, u);
  km_curve c;
  assert_status(km_curve_interpolate(&c, pts, 10, false, NULL), KM_OK);
  /* the third derivative does not jump at the second and last-but-one
   * sites: one cubic spans the first two and the last two intervals */
  const double at[2] = {u[1], u[8]};
  for (int k = 0; k < 2; k++) {
    double l[4][2], r[4][2];
    km_curve_eval_side(&c, at[k], -1, 3, l);
    km_curve_eval_side(&c, at[k], 1, 3, r);
    assert_close(l[3][0], r[3][0], 1e-8 * fmax(1, fabs(l[3][0])));
    assert_close(l[3][1], r[3][1], 1e-8 * fmax(1, fabs(l[3][1])));
  }
  /* the knots are the chord parameters without the second and the
   * last-but-one */
  for (size_t j = 4; j < c.n; j++) assert_close(c.knots[j], u[j - 2], 1e-15);
  /* and the third derivative does jump at such a genuine knot (generic
   * data) */
  double l[4][2], r[4][2];
  km_curve_eval_side(&c, c.knots[6], -1, 3, l);
  km_curve_eval_side(&c, c.knots[6], 1, 3, r);
  assert_true(hypot(l[3][0] - r[3][0], l[3][1] - r[3][1]) > 1e-6);
  km_curve_free(&c);
}

static void collinear_points_give_a_uniform_speed_line(void **state) {
  (void)state;
  /* unevenly spaced points on a line: chord length is the line's own
   * parameter, so the interpolant is the line traced at constant speed */
  const double ts[] = {0, 0.1, 0.15, 0.5, 0.55, 0.9, 1.0};
  double pts[14], A[2] = {-1, 2}, B[2] = {3, 5};
  for (int i = 0; i < 7; i++) {
    pts[2 * i] = A[0] + ts[i] * (B[0] - A[0]);
    pts[2 * i + 1] = A[1] + ts[i] * (B[1] - A[1]);
  }
  km_curve c;
  assert_status(km_curve_interpolate(&c, pts, 7, false, NULL), KM_OK);
  for (int i = 0; i <= 100; i++) {
    double t = i / 100.0, p[3][2];
    km_curve_eval(&c, t, 2, p);
    assert_close(p[0][0], A[0] + t * (B[0] - A[0]), 1e-13);
    assert_close(p[0][1], A[1] + t * (B[1] - A[1]), 1e-13);
    assert_close(p[1][0], B[0] - A[0], 1e-11);
    assert_close(p[1][1], B[1] - A[1], 1e-11);
    assert_close(p[2][0], 0, 1e-9);
  }
  km_curve_free(&c);
}

static void two_points_give_a_straight_segment(void **state) {
  (void)state;
  double pts[] = {1, 1, 4, -3};
  km_curve c;
  assert_status(km_curve_interpolate(&c, pts, 2, false, NULL), KM_OK);
  assert_int_equal(c.degree, 3);
  for (int i = 0; i <= 20; i++) {
    double t = i / 20.0, p[2][2];
    km_curve_eval(&c, t, 1, p);
    assert_close(p[0][0], 1 + 3 * t, 1e-14);
    assert_close(p[0][1], 1 - 4 * t, 1e-14);
    assert_close(hypot(p[1][0], p[1][1]), 5.0, 1e-13);
  }
  km_curve_free(&c);
}

static void three_points_give_a_parabola_through_them(void **state) {
  (void)state;
  double pts[] = {0, 0, 1, 2, 3, 1};
  km_curve c;
  assert_status(km_curve_interpolate(&c, pts, 3, false, NULL), KM_OK);
  assert_passes_through(&c, pts, 3, false);
  /* a parabola: constant second derivative, zero third */
  double p0[4][2], p1[4][2];
  km_curve_eval(&c, 0.1, 3, p0);
  km_curve_eval(&c, 0.8, 3, p1);
  assert_close(p0[2][0], p1[2][0], 1e-11);
  assert_close(p0[2][1], p1[2][1], 1e-11);
  assert_close(p0[3][0], 0, 1e-10);
  assert_close(p0[3][1], 0, 1e-10);
  km_curve_free(&c);
}

static void duplicates_are_dropped(void **state) {
  (void)state;
  double clean[] = {0, 0, 1, 2, 3, 1, 4, 4, 6, 0};
  double dup[] = {0, 0, 0, 0, 1, 2, 3, 1, 3, 1, 3, 1, 4, 4, 6, 0, 6, 0};
  km_curve a, b;
  assert_status(km_curve_interpolate(&a, clean, 5, false, NULL), KM_OK);
  assert_status(km_curve_interpolate(&b, dup, 9, false, NULL), KM_OK);
  assert_int_equal(a.n, b.n);
  assert_memory_equal(a.cp, b.cp, 2 * a.n * sizeof(double));
  km_curve_free(&a);
  km_curve_free(&b);
  /* closed: a repeated first point at the end is the same curve */
  double ring[] = {0, 0, 2, 0, 2, 2, 0, 2};
  double ring_rep[] = {0, 0, 2, 0, 2, 2, 0, 2, 0, 0};
  assert_status(km_curve_interpolate(&a, ring, 4, true, NULL), KM_OK);
  assert_status(km_curve_interpolate(&b, ring_rep, 5, true, NULL), KM_OK);
  assert_int_equal(a.n, b.n);
  assert_memory_equal(a.cp, b.cp, 2 * a.n * sizeof(double));
  km_curve_free(&a);
  km_curve_free(&b);
}

static void too_few_distinct_points_are_degenerate(void **state) {
  (void)state;
  double same[] = {1, 1, 1, 1, 1, 1};
  km_curve c;
  memset(&c, 0x33, sizeof c);
  km_curve before = c;
  km_error e;
  assert_status(km_curve_interpolate(&c, same, 3, false, &e), KM_EDEGENERATE);
  assert_int_equal(e.field, KM_FIELD_POINTS);
  assert_status(km_curve_interpolate(&c, same, 0, false, &e), KM_EDEGENERATE);
  double two[] = {0, 0, 1, 0, 0, 0};
  assert_status(km_curve_interpolate(&c, two, 3, true, &e), KM_EDEGENERATE);
  double bad[] = {0, 0, NAN, 1, 2, 2};
  assert_status(km_curve_interpolate(&c, bad, 3, false, &e), KM_ENONFINITE);
  assert_int_equal(e.field, KM_FIELD_POINTS);
  assert_int_equal(e.index, 1);
  assert_memory_equal(&c, &before, sizeof c);
}

static void
closed_interpolant_passes_through_points_and_is_c2_at_seam(void **state) {
  (void)state;
  const size_t sizes[] = {3, 4, 7, 40};
  for (int s = 0; s < 4; s++) {
    size_t n = sizes[s];
    double pts[80];
    uint64_t st = 77 + (uint64_t)s;
    /* a star-shaped ring with uneven angular steps and radii */
    for (size_t i = 0; i < n; i++) {
      double a = 2 * M_PI * (i + 0.4 * tu_rand(&st)) / n;
      double r = 1 + 0.5 * tu_rand(&st);
      pts[2 * i] = 3 + r * cos(a);
      pts[2 * i + 1] = -1 + r * sin(a);
    }
    km_curve c;
    assert_status(km_curve_interpolate(&c, pts, n, true, NULL), KM_OK);
    assert_true(c.closed);
    assert_true(c.cp[0] == c.cp[2 * (c.n - 1)] &&
                c.cp[1] == c.cp[2 * (c.n - 1) + 1]);
    assert_passes_through(&c, pts, n, true);
    assert_c2(&c);
    double a[3][2], b[3][2];
    km_curve_eval_side(&c, 0.0, 1, 2, a);
    km_curve_eval_side(&c, 1.0, -1, 2, b);
    for (int k = 0; k <= 2; k++) {
      double mag = fmax(1, hypot(a[k][0], a[k][1]));
      assert_close(a[k][0], b[k][0], 1e-10 * mag);
      assert_close(a[k][1], b[k][1], 1e-10 * mag);
    }
    km_curve_free(&c);
  }
}

/* Max over the curve of | |C - centre| - 1 | for a unit circle. */
static double circle_error(size_t n, double phase) {
  double pts[2 * 512];
  for (size_t i = 0; i < n; i++) {
    double a = phase + 2 * M_PI * (double)i / (double)n;
    pts[2 * i] = cos(a);
    pts[2 * i + 1] = sin(a);
  }
  km_curve c;
  assert_status(km_curve_interpolate(&c, pts, n, true, NULL), KM_OK);
  double err = 0;
  for (int i = 0; i <= 20000; i++) {
    double p[1][2];
    km_curve_eval(&c, i / 20000.0, 0, p);
    err = fmax(err, fabs(hypot(p[0][0], p[0][1]) - 1));
  }
  km_curve_free(&c);
  return err;
}

static void closed_circle_samples_converge_like_h4(void **state) {
  (void)state;
  double e8 = circle_error(8, 0.3), e16 = circle_error(16, 0.3);
  double e32 = circle_error(32, 0.3), e64 = circle_error(64, 0.3);
  assert_le(e8, 2e-3);
  /* halving h divides the error by 2^4 */
  assert_in_range((long)(e16 > 0 ? e8 / e16 : 0), 12, 20);
  assert_in_range((long)(e32 > 0 ? e16 / e32 : 0), 12, 20);
  assert_in_range((long)(e64 > 0 ? e32 / e64 : 0), 12, 20);
  assert_le(e64, 1e-6);
}

static void open_arc_samples_converge_like_h4(void **state) {
  (void)state;
  /* a quarter-circle sampled evenly: the not-a-knot interpolant is O(h^4)
   * accurate too */
  double errs[4];
  for (int level = 0; level < 4; level++) {
    size_t n = (size_t)8 << level;
    double pts[2 * 128];
    for (size_t i = 0; i < n; i++) {
      double a = 0.5 * M_PI * (double)i / (double)(n - 1);
      pts[2 * i] = 2 * cos(a);
      pts[2 * i + 1] = 2 * sin(a);
    }
    km_curve c;
    assert_status(km_curve_interpolate(&c, pts, n, false, NULL), KM_OK);
    double err = 0;
    for (int i = 0; i <= 20000; i++) {
      double p[1][2];
      km_curve_eval(&c, i / 20000.0, 0, p);
      err = fmax(err, fabs(hypot(p[0][0], p[0][1]) - 2));
    }
    errs[level] = err;
    km_curve_free(&c);
  }
  for (int level = 1; level < 4; level++) {
    double ratio = errs[level - 1] / errs[level];
    /* (n-1) not n halves: allow the ratio of (7/15)^-4 etc. around 16 */
    assert_true(ratio > 10 && ratio < 26);
  }
}

static const struct CMUnitTest tests[] = {
    cmocka_unit_test(open_interpolant_passes_through_every_point),
    cmocka_unit_test(open_interpolant_is_not_a_knot),
    cmocka_unit_test(collinear_points_give_a_uniform_speed_line),
    cmocka_unit_test(two_points_give_a_straight_segment),
    cmocka_unit_test(three_points_give_a_parabola_through_them),
    cmocka_unit_test(duplicates_are_dropped),
    cmocka_unit_test(too_few_distinct_points_are_degenerate),
    cmocka_unit_test(
        closed_interpolant_passes_through_points_and_is_c2_at_seam),
    cmocka_unit_test(closed_circle_samples_converge_like_h4),
    cmocka_unit_test(open_arc_samples_converge_like_h4),
};

TM_SUITE("interp", tests, NULL, NULL);
