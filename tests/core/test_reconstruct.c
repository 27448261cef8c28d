/* test_reconstruct.c - curves from curvature signatures, against curves known
 * exactly, and round trips reconstruct(signature(C)) = C.
 *
 * Oracles: x = sin s, y = 1 - cos s for kappa = 1; the Cornu spirals of
 * tests/fixtures/analytic.json; a piecewise-polynomial kappa with a jump and
 * a corner whose tangent angle is integrated in closed form. Positions at
 * any s come from the closed-form theta(s) integrated by composite
 * Gauss-Legendre in the test itself (exact to rounding), never from the
 * code under test. The reconstruction's parameter is arc length at its
 * knots, and its documented bound is a distance between the curves as point
 * sets, so points are compared with the nearest point of the other curve.
 */
#include <stdbool.h>
#include <stdio.h>
#include <string.h>

#include "fixtures.h"
#include "km/curve.h"
#include "km/reconstruct.h"
#include "km/signature.h"
#include "curvecases.h"
#include "testutil.h"
#include "testmain.h"

/* ---- an exact curve given by its tangent angle ------------------------ */

#define GRID 2000

typedef struct oracle {
  double (*theta)(double s, const void *ctx);
  const void *ctx;
  double L, x0, y0;
  double gx[GRID + 1], gy[GRID + 1]; /* positions at s_j = L j / GRID */
} oracle;

static double ocos(double s, const void *o) {
  const oracle *q = o;
  return cos(q->theta(s, q->ctx));
}
static double osin(double s, const void *o) {
  const oracle *q = o;
  return sin(q->theta(s, q->ctx));
}

/* The grid of exact positions; theta may jump only at grid points. */
static void oracle_init(oracle *o, double (*theta)(double, const void *),
                        const void *ctx, double L, double x0, double y0) {
  o->theta = theta;
  o->ctx = ctx;
  o->L = L;
  o->x0 = x0;
  o->y0 = y0;
  o->gx[0] = x0;
  o->gy[0] = y0;
  for (int j = 1; j <= GRID; j++) {
    double a = L * (j - 1) / GRID, b = L * j / GRID;
    o->gx[j] = o->gx[j - 1] + tu_integrate(ocos, o, a, b, 1);
    o->gy[j] = o->gy[j - 1] + tu_integrate(osin, o, a, b, 1);
  }
}

/* Exact position at any s in [0, L]. */
static void oracle_point(const oracle *o, double s, double p[2]) {
  int j = (int)floor(s / o->L * GRID);
  if (j < 0) j = 0;
  if (j > GRID) j = GRID;
  double a = o->L * j / GRID;
  if (a > s) {
    j--;
    a = o->L * j / GRID;
  }
  p[0] = o->gx[j] + (s > a ? tu_integrate(ocos, o, a, s, 1) : 0.0);
  p[1] = o->gy[j] + (s > a ? tu_integrate(osin, o, a, s, 1) : 0.0);
}

/* Distance from q to the exact curve near arc length s0: the foot of the
 * perpendicular found by Newton's method on (q - C(s)).T(s) = 0 (its
 * derivative is -1 + kappa (q - C).N, near -1 this close to the curve). */
static double distance_to_exact(const oracle *o, const double q[2], double s0) {
  double s = s0, p[2];
  for (int it = 0; it < 8; it++) {
    if (s < 0) s = 0;
    if (s > o->L) s = o->L;
    oracle_point(o, s, p);
    double th = o->theta(s, o->ctx);
    double step = (q[0] - p[0]) * cos(th) + (q[1] - p[1]) * sin(th);
    if (fabs(step) < 1e-15 * o->L) break;
    s += step;
  }
  if (s < 0) s = 0;
  if (s > o->L) s = o->L;
  oracle_point(o, s, p);
  return hypot(q[0] - p[0], q[1] - p[1]);
}

/* Distance from q to the reconstruction r near its parameter t0, by the
 * same Newton step with r's own derivatives. */
