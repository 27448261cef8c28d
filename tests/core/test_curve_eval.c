/* test_curve_eval.c - de Boor evaluation, derivatives, one-sided limits, arc
 * length and its inversion, against closed forms.
 *
 * Oracles: polynomials written exactly as B-splines through their blossoms
 * (any knot vector, any degree >= the polynomial's), the rational quadratic
 * circle (|C - O| = R and its derivatives), the explicit rational Bezier
 * formula, and closed-form arc lengths (line, circle, parabola via asinh).
 */
#include <stdbool.h>
#include <string.h>

#include "km/curve.h"
#include "curvecases.h"
#include "testutil.h"
#include "testmain.h"

/* Max of |a|, |b|, 1: the scale for a relative comparison of vectors. */
static double scale2(double a, double b) {
  double m = fabs(a) > fabs(b) ? fabs(a) : fabs(b);
  return m > 1.0 ? m : 1.0;
}

/* x(t), y(t): two cubics; the polynomial curve every spline form below
 * represents exactly. */
static const double PX[4] = {1.0, 2.0, -1.0, 0.5};
static const double PY[4] = {0.0, 1.0, -3.0, 2.0};

/* Check position and derivatives 1..3 of c against (PX, PY) at many t. */
static void check_against_poly(const km_curve *c, const double *px,
                               const double *py, int deg, double rel) {
  double t0, t1;
  km_curve_domain(c, &t0, &t1);
  for (int i = 0; i <= 200; i++) {
    double t = t0 + (t1 - t0) * i / 200.0, out[4][2];
    km_curve_eval(c, t, 3, out);
    for (int k = 0; k <= 3; k++) {
      double wx = tu_poly(px, deg, t, k), wy = tu_poly(py, deg, t, k);
      double tol = rel * scale2(wx, wy);
      assert_close(out[k][0], wx, tol);
      assert_close(out[k][1], wy, tol);
    }
  }
  /* exactly at every knot too (span selection) */
  for (size_t j = 0; j < c->n + (size_t)c->degree + 1; j++) {
    double t = c->knots[j], out[4][2];
    km_curve_eval(c, t, 3, out);
    for (int k = 0; k <= 3; k++) {
      double wx = tu_poly(px, deg, t, k), wy = tu_poly(py, deg, t, k);
      assert_close(out[k][0], wx, rel * scale2(wx, wy));
      assert_close(out[k][1], wy, rel * scale2(wx, wy));
    }
  }
}

/* Control points of the polynomial curve (px, py) of degree deg as a
 * degree-p B-spline on knots (nk values). */
static size_t poly_curve_points(const double *px, const double *py, int deg,
                                int p, const double *knots, size_t nk,
                                double *cp) {
  size_t n = nk - (size_t)p - 1;
  tu_poly_to_bspline(px, deg, p, knots, n, cp, 2);
  tu_poly_to_bspline(py, deg, p, knots, n, cp + 1, 2);
  return n;
}

static void eval_bezier_t_t2_t3_is_exact(void **state) {
  (void)state;
  /* (t, t^2) and (t^2, t^3) on [0, 1]: Bernstein coefficients by hand. */
  const double kn[8] = {0, 0, 0, 0, 1, 1, 1, 1};
  const double cp1[8] = {0, 0, 1.0 / 3, 0, 2.0 / 3, 1.0 / 3, 1, 1};
  const double cp2[8] = {0, 0, 0, 0, 1.0 / 3, 0, 1, 1};
  const double x1[4] = {0, 1, 0, 0}, y1[4] = {0, 0, 1, 0};
  const double x2[4] = {0, 0, 1, 0}, y2[4] = {0, 0, 0, 1};
  km_curve c;
  make_curve(&c, 3, 4, kn, cp1, NULL, false);
  check_against_poly(&c, x1, y1, 3, 1e-14);
  km_curve_free(&c);
  make_curve(&c, 3, 4, kn, cp2, NULL, false);
  check_against_poly(&c, x2, y2, 3, 1e-14);
  km_curve_free(&c);
}

