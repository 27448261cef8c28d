/* shape_internal.h - the polyline kernels shared by the shape value, the
 * pairing and the compound morph (shape.c); internal.
 */
#ifndef KM_SHAPE_INTERNAL_H
#define KM_SHAPE_INTERNAL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

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

/* What the edge a -> b adds to the winding number of p: Sunday's
 * crossing-number form, half-open in y so a vertex is counted once. */
static inline int km__edge_winding(const double *a, const double *b,
                                   const double p[2]) {
  double cross = (b[0] - a[0]) * (p[1] - a[1]) - (p[0] - a[0]) * (b[1] - a[1]);
  if (a[1] <= p[1]) return b[1] > p[1] && cross > 0 ? 1 : 0;
  return b[1] <= p[1] && cross < 0 ? -1 : 0;
}

static inline double km__orient2(const double *a, const double *b,
                                 const double *c) {
  return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

/* Segments a b and c d cross properly: strictly opposite signs on both
 * sides (touching or collinear segments do not). */
static inline bool km__edge_crosses(const double *a, const double *b,
                                    const double *c, const double *d) {
  double o1 = km__orient2(a, b, c), o2 = km__orient2(a, b, d);
  double o3 = km__orient2(c, d, a), o4 = km__orient2(c, d, b);
  return ((o1 > 0 && o2 < 0) || (o1 < 0 && o2 > 0)) &&
         ((o3 > 0 && o4 < 0) || (o3 < 0 && o4 > 0));
}

/* Horizontal bands over the edges of a closed polyline (poly_index.c):
 * the winding number of a point and the crossings with another polyline,
 * identical to km__poly_winding and km__poly_crossings, visiting only
 * the edges near the height asked about. P is borrowed: it must not move
 * while the index is used. */
typedef struct km__poly_index {
  const double *P;
  size_t np;
  double y0, y1, inv_h; /* P's height range; bands per unit of height */
  size_t nbands;
  double nbands_f; /* nbands as a double: band_of compares with it */
  size_t *start;   /* nbands + 1: band k lists edge[start[k] .. start[k+1]) */
  uint32_t *edge;  /* edge i joins point i to point i + 1 (mod np) */
  size_t *seen, stamp; /* crossings: an edge once for each edge of the other */
} km__poly_index;

void km__poly_index_init(km__poly_index *ix);
void km__poly_index_free(km__poly_index *ix);
/* KM_OK or KM_ENOMEM (ix then empty). Rebuilding frees what ix held. */
km_status km__poly_index_build(km__poly_index *ix, const double *P, size_t np);
int km__poly_index_winding(const km__poly_index *ix, const double p[2]);
/* As km__poly_crossings(P, np, Q->P, Q->np, poll). */
long km__poly_index_crossings(const double *P, size_t np, km__poly_index *Q,
                              km__poll *poll);

/* A point inside the closed polyline an index was built over, near x
 * (shape.c); x itself when no edge offset lands inside. x and out must
 * not overlap. */
void km__poly_interior_point(const km__poly_index *ix, const double x[2],
                             double out[2]);

/* Signed area (counter-clockwise positive) and area centroid of a closed
 * curve by Gauss-Legendre quadrature of Green's formulas: for a polynomial
 * curve ceil(3p / 2) points a span in its Bezier form, exact up to
 * rounding at any degree; for a rational one 8 points on each quarter of
 * a span (not exact: the integrands are rational). */
void km__curve_area(const km_curve *c, double *area, double centroid[2]);

/* Number of proper crossings between polylines P (np points) and Q (nq
 * points), both closed; polls p (may be NULL) once a segment of P. -1
 * when stopped. */
long km__poly_crossings(const double *P, size_t np, const double *Q, size_t nq,
                        km__poll *poll);

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
  /* intersections AVOID (shape_avoid.c): children placed by the parent's
   * points near them, and per-slot corrections (translation dx, dy and
   * ln of a scale) at t = j / KM__FIX, j = 0..KM__FIX, zero at both ends,
   * applied where fixed[k] through a monotone cubic in t */
  bool local_follow;
  double *fix;          /* 3 (KM__FIX + 1) per pair */
  bool *fixed;          /* npairs, NULL when no slot is corrected */
  bool no_adjust;       /* while corrections are measured: no per-frame move */
  bool free_top_points; /* a top-level unpaired contour's point is where
                           its host maps it, not pulled into the host */
  long preview_fails;   /* mutual crossings and nesting failures of the
                           kept choice's previews (-1: not previewed) */
};

/* Interior frames previewed under AVOID, t = j / (KM__PREVIEWS + 1). */
#define KM__PREVIEWS 7
/* Mutual crossings and nesting failures of m's frames at t = j / (n + 1),
 * j = 1..n, or with between at the n + 1 times halfway between those and
 * the ends (shape_avoid.c). KM_OK or a frame's status. */
km_status km__shape_preview(const km_shape_morph *m, int n, bool between,
                            const km_stop *stop, long *fails, km_error *err);

/* Intervals of the correction grid (shape_avoid.c). */
#define KM__FIX 16

/* Choose placement and corrections of m's frames so that contours do not
 * cross and children stay in their parents (shape_avoid.c); m is still
 * being built. KM_OK, KM_ECANCELLED, KM_ENOMEM, or a frame's status. */
km_status km__shape_avoid(km_shape_morph *m, const km_shape *a,
                          const km_shape *b, const km_stop *stop,
                          km_error *err);

/* Place the unpaired contours' points again (after free_top_points
 * changed), and the anchors and the schedule that follow from them
 * (shape_morph.c). km_shape_morph_create's statuses. */
km_status km__shape_replan(km_shape_morph *m, const km_shape *a,
                           const km_shape *b, const km_stop *stop,
                           km_error *err);

/* Make slot k's schedule fall toward its missing side (shape_morph.c). */
void km__shape_sched_monotone(km_shape_morph *m, size_t k);

/* Slot k's correction at t into d[2] (translation) and *r (scale about
 * its centroid); false when it has none (shape_avoid.c). */
bool km__shape_fix_at(const km_shape_morph *m, size_t k, double t, double d[2],
                      double *r);

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