static double distance_to_curve(const km_curve *r, const double q[2],
                                double t0) {
  double a, b, t = t0, d[2][2];
  km_curve_domain(r, &a, &b);
  for (int it = 0; it < 8; it++) {
    if (t < a) t = a;
    if (t > b) t = b;
    km_curve_eval(r, t, 1, d);
    double v2 = d[1][0] * d[1][0] + d[1][1] * d[1][1];
    if (!(v2 > 0)) break;
    double step =
        ((q[0] - d[0][0]) * d[1][0] + (q[1] - d[0][1]) * d[1][1]) / v2;
    t += step;
    if (fabs(step) < 1e-15 * (b - a)) break;
  }
  if (t < a) t = a;
  if (t > b) t = b;
  km_curve_eval(r, t, 0, d);
  return hypot(q[0] - d[0][0], q[1] - d[0][1]);
}

/* Largest distance between the reconstruction r and the exact curve, as
 * point sets (the documented bound is a distance between the curves, the
 * parameter being arc length at the knots only): each point of r on the
 * grid, at its knots and inside each of its spans to the exact curve, and
 * each grid point of the exact curve to r. */
static double measured_error(const oracle *o, const km_curve *r) {
  double worst = 0.0, d[1][2];
  for (int j = 0; j <= GRID; j++) {
    double s = o->L * j / GRID, g[2] = {o->gx[j], o->gy[j]};
    km_curve_eval(r, s, 0, d);
    worst = fmax(worst, distance_to_exact(o, d[0], s));
    worst = fmax(worst, distance_to_curve(r, g, s));
  }
  size_t nk = r->n + (size_t)r->degree + 1;
  for (size_t k = 0; k + 1 < nk; k++) {
    double a = r->knots[k], b = r->knots[k + 1];
    for (int q = 0; q < 4; q++) {
      double s = a + (b - a) * q / 4.0;
      if (q > 0 && !(b > a)) break;
      if (s > o->L) s = o->L;
      km_curve_eval(r, s, 0, d);
      worst = fmax(worst, distance_to_exact(o, d[0], s));
    }
  }
  return worst;
}

/* Reconstruct and check: the curve is within tol of the exact one at equal
 * s, the reported bound covers the measured error, is within tol and is
 * not absurdly pessimistic. Returns the measured error. */
static double check_reconstruction(const km_signature *sig, const oracle *o,
                                   int degree, double tol, km_curve *out) {
  km_error err;
  double bound = -1.0;
  km_curve_init(out);
  km_status st = km_reconstruct(sig, degree, tol, out, &bound, &err);
  if (st != KM_OK) print_error("reconstruct: %s\n", err.message);
  assert_status(st, KM_OK);
  assert_int_equal(out->degree, degree);
  double t0, t1;
  km_curve_domain(out, &t0, &t1);
  assert_close(t0, 0.0, 1e-12 * o->L);
  assert_close(t1, o->L, 1e-12 * o->L);
  double m = measured_error(o, out);
  if (!(m <= tol && m <= bound && bound <= tol &&
        bound <= 1000.0 * m + 1e-12 * o->L))
    print_error("degree %d tol %.3g: measured %.3g, bound %.3g, %zu points\n",
                degree, tol, m, bound, out->n);
  assert_le(m, tol);
  assert_le(m, bound);
  assert_le(bound, tol);
  assert_le(bound, 1000.0 * m + 1e-12 * o->L);
  return m;
}

static double theta_circle(double s, const void *ctx) {
  (void)ctx;
  return s;
}

