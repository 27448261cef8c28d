/* morph_repair.c - intersections AVOID, second step: frames that still
 * cross after the choices of morph_avoid.c are repaired by moving the
 * strands that cross apart, by a change that varies smoothly in t: a
 * displacement (the default) or a change of curvature.
 *
 * DESIGN. What is left after the free choices are made is mostly a pinch:
 * two strands of the frame (the two sides of a thin stroke, the arms of a
 * 3 where they meet) come close at some time and overlap a little for a
 * few frames - a lens between two crossings. The crossing is shallow
 * beside the shape, so a small local change separates it; the questions
 * are which change, and how to keep the sequence from popping.
 *
 * Two repairs are implemented and measured on the glyph pairs whose
 * frames still cross (tests/fixtures/avoid/repair.json, 21 pairs, 41
 * frames each, 61 crossing frames without repair; bench/bench_repair.c,
 * figures in bench/RESULTS.md "Crossing repair"); the switch between them
 * is internal (morph_repair.h), km_morph_create uses the default.
 *
 * The default, KM__REPAIR_DISPLACEMENT, displaces the strands
 * themselves: D(r, t) = sum_k
 * c_k(t) N_k(r), uniform cubic B-splines N_k in the frame's normalised
 * parameter r (arc length for planned frames) covering only the two
 * strands, with 2-D coefficients. The frame plus D is again a B-spline
 * (D's knots inserted into the frame, exactly), D vanishes at the ends
 * so a closed frame stays closed, and the positions are linear in c,
 * so the fit needs no frame to be rebuilt: Gauss-Newton on one-sided
 * residuals (each sample of one strand at least h on its side of the
 * other strand) with a small ridge and a second-difference smoothing,
 * a few milliseconds a key time. Measured: 43 frames still cross, 8
 * pairs crossing-free, largest move 0.0047 of the frame's length; but D
 * bends the strands it moves, and the largest |kappa| of a repaired frame
 * reaches 19 times the inputs' (DejaVu Sans Oblique 7 -> DejaVu Serif 2;
 * 12 and 19 in three pairs).
 *
 * KM__REPAIR_CURVATURE is the least change of curvature: bumps of
 * curvature (five uniform cubic B-splines across each strand, each
 * coefficient the turn it adds) added to the blended curvature before
 * the closure, the frame then closed and reconstructed as any frame of
 * the general path, so it stays a curvature morph. The frame is a black
 * box from bumps to closed curve, so the same one-sided residuals are
 * fitted by Gauss-Newton with forward differences, one frame per bump
 * and step. A bump turns everything after it and the closure spreads
 * what that moves over the whole length (the first fit moved the median
 * point of a repaired frame by 0.0073 of the length): each strand's
 * bumps therefore keep their own turn at zero and, as a soft residual,
 * the curve past them where it was. Measured: 46 frames still cross, 10
 * pairs crossing-free (it separates three pinches the displacement
 * cannot: DejaVu Sans m -> Liberation Serif 3, DejaVu Serif m -> DejaVu
 * Sans Bold M, Liberation Serif h -> DejaVu Serif Italic W), largest
 * move 0.0059, the median point of a repaired frame moved up to 0.0028
 * of the length, |kappa| at most 2.2 times the inputs' (below 1 in all
 * but one pair), and about three times the displacement's create time;
 * it loses DejaVu Serif G -> Liberation Serif 5 and G -> y, which the
 * displacement repairs.
 * KM__REPAIR_BOTH tries the curvature on each event and the
 * displacement where that is not kept: 39 frames, 11 pairs, no pair
 * worse than the displacement, but four to six times its create time
 * (395-618 ms against 110-115 ms a morph on a loaded machine; the
 * DejaVu Serif G pairs take seconds). The displacement stays the default because it
 * keeps the fewest crossing frames of the two single methods, is local
 * (a repaired frame is the frame plus D, exactly) and keeps create
 * interactive (milliseconds, not seconds); its cost is the curvature
 * spikes above. BOTH is the better repair where create time allows.
 *
 * Which side is right comes from the frames on either side in time that
 * do not cross (the clean neighbours): a strand on the left of the other
 * there must be on its left in between. When the two neighbours disagree
 * the strands pass through each other between the inputs and no
 * displacement can undo it; that event is left and reported. The
 * clearance h is half the strands' distance at the clean neighbours (at
 * most 0.4% of the frame's size), so the neighbours need no change and
 * the coefficients start from zero there.
 *
 * Smooth in t: the coefficients are fitted at key times (the scan times
 * that cross, halfway points, the clean neighbours with c = 0) and
 * interpolated by monotone cubic Hermite (Fritsch-Carlson) per
 * coefficient, so c(t) is C1, zero outside the event and never overshoots
 * the fitted values. Frames between key times are checked (VERIFY per
 * gap); a frame that still crosses becomes a key time itself, twice at
 * most.
 *
 * What it keeps and relaxes: frames outside the events are untouched
 * (the same frames as without repair); frames 0 and 1 too. A frame
 * repaired by displacement is the curvature frame plus D exactly: its
 * tolerance is the frame's, but its curvature is no longer the blend and
 * may exceed the inputs' bound where D bends the strand; its metrics are
 * measured on the repaired curve. A frame repaired by curvature is the
 * blend plus the bumps, closed: its metrics are the general path's, and
 * the bumps may take its curvature past the inputs' bound. Budget: SCAN - 1 frames and crossing counts for every
 * morph; per event at most MAX_KEYS key frames and VERIFY checks between
 * them, every one polling the caller's stop.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bspline_internal.h"
#include "internal.h"
#include "km/alloc.h"
#include "km/signature.h"
#include "morph_closure.h"
#include "morph_internal.h"

/* Frames scanned for crossings: t = k / SCAN. */
#define SCAN 32
/* Key times per scan step inside an event. */
#define REFINE 2
#define MAX_EVENTS 8
#define MAX_KEYS 48
/* Coefficients (2-D) of one event. */
#define MAX_BASIS 96
#define GN_STEPS 16
/* Samples of a strand per basis spacing. */
#define PER_DR 8
/* Checks between neighbouring key times. */
#define VERIFY 3
/* Extra key times added where a check still crosses, per event. */
#define ROUNDS 1
/* Key times fitted per morph, over all events: the fits are most of the
 * repair's cost (a pinch needs 4-12). */
#define FITS 48
/* Scan steps the clean neighbours may move away from a crossing. */
#define STEP_OUT 3
/* Largest displacement of a repair, as a fraction of the frame's size:
 * past it the change is no longer a repair of a pinch but a new shape. */
#define MAX_MOVE 0.05

typedef struct strands {
  double i0, i1, j0, j1; /* two strands in r, i1 < j0 unless wrapped */
} strands;

/* Curvature repair: bumps of curvature per strand, and the largest. */
#define KB_PER 5
#define MAX_KB (2 * KB_PER)
/* Gauss-Newton steps of a curvature fit (each costs MAX_KB + 1 frames). */
#define KGN_STEPS 8
/* Finite-difference step of a bump's turn, radians. */
#define KEPS 1e-5
/* Largest change of a bump's turn in one step, radians. */
#define KSTEP 0.15
/* Weight of the rest of the frame's move against the clearance. */
#ifndef KLOCAL
#define KLOCAL 1.0
#endif

typedef struct km__repair_event {
  size_t w; /* coefficients per key time: 2 nb, or nk */
  /* curvature bumps (KM__REPAIR_CURVATURE): centres and spacings in r;
   * a bump's coefficient is the turn it adds, radians */
  size_t nk;
  double kc[MAX_KB], kdr[MAX_KB];
  double kmove[MAX_KEYS]; /* largest move of a strand per key time */
  long K;                 /* grid: basis functions centred at k / K */
  long ka[2], kb[2];
  size_t nrange;        /* index ranges [ka, kb] of the functions used */
  size_t nb;            /* functions used */
  strands core;         /* where the crossings were */
  strands pad;          /* where the fit looks */
  int sigma_i, sigma_j; /* the side of I seen from J, and of J from I */
  /* per sample of each strand (fit_make's samples), the side of the
   * other strand it is on in both clean frames (+1 left, -1 right), or 0
   * (it does not face the other strand there, or the frames disagree) */
  signed char *side[2];
  double h;    /* clearance */
  double size; /* of the clean frame before the event */
  size_t nt;
  double t[MAX_KEYS];
  double *c;     /* nt x nb x 2 */
  double *slope; /* nt x nb x 2: the Hermite slopes */
} km__repair_event;

struct km__repair {
  bool closed;     /* the morph's frames are closed */
  long fits_left;  /* FITS: the key times fitted, over every event */
  long kfits_left; /* the same for the curvature fits (their own FITS) */
  size_t n;
  km__repair_event ev[MAX_EVENTS];
  int degree; /* of the frames */
};

/* ---- the basis --------------------------------------------------------- */

static double basis(const km__repair_event *e, long k, double r) {
  return km__bspline3(r * (double)e->K - (double)(k - 2));
}

