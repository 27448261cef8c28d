/* curve_ops.c - exact knot-level operations on B-spline / NURBS curves:
 * knot insertion, split, reverse, Bezier extraction, degree elevation,
 * reparameterisation, rigid transforms and making two curves compatible.
 *
 * DESIGN. Everything that changes the basis works on homogeneous points
 * (bezier_util.h), which makes it exact for rational curves too. Insertion
 * is knot refinement (Piegl & Tiller A5.4). Degree elevation extracts the
 * Bezier pieces, elevates each one (the Bernstein elevation formula) and
 * then removes every interior knot back down to its original multiplicity
 * plus `times`; the removals are exact because the elevated curve keeps the
 * continuity the original had. Removal solves the removal equations from
 * both ends towards the middle, so no long one-sided recurrence amplifies
 * rounding.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bezier_util.h"
#include "internal.h"
#include "kernels.h"
#include "km/curve.h"
#include "km/limits.h"

/* ---- homogeneous workspaces ------------------------------------------ */

void km__h_init(km__hcurve *h) { memset(h, 0, sizeof *h); }

void km__h_free(km__hcurve *h) {
  if (!h) return;
  free(h->knots);
  memset(h, 0, sizeof *h);
}

km_status km__h_alloc(km__hcurve *h, int degree, int dim, size_t n) {
  size_t nk = n + (size_t)degree + 1;
  if (n == 0 || n > ((size_t)-1) / sizeof(double) / 8) return KM_ENOMEM;
  double *block = malloc((nk + n * (size_t)dim) * sizeof(double));
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
    x = malloc(cnt * sizeof(double));
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
  free(x);
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
    mult = malloc(nd * sizeof *mult);
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
  free(mult);
  return st;
}

/* ---- public operations ----------------------------------------------- */

static km_status check_curve(const km_curve *c, km_error *err) {
  if (!c || !c->knots || !c->cp || c->degree < KM_MIN_DEGREE ||
      c->degree > KM_MAX_DEGREE || c->n < (size_t)c->degree + 1)
    return km__fail(err, KM_EINVAL, KM_FIELD_NONE, -1, NAN,
                    "not a valid curve");
  return KM_OK;
}

static size_t multiplicity(const km_curve *c, double t) {
  size_t s = 0;
  for (size_t i = 0; i < c->n + (size_t)c->degree + 1; i++)
    if (c->knots[i] == t) s++;
  return s;
}

/* Insert t r times, r already limited; result in *out. */
static km_status insert_times(km_curve *out, const km_curve *c, double t,
                              size_t r) {
  km__hcurve h, q;
  km__h_init(&h);
  km__h_init(&q);
  double *x = NULL;
  km_status st = km__h_from_curve(&h, c, 2);
  if (st) goto cleanup;
  x = malloc((r ? r : 1) * sizeof(double));
  if (!x) {
    st = KM_ENOMEM;
    goto cleanup;
  }
  for (size_t i = 0; i < r; i++) x[i] = t;
  st = km__h_refine(&q, &h, x, r);
  if (st) goto cleanup;
  st = km__h_to_curve(out, &q, c->closed);
cleanup:
  free(x);
  km__h_free(&h);
  km__h_free(&q);
  return st;
}

/* Insert t (within the domain) `times` times, capped so that no interior
 * multiplicity exceeds the degree; at a domain end nothing is inserted.
 * out: a new curve owned by the caller (km_curve_free), same trace and
 * parameterisation, closed flag kept. Returns KM_OK, KM_EINVAL (not a
 * curve; times < 0, field KM_FIELD_TIMES), KM_ENONFINITE (t), KM_ERANGE (t
 * outside the domain, err->param = t), KM_ENOMEM. Thread-safe. */