static void unit_circle_is_reconstructed_within_each_tolerance(void **state) {
  (void)state;
  tf_analytic a;
  assert_int_equal(tf_load_analytic("unit_circle", &a), 0);
  km_signature sig;
  signature_of_analytic(&a, &sig);
  static oracle o;
  oracle_init(&o, theta_circle, NULL, 2 * M_PI, 0, 0);
  /* the oracle itself against the closed form and the fixture */
  for (int j = 0; j <= GRID; j += 50) {
    double s = 2 * M_PI * j / GRID;
    assert_close(o.gx[j], sin(s), 1e-14);
    assert_close(o.gy[j], 1 - cos(s), 1e-14);
  }
  for (int deg = 3; deg <= 5; deg += 2) {
    for (int e = 3; e <= 10; e++) {
      double tol = pow(10.0, -e);
      km_curve r;
      check_reconstruction(&sig, &o, deg, tol, &r);
      /* at the knots the parameter is arc length: closed form there */
      for (size_t k = 0; k < r.n + (size_t)deg + 1; k++) {
        double s = r.knots[k], d[1][2];
        km_curve_eval(&r, s, 0, d);
        assert_close(hypot(d[0][0] - sin(s), d[0][1] - (1 - cos(s))), 0.0, tol);
      }
      /* the fixture's samples */
      for (size_t i = 0; i < a.nsamples; i++) {
        const double *smp = a.samples + 4 * i;
        assert_le(distance_to_curve(&r, smp + 1, smp[0]), tol + a.agreement);
      }
      /* the exact curve closes: so does the result */
      assert_true(r.closed);
      assert_close(r.cp[0], r.cp[2 * r.n - 2], 0.0);
      assert_close(r.cp[1], r.cp[2 * r.n - 1], 0.0);
      km_curve_free(&r);
    }
  }
  km_signature_free(&sig);
  tf_analytic_free(&a);
}

static double theta_cornu(double s, const void *ctx) {
  const double *c = ctx;
  return 0.5 * c[0] * s * s;
}

static void cornu_spirals_are_reconstructed_within_tolerance(void **state) {
  (void)state;
  static const struct {
    const char *name;
    double c; /* kappa = c s */
  } cases[3] = {{"cornu_5", 1.0}, {"spiral_a", 1.0}, {"spiral_b", -0.5}};
  static oracle o;
  for (int ci = 0; ci < 3; ci++) {
    tf_analytic a;
    assert_int_equal(tf_load_analytic(cases[ci].name, &a), 0);
    km_signature sig;
    signature_of_analytic(&a, &sig);
    oracle_init(&o, theta_cornu, &cases[ci].c, a.length, 0, 0);
    /* the oracle against the fixture (independent computations) */
    for (size_t i = 0; i < a.nsamples; i++) {
      const double *smp = a.samples + 4 * i;
      double p[2];
      oracle_point(&o, smp[0], p);
      assert_close(hypot(p[0] - smp[1], p[1] - smp[2]), 0.0,
                   1e-13 + a.agreement);
      assert_close(theta_cornu(smp[0], &cases[ci].c), smp[3], 1e-13);
    }
    for (int deg = 3; deg <= 5; deg += 2) {
      for (int e = 4; e <= 10; e += 3) {
        double tol = pow(10.0, -e);
        km_curve r;
        check_reconstruction(&sig, &o, deg, tol, &r);
        for (size_t i = 0; i < a.nsamples; i++) {
          const double *smp = a.samples + 4 * i;
          assert_le(distance_to_curve(&r, smp + 1, smp[0]), tol + a.agreement);
        }
        assert_false(r.closed);
        km_curve_free(&r);
      }
    }
    km_signature_free(&sig);
    tf_analytic_free(&a);
  }
}

/* kappa = 0.5 + 0.3 s - 0.2 s^2 on [0, 2), a corner of 0.8 at s = 2, then
 * kappa = -0.4 + 0.1 (s - 2)^3 on [2, 5]; angle 0.3 at s = 0. */
static const double KA[3] = {0.5, 0.3, -0.2};
static const double KB[4] = {-1.2, 1.2, -0.6, 0.1};

static double theta_piecewise(double s, const void *ctx) {
  (void)ctx;
  const double IA[4] = {0, 0.5, 0.15, -0.2 / 3};
  const double IB[5] = {0, -1.2, 0.6, -0.2, 0.025};
  if (s < 2.0) return 0.3 + tu_poly(IA, 3, s, 0);
  return 0.3 + tu_poly(IA, 3, 2.0, 0) + 0.8 + tu_poly(IB, 4, s, 0) -
         tu_poly(IB, 4, 2.0, 0);
}

