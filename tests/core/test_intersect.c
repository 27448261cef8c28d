/* test_intersect.c - counting proper self-crossings: loops, figure-eights,
 * circles, tangential touches, crossings on piece boundaries and on the
 * seam of a closed curve.
 *
 * Every expected count is read off the geometry: the loop of a cubic
 * Bezier is located in closed form, polygons are counted by hand, the
 * parabola y = x^2 touches y = 0 once and y = x^2 - 0.01 crosses it at
 * x = +-0.1.
 */
#include "testutil.h"

#include <stdlib.h>
#include <string.h>

#include "km/curve.h"
#include "km/morph.h"
#include "testmain.h"

static km_curve make(int degree, size_t n, const double *knots,
                     const double *cp, const double *w, bool closed) {
  km_curve c;
  km_error e;
  assert_status(km_curve_create(&c, degree, n, knots, cp, w, closed, &e),
                KM_OK);
  return c;
}

/* Degree-1 curve through the points with knots 0, 1, 2, ... */
static km_curve polyline(const double *pts, size_t n, bool closed) {
  double knots[64];
  knots[0] = 0;
  for (size_t i = 0; i < n; i++) knots[i + 1] = (double)i;
  knots[n + 1] = (double)(n - 1);
  return make(1, n, knots, pts, NULL, closed);
}

static void loop_cubic_bezier_crosses_once(void **state) {
  (void)state;
  /* y(t) = 9 t (1 - t) is symmetric, so the loop closes where
   * x(1/2 + a) = x(1/2 - a): a^2 = 3/28, inside (0, 1/2) */
  double knots[] = {0, 0, 0, 0, 1, 1, 1, 1};
  double cp[] = {0, 0, 3, 3, -1, 3, 2, 0};
  km_curve c = make(3, 4, knots, cp, NULL, false);
  assert_int_equal(km_curve_self_intersections(&c, 1e-10), 1);
  km_curve_free(&c);
  /* the same shape without the loop: (0,0),(1,3),(2,3),(3,0) */
  double cp2[] = {0, 0, 1, 3, 2, 3, 3, 0};
  c = make(3, 4, knots, cp2, NULL, false);
  assert_int_equal(km_curve_self_intersections(&c, 1e-10), 0);
  km_curve_free(&c);
}

static void loop_is_found_after_exact_operations(void **state) {
  (void)state;
  /* the loop split over many pieces and raised in degree, made rational
   * by a compatible partner: still one crossing */
  double knots[] = {0, 0, 0, 0, 1, 1, 1, 1};
  double cp[] = {0, 0, 3, 3, -1, 3, 2, 0};
  km_curve c = make(3, 4, knots, cp, NULL, false), k1, k2, e;
  assert_status(km_curve_insert_knot(&k1, &c, 0.1727, 1, NULL), KM_OK);
  assert_status(km_curve_insert_knot(&k2, &k1, 0.5, 2, NULL), KM_OK);
  assert_status(km_curve_elevate(&e, &k2, 2, NULL), KM_OK);
  assert_int_equal(km_curve_self_intersections(&k1, 1e-10), 1);
  assert_int_equal(km_curve_self_intersections(&k2, 1e-10), 1);
  assert_int_equal(km_curve_self_intersections(&e, 1e-10), 1);
  km_curve_free(&c);
  km_curve_free(&k1);
  km_curve_free(&k2);
  km_curve_free(&e);
}

