/* shape_morph.c - the compound morph: a km_morph per pair of contours,
 * vanishing and appearing contours through circles scaled to a point, and
 * the frames with their nesting kept and measured.
 *
 * DESIGN: the turning blend theta_t(r) = (1-t) theta_a(r) + t theta_b(r)
 * does not involve the lengths, so the shape of a frame between a contour
 * and a circle is the same whatever the circle's size; only the length
 * (1-t) L_a + t L_b changes. The curvature morph to an infinitesimal
 * circle is therefore the morph to the circle of the contour's own length,
 * its frames scaled by (1-t) about their centroids: the length falls
 * linearly to 0 and nothing pops. Placement: paired contours keep the
 * engine's fit onto their pair's linear blend; an unpaired one is moved
 * on the straight line between its centroid and its point, the linear
 * blend of a contour and a point. A contour that then leaves its parent
 * is translated toward the parent's centroid by the smallest fraction
 * that puts it back.
 */
#include <math.h>
#include <string.h>

#include "km/alloc.h"
#include "km/shape.h"
#include "kernels.h"
#include "morph_internal.h"
#include "shape_internal.h"
#include "status_internal.h"

void km_shape_morph_options_default(km_shape_morph_options *o) {
  memset(o, 0, sizeof *o);
  km_morph_options_default(&o->morph);
  km_shape_pair_costs_default(&o->costs);
}

void km_shape_morph_free(km_shape_morph *m) {
  if (!m) return;
  for (size_t k = 0; m->morphs && k < m->npairs; k++)
    km_morph_free(m->morphs[k]);
  km__free(m->morphs);
  km__free(m->pairs);
  km__free(m->kind);
  km__free(m->centre);
  km__free(m->point);
  km__free(m->parent_from);
  km__free(m->parent_to);
  km__free(m->anchor);
  km__free(m->ref);
  km__free(m->has_ref);
  km__free(m->sched);
  km__free(m->fix);
  km__free(m->fixed);
  km__free(m);
}

size_t km_shape_morph_pairs(const km_shape_morph *m, km_shape_pair *pairs,
                            size_t cap) {
  for (size_t k = 0; pairs && k < cap && k < m->npairs; k++)
    pairs[k] = m->pairs[k];
  return m->npairs;
}

/* The circle of length len about c, counter-clockwise when ccw: the
 * rational quadratic 9-point NURBS, exact. */
static km_status circle_of(km_curve *out, const double c[2], double len,
                           bool ccw, km_error *err) {
  static const double ux[9] = {1, 1, 0, -1, -1, -1, 0, 1, 1};
  static const double uy[9] = {0, 1, 1, 1, 0, -1, -1, -1, 0};
  static const double kn[12] = {0,   0,    0,    0.25, 0.25, 0.5,
                                0.5, 0.75, 0.75, 1,    1,    1};
  double r = len / (2 * KM_PI), cp[18], w[9];
  for (int i = 0; i < 9; i++) {
    cp[2 * i] = c[0] + r * ux[i];
    cp[2 * i + 1] = c[1] + r * (ccw ? uy[i] : -uy[i]);
    w[i] = (i % 2) ? sqrt(0.5) : 1.0;
  }
  return km_curve_create(out, 2, 9, kn, cp, w, true, err);
}

/* slot of the pair holding contour i on side `from`, -1 if none */
static long slot_of(const km_shape_morph *m, long i, bool from) {
  if (i < 0) return -1;
  for (size_t k = 0; k < m->npairs; k++)
    if ((from ? m->pairs[k].from : m->pairs[k].to) == i) return (long)k;
  return -1;
}

/* The nearest paired top-level contour of s (side `from`) to point c, as a
 * slot; -1 if none. */
