/* fn.c - scalar B-spline functions: construction, evaluation, exact
 * antiderivative, bounds, and the exact linear blend of two functions on
 * different knots over a normalised domain.
 */
#include <math.h>
#include <string.h>

#include "internal.h"
#include "kernels.h"
#include "km/alloc.h"
#include "km/limits.h"

#define FN_MAX_DEGREE KM_MAX_FN_DEGREE

void km_fn_init(km_fn *f) {
  if (f) memset(f, 0, sizeof *f);
}

void km_fn_free(km_fn *f) {
  if (!f) return;
  km__free(f->knots);
  memset(f, 0, sizeof *f);
}

km_status km__fn_alloc(km_fn *f, int degree, size_t n) {
  size_t nk = n + (size_t)degree + 1;
  if (n == 0) return KM_ENOMEM;
  double *block = km__malloc((nk + n) * sizeof(double));
  if (!block) return KM_ENOMEM;
  f->degree = degree;
  f->n = n;
  f->knots = block;
  f->coef = block + nk;
  return KM_OK;
}

km_status km_fn_create(km_fn *out, int degree, size_t n, const double *knots,
                       const double *coef, km_error *err) {
  if (degree < 0 || degree > FN_MAX_DEGREE)
    return km__fail(err, KM_EDEGREE, KM_FIELD_KAPPA_DEGREE, -1, NAN,
                    "degree %d is outside 0..%d", degree, FN_MAX_DEGREE);
  if (!knots || !coef || n < (size_t)degree + 1)
    return km__fail(err, KM_ECOUNT, KM_FIELD_KAPPA_COEFFICIENTS, -1, NAN,
                    "a function of degree %d needs at least %d coefficients",
                    degree, degree + 1);
  size_t nk = n + (size_t)degree + 1;
  for (size_t i = 0; i < n; i++) {
    if (!isfinite(coef[i]))
      return km__fail(err, KM_ENONFINITE, KM_FIELD_KAPPA_COEFFICIENTS, (long)i,
                      NAN, "coefficient %zu is not finite", i);
    if (fabs(coef[i]) > KM_MAX_COORDINATE)
      return km__fail(err, KM_ERANGE, KM_FIELD_KAPPA_COEFFICIENTS, (long)i, NAN,
                      "coefficient %zu exceeds %g in magnitude", i,
                      KM_MAX_COORDINATE);
  }
  for (size_t i = 0; i < nk; i++) {
    if (!isfinite(knots[i]))
      return km__fail(err, KM_ENONFINITE, KM_FIELD_KAPPA_KNOTS, (long)i, NAN,
                      "knot %zu is not finite", i);
    if (fabs(knots[i]) > KM_MAX_COORDINATE)
      return km__fail(err, KM_ERANGE, KM_FIELD_KAPPA_KNOTS, (long)i, NAN,
                      "knot %zu exceeds %g in magnitude", i, KM_MAX_COORDINATE);
    if (i > 0 && knots[i] < knots[i - 1])
      return km__fail(err, KM_EKNOTS, KM_FIELD_KAPPA_KNOTS, (long)i, NAN,
                      "knot vector decreases at index %zu", i);
  }
  for (int i = 1; i <= degree; i++) {
    if (knots[i] != knots[0])
      return km__fail(err, KM_EKNOTS, KM_FIELD_KAPPA_KNOTS, (long)i, NAN,
                      "knot vector is not clamped: the first %d knots must "
                      "be equal",
                      degree + 1);
    if (knots[nk - 1 - (size_t)i] != knots[nk - 1])
      return km__fail(err, KM_EKNOTS, KM_FIELD_KAPPA_KNOTS,
                      (long)(nk - 1 - (size_t)i), NAN,
                      "knot vector is not clamped: the last %d knots must be "
                      "equal",
                      degree + 1);
  }
  if (!(knots[n] > knots[degree]))
    return km__fail(err, KM_EKNOTS, KM_FIELD_KAPPA_KNOTS, (long)n, NAN,
                    "knot vector has an empty domain");
  size_t run = 1;
  for (size_t i = (size_t)degree + 1; i < n; i++) {
    run = knots[i] == knots[i - 1] ? run + 1 : 1;
    if (run > (size_t)degree + 1)
      return km__fail(err, KM_EKNOTS, KM_FIELD_KAPPA_KNOTS, (long)i, NAN,
                      "interior knot at index %zu has multiplicity above "
                      "degree + 1",
                      i);
  }
  km_fn f;
  if (km__fn_alloc(&f, degree, n))
    return km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
  memcpy(f.knots, knots, nk * sizeof(double));
  memcpy(f.coef, coef, n * sizeof(double));
  *out = f;
  return KM_OK;
}

