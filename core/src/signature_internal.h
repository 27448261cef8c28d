/* signature_internal.h - computing signatures and curves from them, with a caller's
 * poll (signature_walk.c, reconstruct.c); internal.
 */
#ifndef KM_SIGNATURE_INTERNAL_H
#define KM_SIGNATURE_INTERNAL_H

#include <stddef.h>

#include "km/curve.h"
#include "km/status.h"
#include "pp_internal.h"
#include "stop_internal.h"

/* km_signature_compute_until, with rel_tol times the curve's length as the
 * tolerance where tol is not positive (the public default is 1e-5). */
struct km_signature;
km_status km__signature_compute(const km_curve *c, double tol, double rel_tol,
                                km__poll *poll, struct km_signature *out,
                                km_error *err);

/* km_reconstruct_until with the caller's poll (NULL: never stops). With
 * points_only not NULL nothing is built: *points_only receives the number
 * of control points the curve would have (out, error_bound unused). */
km_status km__reconstruct(const struct km_signature *sig, int degree,
                          double tol, size_t max_points, km__poll *poll,
                          km_curve *out, double *error_bound,
                          size_t *points_only, km_error *err);

/* theta(s) of a signature as pieces (breaks at kappa's breaks and at the
 * corners; corner turns folded into the pieces' start values) beside the
 * matching kappa pieces. */
struct km_signature;
km_status km__build_theta(const struct km_signature *sig, km_pp *kappa,
                          km_pp *theta);
/* Integral of (cos theta, sin theta) over [u0,u1] of a theta piece (degree
 * d Bernstein coefficients tc, piece length h); kbound bounds |kappa| there
 * and sets the chunking (theta moves <= 0.5 rad per 16-point rule). */
void km__integrate_exp(const double *tc, int d, double h, double u0, double u1,
                       double kbound, double out[2]);
/* Bounds bnd[j] >= |kappa^(j)| (j < nd, derivatives in arc length) over
 * [u0, u1] of a kappa piece (degree dk Bernstein coefficients kc, piece
 * length h), from the Bernstein coefficients of the restricted piece. */
void km__kappa_bounds(const double *kc, int dk, double h, double u0, double u1,
                      int nd, double *bnd);
/* Sup over the jump position c and s in [0, 1] of |q - Hq| for the cubic
 * Hermite interpolant H of q = (s - c)_+^2 / 2 and (s - c)_+^3 / 6, rounded
 * up (0.016151 and 1/192 measured on a fine grid): a cubic Hermite piece of
 * length h across jumps J2, J3 of C'', C''' adds KM__HERMITE_JUMP2 h^2 |J2|
 * + KM__HERMITE_JUMP3 h^3 |J3| to its error. */
#define KM__HERMITE_JUMP2 0.0165
#define KM__HERMITE_JUMP3 0.0053

#endif
