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

#include <stdbool.h>
#include <stddef.h>

#include "km/curve.h"
#include "km/signature.h"
#include "km/stop.h"

typedef enum km_morph_method { KM_METHOD_CURVATURE, KM_METHOD_LINEAR } km_morph_method;
typedef enum km_blend { KM_BLEND_TURNING, KM_BLEND_PAPER } km_blend;
typedef enum km_closure {
  KM_CLOSURE_AUTO,
  KM_CLOSURE_LSQ,
  KM_CLOSURE_C0,
  KM_CLOSURE_C1,
  KM_CLOSURE_G2,
  KM_CLOSURE_NONE
} km_closure;
typedef enum km_anchor { KM_ANCHOR_FIT, KM_ANCHOR_START, KM_ANCHOR_CENTROID } km_anchor;
typedef enum km_orient { KM_ORIENT_AUTO, KM_ORIENT_KEEP } km_orient;

typedef struct km_morph_options {
  km_morph_method method; /* default curvature */
  km_blend blend;         /* default turning */
  km_closure closure;     /* default auto (= lsq) */
  km_anchor anchor;       /* default fit */
  km_orient orient;       /* default auto */
  double tolerance;       /* distance; <= 0: 1e-5 * longer input length */
  int degree;             /* 3 (default) or 5 */
  const double *matches;  /* nmatches pairs (r_from, r_to), borrowed */
  size_t nmatches;
  bool auto_matches;      /* matches: "auto" */
  size_t max_points;      /* control points a frame may have; 0: the core's
                             own bound (KM_MAX_OUTPUT_PIECES) */
  const km_stop *stop;    /* km_morph_create ends early with KM_ECANCELLED
                             when this asks it to (km/stop.h); NULL, the
                             default: never. Borrowed for the call only:
                             the morph keeps no reference to it */
} km_morph_options;

void km_morph_options_default(km_morph_options *o);

/* One input: a curve, a signature, or both (the signature of that curve).
 * With only a signature the curve is reconstructed when needed. */
typedef struct km_morph_input {
  const km_curve *curve;
  const km_signature *sig;
} km_morph_input;

typedef struct km_frame_metrics {
  double length;
  double max_abs_kappa;
  double bending_energy;    /* integral of kappa^2 ds */
  long self_intersections;  /* proper self-crossings */
  double closure_gap;       /* |C(L) - C(0)| before closure; 0 if open */
} km_frame_metrics;

typedef struct km_morph km_morph;

/* Prepare a morph from -> to. Fails with KM_EMIXED (open vs closed),
 * KM_ETURNING (closed curves of different turning numbers; the message
 * gives both), KM_EMATCH (matches not strictly increasing in (0,1) on both
 * sides; err->index is the pair), KM_ECUSP / KM_EDEGENERATE from the
 * inputs, KM_ENOMEM, KM_ECANCELLED when opt->stop asked it to stop (its
 * signatures, tables, automatic matches, start search, plans and preview
 * frames all poll it; nothing is leaked). *out is owned by the caller
 * (km_morph_free). */
km_status km_morph_create(km_morph **out, const km_morph_input *from,
                          const km_morph_input *to,
                          const km_morph_options *opt, km_error *err);
void km_morph_free(km_morph *m);

/* Frame at time t in [0, 1]: its curve (degree opt.degree for curvature
 * frames; the compatible degree for linear frames), and optionally its
 * metrics and its (exact, blended, after closure) signature. t = 0 and
 * t = 1 give the inputs where they stand (within the tolerance).
 * Thread-safe on a shared km_morph. */
km_status km_morph_frame(const km_morph *m, double t, km_curve *out,
                         km_frame_metrics *metrics, km_signature *sig_out,
                         km_error *err);

/* km_morph_frame that ends early when stop (km/stop.h; NULL: never) asks
 * it to: then KM_ECANCELLED and nothing written to out, metrics or
 * sig_out. The blend, closure, reconstruction, plan passes and the
 * crossing count of the metrics poll it. Distinct calls may pass distinct
 * stops on one shared morph. */
km_status km_morph_frame_until(const km_morph *m, double t,
                               const km_stop *stop, km_curve *out,
                               km_frame_metrics *metrics,
                               km_signature *sig_out, km_error *err);

/* What a frame is asked for: its curve alone, or its metrics or signature
 * too (such frames are blended and reconstructed exactly, not taken from
 * the morph's plan, and may have other control points). */
typedef enum km_frame_parts { KM_FRAME_CURVE, KM_FRAME_WITH_METRICS } km_frame_parts;

/* Control points the curve of the frame at t will have (km_morph_frame
 * with metrics or a signature asked for when parts is
 * KM_FRAME_WITH_METRICS), in *points, without building it: exact, and for
 * a planned morph's curves free; otherwise at the cost of the frame's
 * blend and closure (a third to a half of the frame). Stops as
 * km_morph_frame_until. Errors as km_morph_frame. Thread-safe. */
km_status km_morph_frame_points(const km_morph *m, double t,
                                km_frame_parts parts, const km_stop *stop,
                                size_t *points, km_error *err);

/* The correspondence used, as pairs of arc-length fractions (r_from, r_to):
 * writes up to cap pairs into pairs (may be NULL), returns the count. */
size_t km_morph_matches_used(const km_morph *m, double *pairs, size_t cap);

/* Turning numbers and lengths of the two prepared inputs. */
void km_morph_inputs(const km_morph *m, double length[2], double turning[2]);

/* Count proper self-crossings of a curve (exact to the tolerance tol; a
 * curve folded almost onto itself over a long stretch gets the crossings
 * found within a bounded amount of work: see intersect.c). */
long km_curve_self_intersections(const km_curve *c, double tol);
/* The same count ending early when stop (km/stop.h; NULL: never) asks it
 * to: KM_OK with *count, KM_ECANCELLED (*count untouched), KM_EINVAL for
 * an invalid curve, KM_ENOMEM. */
km_status km_curve_self_intersections_until(const km_curve *c, double tol,
                                            const km_stop *stop,
                                            long *count);

#endif
