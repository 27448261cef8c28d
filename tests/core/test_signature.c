/* test_signature.c - curvature signatures of curves whose curvature is known:
 * circles, polygons, lines, rounded rectangles, degenerate control legs,
 * cusps, and the invariances (knot insertion, degree elevation, rigid
 * motion); plus the validation of km_curve_create.
 *
 * Oracles: kappa = 1/R on a circle, kappa = 0 and exterior angles on
 * polygons, closed-form arc lengths, tangent angles of cubics computed
 * from their hodographs, and independent Gauss-Legendre arc lengths.
 */
#include <stdbool.h>
#include <string.h>

#include "fixtures.h"
#include "km/curve.h"
#include "km/reconstruct.h"
#include "km/signature.h"
#include "curvecases.h"
#include "testutil.h"
#include "testmain.h"

/* Signature that must succeed, at tolerance rel * length. */
static void sign(const km_curve *c, double rel, km_signature *sig) {
  km_error err;
  km_signature_init(sig);
  double L = km_curve_length(c);
  km_status st = km_signature_compute(c, rel * L, sig, &err);
  if (st != KM_OK) print_error("signature failed: %s\n", err.message);
  assert_status(st, KM_OK);
}

/* The number of corners, listing the first few when it is wrong. */
#define assert_ncorners(sig, want)                                             \
  do {                                                                         \
    if ((sig)->ncorners != (size_t)(want)) {                                   \
      print_error("%zu corners, expected %d:\n", (sig)->ncorners,              \
                  (int)(want));                                                \
      for (size_t i_ = 0; i_ < (sig)->ncorners && i_ < 6; i_++)                \
        print_error("  s = %.17g turn = %.17g\n", (sig)->corners[i_].s,        \
                    (sig)->corners[i_].turn);                                  \
      fail();                                                                  \
    }                                                                          \
  } while (0)

static double kappa_at(const km_signature *sig, double s) {
  return km_fn_value(&sig->kappa, s);
}

static void circle_case(int ccw) {
  const double R = 2.5, ox = 1.0, oy = -2.0, L = 2 * M_PI * R;
  const double sgn = ccw ? 1.0 : -1.0;
  double kn[12], cp[18], w[9];
  tu_circle_nurbs(ox, oy, R, ccw, kn, cp, w);
  km_curve c;
  make_curve(&c, 2, 9, kn, cp, w, true);
  km_signature sig;
  sign(&c, 1e-10, &sig);
  assert_close(sig.length, L, 1e-12 * L);
  assert_true(sig.closed);
  assert_ncorners(&sig, 0);
  assert_close(sig.turning, sgn * 2 * M_PI, 1e-9);
  assert_close(sig.start[0], ox + R, 1e-12);
  assert_close(sig.start[1], oy, 1e-12);
  assert_close(tu_wrap(sig.angle - sgn * M_PI / 2), 0.0, 1e-12);
  double a, b;
  km_fn_domain(&sig.kappa, &a, &b);
  assert_close(a, 0.0, 0.0);
  assert_close(b, L, 1e-12 * L);
  for (int i = 0; i <= 500; i++) {
    double s = L * i / 500.0;
    assert_close(kappa_at(&sig, s), sgn / R, 1e-9 / R);
    assert_close(
        tu_wrap(km_signature_theta(&sig, s) - sgn * (M_PI / 2 + s / R)), 0.0,
        1e-9);
  }
  assert_close(km_signature_max_abs_kappa(&sig), 1.0 / R, 1e-9 / R);
  assert_close(km_signature_bending_energy(&sig), L / (R * R),
               1e-9 * L / (R * R));
  km_signature_free(&sig);
  km_curve_free(&c);
}

static void circle_has_constant_curvature_one_over_r(void **state) {
  (void)state;
  circle_case(1);
}

static void clockwise_circle_has_curvature_minus_one_over_r(void **state) {
  (void)state;
  circle_case(0);
}

static void polygon_case(double a, double b, int ccw) {
  /* rectangle a x b from (1, 1), degree 1, closed */
  double cp[10] = {1, 1, 1 + a, 1, 1 + a, 1 + b, 1, 1 + b, 1, 1};
  if (!ccw) {
    /* mirror in y = 1: clockwise */
    for (int i = 0; i < 5; i++) cp[2 * i + 1] = 2.0 - cp[2 * i + 1];
  }
  const double kn[7] = {0, 0, 1, 2, 3, 4, 4};
  km_curve c;
  make_curve(&c, 1, 5, kn, cp, NULL, true);
  km_signature sig;
  sign(&c, 1e-10, &sig);
  const double L = 2 * (a + b), sgn = ccw ? 1.0 : -1.0;
  assert_close(sig.length, L, 1e-12 * L);
  assert_ncorners(&sig, 4);
  const double at[4] = {a, a + b, 2 * a + b, L};
  for (int i = 0; i < 4; i++) {
    assert_close(sig.corners[i].s, at[i], 1e-12 * L);
    assert_close(sig.corners[i].turn, sgn * M_PI / 2, 1e-12);
  }
  assert_close(sig.turning, sgn * 2 * M_PI, 1e-12);
  assert_close(tu_wrap(sig.angle), 0.0, 1e-12);
  for (int i = 0; i <= 100; i++)
    assert_close(kappa_at(&sig, L * i / 100.0), 0.0, 1e-12);
  /* theta steps by each corner's turn, which counts from the corner's own
   * s on (from the right) */
  const double eps = 1e-9 * L;
  assert_close(km_signature_theta(&sig, 0.5 * a), 0.0, 1e-12);
  assert_close(km_signature_theta(&sig, a - eps), 0.0, 1e-12);
  assert_close(km_signature_theta(&sig, a + eps), sgn * M_PI / 2, 1e-12);
  assert_close(km_signature_theta(&sig, sig.corners[0].s), sgn * M_PI / 2,
               1e-12);
  assert_close(km_signature_theta(&sig, a + 0.5 * b), sgn * M_PI / 2, 1e-12);
  assert_close(km_signature_theta(&sig, 2 * a + 1.5 * b), sgn * 3 * M_PI / 2,
               1e-12);
  assert_close(km_signature_theta(&sig, L - eps), sgn * 3 * M_PI / 2, 1e-12);
  assert_close(km_signature_theta(&sig, sig.length), sgn * 2 * M_PI, 1e-12);
  km_signature_free(&sig);
  km_curve_free(&c);
}

static void square_has_zero_curvature_and_four_right_corners(void **state) {
  (void)state;
  polygon_case(3.0, 3.0, 1);
  polygon_case(3.0, 1.0, 1);
}

static void clockwise_square_has_four_negative_corners(void **state) {
  (void)state;
  polygon_case(3.0, 3.0, 0);
}

