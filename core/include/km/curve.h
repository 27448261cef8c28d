/* curve.h - planar B-spline and NURBS curves: construction, evaluation,
 * arc length, the exact knot-level operations the rest of kmorph is built
 * from, and counting self-crossings.
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
 * of threads may read one at once. The conventions of km/kmorph.h hold
 * (parameter order, err, validity of inputs, units).
 *
 * Exact operations (insert_knot, split, reverse, to_bezier, elevate,
 * make_compatible, reparam) work on homogeneous points, so the trace is
 * unchanged up to rounding of the control points, rational curves
 * included. Their KM_EINVAL means the curve given is not one (NULL, empty,
 * or a degree or count out of range); their KM_ENONFINITE / KM_EWEIGHT
 * after the arguments are checked can only come from rounding on a curve
 * at the edge of the coordinate range.
 */
#ifndef KM_CURVE_H
#define KM_CURVE_H

#include "km/export.h"

#include <stdbool.h>
#include <stddef.h>

#include "km/status.h"
#include "km/stop.h"

typedef struct km_curve {
  int degree;
  size_t n;      /* number of control points */
  double *knots; /* n + degree + 1 values, clamped */
  double *cp;    /* 2n values: x0, y0, x1, y1, ... */
  double *w;     /* n weights, or NULL for a polynomial curve */
  bool closed;
} km_curve;

/* Make *c empty (all zero), so that km_curve_free may follow whatever
 * happens. c may be NULL. Allocates nothing. */
KM_API void km_curve_init(km_curve *c);

/* Free what *c owns and leave it empty. c may be NULL or empty. */
KM_API void km_curve_free(km_curve *c);

/* Build a curve from borrowed arrays, deep-copied, validating everything.
 *   out     (out) the new curve, owned by the caller (km_curve_free).
 *   degree  1..KM_MAX_DEGREE.
 *   n       number of control points, >= degree + 1.
 *   knots   n + degree + 1 values: non-decreasing, clamped (the first and
 *           last degree + 1 equal, neither repeated more), interior
 *           multiplicity <= degree, non-empty domain [knots[degree],
 *           knots[n]].
 *   cp      2n coordinates x0, y0, x1, ...
 *   w       n weights, or NULL for a polynomial curve.
 *   closed  the first and last control points must agree to 1e-12 of the
 *           largest |coordinate|; the last is then set equal to the first.
 * Returns KM_OK, or for the first fault found (err->field / err->index
 * name the element; index -1 if none):
 *   KM_EDEGREE     degree out of range (KM_FIELD_DEGREE);
 *   KM_ECOUNT      knots or cp NULL, or n < degree + 1
 *                  (KM_FIELD_CONTROL_POINTS);
 *   KM_ENONFINITE  a coordinate (KM_FIELD_CONTROL_POINTS, the point's
 *                  index), a knot (KM_FIELD_KNOTS) or a weight
 *                  (KM_FIELD_WEIGHTS) not finite;
 *   KM_ERANGE      |coordinate| or |knot| > KM_MAX_COORDINATE;
 *   KM_EKNOTS      knots decreasing, not clamped, interior multiplicity
 *                  above the degree, or an empty domain (KM_FIELD_KNOTS);
 *   KM_EWEIGHT     a weight outside [1 / KM_MAX_COORDINATE,
 *                  KM_MAX_COORDINATE] (KM_FIELD_WEIGHTS);
 *   KM_ECLOSED     closed but the end points differ (KM_FIELD_CLOSED);
 *   KM_ENOMEM. */
KM_API km_status km_curve_create(km_curve *out, int degree, size_t n,
                                 const double *knots, const double *cp,
                                 const double *w, bool closed, km_error *err);

/* Deep copy of c into out (owned by the caller), closed flag included.
 * Returns KM_OK or KM_ENOMEM; an empty c (nothing to copy) also gives
 * KM_ENOMEM. */
KM_API km_status km_curve_copy(km_curve *out, const km_curve *c, km_error *err);

/* Parameter domain [knots[degree], knots[n]] into *t0 and *t1 (out). */
KM_API void km_curve_domain(const km_curve *c, double *t0, double *t1);

/* Position and derivatives with respect to t at t, which is clamped to the
 * domain. out (out) has nder + 1 rows, nder clamped to 0..3: out[k][0..1]
 * is the k-th derivative. Derivatives above the degree of a polynomial
 * curve are 0; rational curves use the quotient rule. At an interior knot
 * the right-hand limit is used, at the end of the domain the left one;
 * km_curve_eval_side chooses. */
KM_API void km_curve_eval(const km_curve *c, double t, int nder,
                          double out[][2]);

/* km_curve_eval with the side chosen at a knot: side < 0 the left limit,
 * side >= 0 the right limit (the left one at the end of the domain). */