static long nearest_host(const km_shape_morph *m, const km_shape *s,
                         const double c[2], bool from) {
  long best = -1;
  double bd = INFINITY;
  for (size_t k = 0; k < m->npairs; k++) {
    if (m->kind[k] != KM__PAIRED) continue;
    long i = from ? m->pairs[k].from : m->pairs[k].to;
    if (s->parent[i] >= 0) continue;
    double d = hypot(s->centroid[2 * i] - c[0], s->centroid[2 * i + 1] - c[1]);
    /* hosts at the same distance (a symmetric shape's) within rounding:
     * the first, whatever the rounding of the centroids */
    if (d < bd * (1.0 - 1e-9)) {
      bd = d;
      best = (long)k;
    }
  }
  return best;
}

/* p itself when inside contour j of o, else the nearest of the points
 * set in from j's flattening (km__poly_interior_point). */
static km_status pull_inside(const km_shape *o, size_t j, double p[2]) {
  if (km_shape_winding(o, j, p) != 0) return KM_OK;
  km__poly_index ix;
  km__poly_index_init(&ix);
  km_status st = km__poly_index_build(&ix, o->flat + 2 * o->flat_off[j],
                                      o->flat_off[j + 1] - o->flat_off[j]);
  double q[2];
  if (st == KM_OK) km__poly_interior_point(&ix, p, q);
  km__poly_index_free(&ix);
  if (st == KM_OK) memcpy(p, q, sizeof q);
  return st;
}

/* Where the unpaired contour of slot k ends (vanishing) or starts. */
static km_status place_point(km_shape_morph *m, size_t k, const km_shape *a,
                             const km_shape *b) {
  bool from = m->kind[k] == KM__VANISH;
  const km_shape *s = from ? a : b, *o = from ? b : a;
  long i = from ? m->pairs[k].from : m->pairs[k].to;
  const double *c = s->centroid + 2 * i;
  double *p = m->point + 2 * k;
  long h = from ? m->parent_from[k] : m->parent_to[k];
  if (h < 0) h = nearest_host(m, s, c, from);
  if (h >= 0 && m->kind[h] != KM__PAIRED) {
    p[0] = m->point[2 * h];
    p[1] = m->point[2 * h + 1];
    return KM_OK;
  }
  if (h < 0) {
    /* nothing paired: the same place in the other shape's box */
    double ws = fmax(s->box[2] - s->box[0], s->box[3] - s->box[1]);
    double wo = fmax(o->box[2] - o->box[0], o->box[3] - o->box[1]);
    p[0] = o->box[0] + (c[0] - s->box[0]) * wo / ws;
    p[1] = o->box[1] + (c[1] - s->box[1]) * wo / ws;
    return KM_OK;
  }
  long hs = from ? m->pairs[h].from : m->pairs[h].to;
  long ho = from ? m->pairs[h].to : m->pairs[h].from;
  double f = sqrt(o->area[ho] / s->area[hs]);
  p[0] = o->centroid[2 * ho] + (c[0] - s->centroid[2 * hs]) * f;
  p[1] = o->centroid[2 * ho + 1] + (c[1] - s->centroid[2 * hs + 1]) * f;
  /* a top-level contour's host is not its parent: under avoid it may be
   * left where the mapping puts it, outside the host's partner */
  if (m->free_top_points && (from ? m->parent_from[k] : m->parent_to[k]) < 0)
    return KM_OK;
  return pull_inside(o, (size_t)ho, p);
}

