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

struct km_shape_morph {
  size_t npairs;
  km_shape_pair *pairs;
  km_morph **morphs;
  km__pair_kind *kind;
  double *centre; /* 2 per pair: the unpaired contour's centroid */
  double *point;  /* 2 per pair: where it vanishes or appears */
  long *parent_from, *parent_to; /* parent slots on each side, -1 none */
};

#endif
