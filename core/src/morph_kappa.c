/* morph_kappa.c - the curvature of a planned morph's frames, tabled once.
 *
 * DESIGN. Without matches, frame t of the turning blend has, at the
 * normalised arc length r of every frame (x = r L_t of its own),
 *     kappa_t = w_a A(r) + w_b B(r) + sum_j d_j psi_j(r),
 *     w_a = (1 - t) La / L_t,  w_b = t Lb / L_t,  d_j = NB c_j / L_t,
 * with A(r) = kappa_a(r La), B(r) = kappa_b(r Lb), and psi_j(r) =
 * B3'(NB r - j) the derivatives of the lsq closure's basis (morph_closure.c;
 * c its coefficients, none for an open frame or one closed by turning its
 * corners). Only the weights depend on t. So the breaks of both inputs and
 * of the basis are merged once, and every function is tabled on them in
 * Bernstein form (A and B exactly, each psi_j quadratic on a piece): a
 * frame's curvature is then a weighted sum per piece, its largest |value|
 * a hull search on those sums, and its energy, the integral of kappa^2
 * over x, the quadratic form L_t v' G v in v = (w_a, w_b, d) with G the
 * Gram matrix of the functions over r, also tabled. Before, every frame
 * with metrics merged the breaks, restricted both inputs' pieces to them
 * and elevated them, then did the same again for psi: two thirds of what
 * its metrics cost.
 */
#include <math.h>
#include <string.h>

#include "km/alloc.h"
#include "morph_closure.h"
#include "morph_kappa.h"

#define NB KM__CLOSURE_INTERVALS
#define NF (KM__CLOSURE_INTERVALS - 3)
#define NV (2 + NF) /* the weights: w_a, w_b, then the d_j */

struct km__kappa_table {
  int e;       /* degree of every tabled piece */
  size_t m;    /* pieces */
  double *r;   /* m + 1 breaks in [0, 1] */
  double *a;   /* m * (e + 1): A on each piece */
  double *b;   /* m * (e + 1): B on each piece */
  double *psi; /* m * 4 * (e + 1): psi_(lo + q), q = 0..3, on each piece */
  int *lo;     /* m: the first basis function not zero on the piece */
  double G[NV * NV];
};

void km__kappa_table_free(km__kappa_table *k) {
  if (!k) return;
  km__free(k->r);
  km__free(k->a);
  km__free(k->b);
  km__free(k->psi);
  km__free(k->lo);
  km__free(k);
}

/* psi_j on [r0, r1] of basis interval iv (the quadratic from its values
 * at the ends and the middle), elevated to degree e. */
static void psi_piece(int j, double r0, double r1, int e, double *out) {
  double u0 = NB * r0, u1 = NB * r1, f[3];
  f[0] = km__bspline3_d(u0 - j);
  f[1] = km__bspline3_d(0.5 * (u0 + u1) - j);
  f[2] = km__bspline3_d(u1 - j);
  double q[3] = {f[0], 2 * f[1] - 0.5 * (f[0] + f[2]), f[2]};
  km__bern_elevate(q, 2, e, out);
}

/* The breaks of ka, kb and the basis intervals, merged (as km__pp_blend
 * merges them) into k->r, k->m. */
static km_status merged_breaks(const km_pp *ka, const km_pp *kb,
                               km__kappa_table *k) {
  km_pp U, ab, all;
  km__pp_init(&U);
  km__pp_init(&ab);
  km__pp_init(&all);
  km_status st = km__pp_alloc(&U, 0, NB);
  if (!st) {
    for (int i = 0; i < NB; i++) {
      U.x[i] = (double)i / NB;
      U.c[i] = 0.0;
    }
    U.x[NB] = 1.0;
    st = km__pp_blend(&ab, ka, 0.0, kb, 0.0, 0.0, 1.0);
  }
  if (!st) st = km__pp_blend(&all, &ab, 0.0, &U, 0.0, 0.0, 1.0);
  if (!st) {
    k->m = all.m;
    k->r = all.x;
    all.x = NULL;
  }
  km__pp_free(&U);
  km__pp_free(&ab);
  km__pp_free(&all);
  return st;
}

