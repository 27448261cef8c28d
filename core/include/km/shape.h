/* shape.h - compound shapes: a nesting tree of closed contours, the pairing
 * of two shapes' contours, and the compound morph built on km_morph.
 *
 * A km_shape holds closed contours (deep copies), a fill rule, and the
 * nesting tree found from containment: parent (innermost contour that
 * contains it, -1 for none) and depth (0 at the top) of every contour.
 * Each contour has a role: OUTER (the region just inside it is filled) or
 * HOLE (just inside it is empty). Under KM_FILL_EVENODD the role is the
 * parity of the depth; under KM_FILL_NONZERO it is the winding number,
 * with the input orientations, of a point just inside the contour (0:
 * hole). Orientation is then normalised: OUTER contours counter-clockwise
 * (positive signed area), HOLE contours clockwise; a contour turned round
 * keeps its trace and gets the start point of its reversal.
 *
 * Containment is decided on a flattening of each contour: KM_SHAPE_FLAT
 * points a knot span, uniform in the parameter, which lies within its
 * chord error (about L^2 kappa / (8 KM_SHAPE_FLAT^2) per span of length
 * L) of the curve. Contour j is inside contour i when the majority of
 * KM_SHAPE_VOTES points spread along j have a non-zero winding number
 * about i's flattening; contours are taken not to cross one another
 * (crossing contours get some nesting, not refused).
 *
 * A compound morph pairs the contours level by level of the two trees
 * (top-level with top-level, then the children of each pair of paired
 * contours with each other), morphs each pair with km_morph, and lets an
 * unpaired contour shrink into a point (from side) or grow from one (to
 * side). The conventions of km/kmorph.h hold. Shapes and shape morphs are
 * never changed after construction: any number of threads may read one.
 */
#ifndef KM_SHAPE_H
#define KM_SHAPE_H

#include "km/export.h"

#include <stdbool.h>
#include <stddef.h>

#include "km/curve.h"
#include "km/morph.h"
#include "km/status.h"
#include "km/stop.h"

/* Contours per shape. Default 64; hard bound 4096. Why: pairing costs
 * O(n^2) turning distances and an O(n^3) assignment per level, and a frame
 * counts crossings between every two contours. Where: km_shape_create
 * (KM_ELIMIT, KM_FIELD_NONE, err->index the first contour past it). */
#define KM_SHAPE_DEFAULT_MAX_CONTOURS 64
#define KM_SHAPE_MAX_CONTOURS 4096

/* Control points of all contours together. Default 100,000 (what one curve
 * may have at the service); hard bound 2,000,000 (KM_MAX_PIECES). Where:
 * km_shape_create (KM_ELIMIT, KM_FIELD_CONTROL_POINTS, err->index the
 * contour that goes past it). */
#define KM_SHAPE_DEFAULT_MAX_POINTS 100000
#define KM_SHAPE_MAX_POINTS 2000000

/* Flattening used for containment, areas of crossings and nesting checks:
 * points per knot span, and the points of a contour voting on its
 * containment. */
#define KM_SHAPE_FLAT 48
#define KM_SHAPE_VOTES 9

typedef enum km_fill_rule { KM_FILL_NONZERO, KM_FILL_EVENODD } km_fill_rule;

typedef enum km_contour_role { KM_ROLE_OUTER, KM_ROLE_HOLE } km_contour_role;

typedef struct km_shape {
  size_t ncontours;
  km_curve *contours; /* ncontours closed curves, oriented per role */
  long *parent;       /* innermost containing contour, -1 for none */
  int *depth;         /* 0 for top-level contours */
  km_contour_role *role;
  bool *reversed;   /* the input contour was turned round */
  double *area;     /* |signed area| of each contour */
  double *centroid; /* 2 per contour: the centroid of its area */
  double box[4];    /* xmin, ymin, xmax, ymax of all flattenings */
  double *flat;     /* the flattenings, 2 doubles a point, closed */
  size_t *flat_off; /* ncontours + 1 point offsets into flat */
  km_fill_rule fill;
} km_shape;