static void
eval_polynomial_on_nonuniform_knots_matches_closed_form(void **state) {
  (void)state;
  /* interior knots of multiplicity 1, 2 and 3 (a C0 knot that the
   * polynomial crosses smoothly) */
  const double kn[15] = {-1,  -1,  -1,  -1, -0.4, 0.3, 0.3, 0.9,
                         0.9, 0.9, 1.1, 2,  2,    2,   2};
  double cp[2 * 11];
  size_t n = poly_curve_points(PX, PY, 3, 3, kn, 15, cp);
  km_curve c;
  make_curve(&c, 3, n, kn, cp, NULL, false);
  double t0, t1;
  km_curve_domain(&c, &t0, &t1);
  assert_close(t0, -1.0, 0.0);
  assert_close(t1, 2.0, 0.0);
  check_against_poly(&c, PX, PY, 3, 1e-12);
  km_curve_free(&c);
}

static void eval_cubic_written_in_degree_five_and_nine_is_exact(void **state) {
  (void)state;
  const double kn5[14] = {0, 0, 0, 0, 0, 0, 0.2, 1.5, 3, 3, 3, 3, 3, 3};
  double cp[2 * 12];
  size_t n = poly_curve_points(PX, PY, 3, 5, kn5, 14, cp);
  km_curve c;
  make_curve(&c, 5, n, kn5, cp, NULL, false);
  check_against_poly(&c, PX, PY, 3, 1e-12);
  km_curve_free(&c);

  /* a genuine degree-9 polynomial on a degree-9 spline */
  double kn9[22], cp9[2 * 12], qx[10], qy[10];
  uint64_t seed = 12345;
  for (int i = 0; i < 10; i++) kn9[i] = 0.0, kn9[21 - i] = 1.0;
  kn9[10] = 0.35;
  kn9[11] = 0.6;
  for (int i = 0; i <= 9; i++) {
    qx[i] = tu_uniform(&seed, -1, 1);
    qy[i] = tu_uniform(&seed, -1, 1);
  }
  n = poly_curve_points(qx, qy, 9, 9, kn9, 22, cp9);
  make_curve(&c, 9, n, kn9, cp9, NULL, false);
  check_against_poly(&c, qx, qy, 9, 1e-10);
  km_curve_free(&c);
}

static void eval_rational_with_equal_weights_equals_polynomial(void **state) {
  (void)state;
  const double kn[11] = {0, 0, 0, 0, 0.25, 0.5, 0.75, 1, 1, 1, 1};
  double cp[2 * 7], w[7];
  size_t n = poly_curve_points(PX, PY, 3, 3, kn, 11, cp);
  for (size_t i = 0; i < n; i++) w[i] = 2.5;
  km_curve c;
  make_curve(&c, 3, n, kn, cp, w, false);
  check_against_poly(&c, PX, PY, 3, 1e-12);
  km_curve_free(&c);
}

/* Explicit rational quadratic Bezier and its derivatives by the quotient
 * rule on the closed-form numerator and denominator polynomials. */
static void rational_quadratic_closed_form(const double *P, const double *w,
                                           double u, double out[4][2]) {
  /* numerator N(u) and denominator D(u) in the power basis */
  double n[2][3], d[3];
  for (int k = 0; k < 2; k++) {
    double a = w[0] * P[k], b = w[1] * P[2 + k], c = w[2] * P[4 + k];
    n[k][0] = a;
    n[k][1] = 2 * (b - a);
    n[k][2] = a - 2 * b + c;
  }
  d[0] = w[0];
  d[1] = 2 * (w[1] - w[0]);
  d[2] = w[0] - 2 * w[1] + w[2];
  double dv[4];
  for (int j = 0; j < 4; j++) dv[j] = tu_poly(d, 2, u, j);
  static const double binom[4][4] = {
      {1, 0, 0, 0}, {1, 1, 0, 0}, {1, 2, 1, 0}, {1, 3, 3, 1}};
  for (int k = 0; k < 2; k++) {
    for (int j = 0; j < 4; j++) {
      /* N^(j) = sum_i binom(j,i) D^(i) x^(j-i) */
      double v = tu_poly(n[k], 2, u, j);
      for (int i = 1; i <= j; i++) v -= binom[j][i] * dv[i] * out[j - i][k];
      out[j][k] = v / dv[0];
    }
  }
}

