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
#include <string.h>

#include "internal.h"
#include "kernels.h"
#include "km/alloc.h"
#include "km/limits.h"

void km__pp_init(km_pp *p) {
  memset(p, 0, sizeof *p);
}

void km__pp_free(km_pp *p) {
  if (!p) return;
  km__free(p->x);
  memset(p, 0, sizeof *p);
}

km_status km__pp_alloc(km_pp *p, int degree, size_t m) {
  size_t total = (m + 1) + m * (size_t)(degree + 1);
  double *block = km__malloc(total * sizeof(double));
  if (!block) return KM_ENOMEM;
  p->degree = degree;
  p->m = m;
  p->x = block;
  p->c = block + m + 1;
  return KM_OK;
}

/* Binomial coefficients C(d, j), d <= KM_MAX_FN_DEGREE + 1 (Pascal's
 * triangle; every entry is exact in double). */
const double km__binomial[KM_MAX_FN_DEGREE + 2][KM_MAX_FN_DEGREE + 2] = {
    {1},
    {1, 1},
    {1, 2, 1},
    {1, 3, 3, 1},
    {1, 4, 6, 4, 1},
    {1, 5, 10, 10, 5, 1},
    {1, 6, 15, 20, 15, 6, 1},
    {1, 7, 21, 35, 35, 21, 7, 1},
    {1, 8, 28, 56, 70, 56, 28, 8, 1},
    {1, 9, 36, 84, 126, 126, 84, 36, 9, 1},
    {1, 10, 45, 120, 210, 252, 210, 120, 45, 10, 1},
    {1, 11, 55, 165, 330, 462, 462, 330, 165, 55, 11, 1},
    {1, 12, 66, 220, 495, 792, 924, 792, 495, 220, 66, 12, 1},
    {1, 13, 78, 286, 715, 1287, 1716, 1716, 1287, 715, 286, 78, 13, 1},
    {1, 14, 91, 364, 1001, 2002, 3003, 3432, 3003, 2002, 1001, 364, 91, 14, 1},
    {1, 15, 105, 455, 1365, 3003, 5005, 6435, 6435, 5005, 3003, 1365, 455, 105,
     15, 1},
    {1, 16, 120, 560, 1820, 4368, 8008, 11440, 12870, 11440, 8008, 4368, 1820,
     560, 120, 16, 1},
    {1, 17, 136, 680, 2380, 6188, 12376, 19448, 24310, 24310, 19448, 12376,
     6188, 2380, 680, 136, 17, 1},
    {1, 18, 153, 816, 3060, 8568, 18564, 31824, 43758, 48620, 43758, 31824,
     18564, 8568, 3060, 816, 153, 18, 1},
    {1,     19,    171,   969,   3876,  11628, 27132, 50388, 75582, 92378,
     92378, 75582, 50388, 27132, 11628, 3876,  969,   171,   19,    1},
    {1,     20,     190,    1140,   4845,   15504,  38760,
     77520, 125970, 167960, 184756, 167960, 125970, 77520,
     38760, 15504,  4845,   1140,   190,    20,     1},
    {1,      21,     210,    1330,   5985,   20349,  54264,  116280,
     203490, 293930, 352716, 352716, 293930, 203490, 116280, 54264,
     20349,  5985,   1330,   210,    21,     1},
};

double km__bern_eval(const double *c, int d, double u) {
  /* Horner in s = u / (1 - u) (or its reciprocal past the middle, so that
   * s <= 1): sum c_j C(d, j) u^j (1-u)^(d-j) = (1-u)^d sum c_j C(d, j) s^j.
   * Its rounding error is bounded like de Casteljau's, (2d + 1) eps
   * sum |c_j| B_j(u) (Schumaker and Volk), at O(d) instead of O(d^2): this
   * is the innermost call of signatures, tables and plans. */
  if (d == 0) return c[0];
  const double *bn = km__binomial[d];
  double v = 1.0 - u, acc, f = 1.0;
  if (u <= 0.5) {
    double s = u / v;
    acc = c[d];
    for (int j = d - 1; j >= 0; j--) acc = acc * s + c[j] * bn[j];
    for (int j = 0; j < d; j++) f *= v;
  } else {
    double s = v / u;
    acc = c[0];
    for (int j = 1; j <= d; j++) acc = acc * s + c[j] * bn[j];
    for (int j = 0; j < d; j++) f *= u;
  }
  return acc * f;
}

/* Split at u: left coefficients (over [0,u]) into L, right into R (either
 * may be NULL). */
