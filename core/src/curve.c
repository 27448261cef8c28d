/* curve.c - construction, validation, evaluation and arc length of planar
 * B-spline / NURBS curves.
 *
 * Evaluation computes the non-zero basis functions and their derivatives
 * on the knot span (Cox-de Boor with derivatives, as in Piegl & Tiller
 * A2.3) and applies the quotient rule for rational curves. Arc length is
 * adaptive Gauss-Legendre per knot span: the speed is smooth inside a span
 * and may have kinks only at knots.
 */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "kernels.h"
#include "km/limits.h"

void km_curve_init(km_curve *c) {
  if (c) memset(c, 0, sizeof *c);
}

void km_curve_free(km_curve *c) {
  if (!c) return;
  free(c->knots);
  memset(c, 0, sizeof *c);
}

km_status km__curve_alloc(km_curve *c, int degree, size_t n, bool rational) {
  size_t nk = n + (size_t)degree + 1;
  size_t total = nk + 2 * n + (rational ? n : 0);
  if (n == 0 || total > ((size_t)-1) / sizeof(double)) return KM_ENOMEM;
  double *block = malloc(total * sizeof(double));
  if (!block) return KM_ENOMEM;
  c->degree = degree;
  c->n = n;
  c->knots = block;
  c->cp = block + nk;
  c->w = rational ? block + nk + 2 * n : NULL;
  c->closed = false;
  return KM_OK;
}

static bool bad_number(double v) { return !isfinite(v); }

km_status km_curve_create(km_curve *out, int degree, size_t n,
                          const double *knots, const double *cp,
                          const double *w, bool closed, km_error *err) {
  if (degree < KM_MIN_DEGREE || degree > KM_MAX_DEGREE)
    return km__fail(err, KM_EDEGREE, KM_FIELD_DEGREE, -1, NAN,
                    "degree %d is outside 1..%d", degree, KM_MAX_DEGREE);
  if (!knots || !cp || n < (size_t)degree + 1)
    return km__fail(err, KM_ECOUNT, KM_FIELD_CONTROL_POINTS, -1, NAN,
                    "a curve of degree %d needs at least %d control points",
                    degree, degree + 1);
  size_t nk = n + (size_t)degree + 1;
  for (size_t i = 0; i < n; i++) {
    for (int k = 0; k < 2; k++) {
      double v = cp[2 * i + (size_t)k];
      if (bad_number(v))
        return km__fail(err, KM_ENONFINITE, KM_FIELD_CONTROL_POINTS, (long)i,
                        NAN, "control point %zu is not finite", i);
      if (fabs(v) > KM_MAX_COORDINATE)
        return km__fail(err, KM_ERANGE, KM_FIELD_CONTROL_POINTS, (long)i,
                        NAN, "control point %zu exceeds %g in magnitude", i,
                        KM_MAX_COORDINATE);
    }
  }
  for (size_t i = 0; i < nk; i++) {
    if (bad_number(knots[i]))
      return km__fail(err, KM_ENONFINITE, KM_FIELD_KNOTS, (long)i, NAN,
                      "knot %zu is not finite", i);
    if (fabs(knots[i]) > KM_MAX_COORDINATE)
      return km__fail(err, KM_ERANGE, KM_FIELD_KNOTS, (long)i, NAN,
                      "knot %zu exceeds %g in magnitude", i,
                      KM_MAX_COORDINATE);
    if (i > 0 && knots[i] < knots[i - 1])
      return km__fail(err, KM_EKNOTS, KM_FIELD_KNOTS, (long)i, NAN,
                      "knot vector decreases at index %zu", i);
  }
  for (int i = 1; i <= degree; i++) {
    if (knots[i] != knots[0])
      return km__fail(err, KM_EKNOTS, KM_FIELD_KNOTS, (long)i, NAN,
                      "knot vector is not clamped: the first %d knots must "
                      "be equal",
                      degree + 1);
    if (knots[nk - 1 - (size_t)i] != knots[nk - 1])
      return km__fail(err, KM_EKNOTS, KM_FIELD_KNOTS, (long)(nk - 1 - (size_t)i),
                      NAN,
                      "knot vector is not clamped: the last %d knots must be "
                      "equal",
                      degree + 1);
  }
  if (!(knots[n] > knots[degree]))
    return km__fail(err, KM_EKNOTS, KM_FIELD_KNOTS, (long)n, NAN,
                    "knot vector has an empty domain");
  /* an end knot repeated more than degree + 1 times leaves a control point
   * with no influence: not a clamped B-spline */
  if (!(knots[degree + 1] > knots[degree]))
    return km__fail(err, KM_EKNOTS, KM_FIELD_KNOTS, (long)degree + 1, NAN,
                    "knot vector is not clamped: the first knot repeats more "
                    "than degree + 1 = %d times",
                    degree + 1);
  if (!(knots[n] > knots[n - 1]))
    return km__fail(err, KM_EKNOTS, KM_FIELD_KNOTS, (long)n - 1, NAN,
                    "knot vector is not clamped: the last knot repeats more "
                    "than degree + 1 = %d times",
                    degree + 1);
  /* interior multiplicity <= degree */
  size_t run = 1;
  for (size_t i = (size_t)degree + 1; i <= n; i++) {
    run = knots[i] == knots[i - 1] ? run + 1 : 1;
    if (i < n && knots[i] > knots[degree] && knots[i] < knots[n] &&
        run > (size_t)degree)
      return km__fail(err, KM_EKNOTS, KM_FIELD_KNOTS, (long)i, NAN,
                      "interior knot at index %zu has multiplicity above the "
                      "degree %d",
                      i, degree);
  }
  if (w) {
    for (size_t i = 0; i < n; i++) {
      if (bad_number(w[i]))
        return km__fail(err, KM_ENONFINITE, KM_FIELD_WEIGHTS, (long)i, NAN,
                        "weight %zu is not finite", i);
      if (!(w[i] > 0) || w[i] > KM_MAX_COORDINATE || w[i] < 1.0 / KM_MAX_COORDINATE)
        return km__fail(err, KM_EWEIGHT, KM_FIELD_WEIGHTS, (long)i, NAN,
                        "weight %zu must be positive and within [1e-15, "
                        "1e15]",
                        i);
    }
  }
  if (closed) {
    double dx = cp[2 * (n - 1)] - cp[0], dy = cp[2 * (n - 1) + 1] - cp[1];
    double scale = 0;
    for (size_t i = 0; i < 2 * n; i++) scale = fmax(scale, fabs(cp[i]));
    if (hypot(dx, dy) > 1e-12 * fmax(scale, 1e-300))
      return km__fail(err, KM_ECLOSED, KM_FIELD_CLOSED, -1, NAN,
                      "closed curve: first and last control points differ");
  }
  km_curve c;
  km_status st = km__curve_alloc(&c, degree, n, w != NULL);
  if (st) return km__fail(err, st, KM_FIELD_NONE, -1, NAN, NULL);
  memcpy(c.knots, knots, nk * sizeof(double));
  memcpy(c.cp, cp, 2 * n * sizeof(double));
  if (w) memcpy(c.w, w, n * sizeof(double));
  c.closed = closed;
  if (closed) {
    c.cp[2 * (n - 1)] = c.cp[0];
    c.cp[2 * (n - 1) + 1] = c.cp[1];
  }
  *out = c;
  return KM_OK;
}

