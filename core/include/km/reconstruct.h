/* reconstruct.h - curves from curvature signatures (paper sections 2.2-2.5).
 *
 * C(s) = start + integral of (cos theta, sin theta). theta is exact (the
 * antiderivative of a spline); positions are integrated by adaptive
 * Gauss-Legendre to near machine precision; the result is a piecewise
 * Hermite B-spline (degree 3: C1, degree 5: C2) whose knots are the arc
 * lengths of its joins on the exact curve, and whose pieces are chosen so
 * a rigorous a-priori bound on the distance to the exact curve stays
 * within the tolerance.
 *
 * The signature given must be a valid one (made by km_signature_create or
 * km_signature_compute; it is not checked again). The point of the exact
 * curve at one arc length is km_signature_point (km/signature.h). The
 * conventions of km/kmorph.h hold; the curve made follows the inputs, as
 * it is not of the signature's type.
 */
#ifndef KM_RECONSTRUCT_H
#define KM_RECONSTRUCT_H

#include "km/export.h"

#include "km/curve.h"
#include "km/signature.h"
#include "km/stop.h"

/* Reconstruct sig as a B-spline of degree 3 or 5 within tol, a distance
 * (tol <= 0 or NaN: 1e-5 * length; raised to at least
 * KM_MIN_RELATIVE_TOLERANCE * length). Corners become knots of
 * multiplicity `degree`. The curve's parameter is arc length of the exact
 * curve at its knots (there the two meet); between knots a cubic piece
 * may follow the shape rather than the arc length (the end speeds of a
 * circular arc), which takes far fewer pieces.
 *   out          (out) the curve, owned by the caller (km_curve_free).
 *                out->closed is set when sig->closed and the exact curve
 *                closes to within tol (then the last point is made equal
 *                to the first).
 *   error_bound  (out, may be NULL) an upper bound on the distance
 *                between out and the exact curve as point sets: every
 *                point of either is within it of a point of the other,
 *                piece by piece between the knots; never smaller than
 *                the true error. Degree 5 holds it at equal s too.
 * Returns KM_OK, KM_EDEGREE (degree not 3 or 5; KM_FIELD_DEGREE),
 * KM_ELIMIT (more output pieces than KM_MAX_OUTPUT_PIECES beyond two per
 * piece of sig, or than KM_MAX_PIECES; KM_FIELD_TOLERANCE: a looser
 * tolerance helps), KM_EINVAL (an internal inconsistency building the
 * B-spline: a bug, never expected), KM_ENOMEM. */
KM_API km_status km_reconstruct(const km_signature *sig, int degree, double tol,
                                km_curve *out, double *error_bound,
                                km_error *err);

/* km_reconstruct with the result's control points bounded by max_points
 * (0: the core's own bound alone): a curve needing more fails with
 * KM_ELIMIT (KM_FIELD_TOLERANCE) before it is built. The bound is counted
 * as `degree` points per output piece, and the first piece has one more,
 * so a result may have max_points + 1 points. The service holds answers
 * to its limit on curves this way. Statuses as km_reconstruct. */
KM_API km_status km_reconstruct_within(const km_signature *sig, int degree,
                                       double tol, size_t max_points,
                                       km_curve *out, double *error_bound,
                                       km_error *err);

/* km_reconstruct_within that ends early when stop (km/stop.h; NULL:
 * never) asks it to: then KM_ECANCELLED, *out and *error_bound untouched,
 * nothing leaked. Polled every KM_STOP_POLL_UNITS units of work (an output
 * piece planned, a quadrature node). Other statuses as km_reconstruct. */
KM_API km_status km_reconstruct_until(const km_signature *sig, int degree,
                                      double tol, size_t max_points,
                                      const km_stop *stop, km_curve *out,
                                      double *error_bound, km_error *err);

#endif