/* Flattened index of function k, or -1 when it is not used. */
static long coef_index(const km__repair_event *e, long k) {
  long off = 0;
  for (size_t g = 0; g < e->nrange; g++) {
    if (k >= e->ka[g] && k <= e->kb[g]) return off + (k - e->ka[g]);
    off += e->kb[g] - e->ka[g] + 1;
  }
  return -1;
}

/* Up to four (index, value) pairs of the functions nonzero at r. */
static int basis_at(const km__repair_event *e, double r, long idx[4],
                    double val[4]) {
  long k0 = (long)floor(r * (double)e->K) - 1;
  int n = 0;
  for (long k = k0; k < k0 + 4; k++) {
    long q = coef_index(e, k);
    if (q < 0) continue;
    double v = basis(e, k, r);
    if (v <= 0) continue;
    idx[n] = q;
    val[n] = v;
    n++;
  }
  return n;
}

static void displacement_at(const km__repair_event *e, const double *c,
                            double r, double out[2]) {
  long idx[4];
  double val[4];
  int n = basis_at(e, r, idx, val);
  out[0] = out[1] = 0.0;
  for (int i = 0; i < n; i++) {
    out[0] += val[i] * c[2 * idx[i]];
    out[1] += val[i] * c[2 * idx[i] + 1];
  }
}

/* Interior knots of the event's displacement curve. */
static size_t event_knots(const km__repair_event *e) {
  size_t n = 0;
  for (size_t g = 0; g < e->nrange; g++) n += (size_t)(e->kb[g] - e->ka[g] + 5);
  return n;
}

/* The event's displacement with coefficients c as a cubic B-spline on
 * [0, 1] (see the DESIGN: clamped ends, the ranges' uniform knots between,
 * zero coefficients for the functions that are not the event's). */
static km_status displacement_curve(const km__repair_event *e, const double *c,
                                    km_curve *out, km_error *err) {
  size_t nk = event_knots(e) + 8, n = nk - 4;
  double *U = km__malloc(nk * sizeof *U), *P = km__calloc(2 * n, sizeof *P);
  km_status st = KM_ENOMEM;
  if (!U || !P) goto done;
  size_t u = 0, q = 0;
  for (int i = 0; i < 4; i++) U[u++] = 0.0;
  for (size_t g = 0; g < e->nrange; g++) {
    size_t first = u; /* control index of the range's first function */
    for (long k = e->ka[g] - 2; k <= e->kb[g] + 2; k++)
      U[u++] = (double)k / (double)e->K;
    for (long k = e->ka[g]; k <= e->kb[g]; k++, q++) {
      size_t ci = first + (size_t)(k - e->ka[g]);
      P[2 * ci] = c[2 * q];
      P[2 * ci + 1] = c[2 * q + 1];
    }
  }
  for (int i = 0; i < 4; i++) U[u++] = 1.0;
  st = km_curve_create(out, 3, n, U, P, NULL, false, err);
  km__free(U);
  km__free(P);
  return st;
done:
  km__free(U);
  km__free(P);
  return km__fail(err, st, KM_FIELD_NONE, -1, NAN, NULL);
}

/* *f plus the displacement: exactly, by one merged knot vector; f keeps
 * its domain and closed flag. A rational frame is left as it is. */
static km_status add_displacement(km_curve *f, const km__repair_event *e,
                                  const double *c, km_error *err) {
  if (f->w) return KM_OK;
  double u0, u1;
  km_curve_domain(f, &u0, &u1);
  km_curve d, a, b, r;
  km_curve_init(&d);
  km_curve_init(&a);
  km_curve_init(&b);
  km_curve_init(&r);
  km_status st = displacement_curve(e, c, &d, err);
  if (!st) st = km_curve_make_compatible(f, &d, &a, &b, err);
  if (!st) {
    for (size_t i = 0; i < 2 * a.n; i++) a.cp[i] += b.cp[i];
    st = km_curve_reparam(&r, &a, u0, u1, err);
  }
  if (!st) {
    r.closed = f->closed;
    km_curve_free(f);
    *f = r;
    km_curve_init(&r);
  }
  km_curve_free(&d);
  km_curve_free(&a);
  km_curve_free(&b);
  km_curve_free(&r);
  return st;
}

/* ---- coefficients in t ------------------------------------------------- */

/* Fritsch-Carlson slopes of the event's coefficients over its key times. */
static void hermite_slopes(km__repair_event *e) {
  size_t nt = e->nt, w = e->w;
  for (size_t q = 0; q < w; q++) {
    for (size_t k = 0; k < nt; k++) {
      double m = 0.0;
      if (k > 0 && k + 1 < nt) {
        double h0 = e->t[k] - e->t[k - 1], h1 = e->t[k + 1] - e->t[k];
        double d0 = (e->c[k * w + q] - e->c[(k - 1) * w + q]) / h0;
        double d1 = (e->c[(k + 1) * w + q] - e->c[k * w + q]) / h1;
        if (d0 * d1 > 0) {
          double w0 = 2 * h1 + h0, w1 = h1 + 2 * h0;
          m = (w0 + w1) / (w0 / d0 + w1 / d1);
        }
      }
      e->slope[k * w + q] = m; /* zero at the ends: c is zero there */
    }
  }
}

/* The coefficients at t into c (2 nb values); false outside the event. */
static bool coefficients_at(const km__repair_event *e, double t, double *c) {
  size_t nt = e->nt, w = e->w;
  if (nt < 2 || !(t > e->t[0] && t < e->t[nt - 1])) return false;
  size_t k = 0;
  while (k + 2 < nt && t >= e->t[k + 1]) k++;
  double h = e->t[k + 1] - e->t[k], s = (t - e->t[k]) / h;
  double h00 = (1 + 2 * s) * (1 - s) * (1 - s), h10 = s * (1 - s) * (1 - s);
  double h01 = s * s * (3 - 2 * s), h11 = s * s * (s - 1);
  bool any = false;
  for (size_t q = 0; q < w; q++) {
    c[q] = h00 * e->c[k * w + q] + h10 * h * e->slope[k * w + q] +
           h01 * e->c[(k + 1) * w + q] + h11 * h * e->slope[(k + 1) * w + q];
    if (c[q] != 0) any = true;
  }
  return any;
}

/* ---- frames and strands ------------------------------------------------ */

static void point_at_r(const km_curve *f, double r, double out[2]) {
  double u0, u1, d[1][2];
  km_curve_domain(f, &u0, &u1);
  km_curve_eval(f, u0 + r * (u1 - u0), 0, d);
  out[0] = d[0][0];
  out[1] = d[0][1];
}

static double frame_size(const km_curve *f) {
  double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
  for (size_t i = 0; i < f->n; i++) {
    x0 = fmin(x0, f->cp[2 * i]);
    x1 = fmax(x1, f->cp[2 * i]);
    y0 = fmin(y0, f->cp[2 * i + 1]);
    y1 = fmax(y1, f->cp[2 * i + 1]);
  }
  return hypot(x1 - x0, y1 - y0);
}

/* A strand sampled: parameters and positions (the frame's, without D). */
typedef struct strand {
  size_t n;
  double *r;
  double (*x)[2];
} strand;

static void strand_free(strand *s) {
  km__free(s->r);
  km__free(s->x);
  memset(s, 0, sizeof *s);
}

static km_status strand_sample(strand *s, const km_curve *f, double r0,
                               double r1, long K) {
  size_t n = (size_t)ceil((r1 - r0) * (double)K * PER_DR) + 1;
  if (n < 8) n = 8;
  s->r = km__malloc(n * sizeof *s->r);
  s->x = km__malloc(n * sizeof *s->x);
  if (!s->r || !s->x) return KM_ENOMEM;
  s->n = n;
  for (size_t i = 0; i < n; i++) {
    double r = r0 + (r1 - r0) * (double)i / (double)(n - 1);
    if (r < 0) r += 1.0;
    if (r > 1) r -= 1.0;
    s->r[i] = r;
    point_at_r(f, r, s->x[i]);
  }
  return KM_OK;
}

/* The largest of three numbers (comparisons: no call). */
static inline double fmax3(double a, double b, double c) {
  double m = a > b ? a : b;
  return m > c ? m : c;
}

/* Squared distance from p to segment k of y and its fraction *lam. */
static inline double seg_dist2(const double (*y)[2], size_t k,
                               const double p[2], double *lam) {
  double ex = y[k + 1][0] - y[k][0], ey = y[k + 1][1] - y[k][1];
  double ee = ex * ex + ey * ey;
  double l =
      ee > 0 ? ((p[0] - y[k][0]) * ex + (p[1] - y[k][1]) * ey) / ee : 0.0;
  l = fmin(1.0, fmax(0.0, l));
  double qx = y[k][0] + l * ex - p[0], qy = y[k][1] + l * ey - p[1];
  *lam = l;
  return qx * qx + qy * qy;
}

/* The nearest point to p on the polyline y[0..n): its segment k and
 * fraction lam (the first segment of the least distance); false when the
 * nearest is an end of the polyline (the other strand does not face p).
 * hint (or n for none) is a segment to try first: the previous sample's,
 * so that the segments whose boxes lie farther than it are passed over
 * without their division (the margin covers the rounding of the
 * distances); the answer is the one of the plain scan. */
