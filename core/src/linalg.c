/* linalg.c - small helpers the numerics share: the Bernstein basis, a comparison for qsort, and a radix-2 FFT
 * (cyclic correlations of sampled turning functions). */
#include <math.h>

#include "internal.h"
#include "kernels.h"

void km__bernstein_basis(double u, int d, double *row) {
  double v = 1.0 - u;
  row[0] = 1.0;
  for (int j = 1; j <= d; j++) {
    double saved = 0.0;
    for (int k = 0; k < j; k++) {
      double tmp = row[k];
      row[k] = saved + v * tmp;
      saved = u * tmp;
    }
    row[j] = saved;
  }
}

int km__cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

void km__fft_twiddles(int n, double *tw) {
  for (int k = 0; k < n / 2; k++) {
    double a = -2.0 * KM_PI * k / n;
    tw[2 * k] = cos(a);
    tw[2 * k + 1] = sin(a);
  }
}

void km__fft(double *re, double *im, int n, const double *tw, bool inverse) {
  /* bit-reversal permutation */
  for (int i = 1, j = 0; i < n; i++) {
    int bit = n >> 1;
    for (; j & bit; bit >>= 1) j ^= bit;
    j ^= bit;
    if (i < j) {
      double t = re[i];
      re[i] = re[j];
      re[j] = t;
      t = im[i];
      im[i] = im[j];
      im[j] = t;
    }
  }
  /* butterflies; the stage of length len uses every (n / len)-th twiddle */
  for (int len = 2; len <= n; len <<= 1) {
    int step = n / len;
    for (int i = 0; i < n; i += len)
      for (int k = 0; k < len / 2; k++) {
        double wr = tw[2 * k * step], wi = tw[2 * k * step + 1];
        if (inverse) wi = -wi;
        int a = i + k, b = a + len / 2;
        double xr = re[b] * wr - im[b] * wi, xi = re[b] * wi + im[b] * wr;
        re[b] = re[a] - xr;
        im[b] = im[a] - xi;
        re[a] += xr;
        im[a] += xi;
      }
  }
  if (inverse)
    for (int i = 0; i < n; i++) {
      re[i] /= n;
      im[i] /= n;
    }
}