static void figure_eight_crosses_once(void **state) {
  (void)state;
  /* samples of the lemniscate of Gerono x = cos t, y = sin t cos t: one
   * double point at the origin */
  double pts[64];
  for (int i = 0; i < 24; i++) {
    double t = 2 * M_PI * (i + 0.25) / 24;
    pts[2 * i] = 2 * cos(t);
    pts[2 * i + 1] = sin(t) * cos(t);
  }
  km_curve c;
  assert_status(km_curve_interpolate(&c, pts, 24, true, NULL), KM_OK);
  assert_int_equal(km_curve_self_intersections(&c, 1e-10), 1);
  km_curve_free(&c);
  /* a clamped cubic figure-eight written by hand */
  double knots[] = {0, 0, 0, 0, 1, 2, 3, 4, 5, 6, 7, 7, 7, 7};
  double cp[] = {0,  0, 2,  2, 4,  2,  4,  -2, 2, -2,
                 -2, 2, -4, 2, -4, -2, -2, -2, 0, 0};
  c = make(3, 10, knots, cp, NULL, true);
  assert_int_equal(km_curve_self_intersections(&c, 1e-10), 1);
  km_curve_free(&c);
}

static void circles_do_not_cross_themselves(void **state) {
  (void)state;
  const double s = sqrt(0.5);
  double knots[] = {0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1};
  double cp[] = {3, 0, 3, 3, 0, 3, -3, 3, -3, 0, -3, -3, 0, -3, 3, -3, 3, 0};
  double w[] = {1, s, 1, s, 1, s, 1, s, 1};
  km_curve c = make(2, 9, knots, cp, w, true);
  assert_int_equal(km_curve_self_intersections(&c, 1e-10), 0);
  km_curve e;
  assert_status(km_curve_elevate(&e, &c, 1, NULL), KM_OK);
  assert_int_equal(km_curve_self_intersections(&e, 1e-10), 0);
  km_curve_free(&e);
  km_curve_free(&c);
  double pts[40];
  for (int i = 0; i < 20; i++) {
    pts[2 * i] = cos(2 * M_PI * i / 20);
    pts[2 * i + 1] = sin(2 * M_PI * i / 20);
  }
  assert_status(km_curve_interpolate(&c, pts, 20, true, NULL), KM_OK);
  assert_int_equal(km_curve_self_intersections(&c, 1e-10), 0);
  km_curve_free(&c);
}

/* A segment along y = 0 from x = -2 to 2, up the side x = 2, then the
 * parabola y = x^2 - shift from x = 2 back to x = -2, as quadratic Bezier
 * pieces. */
static km_curve parabola_over_line(double shift) {
  double knots[] = {0, 0, 0, 1, 1, 2, 2, 3, 3, 3};
  double cp[] = {-2, 0,         0, 0,          2,  0,        2, 2 - shift / 2,
                 2,  4 - shift, 0, -4 - shift, -2, 4 - shift};
  return make(2, 7, knots, cp, NULL, false);
}

static void tangential_touch_is_not_a_crossing(void **state) {
  (void)state;
  km_curve c = parabola_over_line(0.0);
  assert_int_equal(km_curve_self_intersections(&c, 1e-10), 0);
  km_curve_free(&c);
}

static void curve_crossing_itself_twice(void **state) {
  (void)state;
  km_curve c = parabola_over_line(0.01);
  assert_int_equal(km_curve_self_intersections(&c, 1e-10), 2);
  km_curve_free(&c);
  /* a shallow crossing: slopes +-2e-3 */
  c = parabola_over_line(1e-6);
  assert_int_equal(km_curve_self_intersections(&c, 1e-12), 2);
  km_curve_free(&c);
  /* lifted clear of the line: no contact */
  c = parabola_over_line(-0.01);
  assert_int_equal(km_curve_self_intersections(&c, 1e-10), 0);
  km_curve_free(&c);
}