static bool project(const double (*y)[2], size_t n, const double p[2],
                    size_t hint, size_t *k_out, double *lam_out,
                    double *dist2) {
  double best = INFINITY;
  size_t bk = 0;
  double bl = 0;
  if (hint + 1 < n) {
    best = seg_dist2(y, hint, p, &bl);
    bk = hint;
  }
  for (size_t k = 0; k + 1 < n; k++) {
    double x0 = y[k][0], x1 = y[k + 1][0], y0 = y[k][1], y1 = y[k + 1][1];
    double bx = x0 < x1 ? fmax3(x0 - p[0], p[0] - x1, 0.0)
                        : fmax3(x1 - p[0], p[0] - x0, 0.0);
    double by = y0 < y1 ? fmax3(y0 - p[1], p[1] - y1, 0.0)
                        : fmax3(y1 - p[1], p[1] - y0, 0.0);
    if (bx * bx + by * by > best * (1 + 1e-9)) continue;
    double lam, d2 = seg_dist2(y, k, p, &lam);
    if (d2 < best || (d2 == best && k < bk)) {
      best = d2;
      bk = k;
      bl = lam;
    }
  }
  *k_out = bk;
  *lam_out = bl;
  *dist2 = best;
  return !((bk == 0 && bl <= 0.0) || (bk + 2 == n && bl >= 1.0));
}

/* Signed distance of p from segment k of y (left of its direction > 0). */
static double side_of(const double (*y)[2], size_t k, double lam,
                      const double p[2], double n_out[2]) {
  double ex = y[k + 1][0] - y[k][0], ey = y[k + 1][1] - y[k][1];
  double len = hypot(ex, ey);
  if (!(len > 0)) {
    n_out[0] = n_out[1] = 0;
    return 0.0;
  }
  n_out[0] = -ey / len;
  n_out[1] = ex / len;
  double qx = y[k][0] + lam * ex, qy = y[k][1] + lam * ey;
  return (p[0] - qx) * n_out[0] + (p[1] - qy) * n_out[1];
}

/* ---- the fit at one time ----------------------------------------------- */

typedef struct fit {
  const km__repair_event *e;
  strand s[2]; /* I and J */
  double size;
} fit;

static void fit_free(fit *f) {
  strand_free(&f->s[0]);
  strand_free(&f->s[1]);
}

static km_status fit_make(fit *ft, const km__repair_event *e,
                          const km_curve *f) {
  memset(ft, 0, sizeof *ft);
  ft->e = e;
  ft->size = frame_size(f);
  km_status st = strand_sample(&ft->s[0], f, e->pad.i0, e->pad.i1, e->K);
  if (!st) st = strand_sample(&ft->s[1], f, e->pad.j0, e->pad.j1, e->K);
  return st;
}

/* Positions of strand s moved by the displacement c into y. */
static void moved(const fit *ft, int s, const double *c, double (*y)[2]) {
  const strand *st = &ft->s[s];
  for (size_t i = 0; i < st->n; i++) {
    double d[2];
    displacement_at(ft->e, c, st->r[i], d);
    y[i][0] = st->x[i][0] + d[0];
    y[i][1] = st->x[i][1] + d[1];
  }
}

/* Which side of the other strand each strand lies on (+1 left, -1 right,
 * 0 when it faces no part of the other) and how far, for the frame
 * without displacement: where the two come closest within the crossing's
 * own stretch (the core) when that faces the other strand, else where
 * they come closest near it (a pinch whose lens is a point), else at the
 * nearest end of the other strand. Only samples near the core count: the
 * padded strands' far ends may face other parts. */
static void sides(const fit *ft, int sigma[2], double sep[2],
                  signed char *per[2]) {
  const km__repair_event *e = ft->e;
  for (int s = 0; s < 2; s++) {
    const strand *a = &ft->s[s], *b = &ft->s[1 - s];
    double lo = s ? e->core.j0 : e->core.i0, hi = s ? e->core.j1 : e->core.i1;
    double p0 = s ? e->pad.j0 : e->pad.i0, p1 = s ? e->pad.j1 : e->pad.i1;
    double wc = fmax(hi - lo, 4.0 / (double)e->K);
    /* best[0]: core, [1]: near it, [2]: near it, facing an end */
    double best[3] = {INFINITY, INFINITY, INFINITY}, bd[3] = {0, 0, 0};
    for (size_t i = 0; i < a->n; i++) {
      double r = p0 + (p1 - p0) * (double)i / (double)(a->n - 1);
      size_t k;
      double lam, d2, n[2];
      bool faces =
          project((const double(*)[2])b->x, b->n, a->x[i], b->n, &k, &lam, &d2);
      double d = side_of((const double(*)[2])b->x, k, lam, a->x[i], n);
      per[s][i] = faces && fabs(d) < 0.05 * ft->size ? (d > 0) - (d < 0) : 0;
      if (r < lo - wc || r > hi + wc) continue;
      int w = !faces ? 2 : (r >= lo && r <= hi) ? 0 : 1;
      for (; w < 3; w++)
        if (fabs(d) < best[w]) {
          best[w] = fabs(d);
          bd[w] = d;
        }
    }
    int w = isfinite(best[0]) ? 0 : isfinite(best[1]) ? 1 : 2;
    sigma[s] = bd[w] > 0 ? 1 : bd[w] < 0 ? -1 : 0;
    sep[s] = best[2];
  }
}

/* Cholesky solve of the n x n SPD system M x = b, in place (x in b). */
static bool cholesky_solve(double *M, double *b, size_t n) {
  for (size_t j = 0; j < n; j++) {
    double s = M[j * n + j];
    for (size_t k = 0; k < j; k++) s -= M[j * n + k] * M[j * n + k];
    if (!(s > 0)) return false;
    double l = sqrt(s);
    M[j * n + j] = l;
    for (size_t i = j + 1; i < n; i++) {
      double v = M[i * n + j];
      for (size_t k = 0; k < j; k++) v -= M[i * n + k] * M[j * n + k];
      M[i * n + j] = v / l;
    }
  }
  for (size_t i = 0; i < n; i++) {
    double v = b[i];
    for (size_t k = 0; k < i; k++) v -= M[i * n + k] * b[k];
    b[i] = v / M[i * n + i];
  }
  for (size_t i = n; i-- > 0;) {
    double v = b[i];
    for (size_t k = i + 1; k < n; k++) v -= M[k * n + i] * b[k];
    b[i] = v / M[i * n + i];
  }
  return true;
}

/* The coefficients c (2 nb, in: the start, out: the fit) that keep every
 * sample of each strand at least h on its side of the other. */
static km_status fit_solve(const fit *ft, double *c, km__poll *poll) {
  const km__repair_event *e = ft->e;
  size_t w = 2 * e->nb,
         nmax = ft->s[0].n > ft->s[1].n ? ft->s[0].n : ft->s[1].n;
  double *M = km__malloc(w * w * sizeof *M), *rhs = km__malloc(w * sizeof *rhs);
  double(*y[2])[2] = {km__malloc(nmax * sizeof *y[0]),
                      km__malloc(nmax * sizeof *y[1])};
  km_status st = KM_ENOMEM;
  if (!M || !rhs || !y[0] || !y[1]) goto done;
  /* residuals farther than reach are other parts of the strands, not the
   * pinch (a U's arms far from its bottom) */
  double reach = 10 * e->h + 0.02 * ft->size;
  st = KM_OK;
  for (int step = 0; step < GN_STEPS; step++) {
    if (km__poll_stop(poll, (long)(ft->s[0].n * ft->s[1].n / 16))) {
      st = KM_ECANCELLED;
      goto done;
    }
    moved(ft, 0, c, y[0]);
    moved(ft, 1, c, y[1]);
    memset(M, 0, w * w * sizeof *M);
    memset(rhs, 0, w * sizeof *rhs);
    double worst = 0.0;
    for (int s = 0; s < 2; s++) {
      const strand *a = &ft->s[s], *b = &ft->s[1 - s];
      int whole = s ? e->sigma_j : e->sigma_i;
      size_t hint = b->n;
      for (size_t i = 0; i < a->n; i++) {
        /* the sample's own side, else its strand's */
        int sigma = e->side[s][i] ? e->side[s][i] : whole;
        if (sigma == 0) continue;
        size_t k;
        double lam, d2, n[2];
        bool faces = project((const double(*)[2])y[1 - s], b->n, y[s][i], hint,
                             &k, &lam, &d2);
        hint = k; /* the next sample's nearest is near this one's */
        if (!faces) continue;
        double d = side_of((const double(*)[2])y[1 - s], k, lam, y[s][i], n);
        double g = sigma * d - e->h;
        if (g >= 0 || fabs(d) > reach) continue;
        worst = fmin(worst, g);
        /* row: d(sigma d)/dc = sigma (N(r_i) - (1-lam) N(r_k) - lam N(r_k+1)) n */
        double row[MAX_BASIS * 2];
        memset(row, 0, w * sizeof *row);
        long idx[4];
        double val[4];
        int m = basis_at(e, a->r[i], idx, val);
        for (int j = 0; j < m; j++) {
          row[2 * idx[j]] += sigma * val[j] * n[0];
          row[2 * idx[j] + 1] += sigma * val[j] * n[1];
        }
        for (int side = 0; side < 2; side++) {
          double f = side ? lam : 1 - lam;
          m = basis_at(e, b->r[k + (size_t)side], idx, val);
          for (int j = 0; j < m; j++) {
            row[2 * idx[j]] -= sigma * f * val[j] * n[0];
            row[2 * idx[j] + 1] -= sigma * f * val[j] * n[1];
          }
        }
        double ac = 0.0;
        for (size_t q = 0; q < w; q++) ac += row[q] * c[q];
        for (size_t p = 0; p < w; p++) {
          if (row[p] == 0) continue;
          rhs[p] += row[p] * (ac - g);
          for (size_t q = 0; q < w; q++) M[p * w + q] += row[p] * row[q];
        }
      }
    }
    if (worst >= -0.02 * e->h) break;
    /* ridge and second differences along each range, per coordinate */
    for (size_t p = 0; p < w; p++) M[p * w + p] += 1e-4;
    size_t off = 0;
    for (size_t g = 0; g < e->nrange; g++) {
      size_t len = (size_t)(e->kb[g] - e->ka[g] + 1);
      for (size_t j = 1; j + 1 < len; j++)
        for (int xy = 0; xy < 2; xy++) {
          size_t q[3] = {2 * (off + j - 1) + (size_t)xy,
                         2 * (off + j) + (size_t)xy,
                         2 * (off + j + 1) + (size_t)xy};
          double a[3] = {1.0, -2.0, 1.0};
          for (int u = 0; u < 3; u++)
            for (int v = 0; v < 3; v++)
              M[q[u] * w + q[v]] += 0.05 * a[u] * a[v];
        }
      off += len;
    }
    if (!cholesky_solve(M, rhs, w)) break;
    /* a trust region: the one-sided residuals and the nearest points
     * change as the strands move, so a step goes at most a little past
     * the deepest violation */
    double big = 0.0, cap = 1.5 * -worst + e->h;
    for (size_t q = 0; q < w; q++) big = fmax(big, fabs(rhs[q] - c[q]));
    double f = big > cap ? cap / big : 1.0;
    for (size_t q = 0; q < w; q++) c[q] += f * (rhs[q] - c[q]);
  }
done:
  km__free(M);
  km__free(rhs);
  km__free(y[0]);
  km__free(y[1]);
  return st;
}