static km_status morph_pair(km_shape_morph *m, size_t k, const km_shape *a,
                            const km_shape *b, const km_morph_options *mo,
                            km_error *err) {
  long i = m->pairs[k].from, j = m->pairs[k].to;
  km_curve circ;
  km_curve_init(&circ);
  km_status st;
  if (i >= 0 && j >= 0) {
    km_morph_input fi = {&a->contours[i], NULL}, ti = {&b->contours[j], NULL};
    st = km_morph_create(&m->morphs[k], &fi, &ti, mo, err);
  } else {
    const km_shape *s = i >= 0 ? a : b;
    const km_curve *c = &s->contours[i >= 0 ? i : j];
    long ci = i >= 0 ? i : j;
    memcpy(m->centre + 2 * k, s->centroid + 2 * ci, 2 * sizeof(double));
    st = circle_of(&circ, s->centroid + 2 * ci, km_curve_length(c),
                   s->role[ci] == KM_ROLE_OUTER, err);
    km_morph_input ci_in = {&circ, NULL}, c_in = {c, NULL};
    if (st == KM_OK)
      st = km_morph_create(&m->morphs[k], i >= 0 ? &c_in : &ci_in,
                           i >= 0 ? &ci_in : &c_in, mo, err);
  }
  km_curve_free(&circ);
  /* contours keep their frames' planned pieces: the placement, the
   * corrections and the checks between contours sample each contour
   * by its parameter, which merged runs no longer keep in arc length */
  if (st == KM_OK) st = km__morph_keep_pieces(m->morphs[k], err);
  if (st != KM_OK && err && st != KM_ECANCELLED) err->index = (long)k;
  return st;
}

static int slot_depth(const km_shape_morph *m, size_t k) {
  int d = 0;
  for (long p = m->parent_from[k] >= 0 ? m->parent_from[k] : m->parent_to[k];
       p >= 0 && d < 1 << 20;
       p = m->parent_from[p] >= 0 ? m->parent_from[p] : m->parent_to[p])
    d++;
  return d;
}

static km_status morph_alloc(km_shape_morph *m, size_t n) {
  m->morphs = km__calloc(n, sizeof *m->morphs);
  m->kind = km__calloc(n, sizeof *m->kind);
  m->centre = km__calloc(2 * n, sizeof *m->centre);
  m->point = km__calloc(2 * n, sizeof *m->point);
  m->parent_from = km__calloc(n, sizeof *m->parent_from);
  m->parent_to = km__calloc(n, sizeof *m->parent_to);
  m->anchor = km__calloc(4 * n, sizeof *m->anchor);
  m->ref = km__calloc(4 * KM__REF_POINTS * n, sizeof *m->ref);
  m->has_ref = km__calloc(n, sizeof *m->has_ref);
  m->sched = km__calloc((KM__SCHED + 1) * n, sizeof *m->sched);
  return m->morphs && m->kind && m->centre && m->point && m->parent_from &&
                 m->parent_to && m->anchor && m->ref && m->has_ref && m->sched
             ? KM_OK
             : KM_ENOMEM;
}

static km_status take_pairs(km_shape_morph *m, const km_shape *a,
                            const km_shape *b,
                            const km_shape_morph_options *opt,
                            const km_stop *stop, km_error *err) {
  if (!opt->pairs)
    return km_shape_pair_auto(a, b, &opt->costs, stop, &m->pairs, &m->npairs,
                              err);
  km_status st = km_shape_pair_check(a, b, opt->pairs, opt->npairs, err);
  if (st != KM_OK) return st;
  m->pairs = km__malloc(opt->npairs * sizeof *m->pairs);
  if (!m->pairs)
    return km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, "out of memory");
  memcpy(m->pairs, opt->pairs, opt->npairs * sizeof *m->pairs);
  m->npairs = opt->npairs;
  return KM_OK;
}

/* The points of unpaired contours, parents before children (a child's
 * point may be its vanishing parent's). KM_OK or KM_ENOMEM. */
static km_status place_points(km_shape_morph *m, const km_shape *a,
                              const km_shape *b) {
  int maxd = 0;
  for (size_t k = 0; k < m->npairs; k++) {
    int d = slot_depth(m, k);
    if (d > maxd) maxd = d;
  }
  km_status st = KM_OK;
  for (int d = 0; d <= maxd; d++)
    for (size_t k = 0; st == KM_OK && k < m->npairs; k++)
      if (m->kind[k] != KM__PAIRED && slot_depth(m, k) == d)
        st = place_point(m, k, a, b);
  return st;
}

/* Kinds, parent slots and the points of unpaired contours. KM_OK or
 * KM_ENOMEM. */