static void eval_rational_quadratic_matches_quotient_rule(void **state) {
  (void)state;
  const double P[6] = {0.5, -1.0, 2.0, 3.0, 4.0, 0.0};
  const double w[3] = {1.5, 3.0, 0.5};
  const double kn[6] = {2, 2, 2, 5, 5, 5};
  km_curve c;
  make_curve(&c, 2, 3, kn, P, w, false);
  for (int i = 0; i <= 100; i++) {
    double u = i / 100.0, want[4][2], got[4][2];
    rational_quadratic_closed_form(P, w, u, want);
    km_curve_eval(&c, 2.0 + 3.0 * u, 3, got);
    double sc = 1.0;
    for (int k = 0; k <= 3; k++) {
      assert_close(got[k][0], want[k][0] / sc,
                   1e-12 * scale2(want[k][0], want[k][1]) / sc);
      assert_close(got[k][1], want[k][1] / sc,
                   1e-12 * scale2(want[k][0], want[k][1]) / sc);
      sc *= 3.0; /* d/dt = (1/3) d/du */
    }
  }
  km_curve_free(&c);
}

static void
eval_nurbs_circle_has_radius_orthogonal_tangent_and_curvature(void **state) {
  (void)state;
  const double R = 2.5, ox = 1.0, oy = -2.0;
  double kn[12], cp[18], w[9];
  tu_circle_nurbs(ox, oy, R, 1, kn, cp, w);
  km_curve c;
  make_curve(&c, 2, 9, kn, cp, w, true);
  for (int i = 0; i <= 400; i++) {
    double t = i / 400.0, d[4][2];
    km_curve_eval(&c, t, 3, d);
    double rx = d[0][0] - ox, ry = d[0][1] - oy;
    double sp = hypot(d[1][0], d[1][1]);
    /* |C - O| = R and its derivatives: C'.r = 0, C'.C' + r.C'' = 0,
     * 3 C'.C'' + r.C''' = 0 */
    assert_close(hypot(rx, ry), R, 1e-13 * R);
    assert_close(rx * d[1][0] + ry * d[1][1], 0.0, 1e-12 * R * sp);
    double c11 = d[1][0] * d[1][0] + d[1][1] * d[1][1];
    double c12 = d[1][0] * d[2][0] + d[1][1] * d[2][1];
    double m2 = hypot(d[2][0], d[2][1]), m3 = hypot(d[3][0], d[3][1]);
    assert_close(c11 + rx * d[2][0] + ry * d[2][1], 0.0,
                 1e-12 * (c11 + R * m2));
    assert_close(3 * c12 + rx * d[3][0] + ry * d[3][1], 0.0,
                 1e-12 * (3 * sp * m2 + R * m3));
    /* curvature 1/R, counter-clockwise positive */
    double cross = d[1][0] * d[2][1] - d[2][0] * d[1][1];
    assert_close(cross / (sp * sp * sp), 1.0 / R, 1e-12 / R);
    /* constant curvature: d/dt [cross / |C'|^3] = 0 */
    double cross3 = d[1][0] * d[3][1] - d[3][0] * d[1][1];
    double dk = (cross3 * c11 - 3.0 * cross * c12);
    assert_close(dk / pow(sp, 5), 0.0,
                 1e-11 * (m3 / (sp * sp) + m2 * m2 / (sp * sp * sp)));
  }
  km_curve_free(&c);
}

