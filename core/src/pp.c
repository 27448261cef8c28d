/* pp.c - piecewise polynomials in Bernstein form, the working form of
 * scalar splines inside the core.
 *
 * B-spline functions are exchanged with callers; the numerics (blending,
 * antiderivatives per piece, bounds on derivatives for error control)
 * are simplest on independent Bernstein pieces, where restriction to a
 * sub-interval and degree elevation are exact and the coefficient hull
 * bounds the values.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "km/limits.h"

void km__pp_init(km_pp *p) { memset(p, 0, sizeof *p); }

void km__pp_free(km_pp *p) {
  if (!p) return;
  free(p->x);
  memset(p, 0, sizeof *p);
}

km_status km__pp_alloc(km_pp *p, int degree, size_t m) {
  size_t total = (m + 1) + m * (size_t)(degree + 1);
  double *block = malloc(total * sizeof(double));
  if (!block) return KM_ENOMEM;
  p->degree = degree;
  p->m = m;
  p->x = block;
  p->c = block + m + 1;
  return KM_OK;
}

double km__bern_eval(const double *c, int d, double u) {
  double b[KM_MAX_FN_DEGREE + 2];
  memcpy(b, c, (size_t)(d + 1) * sizeof(double));
  double v = 1.0 - u;
  for (int r = 1; r <= d; r++)
    for (int j = 0; j <= d - r; j++) b[j] = v * b[j] + u * b[j + 1];
  return b[0];
}

/* Split at u: left coefficients (over [0,u]) into L, right into R (either
 * may be NULL). */
static void bern_split(const double *c, int d, double u, double *L,
                       double *R) {
  double b[KM_MAX_FN_DEGREE + 2];
  memcpy(b, c, (size_t)(d + 1) * sizeof(double));
  double v = 1.0 - u;
  if (L) L[0] = b[0];
  if (R) R[d] = b[d];
  for (int r = 1; r <= d; r++) {
    for (int j = 0; j <= d - r; j++) b[j] = v * b[j] + u * b[j + 1];
    if (L) L[r] = b[0];
    if (R) R[d - r] = b[d - r];
  }
}

void km__bern_restrict(const double *c, int d, double u0, double u1,
                       double *out) {
  double tmp[KM_MAX_FN_DEGREE + 2];
  if (u0 <= 0.0 && u1 >= 1.0) {
    memcpy(out, c, (size_t)(d + 1) * sizeof(double));
    return;
  }
  if (u1 >= 1.0) {
    bern_split(c, d, u0, NULL, out);
    return;
  }
  bern_split(c, d, u1, tmp, NULL);
  if (u0 <= 0.0) {
    memcpy(out, tmp, (size_t)(d + 1) * sizeof(double));
    return;
  }
  bern_split(tmp, d, u0 / u1, NULL, out);
}

void km__bern_elevate(const double *c, int d, int e, double *out) {
  double a[KM_MAX_FN_DEGREE + 2], b[KM_MAX_FN_DEGREE + 2];
  memcpy(a, c, (size_t)(d + 1) * sizeof(double));
  for (int k = d; k < e; k++) {
    b[0] = a[0];
    b[k + 1] = a[k];
    for (int i = 1; i <= k; i++) {
      double al = (double)i / (k + 1);
      b[i] = al * a[i - 1] + (1.0 - al) * a[i];
    }
    memcpy(a, b, (size_t)(k + 2) * sizeof(double));
  }
  memcpy(out, a, (size_t)(e + 1) * sizeof(double));
}

void km__bern_derivative(const double *c, int d, double h, double *out) {
  if (d == 0) {
    out[0] = 0.0;
    return;
  }
  for (int i = 0; i < d; i++) out[i] = d * (c[i + 1] - c[i]) / h;
}

double km__bern_abs_bound(const double *c, int d) {
  double m = 0.0;
  for (int i = 0; i <= d; i++) m = fmax(m, fabs(c[i]));
  return m;
}