static void bern_split(const double *c, int d, double u, double *L, double *R) {
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

void km__bern_halves(const double *c, int d, double *L, double *R) {
  bern_split(c, d, 0.5, L, R);
}

void km__bern_restrict(const double *c, int d, double u0, double u1,
                       double *out) {
  double tmp[KM_MAX_FN_DEGREE + 2];
  if (u0 <= 0.0 && u1 >= 1.0) {
    /* a few values: a loop, not a call to memcpy */
    for (int i = 0; i <= d; i++) out[i] = c[i];
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
  if (e <= d) {
    for (int i = 0; i <= d; i++) out[i] = c[i];
    return;
  }
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
  return km__bracket(p->x, 0, p->m, x); /* x[0] < x < x[m] */
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

void km__fn_pieces_start(km__fn_pieces *it, const km_fn *f) {
  it->f = f;
  it->bezier = is_piecewise_bezier(f);
  it->i = it->bezier ? 0 : (size_t)f->degree;
}

bool km__fn_pieces_next(km__fn_pieces *it, double x[2], double *c) {
  const km_fn *f = it->f;
  int p = f->degree;
  size_t w = (size_t)(p + 1);
  double u[KM_MAX_FN_DEGREE + 2];
  if (it->bezier) {
    if (it->i >= f->n / w) return false;
    x[0] = f->knots[it->i * w];
    x[1] = f->knots[(it->i + 1) * w];
    memcpy(c, f->coef + it->i * w, w * sizeof(double));
    it->i++;
    return true;
  }
  for (; it->i < f->n; it->i++) {
    size_t i = it->i;
    double a = f->knots[i], b = f->knots[i + 1];
    if (!(b > a)) continue;
    x[0] = a;
    x[1] = b;
    for (int j = 0; j <= p; j++) {
      for (int q = 0; q < p; q++) u[q] = q < p - j ? a : b;
      c[j] = p == 0 ? f->coef[i] : blossom(f, i, u);
    }
    it->i++;
    return true;
  }
  return false;
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

/* ---- merging pieces ------------------------------------------------------
 * A signature keeps a break at every knot of its curve, so a smooth curve
 * of many control points has as many pieces although a few would carry it.
 * Work that is proportional to the number of pieces (morph frames: every
 * merged break of two inputs costs quadrature nodes) merges them first:
 * one polynomial of degree d interpolating p at the Chebyshev-Lobatto
 * points of a run of pieces replaces the run where it stays within delta of
 * p. That is checked on the Bernstein coefficients of the difference over
 * every original piece of the run, which bound the difference there, so
 * the merged function is within delta of p everywhere, not only where it
 * was sampled. The interpolant meets p at the run's ends, so continuity is
 * kept; runs never cross a jump. */

typedef struct merge_fit {
  int d;
  double u[KM_MAX_FN_DEGREE + 2]; /* nodes */
  double inv[(KM_MAX_FN_DEGREE + 2) *
             (KM_MAX_FN_DEGREE + 2)]; /* values -> coefficients */
} merge_fit;

static bool merge_fit_make(merge_fit *mf, int d) {
  int n = d + 1;
  double A[(KM_MAX_FN_DEGREE + 2) * (KM_MAX_FN_DEGREE + 2)];
  double y[KM_MAX_FN_DEGREE + 2];
  mf->d = d;
  for (int k = 0; k <= d; k++) mf->u[k] = 0.5 * (1.0 - cos(KM_PI * k / d));
  mf->u[0] = 0.0;
  mf->u[d] = 1.0;
  for (int j = 0; j < n; j++) {
    for (int k = 0; k < n; k++) km__bernstein_basis(mf->u[k], d, A + k * n);
    for (int k = 0; k < n; k++) y[k] = k == j ? 1.0 : 0.0;
    if (!km__solve_dense(A, y, n)) return false;
    for (int k = 0; k < n; k++) mf->inv[k * n + j] = y[k];
  }
  return true;
}

/* Fits pieces [i0, i1) of p with one polynomial (coefficients into coef)
 * and returns whether it stays within delta of every piece. */
static bool merge_try(const km_pp *p, const merge_fit *mf, size_t i0, size_t i1,
                      double delta, double *coef) {
  int d = mf->d, n = d + 1, dp = p->degree;
  double X0 = p->x[i0], W = p->x[i1] - X0, v[KM_MAX_FN_DEGREE + 2];
  size_t i = i0;
  for (int k = 0; k < n; k++) {
    double x = X0 + W * mf->u[k];
    while (i + 1 < i1 && x >= p->x[i + 1]) i++;
    double h = p->x[i + 1] - p->x[i];
    double u = fmin(fmax((x - p->x[i]) / h, 0.0), 1.0);
    v[k] = km__bern_eval(p->c + i * (size_t)(dp + 1), dp, u);
  }
  v[0] = p->c[i0 * (size_t)(dp + 1)];
  v[d] = p->c[(i1 - 1) * (size_t)(dp + 1) + (size_t)dp];
  for (int j = 0; j < n; j++) {
    double s = 0.0;
    for (int k = 0; k < n; k++) s += mf->inv[j * n + k] * v[k];
    coef[j] = s;
  }
  coef[0] = v[0];
  coef[d] = v[d];
  for (i = i0; i < i1; i++) {
    double r[KM_MAX_FN_DEGREE + 2], o[KM_MAX_FN_DEGREE + 2];
    km__bern_restrict(coef, d, (p->x[i] - X0) / W, (p->x[i + 1] - X0) / W, r);
    km__bern_elevate(p->c + i * (size_t)(dp + 1), dp, d, o);
    for (int j = 0; j < n; j++)
      if (!(fabs(r[j] - o[j]) <= delta)) return false;
  }
  return true;
}

km_status km__pp_merge(const km_pp *p, int degree, double delta, km_pp *out) {
  int d = degree > p->degree ? degree : p->degree;
  size_t m = p->m, dp = (size_t)p->degree;
  merge_fit *mf = km__malloc(sizeof *mf);
  double *x = km__malloc((m + 1) * sizeof(double));
  double *c = km__malloc(m * (size_t)(d + 1) * sizeof(double));
  km_status st = mf && x && c ? KM_OK : KM_ENOMEM;
  if (!st && !merge_fit_make(mf, d)) st = KM_ENOCONVERGE;
  size_t np = 0, i = 0;
  while (!st && i < m) {
    /* the run may extend up to the next jump */
    size_t lim = i + 1;
    while (lim < m && fabs(p->c[lim * (dp + 1)] -
                           p->c[(lim - 1) * (dp + 1) + dp]) <= 0.25 * delta)
      lim++;
    double *coef = c + np * (size_t)(d + 1);
    size_t good = i + 1, bad = lim + 1;
    double trial[KM_MAX_FN_DEGREE + 2];
    /* grow the run geometrically, then bisect between the longest that
     * fits and the shortest that does not */
    for (size_t k = 2; i + k <= lim; k *= 2) {
      if (merge_try(p, mf, i, i + k, delta, trial)) {
        good = i + k;
        memcpy(coef, trial, (size_t)(d + 1) * sizeof(double));
      } else {
        bad = i + k;
        break;
      }
    }
    if (bad > lim && good < lim) {
      if (merge_try(p, mf, i, lim, delta, trial)) {
        good = lim;
        memcpy(coef, trial, (size_t)(d + 1) * sizeof(double));
      } else {
        bad = lim;
      }
    }
    while (bad - good > 1) {
      size_t mid = good + (bad - good) / 2;
      if (merge_try(p, mf, i, mid, delta, trial)) {
        good = mid;
        memcpy(coef, trial, (size_t)(d + 1) * sizeof(double));
      } else {
        bad = mid;
      }
    }
    if (good == i + 1)
      km__bern_elevate(p->c + i * (dp + 1), p->degree, d, coef);
    x[np] = p->x[i];
    np++;
    i = good;
  }
  if (st) {
    km__free(mf);
    km__free(x);
    km__free(c);
    return st;
  }
  x[np] = p->x[m];
  km_pp r;
  st = km__pp_alloc(&r, d, np);
  if (!st) {
    memcpy(r.x, x, (np + 1) * sizeof(double));
    memcpy(r.c, c, np * (size_t)(d + 1) * sizeof(double));
    *out = r;
  }
  km__free(mf);
  km__free(x);
  km__free(c);
  return st;
}

km_status km__pp_derivative(const km_pp *p, km_pp *out) {
  int d = p->degree;
  km_pp r;
  km_status st = km__pp_alloc(&r, d > 0 ? d - 1 : 0, p->m);
  if (st) return st;
  memcpy(r.x, p->x, (p->m + 1) * sizeof(double));
  for (size_t i = 0; i < p->m; i++)
    km__bern_derivative(p->c + i * (size_t)(d + 1), d, p->x[i + 1] - p->x[i],
                        r.c + i * (size_t)(r.degree + 1));
  *out = r;
  return KM_OK;
}
