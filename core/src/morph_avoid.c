/* morph_avoid.c - intersections "avoid": of the choices a morph is free to
 * make, keep one whose frames do not cross themselves.
 *
 * DESIGN. Curvature blending keeps most frames simple, but where the two
 * sides of a thin stroke pass through each other (a 2 into a 5, a U into
 * an S) the frames of the aligned correspondence cross at the spine. What
 * decides it is the correspondence, and part of it is free: where a closed
 * `to` starts (its seam) and, when the caller asked for automatic matches,
 * which features are matched. A crossing cannot be undone by placement (a
 * rigid motion), so those are the choices tried.
 *
 * The choice made by the alignment (and by the start search of morph.c)
 * is previewed first: PREVIEWS interior frames, t = k / (PREVIEWS + 1),
 * their crossings counted, and when none crosses CONFIRMS more, halfway
 * between them. When none of those crosses it is kept, untouched, so
 * frames that did not cross are the same frames. Otherwise other starts
 * are previewed in order of the alignment cost (km__sector_shifts: the
 * best start in each sector, so that the candidates spread over the whole
 * contour - the local minima of the cost alone are few and mostly cross
 * alike - and the best aligned of those that do not cross is kept, which
 * keeps the morph from spinning a badly matched blob), automatic matches
 * before none at each; the first whose previews do not cross is kept,
 * failing that the one with the fewest crossings (the earlier among
 * equals).
 * A candidate stops counting once it has as many crossings as the best so
 * far. The choice is made once per morph, so every frame comes from one
 * correspondence and the sequence cannot jump between choices.
 *
 * Budget: the inputs' two frames and at most 48 candidates (the first
 * choice; the best aligned start in each of the other SEAMS - 1 sectors of
 * a closed `to`, times two when matches are automatic; no matches at the
 * first start) and the one kept planned again, each at most PREVIEWS +
 * CONFIRMS frames and their crossing counts - at most 2 + 15 * 49 = 737
 * frames, though the confirming frames are built only for a candidate
 * whose previews do not cross, which mostly ends the search. With 16
 * sectors one pair of the glyph fixtures (a C into an S of DejaVu Serif)
 * kept seven crossing frames. A planned frame is a pass over a few
 * hundred nodes, so the search costs some tens of frames' work on glyphs;
 * every preview and plan polls the caller's stop, and the choice kept is
 * planned like any morph, so the answer's size is predicted from it.
 */
#include <limits.h>
#include <math.h>

#include "bspline_internal.h"
#include "internal.h"
#include "km/alloc.h"
#include "morph_internal.h"

/* Interior frames previewed per candidate, and seam positions tried
 * (shifts of j / SEAMS of the length). */
#define PREVIEWS 7
#define CONFIRMS 8
#define SEAMS 24
/* Candidates are planned and previewed at this multiple of the morph's
 * tolerance (a crossing of stroke sides is wider by orders of magnitude),
 * the one kept planned again at the morph's own and previewed again. */
#define COARSER 10.0

/* The crossings of m's frames at the times t[0..n) into *count, counting
 * stopped once cap is reached; *built adds the frames built. A frame that
 * cannot be built counts as LONG_MAX (the candidate loses); KM_ENOMEM and
 * KM_ECANCELLED fail the search rather than let another candidate win. */
static km_status crossings_at(const km_morph *m, const double *t, int n,
                              long cap, km__poll *poll, long *count,
                              size_t *built) {
  long total = 0;
  for (int k = 0; k < n && total < cap; k++) {
    km_curve c;
    km_curve_init(&c);
    km_status st = km__morph_frame(m, t[k], poll, &c, NULL);
    if (st == KM_ENOMEM || st == KM_ECANCELLED) return st;
    (*built)++;
    if (st != KM_OK) {
      total = LONG_MAX;
      break;
    }
    long x = km__self_intersections(&c, m->tol, poll);
    km_curve_free(&c);
    if (x < 0) return poll && poll->stopped ? KM_ECANCELLED : KM_ENOMEM;
    total += x;
  }
  *count = total;
  return KM_OK;
}

/* The crossings of m's PREVIEWS frames, and when those show none, of the
 * CONFIRMS frames between them: a crossing of stroke sides can live
 * between two previews (frames 0.53 to 0.6 of a 2 into a 5 with the
 * previews at 0.5 and 0.625), and a choice kept on seven previews alone
 * would then cross where nobody looked. Only a choice that is about to be
 * kept pays for the second look. */