size_t km__pp_find(const km_pp *p, double x) {
  if (x <= p->x[0]) return 0;
  if (x >= p->x[p->m]) return p->m - 1;
  size_t lo = 0, hi = p->m; /* x[lo] <= x < x[hi] */
  while (hi - lo > 1) {
    size_t mid = (lo + hi) / 2;
    if (x < p->x[mid])
      hi = mid;
    else
      lo = mid;
  }
  return lo;
}

double km__pp_eval(const km_pp *p, double x) {
  size_t i = km__pp_find(p, x);
  double h = p->x[i + 1] - p->x[i];
  double u = h > 0 ? (x - p->x[i]) / h : 0.0;
  if (u < 0) u = 0;
  if (u > 1) u = 1;
  return km__bern_eval(p->c + i * (size_t)(p->degree + 1), p->degree, u);
}

/* Blossom of the polynomial of span i of a B-spline function at the
 * arguments u[0..p-1] (de Boor's triangle with a different argument per
 * level). */
static double blossom(const km_fn *f, size_t i, const double *u) {
  int p = f->degree;
  double d[KM_MAX_FN_DEGREE + 2];
  const double *U = f->knots;
  for (int j = 0; j <= p; j++) d[j] = f->coef[i - (size_t)p + (size_t)j];
  for (int r = 1; r <= p; r++) {
    for (int j = p; j >= r; j--) {
      double lo = U[i - (size_t)p + (size_t)j];
      double hi = U[i + 1 + (size_t)j - (size_t)r];
      double al = (u[r - 1] - lo) / (hi - lo);
      d[j] = (1.0 - al) * d[j - 1] + al * d[j];
    }
  }
  return d[p];
}

/* True if every distinct knot of f has multiplicity degree + 1: then the
 * coefficients already are the pieces' Bernstein coefficients (the layout
 * km__pp_to_fn writes). */
static bool is_piecewise_bezier(const km_fn *f) {
  size_t nk = f->n + (size_t)f->degree + 1, run = 1;
  for (size_t i = 1; i < nk; i++) {
    if (f->knots[i] == f->knots[i - 1]) {
      run++;
    } else {
      if (run != (size_t)f->degree + 1) return false;
      run = 1;
    }
  }
  return run == (size_t)f->degree + 1;
}

km_status km__pp_from_fn(km_pp *out, const km_fn *f) {
  int p = f->degree;
  if (is_piecewise_bezier(f)) {
    size_t m = f->n / (size_t)(p + 1);
    km_pp r;
    if (km__pp_alloc(&r, p, m)) return KM_ENOMEM;
    for (size_t i = 0; i <= m; i++) r.x[i] = f->knots[i * (size_t)(p + 1)];
    memcpy(r.c, f->coef, f->n * sizeof(double));
    *out = r;
    return KM_OK;
  }
  size_t m = 0;
  for (size_t i = (size_t)p; i < f->n; i++)
    if (f->knots[i + 1] > f->knots[i]) m++;
  km_pp r;
  if (km__pp_alloc(&r, p, m)) return KM_ENOMEM;
  size_t k = 0;
  double u[KM_MAX_FN_DEGREE + 2];
  for (size_t i = (size_t)p; i < f->n; i++) {
    double a = f->knots[i], b = f->knots[i + 1];
    if (!(b > a)) continue;
    r.x[k] = a;
    r.x[k + 1] = b;
    double *c = r.c + k * (size_t)(p + 1);
    for (int j = 0; j <= p; j++) {
      for (int q = 0; q < p; q++) u[q] = q < p - j ? a : b;
      c[j] = p == 0 ? f->coef[i] : blossom(f, i, u);
    }
    k++;
  }
  *out = r;
  return KM_OK;
}

km_status km__pp_to_fn(km_fn *out, const km_pp *p) {
  int d = p->degree;
  size_t n = p->m * (size_t)(d + 1);
  km_fn f;
  if (km__fn_alloc(&f, d, n)) return KM_ENOMEM;
  size_t k = 0;
  for (size_t i = 0; i <= p->m; i++) {
    int mult = d + 1;
    for (int j = 0; j < mult; j++) f.knots[k++] = p->x[i];
  }
  memcpy(f.coef, p->c, n * sizeof(double));
  *out = f;
  return KM_OK;
}
