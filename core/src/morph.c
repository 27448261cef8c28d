/* morph.c - curvature-interpolation morphs (paper section 3): a morph is
 * created once, then frames are asked of it at any t.
 *
 * DESIGN. Creation makes both inputs ready (morph_input.c: signatures,
 * orientation, the start of a closed `to`), sets the correspondence (the
 * caller's matches or "auto", morph_match.c) and decides once how frames
 * are made and closed. Frames of the default morph (turning blend, no
 * matches, cubic output) without metrics or signature come from a plan
 * made once per morph (morph_plan.c); the others blend the signatures
 * exactly (morph_blend.c), close them (morph_closure.c) and reconstruct.
 * Either way the frame is then placed (morph_place.c). Method "linear"
 * blends control points (morph_linear.c).
 */
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "internal.h"
#include "km/alloc.h"
#include "km/limits.h"
#include "km/morph.h"
#include "km/reconstruct.h"
#include "morph_blend.h"
#include "morph_closure.h"
#include "pp_internal.h"
#include "morph_internal.h"
#include "morph_kappa.h"
#include "morph_linear.h"
#include "morph_match.h"
#include "morph_place.h"
#include "morph_plan.h"
#include "signature_internal.h"

void km_morph_options_default(km_morph_options *o) {
  memset(o, 0, sizeof *o);
  o->method = KM_METHOD_CURVATURE;
  o->blend = KM_BLEND_TURNING;
  o->closure = KM_CLOSURE_AUTO;
  o->anchor = KM_ANCHOR_FIT;
  o->orient = KM_ORIENT_AUTO;
  o->tolerance = 0.0;
  o->degree = 3;
}

void km_morph_free(km_morph *m) {
  if (!m) return;
  for (int i = 0; i < 2; i++) {
    km__input_free(&m->in[i]);
    km_curve_free(&m->lin[i]);
  }
  km__free(m->ra);
  km__free(m->rb);
  km__frame_plan_free(m->plan);
  km__kappa_table_free(m->frame_kappa);
  km__free(m->place_ab);
  km__repair_free(m->repair);
  km__free(m);
}

/* Whether the lsq closure goes by the frames' corners (*close): so if it
 * can at t = 1/4, 1/2 and 3/4, for every frame of the morph (a sequence
 * must not switch between closures). A trial that fails rules the corners
 * out, except for want of memory: KM_ENOMEM, as the same morph with memory
 * might close by its corners. */
static km_status corners_close(const km_morph *m, bool *close) {
  *close = false;
  for (int k = 1; k <= 3; k++) {
    km_signature blended, closed;
    km_signature_init(&blended);
    km_signature_init(&closed);
    double gap;
    bool used = false;
    km_status st = km__blend_signature(m, k / 4.0, &blended, NULL);
    if (!st)
      st = km__close_lsq(&blended, true, NULL, &closed, &gap, &used, m->poll,
                         NULL);
    km_signature_free(&blended);
    km_signature_free(&closed);
    if (st == KM_ENOMEM) return st;
    if (st || !used) return KM_OK;
  }
  *close = true;
  return KM_OK;
}

/* Frames of the default morph (turning blend, no matches, cubic output)
 * are planned once: see morph_plan.c. Others are blended piece by piece
 * and reconstructed frame by frame. Either way the kind of closure is
 * chosen here, once. */
static km_status plan_frames(km_morph *m, km_error *err) {
  const km__input *a = &m->in[0], *b = &m->in[1];
  km_closure how =
      m->opt.closure == KM_CLOSURE_AUTO ? KM_CLOSURE_LSQ : m->opt.closure;
  bool lsq = m->closed && how == KM_CLOSURE_LSQ;
  if (m->opt.method != KM_METHOD_CURVATURE) return KM_OK;
  if (m->opt.blend != KM_BLEND_TURNING || m->nk != 2 || m->opt.degree != 3) {
    bool corners = a->sig.ncorners + b->sig.ncorners > 0;
    m->close_by_corners = false;
    if (lsq && corners && corners_close(m, &m->close_by_corners))
      return km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
    return KM_OK;
  }
  const km_pp tp[2] = {a->theta, b->theta};
  double len[2] = {a->sig.length, b->sig.length};
  double ang[2] = {a->sig.angle, b->sig.angle};
  /* a planned frame has two control points a piece and two more (a corner
   * one more); 0 is no bound, so a bound below a piece's worth is one */
  size_t max_pieces = 0;
  if (m->opt.max_points > 0)
    max_pieces = m->opt.max_points >= 4 ? (m->opt.max_points - 2) / 2 : 1;
  double share = m->keep_pieces ? KM__PLAN_KEPT_SHARE : KM__PLAN_PIECE_SHARE;
  km_status st = km__frame_plan_build(&m->plan, tp, len, ang, m->closed, m->tol,
                                      share, max_pieces, m->poll, err);
  if (st == KM_ELIMIT && max_pieces > 0)
    return km__fail(err, KM_ELIMIT, KM_FIELD_TOLERANCE, -1, NAN,
                    "the frames need more than %zu control points at this "
                    "tolerance, the most allowed a curve: loosen the "
                    "tolerance",
                    m->opt.max_points);
  if (!st) m->close_by_corners = lsq && km__frame_plan_by_corners(m->plan);
  if (!st) st = km__place_plan_targets(m, err);
  km__kappa_table_free(m->frame_kappa);
  m->frame_kappa = NULL;
  if (!st && km__kappa_table_build(&a->kappa, &b->kappa, &m->frame_kappa))
    st = km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
  return st;
}