static void
cubic_square_and_star_from_fixtures_have_polygon_corners(void **state) {
  (void)state;
  static const struct {
    const char *pair;
    char which;
  } shapes[2] = {{"square_to_circle", 'a'}, {"circle_to_star", 'b'}};
  for (int k = 0; k < 2; k++) {
    tf_bspline b;
    assert_int_equal(tf_load_shape(shapes[k].pair, shapes[k].which, &b), 0);
    assert_int_equal(b.degree, 3);
    km_curve c;
    make_curve(&c, 3, b.n, b.knots, b.cp, b.w, b.closed);
    km_signature sig;
    sign(&c, 1e-10, &sig);
    /* vertices are every third control point (lines as cubics) */
    size_t nv = (b.n - 1) / 3;
    double area2 = 0, len = 0;
    for (size_t i = 0; i < nv; i++) {
      const double *p = b.cp + 6 * i, *q = b.cp + 6 * ((i + 1) % nv);
      area2 += p[0] * q[1] - q[0] * p[1];
      len += hypot(q[0] - p[0], q[1] - p[1]);
    }
    assert_close(sig.length, len, 1e-12 * len);
    assert_ncorners(&sig, nv);
    double s = 0, sum = 0;
    for (size_t i = 0; i < nv; i++) {
      const double *p = b.cp + 6 * i, *q = b.cp + 6 * ((i + 1) % nv),
                   *r = b.cp + 6 * ((i + 2) % nv);
      s += hypot(q[0] - p[0], q[1] - p[1]);
      double turn = tu_turn(q[0] - p[0], q[1] - p[1], r[0] - q[0], r[1] - q[1]);
      assert_close(sig.corners[i].s, s, 1e-12 * len);
      assert_close(sig.corners[i].turn, turn, 1e-12);
      sum += turn;
    }
    /* the last corner is the seam, at s = length */
    assert_close(sig.corners[nv - 1].s, sig.length, 1e-12 * len);
    assert_close(sig.turning, (area2 > 0 ? 2 : -2) * M_PI, 1e-9);
    assert_close(sum, sig.turning, 1e-9);
    for (int i = 0; i <= 300; i++)
      assert_close(kappa_at(&sig, len * i / 300.0), 0.0, 1e-9 / len);
    km_signature_free(&sig);
    km_curve_free(&c);
    tf_bspline_free(&b);
  }
}

static void straight_line_has_zero_curvature_and_turning(void **state) {
  (void)state;
  /* a straight cubic with uneven speed, heading 0.7 rad */
  const double f[4] = {0.0, 0.1, 2.2, 3.0}, dir = 0.7;
  double cp[8];
  for (int i = 0; i < 4; i++) {
    cp[2 * i] = 1.0 + f[i] * cos(dir);
    cp[2 * i + 1] = 2.0 + f[i] * sin(dir);
  }
  const double kn[8] = {0, 0, 0, 0, 1, 1, 1, 1};
  km_curve c;
  make_curve(&c, 3, 4, kn, cp, NULL, false);
  km_signature sig;
  sign(&c, 1e-10, &sig);
  assert_close(sig.length, 3.0, 3e-12);
  assert_false(sig.closed);
  assert_ncorners(&sig, 0);
  assert_close(sig.turning, 0.0, 1e-12);
  assert_close(sig.angle, dir, 1e-12);
  assert_close(sig.start[0], 1.0, 1e-15);
  assert_close(sig.start[1], 2.0, 1e-15);
  for (int i = 0; i <= 50; i++) {
    assert_close(kappa_at(&sig, 3.0 * i / 50.0), 0.0, 1e-12);
    assert_close(km_signature_theta(&sig, 3.0 * i / 50.0), dir, 1e-12);
  }
  km_signature_free(&sig);
  km_curve_free(&c);
}

/* true when x is within tol of one of the knots of f */
static bool has_knot_near(const km_fn *f, double x, double tol) {
  for (size_t i = 0; i < f->n + (size_t)f->degree + 1; i++)
    if (fabs(f->knots[i] - x) <= tol) return true;
  return false;
}

static void kappa_breakpoints_include_arc_length_images_of_knots(void **state) {
  (void)state;
  /* rounded rectangle: kappa jumps between 0 and 1/r at known s */
  const double W = 7.0, H = 4.0, r = 1.25;
  double kn[20], cp[34], wt[17];
  tu_rounded_rect(-2.0, 0.5, W, H, r, kn, cp, wt);
  km_curve c;
  make_curve(&c, 2, 17, kn, cp, wt, true);
  km_signature sig;
  sign(&c, 1e-10, &sig);
  const double arc = M_PI * r / 2;
  const double seg[8] = {W - 2 * r, arc, H - 2 * r, arc,
                         W - 2 * r, arc, H - 2 * r, arc};
  double L = 0;
  for (int i = 0; i < 8; i++) L += seg[i];
  assert_close(sig.length, L, 1e-12 * L);
  assert_ncorners(&sig, 0);
  assert_close(sig.turning, 2 * M_PI, 1e-9);
  assert_close(tu_wrap(sig.angle), 0.0, 1e-12);
  double s0 = 0;
  for (int i = 0; i < 8; i++) {
    double s1 = s0 + seg[i], want = (i % 2) ? 1.0 / r : 0.0;
    if (i > 0) assert_true(has_knot_near(&sig.kappa, s0, 1e-9 * L));
    /* kappa is exact inside each piece, right up to its ends */
    for (int k = 0; k <= 20; k++) {
      double s = s0 + seg[i] * (1e-9 + (1 - 2e-9) * k / 20.0);
      assert_close(kappa_at(&sig, s), want, 1e-8 / r);
    }
    s0 = s1;
  }
  km_signature_free(&sig);
  km_curve_free(&c);

  /* a generic cubic: breakpoints at length_between(t0, knot) */
  uint64_t seed = 3;
  double gk[14], gp[20];
  tu_gentle_polygon(&seed, 10, 0, 0, 0.3, 1.0, 0.4, gp);
  tu_clamped_knots(&seed, 3, 10, 0.6, gk);
  assert_true(tu_is_regular(3, 10, gk, gp));
  make_curve(&c, 3, 10, gk, gp, NULL, false);
  sign(&c, 1e-8, &sig);
  for (int i = 4; i < 10; i++) {
    double s = km_curve_length_between(&c, 0.0, gk[i]);
    assert_true(has_knot_near(&sig.kappa, s, 1e-9 * sig.length));
  }
  km_signature_free(&sig);
  km_curve_free(&c);
}

/* Max |theta_a - theta_b| and |kappa_a - kappa_b| over many s (the lengths
 * must agree first). */
static void assert_same_signature(const km_signature *a, const km_signature *b,
                                  double theta_tol, double kappa_tol) {
  assert_close(b->length, a->length, 1e-12 * a->length);
  assert_close(b->start[0], a->start[0], 1e-12 * a->length);
  assert_close(b->start[1], a->start[1], 1e-12 * a->length);
  assert_close(tu_wrap(b->angle - a->angle), 0.0, 1e-12);
  assert_ncorners(b, a->ncorners);
  for (size_t i = 0; i < a->ncorners; i++) {
    assert_close(b->corners[i].s, a->corners[i].s, 1e-10 * a->length);
    assert_close(b->corners[i].turn, a->corners[i].turn, 1e-10);
  }
  assert_close(b->turning, a->turning, theta_tol);
  for (int i = 0; i <= 1000; i++) {
    double s = a->length * (i + 0.5) / 1001.0;
    assert_close(km_signature_theta(b, s), km_signature_theta(a, s), theta_tol);
    assert_close(kappa_at(b, s), kappa_at(a, s), kappa_tol);
  }
}

