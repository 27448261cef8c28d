/* signature.h - curvature signatures (paper section 2.1) of planar curves.
 *
 * A signature is what fixes a planar curve up to nothing: smooth curvature
 * kappa(s) on [0, length], the tangent jumps (corners), and the start point
 * and start angle that pin the rigid motion. theta(s) = angle + integral of
 * kappa + sum of corner turns before s.
 */
#ifndef KM_SIGNATURE_H
#define KM_SIGNATURE_H

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
  double angle;     /* tangent angle at s = 0 */
  km_fn kappa;      /* smooth curvature on [0, length] */
  size_t ncorners;
  km_corner *corners; /* sorted by s; owned */
  double turning;   /* integral of kappa + sum of turns */
  bool closed;
} km_signature;

void km_signature_init(km_signature *sig);
void km_signature_free(km_signature *sig);
km_status km_signature_copy(km_signature *out, const km_signature *sig,
                            km_error *err);

/* Validating constructor (copies kappa and corners): length > 0 and finite,
 * kappa's domain equal to [0, length] (to 1e-9 relative; it is snapped),
 * corners sorted, in [0, length], |turn| < pi. turning is computed. For a
 * closed signature a seam corner is given at s = length. */
km_status km_signature_create(km_signature *out, double length,
                              const double start[2], double angle,
                              const km_fn *kappa, const km_corner *corners,
                              size_t ncorners, bool closed, km_error *err);

/* Signature of a curve. tol is the largest allowed distance between the
 * curve the signature describes and c (tol <= 0: 1e-5 * length; clamped
 * below at KM_MIN_RELATIVE_TOLERANCE * length).
 *   - kappa's breakpoints include the arc-length images of c's knots;
 *   - tangent jumps (at knots, or where a degenerate leg hides one) become
 *     corners; a closed curve's seam angle becomes a corner at s = length;
 *   - degenerate legs (C' = 0 at a span end, tangent still defined) are
 *     handled by one-sided tangent limits and refinement toward the point;
 *   - a genuine cusp (tangent reverses) fails with KM_ECUSP, err->param =
 *     the curve parameter;
 *   - zero length fails with KM_EDEGENERATE.
 * Thread-safe; out owned by the caller. */
km_status km_signature_compute(const km_curve *c, double tol,
                               km_signature *out, km_error *err);

/* km_signature_compute that ends early when stop (km/stop.h; NULL: never)
 * asks it to: then KM_ECANCELLED, *out untouched, nothing leaked. It is
 * polled once every KM_STOP_POLL_UNITS curve evaluations. */
km_status km_signature_compute_until(const km_curve *c, double tol,
                                     const km_stop *stop, km_signature *out,
                                     km_error *err);

/* Tangent angle theta(s) (corner turns at s included from the right). */
double km_signature_theta(const km_signature *sig, double s);

/* Curvature extremes and bending energy of the smooth part. */
double km_signature_max_abs_kappa(const km_signature *sig);
double km_signature_bending_energy(const km_signature *sig);

#endif
