/* morph_internal.h - the morph object and its prepared inputs, shared by
 * the files of the morph engine (morph*.c); internal to the core.
 *
 * morph.c creates the object and dispatches frames; the inputs are made
 * ready in morph_input.c (copy, signature, tables, orientation, start),
 * matched in morph_match.c, blended in morph_blend.c, closed in
 * morph_closure.c and placed in morph_place.c; planned frames come from
 * morph_plan.c. Every function declared here reads a morph or an input
 * that does not change any more, so frames may be built from many threads
 * at once.
 */
#ifndef KM_MORPH_INTERNAL_H
#define KM_MORPH_INTERNAL_H

#include <stdbool.h>
#include <stddef.h>

#include "internal.h"
#include "km/curve.h"
#include "km/morph.h"
#include "km/signature.h"
#include "km/status.h"
#include "morph_kappa.h"
#include "morph_plan.h"
#include "morph_repair.h"

/* Samples of an input's position table, at s = L j / KM__TABLE_N: the
 * placement targets and the start alignment read it. */
#define KM__TABLE_N 512
/* Starts of a closed `to` tried, best aligned first (km__best_shifts). */
#define KM__SHIFT_CANDIDATES 4

typedef struct km__repair km__repair;

/* One input of a morph, made ready (km__input_prepare). */
typedef struct km__input {
  km_curve curve;
  bool has_curve;
  km_signature sig;
  km_pp kappa, theta;               /* theta pieces in s */
  double table[KM__TABLE_N + 1][2]; /* positions at s = L j / KM__TABLE_N */
  double centroid[2];
} km__input;

struct km_morph {
  km_morph_options opt;
  double tol;
  bool closed;
  km__input in[2];
  double *ra, *rb; /* correspondence knots, nm+2 of them incl. 0 and 1 */
  size_t nk;
  size_t nuser;         /* match pairs reported */
  km_curve lin[2];      /* compatible curves (linear method) */
  km__frame_plan *plan; /* frames planned once (morph_plan.c), or NULL */
  km__kappa_table *frame_kappa; /* planned frames' curvature (morph_kappa.c) */
  bool close_by_corners;        /* lsq closure by the frames' corners */
  double kmax; /* the inputs' largest |kappa|: the frames' bound */
  /* placement targets of planned frames: the inputs' points at the plan's
   * breaks (x, y of a, then of b) and the break's trapezoid weight; the
   * weights' sum and the weighted means */
  double (*place_ab)[5];
  double place_w_sum, place_qa[2], place_qb[2];
  km_morph_avoidance avoid; /* what intersections AVOID did */
  km__repair *repair;       /* frames repaired (morph_repair.c), or NULL */
  bool keep_pieces; /* planned frames keep the plan's pieces (no merging):
                       contours of compound shapes, whose frames are
                       placed and checked against each other by samples */
  /* the caller's stop condition while km_morph_create runs, NULL after:
   * frames take their own (km_morph_frame_until) */
  km__poll *poll;
};

/* ---- inputs (morph_input.c) ---------------------------------------------
 * Statuses: KM_ENOMEM (with err), KM_ECANCELLED when poll says stop (err
 * untouched: the caller reports the stop), and those of the signature and
 * curve functions named. */

/* Makes *in ready from src (a curve, a signature or both): its copy, its
 * signature (computed from the curve to tol, or without one to 1e-6 of its
 * own length), its theta pieces and its position table. *in is
 * initialised first, so km__input_free may follow any outcome. KM_EINVAL
 * (err) when src has neither. */
km_status km__input_prepare(km__input *in, const km_morph_input *src,
                            double tol, km__poll *poll, km_error *err);
/* Frees what *in holds (an initialised or prepared input). */
void km__input_free(km__input *in);
/* Deep copy of a prepared input into *out (initialised, empty); on failure
 * *out holds what was copied and is freed by km__input_free. */
km_status km__input_copy(km__input *out, const km__input *in, km_error *err);
/* The input's curve, reconstructed from its signature to tol (at most
 * max_points control points, 0: no bound) unless it has one. */
km_status km__input_ensure_curve(km__input *in, double tol, size_t max_points,
                                 km__poll *poll, km_error *err);
/* The closed input started at arc length s0 instead of 0 (exactly: its
 * signature shifted cyclically, its curve split and joined); nothing
 * changes for s0 within 1e-12 L of either end. */
km_status km__input_rotate_start(km__input *in, double s0, km__poll *poll,
                                 km_error *err);
/* The closed input traced backwards, exactly. */
km_status km__input_reverse(km__input *in, km__poll *poll, km_error *err);
/* Position at normalised arc length r in [0, 1] (clamped), linear between
 * the table's points. */
void km__input_point_at(const km__input *in, double r, double out[2]);
/* Tangent angle at arc length s (clamped to the piece at either end). */
double km__input_theta_at(const km__input *in, double s);
/* Fills cand[] with up to KM__SHIFT_CANDIDATES starts of b (fractions of
 * its length), best aligned with a first, and *n (out) with how many (at
 * least one). KM_OK or KM_ENOMEM (then nothing written). */