km_status km_fn_copy(km_fn *out, const km_fn *f, km_error *err) {
  return km_fn_create(out, f->degree, f->n, f->knots, f->coef, err);
}

km_status km_fn_constant(km_fn *out, double a, double b, double c,
                         km_error *err) {
  double knots[2] = {a, b};
  return km_fn_create(out, 0, 1, knots, &c, err);
}

void km_fn_domain(const km_fn *f, double *a, double *b) {
  *a = f->knots[f->degree];
  *b = f->knots[f->n];
}

/* k-th derivative at x on span i: difference the local coefficients k
 * times, then de Boor on the lowered degree. */
static double eval_local(const km_fn *f, size_t i, double x, int k) {
  int p = f->degree;
  if (k > p) return 0.0;
  const double *U = f->knots;
  double e[FN_MAX_DEGREE + 2];
  /* e[j] holds the coefficient with global index i - p + j */
  for (int j = 0; j <= p; j++) e[j] = f->coef[i - (size_t)p + (size_t)j];
  int q = p;
  for (int r = 1; r <= k; r++) {
    /* new coefficients for global j = i-q+1 .. i (local jj = p-q+1..p) */
    for (int jj = p; jj >= p - q + 1; jj--) {
      size_t g = i - (size_t)p + (size_t)jj;
      double den = U[g + (size_t)q] - U[g];
      e[jj] = den > 0 ? q * (e[jj] - e[jj - 1]) / den : 0.0;
    }
    q--;
  }
  /* de Boor for degree q with coefficients e[p-q .. p] */
  double d[FN_MAX_DEGREE + 2];
  for (int j = 0; j <= q; j++) d[j] = e[p - q + j];
  for (int r = 1; r <= q; r++) {
    for (int j = q; j >= r; j--) {
      size_t lo = i - (size_t)q + (size_t)j;
      size_t hi = i + 1 + (size_t)j - (size_t)r;
      double den = U[hi] - U[lo];
      double al = den > 0 ? (x - U[lo]) / den : 0.0;
      d[j] = (1.0 - al) * d[j - 1] + al * d[j];
    }
  }
  return d[q];
}

void km_fn_eval(const km_fn *f, double x, int nder, double *out) {
  double a, b;
  km_fn_domain(f, &a, &b);
  if (x < a) x = a;
  if (x > b) x = b;
  size_t i = km__knot_span(f->knots, f->n, f->degree, x);
  for (int k = 0; k <= nder; k++) out[k] = eval_local(f, i, x, k);
}

double km_fn_value(const km_fn *f, double x) {
  double v;
  km_fn_eval(f, x, 0, &v);
  return v;
}

km_status km_fn_antiderivative(km_fn *out, const km_fn *f, double c0,
                               km_error *err) {
  int p = f->degree;
  if (p + 1 > FN_MAX_DEGREE)
    return km__fail(err, KM_EDEGREE, KM_FIELD_KAPPA_DEGREE, -1, NAN,
                    "antiderivative would exceed degree %d", FN_MAX_DEGREE);
  km_fn r;
  if (km__fn_alloc(&r, p + 1, f->n + 1))
    return km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
  size_t nk = f->n + (size_t)p + 1;
  r.knots[0] = f->knots[0];
  memcpy(r.knots + 1, f->knots, nk * sizeof(double));
  r.knots[nk + 1] = f->knots[nk - 1];
  r.coef[0] = c0;
  for (size_t j = 1; j <= f->n; j++)
    r.coef[j] =
        r.coef[j - 1] +
        f->coef[j - 1] * (f->knots[j + (size_t)p] - f->knots[j - 1]) / (p + 1);
  *out = r;
  return KM_OK;
}

double km_fn_integral(const km_fn *f) {
  int p = f->degree;
  double s = 0.0;
  for (size_t i = 0; i < f->n; i++)
    s += f->coef[i] * (f->knots[i + (size_t)p + 1] - f->knots[i]);
  return s / (p + 1);
}