/* An empty morph (every part initialised, km_morph_free-able) with the
 * caller's poll, or NULL without memory. */
static km_morph *morph_new(km__poll *poll) {
  km_morph *m = km__calloc(1, sizeof *m);
  if (!m) return NULL;
  for (int i = 0; i < 2; i++) {
    km_curve_init(&m->in[i].curve);
    km_signature_init(&m->in[i].sig);
    km__pp_init(&m->in[i].kappa);
    km__pp_init(&m->in[i].theta);
    km_curve_init(&m->lin[i]);
  }
  m->poll = poll;
  return m;
}

/* Both inputs made ready and the frame tolerance set. Inputs' signatures
 * are held to a tenth of the tolerance: their error adds to the frames'.
 * The default tolerance, 1e-5 of the longer length, is known only with
 * both lengths; a tenth of 1e-5 of each curve's own is at least as tight,
 * and needs no length before the signature. */
static km_status prepare_inputs(km_morph *m, const km_morph_input *from,
                                const km_morph_input *to, km_error *err) {
  const km_morph_options *opt = &m->opt;
  double tol = opt->tolerance > 0 ? opt->tolerance : 0.0;
  km_status st = km__input_prepare(&m->in[0], from, 0.1 * tol, m->poll, err);
  if (!st) st = km__input_prepare(&m->in[1], to, 0.1 * tol, m->poll, err);
  if (st) return st;
  if (!(opt->tolerance > 0))
    tol = 1e-5 * fmax(m->in[0].sig.length, m->in[1].sig.length);
  m->tol = tol;
  /* Curvature frames need the signatures only: the curves would be turned
   * and copied with every change of start for nothing. */
  if (opt->method == KM_METHOD_CURVATURE)
    for (int i = 0; i < 2; i++) {
      km_curve_free(&m->in[i].curve);
      m->in[i].has_curve = false;
    }
  return KM_OK;
}

/* Open or closed alike; closed pairs of opposite turning have `to`
 * reversed (orient auto) and, without matches, `to` started where it
 * aligns best (the candidates in cand/ncand, best first). */
static km_status orient_inputs(km_morph *m, double *cand, size_t *ncand,
                               km_error *err) {
  const km_morph_options *opt = &m->opt;
  km__input *a = &m->in[0], *b = &m->in[1];
  if (a->sig.closed != b->sig.closed)
    return km__fail(err, KM_EMIXED, KM_FIELD_CLOSED, -1, NAN,
                    "cannot morph an open curve into a closed one (from is %s, "
                    "to is %s)",
                    a->sig.closed ? "closed" : "open",
                    b->sig.closed ? "closed" : "open");
  m->closed = a->sig.closed;
  if (!m->closed) return KM_OK;
  double na = a->sig.turning / (2 * KM_PI), nb = b->sig.turning / (2 * KM_PI);
  long ta = lround(na), tb = lround(nb);
  if (ta == -tb && ta != 0 && opt->orient == KM_ORIENT_AUTO) {
    km_status st = km__input_reverse(b, m->poll, err);
    if (st) return st;
    tb = lround(b->sig.turning / (2 * KM_PI));
  }
  if (ta != tb)
    return km__fail(err, KM_ETURNING, KM_FIELD_NONE, -1, NAN,
                    "closed curves must have equal turning numbers: from "
                    "turns %ld times, to turns %ld times",
                    ta, tb);
  if (opt->nmatches > 0) return KM_OK;
  if (km__best_shifts(a, b, cand, ncand))
    return km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
  if (!(cand[0] > 0)) return KM_OK;
  return km__input_rotate_start(b, cand[0] * b->sig.length, m->poll, err);
}

