/* kernels.h - the small numeric kernels libkmorph shares; internal.
 *
 * One copy of each: the knot-span search and the cubic B-spline basis
 * (kernels.c), the dense solver (inline here), the Bernstein basis, the comparison of
 * doubles for qsort and the FFT (linalg.c), Gauss-Legendre rules,
 * adaptive quadrature and angle wrapping (status.c, curve.c), the
 * spectral integral at the signature's nodes (signature_theta.c) and a
 * fast sin and cos. Every function here is pure: it reads its arguments
 * and writes only the arrays it is given.
 */
#ifndef KM_KERNELS_H
#define KM_KERNELS_H

#include <math.h>
#include <stdbool.h>
#include <stddef.h>

#define KM_PI 3.14159265358979323846

/* The binary search under every span and piece search: the largest i in
 * [lo, hi) with x[i] <= v, given x[lo] <= v < x[hi] for sorted x (a NaN v
 * gives hi - 1). O(log(hi - lo)). */
static inline size_t km__bracket(const double *x, size_t lo, size_t hi,
                                 double v) {
  while (hi - lo > 1) {
    size_t mid = (lo + hi) / 2;
    if (v < x[mid])
      hi = mid;
    else
      lo = mid;
  }
  return lo;
}

/* Span index i in [p, n - 1] with U[i] <= u < U[i+1], for the knot vector
 * U[0 .. n + p] of n control points of degree p (non-decreasing knots,
 * U[p] < U[n]). u at or past the domain's end U[n] gives the last
 * non-empty span, u at or before its start U[p] the first non-empty one,
 * so the span returned is never empty. A NaN u gives n - 1. Binary search:
 * O(log n). */
size_t km__knot_span(const double *U, size_t n, int p, double u);

/* The four cubic B-spline basis values N[0..3] = N_{i-3..i}(u) on span i
 * of the knot vector U (U[i] <= u <= U[i+1], Cox-de Boor as in Piegl and
 * Tiller's A2.2). A zero-width knot difference contributes 0 instead of a
 * division by zero, so an empty span gives finite values; on a non-empty
 * span none is zero and the values sum to 1 to rounding. */
void km__cubic_basis(const double *U, size_t i, double u, double N[4]);

/* Solve the dense n x n system A x = y in place (row-major A, x returned
 * in y) by Gaussian elimination with partial pivoting; false if a pivot
 * is below 1e-300 (singular to working precision; A and y are then
 * partly eliminated). For interpolation systems and Gauss-Newton steps of
 * at most a few dozen unknowns, and the 6 x 6 system of every theta piece
 * of a signature: inline, so that a call of constant size is compiled
 * for that size. */
static inline bool km__solve_dense(double *A, double *y, int n) {
  for (int c = 0; c < n; c++) {
    int piv = c;
    for (int r = c + 1; r < n; r++)
      if (fabs(A[r * n + c]) > fabs(A[piv * n + c])) piv = r;
    if (!(fabs(A[piv * n + c]) > 1e-300)) return false;
    if (piv != c) {
      for (int k = 0; k < n; k++) {
        double tmp = A[c * n + k];
        A[c * n + k] = A[piv * n + k];
        A[piv * n + k] = tmp;
      }
      double tmp = y[c];
      y[c] = y[piv];
      y[piv] = tmp;
    }
    for (int r = c + 1; r < n; r++) {
      double f = A[r * n + c] / A[c * n + c];
      for (int k = c; k < n; k++) A[r * n + k] -= f * A[c * n + k];
      y[r] -= f * y[c];
    }
  }
  for (int r = n - 1; r >= 0; r--) {
    double v = y[r];
    for (int k = r + 1; k < n; k++) v -= A[r * n + k] * y[k];
    y[r] = v / A[r * n + r];
  }
  return true;
}

/* The d+1 Bernstein basis values B_k^d(u) into row[0..d]. */
void km__bernstein_basis(double u, int d, double *row);
/* qsort comparison of doubles, ascending (NaN compares equal to all). */
int km__cmp_double(const void *a, const void *b);
/* Discrete Fourier transform of n = 2^k complex values in place (X_m = sum
 * x_j e^(-2 pi i j m / n); inverse: with e^(+...) and divided by n), with
 * the n/2 twiddles e^(-2 pi i k / n) from km__fft_twiddles (2 per k). */
void km__fft_twiddles(int n, double *tw);
void km__fft(double *re, double *im, int n, const double *tw, bool inverse);

/* Gauss-Legendre rules on [-1, 1]. */
extern const double km__gl8_x[8], km__gl8_w[8];
extern const double km__gl16_x[16], km__gl16_w[16];

/* Adaptive Gauss-Legendre (8 vs 16 points, bisection) of f over [a, b];
 * NaN when the precision cannot be reached within a fixed amount of work
 * (an integrand that is rounding noise, or nearly singular), so that no
 * caller reports a length less precise than it promises. */
typedef double (*km__scalar_fn)(const void *ctx, double t);
double km__integrate_adaptive(km__scalar_fn f, const void *ctx, double a,
                              double b, double abs_tol);

/* F[k] = integral from -1 to x_k of the degree-14 interpolant of f at the
 * 15 Chebyshev-Lobatto points x_k = -cos(k pi / 14) of [-1, 1] (the
 * signature's nodes). */
void km__cheb_cumulative15(const double *f, double *F);

/* Wrap an angle to (-pi, pi]. */
double km__wrap_angle(double a);

/* sin x and cos x together, for the innermost loops of morph frames (one
 * pair per quadrature node): x - n pi/2 by a three-part split of pi/2
 * (33 + 33 + 53 bits, so n times each leading part is exact for |n| <
 * 2^20), then the Taylor series of sin and cos on |r| <= pi/4 to r^17 and
 * r^18, whose remainders are below 1e-19. Agrees with libm to a few units
 * in the last place (tests/core/test_numerics.c); |x| >= 1e5 goes to libm. */
static inline void km__sincos(double x, double *sn, double *cs) {
  if (!(fabs(x) < 1e5)) {
    *sn = sin(x);
    *cs = cos(x);
    return;
  }
  const double shift =
      6755399441055744.0; /* 1.5 * 2^52: rounds to an integer */
  double n = (x * 0.6366197723675814 + shift) - shift;
  double r = ((x - n * 1.5707963267341256) - n * 6.077100506303966e-11) -
             n * 2.0222662487959506e-21;
  double z = r * r;
  double sr =
      r +
      r * z *
          (-1.0 / 6 +
           z * (1.0 / 120 +
                z * (-1.0 / 5040 +
                     z * (1.0 / 362880 +
                          z * (-1.0 / 39916800 +
                               z * (1.0 / 6227020800.0 +
                                    z * (-1.0 / 1307674368000.0 +
                                         z * (1.0 / 355687428096000.0))))))));
  double cr =
      1.0 +
      z * (-0.5 +
           z * (1.0 / 24 +
                z * (-1.0 / 720 +
                     z * (1.0 / 40320 +
                          z * (-1.0 / 3628800 +
                               z * (1.0 / 479001600 +
                                    z * (-1.0 / 87178291200.0 +
                                         z * (1.0 / 20922789888000.0 +
                                              z * (-1.0 /
                                                   6402373705728000.0)))))))));
  switch ((long)n & 3) {
  case 0:
    *sn = sr;
    *cs = cr;
    break;
  case 1:
    *sn = cr;
    *cs = -sr;
    break;
  case 2:
    *sn = -sr;
    *cs = -cr;
    break;
  default:
    *sn = -cr;
    *cs = sr;
    break;
  }
}

#endif