double km_fn_abs_bound(const km_fn *f, double x0, double x1) {
  km_pp pp;
  if (km__pp_from_fn(&pp, f)) {
    double m = 0; /* fall back to the global coefficient hull */
    for (size_t i = 0; i < f->n; i++) m = fmax(m, fabs(f->coef[i]));
    return m;
  }
  int d = pp.degree;
  double m = 0.0, c[FN_MAX_DEGREE + 2];
  for (size_t i = 0; i < pp.m; i++) {
    double a = pp.x[i], b = pp.x[i + 1];
    double lo = fmax(a, x0), hi = fmin(b, x1);
    if (hi < lo || (hi == lo && !(x0 == x1))) continue;
    double h = b - a;
    km__bern_restrict(pp.c + i * (size_t)(d + 1), d, (lo - a) / h, (hi - a) / h,
                      c);
    m = fmax(m, km__bern_abs_bound(c, d));
  }
  km__pp_free(&pp);
  return m;
}

/* max |p| over [0,1] by subdivision, to rel relative: the coefficient
 * hull bounds from above, end values from below. */
/* Where |p| is concave on the piece (p of one sign s by its coefficients,
 * s p'' <= -k < 0 by those of p''), the largest |p| by Newton on p': the
 * value *at found at u, and returned a bound above every |p(x)| on the
 * piece, |p(u)| + p'(u)^2 / (2 k) (Taylor about u with s p'' <= -k).
 * Returns INFINITY where |p| is not so (or d < 2). Halving towards an
 * interior maximum gains a factor of four a level, some fifteen levels to
 * 1e-9: square_to_circle's frames have eight equal ones each. */
static double concave_max_abs(const double *c, int d, double *at) {
  if (d < 2) return INFINITY;
  double s = c[0] > 0 ? 1.0 : -1.0, d1[FN_MAX_DEGREE + 1],
         d2[FN_MAX_DEGREE + 1], k = INFINITY;
  for (int j = 0; j <= d; j++)
    if (!(s * c[j] > 0)) return INFINITY;
  for (int j = 0; j < d; j++) d1[j] = d * s * (c[j + 1] - c[j]);
  for (int j = 0; j + 1 < d; j++) {
    d2[j] = (d - 1) * (d1[j + 1] - d1[j]);
    if (!(d2[j] < 0)) return INFINITY;
    k = fmin(k, -d2[j]);
  }
  double u = 0.5;
  for (int it = 0; it < 8; it++) {
    /* p' and p'' at u by one de Casteljau pass over p' (degree d - 1):
     * its last two values a, b give p' = a + u (b - a), p'' = (d - 1)
     * (b - a) */
    double w[FN_MAX_DEGREE + 1];
    memcpy(w, d1, (size_t)d * sizeof(double));
    for (int r = d - 1; r > 1; r--)
      for (int j = 0; j < r; j++) w[j] += u * (w[j + 1] - w[j]);
    double g = w[0] + u * (w[1] - w[0]), h = (d - 1) * (w[1] - w[0]);
    if (!(h < 0)) break;
    double v = u - g / h;
    v = v < 0 ? 0 : (v > 1 ? 1 : v);
    bool done = fabs(v - u) <= 1e-9;
    u = v;
    /* quadratic convergence: the next step would be below 1e-18 */
    if (done) break;
  }
  double g = km__bern_eval(d1, d - 1, u);
  /* at an end the slope may point outwards: the bound holds on [0, 1]
   * all the same, and the end value was taken by the caller */
  *at = s * km__bern_eval(c, d, u);
  return *at + g * g / (2 * k);
}

static double bern_max_abs_within(const double *c, int d, double lower,
                                  double rel, int depth) {
  double ends = fmax(fabs(c[0]), fabs(c[d]));
  if (ends > lower) lower = ends;
  double upper = km__bern_abs_bound(c, d);
  if (upper <= lower * (1.0 + rel) || depth > 60) return fmax(lower, ends);
  double at = 0.0, top = concave_max_abs(c, d, &at);
  if (at > lower && top < INFINITY) lower = at;
  if (top <= lower * (1.0 + rel)) return lower;
  double L[FN_MAX_DEGREE + 2], R[FN_MAX_DEGREE + 2];
  km__bern_halves(c, d, L, R);
  double ml = bern_max_abs_within(L, d, lower, rel, depth + 1);
  if (ml > lower) lower = ml;
  double mr = bern_max_abs_within(R, d, lower, rel, depth + 1);
  return fmax(lower, mr);
}

static double bern_max_abs(const double *c, int d, double lower, int depth) {
  return bern_max_abs_within(c, d, lower, 1e-13, depth);
}

double km__pp_max_abs(const km_pp *p) {
  double m = 0.0;
  int d = p->degree;
  for (size_t i = 0; i < p->m; i++)
    m = fmax(m, bern_max_abs(p->c + i * (size_t)(d + 1), d, m, 0));
  return m;
}