/* The correspondence knots from the caller's matches (opt: the caller's
 * options, m->opt holds none), or from "auto" without them. */
static km_status set_correspondence(km_morph *m, const km_morph_options *opt,
                                    km_error *err) {
  size_t nm = opt->nmatches;
  double auto_pairs[2 * 64];
  const double *pairs = opt->matches;
  if (opt->auto_matches && nm == 0) {
    nm = km__auto_matches(&m->in[0], &m->in[1], auto_pairs, 64);
    pairs = auto_pairs;
  }
  m->ra = km__malloc((nm + 2) * sizeof(double));
  m->rb = km__malloc((nm + 2) * sizeof(double));
  if (!m->ra || !m->rb)
    return km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
  m->ra[0] = m->rb[0] = 0.0;
  for (size_t i = 0; i < nm; i++) {
    double x = pairs[2 * i], y = pairs[2 * i + 1];
    if (!(x > m->ra[i]) || !(y > m->rb[i]) || !(x < 1) || !(y < 1) ||
        !isfinite(x) || !isfinite(y))
      return km__fail(err, KM_EMATCH, KM_FIELD_MATCHES, (long)i, NAN,
                      "match %zu must lie strictly inside (0, 1) and strictly "
                      "after the previous match on both curves",
                      i);
    m->ra[i + 1] = x;
    m->rb[i + 1] = y;
  }
  m->ra[nm + 1] = m->rb[nm + 1] = 1.0;
  m->nk = nm + 2;
  m->nuser = nm;
  return KM_OK;
}

km_status km__morph_variant(const km_morph *base, double dshift,
                            bool auto_matches, double tol, km__poll *poll,
                            km_morph **out, km_error *err) {
  km_morph *m = morph_new(poll);
  if (!m) return km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
  m->opt = base->opt;
  m->tol = tol > 0 ? tol : base->tol;
  m->closed = base->closed;
  m->kmax = base->kmax;
  km_morph_options corr = base->opt;
  corr.matches = NULL;
  corr.nmatches = 0;
  corr.auto_matches = auto_matches;
  km_status st = km__input_copy(&m->in[0], &base->in[0], err);
  if (!st) st = km__input_copy(&m->in[1], &base->in[1], err);
  if (!st && dshift > 0)
    st = km__input_rotate_start(&m->in[1], dshift * m->in[1].sig.length, poll,
                                err);
  if (!st) st = set_correspondence(m, &corr, err);
  if (!st) st = plan_frames(m, err);
  if (st) {
    km_morph_free(m);
    return st;
  }
  *out = m;
  return KM_OK;
}

/* The morph of a closed pair without matches with `to` started a further
 * fraction dshift of its length along. */
static km_status morph_shifted(const km_morph *base, double dshift,
                               km__poll *poll, km_morph **out, km_error *err) {
  return km__morph_variant(base, dshift, false, 0.0, poll, out, err);
}

/* The morph with the start of a closed `to` chosen by the alignment cost;
 * the candidates are returned in cand/ncand, best first. */
static km_status create_impl(km_morph **out, const km_morph_input *from,
                             const km_morph_input *to,
                             const km_morph_options *opt, double *cand,
                             size_t *ncand, km__poll *poll, km_error *err) {
  km_morph *m = morph_new(poll);
  if (!m) return km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
  m->opt = *opt;
  m->opt.matches = NULL;
  if (m->opt.degree != 5) m->opt.degree = 3;
  km__input *a = &m->in[0], *b = &m->in[1];
  km_status st = prepare_inputs(m, from, to, err);
  if (!st) st = orient_inputs(m, cand, ncand, err);
  if (!st) st = set_correspondence(m, opt, err);
  if (!st && opt->method == KM_METHOD_LINEAR) {
    st = km__input_ensure_curve(a, 0.1 * m->tol, opt->max_points, poll, err);
    if (!st)
      st = km__input_ensure_curve(b, 0.1 * m->tol, opt->max_points, poll, err);
    if (!st)
      st = km_curve_make_compatible(&a->curve, &b->curve, &m->lin[0],
                                    &m->lin[1], err);
  }
  if (st) goto fail;
  m->kmax = fmax(km_signature_max_abs_kappa(&a->sig),
                 km_signature_max_abs_kappa(&b->sig));
  st = plan_frames(m, err);
  if (st) goto fail;
  *out = m;
  return KM_OK;
fail:
  km_morph_free(m);
  return st;
}

/* Self-crossings of five frames (t = 1/6 .. 5/6), counted until they
 * reach cap: a candidate that has as many as the best one so far loses. */