/* Bounds of one shape; 0 in a field asks for its default. */
typedef struct km_shape_limits {
  size_t max_contours; /* default KM_SHAPE_DEFAULT_MAX_CONTOURS */
  size_t max_points;   /* default KM_SHAPE_DEFAULT_MAX_POINTS */
} km_shape_limits;

/* Make *s empty; s may be NULL. Allocates nothing. */
KM_API void km_shape_init(km_shape *s);

/* Free what *s owns and leave it empty; s may be NULL or empty. */
KM_API void km_shape_free(km_shape *s);

/* Build a shape from n borrowed contours (deep-copied, reoriented per
 * role) under fill rule `fill`, within *lim (NULL: defaults; fields above
 * the hard bounds are lowered to them). out is owned by the caller
 * (km_shape_free). Returns KM_OK, or for the first fault (err->index the
 * contour at fault, -1 if none):
 *   KM_EINVAL      contours NULL, a contour not a curve (NULL arrays,
 *                  degree or count out of range), fill not a rule;
 *   KM_ECOUNT      n == 0;
 *   KM_ELIMIT      n above max_contours (KM_FIELD_NONE, index the first
 *                  contour past it), or the control points of contours
 *                  0..index above max_points (KM_FIELD_CONTROL_POINTS);
 *   KM_ECLOSED     a contour is open (KM_FIELD_CLOSED);
 *   KM_EDEGENERATE a contour of zero length or zero area
 *                  (KM_FIELD_CONTROL_POINTS);
 *   KM_ENONFINITE  a contour's length or area is not finite;
 *   KM_ENOMEM. */
KM_API km_status km_shape_create(km_shape *out, const km_curve *contours,
                                 size_t n, km_fill_rule fill,
                                 const km_shape_limits *lim, km_error *err);

/* Deep copy of s into out (owned by the caller). KM_OK, KM_EINVAL (s
 * empty), KM_ENOMEM. */
KM_API km_status km_shape_copy(km_shape *out, const km_shape *s, km_error *err);

/* Winding number of the point p about contour i of s (its flattening, see
 * above): +1 inside a counter-clockwise contour, -1 inside a clockwise
 * one, 0 outside. A point within the chord error of the contour may get
 * either answer. */
KM_API int km_shape_winding(const km_shape *s, size_t i, const double p[2]);

/* ---- pairing ------------------------------------------------------------ */

/* One pair: contour `from` of the first shape with contour `to` of the
 * second; -1 on one side for a contour that vanishes (to = -1) or appears
 * (from = -1). */
typedef struct km_shape_pair {
  long from;
  long to;
} km_shape_pair;

/* Cost of pairing contour a (first shape) with contour b (second shape):
 *   w_position * |c_a - c_b| + w_size * |ln(A_a / A_b)|
 *   + w_turning * d_turn / pi
 * where c is the area centroid in the unit box of its own shape (the
 * box's corner at 0, its longer side 1), A the area, and d_turn the
 * turning-function distance: the root-mean-square difference of the
 * tangent angles at 64 equal arc-length fractions, minimised over the
 * start point (the 64 cyclic shifts) and a rotation (a constant). A
 * contour left without a partner costs `unpaired`, so a pair is made only
 * when it costs less than two unpaired contours. */
typedef struct km_shape_pair_costs {
  double w_position; /* default 1 */
  double w_size;     /* default 0.5 */
  double w_turning;  /* default 0.5 */
  double unpaired;   /* default 1 */
} km_shape_pair_costs;

/* Fill *c with the defaults noted on each field. */
KM_API void km_shape_pair_costs_default(km_shape_pair_costs *c);

