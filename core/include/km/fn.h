/* fn.h - scalar B-spline functions on an interval, e.g. kappa(s).
 *
 * Knot vectors are clamped (first and last value repeated degree+1 times);
 * interior knots may reach multiplicity degree+1, which makes the function
 * jump there (curvature jumps at C1 joins of the input curve). At a jump
 * the right-hand value is used except at the end of the domain.
 *
 * Ownership as for km_curve: one heap block, km_fn_init / km_fn_free
 * (NULL-safe), out-parameters written only on success, immutable after
 * construction.
 */
#ifndef KM_FN_H
#define KM_FN_H

#include <stddef.h>

#include "km/status.h"

typedef struct km_fn {
  int degree;     /* 0..KM_MAX_FN_DEGREE */
  size_t n;       /* number of coefficients */
  double *knots;  /* n + degree + 1 */
  double *coef;   /* n */
} km_fn;

void km_fn_init(km_fn *f);
void km_fn_free(km_fn *f);

/* Validating constructor (copies): degree 0..KM_MAX_FN_DEGREE (KM_EDEGREE), counts
 * (KM_ECOUNT), finite (KM_ENONFINITE), knots non-decreasing and clamped with
 * interior multiplicity <= degree+1 and a non-empty domain (KM_EKNOTS). */
km_status km_fn_create(km_fn *out, int degree, size_t n, const double *knots,
                       const double *coef, km_error *err);
km_status km_fn_copy(km_fn *out, const km_fn *f, km_error *err);

/* Constant function c on [a, b]. */
km_status km_fn_constant(km_fn *out, double a, double b, double c,
                         km_error *err);

void km_fn_domain(const km_fn *f, double *a, double *b);

/* Value and derivatives up to nder (<= degree+1, higher are 0) at x. */
void km_fn_eval(const km_fn *f, double x, int nder, double *out);
double km_fn_value(const km_fn *f, double x);

/* Exact antiderivative F with F(a) = c0 (degree + 1). Across a jump of f
 * F stays continuous. */
km_status km_fn_antiderivative(km_fn *out, const km_fn *f, double c0,
                               km_error *err);

/* Exact integral over the whole domain. */
double km_fn_integral(const km_fn *f);

/* Upper bound on max |f| over [x0, x1] (subset of the domain), tight to
 * about the square of the span width (Bernstein coefficients after
 * subdivision), and the exact maximum of |f| over the domain to 1e-12
 * relative (critical points by subdivision). */
double km_fn_abs_bound(const km_fn *f, double x0, double x1);
double km_fn_max_abs(const km_fn *f);

/* Integral of f^2 over the domain (exact for a spline, Gauss-Legendre). */
double km_fn_integral_sq(const km_fn *f);

/* Linear blend over a normalised domain: out is defined on [u0, u1] and
 *   out(u0 + r (u1-u0)) = wa * a(a0 + r (a1-a0)) + wb * b(b0 + r (b1-b0))
 * for r in [0,1], exactly (breakpoints merged, degrees raised). */
km_status km_fn_blend(km_fn *out, const km_fn *a, double wa, const km_fn *b,
                      double wb, double u0, double u1, km_error *err);

#endif
