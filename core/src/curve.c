/* curve.c - construction, validation and evaluation of planar B-spline /
 * NURBS curves.
 *
 * Evaluation computes the non-zero basis functions and their derivatives
 * on the knot span (Cox-de Boor with derivatives, as in Piegl & Tiller
 * A2.3) and applies the quotient rule for rational curves. Arc length is
 * curve_length.c, spans in Bezier form curve_span.c.
 */
#include <float.h>
#include <math.h>
#include <string.h>

#include "internal.h"
#include "kernels.h"
#include "km/alloc.h"
#include "km/limits.h"

void km_curve_init(km_curve *c) {
  if (c) memset(c, 0, sizeof *c);
}

void km_curve_free(km_curve *c) {
  if (!c) return;
  km__free(c->knots);
  memset(c, 0, sizeof *c);
}

km_status km__curve_alloc(km_curve *c, int degree, size_t n, bool rational) {
  size_t nk = n + (size_t)degree + 1;
  size_t total = nk + 2 * n + (rational ? n : 0);
  if (n == 0 || total > ((size_t)-1) / sizeof(double)) return KM_ENOMEM;
  double *block = km__malloc(total * sizeof(double));
  if (!block) return KM_ENOMEM;
  c->degree = degree;
  c->n = n;
  c->knots = block;
  c->cp = block + nk;
  c->w = rational ? block + nk + 2 * n : NULL;
  c->closed = false;
  return KM_OK;
}

static bool bad_number(double v) {
  return !isfinite(v);
}

/* ---- the checks of km_curve_create, in the order their errors are
 * reported: control points, knot values, the clamped ends and interior
 * multiplicities, weights, the closing point. */
static km_status check_points(const double *cp, size_t n, km_error *err) {
  for (size_t i = 0; i < n; i++) {
    for (int k = 0; k < 2; k++) {
      double v = cp[2 * i + (size_t)k];
      if (bad_number(v))
        return km__fail(err, KM_ENONFINITE, KM_FIELD_CONTROL_POINTS, (long)i,
                        NAN, "control point %zu is not finite", i);
      if (fabs(v) > KM_MAX_COORDINATE)
        return km__fail(err, KM_ERANGE, KM_FIELD_CONTROL_POINTS, (long)i, NAN,
                        "control point %zu exceeds %g in magnitude", i,
                        KM_MAX_COORDINATE);
    }
  }
  return KM_OK;
}

static km_status check_knot_values(const double *knots, size_t nk,
                                   km_error *err) {
  for (size_t i = 0; i < nk; i++) {
    if (bad_number(knots[i]))
      return km__fail(err, KM_ENONFINITE, KM_FIELD_KNOTS, (long)i, NAN,
                      "knot %zu is not finite", i);
    if (fabs(knots[i]) > KM_MAX_COORDINATE)
      return km__fail(err, KM_ERANGE, KM_FIELD_KNOTS, (long)i, NAN,
                      "knot %zu exceeds %g in magnitude", i, KM_MAX_COORDINATE);
    if (i > 0 && knots[i] < knots[i - 1])
      return km__fail(err, KM_EKNOTS, KM_FIELD_KNOTS, (long)i, NAN,
                      "knot vector decreases at index %zu", i);
  }
  return KM_OK;
}

/* Exactly degree + 1 equal knots at each end, a non-empty domain. */
static km_status check_clamped(const double *knots, size_t n, int degree,
                               km_error *err) {
  size_t nk = n + (size_t)degree + 1;
  for (int i = 1; i <= degree; i++) {
    if (knots[i] != knots[0])
      return km__fail(err, KM_EKNOTS, KM_FIELD_KNOTS, (long)i, NAN,
                      "knot vector is not clamped: the first %d knots must "
                      "be equal",
                      degree + 1);
    if (knots[nk - 1 - (size_t)i] != knots[nk - 1])
      return km__fail(err, KM_EKNOTS, KM_FIELD_KNOTS,
                      (long)(nk - 1 - (size_t)i), NAN,
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
  return KM_OK;
}

/* Interior multiplicity at most the degree: the curve stays continuous. */
static km_status check_interior(const double *knots, size_t n, int degree,
                                km_error *err) {
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
  return KM_OK;
}

static km_status check_weights(const double *w, size_t n, km_error *err) {
  for (size_t i = 0; w && i < n; i++) {
    if (bad_number(w[i]))
      return km__fail(err, KM_ENONFINITE, KM_FIELD_WEIGHTS, (long)i, NAN,
                      "weight %zu is not finite", i);
    if (!(w[i] > 0) || w[i] > KM_MAX_COORDINATE ||
        w[i] < 1.0 / KM_MAX_COORDINATE)
      return km__fail(err, KM_EWEIGHT, KM_FIELD_WEIGHTS, (long)i, NAN,
                      "weight %zu must be positive and within [1e-15, "
                      "1e15]",
                      i);
  }
  return KM_OK;
}

/* A closed curve's last control point is its first, to 1e-12 of the
 * coordinates' magnitude (it is then set to the first exactly). */
static km_status check_closed(const double *cp, size_t n, km_error *err) {
  double dx = cp[2 * (n - 1)] - cp[0], dy = cp[2 * (n - 1) + 1] - cp[1];
  double scale = 0;
  for (size_t i = 0; i < 2 * n; i++) scale = fmax(scale, fabs(cp[i]));
  if (hypot(dx, dy) > 1e-12 * fmax(scale, 1e-300))
    return km__fail(err, KM_ECLOSED, KM_FIELD_CLOSED, -1, NAN,
                    "closed curve: first and last control points differ");
  return KM_OK;
}

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
  km_status st = check_points(cp, n, err);
  if (!st) st = check_knot_values(knots, nk, err);
  if (!st) st = check_clamped(knots, n, degree, err);
  if (!st) st = check_interior(knots, n, degree, err);
  if (!st) st = check_weights(w, n, err);
  if (!st && closed) st = check_closed(cp, n, err);
  if (st) return st;
  km_curve c;
  st = km__curve_alloc(&c, degree, n, w != NULL);
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
  km__curve_eval_span(c, km__find_span(c, t, side), t, nder, out);
}

void km__curve_eval_span(const km_curve *c, size_t i, double t, int nder,
                         double out[][2]) {
  int p = c->degree;
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
