/* test_path.c - the path builder: exact Bezier pieces, SVG elliptical arcs
 * (F.6 centre conversion, radius scaling), degree raising, knots, closing,
 * dropping of zero-length pieces and input validation.
 *
 * Oracles: the Bernstein form of each piece evaluated independently here
 * (de Casteljau), circles and ellipses (|C - O| = r, the ellipse equation,
 * curvature 1/r), arc lengths of circular arcs (r * angle) and the sign of
 * curvature that the sweep flag fixes.
 */
#include <stdbool.h>
#include <string.h>

#include "km/curve.h"
#include "km/path.h"
#include "testutil.h"
#include "testmain.h"

/* Point of the Bezier with control points p (degree d) at u. */
static void bezier(const double p[][2], int d, double u, double out[2]) {
  double q[4][2];
  memcpy(q, p, (size_t)(d + 1) * sizeof q[0]);
  for (int lev = 1; lev <= d; lev++)
    for (int i = 0; i <= d - lev; i++)
      for (int k = 0; k < 2; k++)
        q[i][k] = (1.0 - u) * q[i][k] + u * q[i + 1][k];
  out[0] = q[0][0];
  out[1] = q[0][1];
}

static void pos(const km_curve *c, double t, double out[2]) {
  double v[1][2];
  km_curve_eval(c, t, 0, v);
  out[0] = v[0][0];
  out[1] = v[0][1];
}

/* Signed curvature x'y'' - x''y' over |C'|^3 at t. */
static double curvature(const km_curve *c, double t) {
  double d[3][2];
  km_curve_eval(c, t, 2, d);
  double cr = d[1][0] * d[2][1] - d[1][1] * d[2][0];
  return cr / pow(hypot(d[1][0], d[1][1]), 3);
}

static void build(km_path *p, km_curve *c, double eps) {
  km_error e;
  km_curve_init(c);
  km_status st = km_path_to_curve(p, eps, c, &e);
  if (st) print_error("km_path_to_curve: %s\n", e.message);
  assert_status(st, KM_OK);
}

static void line_path_is_a_degree_one_polyline(void **state) {
  (void)state;
  km_path p;
  km_curve c;
  km_path_init(&p);
  assert_status(km_path_move_to(&p, 1, 2, NULL), KM_OK);
  assert_status(km_path_line_to(&p, 4, 6, NULL), KM_OK);
  assert_status(km_path_line_to(&p, 4, 0, NULL), KM_OK);
  build(&p, &c, 0);
  assert_int_equal(c.degree, 1);
  assert_int_equal(c.n, 3);
  assert_null(c.w);
  assert_false(c.closed);
  double at[2];
  pos(&c, 0.5, at);
  assert_close(at[0], 2.5, 1e-15);
  assert_close(at[1], 4.0, 1e-15);
  pos(&c, 1.75, at);
  assert_close(at[0], 4.0, 1e-15);
  assert_close(at[1], 1.5, 1e-15);
  km_curve_free(&c);
  km_path_free(&p);
}

/* A line, a quadratic and a cubic raised to one cubic: each piece i of the
 * curve on [i, i+1] is the given Bezier at u = t - i. */
static void mixed_pieces_are_raised_to_cubic_exactly(void **state) {
  (void)state;
  const double line[2][2] = {{0, 0}, {3, 1}};
  const double quad[3][2] = {{3, 1}, {5, 4}, {2, 6}};
  const double cub[4][2] = {{2, 6}, {0, 7}, {-2, 3}, {-1, 1}};
  km_path p;
  km_curve c;
  km_path_init(&p);
  assert_status(km_path_move_to(&p, 0, 0, NULL), KM_OK);
  assert_status(km_path_line_to(&p, 3, 1, NULL), KM_OK);
  assert_status(km_path_quad_to(&p, 5, 4, 2, 6, NULL), KM_OK);
  assert_status(km_path_cubic_to(&p, 0, 7, -2, 3, -1, 1, NULL), KM_OK);
  build(&p, &c, 0);
  assert_int_equal(c.degree, 3);
  assert_int_equal(c.n, 10);
  assert_null(c.w);
  /* knots 0000 111 222 3333: piece indices, multiplicity = degree */
  const double want[] = {0, 0, 0, 0, 1, 1, 1, 2, 2, 2, 3, 3, 3, 3};
  for (int i = 0; i < 14; i++) assert_close(c.knots[i], want[i], 0);
  for (int i = 0; i <= 100; i++) {
    double u = i / 100.0, a[2], b[2];
    bezier(line, 1, u, a);
    pos(&c, u, b);
    assert_close(b[0], a[0], 1e-14);
    assert_close(b[1], a[1], 1e-14);
    bezier(quad, 2, u, a);
    pos(&c, 1 + u, b);
    assert_close(b[0], a[0], 1e-14);
    assert_close(b[1], a[1], 1e-14);
    bezier(cub, 3, u, a);
    pos(&c, 2 + u, b);
    assert_close(b[0], a[0], 1e-14);
    assert_close(b[1], a[1], 1e-14);
  }
  /* junctions are the given points bit for bit */
  assert_true(c.cp[6] == 3 && c.cp[7] == 1);
  assert_true(c.cp[12] == 2 && c.cp[13] == 6);
  km_curve_free(&c);
  km_path_free(&p);
}