/* ---- events ------------------------------------------------------------ */

/* Crossings of a frame as strands pairs (lenses): hits paired with their
 * nearest partner, a lone hit as a short window either side. */
static size_t lenses_of(const double *hits, long nh, double u0, double u1,
                        strands *out, size_t cap) {
  size_t n = 0;
  bool used[64] = {false};
  if (nh > 64) nh = 64;
  for (long a = 0; a < nh && n < cap; a++) {
    if (used[a]) continue;
    used[a] = true;
    double ra = (hits[2 * a] - u0) / (u1 - u0),
           rb = (hits[2 * a + 1] - u0) / (u1 - u0);
    long best = -1;
    double bd = INFINITY;
    for (long b = 0; b < nh; b++) {
      if (used[b]) continue;
      double sa = (hits[2 * b] - u0) / (u1 - u0),
             sb = (hits[2 * b + 1] - u0) / (u1 - u0);
      double d = fabs(sa - ra) + fabs(sb - rb);
      if (d < bd) {
        bd = d;
        best = b;
      }
    }
    strands s = {ra, ra, rb, rb};
    if (best >= 0 && bd < 0.25) {
      used[best] = true;
      double sa = (hits[2 * best] - u0) / (u1 - u0),
             sb = (hits[2 * best + 1] - u0) / (u1 - u0);
      s.i0 = fmin(ra, sa);
      s.i1 = fmax(ra, sa);
      s.j0 = fmin(rb, sb);
      s.j1 = fmax(rb, sb);
    }
    out[n++] = s;
  }
  return n;
}

static bool overlaps(double a0, double a1, double b0, double b1, double m) {
  return a0 <= b1 + m && b0 <= a1 + m;
}

typedef struct scan_event {
  strands s;
  int first, last; /* scan indices that cross */
} scan_event;

/* The frame at t without repair. */
static km_status frame_at(const km_morph *m, double t, km__poll *poll,
                          km_curve *f) {
  km_curve_init(f);
  return km__morph_frame(m, t, poll, f, NULL);
}

/* Basis grid and ranges of event e from its core strands. */
static bool event_layout(km__repair_event *e, bool closed) {
  double wi = e->core.i1 - e->core.i0, wj = e->core.j1 - e->core.j0;
  double w = fmax(fmax(wi, wj), 1e-3);
  /* four functions across the wider strand, the grid 1/64 to 1/1024 */
  double dr = fmin(fmax(w / 4, 1.0 / 1024), 1.0 / 64);
  e->K = (long)ceil(1.0 / dr);
  /* the strands slide along each other between the clean frames and the
   * crossing: the fit looks a percent of the length beyond the crossing
   * at least */
  double pad = fmax(0.75 * w + 3.0 / (double)e->K, 0.01);
  e->pad.i0 = e->core.i0 - pad;
  e->pad.i1 = e->core.i1 + pad;
  e->pad.j0 = e->core.j0 - pad;
  e->pad.j1 = e->core.j1 + pad;
  /* but the two stay apart along the curve: points next to each other
   * on the curve are not strands facing each other */
  double gap = 0.01;
  if (e->pad.i1 + gap > e->pad.j0) {
    double mid = 0.5 * (e->core.i1 + e->core.j0);
    e->pad.i1 = fmax(e->core.i1, mid - 0.5 * gap);
    e->pad.j0 = fmin(e->core.j0, mid + 0.5 * gap);
  }
  if (closed && e->pad.j1 + gap > e->pad.i0 + 1.0) {
    double mid = 0.5 * (e->core.j1 + e->core.i0 + 1.0);
    e->pad.j1 = fmax(e->core.j1, mid - 0.5 * gap);
    e->pad.i0 = fmin(e->core.i0 + 1.0, mid + 0.5 * gap) - 1.0;
  }
  if (!closed) {
    e->pad.i0 = fmax(e->pad.i0, 0.0);
    e->pad.j1 = fmin(e->pad.j1, 1.0);
  }
  /* functions whose support meets a padded strand, inside (0, 1) */
  long lo[2] = {(long)floor(e->pad.i0 * (double)e->K) - 1,
                (long)floor(e->pad.j0 * (double)e->K) - 1};
  long hi[2] = {(long)ceil(e->pad.i1 * (double)e->K) + 1,
                (long)ceil(e->pad.j1 * (double)e->K) + 1};
  e->nrange = 0;
  for (int g = 0; g < 2; g++) {
    long a = lo[g] < 3 ? 3 : lo[g], b = hi[g] > e->K - 3 ? e->K - 3 : hi[g];
    if (a > b) continue;
    if (e->nrange && a - 2 <= e->kb[e->nrange - 1] + 2) {
      if (b > e->kb[e->nrange - 1]) e->kb[e->nrange - 1] = b;
      continue;
    }
    e->ka[e->nrange] = a;
    e->kb[e->nrange] = b;
    e->nrange++;
  }
  e->nb = 0;
  for (size_t g = 0; g < e->nrange; g++)
    e->nb += (size_t)(e->kb[g] - e->ka[g] + 1);
  return e->nb > 0 && e->nb <= MAX_BASIS;
}

/* Sides of the strands in the clean frame at t, and their distances. */
static km_status sides_at(const km_morph *m, km__repair_event *e, double t,
                          km__poll *poll, int sg[2], double sep[2],
                          signed char *per[2]) {
  km_curve f;
  km_status st = frame_at(m, t, poll, &f);
  if (st) {
    km_curve_free(&f);
    sg[0] = sg[1] = 0;
    return st == KM_ENOMEM || st == KM_ECANCELLED ? st : KM_OK;
  }
  fit ft;
  st = fit_make(&ft, e, &f);
  if (!st && !(e->size > 0)) e->size = ft.size;
  if (!st && !per[0]) {
    per[0] = km__calloc(ft.s[0].n, 1);
    per[1] = km__calloc(ft.s[1].n, 1);
    if (!per[0] || !per[1]) st = KM_ENOMEM;
  }
  if (!st) sides(&ft, sg, sep, per);
  fit_free(&ft);
  km_curve_free(&f);
  return st;
}

/* Sides and clearance from the clean frames before and after the scan
 * times first..last that cross, into *tb and *ta: the neighbours, or
 * farther (up to STEP_OUT scan steps) while the strands there are closer
 * than a quarter of the wanted clearance - a clearance set by a
 * near-touch would leave the repaired frames near-touching too. *ok
 * false when no side is known or the strands pass through each other. */