static km_status frame_impl(const km_morph *m, double t, km__poll *poll,
                            km_curve *out, km_frame_metrics *metrics,
                            km_signature *sig_out, km_error *err);

/* The crossings into *count, or KM_ENOMEM / KM_ECANCELLED: a preview that
 * could not be made must fail the morph, not make another start win. */
static km_status preview_crossings(const km_morph *m, long cap, long *count) {
  long total = 0;
  static const double T[5] = {3 / 6.0, 2 / 6.0, 4 / 6.0, 1 / 6.0, 5 / 6.0};
  for (int k = 0; k < 5 && total < cap; k++) {
    km_curve c;
    km_status st = frame_impl(m, T[k], m->poll, &c, NULL, NULL, NULL);
    if (st == KM_ENOMEM || st == KM_ECANCELLED) return st;
    if (st != KM_OK) {
      total = LONG_MAX; /* a frame that cannot be built loses */
      break;
    }
    long x = km__self_intersections(&c, m->tol, m->poll);
    km_curve_free(&c);
    if (x < 0) return m->poll && m->poll->stopped ? KM_ECANCELLED : KM_ENOMEM;
    total += x;
  }
  *count = total;
  return KM_OK;
}

/* Among starts that align about as well, prefer one whose frames do not
 * cross themselves: the first candidate, in order of alignment, none of
 * whose five preview frames crosses (each stops at its first crossing);
 * failing that the one with the fewest crossings, the better aligned
 * among equals. Only planned morphs preview (the default: turning blend,
 * cubic output): a frame of any other costs a blend and a reconstruction,
 * twenty of them more than the whole morph. *m is replaced by the morph
 * kept (m or one made from it) and the others are freed; on failure
 * (KM_ENOMEM, KM_ECANCELLED) every one is freed and *m is NULL. */
static km_status pick_start(km_morph **mp, const double *cand, size_t ncand,
                            km__poll *poll) {
  km_morph *alts[KM__SHIFT_CANDIDATES] = {*mp};
  size_t n = 1, pick = SIZE_MAX;
  long x = 0;
  km_status st = preview_crossings(alts[0], 1, &x);
  if (st == KM_OK && x == 0) pick = 0;
  for (size_t i = 1; st == KM_OK && i < ncand && pick == SIZE_MAX; i++) {
    km_morph *alt = NULL;
    double d = cand[i] - cand[0];
    km_status sst =
        morph_shifted(alts[0], d < 0 ? d + 1.0 : d, poll, &alt, NULL);
    if (sst == KM_ENOMEM || sst == KM_ECANCELLED) {
      st = sst;
      break;
    }
    if (sst != KM_OK) continue;
    alts[n++] = alt;
    st = preview_crossings(alt, 1, &x);
    if (st == KM_OK && x == 0) pick = n - 1;
  }
  if (st == KM_OK && pick == SIZE_MAX) {
    long best = LONG_MAX;
    for (size_t k = 0; k < n && st == KM_OK; k++) {
      st = preview_crossings(alts[k], best, &x);
      if (st == KM_OK && (x < best || pick == SIZE_MAX)) {
        best = x;
        pick = k;
      }
    }
  }
  for (size_t k = 0; k < n; k++)
    if (st != KM_OK || k != pick) km_morph_free(alts[k]);
  *mp = st == KM_OK ? alts[pick] : NULL;
  return st;
}

km_status km_morph_create(km_morph **out, const km_morph_input *from,
                          const km_morph_input *to, const km_morph_options *opt,
                          km_error *err) {
  return km__morph_create_repair(out, from, to, opt, KM__REPAIR_DEFAULT, err);
}

km_status km__morph_create_repair(km_morph **out, const km_morph_input *from,
                                  const km_morph_input *to,
                                  const km_morph_options *opt,
                                  km__repair_method repair, km_error *err) {
  double cand[KM__SHIFT_CANDIDATES];
  size_t ncand = 0;
  km_morph *m = NULL;
  km__poll poll;
  km__poll_init(&poll, opt->stop);
  km_status st = create_impl(&m, from, to, opt, cand, &ncand, &poll, err);
  if (st == KM_ECANCELLED || (st && poll.stopped)) return km__stopped(err);
  if (st) return st;
  if (ncand > 1 && opt->method == KM_METHOD_CURVATURE && m->plan)
    st = pick_start(&m, cand, ncand, &poll);
  if (poll.stopped || st == KM_ECANCELLED) {
    km_morph_free(m);
    return km__stopped(err);
  }
  if (!st && opt->intersections == KM_INTERSECTIONS_AVOID &&
      opt->method == KM_METHOD_CURVATURE) {
    st = km__avoid_crossings(&m, &poll);
    /* an input that crosses itself is not repaired: its frames must
     * cross near it */
    if (!st && repair != KM__REPAIR_OFF && m->avoid.input_crossings[0] == 0 &&
        m->avoid.input_crossings[1] == 0) {
      st = km__repair_crossings(m, repair, &poll);
      if (st) { /* the avoidance frees its morphs on failure; so here */
        km_morph_free(m);
        m = NULL;
      }
    }
  }
  if (poll.stopped || st == KM_ECANCELLED) {
    km_morph_free(m);
    return km__stopped(err);
  }
  if (st) return km__fail(err, st, KM_FIELD_NONE, -1, NAN, NULL);
  m->poll = NULL;
  m->opt.stop = NULL;
  *out = m;
  return KM_OK;
}