km_status km_curve_copy(km_curve *out, const km_curve *c, km_error *err) {
  km_curve r;
  km_status st = km__curve_alloc(&r, c->degree, c->n, c->w != NULL);
  if (st) return km__fail(err, st, KM_FIELD_NONE, -1, NAN, NULL);
  memcpy(r.knots, c->knots, (c->n + (size_t)c->degree + 1) * sizeof(double));
  memcpy(r.cp, c->cp, 2 * c->n * sizeof(double));
  if (c->w) memcpy(r.w, c->w, c->n * sizeof(double));
  r.closed = c->closed;
  *out = r;
  return KM_OK;
}

void km_curve_domain(const km_curve *c, double *t0, double *t1) {
  *t0 = c->knots[c->degree];
  *t1 = c->knots[c->n];
}

size_t km__find_span(const km_curve *c, double t, int side) {
  size_t p = (size_t)c->degree, n = c->n;
  const double *U = c->knots;
  size_t lo = km__knot_span(U, n, c->degree, t);
  if (side < 0 && t > U[p] && t < U[n] && U[lo] == t) {
    /* left limit: the span ending at t */
    while (lo > p && U[lo] == t) lo--;
    while (lo < n - 1 && U[lo + 1] < t) lo++;
  }
  return lo;
}

/* Basis functions and derivatives up to nd at t on span i (Piegl-Tiller
 * A2.3). ders[k][j] = k-th derivative of N_{i-p+j}. */
static void basis_ders(const double *U, size_t i, int p, double t, int nd,
                       double ders[4][KM_MAX_DEGREE + 1]) {
  double ndu[KM_MAX_DEGREE + 1][KM_MAX_DEGREE + 1];
  double left[KM_MAX_DEGREE + 1], right[KM_MAX_DEGREE + 1];
  double a[2][KM_MAX_DEGREE + 1];
  ndu[0][0] = 1.0;
  for (int j = 1; j <= p; j++) {
    left[j] = t - U[i + 1 - (size_t)j];
    right[j] = U[i + (size_t)j] - t;
    double saved = 0.0;
    for (int r = 0; r < j; r++) {
      ndu[j][r] = right[r + 1] + left[j - r];
      double temp = ndu[r][j - 1] / ndu[j][r];
      ndu[r][j] = saved + right[r + 1] * temp;
      saved = left[j - r] * temp;
    }
    ndu[j][j] = saved;
  }
  for (int j = 0; j <= p; j++) ders[0][j] = ndu[j][p];
  for (int r = 0; r <= p; r++) {
    int s1 = 0, s2 = 1;
    a[0][0] = 1.0;
    for (int k = 1; k <= nd; k++) {
      double d = 0.0;
      int rk = r - k, pk = p - k;
      if (r >= k) {
        a[s2][0] = a[s1][0] / ndu[pk + 1][rk];
        d = a[s2][0] * ndu[rk][pk];
      }
      int j1 = rk >= -1 ? 1 : -rk;
      int j2 = (r - 1 <= pk) ? k - 1 : p - r;
      for (int j = j1; j <= j2; j++) {
        a[s2][j] = (a[s1][j] - a[s1][j - 1]) / ndu[pk + 1][rk + j];
        d += a[s2][j] * ndu[rk + j][pk];
      }
      if (r <= pk) {
        a[s2][k] = -a[s1][k - 1] / ndu[pk + 1][r];
        d += a[s2][k] * ndu[r][pk];
      }
      ders[k][r] = d;
      int tmp = s1;
      s1 = s2;
      s2 = tmp;
    }
  }
  double f = p;
  for (int k = 1; k <= nd; k++) {
    for (int j = 0; j <= p; j++) ders[k][j] *= f;
    f *= (p - k);
  }
}