static void knot_insertion_and_elevation_keep_the_signature(void **state) {
  (void)state;
  uint64_t seed = 11;
  double gk[12], gp[16];
  tu_gentle_polygon(&seed, 8, 1, 2, -0.5, 1.0, 0.45, gp);
  tu_clamped_knots(&seed, 3, 8, 0.5, gk);
  assert_true(tu_is_regular(3, 8, gk, gp));
  km_curve c, d;
  km_error err;
  make_curve(&c, 3, 8, gk, gp, NULL, false);
  km_signature ref, sig;
  sign(&c, 1e-10, &ref);
  const double kt = km_fn_max_abs(&ref.kappa) * 1e-6;

  /* a new knot once, and an existing knot raised to full multiplicity
   * (a C0 knot the curve crosses smoothly: no corner) */
  km_curve_init(&d);
  assert_status(km_curve_insert_knot(&d, &c, 0.37 * gk[11], 1, &err), KM_OK);
  sign(&d, 1e-10, &sig);
  assert_same_signature(&ref, &sig, 1e-8, kt);
  km_signature_free(&sig);
  km_curve_free(&d);

  km_curve_init(&d);
  assert_status(km_curve_insert_knot(&d, &c, gk[6], 2, &err), KM_OK);
  sign(&d, 1e-10, &sig);
  assert_same_signature(&ref, &sig, 1e-8, kt);
  km_signature_free(&sig);
  km_curve_free(&d);

  for (int times = 1; times <= 2; times++) {
    km_curve_init(&d);
    assert_status(km_curve_elevate(&d, &c, times, &err), KM_OK);
    assert_int_equal(d.degree, 3 + times);
    sign(&d, 1e-10, &sig);
    assert_same_signature(&ref, &sig, 1e-8, kt);
    km_signature_free(&sig);
    km_curve_free(&d);
  }
  km_signature_free(&ref);
  km_curve_free(&c);
}

/* Speed |B'(u)| of a cubic Bezier with control points p[8]. */
static double bezier_speed(double u, const void *ctx) {
  const double *p = ctx;
  double v = 1 - u, d[2];
  for (int k = 0; k < 2; k++)
    d[k] = 3 * (v * v * (p[2 + k] - p[k]) + 2 * u * v * (p[4 + k] - p[2 + k]) +
                u * u * (p[6 + k] - p[4 + k]));
  return hypot(d[0], d[1]);
}

static void
repeated_first_control_point_gives_the_traced_signature(void **state) {
  (void)state;
  /* D(u) = cubic Bezier (0,0), (0,0), (2,1), (3,3): D'(u) = 3u (4 - 3u, 2),
   * zero at u = 0 but the direction (4 - 3u, 2) never vanishes: the trace
   * is regular, with tangent angle atan2(2, 4 - 3u), and its curvature
   * grows like 1/sqrt(s) at the start. */
  const double P[8] = {0, 0, 0, 0, 2, 1, 3, 3};
  const double kn[8] = {0, 0, 0, 0, 1, 1, 1, 1};
  km_curve c;
  make_curve(&c, 3, 4, kn, P, NULL, false);
  km_signature sig;
  sign(&c, 1e-10, &sig);
  const double L = tu_integrate(bezier_speed, P, 0.0, 1.0, 64);
  assert_close(sig.length, L, 1e-12 * L);
  assert_ncorners(&sig, 0);
  assert_close(sig.angle, atan2(2.0, 4.0), 1e-9);
  assert_close(sig.turning, atan2(2.0, 1.0) - atan2(2.0, 4.0), 1e-8);
  for (int i = 1; i <= 100; i++) {
    double u = i / 100.0, s = tu_integrate(bezier_speed, P, 0.0, u, 32);
    assert_close(km_signature_theta(&sig, s), atan2(2.0, 4.0 - 3.0 * u), 1e-8);
  }

  /* the same trace without the repeated point: the right half u in [0.5,1]
   * (de Casteljau) is a regular cubic, and its signature is the tail of
   * the whole one */
  double q[8], b[8];
  for (int k = 0; k < 2; k++) {
    for (int i = 0; i < 4; i++) q[2 * i + k] = P[2 * i + k];
    double m01 = 0.5 * (q[k] + q[2 + k]), m12 = 0.5 * (q[2 + k] + q[4 + k]),
           m23 = 0.5 * (q[4 + k] + q[6 + k]);
    double m012 = 0.5 * (m01 + m12), m123 = 0.5 * (m12 + m23);
    b[k] = 0.5 * (m012 + m123);
    b[2 + k] = m123;
    b[4 + k] = m23;
    b[6 + k] = q[6 + k];
  }
  km_curve half;
  make_curve(&half, 3, 4, kn, b, NULL, false);
  km_signature hs;
  sign(&half, 1e-10, &hs);
  const double s0 = tu_integrate(bezier_speed, P, 0.0, 0.5, 32);
  assert_close(hs.length, L - s0, 1e-12 * L);
  for (int i = 0; i <= 200; i++) {
    double s = hs.length * i / 200.0;
    assert_close(km_signature_theta(&hs, s), km_signature_theta(&sig, s0 + s),
                 1e-8);
    assert_close(kappa_at(&hs, s), kappa_at(&sig, s0 + s),
                 1e-6 * km_fn_max_abs(&hs.kappa));
  }
  km_signature_free(&hs);
  km_curve_free(&half);
  km_signature_free(&sig);
  km_curve_free(&c);
}

static void degenerate_leg_at_a_join_is_smooth_or_a_corner(void **state) {
  (void)state;
  /* piece 1 is regular and ends heading (1, 1); piece 2 repeats its first
   * control point, so its tangent at the join is the direction of P2 - P0:
   * along (1, 1) the join is smooth, along (1, 0) it hides a corner of
   * -pi/4 */
  const double kn[11] = {0, 0, 0, 0, 1, 1, 1, 2, 2, 2, 2};
  const double p1[8] = {0, 0, 1, 0, 2, 0.5, 3, 1.5};
  const double s1 = tu_integrate(bezier_speed, p1, 0.0, 1.0, 64);
  for (int variant = 0; variant < 2; variant++) {
    double cp[14] = {0, 0, 1, 0, 2, 0.5, 3, 1.5, 3, 1.5, 0, 0, 6, 3};
    if (variant == 0) {
      cp[10] = 4.2;
      cp[11] = 2.7;
    } else {
      cp[10] = 4.5;
      cp[11] = 1.5;
    }
    km_curve c;
    make_curve(&c, 3, 7, kn, cp, NULL, false);
    km_signature sig;
    sign(&c, 1e-10, &sig);
    const double p2[8] = {3, 1.5, 3, 1.5, cp[10], cp[11], 6, 3};
    const double L = s1 + tu_integrate(bezier_speed, p2, 0.0, 1.0, 64);
    assert_close(sig.length, L, 1e-12 * L);
    if (variant == 0) {
      assert_ncorners(&sig, 0);
      assert_close(km_signature_theta(&sig, s1 - 1e-9 * L), M_PI / 4, 1e-6);
      assert_close(km_signature_theta(&sig, s1), M_PI / 4, 1e-6);
    } else {
      assert_ncorners(&sig, 1);
      assert_close(sig.corners[0].s, s1, 1e-9 * L);
      assert_close(sig.corners[0].turn, -M_PI / 4, 1e-9);
      assert_close(km_signature_theta(&sig, s1 - 1e-9 * L), M_PI / 4, 1e-6);
      /* right at the corner (its own s: the step must not be probed a
       * rounding error before it) the tangent has turned */
      assert_close(km_signature_theta(&sig, sig.corners[0].s), 0.0, 1e-6);
    }
    /* tangent at the end: (6, 3) - P2 */
    assert_close(
        tu_wrap(km_signature_theta(&sig, L) - atan2(3 - cp[11], 6 - cp[10])),
        0.0, 1e-8);
    km_signature_free(&sig);
    km_curve_free(&c);
  }
}