static void eval_side_gives_one_sided_limits_at_c0_knot(void **state) {
  (void)state;
  /* left piece A on [0,1], right piece B on [1,2.5], A(1) = B(1) for x and
   * y, every derivative different */
  const double ax[4] = {0, 1, 0, 0}, ay[4] = {0, 0, 1, 0};
  const double bx[4] = {5, -6, 2, 0}, by[4] = {1, 1, -2, 1};
  const double kn[11] = {0, 0, 0, 0, 1, 1, 1, 2.5, 2.5, 2.5, 2.5};
  double cp[14];
  /* control points 0..3 come from A, 3..6 from B (blossoms) */
  tu_poly_to_bspline(ax, 3, 3, kn, 4, cp, 2);
  tu_poly_to_bspline(ay, 3, 3, kn, 4, cp + 1, 2);
  tu_poly_to_bspline(bx, 3, 3, kn + 3, 4, cp + 6, 2);
  tu_poly_to_bspline(by, 3, 3, kn + 3, 4, cp + 7, 2);
  km_curve c;
  make_curve(&c, 3, 7, kn, cp, NULL, false);
  double l[4][2], r[4][2], dflt[4][2];
  km_curve_eval_side(&c, 1.0, -1, 3, l);
  km_curve_eval_side(&c, 1.0, 1, 3, r);
  km_curve_eval(&c, 1.0, 3, dflt);
  for (int k = 0; k <= 3; k++) {
    assert_close(l[k][0], tu_poly(ax, 3, 1.0, k), 1e-13);
    assert_close(l[k][1], tu_poly(ay, 3, 1.0, k), 1e-13);
    assert_close(r[k][0], tu_poly(bx, 3, 1.0, k), 1e-12);
    assert_close(r[k][1], tu_poly(by, 3, 1.0, k), 1e-12);
    /* default at an interior knot: the right-hand limit */
    assert_close(dflt[k][0], r[k][0], 1e-13);
    assert_close(dflt[k][1], r[k][1], 1e-13);
  }
  /* the limits really differ (else this test could not fail) */
  assert_true(fabs(l[1][0] - r[1][0]) > 1.0);
  /* at the end of the domain the default is the left limit; outside the
   * domain t is clamped */
  double e[4][2], o[4][2];
  km_curve_eval(&c, 2.5, 3, e);
  km_curve_eval(&c, 7.0, 0, o);
  for (int k = 0; k <= 3; k++) {
    assert_close(e[k][0], tu_poly(bx, 3, 2.5, k), 1e-12);
    assert_close(e[k][1], tu_poly(by, 3, 2.5, k), 1e-12);
  }
  assert_close(o[0][0], tu_poly(bx, 3, 2.5, 0), 1e-12);
  km_curve_eval(&c, -3.0, 0, o);
  assert_close(o[0][0], 0.0, 1e-15);
  assert_close(o[0][1], 0.0, 1e-15);
  km_curve_free(&c);
}

/* Bernstein polynomial of degree 3 with coefficients b at t. */
static double bern3(const double *b, double t) {
  double s = 1 - t;
  return s * s * s * b[0] + 3 * s * s * t * b[1] + 3 * s * t * t * b[2] +
         t * t * t * b[3];
}

