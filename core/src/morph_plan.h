/* morph_plan.h - curvature frames planned once per morph (morph_plan.c):
 * the output pieces and quadrature nodes of every frame of a turning-blend
 * morph without matches, so that a frame costs one pass of sin/cos per
 * closure step (morph_plan.c plans, morph_plan_frame.c builds frames).
 * Internal to the core. */
#ifndef KM_MORPH_PLAN_H
#define KM_MORPH_PLAN_H

#include <stdbool.h>
#include <stddef.h>

#include "internal.h"
#include "km/curve.h"
#include "km/status.h"
#include "morph_closure.h"

typedef struct km__frame_plan km__frame_plan;

/* Shares of the tolerance: the planned Hermite pieces (a bound for every
 * t), and the merging of runs of them into single cubics in each frame (a
 * bound per frame, against the pieces). With the quadrature's tenth and
 * the merged input pieces' tenth a frame is within 0.9 of it of the exact
 * frame (the general path's reconstruction takes 0.9 too), and frames 0
 * and 1 within the tolerance of the inputs with their signatures' tenth. */
#define KM__PLAN_PIECE_SHARE 0.2
#define KM__PLAN_MERGE_SHARE (0.7 - KM__PLAN_PIECE_SHARE)
/* Share of the pieces of frames that keep them unmerged (the contours of
 * compound shapes): as before merging existed. */
#define KM__PLAN_KEPT_SHARE 0.5

/* Plans frames between two inputs given as theta pieces in their own arc
 * length (km__build_theta), with lengths and start angles. Every frame
 * built from the plan is within tol of the exact frame (tol: the frame
 * tolerance; piece_share of it goes to the Hermite pieces
 * (KM__PLAN_PIECE_SHARE for frames that merge them, KM__PLAN_KEPT_SHARE
 * for frames that keep them), the rest of 0.7 to merging them, a tenth to the quadrature
 * and a tenth to merging the inputs' pieces). More than max_pieces pieces
 * a frame (0: no bound but memory) fails with KM_ELIMIT, early: the
 * uniform splits are refused past twice that before their bounds are
 * taken. Stops (KM_ECANCELLED) when poll says so (NULL: never). */
km_status km__frame_plan_build(km__frame_plan **out, const km_pp theta[2],
                               const double length[2], const double angle[2],
                               bool closed, double tol, double piece_share,
                               size_t max_pieces, km__poll *poll,
                               km_error *err);
void km__frame_plan_free(km__frame_plan *p);
size_t km__frame_plan_pieces(const km__frame_plan *p);
size_t km__frame_plan_nodes(const km__frame_plan *p);
/* Control points of every frame km__frame_plan_curve builds, at most (it
 * merges runs of the pieces). */
size_t km__frame_plan_points(const km__frame_plan *p);
/* The pieces' ends in normalised arc length r (pieces + 1 of them). */
const double *km__frame_plan_breaks(const km__frame_plan *p);
/* Whether the lsq closure of this morph's frames goes by their corners
 * (decided once per morph, see morph_plan.c). */
bool km__frame_plan_by_corners(const km__frame_plan *p);

/* How a frame built from the plan was closed, for its metrics (which
 * describe the signature the frame is built from): the coefficients c of
 * the lsq closure's basis, the gap of the frame before closing (in
 * length), and whether it closed by turning its corners (its smooth
 * curvature then the blend's, c zero). */
typedef struct km__plan_closure {
  double c[KM__CLOSURE_INTERVALS - 3];
  double gap0;
  bool by_corners;
} km__plan_closure;

/* The frame at t as a cubic B-spline over its arc length (knots near arc
 * length; the parameter leaves it between them: runs of the plan's pieces
 * merged into single cubics), starting at the origin with tangent angle
 * theta0. close_lsq: closes a closed pair by the
 * lsq correction of theta; merge: merges runs of the pieces (else each
 * piece is Hermite in arc length). The result is marked closed (end snapped to start) when
 * its gap is within the tolerance. ends (optional, 2 (pieces + 1) values)
 * receives the pieces' end points; closure (optional) how the frame was
 * closed (gap0 is measured only when it is asked for). Stops
 * (KM_ECANCELLED) when poll says so (NULL: never). */
km_status km__frame_plan_curve(const km__frame_plan *p, double t, double theta0,
                               bool close_lsq, bool merge, km_curve *out,
                               double *ends, km__plan_closure *closure,
                               km__poll *poll, km_error *err);

#endif