static void rigid_motion_keeps_curvature_and_corners(void **state) {
  (void)state;
  /* two cubic pieces meeting at an angle, then rotated and translated */
  uint64_t seed = 5;
  double cp[14], kn[11] = {0, 0, 0, 0, 1.5, 1.5, 1.5, 3, 3, 3, 3};
  tu_gentle_polygon(&seed, 4, 0, 0, 0.2, 1.0, 0.5, cp);
  /* second piece leaves the join at a 1 rad turn */
  double dir = atan2(cp[7] - cp[5], cp[6] - cp[4]) + 1.0;
  tu_gentle_polygon(&seed, 4, cp[6], cp[7], dir, 1.3, 0.4, cp + 6);
  km_curve c, d;
  make_curve(&c, 3, 7, kn, cp, NULL, false);
  const double rot = 2.2, tx = 5.0, ty = -3.0;
  double rp[14];
  for (int i = 0; i < 7; i++) {
    rp[2 * i] = cos(rot) * cp[2 * i] - sin(rot) * cp[2 * i + 1] + tx;
    rp[2 * i + 1] = sin(rot) * cp[2 * i] + cos(rot) * cp[2 * i + 1] + ty;
  }
  make_curve(&d, 3, 7, kn, rp, NULL, false);
  km_signature a, b;
  sign(&c, 1e-10, &a);
  sign(&d, 1e-10, &b);
  assert_ncorners(&a, 1);
  assert_close(a.corners[0].turn, 1.0, 1e-9);
  assert_close(b.length, a.length, 1e-12 * a.length);
  assert_close(b.start[0], tx, 1e-12);
  assert_close(b.start[1], ty, 1e-12);
  assert_close(tu_wrap(b.angle - a.angle - rot), 0.0, 1e-12);
  assert_ncorners(&b, a.ncorners);
  assert_close(b.corners[0].s, a.corners[0].s, 1e-10 * a.length);
  assert_close(b.corners[0].turn, a.corners[0].turn, 1e-10);
  assert_close(b.turning, a.turning, 1e-8);
  const double kt = 1e-6 * km_fn_max_abs(&a.kappa);
  for (int i = 0; i <= 1000; i++) {
    double s = a.length * (i + 0.5) / 1001.0;
    assert_close(kappa_at(&b, s), kappa_at(&a, s), kt);
    assert_close(
        tu_wrap(km_signature_theta(&b, s) - km_signature_theta(&a, s) - rot),
        0.0, 1e-8);
  }
  km_signature_free(&a);
  km_signature_free(&b);
  km_curve_free(&c);
  km_curve_free(&d);
}

static void cusp_is_refused_with_its_parameter(void **state) {
  (void)state;
  /* C(t) = ((t - t0)^2, (t - t0)^3): C'(t0) = 0 and C'/|C'| goes from
   * (-1, 0) to (1, 0): the tangent reverses at t0 */
  struct {
    double t0, lo, hi, k1, k2;
  } cases[2] = {{0.5, 0.0, 1.0, -1, -1}, {3.3, 2.0, 6.0, 2.7, 4.5}};
  for (int ci = 0; ci < 2; ci++) {
    double t0 = cases[ci].t0;
    double px[4] = {t0 * t0, -2 * t0, 1, 0};
    double py[4] = {-t0 * t0 * t0, 3 * t0 * t0, -3 * t0, 1};
    double kn[10];
    size_t nk = 0;
    for (int i = 0; i < 4; i++) kn[nk++] = cases[ci].lo;
    if (cases[ci].k1 > 0) kn[nk++] = cases[ci].k1;
    if (cases[ci].k2 > 0) kn[nk++] = cases[ci].k2;
    for (int i = 0; i < 4; i++) kn[nk++] = cases[ci].hi;
    size_t n = nk - 4;
    double cp[12];
    tu_poly_to_bspline(px, 3, 3, kn, n, cp, 2);
    tu_poly_to_bspline(py, 3, 3, kn, n, cp + 1, 2);
    km_curve c;
    make_curve(&c, 3, n, kn, cp, NULL, false);
    km_signature sig;
    km_error err;
    km_signature_init(&sig);
    assert_status(km_signature_compute(&c, 0.0, &sig, &err), KM_ECUSP);
    assert_int_equal(err.code, KM_ECUSP);
    assert_close(err.param, t0, 1e-4 * (cases[ci].hi - cases[ci].lo));
    assert_null(sig.corners);
    km_curve_free(&c);
  }

  /* a polyline that turns back on itself: the tangent reverses at t = 1 */
  const double pk[5] = {0, 0, 1, 2, 2}, pp[6] = {0, 0, 2, 0, 1, 0};
  km_curve c;
  make_curve(&c, 1, 3, pk, pp, NULL, false);
  km_signature sig;
  km_error err;
  km_signature_init(&sig);
  assert_status(km_signature_compute(&c, 0.0, &sig, &err), KM_ECUSP);
  assert_close(err.param, 1.0, 1e-9);
  km_curve_free(&c);
}

/* -status of the signature of the curve in ctx (for tu_run_bounded). */
static int signature_status(void *ctx) {
  km_signature sig;
  km_error err;
  km_signature_init(&sig);
  km_status st = km_signature_compute(ctx, 0.0, &sig, &err);
  if (st == KM_OK) km_signature_free(&sig);
  return -(int)st;
}

static void zero_length_curve_is_degenerate(void **state) {
  (void)state;
  const double kn[8] = {0, 0, 0, 0, 1, 1, 1, 1};
  const double cp[8] = {2, 3, 2, 3, 2, 3, 2, 3};
  km_curve c;
  make_curve(&c, 3, 4, kn, cp, NULL, false);
  /* bounded: a failure to stop must fail this test, not stall the suite */
  int r = tu_run_bounded(signature_status, &c, 5);
  if (r < 0)
    print_error("signature of a point: %s\n",
                r == -1 ? "did not finish in 5 s" : "crashed");
  assert_int_equal(r, -KM_EDEGENERATE);
  km_curve_free(&c);

  /* a degree-1 segment of zero length */
  const double k1[4] = {0, 0, 1, 1}, p1[4] = {-1, 5, -1, 5};
  make_curve(&c, 1, 2, k1, p1, NULL, false);
  r = tu_run_bounded(signature_status, &c, 5);
  assert_int_equal(r, -KM_EDEGENERATE);
  km_curve_free(&c);

  /* an empty (init'ed, never created) curve is an error, not a crash */
  km_curve_init(&c);
  r = tu_run_bounded(signature_status, &c, 5);
  assert_true(r > 0);
}

/* km_curve_create must fail with `want`, naming `field` (unless field is
 * negative) and `index` (unless index < -1), and leave out untouched. */
static void expect_create_error(int p, size_t n, const double *kn,
                                const double *cp, const double *w, bool closed,
                                km_status want, int field, long index) {
  km_curve c;
  km_error err;
  km_curve_init(&c);
  memset(&err, 0, sizeof err);
  assert_status(km_curve_create(&c, p, n, kn, cp, w, closed, &err), want);
  assert_int_equal(err.code, want);
  if (field >= 0) assert_int_equal(err.field, field);
  if (index >= -1) assert_int_equal(err.index, index);
  assert_true(err.message[0] != '\0');
  assert_null(c.cp);
  assert_null(c.knots);
}