void km_curve_eval_side(const km_curve *c, double t, int side, int nder,
                        double out[][2]) {
  double t0 = c->knots[c->degree], t1 = c->knots[c->n];
  if (t < t0) t = t0;
  if (t > t1) t = t1;
  if (nder > 3) nder = 3;
  if (nder < 0) nder = 0;
  int p = c->degree;
  size_t i = km__find_span(c, t, side);
  double ders[4][KM_MAX_DEGREE + 1];
  int nd = nder < p ? nder : p;
  basis_ders(c->knots, i, p, t, nd, ders);
  double A[4][3] = {{0}};
  size_t base = i - (size_t)p;
  for (int k = 0; k <= nd; k++) {
    for (int j = 0; j <= p; j++) {
      size_t idx = base + (size_t)j;
      double wj = c->w ? c->w[idx] : 1.0;
      double b = ders[k][j] * wj;
      A[k][0] += b * c->cp[2 * idx];
      A[k][1] += b * c->cp[2 * idx + 1];
      A[k][2] += b;
    }
  }
  if (!c->w) {
    for (int k = 0; k <= nder; k++) {
      out[k][0] = k <= nd ? A[k][0] : 0.0;
      out[k][1] = k <= nd ? A[k][1] : 0.0;
    }
    return;
  }
  static const double binom[4][4] = {
      {1, 0, 0, 0}, {1, 1, 0, 0}, {1, 2, 1, 0}, {1, 3, 3, 1}};
  for (int k = 0; k <= nder; k++) {
    double vx = k <= nd ? A[k][0] : 0.0, vy = k <= nd ? A[k][1] : 0.0;
    for (int j = 1; j <= k; j++) {
      double wj = j <= nd ? A[j][2] : 0.0;
      vx -= binom[k][j] * wj * out[k - j][0];
      vy -= binom[k][j] * wj * out[k - j][1];
    }
    out[k][0] = vx / A[0][2];
    out[k][1] = vy / A[0][2];
  }
}

void km_curve_eval(const km_curve *c, double t, int nder, double out[][2]) {
  km_curve_eval_side(c, t, 1, nder, out);
}

double km__speed(const km_curve *c, double t) {
  double d[2][2];
  km_curve_eval(c, t, 1, d);
  /* not hypot: magnitudes stay far from overflow (coordinates <= 1e15)
   * and this is the innermost loop of every arc length */
  return sqrt(d[1][0] * d[1][0] + d[1][1] * d[1][1]);
}

static double speed_of_curve(const void *ctx, double t) {
  return km__speed((const km_curve *)ctx, t);
}

static double gl16(km__scalar_fn f, const void *ctx, double a, double b) {
  double m = 0.5 * (a + b), h = 0.5 * (b - a), sum = 0.0;
  for (int k = 0; k < 16; k++) sum += km__gl16_w[k] * f(ctx, m + h * km__gl16_x[k]);
  return sum * h;
}

/* whole = the 16-point rule on [a, b], already computed. The error of the
 * whole is estimated by the rule on the two halves: for an integrand
 * analytic near [a, b] the halves are far more accurate, so the
 * difference is the whole's error - also where a feature that is small
 * beside the integral (a speed that nearly vanishes close to an end)
 * slows the convergence, which comparing 8 with 16 points on one interval
 * mistakes for rounding. The halves' sum is returned. Two sums of 16 and
 * 32 rounded terms differ by some ulps of the value whatever the step:
 * below 64 ulps nothing more can be gained. The budget bounds the work on
 * pathological integrands (a speed that is rounding noise around zero). */
static double integrate_rec(km__scalar_fn f, const void *ctx, double a,
                            double b, double whole, double abs_tol, int depth,
                            long *budget) {
  double m = 0.5 * (a + b);
  double l = gl16(f, ctx, a, m), r = gl16(f, ctx, m, b), sum = l + r;
  /* Nor where [a, b] is so narrow beside its position that the nodes are
   * rounded by a part in a thousand: halving it only moves them. */
  if (fabs(sum - whole) <= fmax(abs_tol, 64 * DBL_EPSILON * fabs(sum)) ||
      b - a <= 1024 * DBL_EPSILON * fmax(fabs(a), fabs(b)))
    return sum;
  if (depth >= 40 || --*budget <= 0) return NAN; /* not to the precision */
  return integrate_rec(f, ctx, a, m, l, 0.5 * abs_tol, depth + 1, budget) +
         integrate_rec(f, ctx, m, b, r, 0.5 * abs_tol, depth + 1, budget);
}

double km__integrate_adaptive(km__scalar_fn f, const void *ctx, double a,
                              double b, double abs_tol) {
  if (!(b > a)) return 0.0;
  long budget = 256;
  return integrate_rec(f, ctx, a, b, gl16(f, ctx, a, b), abs_tol, 0, &budget);
}

