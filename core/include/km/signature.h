/* signature.h - curvature signatures (paper section 2.1) of planar curves.
 *
 * A signature is what fixes a planar curve up to nothing: smooth curvature
 * kappa(s) on [0, length], the tangent jumps (corners), and the start point
 * and start angle that pin the rigid motion. theta(s) = angle + integral of
 * kappa + sum of corner turns before s.
 *
 * Ownership: a km_signature owns its kappa and its corners array.
 * km_signature_init() makes an empty one, km_signature_free() accepts NULL
 * and empty ones; out-parameters are written only on success. Signatures
 * are not changed after construction, so any number of threads may read
 * one at once. The conventions of km/kmorph.h hold.
 */
#ifndef KM_SIGNATURE_H
#define KM_SIGNATURE_H

#include "km/export.h"

#include <stdbool.h>
#include <stddef.h>

#include "km/curve.h"
#include "km/fn.h"
#include "km/stop.h"

typedef struct km_corner {
  double s;    /* arc length of the corner, in [0, length] */
  double turn; /* tangent turn there, radians, in (-pi, pi) */
} km_corner;

typedef struct km_signature {
  double length;
  double start[2];
  double angle; /* tangent angle at s = 0 */
  km_fn kappa;  /* smooth curvature on [0, length] */
  size_t ncorners;
  km_corner *corners; /* sorted by s; owned */
  double turning;     /* integral of kappa + sum of turns */
  bool closed;
} km_signature;

/* Make *sig empty (all zero, kappa empty); sig may be NULL. Allocates
 * nothing. */
KM_API void km_signature_init(km_signature *sig);

/* Free what *sig owns and leave it empty; sig may be NULL or empty. */
KM_API void km_signature_free(km_signature *sig);

/* Deep copy of sig into out (owned by the caller), validated again as
 * km_signature_create, whose statuses it returns (an empty sig gives
 * KM_ERANGE on its length). */
KM_API km_status km_signature_copy(km_signature *out, const km_signature *sig,
                                   km_error *err);

/* Validating constructor: kappa (a valid km_fn) and the ncorners corners
 * are borrowed and copied into out (owned by the caller); turning is
 * computed. kappa's domain must be [0, length] to 1e-9 relative and is
 * snapped onto it; corners beyond length by up to 1e-12 relative are
 * snapped to length. A closed signature gives its seam turn as a corner
 * at s = length (not checked). Returns KM_OK, or for the first fault found
 * (err->index the element, -1 if none):
 *   KM_ENONFINITE  length (KM_FIELD_LENGTH), start (KM_FIELD_START, index
 *                  0 for x, 1 for y) or a corner (KM_FIELD_CORNERS) not
 *                  finite;
 *   KM_ERANGE      length not in (0, KM_MAX_COORDINATE]; |start| above
 *                  KM_MAX_COORDINATE; angle not finite or |angle| > 1e6
 *                  (KM_FIELD_ANGLE); a corner outside [0, length] or with
 *                  |turn| >= pi (KM_FIELD_CORNERS);
 *   KM_EKNOTS      kappa's domain is not [0, length]
 *                  (KM_FIELD_KAPPA_KNOTS);
 *   KM_EINVAL      corners not sorted by s (KM_FIELD_CORNERS);
 *   KM_ELIMIT      the curve could turn more than KM_MAX_SIGNATURE_TURNS
 *                  times plus one per four coefficients of kappa (see
 *                  km/limits.h; KM_FIELD_KAPPA_COEFFICIENTS);
 *   km_fn_copy's statuses for kappa; KM_ENOMEM. */
KM_API km_status km_signature_create(km_signature *out, double length,
                                     const double start[2], double angle,
                                     const km_fn *kappa,
                                     const km_corner *corners, size_t ncorners,
                                     bool closed, km_error *err);