static km_status event_sides(const km_morph *m, km__repair_event *e, int first,
                             int last, double *tb, double *ta, km__poll *poll,
                             bool *ok) {
  int sg[2][2];
  double sep[2][2];
  signed char *per[2][2] = {{NULL, NULL}, {NULL, NULL}};
  km_status st = KM_OK;
  *ok = false;
  e->size = 0.0;
  for (int k = 0; k < 2; k++) {
    int at = k ? last + 1 : first - 1;
    for (int step = 0;; step++) {
      st = sides_at(m, e, (double)at / SCAN, poll, sg[k], sep[k], per[k]);
      if (st) goto done;
      double near = fmin(sg[k][0] ? sep[k][0] : INFINITY,
                         sg[k][1] ? sep[k][1] : INFINITY);
      bool end = k ? at >= SCAN : at <= 0;
      if (end || step == STEP_OUT || !(near < 0.001 * e->size)) break;
      at += k ? 1 : -1;
    }
    *(k ? ta : tb) = (double)at / SCAN;
  }
  /* a direction counts where both clean frames see the same side (at a
   * sharp corner poking through a strand, the strand's side of the
   * corner is not defined, the corner's side of the strand is) */
  e->sigma_i = sg[0][0] != 0 && sg[0][0] == sg[1][0] ? sg[0][0] : 0;
  e->sigma_j = sg[0][1] != 0 && sg[0][1] == sg[1][1] ? sg[0][1] : 0;
  /* both seen and both reversed: the strands pass through each other */
  if ((e->sigma_i == 0 && e->sigma_j == 0) ||
      (sg[0][0] && sg[1][0] && sg[0][0] != sg[1][0] && sg[0][1] && sg[1][1] &&
       sg[0][1] != sg[1][1]))
    goto done;
  e->h = 0.004 * e->size;
  for (int k = 0; k < 2; k++)
    for (int d = 0; d < 2; d++)
      if (d ? e->sigma_j : e->sigma_i) e->h = fmin(e->h, 0.5 * sep[k][d]);
  e->h = fmax(e->h, 2 * m->tol);
  /* each sample keeps the side both clean frames agree on */
  for (int d = 0; d < 2; d++) {
    size_t n =
        (size_t)ceil(((d ? e->pad.j1 - e->pad.j0 : e->pad.i1 - e->pad.i0)) *
                     (double)e->K * PER_DR) +
        1;
    if (n < 8) n = 8;
    for (size_t i = 0; i < n; i++)
      if (per[0][d][i] != per[1][d][i]) per[0][d][i] = 0;
    e->side[d] = per[0][d];
    per[0][d] = NULL;
  }
  *ok = true;
done:
  for (int k = 0; k < 2; k++)
    for (int d = 0; d < 2; d++) km__free(per[k][d]);
  return st;
}

/* ---- the curvature repair ---------------------------------------------- */

/* Uniform cubic B-spline bump j of e at r (one period when closed). */
static double bump_at(const km__repair_event *e, size_t j, double r,
                      bool closed) {
  double v = 0.0;
  for (int k = closed ? -1 : 0; k <= (closed ? 1 : 0); k++)
    v += km__bspline3((r + k - e->kc[j]) / e->kdr[j] + 2.0);
  return v / e->kdr[j];
}

static int cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

/* The bumps of events ev[0..n) with coefficients a[i] (NULL: none) as
 * cubic pieces over [0, 1]: exact, from four values a piece. */
static km_status bumps_pp(const km__repair_event *const *ev,
                          const double *const *a, size_t n, bool closed,
                          km_pp *out) {
  size_t nb = 2;
  for (size_t i = 0; i < n; i++) nb += 5 * ev[i]->nk;
  double *x = km__malloc(nb * sizeof *x);
  if (!x) return KM_ENOMEM;
  size_t m = 0;
  x[m++] = 0.0;
  x[m++] = 1.0;
  for (size_t i = 0; i < n; i++)
    for (size_t j = 0; j < ev[i]->nk; j++)
      for (int k = 0; k < 5; k++) {
        double r = ev[i]->kc[j] + (k - 2) * ev[i]->kdr[j];
        if (closed) r -= floor(r);
        if (r > 0 && r < 1) x[m++] = r;
      }
  qsort(x, m, sizeof *x, cmp_double);
  size_t u = 1;
  for (size_t i = 1; i < m; i++)
    if (x[i] - x[u - 1] > 1e-12) x[u++] = x[i];
  x[u - 1] = 1.0;
  km_status st = km__pp_alloc(out, 3, u - 1);
  if (st) {
    km__free(x);
    return st;
  }
  for (size_t p = 0; p + 1 < u; p++) {
    double f[4];
    for (int q = 0; q < 4; q++) {
      double r = x[p] + (x[p + 1] - x[p]) * q / 3.0, v = 0.0;
      for (size_t i = 0; i < n; i++)
        for (size_t j = 0; j < ev[i]->nk; j++)
          if (a[i][j] != 0) v += a[i][j] * bump_at(ev[i], j, r, closed);
      f[q] = v;
    }
    /* Bernstein coefficients of the cubic through f at 0, 1/3, 2/3, 1 */
    double A = 27 * f[1] - 8 * f[0] - f[3], B = 27 * f[2] - f[0] - 8 * f[3];
    double *c = out->c + 4 * p;
    c[0] = f[0];
    c[1] = (2 * A - B) / 18;
    c[2] = (2 * B - A) / 18;
    c[3] = f[3];
    out->x[p] = x[p];
  }
  out->x[u - 1] = 1.0;
  km__free(x);
  return KM_OK;
}

km_status km__add_kappa(const km_signature *sig, const km_pp *dk,
                        km_signature *out, km_error *err) {
  km_pp k0, kt;
  km__pp_init(&k0);
  km__pp_init(&kt);
  double L = sig->length;
  km_status st = km__pp_from_fn(&k0, &sig->kappa);
  if (!st) st = km__pp_blend(&kt, &k0, 1.0, dk, 1.0 / L, 0.0, L);
  if (st)
    st = km__fail(err, st, KM_FIELD_NONE, -1, NAN, NULL);
  else
    st = km__signature_with_kappa(sig, &kt, out, err);
  km__pp_free(&k0);
  km__pp_free(&kt);
  return st;
}

/* Whether an event of the kind (curvature: kappa) changes the frame at t. */
static bool kind_active(const km__repair *rp, double t, bool kappa) {
  for (size_t i = 0; rp && i < rp->n; i++) {
    const km__repair_event *e = &rp->ev[i];
    if ((e->nk > 0) == kappa && e->nt >= 2 && t > e->t[0] &&
        t < e->t[e->nt - 1])
      return true;
  }
  return false;
}

bool km__repair_kappa_active(const km__repair *rp, double t) {
  return kind_active(rp, t, true);
}

bool km__repair_displaces(const km__repair *rp, double t) {
  return kind_active(rp, t, false);
}

km_status km__repair_kappa(const km__repair *rp, double t, size_t nev,
                           km_pp *out) {
  const km__repair_event *ev[MAX_EVENTS];
  double buf[MAX_EVENTS][MAX_KB];
  const double *a[MAX_EVENTS];
  size_t n = 0;
  km__pp_init(out);
  for (size_t i = 0; rp && i < rp->n && i < nev; i++) {
    const km__repair_event *e = &rp->ev[i];
    if (e->nk == 0 || !coefficients_at(e, t, buf[n])) continue;
    ev[n] = e;
    a[n] = buf[n];
    n++;
  }
  if (n == 0) return KM_OK;
  return bumps_pp(ev, a, n, rp->closed, out);
}

/* Bumps over the two strands of e: KB_PER across each crossing's stretch
 * widened by half its width and at least 1% of the length each side. */
static void kappa_layout(km__repair_event *e) {
  double c[2][2] = {{e->core.i0, e->core.i1}, {e->core.j0, e->core.j1}};
  e->nk = 0;
  for (int g = 0; g < 2; g++) {
    double w = c[g][1] - c[g][0], mg = fmax(0.5 * w, 0.01);
    double dr = (w + 2 * mg) / (KB_PER - 1);
    for (int j = 0; j < KB_PER; j++) {
      e->kc[e->nk] = c[g][0] - mg + j * dr;
      e->kdr[e->nk] = dr;
      e->nk++;
    }
  }
  e->w = e->nk;
}

/* Positions (not placed) of the closed signature at normalised arc
 * lengths r[0..n) (any order; order[] sorts them), by one walk. */
static km_status sig_points(const km_signature *sig, const double *r,
                            const size_t *order, size_t n, double (*out)[2]) {
  km_pp kp, tp;
  km_status st = km__build_theta(sig, &kp, &tp);
  if (st) return st;
  int dk = kp.degree, dt = tp.degree;
  double x = sig->start[0], y = sig->start[1], L = sig->length;
  size_t i = 0;
  for (size_t q = 0; q < n; q++) {
    double s = fmin(fmax(r[order[q]] * L, 0.0), L);
    /* whole pieces before s */
    while (i + 1 < tp.m && tp.x[i + 1] <= s) {
      double h = tp.x[i + 1] - tp.x[i], kb[1], d[2];
      km__kappa_bounds(kp.c + i * (size_t)(dk + 1), dk, h, 0.0, 1.0, 1, kb);
      km__integrate_exp(tp.c + i * (size_t)(dt + 1), dt, h, 0.0, 1.0, kb[0], d);
      x += d[0];
      y += d[1];
      i++;
    }
    double h = tp.x[i + 1] - tp.x[i], u = h > 0 ? (s - tp.x[i]) / h : 0.0;
    u = fmin(fmax(u, 0.0), 1.0);
    double kb[1], d[2] = {0, 0};
    if (u > 0) {
      km__kappa_bounds(kp.c + i * (size_t)(dk + 1), dk, h, 0.0, u, 1, kb);
      km__integrate_exp(tp.c + i * (size_t)(dt + 1), dt, h, 0.0, u, kb[0], d);
    }
    out[order[q]][0] = x + d[0];
    out[order[q]][1] = y + d[1];
  }
  km__pp_free(&kp);
  km__pp_free(&tp);
  return KM_OK;
}