double km__length_adaptive(const km_curve *c, double a, double b,
                           double abs_tol) {
  return km__integrate_adaptive(speed_of_curve, c, a, b, abs_tol);
}

/* A scale for absolute tolerances: the control polygon's length bounds the
 * curve's (for positive weights it is not a strict bound, but a sound
 * scale). */
static double polygon_length(const km_curve *c) {
  double L = 0.0;
  for (size_t i = 1; i < c->n; i++)
    L += hypot(c->cp[2 * i] - c->cp[2 * i - 2],
               c->cp[2 * i + 1] - c->cp[2 * i - 1]);
  return L;
}

double km_curve_length_between(const km_curve *c, double ta, double tb) {
  double t0, t1;
  km_curve_domain(c, &t0, &t1);
  if (ta < t0) ta = t0;
  if (tb > t1) tb = t1;
  if (!(tb > ta)) return 0.0;
  double poly = polygon_length(c);
  if (!(poly > 0)) return 0.0; /* every control point equal: a point */
  double tol = 1e-15 * poly;
  double L = 0.0;
  size_t p = (size_t)c->degree;
  for (size_t i = p; i < c->n; i++) {
    double a = fmax(c->knots[i], ta), b = fmin(c->knots[i + 1], tb);
    if (!(b > a)) continue;
    /* integrate in the span's own variable u in [0, 1]: a span far
     * narrower than its knot values would lose digits in t */
    km__bspan sp;
    km__bspan_make(&sp, c, i);
    double w = c->knots[i + 1] - c->knots[i];
    L += km__bspan_length(&sp, (a - c->knots[i]) / w, (b - c->knots[i]) / w,
                          tol);
  }
  return L;
}

double km_curve_length(const km_curve *c) {
  double t0, t1;
  km_curve_domain(c, &t0, &t1);
  return km_curve_length_between(c, t0, t1);
}

double km_curve_param_at_length(const km_curve *c, double s) {
  double t0, t1;
  km_curve_domain(c, &t0, &t1);
  if (s <= 0) return t0;
  double poly = polygon_length(c);
  if (!(poly > 0)) return t0;
  double tol = 1e-15 * poly;
  /* find the span containing s; lengths in each span's own variable u, as
   * km_curve_length_between measures them */
  size_t p = (size_t)c->degree;
  double acc = 0.0, span_len = 0.0;
  km__bspan sp;
  bool found = false;
  for (size_t i = p; i < c->n; i++) {
    if (!(c->knots[i + 1] > c->knots[i])) continue;
    km__bspan_make(&sp, c, i);
    span_len = km__bspan_length(&sp, 0.0, 1.0, tol);
    if (acc + span_len >= s) {
      found = true;
      break;
    }
    acc += span_len;
  }
  if (!found || !(span_len > 0)) return t1;
  double target = s - acc; /* length within the span */
  double lo = 0.0, hi = 1.0, u = target / span_len;
  for (int it = 0; it < KM_MAX_NEWTON_ITERATIONS; it++) {
    double f = km__bspan_length(&sp, 0.0, u, tol) - target;
    if (fabs(f) <= 1e-13 * span_len) break;
    if (f > 0)
      hi = u;
    else
      lo = u;
    double pos[2], d[2];
    km__bspan_eval_u(&sp, u, pos, d);
    double v = sqrt(d[0] * d[0] + d[1] * d[1]);
    double un = v > 0 ? u - f / v : 0.5 * (lo + hi);
    if (!(un > lo && un < hi) || !isfinite(un)) un = 0.5 * (lo + hi);
    if (un == u) break;
    u = un;
  }
  return sp.a + (sp.b - sp.a) * u;
}

/* Bezier form of one span by blossoming the homogeneous control points:
 * b_k = f(a^(p-k), b^k). */
void km__bspan_make(km__bspan *sp, const km_curve *c, size_t i) {
  int p = c->degree;
  const double *U = c->knots;
  double a = U[i], b = U[i + 1];
  sp->degree = p;
  sp->a = a;
  sp->b = b;
  sp->rational = c->w != NULL;
  for (int k = 0; k <= p; k++) {
    double d[KM__BSPAN_MAX][3];
    for (int j = 0; j <= p; j++) {
      size_t g = i - (size_t)p + (size_t)j;
      double w = c->w ? c->w[g] : 1.0;
      d[j][0] = c->cp[2 * g] * w;
      d[j][1] = c->cp[2 * g + 1] * w;
      d[j][2] = w;
    }
    for (int r = 1; r <= p; r++) {
      double u = r <= p - k ? a : b;
      for (int j = p; j >= r; j--) {
        double lo = U[i - (size_t)p + (size_t)j];
        double hi = U[i + 1 + (size_t)j - (size_t)r];
        double al = (u - lo) / (hi - lo);
        for (int q = 0; q < 3; q++) d[j][q] = (1.0 - al) * d[j - 1][q] + al * d[j][q];
      }
    }
    for (int q = 0; q < 3; q++) sp->h[k][q] = d[p][q];
  }
}

/* de Casteljau on the homogeneous points of a rational span down to the
 * last step's two points, d[0] and d[1] (x w, y w, w) */