km_status km_curve_insert_knot(km_curve *out, const km_curve *c, double t,
                               int times, km_error *err) {
  km_status st = check_curve(c, err);
  if (st) return st;
  if (times < 0)
    return km__fail(err, KM_EINVAL, KM_FIELD_TIMES, -1, t,
                    "times must not be negative (got %d)", times);
  if (!isfinite(t))
    return km__fail(err, KM_ENONFINITE, KM_FIELD_NONE, -1, t,
                    "knot value is not finite");
  double t0, t1;
  km_curve_domain(c, &t0, &t1);
  if (t < t0 || t > t1)
    return km__fail(err, KM_ERANGE, KM_FIELD_NONE, -1, t,
                    "knot %g lies outside the domain [%g, %g]", t, t0, t1);
  size_t r = 0;
  if (t > t0 && t < t1) {
    size_t s = multiplicity(c, t);
    r = (size_t)c->degree > s ? (size_t)c->degree - s : 0;
    if ((size_t)times < r) r = (size_t)times;
  }
  st = insert_times(out, c, t, r);
  if (st) return km__fail(err, st, KM_FIELD_NONE, -1, t, NULL);
  return KM_OK;
}

/* Split at t strictly inside the domain into left on [t0, t] and right on
 * [t, t1], both open, meeting in one bit-identical point; each is owned by
 * the caller. Returns KM_OK, KM_EINVAL, KM_ERANGE / KM_ENONFINITE (t not
 * inside), KM_ENOMEM; on failure neither output is written. */
km_status km_curve_split(const km_curve *c, double t, km_curve *left,
                         km_curve *right, km_error *err) {
  km_status st = check_curve(c, err);
  if (st) return st;
  double t0, t1;
  km_curve_domain(c, &t0, &t1);
  if (!(t > t0 && t < t1))
    return km__fail(err, isfinite(t) ? KM_ERANGE : KM_ENONFINITE,
                    KM_FIELD_NONE, -1, t,
                    "split parameter %g is not inside (%g, %g)", t, t0, t1);
  km_curve ins, l, r;
  km_curve_init(&ins);
  km_curve_init(&l);
  km_curve_init(&r);
  int p = c->degree;
  size_t s = multiplicity(c, t);
  st = insert_times(&ins, c, t, (size_t)p > s ? (size_t)p - s : 0);
  if (st) goto cleanup;
  size_t f = 0;
  while (ins.knots[f] != t) f++;
  size_t nl = f, nr = ins.n - f + 1;
  bool rat = ins.w != NULL;
  st = km__curve_alloc(&l, p, nl, rat);
  if (st) goto cleanup;
  st = km__curve_alloc(&r, p, nr, rat);
  if (st) goto cleanup;
  memcpy(l.knots, ins.knots, (f + (size_t)p) * sizeof(double));
  l.knots[f + (size_t)p] = t;
  memcpy(l.cp, ins.cp, 2 * nl * sizeof(double));
  r.knots[0] = t;
  memcpy(r.knots + 1, ins.knots + f, (ins.n + (size_t)p + 1 - f) * sizeof(double));
  memcpy(r.cp, ins.cp + 2 * (f - 1), 2 * nr * sizeof(double));
  if (rat) {
    memcpy(l.w, ins.w, nl * sizeof(double));
    memcpy(r.w, ins.w + (f - 1), nr * sizeof(double));
  }
  *left = l;
  *right = r;
  km_curve_init(&l);
  km_curve_init(&r);
cleanup:
  if (st) km__fail(err, st, KM_FIELD_NONE, -1, t, NULL);
  km_curve_free(&ins);
  km_curve_free(&l);
  km_curve_free(&r);
  return st;
}

/* Same trace backwards on the same domain: C_rev(a + b - t) = C(t).
 * Returns KM_OK, KM_EINVAL, KM_ENOMEM; out owned by the caller. */