KM_API void km_curve_eval_side(const km_curve *c, double t, int side, int nder,
                               double out[][2]);

/* Insert knot t (in the domain) `times` times, capped so that no interior
 * multiplicity exceeds the degree; at a domain end nothing is inserted
 * (out is a copy). out (owned by the caller) has the same trace,
 * parameterisation and closed flag. Returns KM_OK, KM_EINVAL (c not a
 * curve; times < 0, field KM_FIELD_TIMES), KM_ENONFINITE (t),
 * KM_ERANGE (t outside the domain; err->param = t), KM_ENOMEM. */
KM_API km_status km_curve_insert_knot(km_curve *out, const km_curve *c,
                                      double t, int times, km_error *err);

/* Split c at t strictly inside the domain into *left on [t0, t] and
 * *right on [t, t1], both open (closed false), meeting in one
 * bit-identical point; each is owned by the caller. Returns KM_OK,
 * KM_EINVAL (c not a curve), KM_ERANGE / KM_ENONFINITE (t not inside the
 * domain; err->param = t), KM_ENOMEM; on failure neither output is
 * written. */
KM_API km_status km_curve_split(const km_curve *c, double t, km_curve *left,
                                km_curve *right, km_error *err);

/* Same trace backwards on the same domain: out(a + b - t) = c(t), closed
 * flag kept; out owned by the caller. Returns KM_OK, KM_EINVAL (c not a
 * curve), KM_ENOMEM. */
KM_API km_status km_curve_reverse(km_curve *out, const km_curve *c,
                                  km_error *err);

/* Bezier form: every interior knot raised to multiplicity `degree`, so
 * span i has control points degree*i .. degree*(i+1). Same trace, domain
 * and closed flag; out owned by the caller. Returns KM_OK, KM_EINVAL (c
 * not a curve), KM_ENOMEM. */
KM_API km_status km_curve_to_bezier(km_curve *out, const km_curve *c,
                                    km_error *err);

/* Degree raised by times >= 0 (exact); each distinct knot's multiplicity
 * grows by times; closed flag kept; out owned by the caller. Returns KM_OK,
 * KM_EINVAL (c not a curve; times < 0, field KM_FIELD_TIMES), KM_EDEGREE
 * (degree + times above KM_MAX_DEGREE, field KM_FIELD_TIMES), KM_ENOMEM. */
KM_API km_status km_curve_elevate(km_curve *out, const km_curve *c, int times,
                                  km_error *err);

/* Make a and b compatible: both reparameterised linearly onto [0, 1],
 * raised to the larger degree, one merged knot vector (each knot with the
 * larger of its two multiplicities; knots closer than 1e-13 are taken as
 * one, and an interior knot within 1e-13 of an end as that end), both
 * rational if either is (unit weights for a polynomial one).
 * The traces and closed flags are unchanged; *out_a and *out_b are owned
 * by the caller, and on failure neither is written. Returns KM_OK,
 * KM_EINVAL (a or b not a curve), KM_EKNOTS (the merged knot vectors do
 * not agree: rounding, not met in practice), KM_ENOMEM. */
KM_API km_status km_curve_make_compatible(const km_curve *a, const km_curve *b,
                                          km_curve *out_a, km_curve *out_b,
                                          km_error *err);

/* Linear reparameterisation of the domain onto [t0, t1]; the trace is
 * unchanged, the domain ends exact; out owned by the caller. Returns
 * KM_OK, KM_EINVAL (c not a curve), KM_ENONFINITE (t0 or t1), KM_ERANGE
 * (t0 >= t1, or |t0| or |t1| > KM_MAX_COORDINATE), KM_ENOMEM. */
KM_API km_status km_curve_reparam(km_curve *out, const km_curve *c, double t0,
                                  double t1, km_error *err);

/* Arc length of the whole curve, or between parameters ta and tb (each
 * clamped to the domain; 0 unless ta < tb). Adaptive Gauss-Legendre per
 * knot span to an absolute 1e-15 of the control polygon's length, or to
 * the span's own rounding (8 degree ulps of its largest coordinate) where
 * that is larger. 0 for a curve whose control points all coincide. NaN
 * when the speed over a span is rounding noise and the quadrature cannot
 * reach that precision (km_signature_compute refuses such a curve with
 * KM_ENOCONVERGE): callers that must not see NaN check isfinite. */
KM_API double km_curve_length(const km_curve *c);
KM_API double km_curve_length_between(const km_curve *c, double ta, double tb);

