/* morph.h - curvature-interpolation morphs (paper section 3) and the linear
 * control-point baseline.
 *
 * A km_morph is a prepared plan: both inputs' signatures, the
 * correspondence (matches, start point and orientation of closed curves)
 * and the placement data are computed once by km_morph_create; any number
 * of threads may then call km_morph_frame on it concurrently (it is never
 * changed after creation).
 */
#ifndef KM_MORPH_H
#define KM_MORPH_H

#include "km/export.h"

#include <stdbool.h>
#include <stddef.h>

#include "km/curve.h"
#include "km/signature.h"
#include "km/stop.h"

/* Curvature interpolation (the paper), or the baseline: control points of
 * the two inputs made compatible, blended linearly. */
typedef enum km_morph_method {
  KM_METHOD_CURVATURE,
  KM_METHOD_LINEAR
} km_morph_method;

/* TURNING blends the turning functions at equal arc-length fraction r:
 * theta_t(r) = (1-t) theta_a(r) + t theta_b(r), corners included, so total
 * turning is exact and max |kappa_t| <= max(max |kappa_a|, max |kappa_b|).
 * PAPER blends kappa literally: kappa_t(r L_t) = (1-t) kappa_a(r L_a) +
 * t kappa_b(r L_b), which does not close a circle's tangent when the
 * lengths differ. */
typedef enum km_blend { KM_BLEND_TURNING, KM_BLEND_PAPER } km_blend;

/* Closing the frames of closed inputs. AUTO is LSQ: the closed curve
 * whose curvature is nearest the blended one (Gauss-Newton with the two
 * closure constraints). C0, C1, G2: the paper's corrections spreading the
 * end gap over the control polygon. NONE: the gap is left. */
typedef enum km_closure {
  KM_CLOSURE_AUTO,
  KM_CLOSURE_LSQ,
  KM_CLOSURE_C0,
  KM_CLOSURE_C1,
  KM_CLOSURE_G2,
  KM_CLOSURE_NONE
} km_closure;

/* Placement of a frame (curvature fixes it up to a rigid motion): FIT, the
 * rigid motion that best fits the frame to the inputs' points blended
 * linearly; START, the paper's interpolated start point and angle;
 * CENTROID, the frame's arc-length centroid put on the inputs'
 * interpolated centroids (angle as START). */
typedef enum km_anchor {
  KM_ANCHOR_FIT,
  KM_ANCHOR_START,
  KM_ANCHOR_CENTROID
} km_anchor;

/* Closed inputs: AUTO reverses `to` when its turning number is the
 * opposite of `from`'s; KEEP never does (different turning numbers are
 * then KM_ETURNING). */
typedef enum km_orient { KM_ORIENT_AUTO, KM_ORIENT_KEEP } km_orient;

/* Frames that cross themselves: ALLOW takes the correspondence as the
 * alignment chooses it; AVOID, when previews of interior frames of that
 * choice cross, tries the other choices the morph is free to make (the
 * start of a closed `to`, automatic matches or none when "auto" was asked
 * for) and keeps the one whose previews cross least (km_morph_avoided). */
typedef enum km_intersections {
  KM_INTERSECTIONS_ALLOW,
  KM_INTERSECTIONS_AVOID
} km_intersections;

typedef struct km_morph_options {
  km_morph_method method; /* default curvature */
  km_blend blend;         /* default turning */
  km_closure closure;     /* default auto (= lsq) */
  km_anchor anchor;       /* default fit */
  km_orient orient;       /* default auto */
  double tolerance;       /* distance; <= 0: 1e-5 * longer input length */
  int degree;             /* 3 (default) or 5 */
  const double *matches;  /* nmatches pairs (r_from, r_to) of arc-length
                             fractions, strictly increasing inside (0, 1)
                             on both sides; borrowed for km_morph_create */
  size_t nmatches;
  bool auto_matches; /* without matches: align features (curvature
                             extrema, corners) automatically */
  size_t max_points; /* control points a frame may have; 0: the core's
                             own bound (KM_MAX_OUTPUT_PIECES) */
  km_intersections intersections; /* default allow */
  const km_stop *stop; /* km_morph_create ends early with KM_ECANCELLED
                             when this asks it to (km/stop.h); NULL, the
                             default: never. Borrowed for the call only:
                             the morph keeps no reference to it */
} km_morph_options;

