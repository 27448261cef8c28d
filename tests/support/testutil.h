/* testutil.h - small mathematical helpers and assertions shared by the unit
 * tests: value-printing comparisons, a seeded PRNG, polynomial blossoms
 * (to write a known polynomial exactly as a B-spline on any knot vector),
 * Gauss-Legendre quadrature for independent reference integrals.
 *
 * Everything here is independent of libkmorph so that the oracles of the
 * tests never come from the code under test. Header-only (static inline)
 * because each test binary is a single translation unit plus the support
 * objects.
 */
#ifndef KM_TESTUTIL_H
#define KM_TESTUTIL_H

/* cmocka needs these before its own header. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>
#include <math.h>
#include <stdlib.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* |got - want| <= tol, printing both values when it is not. NaN fails. */
#define assert_close(got, want, tol)                                          \
  do {                                                                        \
    double tu_g_ = (got), tu_w_ = (want), tu_t_ = (tol);                      \
    if (!(fabs(tu_g_ - tu_w_) <= tu_t_)) {                                    \
      print_error("%s = %.17g, expected %s = %.17g within %.3g (off by "      \
                  "%.3g)\n",                                                  \
                  #got, tu_g_, #want, tu_w_, tu_t_, fabs(tu_g_ - tu_w_));     \
      fail();                                                                 \
    }                                                                         \
  } while (0)

/* |got - want| <= rel * |want|. */
#define assert_rel(got, want, rel)                                            \
  assert_close((got), (want), (rel) * fabs((double)(want)))

/* a <= b, printing both values when it is not. */
#define assert_le(a, b)                                                       \
  do {                                                                        \
    double tu_a_ = (a), tu_b_ = (b);                                          \
    if (!(tu_a_ <= tu_b_)) {                                                  \
      print_error("expected %s = %.17g <= %s = %.17g\n", #a, tu_a_, #b,       \
                  tu_b_);                                                     \
      fail();                                                                 \
    }                                                                         \
  } while (0)

/* A status comparison that names both codes. */
#define assert_status(got, want)                                              \
  do {                                                                        \
    int tu_s_ = (int)(got), tu_e_ = (int)(want);                              \
    if (tu_s_ != tu_e_) {                                                     \
      print_error("%s returned status %d, expected %s (%d)\n", #got, tu_s_,   \
                  #want, tu_e_);                                              \
      fail();                                                                 \
    }                                                                         \
  } while (0)

/* Angle difference wrapped to (-pi, pi]. */
static inline double tu_wrap(double d) {
  d = fmod(d, 2.0 * M_PI);
  if (d > M_PI) d -= 2.0 * M_PI;
  if (d <= -M_PI) d += 2.0 * M_PI;
  return d;
}

/* xorshift64*: a deterministic PRNG so every run tests the same curves. */
static inline double tu_rand(uint64_t *state) {
  uint64_t x = *state;
  x ^= x >> 12;
  x ^= x << 25;
  x ^= x >> 27;
  *state = x;
  return (double)((x * 2685821657736338717ULL) >> 11) * 0x1.0p-53;
}

/* Uniform in [lo, hi). */
static inline double tu_uniform(uint64_t *state, double lo, double hi) {
  return lo + (hi - lo) * tu_rand(state);
}

/* Value of the k-th derivative of the polynomial sum a[i] x^i (i <= deg). */
static inline double tu_poly(const double *a, int deg, double x, int k) {
  double r = 0.0;
  for (int i = deg; i >= k; i--) {
    double c = a[i];
    for (int j = 0; j < k; j++) c *= (double)(i - j);
    r = r * x + c;
  }
  return r;
}

/* Blossom (polar form) of the polynomial sum a[i] x^i, deg <= p, as a
 * degree-p polynomial, at u[0..p-1]: sum_i a[i] e_i(u) / binom(p, i) with
 * e_i the elementary symmetric polynomials. The B-spline coefficient i of
 * that polynomial on knots t is the blossom at t[i+1..i+p] (Ramshaw), so a
 * polynomial can be written exactly on any clamped knot vector. */
static inline double tu_blossom(const double *a, int deg, int p,
                                const double *u) {
  double e[32] = {1.0};
  for (int j = 0; j < p; j++) {
    for (int i = j + 1; i >= 1; i--) e[i] += e[i - 1] * u[j];
  }
  double r = 0.0, binom = 1.0;
  for (int i = 0; i <= deg; i++) {
    r += a[i] * e[i] / binom;
    binom = binom * (double)(p - i) / (double)(i + 1);
  }
  return r;
}

/* B-spline coefficients (n = nknots - p - 1 of them, stride `stride` into
 * out) of the polynomial a (degree deg <= p) on the knot vector t. */
static inline void tu_poly_to_bspline(const double *a, int deg, int p,
                                      const double *t, size_t n, double *out,
                                      size_t stride) {
  for (size_t i = 0; i < n; i++) out[i * stride] = tu_blossom(a, deg, p, t + i + 1);
}

/* Gauss-Legendre nodes and weights on [-1, 1] (Newton on P_n). n <= 64. */
static inline void tu_gauss_legendre(int n, double *x, double *w) {
  for (int i = 0; i < n; i++) {
    double z = cos(M_PI * (i + 0.75) / (n + 0.5)), dp = 1.0;
    for (int it = 0; it < 100; it++) {
      double p0 = 1.0, p1 = z;
      for (int k = 2; k <= n; k++) {
        double p2 = ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      dp = n * (z * p1 - p0) / (z * z - 1.0);
      double dz = p1 / dp;
      z -= dz;
      if (fabs(dz) < 1e-16) break;
    }
    x[i] = z;
    w[i] = 2.0 / ((1.0 - z * z) * dp * dp);
  }
}

/* Integral of f over [a, b] by composite 20-point Gauss-Legendre on m equal
 * panels: exact for polynomials of degree <= 39 per panel, and to rounding
 * for the smooth analytic integrands the tests use. */
static inline double tu_integrate(double (*f)(double, const void *),
                                  const void *ctx, double a, double b,
                                  int m) {
  double x[20], w[20];
  tu_gauss_legendre(20, x, w);
  double h = (b - a) / m, sum = 0.0;
  for (int p = 0; p < m; p++) {
    double lo = a + p * h, part = 0.0;
    for (int i = 0; i < 20; i++)
      part += w[i] * f(lo + 0.5 * h * (x[i] + 1.0), ctx);
    sum += 0.5 * h * part;
  }
  return sum;
}

/* The rational quadratic (9-point) NURBS circle of radius r about (cx, cy),
 * counter-clockwise when ccw, starting at angle 0, on the domain [0, 1]:
 * knots[12], cp[18], w[9]. Each quarter is exactly a circular arc. */
static inline void tu_circle_nurbs(double cx, double cy, double r, int ccw,
                                   double *knots, double *cp, double *w) {
  static const double ux[9] = {1, 1, 0, -1, -1, -1, 0, 1, 1};
  static const double uy[9] = {0, 1, 1, 1, 0, -1, -1, -1, 0};
  static const double kn[12] = {0, 0, 0, 0.25, 0.25, 0.5,
                                0.5, 0.75, 0.75, 1, 1, 1};
  for (int i = 0; i < 12; i++) knots[i] = kn[i];
  for (int i = 0; i < 9; i++) {
    cp[2 * i] = cx + r * ux[i];
    cp[2 * i + 1] = cy + r * (ccw ? uy[i] : -uy[i]);
    w[i] = (i % 2) ? sqrt(0.5) : 1.0;
  }
}

#endif