km_status km_curve_reverse(km_curve *out, const km_curve *c, km_error *err) {
  km_status st = check_curve(c, err);
  if (st) return st;
  km_curve r;
  st = km__curve_alloc(&r, c->degree, c->n, c->w != NULL);
  if (st) return km__fail(err, st, KM_FIELD_NONE, -1, NAN, NULL);
  size_t n = c->n, nk = n + (size_t)c->degree + 1;
  double a = c->knots[0], b = c->knots[nk - 1];
  for (size_t i = 0; i < nk; i++) r.knots[i] = (a + b) - c->knots[nk - 1 - i];
  /* the clamped ends must stay exactly a and b */
  for (size_t i = 0; i <= (size_t)c->degree; i++) {
    r.knots[i] = a;
    r.knots[nk - 1 - i] = b;
  }
  for (size_t i = 0; i < n; i++) {
    r.cp[2 * i] = c->cp[2 * (n - 1 - i)];
    r.cp[2 * i + 1] = c->cp[2 * (n - 1 - i) + 1];
    if (c->w) r.w[i] = c->w[n - 1 - i];
  }
  r.closed = c->closed;
  *out = r;
  return KM_OK;
}

/* Bezier extraction: every interior knot raised to multiplicity degree.
 * Returns KM_OK, KM_EINVAL, KM_ENOMEM; out owned by the caller. */
km_status km_curve_to_bezier(km_curve *out, const km_curve *c,
                             km_error *err) {
  km__hcurve h, q;
  km__h_init(&h);
  km__h_init(&q);
  km_status st = check_curve(c, err);
  if (st) return st;
  st = km__h_from_curve(&h, c, 2);
  if (!st) st = km__h_to_bezier(&q, &h);
  if (!st) st = km__h_to_curve(out, &q, c->closed);
  if (st) km__fail(err, st, KM_FIELD_NONE, -1, NAN, NULL);
  km__h_free(&h);
  km__h_free(&q);
  return st;
}

/* Degree raised by times >= 0 (exact; homogeneous for NURBS); each
 * distinct knot's multiplicity grows by times. Returns KM_OK, KM_EINVAL
 * (times < 0, field KM_FIELD_TIMES), KM_EDEGREE (degree + times above
 * KM_MAX_DEGREE, field KM_FIELD_TIMES), KM_ENOMEM; out owned by the
 * caller. */
km_status km_curve_elevate(km_curve *out, const km_curve *c, int times,
                           km_error *err) {
  km__hcurve h, q;
  km__h_init(&h);
  km__h_init(&q);
  km_status st = check_curve(c, err);
  if (st) return st;
  if (times < 0)
    return km__fail(err, KM_EINVAL, KM_FIELD_TIMES, -1, NAN,
                    "times must not be negative (got %d)", times);
  if (times > KM_MAX_DEGREE - c->degree)
    return km__fail(err, KM_EDEGREE, KM_FIELD_TIMES, -1, NAN,
                    "degree %d raised %d times exceeds %d", c->degree, times,
                    KM_MAX_DEGREE);
  st = km__h_from_curve(&h, c, 2);
  if (!st) st = km__h_elevate(&q, &h, times);
  if (!st) st = km__h_to_curve(out, &q, c->closed);
  if (st) km__fail(err, st, KM_FIELD_NONE, -1, NAN, NULL);
  km__h_free(&h);
  km__h_free(&q);
  return st;
}

/* Map the knots of h linearly onto [t0, t1], ends exact, order kept. */
static void reparam_knots(double *U, size_t nk, int p, double t0, double t1) {
  double a = U[0], b = U[nk - 1], f = (t1 - t0) / (b - a);
  for (size_t i = 0; i < nk; i++) {
    double v = t0 + (U[i] - a) * f;
    if (v < t0) v = t0;
    if (v > t1) v = t1;
    if (i > 0 && v < U[i - 1]) v = U[i - 1];
    U[i] = v;
  }
  for (size_t i = 0; i <= (size_t)p; i++) {
    U[i] = t0;
    U[nk - 1 - i] = t1;
  }
}

/* Linear map of the domain onto [t0, t1]; the trace is unchanged. Returns
 * KM_OK, KM_EINVAL, KM_ENONFINITE, KM_ERANGE (t0 >= t1 or beyond
 * KM_MAX_COORDINATE), KM_ENOMEM; out owned by the caller. */