static void polygons_count_like_by_hand(void **state) {
  (void)state;
  double bowtie[] = {0, 0, 2, 2, 2, 0, 0, 2, 0, 0};
  km_curve c = polyline(bowtie, 5, true);
  assert_int_equal(km_curve_self_intersections(&c, 1e-10), 1);
  km_curve_free(&c);
  double square[] = {0, 0, 2, 0, 2, 2, 0, 2, 0, 0};
  c = polyline(square, 5, true);
  assert_int_equal(km_curve_self_intersections(&c, 1e-10), 0);
  km_curve_free(&c);
  /* pentagram {5/2}: five crossings */
  double star[12];
  for (int i = 0; i <= 5; i++) {
    double a = M_PI / 2 + 2 * (2 * M_PI / 5) * (i % 5);
    star[2 * i] = cos(a);
    star[2 * i + 1] = sin(a);
  }
  star[10] = star[0];
  star[11] = star[1];
  c = polyline(star, 6, true);
  assert_int_equal(km_curve_self_intersections(&c, 1e-10), 5);
  km_curve_free(&c);
}

/* The regular star polygon {p/q} (p prime, q < p/2) crosses itself
 * p (q - 1) times: every edge meets the 2 (q - 1) edges whose ends
 * separate its own on the circle. Thousands of genuine crossings stay
 * within the count's work bounds. */
static void star_polygons_cross_p_times_q_minus_one(void **state) {
  (void)state;
  const int stars[][2] = {{7, 2}, {7, 3}, {31, 15}, {61, 30}};
  for (size_t k = 0; k < sizeof stars / sizeof *stars; k++) {
    int p = stars[k][0], q = stars[k][1];
    double *pts = malloc(2 * (size_t)(p + 1) * sizeof(double));
    double *knots = malloc((size_t)(p + 3) * sizeof(double));
    assert_non_null(pts);
    assert_non_null(knots);
    for (int i = 0; i <= p; i++) {
      double a = 0.3 + 2 * M_PI * (double)((i * q) % p) / p;
      pts[2 * i] = cos(a);
      pts[2 * i + 1] = sin(a);
    }
    pts[2 * p] = pts[0];
    pts[2 * p + 1] = pts[1];
    knots[0] = 0;
    for (int i = 0; i <= p; i++) knots[i + 1] = i;
    knots[p + 2] = p;
    km_curve c = make(1, (size_t)p + 1, knots, pts, NULL, true);
    long n = km_curve_self_intersections(&c, 1e-10);
    if (n != (long)p * (q - 1))
      print_error("{%d/%d}: %ld crossings\n", p, q, n);
    assert_int_equal(n, (long)p * (q - 1));
    km_curve_free(&c);
    free(pts);
    free(knots);
  }
}

static void crossing_at_a_piece_boundary_counts_once(void **state) {
  (void)state;
  /* the vertical leg passes through the joint (0, 0) of the first two
   * segments */
  double pts[] = {-1, 0, 0, 0, 1, 0, 1, 1, 0, 1, 0, -1};
  km_curve c = polyline(pts, 6, false);
  assert_int_equal(km_curve_self_intersections(&c, 1e-10), 1);
  km_curve_free(&c);
}

static void crossing_at_the_seam_counts_once(void **state) {
  (void)state;
  /* closed polygon starting at (1, 1), which the diagonal from (2, 0) to
   * (0, 2) passes through */
  double pts[] = {1, 1, 2, 2, 2, 0, 0, 2, 0, 0, 1, 1};
  km_curve c = polyline(pts, 6, true);
  assert_int_equal(km_curve_self_intersections(&c, 1e-10), 1);
  km_curve_free(&c);
  /* the seam alone is no crossing, nor an open end touching the curve */
  double hook[] = {0, 0, 2, 0, 2, 2, 1, 2, 1, 0};
  c = polyline(hook, 5, false);
  assert_int_equal(km_curve_self_intersections(&c, 1e-10), 0);
  km_curve_free(&c);
}