/* The samples of a curvature fit: both strands' parameters (as
 * strand_sample takes them, so e->side applies), their positions. */
typedef struct kfit {
  const km_morph *m;
  km__repair_event *e;
  double t;
  size_t n[2], nn;
  size_t nall;   /* nn and the ends of each strand's bumps (lo, hi) */
  double *r;     /* nn = n[0] + n[1] parameters */
  size_t *order; /* r sorted */
  double (*y)[2], (*y1)[2], (*y0)[2];
  double *g, *g1; /* residuals per sample (INFINITY: none) */
  double reach;
  km__poll *poll;
} kfit;

static int cmp_by_r(const void *a, const void *b, const double *r) {
  double x = r[*(const size_t *)a], y = r[*(const size_t *)b];
  return (x > y) - (x < y);
}

static void sort_order(size_t *ord, size_t n, const double *r) {
  /* insertion sort: the two strands are each sorted already but for a
   * wrap, so runs are long */
  for (size_t i = 1; i < n; i++) {
    size_t v = ord[i], j = i;
    while (j > 0 && cmp_by_r(&ord[j - 1], &v, r) > 0) {
      ord[j] = ord[j - 1];
      j--;
    }
    ord[j] = v;
  }
}

static void kfit_free(kfit *k) {
  km__free(k->r);
  km__free(k->order);
  km__free(k->y);
  km__free(k->y1);
  km__free(k->y0);
  km__free(k->g);
  km__free(k->g1);
}

/* Positions of the samples of the frame at k->t with bumps a, into y. */
static km_status kfit_eval(kfit *k, const double *a, double (*y)[2]) {
  const km__repair_event *ev[1] = {k->e};
  const double *aa[1] = {a};
  km_pp dk;
  km__pp_init(&dk);
  km_signature sig;
  km_signature_init(&sig);
  km_status st = bumps_pp(ev, aa, 1, k->m->closed, &dk);
  if (!st) st = km__morph_signature_kappa(k->m, k->t, &dk, k->poll, &sig, NULL);
  if (!st) st = sig_points(&sig, k->r, k->order, k->nall, y);
  km__pp_free(&dk);
  km_signature_free(&sig);
  return st;
}

/* One-sided residuals of positions y: per sample, sigma d - h against the
 * other strand, INFINITY where none applies; the worst into *worst. With
 * only (not NULL), just the samples whose only[] is negative (the
 * violated ones, whose derivatives the fit takes): the projections are
 * most of a fit's cost. */
static void kfit_residuals(const kfit *k, double (*y)[2], double *g,
                           const double *only, double *worst) {
  const km__repair_event *e = k->e;
  *worst = 0.0;
  for (int s = 0; s < 2; s++) {
    size_t off = s ? k->n[0] : 0, ooff = s ? 0 : k->n[0];
    int whole = s ? e->sigma_j : e->sigma_i;
    for (size_t i = 0; i < k->n[s]; i++) {
      g[off + i] = INFINITY;
      int sigma = e->side[s][i] ? e->side[s][i] : whole;
      if (sigma == 0 || (only && !(only[off + i] < 0))) continue;
      size_t q;
      double lam, d2, nrm[2];
      const double(*b)[2] = (const double(*)[2])(y + ooff);
      if (!project(b, k->n[1 - s], y[off + i], k->n[1 - s], &q, &lam, &d2))
        continue;
      double d = side_of(b, q, lam, y[off + i], nrm);
      if (fabs(d) > k->reach) continue;
      g[off + i] = sigma * d - e->h;
      *worst = fmin(*worst, g[off + i]);
    }
  }
}

/* The move of each strand's bumps' far end beyond that of its near end
 * (x, y of I, then of J), from the frame without bumps. */
static void local_change(const kfit *k, double (*y)[2], double out[4]) {
  for (int g = 0; g < 2; g++) {
    size_t lo = k->nn + 2 * (size_t)g, hi = lo + 1;
    for (int c = 0; c < 2; c++)
      out[2 * g + c] = (y[hi][c] - k->y0[hi][c]) - (y[lo][c] - k->y0[lo][c]);
  }
}

/* Fits the bumps at key time t into a (nk, warm start in a); *move
 * receives the largest move of a strand sample. */
static km_status kfit_at(const km_morph *m, km__repair_event *e, double t,
                         double *a, double *move, km__poll *poll) {
  kfit k;
  memset(&k, 0, sizeof k);
  k.m = m;
  k.e = e;
  k.t = t;
  k.poll = poll;
  double span[2][2] = {{e->pad.i0, e->pad.i1}, {e->pad.j0, e->pad.j1}};
  for (int s = 0; s < 2; s++) {
    size_t n =
        (size_t)ceil((span[s][1] - span[s][0]) * (double)e->K * PER_DR) + 1;
    k.n[s] = n < 8 ? 8 : n;
  }
  k.nn = k.n[0] + k.n[1];
  k.nall = k.nn + 4;
  size_t nn = k.nn, w = e->nk, na = k.nall;
  k.r = km__malloc(na * sizeof *k.r);
  k.order = km__malloc(na * sizeof *k.order);
  k.y = km__malloc(na * sizeof *k.y);
  k.y1 = km__malloc(na * sizeof *k.y1);
  k.y0 = km__malloc(na * sizeof *k.y0);
  k.g = km__malloc(nn * sizeof *k.g);
  k.g1 = km__malloc(nn * sizeof *k.g1);
  double *J = km__malloc(nn * w * sizeof *J);
  km_status st = KM_ENOMEM;
  if (!k.r || !k.order || !k.y || !k.y1 || !k.y0 || !k.g || !k.g1 || !J)
    goto done;
  for (int s = 0; s < 2; s++)
    for (size_t i = 0; i < k.n[s]; i++) {
      double r = span[s][0] +
                 (span[s][1] - span[s][0]) * (double)i / (double)(k.n[s] - 1);
      if (r < 0) r += 1.0;
      if (r > 1) r -= 1.0;
      k.r[(s ? k.n[0] : 0) + i] = r;
    }
  for (int g = 0; g < 2; g++)
    for (int side = 0; side < 2; side++) {
      size_t j = (size_t)g * KB_PER + (side ? KB_PER - 1 : 0);
      double r = e->kc[j] + (side ? 2 : -2) * e->kdr[j];
      r = m->closed ? r - floor(r) : fmin(fmax(r, 0.0), 1.0);
      k.r[nn + 2 * (size_t)g + (size_t)side] = r;
    }
  for (size_t i = 0; i < na; i++) k.order[i] = i;
  sort_order(k.order, na, k.r);
  k.reach = 10 * e->h + 0.02 * e->size;
  double zero[MAX_KB] = {0};
  st = kfit_eval(&k, zero, k.y0);
  if (st) goto done;
  double worst;
  st = kfit_eval(&k, a, k.y);
  if (st) goto done;
  kfit_residuals(&k, k.y, k.g, NULL, &worst);
  for (int step = 0; step < KGN_STEPS && worst < -0.02 * e->h; step++) {
    if (km__poll_stop(poll, (long)(nn * (w + 1)))) {
      st = KM_ECANCELLED;
      goto done;
    }
    /* the Jacobian of the violated residuals, by forward differences */
    double lc[4], Jl[4][MAX_KB];
    local_change(&k, k.y, lc);
    for (size_t j = 0; j < w; j++) {
      double b[MAX_KB], wj;
      memcpy(b, a, w * sizeof *b);
      b[j] += KEPS;
      st = kfit_eval(&k, b, k.y1);
      if (st) goto done;
      kfit_residuals(&k, k.y1, k.g1, k.g, &wj);
      double l1[4];
      local_change(&k, k.y1, l1);
      for (int q = 0; q < 4; q++) Jl[q][j] = (l1[q] - lc[q]) / KEPS;
      for (size_t i = 0; i < nn; i++)
        J[i * w + j] =
            k.g[i] < 0 && isfinite(k.g1[i]) ? (k.g1[i] - k.g[i]) / KEPS : 0.0;
    }
    /* normal equations for the new a: least squares of g + J (a' - a) = 0
     * over the violated samples, a ridge, second differences of the turns
     * along each strand, and the total turn kept (a closed frame's
     * tangent closes by itself only then) */
    double M[MAX_KB * MAX_KB] = {0}, rhs[MAX_KB] = {0};
    for (size_t i = 0; i < nn; i++) {
      if (!(k.g[i] < 0)) continue;
      double ja = 0.0;
      for (size_t p = 0; p < w; p++) ja += J[i * w + p] * a[p];
      for (size_t p = 0; p < w; p++) {
        rhs[p] += J[i * w + p] * (ja - k.g[i]);
        for (size_t q = 0; q < w; q++)
          M[p * w + q] += J[i * w + p] * J[i * w + q];
      }
    }
    double sc = e->size * e->size;
    for (size_t p = 0; p < w; p++) M[p * w + p] += 1e-6 * sc;
    for (size_t g0 = 0; g0 < w; g0 += KB_PER)
      for (size_t j = 1; j + 1 < KB_PER; j++) {
        size_t q[3] = {g0 + j - 1, g0 + j, g0 + j + 1};
        double c3[3] = {1.0, -2.0, 1.0};
        for (int u = 0; u < 3; u++)
          for (int v = 0; v < 3; v++)
            M[q[u] * w + q[v]] += 1e-5 * sc * c3[u] * c3[v];
      }
    /* the rest of the frame kept: each strand's bumps close by themselves
     * (no turn, no move past them), so the closure has nothing new to
     * spread */
    for (int q = 0; q < 4 && KLOCAL > 0; q++) {
      double ja = 0.0;
      for (size_t p = 0; p < w; p++) ja += Jl[q][p] * a[p];
      for (size_t p = 0; p < w; p++) {
        rhs[p] += KLOCAL * Jl[q][p] * (ja - lc[q]);
        for (size_t r = 0; r < w; r++)
          M[p * w + r] += KLOCAL * Jl[q][p] * Jl[q][r];
      }
    }
    for (size_t p = 0; p < w; p++)
      for (size_t q = 0; q < w; q++)
        if (KLOCAL == 0 || p / KB_PER == q / KB_PER) M[p * w + q] += 1e2 * sc;
    if (!cholesky_solve(M, rhs, w)) break;
    double mean[2] = {0.0, 0.0};
    for (size_t p = 0; p < w; p++)
      mean[KLOCAL > 0 ? p / KB_PER : 0] +=
          rhs[p] / (double)(KLOCAL > 0 ? KB_PER : w);
    double big = 0.0, dir[MAX_KB];
    for (size_t p = 0; p < w; p++) {
      dir[p] = rhs[p] - mean[KLOCAL > 0 ? p / KB_PER : 0] - a[p];
      big = fmax(big, fabs(dir[p]));
    }
    double f = big > KSTEP ? KSTEP / big : 1.0;
    /* a step that makes the worst residual worse is halved, twice */
    double trial[MAX_KB], wt = 0.0;
    bool took = false;
    for (int half = 0; half < 3; half++, f *= 0.5) {
      for (size_t p = 0; p < w; p++) trial[p] = a[p] + f * dir[p];
      st = kfit_eval(&k, trial, k.y1);
      if (st) goto done;
      kfit_residuals(&k, k.y1, k.g1, NULL, &wt);
      if (wt > worst) {
        took = true;
        break;
      }
    }
    if (!took) break;
    memcpy(a, trial, w * sizeof *a);
    memcpy(k.y, k.y1, nn * sizeof *k.y);
    memcpy(k.g, k.g1, nn * sizeof *k.g);
    worst = wt;
  }
  *move = 0.0;
  for (size_t i = 0; i < nn; i++)
    *move = fmax(*move, hypot(k.y[i][0] - k.y0[i][0], k.y[i][1] - k.y0[i][1]));
  st = KM_OK;
done:
  km__free(J);
  kfit_free(&k);
  return st;
}

