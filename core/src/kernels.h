/* kernels.h - the small numeric kernels libkmorph shares; internal.
 *
 * One copy of each: the knot-span search and the cubic B-spline basis
 * (kernels.c), the dense solver, the Bernstein basis, the comparison of
 * doubles for qsort and the FFT (linalg.c). Every function here is pure:
 * it reads its arguments and writes only the arrays it is given.
 */
#ifndef KM_KERNELS_H
#define KM_KERNELS_H

#include <stdbool.h>
#include <stddef.h>

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
 * partly eliminated). */
bool km__solve_dense(double *A, double *y, int n);
/* The d+1 Bernstein basis values B_k^d(u) into row[0..d]. */
void km__bernstein_basis(double u, int d, double *row);
/* qsort comparison of doubles, ascending (NaN compares equal to all). */
int km__cmp_double(const void *a, const void *b);
/* Discrete Fourier transform of n = 2^k complex values in place (X_m = sum
 * x_j e^(-2 pi i j m / n); inverse: with e^(+...) and divided by n), with
 * the n/2 twiddles e^(-2 pi i k / n) from km__fft_twiddles (2 per k). */
void km__fft_twiddles(int n, double *tw);
void km__fft(double *re, double *im, int n, const double *tw, bool inverse);

#endif