static void count_is_invariant_under_rigid_motion(void **state) {
  (void)state;
  double knots[] = {0, 0, 0, 0, 1, 2, 3, 4, 5, 6, 7, 7, 7, 7};
  double cp[] = {0,  0, 2,  2, 4,  2,  4,  -2, 2, -2,
                 -2, 2, -4, 2, -4, -2, -2, -2, 0, 0};
  km_curve c = make(3, 10, knots, cp, NULL, true), t;
  for (int k = 0; k < 8; k++) {
    assert_status(km_curve_transform(&t, &c, 0.37 * k, 1e3 * k, -7.0 * k, NULL),
                  KM_OK);
    assert_int_equal(km_curve_self_intersections(&t, 0), 1);
    km_curve_free(&t);
  }
  km_curve_free(&c);
}

/* The cubic Bezier with x controls (0, 3, 1 - e, 2) and y controls
 * (0, 3, 3, 0): y(t) = 9 t (1 - t) takes each value at t and 1 - t only,
 * so a crossing is a pair t = 1/2 +- a with x(1/2 + a) = x(1/2 - a). In
 * powers of a, x = c0 + c1 a + c2 a^2 + c3 a^3 with c1 = -3 e / 4 and
 * c3 = 8 + 3 e; its odd part vanishes at a^2 = -c1 / c3: one loop for
 * every e > 0 (the smaller e, the smaller the loop), none for
 * -8/3 < e < 0. Turned through a full circle, the curve's turns in x and
 * in y fall anywhere along the piece, inside the loop or beside it. */
static void cubic_loops_cross_once_however_small_or_turned(void **state) {
  (void)state;
  const double knots[] = {0, 0, 0, 0, 1, 1, 1, 1};
  const double loops[] = {4, 1, 0.1, 1e-2, 1e-3}, open[] = {-1e-2, -1, -2};
  for (int k = 0; k < 8; k++) {
    double e = k < 5 ? loops[k] : open[k - 5];
    long expected = k < 5 ? 1 : 0;
    double cp[] = {0, 0, 3, 3, 1 - e, 3, 2, 0};
    km_curve c = make(3, 4, knots, cp, NULL, false), t;
    for (int r = 0; r < 24; r++) {
      assert_status(
          km_curve_transform(&t, &c, 0.1 + 2 * M_PI * r / 24, 0.5, -2, NULL),
          KM_OK);
      long n = km_curve_self_intersections(&t, 1e-10);
      if (n != expected)
        print_error("e = %g turned %d/24: %ld crossings\n", e, r, n);
      assert_int_equal(n, expected);
      km_curve_free(&t);
    }
    km_curve_free(&c);
  }
}

/* S-curves: x controls (0, 1, 2, 3) make x(t) = 3 t, so each curve is the
 * graph of a function and cannot meet itself; turned, its two turns in y
 * become turns in x and in y anywhere along it. */
static void graphs_turned_any_way_do_not_cross(void **state) {
  (void)state;
  const double knots[] = {0, 0, 0, 0, 1, 1, 1, 1};
  const double heights[] = {0.5, 3, 30};
  for (int k = 0; k < 3; k++) {
    double h = heights[k];
    double cp[] = {0, 0, 1, h, 2, -h, 3, 0};
    km_curve c = make(3, 4, knots, cp, NULL, false), t;
    for (int r = 0; r < 24; r++) {
      assert_status(km_curve_transform(&t, &c, 2 * M_PI * r / 24, 0, 0, NULL),
                    KM_OK);
      assert_int_equal(km_curve_self_intersections(&t, 1e-10), 0);
      km_curve_free(&t);
    }
    km_curve_free(&c);
  }
}

/* Closed curves through samples that start on a turn, so the seam is an
 * extremum in x: the lemniscate of Gerono x = 2 cos t, y = sin t cos t
 * (one double point, the origin, where the branches cross at slopes
 * +-1/2) and the limacon r = 1/2 + cos(theta) (its inner loop closes at
 * the origin, the branches at 120 degrees). The samples are symmetric
 * about the x axis, and so is the interpolant: its double point stays on
 * the axis. */