static km_status plan_slots(km_shape_morph *m, const km_shape *a,
                            const km_shape *b) {
  for (size_t k = 0; k < m->npairs; k++) {
    long i = m->pairs[k].from, j = m->pairs[k].to;
    m->kind[k] = i >= 0 && j >= 0 ? KM__PAIRED
                 : i >= 0         ? KM__VANISH
                                  : KM__APPEAR;
    m->parent_from[k] = i >= 0 ? slot_of(m, a->parent[i], true) : -1;
    m->parent_to[k] = j >= 0 ? slot_of(m, b->parent[j], false) : -1;
  }
  return place_points(m, a, b);
}

/* Anchors of every slot, and the sampled end frames of every paired slot
 * that is some slot's parent. */
static km_status take_refs(km_shape_morph *m, const km_shape *a,
                           const km_shape *b, const km_stop *stop,
                           km_error *err) {
  for (size_t k = 0; k < m->npairs; k++) {
    double *an = m->anchor + 4 * k;
    long i = m->pairs[k].from, j = m->pairs[k].to;
    const double *c0 = i >= 0 ? a->centroid + 2 * i : m->point + 2 * k;
    const double *c1 = j >= 0 ? b->centroid + 2 * j : m->point + 2 * k;
    memcpy(an, c0, 2 * sizeof(double));
    memcpy(an + 2, c1, 2 * sizeof(double));
    long p = m->parent_from[k] >= 0 ? m->parent_from[k] : m->parent_to[k];
    if (p >= 0 && m->kind[p] == KM__PAIRED) m->has_ref[p] = true;
  }
  for (size_t k = 0; k < m->npairs; k++) {
    if (!m->has_ref[k]) continue;
    for (int e = 0; e < 2; e++) {
      km_curve c;
      km_frame_metrics mt;
      km_curve_init(&c);
      km_status st = km_morph_frame_until(m->morphs[k], (double)e, stop, &c,
                                          &mt, NULL, err);
      if (st != KM_OK) {
        if (err && st != KM_ECANCELLED) err->index = (long)k;
        return st;
      }
      km__ref_sample(&c, m->ref + (4 * k + 2 * e) * KM__REF_POINTS);
      km_curve_free(&c);
    }
  }
  return KM_OK;
}

void km__shape_sched_monotone(km_shape_morph *m, size_t k) {
  double *S = m->sched + (KM__SCHED + 1) * k;
  /* each time takes the smaller of its own fit and the next's toward
   * the missing side, so an interval's interpolation stays below the
   * fit at both its ends (and between them where the fit is monotone);
   * the whole end keeps its full size, and the last time before the
   * point its own fit */
  if (m->kind[k] == KM__VANISH) {
    for (int j = 1; j + 1 < KM__SCHED; j++) S[j] = fmin(S[j], S[j + 1]);
    for (int j = 1; j <= KM__SCHED; j++) S[j] = fmin(S[j], S[j - 1]);
  } else if (m->kind[k] == KM__APPEAR) {
    for (int j = KM__SCHED - 1; j > 1; j--) S[j] = fmin(S[j], S[j - 1]);
    for (int j = KM__SCHED - 1; j >= 0; j--) S[j] = fmin(S[j], S[j + 1]);
  }
}

/* The schedule of unpaired contours inside a parent: the scale that fits
 * at each t = j / KM__SCHED, then the running minimum from the side where
 * the contour is whole, so its size only falls toward its missing side
 * (frames between take the linear interpolation). */
