/* test_curve_length_rel.c - km_curve_length_within: the printed length to
 * 1e-12 relative, against closed forms.
 *
 * Oracles: polynomials written exactly as cubic B-splines through their
 * blossoms on any knots (a straight line with uneven and nearly vanishing
 * speed, the parabola y = x^2 by asinh, Neile's parabola (t^2, t^3)
 * through its cusp), the hairpin of curvecases.h, the rational circle
 * (measured by km_curve_length), translations by powers of two (exact),
 * and km_curve_length, km_curve_length_between and
 * km_curve_param_at_length on the same curves.
 */
#include <stdbool.h>
#include <stdint.h>
#include <string.h>

#include "km/curve.h"
#include "curvecases.h"
#include "testutil.h"
#include "testmain.h"

#define REL 1e-12

/* The cubic B-spline of the polynomial curve (px, py) of degree <= 3 on
 * the knots kn (nk values), moved by (ox, oy); caller frees. */
static void poly_cubic(km_curve *c, const double *px, const double *py,
                       const double *kn, size_t nk, double ox, double oy) {
  size_t n = nk - 4;
  double cp[64];
  assert_true(n <= 32);
  tu_poly_to_bspline(px, 3, 3, kn, n, cp, 2);
  tu_poly_to_bspline(py, 3, 3, kn, n, cp + 1, 2);
  for (size_t i = 0; i < n; i++) {
    cp[2 * i] += ox;
    cp[2 * i + 1] += oy;
  }
  make_curve(c, 3, n, kn, cp, NULL, false);
}

/* The length within REL of want, and the lengths the morph uses (to the
 * control polygon) and the parameter at half the length agreeing with it */
static void check_length(const km_curve *c, double want) {
  double L = km_curve_length_within(c, REL);
  assert_rel(L, want, REL);
  assert_rel(km_curve_length(c), L, REL);
  double t0, t1;
  km_curve_domain(c, &t0, &t1);
  assert_rel(km_curve_length_between(c, t0, t1), L, REL);
  double th = km_curve_param_at_length(c, 0.5 * L);
  assert_rel(km_curve_length_between(c, t0, th) +
                 km_curve_length_between(c, th, t1),
             L, REL);
  assert_rel(km_curve_length_between(c, t0, th), 0.5 * L, REL);
}

static void
length_within_of_line_with_uneven_speed_is_the_distance(void **state) {
  (void)state;
  /* (t^3 + e t) along the direction (0.6, 0.8): speed 3 t^2 + e, which
   * nearly vanishes at 0 (F's roots at +-i sqrt(e / 3)), on [-1, 1]; the
   * length is the distance 2 + 2 e */
  const double es[4] = {1.0, 1e-4, 1e-10, 0.0};
  const double kn[10] = {-1, -1, -1, -1, -0.25, 0.5, 1, 1, 1, 1};
  for (int i = 0; i < 4; i++) {
    const double e = es[i];
    const double px[4] = {0, 0.6 * e, 0, 0.6}, py[4] = {0, 0.8 * e, 0, 0.8};
    km_curve c;
    poly_cubic(&c, px, py, kn, 10, 0.0, 0.0);
    check_length(&c, 2.0 + 2.0 * e);
    km_curve_free(&c);
  }
}

/* Arc length of y = x^2 from 0 to X. */
static double parabola_length(double X) {
  return 0.5 * X * sqrt(1.0 + 4.0 * X * X) + 0.25 * asinh(2.0 * X);
}

static void length_within_of_parabola_matches_asinh_closed_form(void **state) {
  (void)state;
  /* x = -3 + 6t, y = x^2 on t in [0, 1] (its speed's continuation
   * vanishes at t = 1/2 +- i/12, near the one span: it is halved): on one
   * span moved 2^30 and 2^-20 away (exactly: its points are integers),
   * and on spans of widths 1e-9 to 1/2 (whose points would round if
   * moved far) */
  const double px[4] = {-3, 6, 0, 0}, py[4] = {9, -36, 36, 0};
  const double bezier[8] = {0, 0, 0, 0, 1, 1, 1, 1};
  const double widths[13] = {0,   0,   0, 0, 1e-9, 1e-6, 1e-3,
                             0.5, 0.5, 1, 1, 1,    1};
  const double L = 2.0 * parabola_length(3.0);
  const double offs[3] = {0.0, 1073741824.0, -9.5367431640625e-7};
  for (int k = 0; k < 3; k++) {
    km_curve c;
    poly_cubic(&c, px, py, bezier, 8, offs[k], -offs[k]);
    check_length(&c, L);
    km_curve_free(&c);
  }
  km_curve c;
  poly_cubic(&c, px, py, widths, 13, offs[2], offs[2]);
  check_length(&c, L);
  km_curve_free(&c);
}

