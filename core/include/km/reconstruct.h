/* reconstruct.h - curves from curvature signatures (paper sections 2.2-2.5).
 *
 * C(s) = start + integral of (cos theta, sin theta). theta is exact (the
 * antiderivative of a spline); positions are integrated by adaptive
 * Gauss-Legendre to near machine precision; the result is a piecewise
 * Hermite B-spline in the arc-length parameter (degree 3: C1, degree 5: C2)
 * whose pieces are chosen so a rigorous a-priori bound on the distance to
 * the exact curve stays within the tolerance.
 */
#ifndef KM_RECONSTRUCT_H
#define KM_RECONSTRUCT_H

#include "km/curve.h"
#include "km/signature.h"
#include "km/stop.h"

/* Reconstruct sig as a B-spline of degree 3 or 5 (else KM_EDEGREE) within
 * tol (tol <= 0: 1e-5 * length). Corners become knots of multiplicity
 * `degree`. The curve's parameter is arc length of the exact curve at its
 * knots. *error_bound (may be NULL) receives an upper bound on the
 * distance between the result and the exact curve at equal s; it is never
 * smaller than the true error. out->closed is set when sig->closed and the
 * exact curve closes to within tol (then the last point is made equal to
 * the first). */
km_status km_reconstruct(const km_signature *sig, int degree, double tol,
                         km_curve *out, double *error_bound, km_error *err);

/* km_reconstruct with at most max_points control points in the result
 * (0: the core's own bound, KM_MAX_OUTPUT_PIECES beyond two pieces per
 * piece of sig): more fails with KM_ELIMIT on the tolerance before the
 * curve is built. The service holds answers to its limit on curves. */
km_status km_reconstruct_within(const km_signature *sig, int degree, double tol,
                                size_t max_points, km_curve *out,
                                double *error_bound, km_error *err);

/* km_reconstruct_within that ends early when stop (km/stop.h; NULL:
 * never) asks it to: then KM_ECANCELLED, *out and *error_bound untouched,
 * nothing leaked. Polled every KM_STOP_POLL_UNITS units of work (an output
 * piece planned, a quadrature node). */
km_status km_reconstruct_until(const km_signature *sig, int degree, double tol,
                               size_t max_points, const km_stop *stop,
                               km_curve *out, double *error_bound,
                               km_error *err);

/* Exact curve point at arc length s (numerical quadrature to ~1e-15 L):
 * used by tests and metrics. pos and tangent angle. */
km_status km_signature_point(const km_signature *sig, double s,
                             double pos[2], double *theta);

#endif
