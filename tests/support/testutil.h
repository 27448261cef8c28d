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
#include <signal.h>
#include <stdbool.h>
#include <stdlib.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* |got - want| <= tol, printing both values when it is not. NaN fails. */
#define assert_close(got, want, tol)                                           \
  do {                                                                         \
    double tu_g_ = (got), tu_w_ = (want), tu_t_ = (tol);                       \
    if (!(fabs(tu_g_ - tu_w_) <= tu_t_)) {                                     \
      print_error("%s = %.17g, expected %s = %.17g within %.3g (off by "       \
                  "%.3g)\n",                                                   \
                  #got, tu_g_, #want, tu_w_, tu_t_, fabs(tu_g_ - tu_w_));      \
      fail();                                                                  \
    }                                                                          \
  } while (0)

/* |got - want| <= rel * |want|. */
#define assert_rel(got, want, rel)                                             \
  assert_close((got), (want), (rel)*fabs((double)(want)))

/* a <= b, printing both values when it is not. */
#define assert_le(a, b)                                                        \
  do {                                                                         \
    double tu_a_ = (a), tu_b_ = (b);                                           \
    if (!(tu_a_ <= tu_b_)) {                                                   \
      print_error("expected %s = %.17g <= %s = %.17g\n", #a, tu_a_, #b,        \
                  tu_b_);                                                      \
      fail();                                                                  \
    }                                                                          \
  } while (0)

/* A status comparison that names both codes. */
#define assert_status(got, want)                                               \
  do {                                                                         \
    int tu_s_ = (int)(got), tu_e_ = (int)(want);                               \
    if (tu_s_ != tu_e_) {                                                      \
      print_error("%s returned status %d, expected %s (%d)\n", #got, tu_s_,    \
                  #want, tu_e_);                                               \
      fail();                                                                  \
    }                                                                          \
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
  for (size_t i = 0; i < n; i++)
    out[i * stride] = tu_blossom(a, deg, p, t + i + 1);
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
                                  const void *ctx, double a, double b, int m) {
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
  static const double kn[12] = {0,   0,    0,    0.25, 0.25, 0.5,
                                0.5, 0.75, 0.75, 1,    1,    1};
  for (int i = 0; i < 12; i++) knots[i] = kn[i];
  for (int i = 0; i < 9; i++) {
    cp[2 * i] = cx + r * ux[i];
    cp[2 * i + 1] = cy + r * (ccw ? uy[i] : -uy[i]);
    w[i] = (i % 2) ? sqrt(0.5) : 1.0;
  }
}

/* The rounded rectangle [x0, x0+w] x [y0, y0+h] with corner radius r as a
 * closed, counter-clockwise degree-2 NURBS: eight Bezier pieces (lines with
 * their middle point at the midpoint, exact quarter circles) joined with
 * knots of multiplicity 2 on [0, 8], starting at (x0 + r, y0) heading +x
 * along the bottom line. knots[20], cp[34], wt[17]. Tangent-continuous
 * everywhere (the seam too); curvature jumps between 0 and 1/r at the
 * joins, which lie at arc lengths w-2r, +pi r/2, +h-2r, +pi r/2, ... */
static inline void tu_rounded_rect(double x0, double y0, double w, double h,
                                   double r, double *knots, double *cp,
                                   double *wt) {
  /* the nine join points and the eight middle control points */
  const double jx[9] = {x0 + r, x0 + w - r, x0 + w, x0 + w, x0 + w - r,
                        x0 + r, x0,         x0,     x0 + r};
  const double jy[9] = {y0,     y0,         y0 + r, y0 + h - r, y0 + h,
                        y0 + h, y0 + h - r, y0 + r, y0};
  const double mx[8] = {0.5 * (jx[0] + jx[1]), x0 + w, x0 + w, x0 + w,
                        0.5 * (jx[4] + jx[5]), x0,     x0,     x0};
  const double my[8] = {y0,     y0,     0.5 * (jy[2] + jy[3]), y0 + h,
                        y0 + h, y0 + h, 0.5 * (jy[6] + jy[7]), y0};
  for (int i = 0; i < 8; i++) {
    cp[4 * i] = jx[i];
    cp[4 * i + 1] = jy[i];
    cp[4 * i + 2] = mx[i];
    cp[4 * i + 3] = my[i];
    wt[2 * i] = 1.0;
    wt[2 * i + 1] = (i % 2) ? sqrt(0.5) : 1.0;
  }
  cp[32] = jx[8];
  cp[33] = jy[8];
  wt[16] = 1.0;
  knots[0] = knots[1] = knots[2] = 0.0;
  for (int i = 1; i < 8; i++) knots[2 * i + 1] = knots[2 * i + 2] = i;
  knots[17] = knots[18] = knots[19] = 8.0;
}

/* Control points of a gently turning random polygon: n points, legs of
 * length step * [0.8, 1.2], each leg turning by at most maxturn from the
 * previous one, starting at (x, y) heading `heading`. */
static inline void tu_gentle_polygon(uint64_t *seed, size_t n, double x,
                                     double y, double heading, double step,
                                     double maxturn, double *cp) {
  double dir = heading;
  cp[0] = x;
  cp[1] = y;
  for (size_t i = 1; i < n; i++) {
    double len = step * tu_uniform(seed, 0.8, 1.2);
    cp[2 * i] = cp[2 * i - 2] + len * cos(dir);
    cp[2 * i + 1] = cp[2 * i - 1] + len * sin(dir);
    dir += tu_uniform(seed, -maxturn, maxturn);
  }
}

/* Clamped knots on [0, n - p] for n control points of degree p, interior
 * knots jittered by up to +-jitter/2 of a unit spacing (seeded). */
static inline void tu_clamped_knots(uint64_t *seed, int p, size_t n,
                                    double jitter, double *knots) {
  size_t nk = n + (size_t)p + 1;
  for (int i = 0; i <= p; i++) {
    knots[i] = 0.0;
    knots[nk - 1 - (size_t)i] = (double)(n - (size_t)p);
  }
  for (size_t i = (size_t)p + 1; i < n; i++)
    knots[i] = (double)(i - (size_t)p) + jitter * (tu_rand(seed) - 0.5);
}

/* A polynomial B-spline is regular (C' != 0) if, on every span, the p
 * hodograph control points that span uses lie in an open half-plane: then
 * every convex combination of them is non-zero. Checks exactly that, with
 * the window's mean direction as the half-plane's normal. */
static inline int tu_is_regular(int p, size_t n, const double *knots,
                                const double *cp) {
  for (size_t span = (size_t)p; span < n; span++) {
    if (!(knots[span + 1] > knots[span])) continue;
    double q[2 * 16], mx = 0.0, my = 0.0;
    for (int k = 0; k < p; k++) {
      size_t i = span - (size_t)p + (size_t)k;
      double den = knots[i + (size_t)p + 1] - knots[i + 1];
      q[2 * k] = p * (cp[2 * i + 2] - cp[2 * i]) / den;
      q[2 * k + 1] = p * (cp[2 * i + 3] - cp[2 * i + 1]) / den;
      double len = hypot(q[2 * k], q[2 * k + 1]);
      if (len == 0.0) return 0;
      mx += q[2 * k] / len;
      my += q[2 * k + 1] / len;
    }
    for (int k = 0; k < p; k++)
      if (!(q[2 * k] * mx + q[2 * k + 1] * my > 0.0)) return 0;
  }
  return 1;
}

/* Tangent turn from direction (ax, ay) to (bx, by), in (-pi, pi]. */
static inline double tu_turn(double ax, double ay, double bx, double by) {
  return atan2(ax * by - ay * bx, ax * bx + ay * by);
}

/* A km_stop condition (countdown_stop with a countdown as its context)
 * that lets the work go on `left` times, then stops it, counting the
 * questions: the tests of where long computations stop. Plain C, so it
 * needs nothing from libkmorph. */
typedef struct countdown {
  long left;  /* answers "go on" this many times, then "stop" */
  long asked; /* questions asked */
} countdown;

static inline bool countdown_stop(void *ctx) {
  countdown *c = ctx;
  c->asked++;
  return c->left-- <= 0;
}

/* Run fn(ctx) in a child process bounded by `seconds`, so that a hang or a
 * crash in the code under test becomes one failed assertion instead of a
 * stalled suite. fn returns a small non-negative code (e.g. -status).
 * Returns that code, or -1 on time-out, -2 on a crash (signal). */
static inline int tu_run_bounded(int (*fn)(void *), void *ctx,
                                 unsigned seconds) {
  pid_t pid = fork();
  if (pid < 0) return -3;
  if (pid == 0) {
    alarm(seconds);
    _exit(fn(ctx) & 0x7f);
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
  }
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  if (WIFSIGNALED(status) && WTERMSIG(status) == SIGALRM) return -1;
  return -2;
}

#endif