static void length_of_line_with_uneven_speed_is_the_distance(void **state) {
  (void)state;
  /* a straight cubic whose speed varies 30-fold: increasing Bernstein
   * coefficients make the position along the line f(t) monotone */
  const double f[4] = {0.0, 0.1, 2.2, 3.0}, dx = 0.6, dy = 0.8;
  double cp[8];
  for (int i = 0; i < 4; i++) {
    cp[2 * i] = 1.0 + dx * f[i];
    cp[2 * i + 1] = 1.0 + dy * f[i];
  }
  const double kn[8] = {0, 0, 0, 0, 1, 1, 1, 1};
  km_curve c;
  make_curve(&c, 3, 4, kn, cp, NULL, false);
  assert_close(km_curve_length(&c), 3.0, 1e-13 * 3.0);
  for (int i = 0; i <= 20; i++) {
    double ta = 0.05 * i * 0.37, tb = 0.05 * i;
    assert_close(km_curve_length_between(&c, ta, tb),
                 bern3(f, tb) - bern3(f, ta), 1e-13 * 3.0);
  }
  /* inversion: f(t) = s solved by bisection on the closed form */
  for (int i = 0; i <= 30; i++) {
    double s = 3.0 * i / 30.0, lo = 0, hi = 1;
    for (int it = 0; it < 200; it++) {
      double mid = 0.5 * (lo + hi);
      if (bern3(f, mid) < s)
        lo = mid;
      else
        hi = mid;
    }
    double t = km_curve_param_at_length(&c, s);
    assert_close(t, 0.5 * (lo + hi), 1e-10);
    assert_close(km_curve_length_between(&c, 0.0, t), s, 1e-12 * 3.0);
  }
  km_curve_free(&c);

  /* a degree-1 polyline along one line, uneven spacing */
  const double kp[6] = {0, 0, 1, 3, 4, 4};
  const double pp[8] = {0, 0, 1, -1, 1.5, -1.5, 4, -4};
  make_curve(&c, 1, 4, kp, pp, NULL, false);
  assert_close(km_curve_length(&c), 4.0 * sqrt(2.0), 1e-13 * 4.0);
  /* positions along the line: 0, 1, 1.5, 4 at t = 0, 1, 3, 4, so t = 0.5
   * is at 0.5 and t = 3.5 at 2.75 */
  assert_close(km_curve_length_between(&c, 0.5, 3.5), 2.25 * sqrt(2.0), 1e-12);
  /* derivatives above the degree vanish */
  double d[4][2];
  km_curve_eval(&c, 2.0, 3, d);
  assert_close(d[1][0], 0.25, 1e-15);
  assert_close(d[1][1], -0.25, 1e-15);
  for (int k = 2; k <= 3; k++) {
    assert_close(d[k][0], 0.0, 0.0);
    assert_close(d[k][1], 0.0, 0.0);
  }
  km_curve_free(&c);
}

static void length_of_nurbs_circle_is_two_pi_r(void **state) {
  (void)state;
  const double R = 2.5, ox = 1.0, oy = -2.0;
  double kn[12], cp[18], w[9];
  tu_circle_nurbs(ox, oy, R, 1, kn, cp, w);
  km_curve c;
  make_curve(&c, 2, 9, kn, cp, w, true);
  const double L = 2.0 * M_PI * R;
  assert_close(km_curve_length(&c), L, 1e-12 * L);
  assert_close(km_curve_length_between(&c, 0.25, 0.5), L / 4, 1e-12 * L);
  assert_close(km_curve_length_between(&c, 0.0, 0.75), 3 * L / 4, 1e-12 * L);
  /* partial arcs: the angle of the explicit rational arc at local u */
  const double P[6] = {R, 0, R, R, 0, R}, ww[3] = {1, sqrt(0.5), 1};
  for (int i = 1; i < 20; i++) {
    double u = i / 20.0, q[4][2];
    rational_quadratic_closed_form(P, ww, u, q);
    double phi = atan2(q[0][1], q[0][0]);
    assert_close(km_curve_length_between(&c, 0.0, 0.25 * u), R * phi,
                 1e-12 * L);
    assert_close(km_curve_length_between(&c, 0.5 + 0.25 * u, 1.0),
                 L / 2 - R * phi, 1e-12 * L);
  }
  /* inversion: the point at arc length s is at angle s / R */
  for (int i = 0; i <= 40; i++) {
    double s = L * i / 40.0, t = km_curve_param_at_length(&c, s), d[1][2];
    assert_close(km_curve_length_between(&c, 0.0, t), s, 1e-12 * L);
    km_curve_eval(&c, t, 0, d);
    double phi = atan2(d[0][1] - oy, d[0][0] - ox);
    assert_close(tu_wrap(phi - s / R), 0.0, 1e-11);
  }
  km_curve_free(&c);
}