/* Fits the coefficients at key time t into c (e->w, warm start in c);
 * *move receives the curvature fit's largest move (0 for a displacement). */
static km_status fit_at(const km_morph *m, km__repair *rp, km__repair_event *e,
                        double t, double *c, double *move, km__poll *poll) {
  if ((e->nk ? rp->kfits_left-- : rp->fits_left--) <= 0) return KM_ELIMIT;
  *move = 0.0;
  if (e->nk) return kfit_at(m, e, t, c, move, poll);
  km_curve f;
  km_status st = frame_at(m, t, poll, &f);
  fit ft;
  memset(&ft, 0, sizeof ft);
  if (!st) st = fit_make(&ft, e, &f);
  if (!st) st = fit_solve(&ft, c, poll);
  fit_free(&ft);
  km_curve_free(&f);
  return st;
}

/* Inserts key time t (strictly between two keys) with coefficients c. */
static bool insert_key(km__repair_event *e, double t, const double *c,
                       double move) {
  size_t w = e->w, k = 1;
  if (e->nt >= MAX_KEYS) return false;
  while (k < e->nt && e->t[k] < t) k++;
  memmove(&e->kmove[k + 1], &e->kmove[k], (e->nt - k) * sizeof *e->kmove);
  e->kmove[k] = move;
  memmove(&e->t[k + 1], &e->t[k], (e->nt - k) * sizeof *e->t);
  memmove(&e->c[(k + 1) * w], &e->c[k * w], (e->nt - k) * w * sizeof *e->c);
  e->t[k] = t;
  memcpy(&e->c[k * w], c, w * sizeof *c);
  e->nt++;
  return true;
}

/* Crossings of the frame at t with the repair so far (events[0..n]). */
static km_status repaired_crossings(const km_morph *m, const km__repair *rp,
                                    double t, km__poll *poll, long *count) {
  km_curve f;
  km_curve_init(&f);
  km_status st = KM_OK;
  if (km__repair_kappa_active(rp, t)) {
    km_pp dk;
    st = km__repair_kappa(rp, t, rp->n, &dk);
    if (!st && dk.m)
      st = km__morph_frame_kappa(m, t, &dk, poll, &f, NULL);
    else if (!st)
      st = frame_at(m, t, poll, &f);
    km__pp_free(&dk);
  } else {
    st = frame_at(m, t, poll, &f);
  }
  double *c = NULL;
  for (size_t i = 0; !st && i < rp->n; i++) {
    const km__repair_event *e = &rp->ev[i];
    if (e->nk) continue;
    km__free(c);
    c = km__malloc(2 * e->nb * sizeof *c);
    if (!c) {
      st = KM_ENOMEM;
      break;
    }
    if (coefficients_at(e, t, c)) st = add_displacement(&f, e, c, NULL);
  }
  km__free(c);
  if (!st) {
    long x = km__self_intersections(&f, m->tol, poll);
    if (x < 0) st = poll && poll->stopped ? KM_ECANCELLED : KM_ENOMEM;
    *count = x;
  }
  km_curve_free(&f);
  return st;
}

/* The largest displacement over the event's key times. */
static double largest_move(const km__repair_event *e) {
  double big = 0.0;
  if (e->nk) {
    for (size_t k = 0; k < e->nt; k++) big = fmax(big, e->kmove[k]);
    return big;
  }
  for (size_t k = 0; k < e->nt; k++)
    for (size_t q = 0; q < e->nb; q++)
      big = fmax(
          big, hypot(e->c[(k * e->nb + q) * 2], e->c[(k * e->nb + q) * 2 + 1]));
  return big;
}

static void event_free(km__repair_event *e) {
  km__free(e->c);
  km__free(e->slope);
  km__free(e->side[0]);
  km__free(e->side[1]);
  e->c = e->slope = NULL;
  e->side[0] = e->side[1] = NULL;
}

void km__repair_free(km__repair *rp) {
  if (!rp) return;
  for (size_t i = 0; i < rp->n; i++) event_free(&rp->ev[i]);
  km__free(rp);
}

/* Key times of event e between the clean neighbours tb and ta, fitted. */
static km_status event_fit(const km_morph *m, km__repair *rp,
                           km__repair_event *e, double tb, double ta,
                           km__poll *poll) {
  size_t w = e->w;
  e->c = km__calloc(MAX_KEYS * w, sizeof *e->c);
  e->slope = km__calloc(MAX_KEYS * w, sizeof *e->slope);
  double *c = km__calloc(w, sizeof *c);
  km_status st = KM_ENOMEM;
  if (!e->c || !e->slope || !c) goto done;
  st = KM_OK;
  long steps = (long)lround((ta - tb) * SCAN * REFINE);
  e->nt = 0;
  for (long j = 0; j <= steps && e->nt < MAX_KEYS; j++) {
    double t = j == steps ? ta : tb + (ta - tb) * (double)j / (double)steps;
    e->t[e->nt] = t;
    e->kmove[e->nt] = 0.0;
    if (j > 0 && j < steps) {
      st = fit_at(m, rp, e, t, c, &e->kmove[e->nt], poll);
      if (st) goto done;
      memcpy(&e->c[e->nt * w], c, w * sizeof *c);
    }
    e->nt++;
  }
  hermite_slopes(e);
done:
  km__free(c);
  return st;
}

/* Checks between the key times of rp's last event; a time that still
 * crosses is fitted and becomes a key (ROUNDS times at most). *left
 * receives the checks that still cross, *before how many of the first
 * round's checks crossed without the event. */
