/* fn.h - scalar B-spline functions on an interval, e.g. kappa(s).
 *
 * Knot vectors are clamped (first and last value repeated degree+1 times);
 * interior knots may reach multiplicity degree+1, which makes the function
 * jump there (curvature jumps at C1 joins of the input curve). At a jump
 * the right-hand value is used except at the end of the domain.
 *
 * Ownership as for km_curve: one heap block, km_fn_init / km_fn_free
 * (NULL-safe), out-parameters written only on success, immutable after
 * construction, so any number of threads may read one at once. The
 * conventions of km/kmorph.h hold. Errors name the kappa fields
 * (KM_FIELD_KAPPA_*), as a km_fn's one use in the service is a
 * signature's curvature.
 */
#ifndef KM_FN_H
#define KM_FN_H

#include "km/export.h"

#include <stddef.h>

#include "km/status.h"

typedef struct km_fn {
  int degree;    /* 0..KM_MAX_FN_DEGREE */
  size_t n;      /* number of coefficients */
  double *knots; /* n + degree + 1 */
  double *coef;  /* n */
} km_fn;

/* Make *f empty (all zero); f may be NULL. Allocates nothing. */
KM_API void km_fn_init(km_fn *f);

/* Free what *f owns and leave it empty; f may be NULL or empty. */
KM_API void km_fn_free(km_fn *f);

/* Validating constructor; knots (n + degree + 1) and coef (n) are
 * borrowed and copied into out (owned by the caller). Returns KM_OK, or
 * for the first fault found (err->index the element, -1 if none):
 *   KM_EDEGREE     degree outside 0..KM_MAX_FN_DEGREE
 *                  (KM_FIELD_KAPPA_DEGREE);
 *   KM_ECOUNT      knots or coef NULL, or n < degree + 1
 *                  (KM_FIELD_KAPPA_COEFFICIENTS);
 *   KM_ENONFINITE / KM_ERANGE  a coefficient (KM_FIELD_KAPPA_COEFFICIENTS)
 *                  or knot (KM_FIELD_KAPPA_KNOTS) not finite or above
 *                  KM_MAX_COORDINATE in magnitude;
 *   KM_EKNOTS      knots decreasing, not clamped, interior multiplicity
 *                  above degree + 1, or an empty domain
 *                  (KM_FIELD_KAPPA_KNOTS);
 *   KM_ENOMEM. */
KM_API km_status km_fn_create(km_fn *out, int degree, size_t n,
                              const double *knots, const double *coef,
                              km_error *err);

/* Deep copy of f into out, validated as km_fn_create (whose statuses it
 * returns; an empty f gives KM_ECOUNT). */
KM_API km_status km_fn_copy(km_fn *out, const km_fn *f, km_error *err);

/* Constant function c on [a, b] (degree 0, one coefficient) into out.
 * Returns km_fn_create's statuses: KM_EKNOTS unless a < b, KM_ENONFINITE /
 * KM_ERANGE for a, b or c, KM_ENOMEM. */
KM_API km_status km_fn_constant(km_fn *out, double a, double b, double c,
                                km_error *err);

/* Domain [knots[degree], knots[n]] into *a and *b (out). */
KM_API void km_fn_domain(const km_fn *f, double *a, double *b);

/* Value and derivatives up to order nder >= 0 at x (clamped to the
 * domain) into out[0..nder] (out): derivatives above the degree are 0. At
 * a knot the right-hand limit is used, at the end of the domain the left
 * one. km_fn_value is out[0] alone. */
KM_API void km_fn_eval(const km_fn *f, double x, int nder, double *out);
KM_API double km_fn_value(const km_fn *f, double x);

/* Exact antiderivative F of f with F(a) = c0, a the start of the domain:
 * degree + 1, one more coefficient, the same breakpoints; continuous
 * across a jump of f. out owned by the caller. Returns KM_OK, KM_EDEGREE
 * (f's degree is already KM_MAX_FN_DEGREE; KM_FIELD_KAPPA_DEGREE),
 * KM_ENOMEM. */
KM_API km_status km_fn_antiderivative(km_fn *out, const km_fn *f, double c0,
                                      km_error *err);

/* Exact integral of f over its whole domain (sum of coefficients times
 * their basis integrals). */
KM_API double km_fn_integral(const km_fn *f);

/* Upper bound on max |f| over [x0, x1] (within the domain; 0 if the two
 * do not meet): the largest Bernstein coefficient of f restricted to that
 * interval, tight to about the square of the span width. Never below the
 * true maximum; without memory for the Bernstein form, the largest |c_i|
 * over the whole domain. */
KM_API double km_fn_abs_bound(const km_fn *f, double x0, double x1);

/* Maximum of |f| over the domain, to 1e-13 relative (subdivision of the
 * Bernstein pieces toward the maximum, at most 60 levels deep); without
 * memory for the Bernstein form, km_fn_abs_bound over the domain. */
KM_API double km_fn_max_abs(const km_fn *f);

/* Integral of f^2 over the domain, exact up to rounding (products of the
 * Bernstein pieces in closed form). NaN when memory runs out. */
KM_API double km_fn_integral_sq(const km_fn *f);

/* Linear blend over a normalised domain: out is defined on [u0, u1] and
 *   out(u0 + r (u1-u0)) = wa * a(a0 + r (a1-a0)) + wb * b(b0 + r (b1-b0))
 * for r in [0,1], [a0, a1] and [b0, b1] the domains of a and b, exactly:
 * the breakpoints of both merged (closer than 1e-13 of the normalised
 * domain taken as one), degrees raised to the larger. wa and wb are used
 * as given (not checked: finite weights give a finite blend). out owned
 * by the caller. Returns KM_OK, KM_EINVAL (u0 >= u1 or either not finite),
 * KM_ENOMEM. */
KM_API km_status km_fn_blend(km_fn *out, const km_fn *a, double wa,
                             const km_fn *b, double wb, double u0, double u1,
                             km_error *err);

#endif