/* Arc length of y = x^2 from 0 to X. */
static double parabola_length(double X) {
  return 0.5 * X * sqrt(1.0 + 4.0 * X * X) + 0.25 * asinh(2.0 * X);
}

static void length_of_parabola_matches_asinh_closed_form(void **state) {
  (void)state;
  /* x = -0.5 + 2t, y = x^2 on t in [0, 1], written as a cubic spline with
   * interior knots (blossoms) */
  const double qx[4] = {-0.5, 2.0, 0, 0}, qy[4] = {0.25, -2.0, 4.0, 0};
  const double kn[11] = {0, 0, 0, 0, 0.3, 0.7, 0.7, 1, 1, 1, 1};
  double cp[14];
  size_t n = poly_curve_points(qx, qy, 3, 3, kn, 11, cp);
  km_curve c;
  make_curve(&c, 3, n, kn, cp, NULL, false);
  const double L = parabola_length(1.5) - parabola_length(-0.5);
  assert_close(km_curve_length(&c), L, 1e-12 * L);
  for (int i = 0; i <= 25; i++) {
    double ta = 0.4 * i / 25.0, tb = 0.4 + 0.6 * i / 25.0;
    double want =
        parabola_length(-0.5 + 2 * tb) - parabola_length(-0.5 + 2 * ta);
    assert_close(km_curve_length_between(&c, ta, tb), want, 1e-12 * L);
  }
  for (int i = 0; i <= 25; i++) {
    double s = L * i / 25.0, t = km_curve_param_at_length(&c, s);
    assert_close(parabola_length(-0.5 + 2 * t) - parabola_length(-0.5), s,
                 1e-12 * L);
  }
  km_curve_free(&c);
}

static void param_at_length_clamps_to_the_ends(void **state) {
  (void)state;
  const double kn[11] = {-1, -1, -1, -1, 0, 0.5, 1, 2, 2, 2, 2};
  double cp[14];
  size_t n = poly_curve_points(PX, PY, 3, 3, kn, 11, cp);
  km_curve c;
  make_curve(&c, 3, n, kn, cp, NULL, false);
  double L = km_curve_length(&c);
  assert_true(L > 0);
  assert_close(km_curve_param_at_length(&c, 0.0), -1.0, 1e-12);
  assert_close(km_curve_param_at_length(&c, -5.0), -1.0, 1e-12);
  assert_close(km_curve_param_at_length(&c, L), 2.0, 1e-12);
  assert_close(km_curve_param_at_length(&c, 2 * L), 2.0, 1e-12);
  /* lengths add up over a split point */
  assert_close(km_curve_length_between(&c, -1.0, 0.3) +
                   km_curve_length_between(&c, 0.3, 2.0),
               L, 1e-13 * L);
  km_curve_free(&c);
}

/* 0 when the length of the curve in ctx is 0 up to rounding (for
 * tu_run_bounded). */
static int length_is_zero(void *ctx) {
  double L = km_curve_length(ctx);
  return L >= 0.0 && L <= 1e-13 ? 0 : 1;
}

static void length_of_a_point_curve_is_zero(void **state) {
  (void)state;
  /* every control point the same (away from the origin, so that de Boor's
   * convex combinations round): the length is 0 up to rounding, and
   * finding it must terminate; bounded so a hang fails this test only */
  const double kn[8] = {0, 0, 0, 0, 1, 1, 1, 1};
  const double cp[8] = {2, 3, 2, 3, 2, 3, 2, 3};
  km_curve c;
  make_curve(&c, 3, 4, kn, cp, NULL, false);
  int r = tu_run_bounded(length_is_zero, &c, 5);
  if (r == -1) print_error("km_curve_length did not finish in 5 s\n");
  assert_int_equal(r, 0);
  km_curve_free(&c);
}