static void
error_bound_covers_the_true_error_with_a_corner_and_a_jump(void **state) {
  (void)state;
  /* kappa as one cubic spline: knot 2 of multiplicity 4 makes the jump */
  const double kn[14] = {0, 0, 0, 0, 1, 2, 2, 2, 2, 3.5, 5, 5, 5, 5};
  double coef[10];
  tu_poly_to_bspline(KA, 2, 3, kn, 5, coef, 1);
  tu_poly_to_bspline(KB, 3, 3, kn + 5, 5, coef + 5, 1);
  km_fn kappa;
  km_error err;
  km_fn_init(&kappa);
  assert_status(km_fn_create(&kappa, 3, 10, kn, coef, &err), KM_OK);
  assert_close(km_fn_value(&kappa, 1.0), tu_poly(KA, 2, 1.0, 0), 1e-14);
  assert_close(km_fn_value(&kappa, 4.0), tu_poly(KB, 3, 4.0, 0), 1e-14);
  const km_corner corner = {2.0, 0.8};
  const double start[2] = {1.0, -2.0};
  km_signature sig;
  km_signature_init(&sig);
  assert_status(km_signature_create(&sig, 5.0, start, 0.3, &kappa, &corner, 1,
                                    false, &err),
                KM_OK);
  km_fn_free(&kappa);
  static oracle o;
  oracle_init(&o, theta_piecewise, NULL, 5.0, 1.0, -2.0);
  /* km_signature_point against the oracle */
  for (int j = 0; j <= GRID; j += 40) {
    double s = 5.0 * j / GRID, p[2], th;
    assert_status(km_signature_point(&sig, s, p, &th), KM_OK);
    assert_close(hypot(p[0] - o.gx[j], p[1] - o.gy[j]), 0.0, 1e-13);
  }
  for (int deg = 3; deg <= 5; deg += 2) {
    for (int e = 3; e <= 9; e += 2) {
      km_curve r;
      check_reconstruction(&sig, &o, deg, pow(10.0, -e), &r);
      /* the corner is a knot of multiplicity `degree` at s = 2 */
      int mult = 0;
      for (size_t k = 0; k < r.n + (size_t)deg + 1; k++)
        if (fabs(r.knots[k] - 2.0) <= 1e-12) mult++;
      assert_int_equal(mult, deg);
      km_curve_free(&r);
    }
  }
  km_signature_free(&sig);
}

/* ---- round trips --------------------------------------------------------- */

/* reconstruct(signature(c)) against c at equal arc length, within 10 tol;
 * returns the largest distance found. */
static double round_trip(const km_curve *c, double rel_tol, int degree) {
  const double L = km_curve_length(c), tol = rel_tol * L;
  km_signature sig;
  km_error err;
  km_signature_init(&sig);
  km_status st = km_signature_compute(c, tol, &sig, &err);
  if (st != KM_OK) print_error("signature: %s\n", err.message);
  assert_status(st, KM_OK);
  km_curve r;
  double bound;
  km_curve_init(&r);
  st = km_reconstruct(&sig, degree, tol, &r, &bound, &err);
  if (st != KM_OK) print_error("reconstruct: %s\n", err.message);
  assert_status(st, KM_OK);
  assert_le(bound, tol);
  double worst = 0.0, s = 0.0, tprev = c->knots[c->degree];
  for (size_t k = (size_t)c->degree; k < c->n; k++) {
    double a = c->knots[k], b = c->knots[k + 1];
    if (!(b > a)) continue;
    for (int q = 0; q <= 40; q++) {
      double t = a + (b - a) * q / 40.0, dc[1][2];
      s += km_curve_length_between(c, tprev, t);
      tprev = t;
      /* left limit at the span's end: the same point (C0 at least) */
      km_curve_eval_side(c, t, q == 40 ? -1 : 1, 0, dc);
      double e = distance_to_curve(&r, dc[0], s);
      if (e > worst) worst = e;
    }
  }
  if (!(worst <= 10 * tol))
    print_error("round trip degree %d, tol %.3g: off by %.3g\n", degree, tol,
                worst);
  assert_le(worst, 10 * tol);
  assert_close(s, L, 1e-12 * L);
  if (c->closed) assert_true(r.closed);
  km_curve_free(&r);
  km_signature_free(&sig);
  return worst;
}