km_status km_curve_reparam(km_curve *out, const km_curve *c, double t0,
                           double t1, km_error *err) {
  km_status st = check_curve(c, err);
  if (st) return st;
  if (!isfinite(t0) || !isfinite(t1))
    return km__fail(err, KM_ENONFINITE, KM_FIELD_NONE, -1, NAN,
                    "domain ends must be finite");
  if (!(t0 < t1) || fabs(t0) > KM_MAX_COORDINATE ||
      fabs(t1) > KM_MAX_COORDINATE)
    return km__fail(err, KM_ERANGE, KM_FIELD_NONE, -1, NAN,
                    "domain [%g, %g] is empty or too large", t0, t1);
  km_curve r;
  st = km_curve_copy(&r, c, err);
  if (st) return st;
  reparam_knots(r.knots, r.n + (size_t)r.degree + 1, r.degree, t0, t1);
  *out = r;
  return KM_OK;
}

/* Rigid motion x' = R(rot) x + (tx, ty) of the control points (exact for
 * NURBS too: rational curves are affinely invariant). Returns KM_OK,
 * KM_EINVAL, KM_ENONFINITE, KM_ERANGE (a point beyond KM_MAX_COORDINATE,
 * err->index names it), KM_ENOMEM; out owned by the caller. */
km_status km__curve_transform_in_place(km_curve *c, double rot, double tx,
                                      double ty, km_error *err) {
  if (!isfinite(rot) || !isfinite(tx) || !isfinite(ty))
    return km__fail(err, KM_ENONFINITE, KM_FIELD_NONE, -1, NAN,
                    "rotation and translation must be finite");
  double cs = cos(rot), sn = sin(rot);
  for (size_t i = 0; i < c->n; i++) {
    double x = c->cp[2 * i], y = c->cp[2 * i + 1];
    double nx = cs * x - sn * y + tx, ny = sn * x + cs * y + ty;
    if (!(fabs(nx) <= KM_MAX_COORDINATE && fabs(ny) <= KM_MAX_COORDINATE))
      return km__fail(err, KM_ERANGE, KM_FIELD_CONTROL_POINTS, (long)i, NAN,
                      "transformed control point %zu exceeds %g", i,
                      KM_MAX_COORDINATE);
    c->cp[2 * i] = nx;
    c->cp[2 * i + 1] = ny;
  }
  if (c->closed) {
    c->cp[2 * (c->n - 1)] = c->cp[0];
    c->cp[2 * (c->n - 1) + 1] = c->cp[1];
  }
  return KM_OK;
}

km_status km_curve_transform(km_curve *out, const km_curve *c, double rot,
                             double tx, double ty, km_error *err) {
  km_status st = check_curve(c, err);
  if (st) return st;
  km_curve r;
  st = km_curve_copy(&r, c, err);
  if (!st) st = km__curve_transform_in_place(&r, rot, tx, ty, err);
  if (st) {
    km_curve_free(&r);
    return st;
  }
  *out = r;
  return KM_OK;
}

/* Interior knots of h missing from `other` (as multiset), sorted, written
 * to x (capacity: other's knot count); returns the count. Values of h
 * within `snap` of a knot of other are first moved onto it so that both
 * vectors end up bit-identical. */
static size_t missing_knots(const km__hcurve *h, const km__hcurve *o,
                            double *x) {
  int p = h->degree;
  size_t cnt = 0, i = (size_t)p + 1, j = (size_t)p + 1;
  size_t ie = h->n, je = o->n; /* interior knots are [p+1, n) */
  while (j < je) {
    double v = o->knots[j];
    if (i < ie && h->knots[i] < v) {
      i++;
    } else if (i < ie && h->knots[i] == v) {
      i++;
      j++;
    } else {
      x[cnt++] = v;
      j++;
    }
  }
  return cnt;
}