double km__pp_max_abs_within(const km_pp *p, double rel) {
  double m = 0.0;
  int d = p->degree;
  /* every piece's end values first: a lower bound that spares refining
   * pieces whose own maximum is not the largest (a curvature that is
   * nearly constant on a stretch has many, each refined in turn when
   * compared with the running maximum only) */
  for (size_t i = 0; i < p->m; i++) {
    const double *c = p->c + i * (size_t)(d + 1);
    m = fmax(m, fmax(fabs(c[0]), fabs(c[d])));
  }
  for (size_t i = 0; i < p->m; i++) {
    const double *c = p->c + i * (size_t)(d + 1);
    /* a piece monotone by its coefficients (their differences of one
     * sign) has its largest |value| at an end, taken above: most pieces
     * of a curvature, whose subdivision towards an end maximum only
     * halves the gap a level */
    bool up = true, down = true;
    for (int j = 0; j < d; j++) {
      up = up && c[j + 1] >= c[j];
      down = down && c[j + 1] <= c[j];
    }
    if (!up && !down) m = fmax(m, bern_max_abs_within(c, d, m, rel, 0));
  }
  return m;
}

/* Piece by piece on the stack: a maximum cannot report out of memory, so
 * it must not need any (it was a looser bound then, a different answer). */
double km_fn_max_abs(const km_fn *f) {
  km__fn_pieces it;
  double x[2], c[KM_MAX_FN_DEGREE + 1], m = 0.0;
  km__fn_pieces_start(&it, f);
  while (km__fn_pieces_next(&it, x, c))
    m = fmax(m, bern_max_abs(c, f->degree, m, 0));
  return m;
}

static double binom(int n, int k) {
  double r = 1.0;
  for (int i = 1; i <= k; i++) r = r * (n - k + i) / i;
  return r;
}

/* Product of two degree-d Bernstein polynomials: coefficient k of degree
 * 2d is sum over a of C(d,a) C(d,k-a) / C(2d,k) f_a g_(k-a); the integral
 * over a piece of width h is h times their mean. These are the weights. */
static void sq_weights(int d, double w[FN_MAX_DEGREE + 2][FN_MAX_DEGREE + 2]) {
  /* the binomials once each (exact integers, as binom gives them) */
  double bd[FN_MAX_DEGREE + 2], b2d[2 * FN_MAX_DEGREE + 3];
  for (int a = 0; a <= d; a++) bd[a] = binom(d, a);
  for (int k = 0; k <= 2 * d; k++) b2d[k] = binom(2 * d, k);
  for (int a = 0; a <= d; a++)
    for (int b = 0; b <= d; b++) w[a][b] = bd[a] * bd[b] / b2d[a + b];
}

void km__bern_product_weights(int d, km__bern_weights w) {
  sq_weights(d, w);
}

double km__bern_inner(km__bern_weights w, const double *f, const double *g,
                      int d) {
  double s = 0.0;
  for (int a = 0; a <= d; a++)
    for (int b = 0; b <= d; b++) s += w[a][b] * f[a] * g[b];
  return s / (2 * d + 1);
}

static double piece_sq(double w[FN_MAX_DEGREE + 2][FN_MAX_DEGREE + 2],
                       const double *c, int d, double h) {
  double s = 0.0;
  for (int a = 0; a <= d; a++)
    for (int b = 0; b <= d; b++) s += w[a][b] * c[a] * c[b];
  return h * s / (2 * d + 1);
}

double km__pp_integral_sq(const km_pp *p) {
  int d = p->degree;
  double w[FN_MAX_DEGREE + 2][FN_MAX_DEGREE + 2];
  sq_weights(d, w);
  double total = 0.0;
  for (size_t i = 0; i < p->m; i++)
    total += piece_sq(w, p->c + i * (size_t)(d + 1), d, p->x[i + 1] - p->x[i]);
  return total;
}

/* Piece by piece on the stack, like km_fn_max_abs: no memory to run out
 * of (it answered NaN then). */
double km_fn_integral_sq(const km_fn *f) {
  km__fn_pieces it;
  double w[FN_MAX_DEGREE + 2][FN_MAX_DEGREE + 2];
  double x[2], c[KM_MAX_FN_DEGREE + 1], total = 0.0;
  sq_weights(f->degree, w);
  km__fn_pieces_start(&it, f);
  while (km__fn_pieces_next(&it, x, c))
    total += piece_sq(w, c, f->degree, x[1] - x[0]);
  return total;
}

/* Coefficients of the piece of p covering [r0, r1] (normalised r over p's
 * domain), elevated to degree e. *at is the piece the last call found:
 * the intervals come in increasing order, so the search walks on from
 * there to the piece km__pp_find would give (the last whose start is at
 * or below the middle). */