/* A quarter arc of radius 5 around (1, 2): one rational quadratic piece
 * with middle weight cos(45 deg); every point at distance 5 from the
 * centre; a line added after it keeps weight 1. */
static void quarter_arc_is_one_exact_rational_piece(void **state) {
  (void)state;
  km_path p;
  km_curve c;
  km_path_init(&p);
  assert_status(km_path_move_to(&p, 6, 2, NULL), KM_OK);
  assert_status(km_path_arc_to(&p, 5, 5, 0, false, true, 1, 7, NULL), KM_OK);
  assert_status(km_path_line_to(&p, -3, 7, NULL), KM_OK);
  build(&p, &c, 0);
  assert_int_equal(c.degree, 2);
  assert_int_equal(c.n, 5);
  assert_non_null(c.w);
  assert_close(c.w[1], sqrt(0.5), 1e-15);
  assert_close(c.w[3], 1.0, 0);
  assert_close(c.w[4], 1.0, 0);
  for (int i = 0; i <= 200; i++) {
    double t = i / 200.0, at[2];
    pos(&c, t, at);
    assert_close(hypot(at[0] - 1, at[1] - 2), 5.0, 5e-15 * 5);
  }
  /* the line piece stays a line: its midpoint is the chord's */
  double at[2];
  pos(&c, 1.5, at);
  assert_close(at[0], -1.0, 1e-14);
  assert_close(at[1], 7.0, 1e-14);
  km_curve_free(&c);
  km_path_free(&p);
}

/* A full circle of radius r as two half arcs: curvature 1/r and distance r
 * from the centre everywhere, pieces of 90 degrees. */
static void two_half_arcs_make_a_circle_of_curvature_one_over_r(void **state) {
  (void)state;
  const double r = 80, cx = 100, cy = 100;
  km_path p;
  km_curve c;
  km_path_init(&p);
  assert_status(km_path_move_to(&p, cx - r, cy, NULL), KM_OK);
  assert_status(km_path_arc_to(&p, r, r, 0, true, true, cx + r, cy, NULL),
                KM_OK);
  assert_status(km_path_arc_to(&p, r, r, 0, true, true, cx - r, cy, NULL),
                KM_OK);
  assert_status(km_path_close(&p, NULL), KM_OK);
  build(&p, &c, 0);
  assert_true(c.closed);
  assert_int_equal(c.n, 9); /* 4 quarter pieces */
  double t0, t1;
  km_curve_domain(&c, &t0, &t1);
  assert_close(t1 - t0, 4.0, 0);
  for (int i = 0; i <= 1000; i++) {
    double t = t0 + (t1 - t0) * i / 1000.0, at[2];
    pos(&c, t, at);
    assert_rel(hypot(at[0] - cx, at[1] - cy), r, 1e-12);
    /* sweep = 1: positive angle direction, so positive x'y'' - x''y' */
    assert_close(curvature(&c, t), 1.0 / r, 1e-9 / r);
  }
  km_curve_free(&c);
  km_path_free(&p);
}

/* F.6.6: radii too small to reach the end point are scaled up until they
 * just do: from (0,0) to (10,0) with r = 1 the arc is a half circle of
 * radius 5 around (5,0); sweep = 1 passes through (5,-5). */