km_status km__best_shifts(const km__input *a, const km__input *b, double *cand,
                          size_t *n);

/* ---- morphs made from a morph (morph.c) and crossings (morph_avoid.c) */

/* The morph base with its closed `to` started a further fraction dshift of
 * its length along (0: where it is), with automatic matches or none, at
 * frame tolerance tol (<= 0: base's): its inputs are copied, not computed
 * again, and it is planned as base was. Statuses as km_morph_create (err
 * may be NULL). */
km_status km__morph_variant(const km_morph *base, double dshift,
                            bool auto_matches, double tol, km__poll *poll,
                            km_morph **out, km_error *err);
/* The curve of the frame at t, as km_morph_frame_until with poll. */
km_status km__morph_frame(const km_morph *m, double t, km__poll *poll,
                          km_curve *out, km_error *err);
/* intersections AVOID: *mp is replaced by the choice kept (the others are
 * freed) and its avoid report filled. KM_OK, KM_ENOMEM or KM_ECANCELLED
 * (then every morph is freed and *mp is NULL). */
km_status km__avoid_crossings(km_morph **mp, km__poll *poll);

/* intersections AVOID, second step (morph_repair.c): frames at k / 32
 * are scanned for crossings and the strands that cross are moved apart by
 * a change smooth in t (a displacement, a change of curvature or either,
 * as how says), kept in m->repair (NULL when nothing
 * crosses) with the report in m->avoid. KM_OK, KM_ENOMEM or
 * KM_ECANCELLED (then m is as it was). */
/* Planned frames of m keep the plan's pieces from here on, unmerged (the
 * contours of a compound morph, shape_morph.c), planned again within
 * KM__PLAN_KEPT_SHARE of the tolerance. KM_OK, KM_ENOMEM (m then has no
 * plan: its frames take the general path). */
km_status km__morph_keep_pieces(km_morph *m, km_error *err);
km_status km__repair_crossings(km_morph *m, km__repair_method how,
                               km__poll *poll);
void km__repair_free(km__repair *rp);
/* Whether rp changes the curvature of the frame at t (an event repaired
 * by curvature), and whether it displaces it (an event repaired by
 * displacement); false for NULL. */
bool km__repair_kappa_active(const km__repair *rp, double t);
bool km__repair_displaces(const km__repair *rp, double t);
/* The curvature repair's change at t, the sum over its first nev events
 * (all: (size_t)-1), as pieces over the normalised arc length [0, 1] in
 * units of 1 / length (an empty *out, m = 0, when nothing changes; the
 * caller frees it). KM_OK or KM_ENOMEM. */
km_status km__repair_kappa(const km__repair *rp, double t, size_t nev,
                           km_pp *out);
/* sig with dk (as km__repair_kappa makes it) added to its curvature, into
 * *out (the caller frees it). Statuses of km_signature_create. */
km_status km__add_kappa(const km_signature *sig, const km_pp *dk,
                        km_signature *out, km_error *err);
/* The frame at t (placed, closed as any frame) of the blend plus dk, by
 * the general path; and its closed signature before the reconstruction
 * (not placed). Statuses as km_morph_frame. */
km_status km__morph_frame_kappa(const km_morph *m, double t, const km_pp *dk,
                                km__poll *poll, km_curve *out, km_error *err);
km_status km__morph_signature_kappa(const km_morph *m, double t,
                                    const km_pp *dk, km__poll *poll,
                                    km_signature *out, km_error *err);
/* Whether the repair moves the frame at t. */
bool km__repair_active(const km__repair *rp, double t);
/* Control points the repair adds to the frame at t, at most. */
size_t km__repair_extra_points(const km__repair *rp, double t);
/* *f (the frame at t, placed) moved by the repair at t; *moved_by
 * receives a bound on the displacement. KM_OK or KM_ENOMEM (err). */
km_status km__repair_apply(const km__repair *rp, double t, km_curve *f,
                           double *moved_by, km_error *err);

/* Other starts of b: in each of nsec (>= 2) equal sectors of its length
 * but the one centred on its own start, the start that aligns best with a
 * (km__best_shifts' cost), best first: fractions of its length into cand
 * (nsec - 1 places), their costs into costs, then the cost of b's own
 * start (nsec places); *n (out) how many. KM_OK or KM_ENOMEM. */
km_status km__sector_shifts(const km__input *a, const km__input *b, size_t nsec,
                            double *cand, double *costs, size_t *n);

/* Pieces of p restricted to [x0, x1] (x0 < x1, inside p's breaks) into
 * *out (initialised, empty; the caller frees it). KM_ENOMEM, no message. */
km_status km__pp_slice(km_pp *out, const km_pp *p, double x0, double x1);
/* qsort comparison of km_corner by arc length. */
int km__cmp_corner(const void *x, const void *y);

#endif