static void homogeneous_to_last_step(const km__bspan *sp, double u,
                                     double d[][3]) {
  int p = sp->degree;
  double v = 1.0 - u;
  memcpy(d, sp->h, sizeof(double) * 3 * (size_t)(p + 1));
  for (int r = 1; r < p; r++)
    for (int j = 0; j <= p - r; j++) {
      d[j][0] = v * d[j][0] + u * d[j + 1][0];
      d[j][1] = v * d[j][1] + u * d[j + 1][1];
      d[j][2] = v * d[j][2] + u * d[j + 1][2];
    }
}

/* km__bspan_eval_u, and in *wf (if not NULL) the factor by which the
 * rounding of the points reaches the derivative beyond its polynomial
 * share (see km__bspan_eval) */
static void eval_u(const km__bspan *sp, double u, double pos[2],
                   double der_u[2], double *wf) {
  int p = sp->degree;
  double v = 1.0 - u;
  if (wf) *wf = 1.0;
  if (!sp->rational && p == 3) {
    /* cubics (every SVG curve): the same de Casteljau steps, unrolled */
    for (int q = 0; q < 2; q++) {
      double a = v * sp->h[0][q] + u * sp->h[1][q];
      double b = v * sp->h[1][q] + u * sp->h[2][q];
      double c = v * sp->h[2][q] + u * sp->h[3][q];
      double d = v * a + u * b, e = v * b + u * c;
      pos[q] = v * d + u * e;
      der_u[q] = 3.0 * (e - d);
    }
    return;
  }
  if (!sp->rational) {
    /* weights 1: Horner in s = u / (1 - u), or its reciprocal past the
     * middle so that s <= 1, on the control points and on the legs (the
     * hodograph): O(p) instead of de Casteljau's O(p^2), with the same
     * error bound (see km__bern_eval), and the derivative from the legs'
     * differences keeps its digits far from the origin */
    const double *bp = km__binomial[p], *bq = km__binomial[p - 1];
    for (int q = 0; q < 2; q++) {
      double a, b, f = 1.0;
      if (u <= 0.5) {
        double s = u / v;
        a = sp->h[p][q];
        b = sp->h[p][q] - sp->h[p - 1][q];
        for (int j = p - 1; j >= 0; j--) {
          a = a * s + sp->h[j][q] * bp[j];
          if (j < p - 1) b = b * s + (sp->h[j + 1][q] - sp->h[j][q]) * bq[j];
        }
        for (int j = 1; j < p; j++) f *= v;
        pos[q] = a * f * v;
      } else {
        double s = v / u;
        a = sp->h[0][q];
        b = sp->h[1][q] - sp->h[0][q];
        for (int j = 1; j <= p; j++) {
          a = a * s + sp->h[j][q] * bp[j];
          if (j < p) b = b * s + (sp->h[j + 1][q] - sp->h[j][q]) * bq[j];
        }
        for (int j = 1; j < p; j++) f *= u;
        pos[q] = a * f * u;
      }
      der_u[q] = p * b * f;
    }
    return;
  }
  double d[KM__BSPAN_MAX][3];
  homogeneous_to_last_step(sp, u, d);
  /* The last step joins two points P0, P1 of weights w0, w1: C = (v w0 P0
   * + u w1 P1) / w and C' = p w0 w1 / w^2 (P1 - P0), with w = v w0 + u w1.
   * Unlike the quotient rule (H' - C w') / w, no large terms cancel, so
   * the direction keeps its digits whatever the weights. */
  double w0 = d[0][2], w1 = d[1][2], w = v * w0 + u * w1;
  double f = p * (w0 / w) * (w1 / w);
  for (int q = 0; q < 2; q++) {
    pos[q] = (v * d[0][q] + u * d[1][q]) / w;
    der_u[q] = f * (d[1][q] / w1 - d[0][q] / w0);
  }
  if (wf) *wf = f / p;
}

void km__bspan_eval_u(const km__bspan *sp, double u, double pos[2],
                      double der_u[2]) {
  eval_u(sp, u, pos, der_u, NULL);
}

void km__bspan_eval(const km__bspan *sp, double t, double pos[2],
                    double der[2], double *wf) {
  double len = sp->b - sp->a;
  eval_u(sp, (t - sp->a) / len, pos, der, wf);
  der[0] /= len;
  der[1] /= len;
}

/* |dC/du|; without weights from the hodograph, p times the Bezier curve of
 * the legs, at a third of the cost of position and derivative */
static double polynomial_speed_u(const km__bspan *sp, double u) {
  int p = sp->degree;
  double v = 1.0 - u, e[KM__BSPAN_MAX][2];
  for (int j = 0; j < p; j++) {
    e[j][0] = sp->h[j + 1][0] - sp->h[j][0];
    e[j][1] = sp->h[j + 1][1] - sp->h[j][1];
  }
  for (int r = 1; r < p; r++)
    for (int j = 0; j < p - r; j++) {
      e[j][0] = v * e[j][0] + u * e[j + 1][0];
      e[j][1] = v * e[j][1] + u * e[j + 1][1];
    }
  double dx = p * e[0][0], dy = p * e[0][1];
  return sqrt(dx * dx + dy * dy);
}

/* |dC/du| of a rational span by km__bspan_eval_u's steps (the same
 * digits) without the position, and in *f the weight factor p w0 w1 / w^2
 * of its last step, by which the rounding of the points is multiplied. */