static void too_small_radii_are_scaled_up(void **state) {
  (void)state;
  km_path p;
  km_curve c;
  km_path_init(&p);
  assert_status(km_path_move_to(&p, 0, 0, NULL), KM_OK);
  assert_status(km_path_arc_to(&p, 1, 1, 0, false, true, 10, 0, NULL), KM_OK);
  build(&p, &c, 0);
  double t0, t1, at[2];
  km_curve_domain(&c, &t0, &t1);
  for (int i = 0; i <= 100; i++) {
    pos(&c, t0 + (t1 - t0) * i / 100.0, at);
    assert_close(hypot(at[0] - 5, at[1]), 5.0, 1e-13);
  }
  pos(&c, 0.5 * (t0 + t1), at);
  assert_close(at[0], 5.0, 1e-13);
  assert_close(at[1], -5.0, 1e-13);
  assert_close(km_curve_length(&c), 5.0 * M_PI, 1e-10);
  km_curve_free(&c);
  km_path_free(&p);

  /* An ellipse 2:1 scaled the same way keeps its ratio: rx = 2 ry. */
  km_path_init(&p);
  assert_status(km_path_move_to(&p, 0, 0, NULL), KM_OK);
  assert_status(km_path_arc_to(&p, 0.2, 0.1, 0, false, false, 0, 4, NULL),
                KM_OK);
  build(&p, &c, 0);
  km_curve_domain(&c, &t0, &t1);
  for (int i = 0; i <= 100; i++) {
    pos(&c, t0 + (t1 - t0) * i / 100.0, at);
    /* centre (0,2), ry = 2 (half the chord), rx = 4 */
    double ex = at[0] / 4.0, ey = (at[1] - 2.0) / 2.0;
    assert_close(ex * ex + ey * ey, 1.0, 1e-13);
  }
  km_curve_free(&c);
  km_path_free(&p);
}

/* A rotated ellipse: every point satisfies the ellipse equation in the
 * frame rotated by the x-axis-rotation. */
static void rotated_elliptical_arc_lies_on_its_ellipse(void **state) {
  (void)state;
  const double rx = 30, ry = 12, phi = 30.0 * M_PI / 180.0;
  /* end points: two points of the ellipse around (0,0) at angles 0.3, 2.9 */
  double pts[2][2];
  const double ang[2] = {0.3, 2.9};
  for (int k = 0; k < 2; k++) {
    double u = rx * cos(ang[k]), v = ry * sin(ang[k]);
    pts[k][0] = cos(phi) * u - sin(phi) * v;
    pts[k][1] = sin(phi) * u + cos(phi) * v;
  }
  for (int large = 0; large <= 1; large++) {
    km_path p;
    km_curve c;
    km_path_init(&p);
    assert_status(km_path_move_to(&p, pts[0][0], pts[0][1], NULL), KM_OK);
    /* small arc counter-clockwise in angle = sweep 1; large = other way,
     * which lies on the other ellipse through the points: only the small
     * sweep-1 and large sweep-0 arcs lie on the ellipse around (0,0). */
    assert_status(km_path_arc_to(&p, rx, ry, 30, large, !large, pts[1][0],
                                 pts[1][1], NULL),
                  KM_OK);
    build(&p, &c, 0);
    double t0, t1;
    km_curve_domain(&c, &t0, &t1);
    for (int i = 0; i <= 200; i++) {
      double at[2];
      pos(&c, t0 + (t1 - t0) * i / 200.0, at);
      double u = cos(phi) * at[0] + sin(phi) * at[1];
      double v = -sin(phi) * at[0] + cos(phi) * at[1];
      assert_close((u / rx) * (u / rx) + (v / ry) * (v / ry), 1.0, 1e-12);
    }
    /* the small arc spans 2.6 rad of parameter angle, the large 2pi-2.6:
     * pieces of at most 90 degrees */
    size_t pieces = (c.n - 1) / 2;
    assert_int_equal(pieces, large ? 3 : 2);
    km_curve_free(&c);
    km_path_free(&p);
  }
}

/* The four flag combinations from (0,0) to (r,r) on circles of radius r:
 * small arcs are a quarter (length pi r / 2), large three quarters; the
 * sweep flag fixes the sign of curvature. */