static void random_regular_curves_survive_a_round_trip(void **state) {
  (void)state;
  uint64_t seed = 2024;
  for (int trial = 0; trial < 6; trial++) {
    int p = trial % 2 ? 5 : 3;
    size_t n = 10 + (size_t)trial;
    double cp[2 * 16], kn[16 + 6];
    tu_gentle_polygon(&seed, n, tu_uniform(&seed, -5, 5),
                      tu_uniform(&seed, -5, 5), tu_uniform(&seed, -3, 3),
                      tu_uniform(&seed, 0.5, 3), 0.35, cp);
    tu_clamped_knots(&seed, p, n, 0.6, kn);
    /* regular by construction; verify (hodograph in a half-plane) */
    assert_true(tu_is_regular(p, n, kn, cp));
    km_curve c;
    make_curve(&c, p, n, kn, cp, NULL, false);
    round_trip(&c, 1e-6, 3);
    round_trip(&c, 1e-6, 5);
    if (trial < 2) round_trip(&c, 1e-9, 5);
    km_curve_free(&c);
  }
}

static void rounded_rectangle_survives_a_round_trip(void **state) {
  (void)state;
  double kn[20], cp[34], wt[17];
  tu_rounded_rect(10.0, -4.0, 30.0, 12.0, 3.0, kn, cp, wt);
  km_curve c;
  make_curve(&c, 2, 17, kn, cp, wt, true);
  round_trip(&c, 1e-6, 3);
  round_trip(&c, 1e-8, 5);
  km_curve_free(&c);
}

static void letter_outline_with_corners_survives_a_round_trip(void **state) {
  (void)state;
  /* a "D": a quadratic (elevated exactly to a cubic), a cubic joining it
   * smoothly, and two lines, with corners at (0,10), (-1,5) and the seam
   * (0,0) */
  const double cp[26] = {0,        0,
                         10.0 / 3, 0,
                         5.5,      1,
                         6.5,      3,
                         7.25,     4.5,
                         6,        10,
                         0,        10,
                         -1.0 / 3, 10 - 5.0 / 3,
                         -2.0 / 3, 10 - 10.0 / 3,
                         -1,       5,
                         -2.0 / 3, 5 - 5.0 / 3,
                         -1.0 / 3, 5 - 10.0 / 3,
                         0,        0};
  const double kn[17] = {0, 0, 0, 0, 1, 1, 1, 2, 2, 2, 3, 3, 3, 4, 4, 4, 4};
  km_curve c;
  make_curve(&c, 3, 13, kn, cp, NULL, true);
  /* its signature has exactly the three corners, of known turns */
  km_signature sig;
  km_error err;
  km_signature_init(&sig);
  double L = km_curve_length(&c);
  assert_status(km_signature_compute(&c, 1e-9 * L, &sig, &err), KM_OK);
  assert_int_equal(sig.ncorners, 3);
  assert_close(sig.corners[0].turn, atan(5.0), 1e-9);
  assert_close(sig.corners[1].turn, atan2(10.0, 24.0), 1e-9);
  assert_close(sig.corners[2].turn, atan(5.0), 1e-9);
  assert_close(sig.corners[1].s - sig.corners[0].s, sqrt(26.0), 1e-9 * L);
  assert_close(sig.corners[2].s, L, 1e-9 * L);
  assert_close(sig.turning, 2 * M_PI, 1e-9);
  km_signature_free(&sig);
  round_trip(&c, 1e-6, 3);
  round_trip(&c, 1e-6, 5);
  round_trip(&c, 1e-9, 3);
  km_curve_free(&c);
}

static void fixture_outlines_survive_a_round_trip(void **state) {
  (void)state;
  static const struct {
    const char *pair;
    char which;
  } shapes[] = {{"U_to_S", 'a'},
                {"U_to_S", 'b'},
                {"crescent_to_heart", 'a'},
                {"crescent_to_heart", 'b'},
                {"arrow_rot90", 'a'},
                {"spiral_open", 'a'},
                {"circle_to_star", 'a'}};
  for (size_t i = 0; i < sizeof shapes / sizeof shapes[0]; i++) {
    tf_bspline b;
    assert_int_equal(tf_load_shape(shapes[i].pair, shapes[i].which, &b), 0);
    km_curve c;
    make_curve(&c, b.degree, b.n, b.knots, b.cp, b.w, b.closed);
    round_trip(&c, 1e-6, 3);
    km_curve_free(&c);
    tf_bspline_free(&b);
  }
}