static void curve_create_rejects_bad_input_naming_the_field(void **state) {
  (void)state;
  const double kn[9] = {0, 0, 0, 0, 0.5, 1, 1, 1, 1};
  const double cp[12] = {0, 0, 1, 2, 3, 3, 4, 1, 5, 0, 6, 1};
  const double w[5] = {1, 1, 1, 1, 1};
  /* sanity: the unmodified input is valid */
  km_curve ok;
  make_curve(&ok, 3, 5, kn, cp, w, false);
  km_curve_free(&ok);

  /* decreasing knots: the element smaller than its predecessor */
  const double dec[9] = {0, 0, 0, 0, -0.5, 1, 1, 1, 1};
  expect_create_error(3, 5, dec, cp, NULL, false, KM_EKNOTS, KM_FIELD_KNOTS, 4);
  const double dec6[10] = {0, 0, 0, 0, 0.5, 0.4, 1, 1, 1, 1};
  expect_create_error(3, 6, dec6, cp, NULL, false, KM_EKNOTS, KM_FIELD_KNOTS,
                      5);
  expect_create_error(0, 5, kn, cp, NULL, false, KM_EDEGREE, KM_FIELD_DEGREE,
                      -2);
  expect_create_error(20, 5, kn, cp, NULL, false, KM_EDEGREE, KM_FIELD_DEGREE,
                      -2);
  /* the knot count is n + degree + 1, so a wrong count shows as too few
   * control points for the degree (the contract layer checks array
   * lengths, which the core never sees) */
  expect_create_error(3, 3, kn, cp, NULL, false, KM_ECOUNT, -1, -2);
  expect_create_error(3, 0, kn, cp, NULL, false, KM_ECOUNT, -1, -2);
  double bad[10];
  memcpy(bad, cp, sizeof bad);
  bad[5] = NAN;
  expect_create_error(3, 5, kn, bad, NULL, false, KM_ENONFINITE,
                      KM_FIELD_CONTROL_POINTS, 2);
  bad[5] = INFINITY;
  expect_create_error(3, 5, kn, bad, NULL, false, KM_ENONFINITE,
                      KM_FIELD_CONTROL_POINTS, 2);
  bad[5] = 1e300;
  expect_create_error(3, 5, kn, bad, NULL, false, KM_ERANGE,
                      KM_FIELD_CONTROL_POINTS, 2);
  double nk[9];
  memcpy(nk, kn, sizeof nk);
  nk[4] = NAN;
  expect_create_error(3, 5, nk, cp, NULL, false, KM_ENONFINITE, KM_FIELD_KNOTS,
                      4);
  double ww[5] = {1, 1, 0, 1, 1};
  expect_create_error(3, 5, kn, cp, ww, false, KM_EWEIGHT, KM_FIELD_WEIGHTS, 2);
  ww[2] = 1;
  ww[3] = -1;
  expect_create_error(3, 5, kn, cp, ww, false, KM_EWEIGHT, KM_FIELD_WEIGHTS, 3);
  ww[3] = NAN;
  expect_create_error(3, 5, kn, cp, ww, false, KM_ENONFINITE, KM_FIELD_WEIGHTS,
                      3);
  /* closed, but the last point is not the first */
  expect_create_error(3, 5, kn, cp, NULL, true, KM_ECLOSED, -1, -2);
  /* not clamped; interior multiplicity above the degree; empty domain */
  const double unc[9] = {0, 0, 0, 0.1, 0.5, 1, 1, 1, 1};
  expect_create_error(3, 5, unc, cp, NULL, false, KM_EKNOTS, KM_FIELD_KNOTS,
                      -2);
  const double m4[10] = {0, 0, 0, 0.5, 0.5, 0.5, 0.5, 1, 1, 1};
  const double cp7[14] = {0, 0, 1, 2, 3, 3, 4, 1, 5, 0, 6, 1, 7, 0};
  expect_create_error(2, 7, m4, cp7, NULL, false, KM_EKNOTS, KM_FIELD_KNOTS,
                      -2);
  const double flat[9] = {1, 1, 1, 1, 1, 1, 1, 1, 1};
  expect_create_error(3, 5, flat, cp, NULL, false, KM_EKNOTS, KM_FIELD_KNOTS,
                      -2);
}

/* Signature that must succeed at the absolute tolerance tol. */
static void sign_abs(const km_curve *c, double tol, km_signature *sig) {
  km_error err;
  km_signature_init(sig);
  km_status st = km_signature_compute(c, tol, sig, &err);
  if (st != KM_OK) print_error("signature failed: %s\n", err.message);
  assert_status(st, KM_OK);
}

/* The exact curve's end point, from the signature alone. */
static void signature_end(const km_signature *sig, double end[2]) {
  double th;
  assert_status(km_signature_point(sig, sig->length, end, &th), KM_OK);
}

static void sharp_turn_close_to_the_end_has_its_exact_length(void **state) {
  (void)state;
  /* C(t) = sigma (t - t^2/2, d t), a quadratic Bezier: |C'| = sigma
   * sqrt((1-t)^2 + d^2), so the curve runs along x and turns up by nearly
   * pi/2 within a length of about sigma d at its end, and
   *   L = sigma (sqrt(1 + d^2) + d^2 asinh(1/d)) / 2.
   * The speed's near-zero beside the end is a feature far smaller than the
   * integral: an 8- against 16-point estimate takes its slow convergence
   * for rounding (a length 4e-8 too short at d = 1e-4). */
  const double kn[6] = {0, 0, 0, 1, 1, 1};
  const double ds[2] = {1e-4, 1e-5}, sigmas[3] = {1.0, 1e-15, 1e12};
  for (int i = 0; i < 2; i++) {
    for (int j = 0; j < 3; j++) {
      double d = ds[i], sg = sigmas[j];
      double cp[6] = {0, 0, 0.5 * sg, 0.5 * d * sg, 0.5 * sg, d * sg};
      double L = sg * 0.5 * (sqrt(1 + d * d) + d * d * asinh(1 / d));
      km_curve c;
      make_curve(&c, 2, 3, kn, cp, NULL, false);
      assert_close(km_curve_length(&c), L, 1e-14 * L);
      km_signature sig;
      sign_abs(&c, 1e-12 * L, &sig);
      assert_close(sig.length, L, 1e-14 * L);
      assert_close(sig.angle, atan(d), 1e-12);
      assert_close(sig.turning, M_PI / 2 - atan(d), 1e-12);
      double end[2];
      signature_end(&sig, end);
      assert_close(end[0], 0.5 * sg, 1e-12 * L);
      assert_close(end[1], d * sg, 1e-12 * L);
      km_signature_free(&sig);
      km_curve_free(&c);
    }
  }
}