static km_status preview_crossings(const km_morph *m, long cap, km__poll *poll,
                                   long *count, size_t *built) {
  /* the middle first, then halving the gaps: crossings of thin strokes
   * are widest in the middle, and a candidate that crosses is mostly
   * ruled out by its first preview */
  static const double previews[PREVIEWS] = {4 / 8.0, 2 / 8.0, 6 / 8.0, 1 / 8.0,
                                            3 / 8.0, 5 / 8.0, 7 / 8.0};
  static const double confirms[CONFIRMS] = {7 / 16.0,  9 / 16.0, 5 / 16.0,
                                            11 / 16.0, 3 / 16.0, 13 / 16.0,
                                            1 / 16.0,  15 / 16.0};
  km_status st = crossings_at(m, previews, PREVIEWS, cap, poll, count, built);
  if (st || *count > 0) return st;
  return crossings_at(m, confirms, CONFIRMS, cap, poll, count, built);
}

/* Self-crossings of the frames at t = 0 and 1, the inputs as the morph
 * traces them, into counts. */
static km_status input_crossings(const km_morph *m, km__poll *poll,
                                 long counts[2]) {
  for (int i = 0; i < 2; i++) {
    km_curve c;
    km_curve_init(&c);
    km_status st = km__morph_frame(m, (double)i, poll, &c, NULL);
    if (st == KM_ENOMEM || st == KM_ECANCELLED) return st;
    counts[i] = 0;
    if (st != KM_OK) continue;
    long x = km__self_intersections(&c, m->tol, poll);
    km_curve_free(&c);
    if (x < 0) return poll && poll->stopped ? KM_ECANCELLED : KM_ENOMEM;
    counts[i] = x;
  }
  return KM_OK;
}

/* The choice kept by the search: the start shift and whether matched. */
typedef struct choice {
  double shift;
  bool with_auto;
  long crossings;
} choice;

km_status km__avoid_crossings(km_morph **mp, km__poll *poll) {
  km_morph *base = *mp, *alt = NULL;
  km_morph_avoidance rep = {0};
  long bx = 0;
  km_status st = input_crossings(base, poll, rep.input_crossings);
  if (!st) st = preview_crossings(base, LONG_MAX, poll, &bx, &rep.previews);
  if (st) goto fail;
  rep.crossings_before = rep.crossings_after = bx;
  if (bx == 0) goto done;
  rep.searched = true;
  bool auto_m = base->opt.auto_matches && base->opt.nmatches == 0;
  /* [0] is the morph's own start; km__sector_shifts writes SEAMS - 1
   * starts after it and the own start's cost after those */
  double shift[SEAMS + 1], cost[SEAMS + 1];
  size_t nshift = 0;
  if (base->closed && base->opt.nmatches == 0 &&
      km__sector_shifts(&base->in[0], &base->in[1], SEAMS, shift + 1, cost + 1,
                        &nshift)) {
    st = KM_ENOMEM;
    goto fail;
  }
  shift[0] = 0.0;
  choice best = {0.0, auto_m, bx};
  for (size_t j = 0; j <= nshift && best.crossings > 0; j++) {
    for (int mode = 0; mode < 2 && best.crossings > 0; mode++) {
      bool with_auto = mode == 0 ? auto_m : false;
      if (mode == 1 && !auto_m) break;
      if (j == 0 && with_auto == auto_m) continue; /* the first choice */
      st = km__morph_variant(base, shift[j], with_auto, COARSER * base->tol,
                             poll, &alt, NULL);
      if (st == KM_ENOMEM || st == KM_ECANCELLED) goto fail;
      if (st != KM_OK) continue; /* a choice that cannot be planned */
      long x = 0;
      st = preview_crossings(alt, best.crossings, poll, &x, &rep.previews);
      km_morph_free(alt);
      alt = NULL;
      if (st) goto fail;
      if (x < best.crossings) best = (choice){shift[j], with_auto, x};
    }
  }
  if (best.crossings < bx) {
    /* the choice at the morph's own tolerance, kept if it still crosses
     * less than the first */
    long x = 0;
    st = km__morph_variant(base, best.shift, best.with_auto, 0.0, poll, &alt,
                           NULL);
    if (st == KM_ENOMEM || st == KM_ECANCELLED) goto fail;
    if (!st) st = preview_crossings(alt, bx, poll, &x, &rep.previews);
    if (st == KM_ENOMEM || st == KM_ECANCELLED) goto fail;
    if (!st && x < bx) {
      km_morph_free(base);
      base = alt;
      alt = NULL;
      rep.changed = true;
      rep.crossings_after = x;
    }
    km_morph_free(alt);
    alt = NULL;
  }
done:
  base->avoid = rep;
  *mp = base;
  return KM_OK;
fail:
  km_morph_free(alt);
  km_morph_free(base);
  *mp = NULL;
  return st ? st : KM_ENOMEM;
}