size_t km_morph_matches_used(const km_morph *m, double *pairs, size_t cap) {
  for (size_t i = 0; i < m->nuser && i < cap && pairs; i++) {
    pairs[2 * i] = m->ra[i + 1];
    pairs[2 * i + 1] = m->rb[i + 1];
  }
  return m->nuser;
}

void km_morph_inputs(const km_morph *m, double length[2], double turning[2]) {
  for (int i = 0; i < 2; i++) {
    length[i] = m->in[i].sig.length;
    turning[i] = m->in[i].sig.turning;
  }
}

/* A frame from the plan: the curve, and how it was closed into *closure
 * (NULL: not wanted) for its metrics. */
static km_status planned_frame(const km_morph *m, double t, km_closure how,
                               km__poll *poll, km_curve *out,
                               km__plan_closure *closure, km_error *err) {
  const km__input *a = &m->in[0], *b = &m->in[1];
  double phia = a->sig.angle, phib = phia + km__wrap_angle(b->sig.angle - phia);
  double rot, T[2];
  size_t nb = km__frame_plan_pieces(m->plan) + 1;
  double *buf = km__malloc(2 * nb * sizeof(double));
  if (!buf) return km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
  double(*P)[2] = (double(*)[2])buf;
  km_curve f;
  km_curve_init(&f);
  /* a frame the crossing repair moves keeps the planned pieces: the
   * repair's displacement lives in arc length, which merged runs leave
   * between their knots */
  bool merge = !m->keep_pieces && !km__repair_active(m->repair, t);
  km_status st = km__frame_plan_curve(m->plan, t, (1 - t) * phia + t * phib,
                                      how == KM_CLOSURE_LSQ, merge, &f, buf,
                                      closure, poll, err);
  if (st) goto done;
  if (m->closed && !f.closed && how != KM_CLOSURE_NONE)
    km__close_polygon(&f, how == KM_CLOSURE_LSQ ? KM_CLOSURE_C0 : how);
  km__place_planned(m, t, (const double(*)[2])P, nb, &rot, T);
  st = km__curve_transform_in_place(&f, rot, T[0], T[1], err);
  if (!st) {
    *out = f;
    km_curve_init(&f);
  }
done:
  km_curve_free(&f);
  km__free(buf);
  return st;
}

km_status km__morph_keep_pieces(km_morph *m, km_error *err) {
  m->keep_pieces = true;
  if (!m->plan) return KM_OK;
  /* planned again with the pieces' share of unmerged frames: fewer
   * pieces, the same frames within the tolerance */
  km__frame_plan_free(m->plan);
  m->plan = NULL;
  km__free(m->place_ab);
  m->place_ab = NULL;
  return plan_frames(m, err);
}

km_status km__morph_frame(const km_morph *m, double t, km__poll *poll,
                          km_curve *out, km_error *err) {
  return frame_impl(m, t, poll, out, NULL, NULL, err);
}

static km_status frame_signature(const km_morph *m, double t, const km_pp *dk,
                                 km__poll *poll, km_signature *out, double *gap,
                                 km_error *err);
static km_status frame_base(const km_morph *m, double t, const km_pp *dk,
                            km__poll *poll, km_curve *out,
                            km_frame_metrics *metrics, km_signature *sig_out,
                            km_error *err);

km_status km__morph_frame_kappa(const km_morph *m, double t, const km_pp *dk,
                                km__poll *poll, km_curve *out, km_error *err) {
  return frame_base(m, t, dk, poll, out, NULL, NULL, err);
}

km_status km__morph_signature_kappa(const km_morph *m, double t,
                                    const km_pp *dk, km__poll *poll,
                                    km_signature *out, km_error *err) {
  return frame_signature(m, t, dk, poll, out, NULL, err);
}