static void arc_flags_choose_length_and_turning_direction(void **state) {
  (void)state;
  const double r = 3;
  for (int large = 0; large <= 1; large++)
    for (int sweep = 0; sweep <= 1; sweep++) {
      km_path p;
      km_curve c;
      km_path_init(&p);
      assert_status(km_path_move_to(&p, 0, 0, NULL), KM_OK);
      assert_status(km_path_arc_to(&p, r, r, 0, large, sweep, r, r, NULL),
                    KM_OK);
      build(&p, &c, 0);
      double want = (large ? 1.5 : 0.5) * M_PI * r;
      assert_close(km_curve_length(&c), want, 1e-11 * want);
      double t0, t1;
      km_curve_domain(&c, &t0, &t1);
      for (int i = 0; i <= 20; i++) {
        double k = curvature(&c, t0 + (t1 - t0) * i / 20.0);
        assert_close(k, (sweep ? 1.0 : -1.0) / r, 1e-9 / r);
      }
      km_curve_free(&c);
      km_path_free(&p);
    }
}

static void zero_radius_arc_is_a_straight_line(void **state) {
  (void)state;
  km_path p;
  km_curve c;
  km_path_init(&p);
  assert_status(km_path_move_to(&p, 0, 0, NULL), KM_OK);
  assert_status(km_path_arc_to(&p, 0, 5, 0, false, true, 4, 3, NULL), KM_OK);
  build(&p, &c, 0);
  assert_int_equal(c.degree, 1);
  assert_null(c.w);
  assert_close(km_curve_length(&c), 5.0, 1e-14);
  km_curve_free(&c);
  km_path_free(&p);
}

/* Pieces that are a single point are dropped, the path otherwise kept:
 * an arc to the current point, a line of zero length, a cubic with all
 * four points equal. A cubic with only a zero-length control leg stays. */
static void point_pieces_are_dropped_but_degenerate_legs_kept(void **state) {
  (void)state;
  km_path p;
  km_curve c;
  km_path_init(&p);
  assert_status(km_path_move_to(&p, 1, 1, NULL), KM_OK);
  assert_status(km_path_arc_to(&p, 2, 2, 0, 0, 1, 1, 1, NULL), KM_OK);
  assert_status(km_path_line_to(&p, 1, 1, NULL), KM_OK);
  assert_status(km_path_cubic_to(&p, 1, 1, 1, 1, 1, 1, NULL), KM_OK);
  assert_status(km_path_cubic_to(&p, 1, 1, 3, 2, 5, 1, NULL), KM_OK);
  assert_status(km_path_line_to(&p, 5, 1, NULL), KM_OK);
  build(&p, &c, 0);
  assert_int_equal(c.degree, 3);
  assert_int_equal(c.n, 4);                  /* one piece */
  assert_true(c.cp[2] == 1 && c.cp[3] == 1); /* the zero leg is kept */
  km_curve_free(&c);
  km_path_free(&p);

  /* nothing but points: a degenerate path */
  km_path_init(&p);
  assert_status(km_path_move_to(&p, 1, 1, NULL), KM_OK);
  assert_status(km_path_line_to(&p, 1, 1, NULL), KM_OK);
  km_curve_init(&c);
  assert_status(km_path_to_curve(&p, 0, &c, NULL), KM_EDEGENERATE);
  km_path_free(&p);
}

/* With eps > 0 a piece within eps of the previous end is dropped and the
 * next one attached there: the shape moves by at most eps. */
static void
pieces_within_eps_are_dropped_and_the_path_stays_joined(void **state) {
  (void)state;
  km_path p;
  km_curve c;
  km_path_init(&p);
  assert_status(km_path_move_to(&p, 0, 0, NULL), KM_OK);
  assert_status(km_path_line_to(&p, 10, 0, NULL), KM_OK);
  assert_status(km_path_line_to(&p, 10, 1e-12, NULL), KM_OK);
  assert_status(km_path_line_to(&p, 10, 10, NULL), KM_OK);
  build(&p, &c, 1e-9);
  assert_int_equal(c.n, 3);
  assert_true(c.cp[2] == 10 && c.cp[3] == 0);
  assert_true(c.cp[4] == 10 && c.cp[5] == 10);
  km_curve_free(&c);
  /* eps = 0 keeps the tiny piece */
  build(&p, &c, 0);
  assert_int_equal(c.n, 4);
  km_curve_free(&c);
  km_path_free(&p);
}