static void piece_on(const km_pp *p, double r0, double r1, int e, size_t *at,
                     double *out) {
  double a = p->x[0], b = p->x[p->m], L = b - a;
  double x0 = a + r0 * L, x1 = a + r1 * L, mid = 0.5 * (x0 + x1);
  size_t i = *at;
  while (i + 1 < p->m && p->x[i + 1] <= mid) i++;
  *at = i;
  double pa = p->x[i], h = p->x[i + 1] - pa;
  double u0 = (x0 - pa) / h, u1 = (x1 - pa) / h;
  if (u0 < 0) u0 = 0;
  if (u1 > 1) u1 = 1;
  double tmp[FN_MAX_DEGREE + 2];
  km__bern_restrict(p->c + i * (size_t)(p->degree + 1), p->degree, u0, u1, tmp);
  km__bern_elevate(tmp, p->degree, e, out);
}

km_status km__pp_blend(km_pp *out, const km_pp *a, double wa, const km_pp *b,
                       double wb, double u0, double u1) {
  size_t nr = a->m + b->m + 2;
  double *r = km__malloc(nr * sizeof(double));
  if (!r) return KM_ENOMEM;
  size_t k = 0, ia = 0, ib = 0;
  double La = a->x[a->m] - a->x[0], Lb = b->x[b->m] - b->x[0];
  /* both break sequences are sorted: merge them */
  while (ia <= a->m || ib <= b->m) {
    double ra = ia <= a->m ? (a->x[ia] - a->x[0]) / La : INFINITY;
    double rb = ib <= b->m ? (b->x[ib] - b->x[0]) / Lb : INFINITY;
    if (ra <= rb) {
      r[k++] = ra;
      ia++;
    } else {
      r[k++] = rb;
      ib++;
    }
  }
  size_t m = 0;
  for (size_t i = 0; i < k; i++) {
    double v = r[i] < 0 ? 0 : (r[i] > 1 ? 1 : r[i]);
    if (m == 0 || v - r[m - 1] > 1e-13) r[m++] = v;
  }
  r[0] = 0.0;
  if (r[m - 1] < 1.0 - 1e-13)
    r[m++] = 1.0;
  else
    r[m - 1] = 1.0;
  int e = a->degree > b->degree ? a->degree : b->degree;
  km_pp o;
  if (km__pp_alloc(&o, e, m - 1)) {
    km__free(r);
    return KM_ENOMEM;
  }
  double ca[FN_MAX_DEGREE + 2], cb[FN_MAX_DEGREE + 2];
  size_t at_a = 0, at_b = 0;
  for (size_t i = 0; i + 1 < m; i++) {
    piece_on(a, r[i], r[i + 1], e, &at_a, ca);
    piece_on(b, r[i], r[i + 1], e, &at_b, cb);
    double *c = o.c + i * (size_t)(e + 1);
    for (int j = 0; j <= e; j++) c[j] = wa * ca[j] + wb * cb[j];
    o.x[i] = u0 + r[i] * (u1 - u0);
  }
  o.x[0] = u0;
  o.x[m - 1] = u1;
  km__free(r);
  *out = o;
  return KM_OK;
}

void km__pp_on_breaks(const km_pp *p, const double *r, size_t m, int e,
                      double *out) {
  size_t at = 0;
  for (size_t i = 0; i < m; i++)
    piece_on(p, r[i], r[i + 1], e, &at, out + i * (size_t)(e + 1));
}

km_status km_fn_blend(km_fn *out, const km_fn *a, double wa, const km_fn *b,
                      double wb, double u0, double u1, km_error *err) {
  if (!(u1 > u0) || !isfinite(u0) || !isfinite(u1))
    return km__fail(err, KM_EINVAL, KM_FIELD_NONE, -1, NAN,
                    "blend domain must be a non-empty finite interval");
  km_pp pa, pb, po;
  km__pp_init(&pa);
  km__pp_init(&pb);
  km__pp_init(&po);
  km_status st = km__pp_from_fn(&pa, a);
  if (!st) st = km__pp_from_fn(&pb, b);
  if (!st) st = km__pp_blend(&po, &pa, wa, &pb, wb, u0, u1);
  if (!st) st = km__pp_to_fn(out, &po);
  km__pp_free(&pa);
  km__pp_free(&pb);
  km__pp_free(&po);
  if (st) return km__fail(err, st, KM_FIELD_NONE, -1, NAN, NULL);
  return KM_OK;
}