static double rational_speed_u(const km__bspan *sp, double u, double *f) {
  int p = sp->degree;
  double v = 1.0 - u, d[KM__BSPAN_MAX][3];
  homogeneous_to_last_step(sp, u, d);
  double w0 = d[0][2], w1 = d[1][2], w = v * w0 + u * w1;
  *f = p * (w0 / w) * (w1 / w);
  double dx = *f * (d[1][0] / w1 - d[0][0] / w0);
  double dy = *f * (d[1][1] / w1 - d[0][1] / w0);
  return sqrt(dx * dx + dy * dy);
}

double km__bspan_noise(const km__bspan *sp) {
  double M = 0.0;
  for (int q = 0; q <= sp->degree; q++)
    M = fmax(M, fmax(fabs(sp->h[q][0]), fabs(sp->h[q][1])) /
                    fmax(sp->h[q][2], 1e-300));
  return 8.0 * DBL_EPSILON * sp->degree * M;
}

/* A span's speed is computed from points of magnitude up to M: its
 * rounding, 8 eps M (unit) times the weight factor f of the last de
 * Casteljau step (rational_speed_u) - p without weights, but up to p times
 * the ratio of the extreme weights where a small weight meets a large one.
 * There f is large only over a stretch of u about as narrow as that ratio
 * is large (the curve leaves such a point in a boundary layer of the
 * parameter): the rounding is local, and so is the precision a length can
 * have. */
typedef struct span_quad {
  const km__bspan *sp;
  double unit;
  long evals;
} span_quad;

/* The 16-point rule on [a, b], and in *noise the rounding its sum may
 * carry: the largest rounding of the speed at its nodes over the width. */
static double span_gl16(span_quad *q, double a, double b, double *noise) {
  const km__bspan *sp = q->sp;
  double m = 0.5 * (a + b), h = 0.5 * (b - a), sum = 0.0, fmaxn;
  q->evals += 16;
  if (!sp->rational) {
    for (int k = 0; k < 16; k++)
      sum += km__gl16_w[k] * polynomial_speed_u(sp, m + h * km__gl16_x[k]);
    fmaxn = sp->degree;
  } else {
    /* Where small and large weights meet, the speed also varies so fast
     * (by a factor e per 1e-3 of u near the end of a rational cubic at
     * 1e15 whose end weight is 1e-4 of its neighbour's) that rounding the
     * nodes to doubles, by eps |u|, moves it by 1e-13 of itself: more than
     * the points' rounding, and as local. Bisection toward such a point
     * found halves and whole differing by that at every depth, and the
     * length of a part of the span came out NaN. The slope comes from
     * neighbouring nodes. */
    double v[16], slope = 0.0;
    fmaxn = 0.0;
    for (int k = 0; k < 16; k++) {
      double f;
      v[k] = rational_speed_u(sp, m + h * km__gl16_x[k], &f);
      sum += km__gl16_w[k] * v[k];
      fmaxn = fmax(fmaxn, f);
    }
    for (int k = 1; k < 16; k++)
      slope = fmax(slope, fabs(v[k] - v[k - 1]) /
                              (h * (km__gl16_x[k - 1] - km__gl16_x[k])));
    *noise = (q->unit * fmaxn +
              slope * DBL_EPSILON * fmax(fabs(a), fabs(b))) *
             (b - a);
    return sum * h;
  }
  *noise = q->unit * fmaxn * (b - a);
  return sum * h;
}

/* Adaptive quadrature as integrate_rec (the 16-point rule on [a, b]
 * against its halves, bisecting where they differ by more than the
 * tolerance), except that a difference within the rounding the rules
 * carry there is accepted: it cannot be refined, and it is local. Asking
 * the whole span instead for the rounding of its worst point (the ratio
 * of its extreme weights times the span's noise, wherever the uniform
 * request fails) lets the first rule through unrefined: both it and its
 * halves step over a boundary layer narrower than their nodes' spacing (a
 * degree-9 span at 1e6 whose weights jump from 0.1 to 100 at a
 * degenerate leg leaves its first point within about 1e-4 in u) and
 * agreed on a length 9.2e-6 (2e-5 of it) too long at a tolerance of
 * 1e-6, where the rounding over the span integrates to about 1e-8. */
static double span_rec(span_quad *q, double a, double b, double whole,
                       double whole_noise, double abs_tol, int depth,
                       long *budget) {
  double m = 0.5 * (a + b), nl, nr;
  double l = span_gl16(q, a, m, &nl), r = span_gl16(q, m, b, &nr);
  double sum = l + r;
  double rounding =
      fmax(64 * DBL_EPSILON * fabs(sum), fmax(whole_noise, nl + nr));
  /* nor where [a, b] is so narrow beside its position that the nodes are
   * rounded by a part in a thousand: halving it only moves them */
  if (fabs(sum - whole) <= fmax(abs_tol, rounding) ||
      b - a <= 1024 * DBL_EPSILON * fmax(fabs(a), fabs(b)))
    return sum;
  if (depth >= 40 || --*budget <= 0) return NAN; /* not to the precision */
  return span_rec(q, a, m, l, nl, 0.5 * abs_tol, depth + 1, budget) +
         span_rec(q, m, b, r, nr, 0.5 * abs_tol, depth + 1, budget);
}