static void repeated_control_point_survives_a_round_trip(void **state) {
  (void)state;
  /* P1 = P0: C' = 0 at the start, the trace is regular */
  const double P[8] = {0, 0, 0, 0, 2, 1, 3, 3};
  const double kn[8] = {0, 0, 0, 0, 1, 1, 1, 1};
  km_curve c;
  make_curve(&c, 3, 4, kn, P, NULL, false);
  round_trip(&c, 1e-6, 3);
  round_trip(&c, 1e-8, 5);
  km_curve_free(&c);
}

static void reconstruct_rejects_other_degrees(void **state) {
  (void)state;
  km_fn kappa;
  km_error err;
  km_fn_init(&kappa);
  assert_status(km_fn_constant(&kappa, 0.0, 1.0, 0.5, &err), KM_OK);
  const double start[2] = {0, 0};
  km_signature sig;
  km_signature_init(&sig);
  assert_status(
      km_signature_create(&sig, 1.0, start, 0.0, &kappa, NULL, 0, false, &err),
      KM_OK);
  km_fn_free(&kappa);
  const int bad[4] = {1, 2, 4, 7};
  for (int i = 0; i < 4; i++) {
    km_curve r;
    km_curve_init(&r);
    assert_status(km_reconstruct(&sig, bad[i], 1e-6, &r, NULL, &err),
                  KM_EDEGREE);
    assert_null(r.cp);
  }
  km_signature_free(&sig);
}

static void
corner_one_ulp_before_a_curvature_break_keeps_its_turn(void **state) {
  (void)state;
  /* kappa = 2^40 on [a, b] = [1/2 - 2^-40, 1/2] and 0 elsewhere, length 1,
   * a corner of pi/2 at s_c one ulp before b. theta climbs to 1 rad over
   * [a, b], so the piece [s_c, b] between the corner and the break, one ulp
   * long, still turns by 2^40 * 2^-54 = 2^-14 rad; its midpoint rounds onto
   * b. Exactly: theta = 1 + pi/2 after b, and the end point is
   *   (a + sin(phi) / K, (1 - cos phi) / K) + (1/2)(cos, sin)(1 + pi/2)
   * with phi = 1 - 2^-14, up to the 2^-54 long piece. */
  const double K = 0x1p40, b = 0.5, a = b - 0x1p-40;
  const double sc = b - 0x1p-54, phi = 1 - 0x1p-14, th1 = 1 + M_PI / 2;
  const double kn[4] = {0, a, b, 1}, coef[3] = {0, K, 0};
  km_fn kappa;
  km_error err;
  km_fn_init(&kappa);
  assert_status(km_fn_create(&kappa, 0, 3, kn, coef, &err), KM_OK);
  const km_corner corner = {sc, M_PI / 2};
  const double start[2] = {0, 0};
  km_signature sig;
  km_signature_init(&sig);
  assert_status(km_signature_create(&sig, 1.0, start, 0.0, &kappa, &corner, 1,
                                    false, &err),
                KM_OK);
  km_fn_free(&kappa);
  double ex = a + sin(phi) / K + 0.5 * cos(th1);
  double ey = (1 - cos(phi)) / K + 0.5 * sin(th1);
  double p[2], th;
  assert_status(km_signature_point(&sig, 1.0, p, &th), KM_OK);
  assert_close(th, th1, 1e-12);
  assert_close(p[0], ex, 1e-13);
  assert_close(p[1], ey, 1e-13);
  for (int deg = 3; deg <= 5; deg += 2) {
    km_curve r;
    double bound;
    km_curve_init(&r);
    assert_status(km_reconstruct(&sig, deg, 1e-9, &r, &bound, &err), KM_OK);
    assert_le(bound, 1e-9);
    double q[1][2], t0, t1;
    km_curve_domain(&r, &t0, &t1);
    km_curve_eval(&r, t1, 0, q);
    assert_close(q[0][0], ex, bound + 1e-13);
    assert_close(q[0][1], ey, bound + 1e-13);
    km_curve_free(&r);
  }
  km_signature_free(&sig);
}

