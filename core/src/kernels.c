/* kernels.c - the knot-span search and the cubic B-spline basis, shared
 * by evaluation, refinement, interpolation and fitting (kernels.h). */
#include "kernels.h"

size_t km__knot_span(const double *U, size_t n, int p, double u) {
  size_t lo = (size_t)p, hi = n;
  /* the ends step over repeated knots, so the span found is not empty */
  if (u >= U[n]) {
    lo = n - 1;
    while (lo > (size_t)p && U[lo] == U[n]) lo--;
    return lo;
  }
  if (u <= U[p]) {
    while (lo < n - 1 && U[lo + 1] == U[p]) lo++;
    return lo;
  }
  return km__bracket(U, lo, hi, u); /* U[lo] <= u < U[hi] */
}

void km__cubic_basis(const double *U, size_t i, double u, double N[4]) {
  double left[4], right[4];
  N[0] = 1.0;
  for (int j = 1; j <= 3; j++) {
    left[j] = u - U[i + 1 - (size_t)j];
    right[j] = U[i + (size_t)j] - u;
    double saved = 0.0;
    for (int r = 0; r < j; r++) {
      double den = right[r + 1] + left[j - r];
      double tmp = den != 0 ? N[r] / den : 0.0;
      N[r] = saved + right[r + 1] * tmp;
      saved = left[j - r] * tmp;
    }
    N[j] = saved;
  }
}