static void length_within_of_cusp_counts_both_branches(void **state) {
  (void)state;
  /* Neile's parabola (t^2, t^3) on [-1, 1]: the speed |t| sqrt(4 + 9
   * t^2) vanishes at the cusp, a root on the interval itself; the length
   * of each branch is (13^(3/2) - 8) / 27 */
  const double px[4] = {0, 0, 1, 0}, py[4] = {0, 0, 0, 1};
  const double kn[8] = {-1, -1, -1, -1, 1, 1, 1, 1};
  km_curve c;
  poly_cubic(&c, px, py, kn, 8, 0.0, 0.0);
  check_length(&c, 2.0 * (13.0 * sqrt(13.0) - 8.0) / 27.0);
  km_curve_free(&c);
}

static void length_within_of_hairpin_counts_its_tip(void **state) {
  (void)state;
  /* curvecases.h: a tip 1e-6 wide 1e-3 from the span's start */
  km_curve c;
  tc_hairpin(&c, 3, 0.0, 0.0, 0.0);
  check_length(&c, tc_hairpin_length(0, 1));
  km_curve_free(&c);
}

static void length_within_of_circle_is_two_pi_r(void **state) {
  (void)state;
  /* rational: measured by km_curve_length, the same digits */
  const double R = 2.5;
  double kn[12], cp[18], w[9];
  tu_circle_nurbs(1.0, -2.0, R, 1, kn, cp, w);
  km_curve c;
  make_curve(&c, 2, 9, kn, cp, w, true);
  assert_rel(km_curve_length_within(&c, REL), 2.0 * M_PI * R, REL);
  assert_true(km_curve_length_within(&c, REL) == km_curve_length(&c));
  km_curve_free(&c);
}

static void length_within_of_point_curve_is_zero(void **state) {
  (void)state;
  const double kn[8] = {0, 0, 0, 0, 1, 1, 1, 1};
  const double cp[8] = {2, 3, 2, 3, 2, 3, 2, 3};
  km_curve c;
  make_curve(&c, 3, 4, kn, cp, NULL, false);
  assert_true(km_curve_length_within(&c, REL) == 0.0);
  km_curve_free(&c);
}

/* xorshift64: the same curves on every run */
static double next_unit(uint64_t *s) {
  *s ^= *s << 13;
  *s ^= *s >> 7;
  *s ^= *s << 17;
  return (double)(*s >> 11) / 9007199254740992.0;
}

static void length_within_agrees_with_length_on_random_cubics(void **state) {
  (void)state;
  /* random open and Hermite-like (double-knot) cubics: loops, nearly
   * cusps, spans 1e-4 to 1 wide; and the same moved 2^20 away, exactly
   * (the points are multiples of 2^-20), where km_curve_length carries the
   * rounding of its span's Bezier points but the length is the same */
  uint64_t s = 0x9E3779B97F4A7C15u;
  const double off = 1048576.0;
  for (int trial = 0; trial < 300; trial++) {
    size_t n = 4 + (size_t)(next_unit(&s) * 12);
    double kn[20], cp[40], far[40], t = 0.0;
    bool doubled = trial % 2;
    for (int i = 0; i < 4; i++) kn[i] = 0.0;
    for (size_t i = 4; i < n; i++) {
      if (!(doubled && i % 2 == 1)) t += pow(10.0, -4.0 * next_unit(&s));
      kn[i] = t;
    }
    t += 0.5;
    for (size_t i = n; i < n + 4; i++) kn[i] = t;
    for (size_t i = 0; i < 2 * n; i++) {
      cp[i] = round(100.0 * (next_unit(&s) - 0.5) * off) / off;
      far[i] = cp[i] + off;
    }
    km_curve c, cf;
    make_curve(&c, 3, n, kn, cp, NULL, false);
    make_curve(&cf, 3, n, kn, far, NULL, false);
    double L = km_curve_length(&c);
    assert_rel(km_curve_length_within(&c, REL), L, REL);
    assert_rel(km_curve_length_within(&cf, REL), L, REL);
    km_curve_free(&c);
    km_curve_free(&cf);
  }
}

static const struct CMUnitTest tests[] = {
    cmocka_unit_test(length_within_of_line_with_uneven_speed_is_the_distance),
    cmocka_unit_test(length_within_of_parabola_matches_asinh_closed_form),
    cmocka_unit_test(length_within_of_cusp_counts_both_branches),
    cmocka_unit_test(length_within_of_hairpin_counts_its_tip),
    cmocka_unit_test(length_within_of_circle_is_two_pi_r),
    cmocka_unit_test(length_within_of_point_curve_is_zero),
    cmocka_unit_test(length_within_agrees_with_length_on_random_cubics),
};

TM_SUITE("curve_length_rel", tests, NULL, NULL);