/* ---- where the quadrature must not step over a feature ----------------
 *
 * Adaptive quadrature judges a length by comparing rules, and two rules
 * agree on a wrong value when the speed has a feature narrower than the
 * spacing of both rules' nodes. Two such features are found from the
 * span's Bernstein coefficients rather than by sampling:
 *   - A hairpin: C' passes close by zero, and |C'| has a V-shaped dip (the
 *     tangent turns by nearly pi within it). Where no node lands in the
 *     dip, every rule integrates the smooth branch on one side across it
 *     and the run into the tip and back is lost: an open cubic near 1e12
 *     whose span turns back 5e-4 of the span from its start was measured
 *     2,503 too short (1.6e-6 of it) at every depth, its nodes all beyond
 *     the tip. dC/du is N(u) / w(u)^2 with N a polynomial in Bernstein form
 *     (degree p - 1 without weights; 2p - 1 with them, N = A' w - A w' for
 *     the homogeneous numerator A taken about the span's first point,
 *     whose large coordinates would otherwise cancel). Where N's
 *     coefficients lie in a cone of half-angle 60 degrees, |C'| is at
 *     least half of a polynomial with non-negative coefficients over w^2
 *     and has no dip; elsewhere the interval is halved (de Casteljau)
 *     until its parts pass, and where a part fails whose halves pass,
 *     their common end is a break. A smooth turn (a semicircle) passes
 *     after a halving or two, and the first three halvings are wide
 *     enough for the rules' nodes to sample what lies in them; only a
 *     real dip goes deep. Split there, the dip's wrong branch (beyond the
 *     point where the tangent has turned through 60 degrees from its
 *     least speed) is some |C'|min / |C''| wide and costs about
 *     |C'|min^2 / |C''|: second order in the least speed.
 *   - A boundary layer: where a small weight meets a large one, w has a
 *     zero just outside the interval, and the curve leaves the small
 *     weight's point within a part of u about as narrow as their ratio is
 *     large: a degree-9 segment at 1e6 whose weights jump from 0.1 to 300
 *     at a degenerate leg was measured 7.7e-7 short (its nodes all beyond
 *     the layer). Where w's coefficients on a part differ by more than a
 *     factor 4, w's zero is at least about as far from the part as the
 *     part is wide, and the rules converge honestly; elsewhere the part is
 *     halved and every halving is a break, so parts shrink geometrically
 *     toward the layer. */
#define HODO_MAX (2 * KM__BSPAN_MAX)
#define PART_VISITS 4096
#define BREAKS_MAX 256

typedef struct part_search {
  double floor; /* N's coefficients below this are rounding: no direction */
  double tiny;  /* a part this short in length is not halved further */
  int dn, dw;   /* the degrees of N and of w */
  int visits;
  size_t n;
  double out[BREAKS_MAX];
} part_search;

/* N (x, y) and w in Bernstein form on a part of the span */
typedef struct part {
  double x[HODO_MAX], y[HODO_MAX], w[KM__BSPAN_MAX];
} part;

/* Whether N's coefficients above the floor lie within 60 degrees of their
 * sum (any axis serves the bound; this one needs no square roots), and in
 * *big the largest magnitude. */
static bool hodo_in_cone(const part *pt, int d, double floor, double *big) {
  double ex = 0.0, ey = 0.0, n2[HODO_MAX], big2 = 0.0, f2 = floor * floor;
  for (int j = 0; j <= d; j++) {
    n2[j] = pt->x[j] * pt->x[j] + pt->y[j] * pt->y[j];
    big2 = fmax(big2, n2[j]);
    if (n2[j] > f2) {
      ex += pt->x[j];
      ey += pt->y[j];
    }
  }
  *big = sqrt(big2);
  double e2 = ex * ex + ey * ey;
  for (int j = 0; j <= d; j++) {
    if (!(n2[j] > f2)) continue;
    double dot = pt->x[j] * ex + pt->y[j] * ey;
    if (!(dot > 0.0 && dot * dot >= 0.25 * n2[j] * e2)) return false;
  }
  return true;
}

static void restrict_part(const part_search *ps, const part *pt, bool weights,
                          double u0, double u1, part *out) {
  km__bern_restrict(pt->x, ps->dn, u0, u1, out->x);
  km__bern_restrict(pt->y, ps->dn, u0, u1, out->y);
  if (weights) km__bern_restrict(pt->w, ps->dw, u0, u1, out->w);
}

static void add_break(part_search *ps, double u) {
  if (ps->n < BREAKS_MAX) ps->out[ps->n++] = u;
}

/* The part [a, b] (weights: whether w counts): true where it needs no
 * break inside */