static km_status take_schedule(km_shape_morph *m, const km_stop *stop,
                               km_error *err) {
  size_t n = m->npairs;
  bool any = false;
  for (size_t k = 0; k < n; k++)
    any = any || (m->kind[k] != KM__PAIRED &&
                  (m->parent_from[k] >= 0 || m->parent_to[k] >= 0));
  if (!any) return KM_OK;
  double *ratio = km__malloc(n * sizeof *ratio);
  if (!ratio)
    return km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, "out of memory");
  km_status st = KM_OK;
  for (int j = 0; st == KM_OK && j <= KM__SCHED; j++) {
    double t = (double)j / KM__SCHED;
    for (size_t k = 0; k < n; k++) ratio[k] = 1.0;
    if (j > 0 && j < KM__SCHED)
      st = km__shape_frame_ratios(m, t, stop, ratio, err);
    for (size_t k = 0; k < n; k++) {
      double s = m->kind[k] == KM__VANISH   ? 1.0 - t
                 : m->kind[k] == KM__APPEAR ? t
                                            : 1.0;
      m->sched[(KM__SCHED + 1) * k + (size_t)j] = s * ratio[k];
    }
  }
  km__free(ratio);
  if (st != KM_OK) return st;
  for (size_t k = 0; k < n; k++) km__shape_sched_monotone(m, k);
  m->scheduled = true;
  return KM_OK;
}

km_status km__shape_replan(km_shape_morph *m, const km_shape *a,
                           const km_shape *b, const km_stop *stop,
                           km_error *err) {
  km_status st = place_points(m, a, b);
  if (st != KM_OK)
    return km__fail(err, st, KM_FIELD_NONE, -1, NAN, "out of memory");
  st = take_refs(m, a, b, stop, err);
  m->scheduled = false;
  if (st == KM_OK) st = take_schedule(m, stop, err);
  return st;
}

/* One morph of from and to with the pairing of opt (or the automatic
 * one), its choices made under AVOID. */
static km_status morph_once(km_shape_morph **out, const km_shape *from,
                            const km_shape *to,
                            const km_shape_morph_options *opt,
                            const km_stop *stop, km_error *err) {
  km_shape_morph *m = km__calloc(1, sizeof *m);
  if (!m)
    return km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, "out of memory");
  m->preview_fails = -1;
  km_status st = take_pairs(m, from, to, opt, stop, err);
  if (st == KM_OK) {
    st = morph_alloc(m, m->npairs);
    if (st != KM_OK)
      km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, "out of memory");
  }
  if (st != KM_OK) goto cleanup;
  st = plan_slots(m, from, to);
  if (st != KM_OK) {
    km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, "out of memory");
    goto cleanup;
  }
  km_morph_options mo = opt->morph;
  mo.stop = stop;
  for (size_t k = 0; st == KM_OK && k < m->npairs; k++)
    st = morph_pair(m, k, from, to, &mo, err);
  if (st == KM_OK) st = take_refs(m, from, to, stop, err);
  if (st == KM_OK) st = take_schedule(m, stop, err);
  if (st == KM_OK && opt->morph.intersections == KM_INTERSECTIONS_AVOID)
    st = km__shape_avoid(m, from, to, stop, err);
  if (st != KM_OK) goto cleanup;
  *out = m;
  m = NULL;
cleanup:
  km_shape_morph_free(m);
  return st;
}

/* The swap of pairs i and j of base into cand (n pairs), if both are
 * paired and the result is a valid pairing. */
static bool swapped(const km_shape *from, const km_shape *to,
                    const km_shape_pair *base, size_t n, size_t i, size_t j,
                    km_shape_pair *cand) {
  if (base[i].from < 0 || base[i].to < 0 || base[j].from < 0 || base[j].to < 0)
    return false;
  memcpy(cand, base, n * sizeof *cand);
  cand[i].to = base[j].to;
  cand[j].to = base[i].to;
  return km_shape_pair_check(from, to, cand, n, NULL) == KM_OK;
}

/* Failures of m's frames at the previews' times and halfway between them
 * (15 interior frames): what a pairing is judged by. */
static km_status fine_fails(const km_shape_morph *m, const km_stop *stop,
                            long *fails, km_error *err) {
  long between = 0;
  km_status st = km__shape_preview(m, KM__PREVIEWS, true, stop, &between, err);
  *fails = (m->preview_fails > 0 ? m->preview_fails : 0) + between;
  return st;
}