void km_morph_avoided(const km_morph *m, km_morph_avoidance *out) {
  *out = m->avoid;
}

km_status km_morph_frame(const km_morph *m, double t, km_curve *out,
                         km_frame_metrics *metrics, km_signature *sig_out,
                         km_error *err) {
  return frame_impl(m, t, NULL, out, metrics, sig_out, err);
}

km_status km_morph_frame_until(const km_morph *m, double t, const km_stop *stop,
                               km_curve *out, km_frame_metrics *metrics,
                               km_signature *sig_out, km_error *err) {
  km__poll poll;
  km__poll_init(&poll, stop);
  return frame_impl(m, t, &poll, out, metrics, sig_out, err);
}

/* Frame t's exact signature, the blend and the closure of the general
 * path (lsq when the morph closes so), into *out (the caller frees it);
 * gap (if not NULL) receives the gap before closure (0 when open). dk
 * (NULL: none) is a change of curvature added to the blend before the
 * closure (the curvature repair, km__repair_kappa). */
static km_status frame_signature(const km_morph *m, double t, const km_pp *dk,
                                 km__poll *poll, km_signature *out, double *gap,
                                 km_error *err) {
  km_closure how =
      m->opt.closure == KM_CLOSURE_AUTO ? KM_CLOSURE_LSQ : m->opt.closure;
  km_signature blended;
  km_signature_init(&blended);
  double g = 0.0;
  km_status st = km__blend_signature(m, t, &blended, err);
  if (!st && dk) {
    km_signature sum;
    km_signature_init(&sum);
    st = km__add_kappa(&blended, dk, &sum, err);
    km_signature_free(&blended);
    blended = sum;
  }
  /* the blend is linear in the pieces: a few units each */
  if (!st && km__poll_stop(poll, 4 * (long)blended.kappa.n))
    st = km__stopped(err);
  if (!st && m->closed && how == KM_CLOSURE_LSQ) {
    /* the closure measures the gap itself (its first residual) */
    st = km__close_within_bound(m, &blended, out, &g, poll, err);
  } else if (!st) {
    double end[2];
    if (m->closed && gap)
      st = km_signature_point(&blended, blended.length, end, NULL);
    if (!st && m->closed && gap)
      g = hypot(end[0] - blended.start[0], end[1] - blended.start[1]);
    if (!st) {
      *out = blended;
      km_signature_init(&blended);
    }
  }
  if (!st && gap) *gap = g;
  km_signature_free(&blended);
  return st;
}

/* The metrics measured on the returned curve (its crossings) and the
 * gap before closure. */
static km_status curve_metrics(const km_morph *m, const km_curve *placed,
                               double gap, km__poll *poll,
                               km_frame_metrics *metrics, km_error *err) {
  metrics->self_intersections = km__self_intersections(placed, m->tol, poll);
  metrics->closure_gap = m->closed ? gap : 0.0;
  if (poll && poll->stopped) return km__stopped(err);
  /* -1 for a valid curve that was not stopped: no memory */
  if (metrics->self_intersections < 0)
    return km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
  return KM_OK;
}

/* Metrics of the exact frame sig, its placed curve and its gap. */
static km_status exact_metrics(const km_morph *m, const km_signature *sig,
                               const km_curve *placed, double gap,
                               km__poll *poll, km_frame_metrics *metrics,
                               km_error *err) {
  metrics->length = sig->length;
  metrics->max_abs_kappa = km_signature_max_abs_kappa(sig);
  metrics->bending_energy = km_signature_bending_energy(sig);
  return curve_metrics(m, placed, gap, poll, metrics, err);
}

/* sig moved by the frame's placement (rotation rot about the origin, then
 * T) into *out. */
static km_status placed_signature(const km_signature *sig, double rot,
                                  const double T[2], km_signature *out,
                                  km_error *err) {
  double cr = cos(rot), sr = sin(rot);
  double start[2] = {cr * sig->start[0] - sr * sig->start[1] + T[0],
                     sr * sig->start[0] + cr * sig->start[1] + T[1]};
  return km_signature_create(out, sig->length, start, sig->angle + rot,
                             &sig->kappa, sig->corners, sig->ncorners,
                             sig->closed, err);
}

/* How closely a planned frame's max |kappa| is found: far below the
 * tolerance the frame itself is within. square_to_circle's frames have
 * eight equal maxima: refined by halving until the hull met them, to
 * 1e-13 that was a third of a frame with metrics (where |kappa| is
 * concave a Newton step now ends the search to rounding). */
#define MAX_KAPPA_REL 1e-9