/* Fill *o with the defaults noted on each field: curvature method,
 * turning blend, automatic closure, fit anchor, automatic orientation,
 * default tolerance, degree 3, no matches, no bound beyond the core's, no
 * stop. */
KM_API void km_morph_options_default(km_morph_options *o);

/* One input: a curve, a signature, or both (the signature of that curve).
 * With only a signature the curve is reconstructed when needed. */
typedef struct km_morph_input {
  const km_curve *curve;
  const km_signature *sig;
} km_morph_input;

/* Metrics of a frame. Curvature frames: of the exact frame, the curve of
 * the blended signature after closure, which the returned B-spline
 * approximates within the tolerance. Linear frames: of the B-spline
 * itself, max |kappa| and the energy from quadrature samples. */
typedef struct km_frame_metrics {
  double length;
  double max_abs_kappa;    /* 1 / length unit */
  double bending_energy;   /* integral of kappa^2 ds */
  long self_intersections; /* proper self-crossings of the returned curve
                               (km_curve_self_intersections at the morph's
                               tolerance); out of memory fails the frame
                               with KM_ENOMEM */
  double closure_gap;      /* |C(L) - C(0)| before closure; 0 if open */
} km_frame_metrics;

typedef struct km_morph km_morph;

/* Prepare a morph from -> to into *out (owned by the caller,
 * km_morph_free). Each input gives a curve, a signature or both; they and
 * *opt are borrowed for the call only (the morph keeps deep copies).
 * opt must not be NULL (start from km_morph_options_default). The
 * tolerance is opt->tolerance, a distance (<= 0: 1e-5 of the longer
 * input's length); signatures computed from input curves are held to a
 * tenth of it (without one, to 1e-6 of each curve's own length). A degree
 * other than 5 is taken as 3. Closed inputs of opposite turning numbers
 * have `to` reversed unless opt->orient is KM_ORIENT_KEEP. Returns KM_OK,
 * or:
 *   KM_EINVAL       an input with neither curve nor signature;
 *   km_curve_copy's, km_signature_copy's (km_signature_create's) and
 *   km_signature_compute's statuses for the inputs (KM_ECUSP,
 *                   KM_EDEGENERATE, KM_ERANGE, KM_ENOCONVERGE, KM_ELIMIT);
 *   KM_EMIXED       one input open, the other closed (KM_FIELD_CLOSED);
 *   KM_ETURNING     closed inputs of different turning numbers (the
 *                   message gives both);
 *   KM_EMATCH       matches not strictly increasing inside (0, 1) on both
 *                   sides, or not finite (KM_FIELD_MATCHES, err->index
 *                   the pair);
 *   KM_ELIMIT       the planned frames need more control points than
 *                   opt->max_points, or more pieces than the core allows
 *                   (KM_FIELD_TOLERANCE); for the linear method, an input
 *                   reconstructed beyond opt->max_points;
 *   KM_ENOCONVERGE, KM_EDEGENERATE  planning the frames failed;
 *   km_curve_make_compatible's statuses (linear method);
 *   KM_ECANCELLED   opt->stop asked to stop (its signatures, tables,
 *                   automatic matches, start search, plans and preview
 *                   frames all poll it; nothing is leaked);
 *   KM_ENOMEM. */
KM_API km_status km_morph_create(km_morph **out, const km_morph_input *from,
                                 const km_morph_input *to,
                                 const km_morph_options *opt, km_error *err);

/* Free the morph and everything it holds; m may be NULL. */
KM_API void km_morph_free(km_morph *m);

/* Frame at time t in [0, 1] into *out (owned by the caller): its curve
 * (degree opt.degree for curvature frames; the compatible degree of the
 * two inputs for linear frames), and when asked (NULL: not) its metrics
 * (*metrics) and its exact, blended, closed and placed signature
 * (*sig_out, owned by the caller). t = 0 and t = 1 give the inputs where
 * they stand, within the tolerance. A planned morph's frames come from
 * its plan, with metrics too (those of the exact blended and closed
 * signature; the crossings counted on the returned curve); frames with a
 * signature asked for are blended and reconstructed exactly rather than
 * taken from the plan, and may have other control points. For the
 * linear method a frame that is not regular (a cusp) has no signature:
 * *sig_out is then left empty (km_signature_init; length 0) with KM_OK.
 * Returns KM_OK, or:
 *   KM_ERANGE       t outside [0, 1] or NaN (KM_FIELD_TIMES, err->param
 *                   = t); a placed control point beyond KM_MAX_COORDINATE;
 *   KM_ELIMIT       the frame needs more control points than
 *                   opt.max_points, or more pieces than the core allows
 *                   (KM_FIELD_TOLERANCE);
 *   KM_ENOCONVERGE  closing a closed frame did not converge;
 *   km_signature_create's statuses for the blended signature;
 *   KM_ENOMEM.
 * Thread-safe on a shared km_morph: it is only read. */