static void
high_order_degenerate_ends_take_the_first_distinct_point(void **state) {
  (void)state;
  /* A degree-9 Bezier R R R R S S T T T T: C - R ~ (S - R) u^4 at the
   * start and C - T ~ (S - T) (1-u)^4 at the end, and C' is a positive
   * combination of S - R and T - S, so the tangent turns monotonically
   * from the direction of S - R to that of T - S (173 degrees here, never
   * reversing). The first three derivatives vanish at both ends, and at
   * coordinates near 1e15 a chord short enough to stand for the tangent is
   * lost in rounding. */
  const double R[2] = {-894895856175555.1, -975982298534599.8};
  const double S[2] = {484367133066834.56, 745204853368963.1};
  const double T[2] = {-414511328823758.25, -700495917211642.6};
  double cp[20], kn[20];
  for (int i = 0; i < 10; i++) {
    const double *P = i < 4 ? R : i < 6 ? S : T;
    cp[2 * i] = P[0];
    cp[2 * i + 1] = P[1];
    kn[i] = 0.0;
    kn[10 + i] = 1.0;
  }
  km_curve c;
  make_curve(&c, 9, 10, kn, cp, NULL, false);
  double L = km_curve_length(&c);
  km_signature sig;
  sign_abs(&c, 1e-13 * L, &sig);
  assert_close(tu_wrap(sig.angle - atan2(S[1] - R[1], S[0] - R[0])), 0, 1e-12);
  assert_close(sig.turning,
               tu_turn(S[0] - R[0], S[1] - R[1], T[0] - S[0], T[1] - S[1]),
               1e-9);
  assert_ncorners(&sig, 0);
  double end[2];
  signature_end(&sig, end);
  assert_close(end[0], T[0], 1e-12 * L);
  assert_close(end[1], T[1], 1e-12 * L);
  km_signature_free(&sig);
  km_curve_free(&c);

  /* C(t) = (t^4, t^5) on [0, 1] as a degree-9 Bezier: its tangent starts
   * along +x exactly, ends at angle atan(5/4), and
   *   L = [(2/5) u^(5/2) - (32/3) u^(3/2)] / 1250, u = 16 + 25 t^2. */
  const double px[6] = {0, 0, 0, 0, 1, 0}, py[6] = {0, 0, 0, 0, 0, 1};
  tu_poly_to_bspline(px, 5, 9, kn, 10, cp, 2);
  tu_poly_to_bspline(py, 5, 9, kn, 10, cp + 1, 2);
  make_curve(&c, 9, 10, kn, cp, NULL, false);
  double u1 = 41, u0 = 16;
  L = (0.4 * pow(u1, 2.5) - 32.0 / 3 * pow(u1, 1.5) -
       (0.4 * pow(u0, 2.5) - 32.0 / 3 * pow(u0, 1.5))) /
      1250;
  sign_abs(&c, 1e-11 * L, &sig);
  assert_close(sig.length, L, 1e-14 * L);
  assert_close(sig.angle, 0.0, 1e-15);
  assert_close(sig.turning, atan(1.25), 1e-12);
  signature_end(&sig, end);
  assert_close(end[0], 1.0, 1e-11 * L);
  assert_close(end[1], 1.0, 1e-11 * L);
  km_signature_free(&sig);
  km_curve_free(&c);
}

static void closed_rational_curve_with_a_tiny_span_closes(void **state) {
  (void)state;
  /* A closed rational cubic whose first span is 1e-9 wide in t and ends in
   * a nearly degenerate leg (weights 0.01 and 10): the tangent turns by
   * 2.68 rad there within a length below 1e-15 of the curve's, so the turn
   * is a corner that must sit exactly on the span's end. A closed curve
   * ends where it starts and, being simple, turns by 2 pi. */
  const double kn[10] = {0,           0,          0,           0,
                         1e-9,        1e-9,       1.000000001, 1.000000001,
                         1.000000001, 1.000000001};
  const double cp[12] = {
      -0.0097656214236667427, -0.00030289158464942399, 0.00016800183108262701,
      -0.0027754634927901123, 0.0046691081101701368,   0.0002986190585183479,
      -0.0077230487525749604, -0.0014888227664606702,  -0.0083865110246433214,
      0.0026475928892957957,  -0.0097656214236667427,  -0.00030289158464942399};
  const double w[6] = {0.01, 0.01, 0.01, 0.01, 10, 10};
  km_curve c;
  make_curve(&c, 3, 6, kn, cp, w, true);
  const double rel[2] = {1e-5, 1e-9};
  for (int i = 0; i < 2; i++) {
    km_signature sig;
    sign(&c, rel[i], &sig);
    double tol = rel[i] * sig.length, end[2];
    assert_close(sig.turning, 2 * M_PI, 1e-9);
    signature_end(&sig, end);
    assert_close(end[0], cp[0], tol);
    assert_close(end[1], cp[1], tol);
    /* every corner lies on a breakpoint of kappa */
    for (size_t k = 0; k < sig.ncorners; k++) {
      bool on = false;
      for (size_t j = 0; j < sig.kappa.n + (size_t)sig.kappa.degree + 1; j++)
        on = on || sig.kappa.knots[j] == sig.corners[k].s;
      assert_true(on);
    }
    km_signature_free(&sig);
  }
  km_curve_free(&c);
}

/* km_signature_compute on ctx at tolerance 1e-12: its status, negated. */
static int tight_signature_status(void *ctx) {
  km_signature sig;
  km_error err;
  km_signature_init(&sig);
  km_status st = km_signature_compute(ctx, 1e-12, &sig, &err);
  if (st == KM_OK) km_signature_free(&sig);
  return -(int)st;
}

static void curve_far_from_the_origin_keeps_to_its_rounding(void **state) {
  (void)state;
  /* A unit circle about (1e6, 1e6): its points are known to about 1e-10,
   * so a tolerance of 1e-12 is raised to the curve's rounding instead of
   * refining into noise; length 2 pi, curvature 1, turning 2 pi. */
  double kn[12], cp[18], w[9];
  tu_circle_nurbs(1e6, 1e6, 1.0, 1, kn, cp, w);
  km_curve c;
  make_curve(&c, 2, 9, kn, cp, w, true);
  assert_int_equal(tu_run_bounded(tight_signature_status, &c, 5), 0);
  km_signature sig;
  sign_abs(&c, 1e-12, &sig);
  assert_close(sig.length, 2 * M_PI, 1e-8);
  assert_close(sig.turning, 2 * M_PI, 1e-9);
  for (int i = 0; i <= 100; i++)
    assert_close(km_fn_value(&sig.kappa, sig.length * i / 100), 1.0, 1e-3);
  double end[2];
  signature_end(&sig, end);
  assert_close(end[0], cp[0], 1e-7);
  assert_close(end[1], cp[1], 1e-7);
  km_signature_free(&sig);
  km_curve_free(&c);

  /* A circle of radius 1e-6 there: its shape is below the rounding of its
   * coordinates even at the default tolerance, and it is refused */
  tu_circle_nurbs(1e6, 1e6, 1e-6, 1, kn, cp, w);
  make_curve(&c, 2, 9, kn, cp, w, true);
  assert_int_equal(tu_run_bounded(tight_signature_status, &c, 5), -KM_ERANGE);
  km_error err;
  km_signature_init(&sig);
  assert_status(km_signature_compute(&c, 0.0, &sig, &err), KM_ERANGE);
  assert_int_equal(err.field, KM_FIELD_CONTROL_POINTS);
  km_curve_free(&c);
}

