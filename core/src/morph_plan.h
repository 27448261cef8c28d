/* morph_plan.h - curvature frames planned once per morph (morph_plan.c):
 * the output pieces and quadrature nodes of every frame of a turning-blend
 * morph without matches, so that a frame costs one pass of sin/cos per
 * closure step. Internal to the core. */
#ifndef KM_MORPH_PLAN_H
#define KM_MORPH_PLAN_H

#include <stdbool.h>
#include <stddef.h>

#include "internal.h"
#include "km/curve.h"
#include "km/status.h"

/* Uniform intervals of the lsq closure's basis over the whole curve: its
 * interior cubic B-splines (KM__CLOSURE_INTERVALS - 3 of them) vanish with
 * two derivatives at the seam. */
#define KM__CLOSURE_INTERVALS 16

typedef struct km__frame_plan km__frame_plan;

/* Plans frames between two inputs given as theta pieces in their own arc
 * length (km__build_theta), with lengths and start angles. Every frame
 * built from the plan is within tol of the exact frame (tol: the frame
 * tolerance; a half goes to the Hermite pieces, a tenth to the quadrature
 * and a tenth to merging the inputs' pieces). More than max_pieces pieces
 * a frame (0: no bound but memory) fails with KM_ELIMIT, early: the
 * uniform splits are refused past twice that before their bounds are
 * taken. Stops (KM_ECANCELLED) when poll says so (NULL: never). */
km_status km__frame_plan_build(km__frame_plan **out, const km_pp theta[2], const double length[2],
                               const double angle[2], bool closed, double tol,
                               size_t max_pieces, km__poll *poll,
                               km_error *err);
void km__frame_plan_free(km__frame_plan *p);
size_t km__frame_plan_pieces(const km__frame_plan *p);
size_t km__frame_plan_nodes(const km__frame_plan *p);
/* Control points of every frame km__frame_plan_curve builds. */
size_t km__frame_plan_points(const km__frame_plan *p);
/* The pieces' ends in normalised arc length r (pieces + 1 of them). */
const double *km__frame_plan_breaks(const km__frame_plan *p);
/* Whether the lsq closure of this morph's frames goes by their corners
 * (decided once per morph, see morph_plan.c). */
bool km__frame_plan_by_corners(const km__frame_plan *p);

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

/* The frame at t as a cubic B-spline in its arc length, starting at the
 * origin with tangent angle theta0. close_lsq: closes a closed pair by the
 * lsq correction of theta. The result is marked closed (end snapped to start) when
 * its gap is within the tolerance. ends (optional, 2 (pieces + 1) values)
 * receives the pieces' end points. Stops (KM_ECANCELLED) when poll says so
 * (NULL: never). */
km_status km__frame_plan_curve(const km__frame_plan *p, double t,
                               double theta0, bool close_lsq, km_curve *out,
                               double *ends, km__poll *poll, km_error *err);

/* Closure by the corners: a frame whose integral of e^(i theta) splits at
 * its nc interior corners (turns tau) into stretch integrals S (2 (nc + 1)
 * values, complex, in order) closes when the corners turn by delta more:
 * G = sum_m e^(i (delta_1 + ... + delta_m)) S_m = 0 with sum delta = 0 (the
 * tangent stays closed). delta is the least such change in sum
 * delta_k^2 / |tau_k| (corners change in proportion to their turn), by
 * Gauss-Newton. Smooth stretches keep their curvature exactly. Returns
 * false (delta unusable) with fewer than three corners, without
 * convergence, or when a corner would change by more than half its
 * turn. */
bool km__close_by_corners(const double *S, const double *tau, size_t nc,
                          double *delta);

#endif