/* Arc length of the whole curve to within rel_tol of itself (rel_tol
 * below 1e-13 is taken as 1e-13), by a bound that is proven, not
 * estimated: on each span of a polynomial cubic the error of a
 * Gauss-Legendre rule is bounded from where the speed's continuation to
 * the complex plane vanishes, and a piece is halved until the bound
 * passes. Any other curve, or a cubic whose bound does not pass within a
 * fixed amount of work (a span whose speed vanishes), is measured by
 * km_curve_length. About a tenth of km_curve_length's work on a glyph
 * morph's frames, and its value agrees with km_curve_length's to
 * rel_tol: for lengths a caller prints, not for lengths the morph
 * computes with (its frames depend on km_curve_length's own digits). c
 * a valid curve; thread-safe. */
KM_API double km_curve_length_within(const km_curve *c, double rel_tol);

/* Inverse of arc length: the parameter t with length(t0, t) = s. s <= 0
 * gives t0, s at or beyond the length t1. Safeguarded Newton inside the span
 * holding s (bisection when a step leaves the bracket, at most
 * KM_MAX_NEWTON_ITERATIONS steps), to |length error| <= 1e-13 of that
 * span's length. */
KM_API double km_curve_param_at_length(const km_curve *c, double s);

/* The cubic B-spline interpolating the n points pts (2n coordinates),
 * chord-length parameters on [0, 1]. Open: not-a-knot ends; 2 points give
 * the segment at uniform speed, 3 the parabola. Closed: periodic C2, the
 * last point joined smoothly to the first (the first point need not be
 * repeated), stored clamped with the first point repeated at the end.
 * Consecutive duplicate points (and, closed, repeats of the first point at
 * the end) are dropped first. out owned by the caller. Returns KM_OK,
 * KM_EINVAL (pts NULL with n > 0), KM_ELIMIT (n too large to allocate
 * for), KM_ENONFINITE / KM_ERANGE (a point, KM_FIELD_POINTS, err->index
 * names it), KM_EDEGENERATE (fewer than 2 distinct points, 3 when closed,
 * or points too close to separate; KM_FIELD_POINTS), KM_ENOCONVERGE (the
 * interpolation system is singular; KM_FIELD_POINTS), KM_ERANGE (the
 * interpolant overflows the coordinate range, index -1), KM_ENOMEM. */
KM_API km_status km_curve_interpolate(km_curve *out, const double *pts,
                                      size_t n, bool closed, km_error *err);

/* A cubic B-spline with few control points that passes through the first
 * and last point (closed: through the first point, tangent continuous at
 * the seam) and within tol, a
 * distance, of every point: knots are added where points miss. Fewer than
 * 8 points, tol <= 0 or not finite, or input that would need about as many
 * control points as points (or more than 400), get the exact interpolant
 * of km_curve_interpolate. out owned by the caller. Returns
 * km_curve_interpolate's statuses, km_curve_create's for the fitted
 * control points (KM_FIELD_CONTROL_POINTS), KM_ENOMEM. */
KM_API km_status km_curve_fit_points(km_curve *out, const double *pts, size_t n,
                                     bool closed, double tol, km_error *err);

/* Rigid motion x' = R x + (tx, ty) of the control points, R the rotation
 * by `rot` radians about the origin (exact for NURBS: rational curves are
 * affinely invariant); closed flag kept, out owned by the caller. Returns
 * KM_OK, KM_EINVAL (c not a curve), KM_ENONFINITE (rot, tx or ty),
 * KM_ERANGE (a moved point beyond KM_MAX_COORDINATE; field
 * KM_FIELD_CONTROL_POINTS, err->index names it), KM_ENOMEM. */
KM_API km_status km_curve_transform(km_curve *out, const km_curve *c,
                                    double rot, double tx, double ty,
                                    km_error *err);

/* Number of proper self-crossings of c: points where two different
 * parameters meet within tol (absolute, at least 1e-13 of the control
 * polygon's extent; tol <= 0 or NaN means 1e-9 of it) and the branches
 * cross transversally. The seam of a closed curve, the shared ends of
 * adjacent pieces, the ends of an open curve and tangential touches are
 * not crossings; overlapping (collinear or coincident) stretches are not
 * counted. The work is bounded: a curve folded almost onto itself over a
 * long stretch gets the crossings found within that bound, a lower bound
 * of the true count. Returns the count, 0 for a curve that is one point,
 * or -1 when c is not a curve (NULL, empty) or memory runs out. Allocates
 * only scratch. */
KM_API long km_curve_self_intersections(const km_curve *c, double tol);

/* km_curve_self_intersections that ends early when stop (km/stop.h; NULL:
 * never) asks it to. *count (out) receives the count on KM_OK only.
 * Returns KM_OK, KM_ECANCELLED, KM_EINVAL (c not a curve), KM_ENOMEM.
 * It takes no km_error: nothing but memory can fail and no field is at
 * fault. */
KM_API km_status km_curve_self_intersections_until(const km_curve *c,
                                                   double tol,
                                                   const km_stop *stop,
                                                   long *count);

#endif
