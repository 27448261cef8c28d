/* curve_length.c - speed and arc length of curves, and the parameter at
 * a given length.
 *
 * Arc length is adaptive Gauss-Legendre per knot span: the speed is
 * smooth inside a span and may have kinks only at knots.
 */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "kernels.h"
#include "km/limits.h"

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
  for (int k = 0; k < 16; k++)
    sum += km__gl16_w[k] * f(ctx, m + h * km__gl16_x[k]);
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
