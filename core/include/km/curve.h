/* curve.h - planar B-spline and NURBS curves: construction, evaluation and
 * the exact knot-level operations the rest of kmorph is built from.
 *
 * A km_curve is a clamped B-spline of degree 1..KM_MAX_DEGREE with n >=
 * degree+1 control points, n+degree+1 knots and optional positive weights
 * (NURBS). A closed curve is stored clamped with its first and last control
 * points equal; its seam continuity is measured, never assumed.
 *
 * Ownership: a km_curve owns one heap block holding knots, points and
 * weights. km_curve_init() makes an empty curve, km_curve_free() accepts
 * NULL and empty curves. Functions writing a km_curve *out free nothing in
 * it: pass an empty (init'ed) or freed curve. Out-parameters are written
 * only on success. Curves are not changed after construction, so any number
 * of threads may read one at once.
 */
#ifndef KM_CURVE_H
#define KM_CURVE_H

#include <stdbool.h>
#include <stddef.h>

#include "km/status.h"

typedef struct km_curve {
  int degree;
  size_t n;      /* number of control points */
  double *knots; /* n + degree + 1 values, clamped */
  double *cp;    /* 2n values: x0, y0, x1, y1, ... */
  double *w;     /* n weights, or NULL for a polynomial curve */
  bool closed;
} km_curve;

void km_curve_init(km_curve *c);
void km_curve_free(km_curve *c);

/* Build a curve from borrowed arrays (deep-copied), validating everything:
 * degree range (KM_EDEGREE), counts (KM_ECOUNT), finiteness (KM_ENONFINITE),
 * |coordinate| <= KM_MAX_COORDINATE (KM_ERANGE), knots non-decreasing,
 * clamped, interior multiplicity <= degree, non-empty domain (KM_EKNOTS),
 * weights > 0 (KM_EWEIGHT), closed implies first == last point
 * (KM_ECLOSED). `w` may be NULL. err->field/index name the offending
 * element. */
km_status km_curve_create(km_curve *out, int degree, size_t n,
                          const double *knots, const double *cp,
                          const double *w, bool closed, km_error *err);

/* Deep copy. */
km_status km_curve_copy(km_curve *out, const km_curve *c, km_error *err);

/* Parameter domain [knots[degree], knots[n]]. */
void km_curve_domain(const km_curve *c, double *t0, double *t1);

/* Position and derivatives up to order nder (0..3) at t (clamped to the
 * domain): out[k][0..1] is the k-th derivative. Rational curves are handled
 * by the quotient rule. At an interior knot the right-hand limit is used
 * unless t is the end of the domain; km_curve_eval_side chooses. */
void km_curve_eval(const km_curve *c, double t, int nder, double out[][2]);
/* side < 0: left limit at a knot, side >= 0: right limit. */
void km_curve_eval_side(const km_curve *c, double t, int side, int nder,
                        double out[][2]);

/* Insert knot t `times` times (multiplicity never exceeds degree). Exact:
 * the curve traced is unchanged. */
km_status km_curve_insert_knot(km_curve *out, const km_curve *c, double t,
                               int times, km_error *err);

/* Split at interior parameter t into two clamped curves (each open). */
km_status km_curve_split(const km_curve *c, double t, km_curve *left,
                         km_curve *right, km_error *err);

/* Same trace, opposite direction; domain kept. */
km_status km_curve_reverse(km_curve *out, const km_curve *c, km_error *err);

/* Bezier form: every interior knot raised to multiplicity `degree`, so span
 * i has control points degree*i .. degree*(i+1). */
km_status km_curve_to_bezier(km_curve *out, const km_curve *c,
                             km_error *err);

/* Raise the degree by `times` (exact). */
km_status km_curve_elevate(km_curve *out, const km_curve *c, int times,
                           km_error *err);

/* Make a and b compatible: both reparameterised linearly onto [0, 1],
 * raised to the larger degree, knot vectors merged, both rational if either
 * is. The traces are unchanged. */
km_status km_curve_make_compatible(const km_curve *a, const km_curve *b,
                                   km_curve *out_a, km_curve *out_b,
                                   km_error *err);

/* Linear reparameterisation of the domain onto [t0, t1] (t0 < t1). */
km_status km_curve_reparam(km_curve *out, const km_curve *c, double t0,
                           double t1, km_error *err);

/* Arc length of the whole curve, or between parameters ta <= tb, to about
 * 1e-13 relative (adaptive Gauss-Legendre per knot span). */
double km_curve_length(const km_curve *c);
double km_curve_length_between(const km_curve *c, double ta, double tb);

/* Inverse of arc length: the parameter t with length(t0, t) = s (s clamped
 * to [0, L]); safeguarded Newton, to |Δs| <= 1e-12 L. */
double km_curve_param_at_length(const km_curve *c, double s);

/* Build the cubic B-spline interpolating points (chord-length
 * parameterisation). Open: not-a-knot ends. Closed: periodic C2 through the
 * points with the last joined smoothly to the first (the first point need
 * not be repeated). Consecutive duplicate points are dropped. n >= 2. */
km_status km_curve_interpolate(km_curve *out, const double *pts, size_t n,
                               bool closed, km_error *err);

/* A cubic B-spline through the first and last point (closed: through the
 * first point, tangent continuous at the seam) that passes within tol of
 * every point, with few control points (knots added where points miss;
 * see core/src/fit.c). Fewer than 8 points, or input that would need
 * about as many control points as points, get the exact interpolant of
 * km_curve_interpolate. */
km_status km_curve_fit_points(km_curve *out, const double *pts, size_t n,
                              bool closed, double tol, km_error *err);

/* Apply x' = R x + t with R the rotation by angle `rot`. */
km_status km_curve_transform(km_curve *out, const km_curve *c, double rot,
                             double tx, double ty, km_error *err);

#endif