/* The Gram matrix of the tabled functions over r in [0, 1]. */
static void gram(km__kappa_table *k) {
  int e = k->e;
  size_t s = (size_t)(e + 1);
  km__bern_weights w;
  km__bern_product_weights(e, w);
  memset(k->G, 0, sizeof k->G);
  for (size_t i = 0; i < k->m; i++) {
    const double *f[6];
    int idx[6], n = 0;
    f[n] = k->a + i * s;
    idx[n++] = 0;
    f[n] = k->b + i * s;
    idx[n++] = 1;
    for (int q = 0; q < 4; q++) {
      int j = k->lo[i] + q;
      if (j < 0 || j >= NF) continue;
      f[n] = k->psi + (4 * i + (size_t)q) * s;
      idx[n++] = 2 + j;
    }
    double h = k->r[i + 1] - k->r[i];
    for (int p = 0; p < n; p++)
      for (int q = p; q < n; q++) {
        double v = h * km__bern_inner(w, f[p], f[q], e);
        k->G[idx[p] * NV + idx[q]] += v;
        if (idx[p] != idx[q]) k->G[idx[q] * NV + idx[p]] += v;
      }
  }
}

km_status km__kappa_table_build(const km_pp *ka, const km_pp *kb,
                                km__kappa_table **out) {
  *out = NULL;
  km__kappa_table *k = km__calloc(1, sizeof *k);
  if (!k) return KM_ENOMEM;
  km_status st = merged_breaks(ka, kb, k);
  int e = ka->degree > kb->degree ? ka->degree : kb->degree;
  k->e = e > 2 ? e : 2;
  size_t s = (size_t)(k->e + 1);
  if (!st) {
    k->a = km__malloc(k->m * s * sizeof(double));
    k->b = km__malloc(k->m * s * sizeof(double));
    k->psi = km__malloc(4 * k->m * s * sizeof(double));
    k->lo = km__malloc(k->m * sizeof(int));
    if (!k->a || !k->b || !k->psi || !k->lo) st = KM_ENOMEM;
  }
  if (st) {
    km__kappa_table_free(k);
    return st;
  }
  km__pp_on_breaks(ka, k->r, k->m, k->e, k->a);
  km__pp_on_breaks(kb, k->r, k->m, k->e, k->b);
  for (size_t i = 0; i < k->m; i++) {
    double r0 = k->r[i], r1 = k->r[i + 1];
    int iv = (int)floor(0.5 * (r0 + r1) * NB);
    iv = iv < 0 ? 0 : (iv > NB - 1 ? NB - 1 : iv);
    /* B3(u - j) is not zero for j < u < j + 4 */
    k->lo[i] = iv - 3;
    for (int q = 0; q < 4; q++) {
      int j = iv - 3 + q;
      double *o = k->psi + (4 * i + (size_t)q) * s;
      if (j < 0 || j >= NF)
        memset(o, 0, s * sizeof(double));
      else
        psi_piece(j, r0, r1, k->e, o);
    }
  }
  gram(k);
  *out = k;
  return KM_OK;
}

km_status km__kappa_table_metrics(const km__kappa_table *k, double t, double La,
                                  double Lb, const double *c, double rel,
                                  double *max_abs, double *energy) {
  double Lt = (1 - t) * La + t * Lb, v[NV] = {0};
  v[0] = (1 - t) * La / Lt;
  v[1] = t * Lb / Lt;
  if (c)
    for (int j = 0; j < NF; j++) v[2 + j] = NB * c[j] / Lt;
  size_t s = (size_t)(k->e + 1);
  double *K = km__malloc(k->m * s * sizeof(double));
  if (!K) return KM_ENOMEM;
  for (size_t i = 0; i < k->m; i++) {
    const double *A = k->a + i * s, *B = k->b + i * s;
    double *o = K + i * s;
    for (size_t q = 0; q < s; q++) o[q] = v[0] * A[q] + v[1] * B[q];
    if (!c) continue;
    for (int q = 0; q < 4; q++) {
      int j = k->lo[i] + q;
      if (j < 0 || j >= NF) continue;
      const double *P = k->psi + (4 * i + (size_t)q) * s;
      for (size_t l = 0; l < s; l++) o[l] += v[2 + j] * P[l];
    }
  }
  km_pp view = {k->e, k->m, k->r, K};
  *max_abs = km__pp_max_abs_within(&view, rel);
  km__free(K);
  /* the energy: L_t v' G v (kappa^2 integrated over x = r L_t) */
  int n = c ? NV : 2;
  double q = 0.0;
  for (int i = 0; i < n; i++) {
    double row = 0.0;
    for (int j = 0; j < n; j++) row += k->G[i * NV + j] * v[j];
    q += v[i] * row;
  }
  *energy = Lt * fmax(q, 0.0); /* G is semi-definite: only rounding below */
  return KM_OK;
}