/* Signature of the curve c into out (owned by the caller). tol is the
 * largest allowed distance between the curve the signature describes and
 * c (tol <= 0 or NaN: 1e-5 * length); it is raised to at least
 * KM_MIN_RELATIVE_TOLERANCE * length and to the curve's own rounding
 * (KM_MIN_TOLERANCE_ULPS in km/limits.h).
 *   - kappa's breakpoints include the arc-length images of c's knots;
 *   - tangent jumps (at knots, or where a degenerate leg hides one) become
 *     corners; a closed curve's seam angle becomes a corner at s = length;
 *   - degenerate legs (C' = 0 at a span end, tangent still defined) are
 *     handled by one-sided tangent limits and refinement toward the point.
 * The work is bounded (KM_SIGNATURE_WORK_* in km/limits.h). Returns KM_OK,
 * or (err->param the curve parameter t of the fault, NAN if none):
 *   KM_EINVAL       c is not a curve (NULL, empty, degree or count out of
 *                   range);
 *   KM_ECUSP        a genuine cusp: the tangent reverses (KM_FIELD_KNOTS
 *                   when found between two spans, else
 *                   KM_FIELD_CONTROL_POINTS);
 *   KM_EDEGENERATE  zero length, or no tangent direction near t
 *                   (KM_FIELD_CONTROL_POINTS);
 *   KM_ERANGE       the curve is too small for its distance from the
 *                   origin: its shape is rounding noise at the default
 *                   tolerance, or spans are no longer than the rounding
 *                   of their coordinates (KM_FIELD_CONTROL_POINTS);
 *   KM_ENOCONVERGE  an arc length cannot be computed to full precision
 *                   (the speed nearly vanishes inside a span;
 *                   KM_FIELD_CONTROL_POINTS);
 *   KM_ELIMIT       the work budget spent (KM_FIELD_TOLERANCE: a looser
 *                   tolerance helps), or more than KM_MAX_PIECES pieces;
 *   KM_ENOMEM. */
KM_API km_status km_signature_compute(const km_curve *c, double tol,
                                      km_signature *out, km_error *err);

/* km_signature_compute that ends early when stop (km/stop.h; NULL: never)
 * asks it to: then KM_ECANCELLED, *out untouched, nothing leaked. It is
 * polled once every KM_STOP_POLL_UNITS curve evaluations. Other statuses
 * and the order as km_signature_compute. */
KM_API km_status km_signature_compute_until(const km_curve *c, double tol,
                                            const km_stop *stop,
                                            km_signature *out, km_error *err);

/* Tangent angle theta(s) in radians, unwrapped (it accumulates the
 * turning, not reduced to (-pi, pi]), corner turns at s included (the
 * right-hand limit). Builds kappa's antiderivative on each call: O(number
 * of coefficients). Should that allocation fail, the integral of kappa is
 * left out of the answer. */
KM_API double km_signature_theta(const km_signature *sig, double s);

/* Point of the exact curve at arc length s (clamped to [0, length]) into
 * pos (out), and its tangent angle into *theta (out; may be NULL):
 * start + integral of (cos theta, sin theta), by quadrature to about
 * 1e-15 of the length. At an interior corner *theta is the angle arriving
 * there (the left-hand limit, unlike km_signature_theta); corners at s = 0
 * are included. Used by tests, metrics and closure. Returns KM_OK or
 * KM_ENOMEM (nothing written).
 * It takes no km_error: only memory can fail. */
KM_API km_status km_signature_point(const km_signature *sig, double s,
                                    double pos[2], double *theta);

/* Largest |kappa| over [0, length] (km_fn_max_abs: to 1e-13 relative). */
KM_API double km_signature_max_abs_kappa(const km_signature *sig);

/* Bending energy: the integral of kappa^2 ds over [0, length]
 * (km_fn_integral_sq; NaN when memory runs out). Corners add nothing. */
KM_API double km_signature_bending_energy(const km_signature *sig);

#endif