/* The optimal pairing of a's contours with b's under *costs (NULL:
 * defaults), level by level: the top-level contours among themselves,
 * then the children of every pair among themselves; the children of an
 * unpaired contour are unpaired. Each level is an exact minimum-cost
 * assignment (Hungarian method on the (n + m) square matrix of pair and
 * no-partner costs). Only contours of one role are paired. *pairs (out,
 * on KM_OK only, owned by the caller, freed with km_shape_pairs_free) receives *npairs pairs: first the paired ones in
 * a's order, then a's unpaired ones, then b's. Returns KM_OK, KM_EINVAL
 * (a or b empty, a cost not finite or negative), KM_ECANCELLED (stop),
 * KM_ENOMEM. */
KM_API km_status km_shape_pair_auto(const km_shape *a, const km_shape *b,
                                    const km_shape_pair_costs *costs,
                                    const km_stop *stop, km_shape_pair **pairs,
                                    size_t *npairs, km_error *err);

/* Free pairs from km_shape_pair_auto; NULL is a no-op. */
KM_API void km_shape_pairs_free(km_shape_pair *pairs);

/* Check a caller's pairing of a with b: every contour of a and of b in
 * exactly one pair, indices in range, no pair (-1, -1), paired contours of
 * one role, and the parents of two paired contours paired with each other
 * (or both top-level). Returns KM_OK, or KM_EMATCH (KM_FIELD_MATCHES,
 * err->index the pair at fault; for a contour in no pair, index npairs and
 * the message names the contour), KM_EINVAL (pairs NULL with npairs > 0,
 * a or b empty). */
KM_API km_status km_shape_pair_check(const km_shape *a, const km_shape *b,
                                     const km_shape_pair *pairs, size_t npairs,
                                     km_error *err);

/* ---- the compound morph ------------------------------------------------- */

typedef struct km_shape_morph_options {
  km_morph_options morph;     /* for every pair (its stop is not used) */
  const km_shape_pair *pairs; /* the caller's pairing, npairs pairs,
                                 borrowed for the call; NULL: automatic */
  size_t npairs;
  km_shape_pair_costs costs; /* for the automatic pairing */
  /* pairs (when given) came from km_shape_pair_auto, not from a person:
   * under intersections AVOID the morph may pair otherwise where its
   * previews still fail (automatic pairing is always free so) */
  bool pairs_free;
} km_shape_morph_options;

/* Fill *o with defaults: km_morph_options_default, automatic pairing,
 * km_shape_pair_costs_default. */
KM_API void km_shape_morph_options_default(km_shape_morph_options *o);

/* Other pairings a morph under intersections AVOID tries at most. */
#define KM_SHAPE_PAIRINGS_TRIED 6

typedef struct km_shape_morph km_shape_morph;

/* A frame of a compound morph: one slot per pair, in the morph's pair
 * order (km_shape_morph_pairs). A contour collapsed to a point (a
 * vanishing one at t = 1, an appearing one at t = 0) is omitted with its
 * slot kept: present[k] false, contours[k] empty (km_curve_init), its
 * metrics zero. */
typedef struct km_shape_frame {
  size_t ncontours;
  km_curve *contours;
  km_frame_metrics *metrics; /* per contour (km_morph_frame's metrics of
                                its pair's frame, length scaled) */
  bool *present;
  long *parent;              /* the slot of the contour it must lie in (its
                            parent at the nearer end: from for t < 0.5),
                            -1 for none */
  long mutual_intersections; /* proper crossings between different
                                contours, on their flattenings */
  bool nesting_ok;           /* every present contour with a parent lies
                            inside it (all its flattening points) */
  size_t adjusted;           /* contours moved to keep them in their parent */
} km_shape_frame;

KM_API void km_shape_frame_init(km_shape_frame *f);
KM_API void km_shape_frame_free(km_shape_frame *f);