static void
rational_segment_leaving_a_degenerate_leg_has_its_length(void **state) {
  (void)state;
  /* the segment of curvecases.h, its boundary layer narrower as w1 grows;
   * 1e-8 is a third of the rounding floor of a signature at 1e6 */
  const double w1s[4] = {100, 300, 1000, 10000};
  for (int i = 0; i < 4; i++) {
    km_curve c;
    tc_rational_segment_leaving_a_degenerate_leg(&c, w1s[i]);
    const double L = sqrt(1.25), tol = 1e-8;
    assert_close(km_curve_length(&c), L, tol);
    double t = km_curve_param_at_length(&c, 0.5 * L), d[1][2];
    km_curve_eval(&c, t, 0, d);
    assert_close(d[0][0], 1e6 + 0.5, tol);
    assert_close(d[0][1], 1e6 + 0.25, tol);
    assert_close(km_curve_length_between(&c, t, 1.0), 0.5 * L, tol);
    km_curve_free(&c);
  }
}

static void hairpin_length_counts_its_tip(void **state) {
  (void)state;
  /* curvecases.h: a tip the quadrature's nodes all step over; as a
   * quadratic and a cubic, with and without (equal) weights, and far from
   * the origin */
  const double L = tc_hairpin_length(0, 1), U = TC_HAIRPIN_U;
  for (int v = 0; v < 8; v++) {
    km_curve c;
    double off = v >= 4 ? 1e3 : 0.0;
    tc_hairpin(&c, 2 + v % 2, (v / 2) % 2 ? 3.0 : 0.0, off, off);
    /* a few ulps of the coordinates a node, far from the origin */
    double tol = 1e-13 * L + 64 * 2.2e-16 * off;
    assert_close(km_curve_length(&c), L, tol);
    assert_close(km_curve_length_between(&c, 0, 2 * U),
                 tc_hairpin_length(0, 2 * U), tol);
    assert_close(km_curve_length_between(&c, 0.5 * U, 0.7),
                 tc_hairpin_length(0.5 * U, 0.7), tol);
    /* the point at the arc length of u = 0.5 is u = 0.5 */
    assert_close(km_curve_param_at_length(&c, tc_hairpin_length(0, 0.5)), 0.5,
                 1e-9);
    km_curve_free(&c);
  }
}

static const struct CMUnitTest tests[] = {
    cmocka_unit_test(eval_bezier_t_t2_t3_is_exact),
    cmocka_unit_test(eval_polynomial_on_nonuniform_knots_matches_closed_form),
    cmocka_unit_test(eval_cubic_written_in_degree_five_and_nine_is_exact),
    cmocka_unit_test(eval_rational_with_equal_weights_equals_polynomial),
    cmocka_unit_test(eval_rational_quadratic_matches_quotient_rule),
    cmocka_unit_test(
        eval_nurbs_circle_has_radius_orthogonal_tangent_and_curvature),
    cmocka_unit_test(eval_side_gives_one_sided_limits_at_c0_knot),
    cmocka_unit_test(length_of_line_with_uneven_speed_is_the_distance),
    cmocka_unit_test(length_of_nurbs_circle_is_two_pi_r),
    cmocka_unit_test(length_of_parabola_matches_asinh_closed_form),
    cmocka_unit_test(param_at_length_clamps_to_the_ends),
    cmocka_unit_test(length_of_a_point_curve_is_zero),
    cmocka_unit_test(rational_segment_leaving_a_degenerate_leg_has_its_length),
    cmocka_unit_test(hairpin_length_counts_its_tip),
};

TM_SUITE("curve_eval", tests, NULL, NULL);