static void spans_below_their_rounding_are_traced_or_refused(void **state) {
  (void)state;
  /* A polyline at (1e9, 1e9): 400 legs of 1e-6 along +x, each shorter
   * than the rounding of its own speed there (8 ulps of 1e9), then one of
   * 4e-4 up. Asked for 1e-4, a quarter of either stretch, a signature
   * must end at the last point within that, or refuse: taking every short
   * leg for a point leaves a line straight up, 4e-4 off the end. */
  enum { SHORT = 400, N = SHORT + 2 };
  double cp[2 * N], kn[N + 2];
  for (int i = 0; i <= SHORT; i++) {
    cp[2 * i] = 1e9 + 1e-6 * i;
    cp[2 * i + 1] = 1e9;
  }
  cp[2 * (N - 1)] = cp[2 * SHORT];
  cp[2 * (N - 1) + 1] = 1e9 + 4e-4;
  kn[0] = 0;
  for (int i = 1; i <= N; i++) kn[i] = i - 1;
  kn[N + 1] = N - 1;
  km_curve c;
  make_curve(&c, 1, N, kn, cp, NULL, false);
  const double tol = 1e-4;
  km_signature sig;
  km_error err;
  km_signature_init(&sig);
  km_status st = km_signature_compute(&c, tol, &sig, &err);
  if (st == KM_OK) {
    double end[2];
    signature_end(&sig, end);
    assert_true(hypot(end[0] - cp[2 * (N - 1)], end[1] - cp[2 * N - 1]) <= tol);
    km_signature_free(&sig);
  } else {
    assert_status(st, KM_ERANGE);
    assert_int_equal(err.field, KM_FIELD_CONTROL_POINTS);
  }
  km_curve_free(&c);
}

static void
closed_curve_ending_below_resolution_turns_whole_turns(void **state) {
  (void)state;
  /* A closed rational cubic 0.01 across at (1e9, 1e9), weights over three
   * decades: its last piece ends in a stretch below the resolution of its
   * directions, whose turn was handed on to a next piece that never came,
   * and the signature turned by -0.486 rad. A closed curve's tangent
   * comes back to itself: the turning is a whole number of turns. */
  const double cp[12] = {
      999999999.9900002,  1000000000.0098441, 999999999.9911841,
      1000000000.0039104, 1000000000.0087808, 1000000000.0029039,
      1000000000.0071814, 1000000000.00604,   999999999.9923563,
      999999999.9920048,  999999999.9900002,  1000000000.0098441};
  const double w[6] = {
      1, 3.1622776601683795, 0.31622776601683794, 0.03162277660168379, 0.01,
      10};
  const double kn[10] = {0.0, 0.0, 0.0, 0.0, 1.0, 3.0, 4.0, 4.0, 4.0, 4.0};
  km_curve c;
  make_curve(&c, 3, 6, kn, cp, w, true);
  km_signature sig;
  km_error err;
  km_signature_init(&sig);
  km_status st = km_signature_compute(&c, 1e-4, &sig, &err);
  if (st == KM_OK) {
    double turns = sig.turning / (2 * M_PI);
    assert_close(turns, nearbyint(turns), 1e-9);
    km_signature_free(&sig);
  } else {
    assert_status(st, KM_ERANGE);
  }
  km_curve_free(&c);
}

/* An edge of a polygon has one direction, computed exactly the same at
 * every node, so theta is constant on it and kappa exactly zero: not 1e-13
 * of noise from the fit, which frames would carry as curvature between
 * corners. A pentagon at arbitrary angles, a rotated square and an L. */
static void polygon_edges_have_exactly_zero_curvature(void **state) {
  (void)state;
  const double pent[12] = {0.3,  -1.1, 1.7,  -0.4, 1.2, 1.3,
                           -0.6, 0.9,  -0.8, -0.7, 0.3, -1.1};
  const double kp[8] = {0, 0, 1, 2, 3, 4, 5, 5};
  double sq[10], ksq[7] = {0, 0, 1, 2, 3, 4, 4};
  for (int i = 0; i < 5; i++) {
    double a = 0.37 + M_PI / 2 * (i % 4);
    sq[2 * i] = 3.0 + 2.5 * cos(a);
    sq[2 * i + 1] = -7.0 + 2.5 * sin(a);
  }
  const double ell[16] = {1.5, 0, 3, 0, 3, 1, 2, 1, 2, 2, 0, 2, 0, 0, 1.5, 0};
  const double kl[10] = {0, 0, 1.5, 2.5, 3.5, 4.5, 6.5, 8.5, 10, 10};
  const double *pts[3] = {pent, sq, ell}, *kns[3] = {kp, ksq, kl};
  const size_t ns[3] = {6, 5, 8};
  for (int k = 0; k < 3; k++) {
    km_curve c;
    make_curve(&c, 1, ns[k], kns[k], pts[k], NULL, true);
    km_signature sig;
    sign(&c, 0, &sig);
    for (size_t i = 0; i < sig.kappa.n; i++) {
      if (sig.kappa.coef[i] != 0.0)
        print_error("polygon %d: kappa coefficient %zu is %.3g\n", k, i,
                    sig.kappa.coef[i]);
      assert_true(sig.kappa.coef[i] == 0.0);
    }
    assert_close(sig.turning, 2 * M_PI, 1e-12);
    km_signature_free(&sig);
    km_curve_free(&c);
  }
}

/* Two unit edges meeting at a knot with a turn of delta = 4e-12 rad, below
 * what reads as rounding (1e-11): at a tolerance of 1e-13 of the length it
 * moves the end by delta (4e-12, twenty times the tolerance), so it must
 * be kept - a turn dropped at a knot moved every later point (a closed
 * degree-9 curve ended 1.5e-12 of its length off). At the default
 * tolerance it is absorbed by an edge and no corner is reported. The end
 * is (1 + cos delta, sin delta) exactly. */
static void
turn_below_rounding_at_a_knot_counts_at_tight_tolerance(void **state) {
  (void)state;
  const double delta = 4e-12;
  const double kn[5] = {0, 0, 1, 2, 2};
  const double cp[6] = {0, 0, 1, 0, 1 + cos(delta), sin(delta)};
  const double rels[2] = {1e-13, 0};
  for (int k = 0; k < 2; k++) {
    km_curve c;
    make_curve(&c, 1, 3, kn, cp, NULL, false);
    km_signature sig;
    double L = 2.0, tol = rels[k] > 0 ? rels[k] * L : 1e-5 * L;
    sign_abs(&c, rels[k] * L, &sig);
    double end[2];
    signature_end(&sig, end);
    assert_close(end[0], 1 + cos(delta), tol);
    assert_close(end[1], sin(delta), tol);
    if (rels[k] > 0) {
      assert_close(sig.turning, delta, 1e-15);
    } else {
      assert_ncorners(&sig, 0);
    }
    km_signature_free(&sig);
    km_curve_free(&c);
  }
}

static void
rational_span_leaving_a_degenerate_leg_has_its_exact_length(void **state) {
  (void)state;
  /* the segment of curvecases.h, its boundary layer narrower as w1 grows,
   * at a loose tolerance and at one below the rounding floor at 1e6 (16 p
   * ulps of 1e6, 3.2e-8, which the signature keeps to): a straight
   * segment, however its directions are rounded where it leaves its
   * start, is no cusp */
  const double w1s[4] = {100, 300, 1000, 10000}, tols[2] = {1e-6, 1e-9};
  const double floor = 16 * 9 * 2.220446049250313e-16 * (1e6 + 1);
  for (int i = 0; i < 8; i++) {
    km_curve c;
    tc_rational_segment_leaving_a_degenerate_leg(&c, w1s[i / 2]);
    double tol = tols[i % 2], promised = fmax(tol, floor);
    km_signature sig;
    sign_abs(&c, tol, &sig);
    assert_close(sig.length, sqrt(1.25), promised);
    assert_close(sig.turning, 0.0, 1e-9);
    double end[2];
    signature_end(&sig, end);
    assert_close(end[0], 1e6 + 1, 2 * promised);
    assert_close(end[1], 1e6 + 0.5, 2 * promised);
    km_signature_free(&sig);
    km_curve_free(&c);
  }
}

