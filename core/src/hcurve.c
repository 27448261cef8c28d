/* hcurve.c - homogeneous B-spline workspaces (hcurve.h): conversion from
 * and to curves, knot refinement, Bezier extraction, knot removal and
 * degree elevation.
 *
 * DESIGN. Insertion is knot refinement (Piegl & Tiller A5.4). Degree
 * elevation extracts the Bezier pieces, elevates each one (the Bernstein
 * elevation formula) and then removes every interior knot back down to its
 * original multiplicity plus `times`; the removals are exact because the
 * elevated curve keeps the continuity the original had. Removal solves the
 * removal equations from both ends towards the middle, so no long
 * one-sided recurrence amplifies rounding.
 */
#include <math.h>
#include <string.h>

#include "hcurve.h"
#include "internal.h"
#include "kernels.h"
#include "km/alloc.h"
#include "km/curve.h"
#include "km/limits.h"

void km__h_init(km__hcurve *h) {
  memset(h, 0, sizeof *h);
}

void km__h_free(km__hcurve *h) {
  if (!h) return;
  km__free(h->knots);
  memset(h, 0, sizeof *h);
}

km_status km__h_alloc(km__hcurve *h, int degree, int dim, size_t n) {
  size_t nk = n + (size_t)degree + 1;
  if (n == 0 || n > ((size_t)-1) / sizeof(double) / 8) return KM_ENOMEM;
  double *block = km__malloc((nk + n * (size_t)dim) * sizeof(double));
  if (!block) return KM_ENOMEM;
  h->degree = degree;
  h->dim = dim;
  h->n = n;
  h->knots = block;
  h->pw = block + nk;
  return KM_OK;
}

double km__binom(int n, int k) {
  if (k < 0 || k > n) return 0.0;
  double r = 1.0;
  for (int i = 1; i <= k; i++) r = r * (double)(n - k + i) / (double)i;
  return r;
}

km_status km__h_from_curve(km__hcurve *h, const km_curve *c, int dim) {
  if (c->w) dim = 3;
  km_status st = km__h_alloc(h, c->degree, dim, c->n);
  if (st) return st;
  memcpy(h->knots, c->knots, (c->n + (size_t)c->degree + 1) * sizeof(double));
  for (size_t i = 0; i < c->n; i++) {
    double w = c->w ? c->w[i] : 1.0;
    if (dim == 3) {
      h->pw[3 * i] = w * c->cp[2 * i];
      h->pw[3 * i + 1] = w * c->cp[2 * i + 1];
      h->pw[3 * i + 2] = w;
    } else {
      h->pw[2 * i] = c->cp[2 * i];
      h->pw[2 * i + 1] = c->cp[2 * i + 1];
    }
  }
  return KM_OK;
}

km_status km__h_to_curve(km_curve *out, const km__hcurve *h, bool closed) {
  km_curve r;
  km_status st = km__curve_alloc(&r, h->degree, h->n, h->dim == 3);
  if (st) return st;
  memcpy(r.knots, h->knots, (h->n + (size_t)h->degree + 1) * sizeof(double));
  for (size_t i = 0; i < h->n; i++) {
    if (h->dim == 3) {
      double w = h->pw[3 * i + 2];
      if (!(w > 0)) {
        km_curve_free(&r);
        return isfinite(w) ? KM_EWEIGHT : KM_ENONFINITE;
      }
      r.w[i] = w;
      r.cp[2 * i] = h->pw[3 * i] / w;
      r.cp[2 * i + 1] = h->pw[3 * i + 1] / w;
    } else {
      r.cp[2 * i] = h->pw[2 * i];
      r.cp[2 * i + 1] = h->pw[2 * i + 1];
    }
    if (!isfinite(r.cp[2 * i]) || !isfinite(r.cp[2 * i + 1])) {
      km_curve_free(&r);
      return KM_ENONFINITE;
    }
  }
  r.closed = closed;
  if (closed) {
    /* the seam is unchanged by every exact operation; keep it bit-exact
     * although w x / w may round differently at the two ends */
    r.cp[2 * (h->n - 1)] = r.cp[0];
    r.cp[2 * (h->n - 1) + 1] = r.cp[1];
  }
  *out = r;
  return KM_OK;
}

