/* shape_internal.h - the polyline kernels shared by the shape value, the
 * pairing and the compound morph (shape.c); internal.
 */
#ifndef KM_SHAPE_INTERNAL_H
#define KM_SHAPE_INTERNAL_H

#include <stddef.h>

#include "km/curve.h"
#include "km/shape.h"
#include "stop_internal.h"

/* Flattening of c: KM_SHAPE_FLAT points a non-empty knot span, uniform in
 * the parameter, then the end point; *pts (km__malloc'd, the caller
 * frees) gets 2 doubles a point, *np the count. KM_OK or KM_ENOMEM. */
km_status km__shape_flatten(const km_curve *c, double **pts, size_t *np);

/* Winding number of p about the closed polyline P of np points (the last
 * joined to the first). */
int km__poly_winding(const double *P, size_t np, const double p[2]);

/* Signed area (counter-clockwise positive) and area centroid of a closed
 * curve by Gauss-Legendre quadrature of Green's formulas, exact up to
 * rounding for polynomial curves of degree <= 4 (8 points on 4 panels a
 * span). */
void km__curve_area(const km_curve *c, double *area, double centroid[2]);

/* Number of proper crossings between polylines P (np points) and Q (nq
 * points), both closed; polls p (may be NULL) once a segment of P. -1
 * when stopped. */
long km__poly_crossings(const double *P, size_t np, const double *Q, size_t nq,
                        km__poll *poll);

/* A point inside the closed polyline P (np points) near x (shape.c); x
 * itself when no edge offset lands inside. */
void km__poly_interior_point(const double *P, size_t np, const double x[2],
                             double out[2]);

/* The compound morph (shape_morph.c), read by its frames (shape_frame.c). */
typedef enum km__pair_kind { KM__PAIRED, KM__VANISH, KM__APPEAR } km__pair_kind;

/* Points a parent's frames are sampled at, equal steps of the parameter
 * (the arc length of a curvature frame), to follow the parent's motion. */
#define KM__REF_POINTS 64

/* Times an unpaired contour's size is measured at to keep its shrinking
 * monotone (shape_morph.c): t = j / KM__SCHED. */
#define KM__SCHED 32

struct km_shape_morph {
  size_t npairs;
  km_shape_pair *pairs;
  km_morph **morphs;
  km__pair_kind *kind;
  double *centre; /* 2 per pair: the unpaired contour's centroid */
  double *point;  /* 2 per pair: where it vanishes or appears */
  long *parent_from, *parent_to; /* parent slots on each side, -1 none */
  double *anchor; /* 4 per pair: where its centroid is at t = 0 and t = 1
                     (an unpaired contour's point on its missing side) */
  double *ref;    /* 4 KM__REF_POINTS per pair: a paired parent's frames
                     at t = 0 and t = 1 sampled (has_ref), else unset */
  bool *has_ref;
  double *sched; /* KM__SCHED + 1 per pair: the largest scale (of its full
                     size) an unpaired contour has at t = j / KM__SCHED,
                     falling toward its missing side; used when scheduled */
  bool scheduled;
};

/* The scale each unpaired slot of the frame at t takes to fit in its
 * parent, as a fraction of its nominal (1 - t or t), into ratio[npairs]
 * (1 for the others), without the schedule (shape_frame.c). KM_OK or the
 * statuses of km_shape_morph_frame_until. */
km_status km__shape_frame_ratios(const km_shape_morph *m, double t,
                                 const km_stop *stop, double *ratio,
                                 km_error *err);

/* Where slot k's centroid goes in frame f at t: the anchors at t = 0
 * and t = 1 carried by the similarities that best map its parent's
 * frames at t = 0 and t = 1 onto the parent's frame at t, blended
 * (1 - t, t). false (out unset) when slot k has no such parent: none, or
 * different ones at the two ends, or one not paired (shape_frame.c). */
bool km__follow_parent(const km_shape_morph *m, size_t k, long parent,
                       const km_curve *parent_now, double t, double out[2]);

/* P sampled at KM__REF_POINTS equal parameter steps into out (2 doubles
 * a point). */
void km__ref_sample(const km_curve *c, double *out);

#endif