static void hairpin_whose_tip_is_rounding_turns_only_once(void **state) {
  (void)state;
  /* A closed rational wave of degree 7 at (1e6, 1e6): 47 points from x =
   * -1 to 1, y = 1e-4 sin(34 pi x), then back to the first, weights over
   * four decades. Where it turns back its tip is a few ulps of 1e6 long,
   * traced in pieces of zero length whose turns are handed on or absorbed
   * by their neighbours; a turn absorbed after another was handed on was
   * counted twice (7.4e-4 rad) and the signature ended 1.5e-3 from its
   * start at a tolerance of 1e-3. A closed curve's signature ends where
   * the curve starts. */
  enum { N = 48, P = 7 };
  static const int wexp[N] = {0, 7, 7, 2, 3, 6, 2, 4, 4, 5, 5, 5, 5, 5, 5, 5,
                              5, 5, 5, 5, 2, 2, 5, 5, 3, 3, 4, 3, 7, 3, 3, 3,
                              3, 1, 0, 0, 0, 6, 3, 3, 3, 3, 3, 3, 3, 0, 8, 0};
  double cp[2 * N], w[N], kn[N + P + 1];
  for (int i = 0; i < N; i++) {
    double x = (double)i / (N - 1);
    cp[2 * i] = 1e6 + (2 * x - 1);
    cp[2 * i + 1] = 1e6 + 1e-4 * sin(2 * M_PI * 17 * x);
    w[i] = pow(10.0, (wexp[i] - 4) / 2.0);
  }
  cp[2 * (N - 1)] = cp[0];
  cp[2 * (N - 1) + 1] = cp[1];
  for (int i = 0; i < N + P + 1; i++)
    kn[i] = i <= P ? 0 : i >= N ? N - P : i - P;
  km_curve c;
  make_curve(&c, P, N, kn, cp, w, true);
  const double tol = 1e-3;
  km_signature sig;
  sign_abs(&c, tol, &sig);
  double turns = sig.turning / (2 * M_PI);
  assert_close(turns, nearbyint(turns), 1e-9);
  double end[2];
  signature_end(&sig, end);
  assert_true(hypot(end[0] - cp[0], end[1] - cp[1]) <= tol);
  km_signature_free(&sig);
  km_curve_free(&c);
}

static void hairpin_signature_counts_its_tip(void **state) {
  (void)state;
  /* The hairpin of curvecases.h, whose tip every quadrature node of its
   * span steps over, as a quadratic and a cubic, with and without
   * (equal) weights, at the origin and at (1e3, 1e3) where the speed's
   * rounding loosens what the quadrature is asked: the signature is as
   * long as the curve, turns as its end tangents do, and ends at its end.
   * Measured with its tip lost, the length came out U^2 = 1e-6 short (an
   * open cubic near 1e12 ended 8.8 times its tolerance off the same way) */
  const double L = tc_hairpin_length(0, 1), U = TC_HAIRPIN_U, E = TC_HAIRPIN_E;
  const double turn = atan2(E, 1 - U) - atan2(E, -U);
  for (int v = 0; v < 8; v++) {
    km_curve c;
    double off = (v / 4) % 2 ? 1e3 : 0.0, tol = 1e-9;
    tc_hairpin(&c, 2 + v % 2, (v / 2) % 2 ? 3.0 : 0.0, off, off);
    km_signature sig;
    sign_abs(&c, tol, &sig);
    assert_close(sig.length, L, tol);
    assert_close(sig.turning, turn, 1e-9);
    double end[2];
    signature_end(&sig, end);
    assert_close(end[0], off + 0.5 - U, 2 * tol);
    assert_close(end[1], off + E, 2 * tol);
    km_signature_free(&sig);
    km_curve_free(&c);
  }
}

static void rational_end_in_a_boundary_layer_keeps_its_turn(void **state) {
  (void)state;
  /* A rational cubic at 1e15 whose end weight is 1e-4 of its neighbour's
   * (weights 100, 0.01, 100, 0.01): the curve runs from P0 to near P2 and
   * leaves for P3 in a boundary layer of the parameter at t = 1, where
   * 99.9% of its length lies in the last 3% of t. A clamped rational
   * Bezier ends at its last control point, so the signature must end
   * there within the tolerance. The turn of 9e-6 rad just before the
   * layer fell between two Chebyshev nodes of a piece holding that length
   * (theta free there within its range), 8e-6 rad behind the curve: the
   * end was 3.4e9 off at a tolerance of 1e9. */
  const double kn[8] = {0, 0, 0, 0, 1, 1, 1, 1};
  const double cp[8] = {
      0,     -89407186999313.359, 500000000000000, -89407186999313.359,
      10000, -89407086999313.344, 750000000000000, -92669565880827.047};
  const double w[4] = {100, 0.01, 100, 0.01};
  km_curve c;
  make_curve(&c, 3, 4, kn, cp, w, false);
  const double tol = 1e9;
  km_signature sig;
  sign_abs(&c, tol, &sig);
  double end[2];
  signature_end(&sig, end);
  assert_true(hypot(end[0] - cp[6], end[1] - cp[7]) <= tol);
  km_signature_free(&sig);
  km_curve_free(&c);
}

static const struct CMUnitTest tests[] = {
    cmocka_unit_test(circle_has_constant_curvature_one_over_r),
    cmocka_unit_test(clockwise_circle_has_curvature_minus_one_over_r),
    cmocka_unit_test(square_has_zero_curvature_and_four_right_corners),
    cmocka_unit_test(polygon_edges_have_exactly_zero_curvature),
    cmocka_unit_test(turn_below_rounding_at_a_knot_counts_at_tight_tolerance),
    cmocka_unit_test(clockwise_square_has_four_negative_corners),
    cmocka_unit_test(cubic_square_and_star_from_fixtures_have_polygon_corners),
    cmocka_unit_test(straight_line_has_zero_curvature_and_turning),
    cmocka_unit_test(kappa_breakpoints_include_arc_length_images_of_knots),
    cmocka_unit_test(knot_insertion_and_elevation_keep_the_signature),
    cmocka_unit_test(repeated_first_control_point_gives_the_traced_signature),
    cmocka_unit_test(degenerate_leg_at_a_join_is_smooth_or_a_corner),
    cmocka_unit_test(rigid_motion_keeps_curvature_and_corners),
    cmocka_unit_test(cusp_is_refused_with_its_parameter),
    cmocka_unit_test(zero_length_curve_is_degenerate),
    cmocka_unit_test(curve_create_rejects_bad_input_naming_the_field),
    cmocka_unit_test(sharp_turn_close_to_the_end_has_its_exact_length),
    cmocka_unit_test(high_order_degenerate_ends_take_the_first_distinct_point),
    cmocka_unit_test(closed_rational_curve_with_a_tiny_span_closes),
    cmocka_unit_test(curve_far_from_the_origin_keeps_to_its_rounding),
    cmocka_unit_test(spans_below_their_rounding_are_traced_or_refused),
    cmocka_unit_test(closed_curve_ending_below_resolution_turns_whole_turns),
    cmocka_unit_test(
        rational_span_leaving_a_degenerate_leg_has_its_exact_length),
    cmocka_unit_test(rational_end_in_a_boundary_layer_keeps_its_turn),
    cmocka_unit_test(hairpin_whose_tip_is_rounding_turns_only_once),
    cmocka_unit_test(hairpin_signature_counts_its_tip),
};

TM_SUITE("signature", tests, NULL, NULL);