km_status km__h_refine(km__hcurve *out, const km__hcurve *h, const double *x,
                       size_t nx) {
  int p = h->degree, d = h->dim;
  size_t n = h->n;
  km__hcurve q;
  km_status st = km__h_alloc(&q, p, d, n + nx);
  if (st) return st;
  const double *U = h->knots, *P = h->pw;
  double *Ub = q.knots, *Q = q.pw;
  size_t m = n + (size_t)p; /* last knot index */
  if (nx == 0) {
    memcpy(Ub, U, (m + 1) * sizeof(double));
    memcpy(Q, P, n * (size_t)d * sizeof(double));
    *out = q;
    return KM_OK;
  }
  /* A5.4 with r = nx - 1 and n = last point index; all indices >= 0 */
  size_t r = nx - 1, nl = n - 1;
  size_t a = km__knot_span(U, n, p, x[0]);
  size_t b = km__knot_span(U, n, p, x[r]) + 1;
  for (size_t j = 0; j <= a - (size_t)p; j++)
    memcpy(Q + j * (size_t)d, P + j * (size_t)d, (size_t)d * sizeof(double));
  for (size_t j = b - 1; j <= nl; j++)
    memcpy(Q + (j + r + 1) * (size_t)d, P + j * (size_t)d,
           (size_t)d * sizeof(double));
  for (size_t j = 0; j <= a; j++) Ub[j] = U[j];
  for (size_t j = b + (size_t)p; j <= m; j++) Ub[j + r + 1] = U[j];
  size_t i = b + (size_t)p - 1, k = b + (size_t)p + r;
  for (size_t jj = nx; jj-- > 0;) {
    while (x[jj] <= U[i] && i > a) {
      memcpy(Q + (k - (size_t)p - 1) * (size_t)d,
             P + (i - (size_t)p - 1) * (size_t)d, (size_t)d * sizeof(double));
      Ub[k] = U[i];
      k--;
      i--;
    }
    memcpy(Q + (k - (size_t)p - 1) * (size_t)d, Q + (k - (size_t)p) * (size_t)d,
           (size_t)d * sizeof(double));
    for (int l = 1; l <= p; l++) {
      size_t ind = k - (size_t)p + (size_t)l;
      double alfa = Ub[k + (size_t)l] - x[jj];
      double *dst = Q + (ind - 1) * (size_t)d;
      const double *src = Q + ind * (size_t)d;
      if (alfa == 0.0) {
        memcpy(dst, src, (size_t)d * sizeof(double));
      } else {
        alfa /= Ub[k + (size_t)l] - U[i - (size_t)p + (size_t)l];
        for (int e = 0; e < d; e++)
          dst[e] = alfa * dst[e] + (1.0 - alfa) * src[e];
      }
    }
    Ub[k] = x[jj];
    k--;
  }
  *out = q;
  return KM_OK;
}

km_status km__h_to_bezier(km__hcurve *out, const km__hcurve *h) {
  int p = h->degree;
  size_t n = h->n;
  const double *U = h->knots;
  size_t cnt = 0;
  for (size_t i = (size_t)p + 1; i < n;) {
    size_t j = i;
    while (j + 1 < n && U[j + 1] == U[i]) j++;
    size_t s = j - i + 1;
    if (s < (size_t)p) cnt += (size_t)p - s;
    i = j + 1;
  }
  double *x = NULL;
  if (cnt) {
    x = km__malloc(cnt * sizeof(double));
    if (!x) return KM_ENOMEM;
  }
  size_t c = 0;
  for (size_t i = (size_t)p + 1; i < n;) {
    size_t j = i;
    while (j + 1 < n && U[j + 1] == U[i]) j++;
    size_t s = j - i + 1;
    for (; s < (size_t)p; s++) x[c++] = U[i];
    i = j + 1;
  }
  km_status st = km__h_refine(out, h, x, cnt);
  km__free(x);
  return st;
}