static void snap_knots(km__hcurve *b, const km__hcurve *a, double snap) {
  size_t j = (size_t)a->degree + 1;
  for (size_t i = (size_t)b->degree + 1; i < b->n; i++) {
    double v = b->knots[i];
    while (j < a->n && a->knots[j] < v - snap) j++;
    if (j < a->n && fabs(a->knots[j] - v) <= snap) b->knots[i] = a->knots[j];
  }
}

/* Both curves on [0, 1], of the larger degree, with one merged knot vector
 * (multiplicity the larger of the two; knots closer than 1e-13 are taken
 * as one) and both rational if either is (unit weights for a polynomial
 * one). Traces unchanged, closed flags kept. Returns KM_OK, KM_EINVAL,
 * KM_ENOMEM; on failure neither output is written; outputs owned by the
 * caller. Thread-safe. */
km_status km_curve_make_compatible(const km_curve *a, const km_curve *b,
                                   km_curve *out_a, km_curve *out_b,
                                   km_error *err) {
  km_status st = check_curve(a, err);
  if (!st) st = check_curve(b, err);
  if (st) return st;
  km__hcurve ha, hb, ea, eb, ra, rb;
  km__h_init(&ha);
  km__h_init(&hb);
  km__h_init(&ea);
  km__h_init(&eb);
  km__h_init(&ra);
  km__h_init(&rb);
  km_curve ca, cb;
  km_curve_init(&ca);
  km_curve_init(&cb);
  double *x = NULL;
  int dim = (a->w || b->w) ? 3 : 2;
  int q = a->degree > b->degree ? a->degree : b->degree;
  st = km__h_from_curve(&ha, a, dim);
  if (st) goto cleanup;
  st = km__h_from_curve(&hb, b, dim);
  if (st) goto cleanup;
  reparam_knots(ha.knots, ha.n + (size_t)ha.degree + 1, ha.degree, 0.0, 1.0);
  reparam_knots(hb.knots, hb.n + (size_t)hb.degree + 1, hb.degree, 0.0, 1.0);
  st = km__h_elevate(&ea, &ha, q - a->degree);
  if (st) goto cleanup;
  st = km__h_elevate(&eb, &hb, q - b->degree);
  if (st) goto cleanup;
  /* knots a hair apart (rounding in the reparameterisation) are the same
   * knot: moving one by 1e-13 of the domain changes the curve by less than
   * rounding elsewhere does, while keeping both would add a sliver span */
  snap_knots(&eb, &ea, 1e-13);
  x = malloc((ea.n + eb.n + 2) * sizeof(double));
  if (!x) {
    st = KM_ENOMEM;
    goto cleanup;
  }
  size_t nxa = missing_knots(&ea, &eb, x);
  st = km__h_refine(&ra, &ea, x, nxa);
  if (st) goto cleanup;
  size_t nxb = missing_knots(&eb, &ea, x);
  st = km__h_refine(&rb, &eb, x, nxb);
  if (st) goto cleanup;
  if (ra.n != rb.n) {
    st = KM_EKNOTS;
    goto cleanup;
  }
  /* identical by construction; copy so rounding cannot tell them apart */
  memcpy(rb.knots, ra.knots, (ra.n + (size_t)q + 1) * sizeof(double));
  st = km__h_to_curve(&ca, &ra, a->closed);
  if (st) goto cleanup;
  st = km__h_to_curve(&cb, &rb, b->closed);
  if (st) goto cleanup;
  *out_a = ca;
  *out_b = cb;
  km_curve_init(&ca);
  km_curve_init(&cb);
cleanup:
  if (st) km__fail(err, st, KM_FIELD_NONE, -1, NAN, NULL);
  free(x);
  km__h_free(&ha);
  km__h_free(&hb);
  km__h_free(&ea);
  km__h_free(&eb);
  km__h_free(&ra);
  km__h_free(&rb);
  km_curve_free(&ca);
  km_curve_free(&cb);
  return st;
}