/* Close adds the line back to the start and makes first == last exactly;
 * a path already at its start gets no extra piece. */
static void close_joins_the_end_to_the_start(void **state) {
  (void)state;
  km_path p;
  km_curve c;
  km_path_init(&p);
  assert_status(km_path_move_to(&p, 0.1, 0.2, NULL), KM_OK);
  assert_status(km_path_line_to(&p, 10, 0, NULL), KM_OK);
  assert_status(km_path_quad_to(&p, 10, 10, 0, 10, NULL), KM_OK);
  assert_status(km_path_close(&p, NULL), KM_OK);
  build(&p, &c, 0);
  assert_true(c.closed);
  assert_int_equal(c.n, 3 * 2 + 1);
  assert_true(c.cp[0] == 0.1 && c.cp[1] == 0.2);
  assert_true(c.cp[2 * (c.n - 1)] == 0.1 && c.cp[2 * (c.n - 1) + 1] == 0.2);
  km_curve_free(&c);
  /* nothing more after close */
  assert_status(km_path_line_to(&p, 3, 3, NULL), KM_EINVAL);
  km_path_free(&p);

  km_path_init(&p);
  assert_status(km_path_move_to(&p, 0, 0, NULL), KM_OK);
  assert_status(km_path_arc_to(&p, 1, 1, 0, 1, 1, 2, 0, NULL), KM_OK);
  assert_status(km_path_arc_to(&p, 1, 1, 0, 1, 1, 0, 0, NULL), KM_OK);
  assert_status(km_path_close(&p, NULL), KM_OK);
  build(&p, &c, 0);
  assert_int_equal(c.n, 9); /* four quarters, no closing line */
  km_curve_free(&c);
  km_path_free(&p);
}

static void bad_coordinates_and_misuse_are_refused(void **state) {
  (void)state;
  km_path p;
  km_error e;
  km_path_init(&p);
  assert_status(km_path_line_to(&p, 1, 1, &e), KM_EINVAL);
  assert_status(km_path_move_to(&p, NAN, 0, &e), KM_ENONFINITE);
  assert_status(km_path_move_to(&p, 0, 2e15, &e), KM_ERANGE);
  assert_int_equal(e.index, 1);
  assert_status(km_path_move_to(&p, 0, 0, &e), KM_OK);
  assert_status(km_path_move_to(&p, 1, 0, &e), KM_EINVAL);
  assert_status(km_path_cubic_to(&p, 0, 1, INFINITY, 0, 1, 1, &e),
                KM_ENONFINITE);
  assert_int_equal(e.index, 2);
  assert_status(km_path_quad_to(&p, 0, 1, -1e16, 0, &e), KM_ERANGE);
  assert_status(km_path_arc_to(&p, NAN, 1, 0, 0, 0, 1, 1, &e), KM_ENONFINITE);
  /* an absurdly flat ellipse scaled to reach its end leaves the range */
  assert_status(km_path_arc_to(&p, 1e-300, 1, 0, 0, 0, 1, 0, &e), KM_ERANGE);
  /* nothing was added by the failures */
  assert_int_equal(p.npieces, 0);
  km_path_free(&p);
  km_path_free(NULL);
}

static const struct CMUnitTest tests[] = {
    cmocka_unit_test(line_path_is_a_degree_one_polyline),
    cmocka_unit_test(mixed_pieces_are_raised_to_cubic_exactly),
    cmocka_unit_test(quarter_arc_is_one_exact_rational_piece),
    cmocka_unit_test(two_half_arcs_make_a_circle_of_curvature_one_over_r),
    cmocka_unit_test(too_small_radii_are_scaled_up),
    cmocka_unit_test(rotated_elliptical_arc_lies_on_its_ellipse),
    cmocka_unit_test(arc_flags_choose_length_and_turning_direction),
    cmocka_unit_test(zero_radius_arc_is_a_straight_line),
    cmocka_unit_test(point_pieces_are_dropped_but_degenerate_legs_kept),
    cmocka_unit_test(pieces_within_eps_are_dropped_and_the_path_stays_joined),
    cmocka_unit_test(close_joins_the_end_to_the_start),
    cmocka_unit_test(bad_coordinates_and_misuse_are_refused),
};

TM_SUITE("path", tests, NULL, NULL);