/* Prepare the morph from -> to into *out (owned by the caller,
 * km_shape_morph_free). opt may be NULL (defaults). Pairs come from
 * opt->pairs (checked by km_shape_pair_check) or km_shape_pair_auto.
 * Every pair (i, j) gets km_morph_create(from contour i, to contour j);
 * a vanishing contour gets a morph to the circle of its own length and
 * orientation about its centroid, an appearing one from such a circle:
 * the turning blend does not depend on the lengths, so its frame scaled
 * by (1 - t) (vanishing) or t (appearing) about its centroid is the
 * curvature morph to or from an infinitesimal circle. Its point, where it
 * ends or starts, is its centroid mapped onto its host pair (its parent's
 * pair, or for a top-level contour the nearest paired top-level contour)
 * by the host's centroids and the square root of its areas' ratio,
 * pulled into the host's partner when it falls outside. Under
 * opt->morph.intersections KM_INTERSECTIONS_AVOID, when previews of
 * interior frames show mutual crossings or a child outside its parent,
 * the morph may place children by the part of their parent near them and
 * correct contours' placement and size by amounts smooth in t and zero at
 * t = 0 and 1; a morph whose previews are clean gets the frames it gets
 * under ALLOW. When they still fail and the pairing is free (automatic,
 * or opt->pairs_free), pairings that swap the partners of two pairs are
 * tried (at most KM_SHAPE_PAIRINGS_TRIED, each a whole morph) and the
 * one whose previews fail least is kept (km_shape_morph_pairs tells it). stop is polled throughout (NULL: never). Returns KM_OK, or (err->index the pair at
 * fault where there is one):
 *   KM_EINVAL    from or to empty;
 *   km_shape_pair_check's statuses for opt->pairs;
 *   km_morph_create's statuses for a pair (err->index the pair);
 *   KM_ECANCELLED, KM_ENOMEM. */
KM_API km_status km_shape_morph_create(km_shape_morph **out,
                                       const km_shape *from, const km_shape *to,
                                       const km_shape_morph_options *opt,
                                       const km_stop *stop, km_error *err);

KM_API void km_shape_morph_free(km_shape_morph *m);

/* The pairs used (the pair order of the frames): writes min(count, cap)
 * into pairs (may be NULL) and returns the count. */
KM_API size_t km_shape_morph_pairs(const km_shape_morph *m,
                                   km_shape_pair *pairs, size_t cap);

/* The point an unpaired contour collapses into: where slot `slot` of m
 * vanishes (at t = 1) or appears from (at t = 0), written to p. False,
 * p untouched, for a paired slot or a slot out of range. */
KM_API bool km_shape_morph_collapse_point(const km_shape_morph *m, size_t slot,
                                          double p[2]);

/* Frame at t in [0, 1] into *out (owned by the caller, km_shape_frame
 * _free; taken as empty). Each pair's curve is km_morph_frame_until's at t
 * (the engine's fit placement onto the pair's linear blend); a vanishing
 * or appearing contour is scaled about its centroid. A contour with one
 * paired parent at both ends (or at its one end) then follows the
 * parent: its centroid goes where the similarities best mapping the
 * parent's end frames onto the parent's frame at t carry its centroids at
 * t = 0 and 1 (an unpaired one's point on its missing side), blended
 * (1 - t, t), so the parts move and turn as one shape. An unpaired contour
 * inside a parent takes the largest size that fits in the parent, measured
 * when the morph is made at t = j / 32 and kept monotone (it never grows
 * toward its missing side), its centre moved inside the parent if it lies
 * outside. A contour still outside its parent is then translated toward
 * the parent's inside by the smallest fraction (bisection to 1/1024) that
 * puts it inside; out->adjusted counts them. t = 0 and t = 1 give the inputs
 * within the morph tolerance. Returns KM_OK, or:
 *   KM_ERANGE     t outside [0, 1] or NaN (KM_FIELD_TIMES, param t);
 *   km_morph_frame_until's statuses (err->index the pair);
 *   KM_ECANCELLED, KM_ENOMEM.
 * Thread-safe on a shared morph. */
KM_API km_status km_shape_morph_frame_until(const km_shape_morph *m, double t,
                                            const km_stop *stop,
                                            km_shape_frame *out, km_error *err);

#endif