static void closed_curves_starting_on_a_turn(void **state) {
  (void)state;
  double pts[2 * 48];
  for (int i = 0; i < 24; i++) {
    double t = 2 * M_PI * i / 24;
    pts[2 * i] = 2 * cos(t);
    pts[2 * i + 1] = sin(t) * cos(t);
  }
  km_curve c;
  assert_status(km_curve_interpolate(&c, pts, 24, true, NULL), KM_OK);
  assert_int_equal(km_curve_self_intersections(&c, 1e-10), 1);
  km_curve_free(&c);
  for (int i = 0; i < 48; i++) {
    double t = 2 * M_PI * i / 48, r = 0.5 + cos(t);
    pts[2 * i] = r * cos(t);
    pts[2 * i + 1] = r * sin(t);
  }
  assert_status(km_curve_interpolate(&c, pts, 48, true, NULL), KM_OK);
  assert_int_equal(km_curve_self_intersections(&c, 1e-10), 1);
  km_curve_free(&c);
}

/* The Lissajous figure x = sin(a t + phi), y = sin(b t) (a, b coprime,
 * phi generic) has 2 a b - a - b double points, all transversal; its
 * interpolant through dense samples keeps them. Its turns in x and in y
 * are many and close to the crossings, where a split in the wrong place
 * would show. */
static void lissajous_figures_cross_2ab_minus_a_minus_b_times(void **state) {
  (void)state;
  const int figures[][2] = {{1, 2}, {1, 3}, {3, 2}, {3, 4}, {2, 5}};
  enum { SAMPLES = 240 };
  static double pts[2 * SAMPLES];
  for (size_t k = 0; k < sizeof figures / sizeof *figures; k++) {
    int a = figures[k][0], b = figures[k][1];
    for (int i = 0; i < SAMPLES; i++) {
      double t = 2 * M_PI * i / SAMPLES;
      pts[2 * i] = sin(a * t + 0.3);
      pts[2 * i + 1] = sin(b * t);
    }
    km_curve c;
    assert_status(km_curve_interpolate(&c, pts, SAMPLES, true, NULL), KM_OK);
    long n = km_curve_self_intersections(&c, 1e-10);
    if (n != 2L * a * b - a - b) print_error("%d:%d: %ld crossings\n", a, b, n);
    assert_int_equal(n, 2L * a * b - a - b);
    km_curve_free(&c);
  }
}

static void invalid_curve_gives_minus_one(void **state) {
  (void)state;
  assert_int_equal(km_curve_self_intersections(NULL, 1e-9), -1);
  km_curve empty;
  km_curve_init(&empty);
  assert_int_equal(km_curve_self_intersections(&empty, 1e-9), -1);
}

static const struct CMUnitTest tests[] = {
    cmocka_unit_test(loop_cubic_bezier_crosses_once),
    cmocka_unit_test(loop_is_found_after_exact_operations),
    cmocka_unit_test(figure_eight_crosses_once),
    cmocka_unit_test(circles_do_not_cross_themselves),
    cmocka_unit_test(tangential_touch_is_not_a_crossing),
    cmocka_unit_test(curve_crossing_itself_twice),
    cmocka_unit_test(polygons_count_like_by_hand),
    cmocka_unit_test(star_polygons_cross_p_times_q_minus_one),
    cmocka_unit_test(crossing_at_a_piece_boundary_counts_once),
    cmocka_unit_test(crossing_at_the_seam_counts_once),
    cmocka_unit_test(count_is_invariant_under_rigid_motion),
    cmocka_unit_test(cubic_loops_cross_once_however_small_or_turned),
    cmocka_unit_test(graphs_turned_any_way_do_not_cross),
    cmocka_unit_test(closed_curves_starting_on_a_turn),
    cmocka_unit_test(lissajous_figures_cross_2ab_minus_a_minus_b_times),
    cmocka_unit_test(invalid_curve_gives_minus_one),
};

TM_SUITE("intersect", tests, NULL, NULL);