/* Under AVOID with a free pairing: pairings that swap the partners of two
 * pairs (both paired, the swap valid by km_shape_pair_check: same roles,
 * paired parents), in pair order, each a whole morph with its own
 * choices, judged by the failures of 15 interior frames (the 7 previews
 * and the 8 times between them and the ends: a crossing between previews
 * is what the placement left); the first with fewer failures than the
 * best so far replaces it, until one is clean or KM_SHAPE_PAIRINGS_TRIED
 * are tried. Shapes without a valid swap (a glyph's outer contour and its
 * hole) cost nothing more. Two bars of pause into the two of equal, or a
 * dot and a stem into a question mark's body and dot, are paired by
 * position, and their blends pass through each other: the swap keeps them
 * apart. A swap whose pair cannot be morphed is passed over. */
static km_status other_pairings(km_shape_morph **best, const km_shape *from,
                                const km_shape *to,
                                const km_shape_morph_options *opt,
                                const km_stop *stop, km_error *err) {
  size_t n = (*best)->npairs;
  km_shape_pair *cand = km__malloc(2 * (n ? n : 1) * sizeof *cand);
  if (!cand)
    return km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, "out of memory");
  /* swaps of the first pairing, which the best may replace */
  km_shape_pair *base = cand + n;
  memcpy(base, (*best)->pairs, n * sizeof *base);
  bool any = false;
  for (size_t i = 0; i < n && !any; i++)
    for (size_t j = i + 1; j < n && !any; j++)
      any = swapped(from, to, base, n, i, j, cand);
  long best_fails = 0;
  km_status st = any ? fine_fails(*best, stop, &best_fails, err) : KM_OK;
  km_shape_morph_options o = *opt;
  o.pairs = cand;
  o.npairs = n;
  o.pairs_free = false;
  int tried = 0;
  for (size_t i = 0; i < n && st == KM_OK && best_fails > 0; i++)
    for (size_t j = i + 1; j < n && st == KM_OK && best_fails > 0; j++) {
      if (tried >= KM_SHAPE_PAIRINGS_TRIED) break;
      if (!swapped(from, to, base, n, i, j, cand)) continue;
      tried++;
      km_shape_morph *alt = NULL;
      km_error e2;
      st = morph_once(&alt, from, to, &o, stop, &e2);
      long fails = 0;
      if (st == KM_OK) st = fine_fails(alt, stop, &fails, &e2);
      if (st == KM_ECANCELLED || st == KM_ENOMEM) {
        if (err) *err = e2;
        km_shape_morph_free(alt);
        break;
      }
      st = KM_OK; /* a pairing that cannot be morphed is passed over */
      if (alt && fails < best_fails) {
        km_shape_morph_free(*best);
        *best = alt;
        best_fails = fails;
      } else {
        km_shape_morph_free(alt);
      }
    }
  km__free(cand);
  return st;
}

km_status km_shape_morph_create(km_shape_morph **out, const km_shape *from,
                                const km_shape *to,
                                const km_shape_morph_options *opt,
                                const km_stop *stop, km_error *err) {
  km_shape_morph_options def;
  km_shape_morph_options_default(&def);
  if (!opt) opt = &def;
  if (!out || !from || !to || !from->ncontours || !to->ncontours)
    return km__fail(err, KM_EINVAL, KM_FIELD_NONE, -1, NAN, "empty shape");
  km_shape_morph *m = NULL;
  km_status st = morph_once(&m, from, to, opt, stop, err);
  if (st == KM_OK && (opt->pairs == NULL || opt->pairs_free) &&
      opt->morph.intersections == KM_INTERSECTIONS_AVOID)
    st = other_pairings(&m, from, to, opt, stop, err);
  if (st != KM_OK) {
    km_shape_morph_free(m);
    return st;
  }
  *out = m;
  return KM_OK;
}