/* The planned frame with the metrics of the signature it is built from:
 * the blend closed by the frame's own closure correction (the basis and
 * metric of the general path's lsq closure, its coefficients those the
 * planned frame found) gives length, curvature, energy and gap exactly,
 * and the crossings are counted on the returned curve, which is within
 * the tolerance of it. Neither the exact frame's reconstruction nor a
 * second closure solve is needed: a frame with metrics costs a weighted
 * sum over the curvature tabled once per morph (morph_kappa.c: no blend
 * of pieces, no signature), one pass for the gap and the crossing count
 * beyond the planned frame, and has the same curve as without. A frame closed by turning its corners, and an open one,
 * have the blend's smooth curvature and length. */
static km_status planned_frame_with_metrics(const km_morph *m, double t,
                                            km_closure how, km__poll *poll,
                                            km_curve *out,
                                            km_frame_metrics *metrics,
                                            km_error *err) {
  km_curve f;
  km_curve_init(&f);
  km_status st = KM_OK;
  bool lsq = m->closed && how == KM_CLOSURE_LSQ;
  if (lsq || !m->closed) {
    /* zero: a frame that failed before its closure leaves it so */
    km__plan_closure cl;
    memset(&cl, 0, sizeof cl);
    st = planned_frame(m, t, how, poll, &f, lsq ? &cl : NULL, err);
    /* the curvature the frame is built from, tabled once per morph;
     * turning the corners leaves the blend's smooth curvature */
    double La = m->in[0].sig.length, Lb = m->in[1].sig.length;
    bool psi = lsq && !cl.by_corners;
    if (!st && km__kappa_table_metrics(
                   m->frame_kappa, t, La, Lb, psi ? cl.c : NULL, MAX_KAPPA_REL,
                   &metrics->max_abs_kappa, &metrics->bending_energy))
      st = km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
    if (!st) {
      metrics->length = (1 - t) * La + t * Lb;
      st = curve_metrics(m, &f, lsq ? cl.gap0 : 0.0, poll, metrics, err);
    }
  } else {
    /* the other closures: the general path's signature and gap */
    km_signature sig;
    km_signature_init(&sig);
    double gap = 0.0;
    st = frame_signature(m, t, NULL, poll, &sig, &gap, err);
    if (!st) st = planned_frame(m, t, how, poll, &f, NULL, err);
    if (!st) st = exact_metrics(m, &sig, &f, gap, poll, metrics, err);
    km_signature_free(&sig);
  }
  if (!st) {
    *out = f;
    km_curve_init(&f);
  }
  km_curve_free(&f);
  return st;
}

/* The frame at t; dk (NULL: none) as in frame_signature, which takes the
 * general path. */
static km_status frame_base(const km_morph *m, double t, const km_pp *dk,
                            km__poll *poll, km_curve *out,
                            km_frame_metrics *metrics, km_signature *sig_out,
                            km_error *err) {
  if (!(t >= 0.0 && t <= 1.0))
    return km__fail(err, KM_ERANGE, KM_FIELD_TIMES, -1, t,
                    "time %g is outside [0, 1]", t);
  if (m->opt.method == KM_METHOD_LINEAR)
    return km__linear_frame(m, t, out, metrics, sig_out, poll, err);
  km_closure how =
      m->opt.closure == KM_CLOSURE_AUTO ? KM_CLOSURE_LSQ : m->opt.closure;
  if (m->plan && !sig_out && !dk)
    return metrics
               ? planned_frame_with_metrics(m, t, how, poll, out, metrics, err)
               : planned_frame(m, t, how, poll, out, NULL, err);
  km_signature sig;
  km_signature_init(&sig);
  km_curve f, placed;
  km_curve_init(&f);
  km_curve_init(&placed);
  double gap = 0.0, bound = 0.0, rot, T[2];
  km_status st = frame_signature(m, t, dk, poll, &sig, &gap, err);
  if (!st)
    st = km__reconstruct(&sig, m->opt.degree, 0.9 * m->tol, m->opt.max_points,
                         poll, &f, &bound, NULL, err);
  if (st) goto done;
  if (m->closed && !f.closed && how != KM_CLOSURE_NONE && how != KM_CLOSURE_LSQ)
    km__close_polygon(&f, how);
  else if (m->closed && !f.closed && how == KM_CLOSURE_LSQ)
    km__close_polygon(&f, KM_CLOSURE_C0); /* residual below rounding */
  if (km__place_frame(m, t, &f, sig.length, &rot, T)) {
    st = km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
    goto done;
  }
  st = km_curve_transform(&placed, &f, rot, T[0], T[1], err);
  if (st) goto done;
  placed.closed = f.closed;
  if (metrics) st = exact_metrics(m, &sig, &placed, gap, poll, metrics, err);
  if (!st && sig_out) st = placed_signature(&sig, rot, T, sig_out, err);
  if (st) goto done;
  *out = placed;
  km_curve_init(&placed);
done:
  km_signature_free(&sig);
  km_curve_free(&f);
  km_curve_free(&placed);
  return st;
}