/* kappa from 666,660 down to -2 over 4 units: the curve turns 212,204
 * times, and at 2e-3 its reconstruction would take some 85,000 quintic
 * pieces (400,000 control points, seconds). It is refused at once with
 * the tolerance named; a tolerance that needs few pieces is served. */
/* kappa falling linearly from k0 to -2 over 4 units: sum |c_i| h_i / 2 =
 * 2 (k0 + 2) bounds the integral of |kappa|, and the curve turns
 * (k0 - 2) 2 / (2 pi) times. */
static km_status falling_kappa(km_signature *sig, double k0, km_error *err) {
  km_fn kappa;
  km_fn_init(&kappa);
  const double kn[4] = {0, 0, 4, 4}, co[2] = {k0, -2};
  assert_status(km_fn_create(&kappa, 1, 2, kn, co, err), KM_OK);
  const double start[2] = {0, 0};
  km_signature_init(sig);
  km_status st =
      km_signature_create(sig, 4.0, start, 0.0, &kappa, NULL, 0, false, err);
  km_fn_free(&kappa);
  return st;
}

static void reconstruction_that_turns_without_end_is_refused(void **state) {
  (void)state;
  km_error err;
  km_signature sig;
  /* 212,204 turns: past the 2,000 (+ 1/4 a coefficient) any signature may
   * make, refused where it is given, naming kappa */
  assert_status(falling_kappa(&sig, 666660, &err), KM_ELIMIT);
  assert_int_equal(err.field, KM_FIELD_KAPPA_COEFFICIENTS);
  assert_null(sig.kappa.coef);
  /* the bound 2 (k0 + 2) against 2 pi 2000.5: k0 = 6282.8 is the edge */
  assert_status(falling_kappa(&sig, 6300, &err), KM_ELIMIT);
  assert_status(falling_kappa(&sig, 6250, &err), KM_OK);
  assert_close(sig.turning / (2 * M_PI), (6250.0 - 2.0) * 2 / (2 * M_PI), 1e-9);
  /* 1,989 turns at 1e-12: quintic pieces of h = (46080 tol / kappa^5)^(1/6)
   * number K^(5/6) 4 (6/11) / (46080 tol)^(1/6) ~ 53,000, past the 20,000
   * beyond the input's: refused on the tolerance before any is built */
  km_curve r;
  km_curve_init(&r);
  assert_status(km_reconstruct(&sig, 5, 1e-12, &r, NULL, &err), KM_ELIMIT);
  assert_int_equal(err.field, KM_FIELD_TOLERANCE);
  assert_null(r.cp);
  km_signature_free(&sig);
  /* kappa = 1 over 4 units needs a handful */
  km_fn kappa;
  km_fn_init(&kappa);
  assert_status(km_fn_constant(&kappa, 0.0, 4.0, 1.0, &err), KM_OK);
  km_signature_init(&sig);
  const double start[2] = {0, 0};
  assert_status(
      km_signature_create(&sig, 4.0, start, 0.0, &kappa, NULL, 0, false, &err),
      KM_OK);
  double bound;
  assert_status(km_reconstruct(&sig, 5, 2.1e-3, &r, &bound, &err), KM_OK);
  assert_true(r.n < 100 && bound <= 2.1e-3);
  km_curve_free(&r);
  km_fn_free(&kappa);
  km_signature_free(&sig);
}

/* The answer's curve is held to a number of control points: within it or
 * refused on the tolerance, never larger. The unit circle at 1e-9 takes
 * some 64 cubic pieces (the rigorous bound of an arc-shaped piece of
 * length h is about h^6 / 2000 there), two control points each, while the
 * limit allows `degree` points a piece (a corner adds one): 200 holds
 * them, 150 does not. No cubic is much better: the best cubic arc turning
 * phi is off by about phi^6 / 56000, so at least 34 pieces, 70 points. */