static km_status event_verify(const km_morph *m, km__repair *rp, km__poll *poll,
                              long *left, long *before) {
  km__repair_event *e = &rp->ev[rp->n - 1];
  size_t w = e->w;
  double *c = km__malloc(w * sizeof *c);
  if (!c) return KM_ENOMEM;
  km_status st = KM_OK;
  for (int round = 0; round <= ROUNDS; round++) {
    double bad[MAX_KEYS];
    size_t nbad = 0;
    *left = *before = 0;
    for (size_t k = 0; k + 1 < e->nt; k++) {
      for (int v = 1; v <= VERIFY; v++) {
        double t = e->t[k] + (e->t[k + 1] - e->t[k]) * v / (VERIFY + 1.0);
        long x = 0;
        rp->n--; /* the frame without this event */
        st = repaired_crossings(m, rp, t, poll, &x);
        rp->n++;
        if (st) goto done;
        *before += x > 0;
        st = repaired_crossings(m, rp, t, poll, &x);
        if (st) goto done;
        if (x > 0) {
          (*left)++;
          if (nbad < MAX_KEYS) bad[nbad++] = t;
        }
      }
    }
    if (*left == 0 || round == ROUNDS) break;
    for (size_t i = 0; i < nbad; i++) {
      if (!coefficients_at(e, bad[i], c)) memset(c, 0, w * sizeof *c);
      double mv;
      st = fit_at(m, rp, e, bad[i], c, &mv, poll);
      if (st == KM_ELIMIT) {
        st = KM_OK;
        break;
      }
      if (st) goto done;
      if (!insert_key(e, bad[i], c, mv)) break;
    }
    hermite_slopes(e);
  }
done:
  km__free(c);
  return st;
}

/* Scan: the lenses of the frames at k / SCAN grouped into events. */
static km_status scan(const km_morph *m, km__poll *poll, scan_event *ev,
                      size_t *nev, long *crossing_frames) {
  *nev = 0;
  *crossing_frames = 0;
  for (int k = 1; k < SCAN; k++) {
    km_curve f;
    km_status st = frame_at(m, (double)k / SCAN, poll, &f);
    if (st) {
      km_curve_free(&f);
      if (st == KM_ENOMEM || st == KM_ECANCELLED) return st;
      continue;
    }
    double *hits = NULL, u0, u1;
    km_curve_domain(&f, &u0, &u1);
    long nh = km__self_intersection_params(&f, m->tol, poll, &hits);
    km_curve_free(&f);
    if (nh < 0) return poll && poll->stopped ? KM_ECANCELLED : KM_ENOMEM;
    if (nh > 0) (*crossing_frames)++;
    strands ls[16];
    size_t nl = lenses_of(hits, nh, u0, u1, ls, 16);
    km__free(hits);
    for (size_t i = 0; i < nl; i++) {
      size_t j = 0;
      for (; j < *nev; j++) {
        scan_event *e = &ev[j];
        double m0 = 0.02;
        if (e->last >= k - 1 &&
            overlaps(e->s.i0, e->s.i1, ls[i].i0, ls[i].i1, m0) &&
            overlaps(e->s.j0, e->s.j1, ls[i].j0, ls[i].j1, m0))
          break;
      }
      if (j == *nev) {
        if (*nev == MAX_EVENTS) continue;
        ev[j].s = ls[i];
        ev[j].first = k;
        (*nev)++;
      } else {
        scan_event *e = &ev[j];
        e->s.i0 = fmin(e->s.i0, ls[i].i0);
        e->s.i1 = fmax(e->s.i1, ls[i].i1);
        e->s.j0 = fmin(e->s.j0, ls[i].j0);
        e->s.j1 = fmax(e->s.j1, ls[i].j1);
      }
      ev[j].last = k;
    }
  }
  return KM_OK;
}

km_status km__repair_crossings(km_morph *m, km__repair_method how,
                               km__poll *poll) {
  scan_event sev[MAX_EVENTS];
  size_t nsev;
  long frames;
  km_status st = scan(m, poll, sev, &nsev, &frames);
  m->avoid.repair_scan_crossing = frames;
  if (st || nsev == 0) return st;
  /* frames that cross over most of the morph are no pinch: a displacement
   * of at most MAX_MOVE cannot hold them apart, and trying spends the
   * whole budget of fits for nothing (a 3-frame request took 0.3 s). The
   * pairs of repair.json cross on 9 of the 31 scan frames at most. */
  if (2 * frames > SCAN - 1) {
    m->avoid.repair_unrepaired = (long)nsev;
    return KM_OK;
  }
  km__repair *rp = km__calloc(1, sizeof *rp);
  if (!rp) return KM_ENOMEM;
  rp->degree = m->opt.degree;
  rp->closed = m->closed;
  rp->fits_left = rp->kfits_left = FITS;
  long unrepaired = 0, left_total = 0;
  /* each event by curvature, by displacement, or by curvature and, where
   * that is not kept, by displacement */
  int tries = how == KM__REPAIR_BOTH ? 2 : 1;
  bool stop = false;
  for (size_t i = 0; i < nsev && !stop; i++) {
    bool kept = false;
    for (int attempt = 0; attempt < tries && !kept && !stop; attempt++) {
      km__repair_event *e = &rp->ev[rp->n];
      memset(e, 0, sizeof *e);
      e->core = sev[i].s;
      if (!event_layout(e, m->closed)) break;
      e->w = 2 * e->nb;
      if (how != KM__REPAIR_DISPLACEMENT && attempt == 0) kappa_layout(e);
      double tb = 0.0, ta = 1.0;
      bool ok;
      st = event_sides(m, e, sev[i].first, sev[i].last, &tb, &ta, poll, &ok);
      if (st || !ok) {
        event_free(e);
        stop = st != KM_OK;
        break;
      }
      st = event_fit(m, rp, e, tb, ta, poll);
      if (st == KM_ELIMIT && attempt + 1 < tries) {
        /* the curvature fits' budget is spent: displacement */
        event_free(e);
        st = KM_OK;
        continue;
      }
      if (st == KM_ELIMIT) { /* the budget is spent: no more events */
        event_free(e);
        unrepaired += (long)(nsev - i - 1);
        st = KM_OK;
        stop = true;
        break;
      }
      if (st) {
        event_free(e);
        stop = true;
        break;
      }
      rp->n++;
      long left = 0, before = 0;
      st = event_verify(m, rp, poll, &left, &before);
      if (st) {
        stop = true;
        break;
      }
      /* kept when it helps and stays a local change */
      if (left >= before || largest_move(e) > MAX_MOVE * e->size) {
        event_free(e);
        rp->n--;
        continue;
      }
      left_total += left;
      kept = true;
    }
    if (!kept && !st) unrepaired++;
  }
  if (!st) {
    m->avoid.repair_events = (long)rp->n;
    m->avoid.repair_unrepaired = unrepaired;
    m->avoid.repair_checks_crossing = left_total;
  }
  if (st || rp->n == 0) {
    km__repair_free(rp);
    return st;
  }
  m->repair = rp;
  return KM_OK;
}

/* ---- frames ------------------------------------------------------------ */

/* The curvature repair's largest move at t: the larger of the key times'
 * either side (a strand's move, measured at the fit). */
static double kappa_move(const km__repair_event *e, double t) {
  size_t k = 0;
  while (k + 2 < e->nt && t >= e->t[k + 1]) k++;
  return fmax(e->kmove[k], e->kmove[k + 1]);
}

bool km__repair_active(const km__repair *rp, double t) {
  for (size_t i = 0; rp && i < rp->n; i++) {
    const km__repair_event *e = &rp->ev[i];
    if (e->nt >= 2 && t > e->t[0] && t < e->t[e->nt - 1]) return true;
  }
  return false;
}

size_t km__repair_extra_points(const km__repair *rp, double t) {
  size_t extra = 0;
  int p = rp ? rp->degree : 3;
  for (size_t i = 0; rp && i < rp->n; i++) {
    const km__repair_event *e = &rp->ev[i];
    if (e->nk == 0 && e->nt >= 2 && t > e->t[0] && t < e->t[e->nt - 1])
      extra += event_knots(e) * (size_t)(p - 2);
  }
  return extra;
}

km_status km__repair_apply(const km__repair *rp, double t, km_curve *f,
                           double *moved_by, km_error *err) {
  *moved_by = 0.0;
  km_status st = KM_OK;
  for (size_t i = 0; rp && !st && i < rp->n; i++) {
    const km__repair_event *e = &rp->ev[i];
    double c[MAX_BASIS * 2];
    if (e->nk || !coefficients_at(e, t, c)) continue;
    /* the largest displacement: D is a convex combination of its
     * coefficients, so their largest norm bounds it */
    for (size_t q = 0; q < e->nb; q++)
      *moved_by = fmax(*moved_by, hypot(c[2 * q], c[2 * q + 1]));
    st = add_displacement(f, e, c, err);
  }
  return st;
}

double km_morph_repaired(const km_morph *m, double t) {
  double size = 0.0;
  for (size_t i = 0; m->repair && i < m->repair->n; i++) {
    const km__repair_event *e = &m->repair->ev[i];
    double c[MAX_BASIS * 2];
    if (!coefficients_at(e, t, c)) continue;
    if (e->nk) {
      size = fmax(size, kappa_move(e, t));
      continue;
    }
    for (size_t q = 0; q < e->nb; q++)
      size = fmax(size, hypot(c[2 * q], c[2 * q + 1]));
  }
  return size;
}