void km__h_remove_knot(km__hcurve *h, size_t r) {
  int p = h->degree, d = h->dim;
  size_t n = h->n;
  double *U = h->knots, *P = h->pw;
  double u = U[r];
  size_t s = 1;
  while (s <= r && U[r - s] == u) s++;
  if (s <= (size_t)p) {
    /* Unknowns Q[L..R]; Q[L-1] = P[L-1] and Q[R+1] = P[R+2] are kept. The
     * insertion equations P[i] = a_i Q[i] + (1 - a_i) Q[i-1], i = L..R+1,
     * are one more than the unknowns: solve the first half from the left,
     * the second from the right, and leave the middle one (consistency)
     * unused. */
    size_t L = r - (size_t)p, nu = (size_t)p - s;
    double tmp[(KM_MAX_DEGREE + 2) * 3];
    memcpy(tmp, P + (L - 1) * (size_t)d, (size_t)d * sizeof(double));
    memcpy(tmp + (nu + 1) * (size_t)d, P + (r - s + 1) * (size_t)d,
           (size_t)d * sizeof(double));
    size_t nleft = (nu + 1) / 2;
    for (size_t k = 0; k < nleft; k++) {
      size_t i = L + k;
      double a = (u - U[i]) / (U[i + (size_t)p + 1] - U[i]);
      for (int e = 0; e < d; e++)
        tmp[(k + 1) * (size_t)d + (size_t)e] =
            (P[i * (size_t)d + (size_t)e] -
             (1.0 - a) * tmp[k * (size_t)d + (size_t)e]) /
            a;
    }
    for (size_t k = nu; k > nleft; k--) {
      /* equation i = L + k gives Q[L+k-1] = tmp[k] from Q[L+k] = tmp[k+1] */
      size_t i = L + k;
      double a = (u - U[i]) / (U[i + (size_t)p + 1] - U[i]);
      for (int e = 0; e < d; e++)
        tmp[k * (size_t)d + (size_t)e] =
            (P[i * (size_t)d + (size_t)e] -
             a * tmp[(k + 1) * (size_t)d + (size_t)e]) /
            (1.0 - a);
    }
    memcpy(P + L * (size_t)d, tmp + (size_t)d, nu * (size_t)d * sizeof(double));
  }
  /* drop P[r-s] (now Q[R] sits at r-s-1) and the knot U[r] */
  size_t drop = r - s; /* old P[r-s] has no successor in the new curve */
  memmove(P + drop * (size_t)d, P + (drop + 1) * (size_t)d,
          (n - drop - 1) * (size_t)d * sizeof(double));
  memmove(U + r, U + r + 1, (n + (size_t)p - r) * sizeof(double));
  h->n = n - 1;
}

km_status km__h_elevate(km__hcurve *out, const km__hcurve *h, int times) {
  int p = h->degree, d = h->dim, q = p + times;
  if (times == 0) return km__h_refine(out, h, NULL, 0);
  km__hcurve bz, e;
  km__h_init(&bz);
  km__h_init(&e);
  size_t *mult = NULL;
  km_status st = KM_OK;
  size_t n = h->n;
  const double *U = h->knots;
  /* original multiplicities of the distinct interior knots */
  size_t nd = 0;
  for (size_t i = (size_t)p + 1; i < n; i++)
    if (U[i] != U[i - 1]) nd++;
  if (nd) {
    mult = km__malloc(nd * sizeof *mult);
    if (!mult) {
      st = KM_ENOMEM;
      goto cleanup;
    }
  }
  {
    size_t k = 0;
    for (size_t i = (size_t)p + 1; i < n;) {
      size_t j = i;
      while (j + 1 < n && U[j + 1] == U[i]) j++;
      mult[k++] = j - i + 1;
      i = j + 1;
    }
  }
  st = km__h_to_bezier(&bz, h);
  if (st) goto cleanup;
  size_t pieces = (bz.n - 1) / (size_t)p;
  st = km__h_alloc(&e, q, d, pieces * (size_t)q + 1);
  if (st) goto cleanup;
  {
    size_t k = 0;
    for (int j = 0; j <= q; j++) e.knots[k++] = bz.knots[0];
    for (size_t pc = 1; pc < pieces; pc++)
      for (int j = 0; j < q; j++) e.knots[k++] = bz.knots[pc * (size_t)p + 1];
    for (int j = 0; j <= q; j++) e.knots[k++] = bz.knots[bz.n + (size_t)p];
  }
  for (size_t pc = 0; pc < pieces; pc++) {
    const double *b = bz.pw + pc * (size_t)p * (size_t)d;
    double *o = e.pw + pc * (size_t)q * (size_t)d;
    for (int i = 0; i <= q; i++) {
      double acc[3] = {0, 0, 0};
      int jlo = i - times > 0 ? i - times : 0, jhi = i < p ? i : p;
      double inv = 1.0 / km__binom(q, i);
      for (int j = jlo; j <= jhi; j++) {
        double f = km__binom(p, j) * km__binom(times, i - j) * inv;
        for (int c = 0; c < d; c++) acc[c] += f * b[j * d + c];
      }
      for (int c = 0; c < d; c++) o[i * d + c] = acc[c];
    }
  }
  /* back to the original continuity, right to left so that the indices of
   * the knots still to be treated do not move */
  for (size_t k = nd; k-- > 0;) {
    size_t r = (size_t)q + (k + 1) * (size_t)q;
    for (size_t t = mult[k]; t < (size_t)p; t++) km__h_remove_knot(&e, r--);
  }
  *out = e;
  km__h_init(&e);
cleanup:
  km__h_free(&bz);
  km__h_free(&e);
  km__free(mult);
  return st;
}