static bool find_breaks(part_search *ps, const part *pt, bool weights,
                        double a, double b, int depth) {
  double big, wlo = 1.0, whi = 1.0;
  if (weights) {
    wlo = whi = pt->w[0];
    for (int j = 1; j <= ps->dw; j++) {
      wlo = fmin(wlo, pt->w[j]);
      whi = fmax(whi, pt->w[j]);
    }
  }
  bool cone = hodo_in_cone(pt, ps->dn, ps->floor, &big);
  bool layer = whi > 4.0 * wlo;
  if ((cone && !layer) || ++ps->visits > PART_VISITS) return true;
  double m = 0.5 * (a + b);
  if ((b - a) * big / (wlo * wlo) <= ps->tiny || depth >= 60 ||
      b - a <= 1024 * DBL_EPSILON * fmax(fabs(a), fabs(b))) {
    if (depth >= 3 || layer) add_break(ps, m);
    return false;
  }
  part half;
  size_t before = ps->n;
  restrict_part(ps, pt, weights, 0.0, 0.5, &half);
  bool lp = find_breaks(ps, &half, weights, a, m, depth + 1);
  restrict_part(ps, pt, weights, 0.5, 1.0, &half);
  bool rp = find_breaks(ps, &half, weights, m, b, depth + 1);
  if (layer || (lp && rp && depth >= 3)) {
    /* in order: the left half's breaks stand before the right half's */
    size_t k = before;
    while (k < ps->n && ps->out[k] < m) k++;
    if (ps->n < BREAKS_MAX) {
      memmove(ps->out + k + 1, ps->out + k, (ps->n - k) * sizeof(double));
      ps->out[k] = m;
      ps->n++;
    }
  }
  return false;
}

/* The breaks of (u0, u1), in order, down to parts no longer than tiny,
 * where N's coefficients below floor are rounding: ps->out[0 .. ps->n). */
static void span_breaks(const km__bspan *sp, double u0, double u1,
                        double floor, double tiny, part_search *ps) {
  int p = sp->degree;
  part whole, pt;
  ps->n = 0;
  ps->visits = 0;
  for (int k = 0; k <= p; k++) whole.w[k] = sp->h[k][2];
  if (!sp->rational) {
    ps->dn = p - 1;
    for (int j = 0; j < p; j++) {
      whole.x[j] = p * (sp->h[j + 1][0] - sp->h[j][0]);
      whole.y[j] = p * (sp->h[j + 1][1] - sp->h[j][1]);
    }
  } else {
    /* N_k = sum over i + j = k of C(p-1, i) C(p, j) / C(2p-1, k)
     * (dA_i w_j - dw_i A_j), the product rule of Bernstein forms */
    const double *w = whole.w;
    double A[KM__BSPAN_MAX][2];
    double ox = sp->h[0][0] / sp->h[0][2], oy = sp->h[0][1] / sp->h[0][2];
    for (int j = 0; j <= p; j++) {
      A[j][0] = sp->h[j][0] - w[j] * ox;
      A[j][1] = sp->h[j][1] - w[j] * oy;
    }
    int d = ps->dn = 2 * p - 1;
    for (int k = 0; k <= d; k++) whole.x[k] = whole.y[k] = 0.0;
    for (int i = 0; i < p; i++) {
      double dax = p * (A[i + 1][0] - A[i][0]), day = p * (A[i + 1][1] - A[i][1]);
      double dw = p * (w[i + 1] - w[i]);
      for (int j = 0; j <= p; j++) {
        double f = km__binomial[p - 1][i] * km__binomial[p][j] /
                   km__binomial[d][i + j];
        whole.x[i + j] += f * (dax * w[j] - dw * A[j][0]);
        whole.y[i + j] += f * (day * w[j] - dw * A[j][1]);
      }
    }
  }
  ps->floor = floor;
  ps->tiny = tiny;
  ps->dw = p;
  restrict_part(ps, &whole, sp->rational, u0, u1, &pt);
  find_breaks(ps, &pt, sp->rational, u0, u1, 0);
}

double km__bspan_length_counted(const km__bspan *sp, double u0, double u1,
                                double abs_tol, long *evals) {
  if (!(u1 > u0)) return 0.0;
  /* Asking for more than the span's rounding (km__bspan_noise) over the
   * width only refines into noise (a short span far from the origin). A
   * rational span is granted up to four times that at once where its
   * weights vary by more than a factor 4 - a few units of the weight
   * factor over the span - and beyond that only where the rounding is
   * locally larger (span_rec). */
  double wmax = 0.0, wmin = INFINITY;
  for (int k = 0; k <= sp->degree; k++) {
    wmax = fmax(wmax, sp->h[k][2]);
    wmin = fmin(wmin, sp->h[k][2]);
  }
  double ratio = sp->rational ? wmax / wmin : 1.0;
  double noise = km__bspan_noise(sp);
  span_quad q = {sp, noise / sp->degree, 0};
  double tol = fmax(abs_tol, noise * (u1 - u0) * fmin(ratio, 4.0));
  /* the rules must not step over a hairpin's tip or a boundary layer:
   * parts end there */
  part_search ps;
  /* N's rounding: the points' (noise, over p) times p and the weights'
   * scale twice */
  span_breaks(sp, u0, u1, noise * (sp->rational ? wmax * wmax : 1.0),
              0.0625 * tol, &ps);
  double len = 0.0, a = u0;
  long budget = 256 + 8 * (long)ps.n;
  for (size_t i = 0; i <= ps.n; i++) {
    double b = i < ps.n ? ps.out[i] : u1, wn;
    if (!(b > a)) continue;
    double whole = span_gl16(&q, a, b, &wn);
    len += span_rec(&q, a, b, whole, wn, tol * ((b - a) / (u1 - u0)), 0,
                    &budget);
    a = b;
  }
  if (evals) *evals += q.evals;
  return len;
}

double km__bspan_length(const km__bspan *sp, double u0, double u1,
                        double abs_tol) {
  return km__bspan_length_counted(sp, u0, u1, abs_tol, NULL);
}