KM_API km_status km_morph_frame(const km_morph *m, double t, km_curve *out,
                                km_frame_metrics *metrics,
                                km_signature *sig_out, km_error *err);

/* km_morph_frame that ends early when stop (km/stop.h; NULL: never) asks
 * it to: then KM_ECANCELLED and nothing written to out, metrics or
 * sig_out. The blend, closure, reconstruction, plan passes and the
 * crossing count of the metrics poll it. Distinct calls may pass distinct
 * stops on one shared morph. Other statuses as km_morph_frame. */
KM_API km_status km_morph_frame_until(const km_morph *m, double t,
                                      const km_stop *stop, km_curve *out,
                                      km_frame_metrics *metrics,
                                      km_signature *sig_out, km_error *err);

/* What a frame is asked for: its curve alone, its metrics too (the same
 * curve: a planned morph's frame with the metrics of its exact
 * signature), or its signature too (such frames are blended and
 * reconstructed exactly, not taken from the morph's plan, and may have
 * other control points). */
typedef enum km_frame_parts {
  KM_FRAME_CURVE,
  KM_FRAME_WITH_METRICS,
  KM_FRAME_WITH_SIGNATURE
} km_frame_parts;

/* Control points the curve of the frame at t will have (km_morph_frame
 * with what parts says asked for), into *points (out, on KM_OK only):
 * exact; free for a linear morph, at the cost of the frame for a planned
 * morph's curves (each frame merges runs of the plan's pieces as it can,
 * so counts differ between frames), otherwise at the cost of the frame's
 * blend and closure (a third to a half of the frame). Stops as km_morph_frame_until (stop
 * may be NULL). Statuses as km_morph_frame_until. Thread-safe. */
KM_API km_status km_morph_frame_points(const km_morph *m, double t,
                                       km_frame_parts parts,
                                       const km_stop *stop, size_t *points,
                                       km_error *err);

/* The correspondence used, as pairs of arc-length fractions (r_from, r_to)
 * strictly inside (0, 1): writes the first min(count, cap) pairs into
 * pairs (out, 2 cap doubles; may be NULL to ask the count) and returns
 * the count, the given or automatic matches (0 without matches). */
KM_API size_t km_morph_matches_used(const km_morph *m, double *pairs,
                                    size_t cap);

/* What km_morph_create's crossing avoidance did (intersections AVOID). */
typedef struct km_morph_avoidance {
  bool searched;           /* the first choice's previews crossed, others were
                            tried */
  bool changed;            /* another choice was kept */
  long crossings_before;   /* crossings of the previews of the first choice */
  long crossings_after;    /* of the choice kept (0: none seen) */
  long input_crossings[2]; /* self-crossings of from and to themselves */
  size_t previews;         /* preview frames built */
  /* the repair (frames that still cross after the choice): frames of the
   * scan at t = k / 32 that crossed, events (pinches) repaired, events
   * that could not be (their strands pass through each other between
   * clean frames), and checks between the key times that still cross */
  long repair_scan_crossing;
  long repair_events;
  long repair_unrepaired;
  long repair_checks_crossing;
} km_morph_avoidance;

/* Whether the frame at t is repaired (moved by a displacement that
 * separates strands that would cross), and by how much at most (the
 * displacement's largest size, 0 when not repaired). */
KM_API double km_morph_repaired(const km_morph *m, double t);

/* The report of km_morph_create's avoidance into *out (all zero when
 * intersections was ALLOW or the inputs are not curvature-morphed). */
KM_API void km_morph_avoided(const km_morph *m, km_morph_avoidance *out);

/* Lengths and turnings (total tangent turn in radians, 2 pi times the
 * turning number for a closed curve) of the two prepared inputs, from
 * first, to second, into length and turning (out). */
KM_API void km_morph_inputs(const km_morph *m, double length[2],
                            double turning[2]);

#endif
