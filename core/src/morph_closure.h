/* morph_closure.h - closing the frames of closed morphs (morph_closure.c):
 * the lsq closure (least change of curvature, by the corners or by cubic
 * B-splines added to theta) and the paper's control-polygon corrections;
 * internal to the core. The planned frames (morph_plan.c) close with the
 * same basis and metric. */
#ifndef KM_MORPH_CLOSURE_H
#define KM_MORPH_CLOSURE_H

#include <stdbool.h>
#include <stddef.h>

#include "internal.h"
#include "km/curve.h"
#include "km/morph.h"
#include "km/signature.h"
#include "km/status.h"

/* Uniform intervals of the lsq closure's basis over the whole curve: its
 * interior cubic B-splines (KM__CLOSURE_INTERVALS - 3 of them) vanish with
 * two derivatives at the seam. */
#define KM__CLOSURE_INTERVALS 16

/* The uniform cubic B-spline on [0, 4] (the closure's basis function) and
 * its derivative. */
double km__bspline3(double u);
double km__bspline3_d(double u);

/* The lsq closure's metric: Gram matrix of the derivatives of its basis
 * functions in the variable of unit knot spacing ((KM__CLOSURE_INTERVALS -
 * 3)^2 values, exact). */
void km__closure_metric(double *M);
/* The same Gram matrix with the weight w[iv] on basis interval iv
 * (KM__CLOSURE_INTERVALS of them): integral of w psi_i' psi_j'. */
void km__closure_metric_weighted(const double *w, double *M);
/* Cholesky factor Lc (lower, row-major, the same size) of
 * km__closure_metric; false if it is not positive definite. */
bool km__closure_metric_factor(double *Lc);
/* y = M^-1 y for the metric factored by km__closure_metric_factor. */
void km__closure_metric_solve(const double *Lc, double *y);

/* Closure by the corners: a frame whose integral of e^(i theta) splits at
 * its nc interior corners (turns tau) into stretch integrals S (2 (nc + 1)
 * values, complex, in order) closes when the corners turn by delta more:
 * G = sum_m e^(i (delta_1 + ... + delta_m)) S_m = 0 with sum delta = 0 (the
 * tangent stays closed). delta is the least such change in sum
 * delta_k^2 / |tau_k| (corners change in proportion to their turn), by
 * Gauss-Newton. Smooth stretches keep their curvature exactly. *closes
 * receives false (delta unusable) with fewer than three corners, without
 * convergence, or when a corner would change by more than half its turn.
 * KM_ENOMEM (*closes false) without memory for the iteration: not a
 * "cannot close", which would silently take the smooth closure. */
km_status km__close_by_corners(const double *S, const double *tau, size_t nc,
                               double *delta, bool *closes);

/* Closed curve nearest in curvature (L2, weighted by weights[iv] on the
 * basis interval iv when weights is not NULL) to the closed signature sig,
 * into *out (the caller frees it); *gap0 receives the gap before. With
 * by_corners, the interior corners take the whole correction when they
 * can (km__close_by_corners: the smooth curvature keeps its bound,
 * straight edges stay straight; *used_corners, if not NULL, then true),
 * else the smooth curvature does. KM_ECANCELLED (err, via km__stopped)
 * when poll says stop; KM_ENOMEM, KM_ELIMIT (too many quadrature nodes)
 * and KM_ENOCONVERGE (err); the statuses of km_signature_create. */
km_status km__close_lsq(const km_signature *sig, bool by_corners,
                        const double *weights, km_signature *out, double *gap0,
                        bool *used_corners, km__poll *poll, km_error *err);
/* sig with its curvature changed by the closure correction psi' of
 * coefficients c (KM__CLOSURE_INTERVALS - 3 of them, in radians of
 * tangent angle) into *out, as km__close_lsq closes it. KM_ENOMEM. */
km_status km__closure_add(const km_signature *sig, const double *c,
                          km_signature *out, km_error *err);
/* sig with its smooth curvature replaced by kt (over [0, sig's length])
 * into *out: the same length, start, angle and corners. KM_ENOMEM (err)
 * and the statuses of km_signature_create. */
km_status km__signature_with_kappa(const km_signature *sig, const km_pp *kt,
                                   km_signature *out, km_error *err);
/* Curvature kappa (over [0, L] in arc length) changed by the closure
 * correction psi' of coefficients c into *out (the caller frees it), as
 * km__closure_add changes a signature's. KM_ENOMEM. */
km_status km__closure_kappa(const km_pp *kappa, double L, const double *c,
                            km_pp *out);
/* km__close_lsq of a blended frame of m (with m's closure by corners),
 * kept within the inputs' largest |kappa| where the least change would
 * cross it; statuses as km__close_lsq. */
km_status km__close_within_bound(const km_morph *m, const km_signature *blended,
                                 km_signature *out, double *gap, km__poll *poll,
                                 km_error *err);
/* The paper's corrections of the control polygon (section 3.2) of a
 * curve whose ends miss each other: c0 spreads the gap over the points,
 * c1 also matches the end tangents, g2 also the end curvatures. c is
 * marked closed. */
void km__close_polygon(km_curve *c, km_closure how);

#endif