static void reconstruction_holds_to_a_number_of_points(void **state) {
  (void)state;
  km_error err;
  km_signature sig;
  km_fn kappa;
  km_fn_init(&kappa);
  assert_status(km_fn_constant(&kappa, 0.0, 2 * M_PI, 1.0, &err), KM_OK);
  const double start[2] = {1, 0};
  assert_status(km_signature_create(&sig, 2 * M_PI, start, M_PI / 2, &kappa,
                                    NULL, 0, true, &err),
                KM_OK);
  km_curve r;
  km_curve_init(&r);
  const size_t limits[] = {2000, 400, 200, 150, 100, 3};
  for (size_t k = 0; k < sizeof limits / sizeof *limits; k++) {
    km_status st =
        km_reconstruct_within(&sig, 3, 1e-9, limits[k], &r, NULL, &err);
    if (limits[k] >= 200) assert_status(st, KM_OK);
    if (limits[k] <= 150) {
      assert_status(st, KM_ELIMIT);
      assert_int_equal(err.field, KM_FIELD_TOLERANCE);
    }
    if (st == KM_OK) {
      assert_true(r.n <= limits[k]);
      assert_true(r.n >= 70);
    }
    km_curve_free(&r);
  }
  km_fn_free(&kappa);
  km_signature_free(&sig);
}

/* A polyline of three unit edges turning 1 rad at each inner corner is
 * three straight pieces, 3 * 3 + 1 = 10 control points at degree 3 (a
 * Hermite piece adds three points to the one it starts from): a limit of
 * 10 holds it, one of 9 must refuse it rather than answer 10 points. */
static void polyline_is_held_to_a_limit_of_exactly_its_points(void **state) {
  (void)state;
  km_error err;
  km_signature sig;
  km_fn kappa;
  km_fn_init(&kappa);
  assert_status(km_fn_constant(&kappa, 0.0, 3.0, 0.0, &err), KM_OK);
  const double start[2] = {0, 0};
  const km_corner corners[2] = {{1.0, 1.0}, {2.0, 1.0}};
  assert_status(km_signature_create(&sig, 3.0, start, 0.0, &kappa, corners, 2,
                                    false, &err),
                KM_OK);
  km_curve r;
  km_curve_init(&r);
  assert_status(km_reconstruct_within(&sig, 3, 1e-6, 0, &r, NULL, &err), KM_OK);
  size_t needed = r.n;
  km_curve_free(&r);
  assert_int_equal(needed, 10);
  assert_status(km_reconstruct_within(&sig, 3, 1e-6, needed, &r, NULL, &err),
                KM_OK);
  assert_true(r.n <= needed);
  km_curve_free(&r);
  km_status st =
      km_reconstruct_within(&sig, 3, 1e-6, needed - 1, &r, NULL, &err);
  assert_status(st, KM_ELIMIT);
  assert_int_equal(err.field, KM_FIELD_TOLERANCE);
  km_curve_free(&r);
  km_fn_free(&kappa);
  km_signature_free(&sig);
}

static const struct CMUnitTest tests[] = {
    cmocka_unit_test(unit_circle_is_reconstructed_within_each_tolerance),
    cmocka_unit_test(cornu_spirals_are_reconstructed_within_tolerance),
    cmocka_unit_test(
        error_bound_covers_the_true_error_with_a_corner_and_a_jump),
    cmocka_unit_test(random_regular_curves_survive_a_round_trip),
    cmocka_unit_test(rounded_rectangle_survives_a_round_trip),
    cmocka_unit_test(letter_outline_with_corners_survives_a_round_trip),
    cmocka_unit_test(fixture_outlines_survive_a_round_trip),
    cmocka_unit_test(repeated_control_point_survives_a_round_trip),
    cmocka_unit_test(reconstruct_rejects_other_degrees),
    cmocka_unit_test(reconstruction_that_turns_without_end_is_refused),
    cmocka_unit_test(reconstruction_holds_to_a_number_of_points),
    cmocka_unit_test(polyline_is_held_to_a_limit_of_exactly_its_points),
    cmocka_unit_test(corner_one_ulp_before_a_curvature_break_keeps_its_turn),
};

TM_SUITE("reconstruct", tests, NULL, NULL);