/* The metrics and signature of a repaired frame f, measured on f (the
 * blend describes the frame before the repair). The closure gap is the
 * blend's: the repair moves neither end. */
static km_status repaired_metrics(const km_morph *m, const km_curve *f,
                                  km__poll *poll, km_frame_metrics *metrics,
                                  km_signature *sig_out, km_error *err) {
  km_signature sig;
  km_signature_init(&sig);
  km_status st = km__signature_compute(f, m->tol, 1e-5, poll, &sig, err);
  if (!st && metrics) {
    metrics->length = sig.length;
    metrics->max_abs_kappa = km_signature_max_abs_kappa(&sig);
    metrics->bending_energy = km_signature_bending_energy(&sig);
    metrics->self_intersections = km__self_intersections(f, m->tol, poll);
    if (poll && poll->stopped) st = km__stopped(err);
    if (!st && metrics->self_intersections < 0)
      st = km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
  }
  if (!st && sig_out) {
    km_signature_free(sig_out);
    *sig_out = sig;
    km_signature_init(&sig);
  }
  km_signature_free(&sig);
  return st;
}

static km_status frame_impl(const km_morph *m, double t, km__poll *poll,
                            km_curve *out, km_frame_metrics *metrics,
                            km_signature *sig_out, km_error *err) {
  /* the curvature repair: the frame of the changed curvature, closed and
   * measured as any frame of the general path */
  km_pp dk;
  km__pp_init(&dk);
  km_status st = km__repair_kappa_active(m->repair, t)
                     ? km__repair_kappa(m->repair, t, (size_t)-1, &dk)
                     : KM_OK;
  if (st) return km__fail(err, st, KM_FIELD_NONE, -1, NAN, NULL);
  st = frame_base(m, t, dk.m ? &dk : NULL, poll, out, metrics, sig_out, err);
  km__pp_free(&dk);
  if (st || !km__repair_displaces(m->repair, t)) return st;
  double moved;
  st = km__repair_apply(m->repair, t, out, &moved, err);
  if (!st && (metrics || sig_out))
    st = repaired_metrics(m, out, poll, metrics, sig_out, err);
  if (st) {
    km_curve_free(out);
    if (sig_out) km_signature_free(sig_out);
  }
  return st;
}

km_status km_morph_frame_points(const km_morph *m, double t,
                                km_frame_parts parts, const km_stop *stop,
                                size_t *points, km_error *err) {
  if (!(t >= 0.0 && t <= 1.0))
    return km__fail(err, KM_ERANGE, KM_FIELD_TIMES, -1, t,
                    "time %g is outside [0, 1]", t);
  if (m->opt.method == KM_METHOD_LINEAR) {
    *points = m->lin[0].n;
    return KM_OK;
  }
  bool kappa = km__repair_kappa_active(m->repair, t);
  size_t extra = km__repair_extra_points(m->repair, t);
  km__poll poll;
  km__poll_init(&poll, stop);
  if (m->plan && parts != KM_FRAME_WITH_SIGNATURE && !kappa) {
    /* the count of the frame itself: each merges runs of the plan's
     * pieces as it can */
    km_closure how =
        m->opt.closure == KM_CLOSURE_AUTO ? KM_CLOSURE_LSQ : m->opt.closure;
    km_curve f;
    km_curve_init(&f);
    km_status st = planned_frame(m, t, how, &poll, &f, NULL, err);
    if (!st) *points = f.n + extra;
    km_curve_free(&f);
    return st;
  }
  km_signature sig;
  km_signature_init(&sig);
  size_t n = 0;
  km_pp dk;
  km__pp_init(&dk);
  km_status st =
      kappa ? km__repair_kappa(m->repair, t, (size_t)-1, &dk) : KM_OK;
  if (st) return km__fail(err, st, KM_FIELD_NONE, -1, NAN, NULL);
  st = frame_signature(m, t, dk.m ? &dk : NULL, &poll, &sig, NULL, err);
  km__pp_free(&dk);
  if (!st)
    st = km__reconstruct(&sig, m->opt.degree, 0.9 * m->tol, m->opt.max_points,
                         &poll, NULL, NULL, &n, err);
  km_signature_free(&sig);
  if (!st) *points = n + extra;
  return st;
}
