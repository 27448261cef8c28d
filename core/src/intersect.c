/* intersect.c - counting the proper self-crossings of a planar B-spline /
 * NURBS curve.
 *
 * DESIGN. The curve is cut into its Bezier pieces (homogeneous, so rational
 * curves are exact) and each piece into sub-curves whose control polygons
 * are monotone in x and in y: a polynomial piece of degree <= 3 is cut
 * where x' or y' vanishes (roots of a quadratic), and whatever is still
 * not monotone, with every rational or higher-degree piece, is halved
 * until it is. Such a sub-curve is itself monotone in both coordinates
 * (for positive weights the derivative of a rational Bezier coordinate is
 * a positive combination of control differences), so it cannot cross
 * itself: only pairs of sub-curves need testing. Pairs are pruned by a
 * sweep over their bounding boxes, then subdivided while their boxes
 * overlap until both are flat; the chords' intersection seeds Newton on
 * the exact pieces. A root counts when |C(s) - C(t)| <= tol, the two
 * parameters are different points of the curve (not the shared end of
 * adjacent pieces, not the seam of a closed curve, not an end of an open
 * one), and the tangents are transversal. Roots found twice (a crossing on
 * a piece boundary, or on the seam) are merged by parameter.
 */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "hcurve.h"
#include "internal.h"
#include "km/alloc.h"
#include "km/curve.h"
#include "km/limits.h"
#include "km/morph.h"

#define MAXC (KM_MAX_DEGREE + 1)

/* Smallest sine of the crossing angle that still counts as a crossing. At
 * a tangential touch Newton converges only to about sqrt(eps) in the
 * parameter, which leaves a sine of about sqrt(eps * curvature * size)
 * (1e-7 for curvature ~ 1/size, 1e-6 for features 1e-4 of the size);
 * crossings at smaller angles than this are reported as touches. */
#define MIN_CROSSING_SINE 1e-5

/* Sub-curves per monotone split and pair subdivision depth: 2^-24 of a
 * piece is far below any loop that matters; 2^-60 is below resolution. */
#define MONO_DEPTH 24
#define PAIR_DEPTH 60
/* Work bounds: pair subdivisions and Newton starts per count. Two branches
 * that run within the flatness of each other for a long stretch (a
 * hairpin folded almost onto itself) keep every pair of their sub-curves
 * overlapping; past these bounds pairs are seeded where they stand and
 * then no longer refined, so the count is what was found by then. The
 * frames of the fixtures and of icon morphs need under 200 and under 10. */
#define PAIR_BUDGET 50000L
#define SEED_BUDGET 5000L
/* Newton iterations per count: a seed converges in under ten, a touch
 * wanders up to a hundred; 5,000 seeds of a hundred would be 10^6
 * evaluations (a spiral wound 200 times took 0.4 s a frame). */
#define NEWTON_BUDGET 50000L
/* Box tests of the sweep per count: a curve wound tightly on itself puts
 * every sub-curve's box over every other's (8,192^2 / 2 tests). */
#define SWEEP_BUDGET 4000000L
/* Sub-curves per count (frames of the fixtures have some hundreds): a
 * piece split toward every wiggle would need 2^24 of them; past this the
 * rest are taken as they are. */
#define MAX_SEGS 8192

typedef struct seg {
  size_t piece;
  double u0, u1;     /* local parameter range within the piece */
  double h[MAXC][3]; /* homogeneous Bezier points of the sub-curve */
  double xmin, xmax, ymin, ymax;
  int way[2]; /* travel() of a kept sub-curve, for the sweep's pruning */
} seg;

typedef struct ctx {
  int p;
  const km__hcurve *bz; /* Bezier form, dim 3 */
  size_t pieces;        /* Bezier pieces of bz */
  double t0, t1;        /* curve domain */
  double tol, flat, size, eps_t;
  double mono_eps; /* step back a monotone control polygon may take */
  double mag;      /* largest |coordinate| of the control points */
  double margin;   /* rounding of the coordinates: the boxes' margin */
  long pairs_left, seeds_left, newton_left; /* work bounds (*_BUDGET) */
  bool closed;
  bool polynomial; /* unit weights and degree <= 3: turns in closed form */
  seg *segs;
  size_t nseg, capseg;
  double *hits; /* (ta, tb) pairs, ta < tb */
  size_t nhit, caphit;
  bool oom;       /* out of memory, or stopped: the count ends */
  km__poll *poll; /* the caller's stop condition, or NULL */
} ctx;

static void cart(const double h[3], double out[2]) {
  out[0] = h[0] / h[2];
  out[1] = h[1] / h[2];
}

static void seg_bbox(seg *s, int p) {
  double q[2];
  cart(s->h[0], q);
  s->xmin = s->xmax = q[0];
  s->ymin = s->ymax = q[1];
  /* comparisons, not fmin and fmax (calls here): the points are finite */
  for (int i = 1; i <= p; i++) {
    cart(s->h[i], q);
    if (q[0] < s->xmin) s->xmin = q[0];
    if (q[0] > s->xmax) s->xmax = q[0];
    if (q[1] < s->ymin) s->ymin = q[1];
    if (q[1] > s->ymax) s->ymax = q[1];
  }
}

/* de Casteljau at t in (0, 1) of s, which is the piece's parameter u: the
 * sub-curves before and after it. */
static void split_at(const seg *s, int p, double t, double u, seg *l, seg *r) {
  double tmp[MAXC][3];
  memcpy(tmp, s->h, sizeof tmp);
  l->piece = r->piece = s->piece;
  l->u0 = s->u0;
  l->u1 = u;
  r->u0 = u;
  r->u1 = s->u1;
  for (int c = 0; c < 3; c++) {
    l->h[0][c] = tmp[0][c];
    r->h[p][c] = tmp[p][c];
  }
  for (int k = 1; k <= p; k++) {
    for (int i = 0; i <= p - k; i++)
      for (int c = 0; c < 3; c++)
        tmp[i][c] = (1 - t) * tmp[i][c] + t * tmp[i + 1][c];
    for (int c = 0; c < 3; c++) {
      l->h[k][c] = tmp[0][c];
      r->h[p - k][c] = tmp[p - k][c];
    }
  }
  seg_bbox(l, p);
  seg_bbox(r, p);
}

/* de Casteljau at 1/2: both halves (split_at at one half: (a + b) / 2
 * and a / 2 + b / 2 round alike, halving being exact). */
static void split_half(const seg *s, int p, seg *l, seg *r) {
  split_at(s, p, 0.5, 0.5 * (s->u0 + s->u1), l, r);
}

static bool monotone(const seg *s, int p, double eps) {
  int sx = 0, sy = 0;
  double a[2], b[2];
  cart(s->h[0], a);
  for (int i = 1; i <= p; i++) {
    cart(s->h[i], b);
    double dx = b[0] - a[0], dy = b[1] - a[1];
    int cx = dx > eps ? 1 : (dx < -eps ? -1 : 0);
    int cy = dy > eps ? 1 : (dy < -eps ? -1 : 0);
    if (cx && sx && cx != sx) return false;
    if (cy && sy && cy != sy) return false;
    if (cx) sx = cx;
    if (cy) sy = cy;
    a[0] = b[0];
    a[1] = b[1];
  }
  return true;
}

/* Sign of a sub-curve's travel in x and in y (from its first control
 * point to its last; 0 if none). */
static void travel(const seg *s, int p, int sg[2]) {
  double a[2], b[2];
  cart(s->h[0], a);
  cart(s->h[p], b);
  for (int k = 0; k < 2; k++) sg[k] = (b[k] > a[k]) - (b[k] < a[k]);
}

/* The place of the next sub-curve kept, segs[nseg], or NULL when memory
 * runs out. */
static seg *next_seg(ctx *x) {
  if (x->nseg == x->capseg) {
    size_t cap = x->capseg ? 2 * x->capseg : 64;
    seg *n = km__realloc(x->segs, cap * sizeof *n);
    if (!n) {
      x->oom = true;
      return NULL;
    }
    x->segs = n;
    x->capseg = cap;
  }
  return &x->segs[x->nseg];
}

/* Keeps s, which may already stand in next_seg()'s place. */
static void push_seg(ctx *x, const seg *s) {
  seg *kept = next_seg(x);
  if (!kept) return;
  if (kept != s) *kept = *s;
  travel(kept, x->p, kept->way);
  x->nseg++;
}

static void collect(ctx *x, const seg *s, int depth) {
  if (x->oom || (x->oom = km__poll_stop(x->poll, 4))) return;
  if (depth >= MONO_DEPTH || x->nseg >= MAX_SEGS ||
      monotone(s, x->p, x->mono_eps)) {
    push_seg(x, s);
    return;
  }
  seg l, r;
  split_half(s, x->p, &l, &r);
  collect(x, &l, depth + 1);
  collect(x, &r, depth + 1);
}

/* Roots closer than this to an end of the piece or to each other are not
 * split at: the sliver between would turn back by some 1e-18 of the size. */
#define ROOT_GAP 1e-9

/* Appends to roots[n ..] the parameters in (ROOT_GAP, 1 - ROOT_GAP) where
 * coordinate k of the polynomial Bezier piece s (degree <= 3, unit
 * weights) has a zero derivative; returns the new count. The derivative's
 * Bernstein coefficients are the control differences d: if they keep one
 * sign there is no turn to find. */
static int turning_params(const seg *s, int p, int k, double *roots, int n) {
  double d[MAXC - 1];
  for (int i = 0; i < p; i++) d[i] = s->h[i + 1][k] - s->h[i][k];
  bool up = false, down = false;
  for (int i = 0; i < p; i++) {
    up |= d[i] > 0;
    down |= d[i] < 0;
  }
  if (!(up && down)) return n;
  double cand[2];
  int nc = 0;
  if (p == 2) {
    cand[nc++] = d[0] / (d[0] - d[1]);
  } else {
    /* d0 (1-u)^2 + 2 d1 u (1-u) + d2 u^2 = a u^2 + b u + c; the roots in
     * the form that does not cancel (Numerical Recipes 5.6) */
    double a = d[0] - 2 * d[1] + d[2], b = 2 * (d[1] - d[0]), c = d[0];
    double scale = fabs(d[0]) + fabs(d[1]) + fabs(d[2]);
    if (fabs(a) <= 1e-12 * scale) {
      if (b != 0) cand[nc++] = -c / b;
    } else {
      double disc = b * b - 4 * a * c;
      if (disc >= 0) {
        double q = -0.5 * (b + copysign(sqrt(disc), b));
        cand[nc++] = q / a;
        if (q != 0) cand[nc++] = c / q;
      }
    }
  }
  for (int i = 0; i < nc; i++)
    if (cand[i] > ROOT_GAP && cand[i] < 1 - ROOT_GAP) roots[n++] = cand[i];
  return n;
}

/* A whole Bezier piece into monotone sub-curves. A polynomial piece of
 * degree <= 3 is cut where x' or y' vanishes: between those points the
 * curve is monotone, and its control polygon almost always is too;
 * collect() checks that and halves the rare one that is not, so every
 * sub-curve kept still has a monotone control polygon. Halving alone
 * never lands on a turn and closes in on it level by level. */
static void collect_piece(ctx *x, const seg *s) {
  int p = x->p;
  if (!x->polynomial) {
    collect(x, s, 0);
    return;
  }
  /* most pieces are monotone already: kept as collect() would keep them */
  if (x->oom || (x->oom = km__poll_stop(x->poll, 4))) return;
  if (monotone(s, p, x->mono_eps)) {
    push_seg(x, s);
    return;
  }
  double roots[4];
  int n = turning_params(s, p, 0, roots, 0);
  n = turning_params(s, p, 1, roots, n);
  for (int i = 1; i < n; i++)
    for (int j = i; j > 0 && roots[j - 1] > roots[j]; j--) {
      double t = roots[j];
      roots[j] = roots[j - 1];
      roots[j - 1] = t;
    }
  seg rest = *s, l, r;
  double from = 0;
  for (int i = 0; i < n && !x->oom; i++) {
    if (roots[i] - from <= ROOT_GAP || 1 - roots[i] <= ROOT_GAP) continue;
    split_at(&rest, p, (roots[i] - from) / (1 - from), roots[i], &l, &r);
    collect(x, &l, 0);
    rest = r;
    from = roots[i];
  }
  collect(x, &rest, 0);
}

/* Largest distance of the control points from the chord. */
static double flatness(const seg *s, int p) {
  double a[2], b[2], q[2];
  cart(s->h[0], a);
  cart(s->h[p], b);
  double dx = b[0] - a[0], dy = b[1] - a[1], len = hypot(dx, dy), d = 0;
  for (int i = 1; i < p; i++) {
    cart(s->h[i], q);
    double e = len > 0 ? fabs((q[0] - a[0]) * dy - (q[1] - a[1]) * dx) / len
                       : hypot(q[0] - a[0], q[1] - a[1]);
    d = fmax(d, e);
  }
  return d;
}

/* Point and derivative (with respect to the local parameter) of piece k at
 * u in [0, 1]. */
static void eval_piece(const ctx *x, size_t k, double u, double P[2],
                       double D[2]) {
  int p = x->p;
  double tmp[MAXC][3];
  memcpy(tmp, x->bz->pw + k * (size_t)p * 3,
         (size_t)(p + 1) * 3 * sizeof(double));
  double d[3] = {0, 0, 0};
  for (int lvl = 1; lvl <= p; lvl++) {
    if (lvl == p)
      for (int c = 0; c < 3; c++) d[c] = p * (tmp[1][c] - tmp[0][c]);
    for (int i = 0; i <= p - lvl; i++)
      for (int c = 0; c < 3; c++)
        tmp[i][c] = (1 - u) * tmp[i][c] + u * tmp[i + 1][c];
  }
  double w = tmp[0][2];
  P[0] = tmp[0][0] / w;
  P[1] = tmp[0][1] / w;
  D[0] = (d[0] - P[0] * d[2]) / w;
  D[1] = (d[1] - P[1] * d[2]) / w;
}

static double piece_t(const ctx *x, size_t k, double u) {
  const double *U = x->bz->knots;
  double a = U[(size_t)x->p * (k + 1)], b = U[(size_t)x->p * (k + 2)];
  return a + u * (b - a);
}

static void add_hit(ctx *x, double ta, double tb) {
  if (ta > tb) {
    double t = ta;
    ta = tb;
    tb = t;
  }
  for (size_t i = 0; i < x->nhit; i++)
    if (fabs(x->hits[2 * i] - ta) <= x->eps_t &&
        fabs(x->hits[2 * i + 1] - tb) <= x->eps_t)
      return;
  if (x->nhit == x->caphit) {
    size_t cap = x->caphit ? 2 * x->caphit : 16;
    double *n = km__realloc(x->hits, 2 * cap * sizeof(double));
    if (!n) {
      x->oom = true;
      return;
    }
    x->hits = n;
    x->caphit = cap;
  }
  x->hits[2 * x->nhit] = ta;
  x->hits[2 * x->nhit + 1] = tb;
  x->nhit++;
}

/* Newton on C_a(ua) = C_b(ub) from a chord estimate; record proper
 * crossings. */
static void refine(ctx *x, size_t ka, double ua, size_t kb, double ub) {
  double Pa[2], Da[2], Pb[2], Db[2];
  /* Newton, keeping the best iterate: at a tangential touch the iteration
   * ends up wandering in rounding noise, and the best point there is the
   * one whose tangents are closest to parallel */
  double best = INFINITY, bua = ua, bub = ub;
  for (int it = 0; it < 100 && x->newton_left > 0; it++, x->newton_left--) {
    if ((x->oom = km__poll_stop(x->poll, 2))) return;
    eval_piece(x, ka, ua, Pa, Da);
    eval_piece(x, kb, ub, Pb, Db);
    double fx = Pa[0] - Pb[0], fy = Pa[1] - Pb[1], f = hypot(fx, fy);
    if (f < best) {
      best = f;
      bua = ua;
      bub = ub;
    }
    double det = Db[0] * Da[1] - Da[0] * Db[1];
    double na = hypot(Da[0], Da[1]), nb = hypot(Db[0], Db[1]);
    if (f == 0 || !(fabs(det) > 0) || !isfinite(det)) break;
    /* converged on a well-conditioned (transversal) root */
    if (f <= 1e-15 * x->size && fabs(det) >= 1e-3 * na * nb) break;
    double dua = (fx * Db[1] - Db[0] * fy) / det;
    double dub = (Da[1] * fx - Da[0] * fy) / det;
    if (!isfinite(dua) || !isfinite(dub)) break;
    double nua = fmin(1.0, fmax(0.0, ua + dua));
    double nub = fmin(1.0, fmax(0.0, ub + dub));
    if (nua == ua && nub == ub) break;
    ua = nua;
    ub = nub;
  }
  ua = bua;
  ub = bub;
  eval_piece(x, ka, ua, Pa, Da);
  eval_piece(x, kb, ub, Pb, Db);
  /* A crossing is a root: Newton, quadratic there, meets it to the
   * rounding of the coordinates. Two branches that only come within tol
   * (round a sharp tip, where a degenerate control leg puts curvature in
   * the hundreds) leave Newton wandering, and its best iterate there is no
   * crossing however close. */
  double reach = fmax(1e-10 * x->size, 256 * DBL_EPSILON * x->mag);
  if (!(hypot(Pa[0] - Pb[0], Pa[1] - Pb[1]) <= fmin(x->tol, reach))) return;
  double ta = piece_t(x, ka, ua), tb = piece_t(x, kb, ub);
  if (x->closed) {
    /* the seam is one point of a closed curve */
    if (ta >= x->t1 - x->eps_t) ta = x->t0;
    if (tb >= x->t1 - x->eps_t) tb = x->t0;
  } else if (fmin(ta, tb) <= x->t0 + x->eps_t ||
             fmax(ta, tb) >= x->t1 - x->eps_t) {
    /* an end of an open curve touching it is not a crossing */
    return;
  }
  if (fabs(ta - tb) <= x->eps_t) return; /* the same point of the curve */
  double na = hypot(Da[0], Da[1]), nb = hypot(Db[0], Db[1]);
  /* Two parameters a few tolerances apart along the curve are one point
   * seen twice (their positions agree to tol trivially), not a crossing:
   * compare their distance along the curve with tol. */
  {
    const double *U = x->bz->knots;
    double wa = U[(size_t)x->p * (ka + 2)] - U[(size_t)x->p * (ka + 1)];
    double wb = U[(size_t)x->p * (kb + 2)] - U[(size_t)x->p * (kb + 1)];
    double speed = fmax(wa > 0 ? na / wa : 0.0, wb > 0 ? nb / wb : 0.0);
    if (fabs(ta - tb) * speed <= 4.0 * x->tol) return;
  }
  if (!(na > 0 && nb > 0)) return;
  double sine = fabs(Da[0] * Db[1] - Da[1] * Db[0]) / (na * nb);
  if (!(sine >= MIN_CROSSING_SINE)) return;
  add_hit(x, ta, tb);
}

static bool boxes_overlap(const seg *a, const seg *b, double m) {
  return a->xmin <= b->xmax + m && b->xmin <= a->xmax + m &&
         a->ymin <= b->ymax + m && b->ymin <= a->ymax + m;
}

/* Chord intersection of two flat sub-curves seeds Newton. The parameter
 * window is a little wider than [0, 1] because a flat chord is only
 * tol-close to its curve; duplicates from neighbours are merged later. */
static void chord_seed(ctx *x, const seg *A, const seg *B) {
  if (x->seeds_left <= 0) return;
  int p = x->p;
  double a0[2], a1[2], b0[2], b1[2];
  cart(A->h[0], a0);
  cart(A->h[p], a1);
  cart(B->h[0], b0);
  cart(B->h[p], b1);
  double ax = a1[0] - a0[0], ay = a1[1] - a0[1];
  double bx = b1[0] - b0[0], by = b1[1] - b0[1];
  double det = bx * ay - ax * by;
  double la = hypot(ax, ay), lb = hypot(bx, by);
  if (!(la > 0 && lb > 0) || !(fabs(det) > 1e-12 * la * lb)) return;
  double rx = b0[0] - a0[0], ry = b0[1] - a0[1];
  double s = (bx * ry - by * rx) / det; /* on A */
  double t = (ax * ry - ay * rx) / det; /* on B */
  const double w = 0.05;
  if (s < -w || s > 1 + w || t < -w || t > 1 + w) return;
  s = fmin(1, fmax(0, s));
  t = fmin(1, fmax(0, t));
  x->seeds_left--;
  refine(x, A->piece, A->u0 + s * (A->u1 - A->u0), B->piece,
         B->u0 + t * (B->u1 - B->u0));
}

static void pair(ctx *x, const seg *A, const seg *B, int depth) {
  if (x->oom || !boxes_overlap(A, B, x->margin)) return;
  /* two flatness tests and a split: some 4 units */
  if ((x->oom = km__poll_stop(x->poll, 4))) return;
  int p = x->p;
  if (--x->pairs_left <= 0) {
    chord_seed(x, A, B);
    return;
  }
  bool fa = flatness(A, p) <= x->flat, fb = flatness(B, p) <= x->flat;
  if ((fa && fb) || depth >= PAIR_DEPTH) {
    chord_seed(x, A, B);
    return;
  }
  /* split the one that is not flat, else the larger */
  double sa = (A->xmax - A->xmin) + (A->ymax - A->ymin);
  double sb = (B->xmax - B->xmin) + (B->ymax - B->ymin);
  seg l, r;
  if (!fa && (fb || sa >= sb)) {
    split_half(A, p, &l, &r);
    pair(x, &l, B, depth + 1);
    pair(x, &r, B, depth + 1);
  } else {
    split_half(B, p, &l, &r);
    pair(x, A, &l, depth + 1);
    pair(x, A, &r, depth + 1);
  }
}

/* Two sub-curves that follow each other along the curve (A's end is B's
 * start) and travel the same way in x or in y cannot cross: say both go
 * up in y; A lies below the shared point's y and B above it, so they can
 * meet only on that line, where neither passes to the other side - a
 * touch at most, never a proper crossing. (At an extremum in x the two
 * travel opposite ways in x but the same way in y.) Subdividing toward the
 * shared end would otherwise cost some forty levels a pair. */
static bool consecutive_same_way(const ctx *x, const seg *A, const seg *B) {
  size_t last = x->pieces - 1;
  const seg *f = NULL, *g = NULL;
  for (int k = 0; k < 2 && !f; k++) {
    const seg *u = k ? B : A, *v = k ? A : B;
    bool same = u->piece == v->piece && u->u1 == v->u0;
    bool next = u->u1 == 1.0 && v->u0 == 0.0 &&
                (v->piece == u->piece + 1 ||
                 (x->closed && u->piece == last && v->piece == 0));
    if (same || next) {
      f = u;
      g = v;
    }
  }
  if (!f) return false;
  return (f->way[0] != 0 && f->way[0] == g->way[0]) ||
         (f->way[1] != 0 && f->way[1] == g->way[1]);
}

/* Sort order[0 .. n) by xmin, stably (equal keys keep their order, as
 * with the C library's merge sort this replaces: the sweep then visits
 * pairs in the same order), with tmp[0 .. n) as scratch. Bottom-up merge
 * over runs of 16 sorted by insertion: no callback a comparison, which
 * cost a seventh of a frame's count. */
static void sort_by_xmin(seg **order, seg **tmp, size_t n) {
  const size_t run = 16;
  for (size_t lo = 0; lo < n; lo += run) {
    size_t hi = lo + run < n ? lo + run : n;
    for (size_t i = lo + 1; i < hi; i++) {
      seg *s = order[i];
      size_t j = i;
      for (; j > lo && order[j - 1]->xmin > s->xmin; j--)
        order[j] = order[j - 1];
      order[j] = s;
    }
  }
  seg **from = order, **to = tmp;
  for (size_t width = run; width < n; width *= 2) {
    for (size_t lo = 0; lo < n; lo += 2 * width) {
      size_t mid = lo + width < n ? lo + width : n;
      size_t hi = mid + width < n ? mid + width : n;
      size_t i = lo, j = mid, k = lo;
      while (i < mid && j < hi)
        to[k++] = from[j]->xmin < from[i]->xmin ? from[j++] : from[i++];
      while (i < mid) to[k++] = from[i++];
      while (j < hi) to[k++] = from[j++];
    }
    seg **t = from;
    from = to;
    to = t;
  }
  if (from != order) memcpy(order, from, n * sizeof *order);
}

/* Number of proper self-crossings of c: points where two different
 * parameters meet within tol (absolute, clamped to at least 1e-13 of the
 * control polygon's extent; tol <= 0 or NaN means 1e-9 of it) and the
 * branches cross at a sine of at least MIN_CROSSING_SINE. The seam of a
 * closed curve, the shared ends of adjacent pieces, the ends of an open
 * curve and tangential touches are not crossings; overlapping (collinear
 * or coincident) stretches are not counted. Returns -1 for an invalid
 * curve or when memory runs out. Work is bounded (PAIR_BUDGET): a curve
 * folded almost onto itself over a long stretch gets the crossings found
 * within it. Thread-safe; allocates only scratch. */
long km_curve_self_intersections(const km_curve *c, double tol) {
  return km__self_intersections(c, tol, NULL);
}

km_status km_curve_self_intersections_until(const km_curve *c, double tol,
                                            const km_stop *stop, long *count) {
  km__poll poll;
  km__poll_init(&poll, stop);
  long n = km__self_intersections(c, tol, &poll);
  if (poll.stopped) return KM_ECANCELLED;
  if (n < 0) return c && c->knots && c->cp ? KM_ENOMEM : KM_EINVAL;
  *count = n;
  return KM_OK;
}

/* The scales of the search from the control points' box: size, magnitude,
 * tolerance, flatness, margin, budgets. False for a curve of no size. */
static bool set_scales(ctx *x, const km_curve *c, double tol) {
  double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
  /* comparisons, not fmin and fmax: a curve's points are finite */
  for (size_t i = 0; i < c->n; i++) {
    double px = c->cp[2 * i], py = c->cp[2 * i + 1];
    if (px < xmin) xmin = px;
    if (px > xmax) xmax = px;
    if (py < ymin) ymin = py;
    if (py > ymax) ymax = py;
  }
  x->size = hypot(xmax - xmin, ymax - ymin);
  x->mag = fmax(fmax(fabs(xmin), fabs(xmax)), fmax(fabs(ymin), fabs(ymax)));
  if (!(x->size > 0) || !isfinite(x->size)) return false;
  double floor_tol = KM_MIN_RELATIVE_TOLERANCE * x->size;
  x->tol = (tol > 0 && isfinite(tol)) ? fmax(tol, floor_tol) : 1e-9 * x->size;
  /* Flat enough to seed Newton: within the tolerance, but no coarser than
   * 1e-4 of the size, whatever tolerance is asked (a seed must lie near
   * its root). A sub-curve lies inside the box of its control points, so
   * boxes need no margin beyond the rounding of the coordinates: a loose
   * tolerance must not make every pair of a small curve overlap. */
  x->flat = fmax(fmin(x->tol, 1e-4 * x->size), 1e-7 * x->size);
  x->margin = 256 * DBL_EPSILON * fmax(x->mag, x->size);
  /* monotone up to the rounding of the coordinates (far from the origin
   * that rounding wiggles every control polygon, however small) and up to
   * a tenth of the tolerance: a sub-curve monotone but for steps back of
   * that size can only loop within it, below what the count resolves */
  x->mono_eps =
      fmax(fmax(1e-15 * x->size, 64 * DBL_EPSILON * x->mag), 0.1 * x->tol);
  x->eps_t = 1e-8 * (x->t1 - x->t0);
  x->pairs_left = PAIR_BUDGET;
  x->seeds_left = SEED_BUDGET;
  x->newton_left = NEWTON_BUDGET;
  return true;
}

/* Sweep the flat sub-curves in order of xmin (order: pointers to them)
 * and test every pair whose boxes overlap. */
static void sweep_pairs(ctx *x, seg **order) {
  long sweep_left = SWEEP_BUDGET;
  for (size_t i = 0; i < x->nseg && !x->oom; i++) {
    /* past every bound nothing more can be found */
    if (x->pairs_left <= 0 && (x->seeds_left <= 0 || x->newton_left <= 0))
      break;
    for (size_t j = i + 1; j < x->nseg && !x->oom && sweep_left-- > 0; j++) {
      if ((j & 15) == 0 && (x->oom = km__poll_stop(x->poll, 4))) break;
      if (order[j]->xmin > order[i]->xmax + x->margin) break;
      if (!boxes_overlap(order[i], order[j], x->margin)) continue;
      if (consecutive_same_way(x, order[i], order[j])) continue;
      pair(x, order[i], order[j], 0);
    }
  }
}

long km__self_intersections(const km_curve *c, double tol, km__poll *poll) {
  return km__self_intersection_params(c, tol, poll, NULL);
}

long km__self_intersection_params(const km_curve *c, double tol, km__poll *poll,
                                  double **hits) {
  if (hits) *hits = NULL;
  if (!c || !c->knots || !c->cp || c->degree < KM_MIN_DEGREE ||
      c->degree > KM_MAX_DEGREE || c->n < (size_t)c->degree + 1)
    return -1;
  km__hcurve h, bz;
  km__h_init(&h);
  km__h_init(&bz);
  ctx x;
  memset(&x, 0, sizeof x);
  x.poll = poll;
  seg **order = NULL;
  long result = -1;
  if (km__h_from_curve(&h, c, 3) || km__h_to_bezier(&bz, &h)) goto cleanup;
  int p = c->degree;
  x.p = p;
  x.bz = &bz;
  x.closed = c->closed;
  x.polynomial = !c->w && p <= 3;
  km_curve_domain(c, &x.t0, &x.t1);
  if (!set_scales(&x, c, tol)) {
    result = 0;
    goto cleanup;
  }
  /* every Bezier piece cut into monotone sub-curves */
  x.pieces = (bz.n - 1) / (size_t)p;
  for (size_t k = 0; k < x.pieces && !x.oom; k++) {
    /* built where it is kept, so that a piece kept whole (most are) is
     * not copied; split, it is read no more once its parts are kept */
    seg *s = next_seg(&x);
    if (!s) break;
    s->piece = k;
    s->u0 = 0;
    s->u1 = 1;
    memcpy(s->h, bz.pw + k * (size_t)p * 3,
           (size_t)(p + 1) * 3 * sizeof(double));
    seg_bbox(s, p);
    collect_piece(&x, s);
  }
  if (x.oom) goto cleanup;
  /* the sweep orders pointers: a sub-curve is hundreds of bytes */
  order = km__malloc((2 * x.nseg + 1) * sizeof *order);
  if (!order) goto cleanup;
  for (size_t i = 0; i < x.nseg; i++) order[i] = &x.segs[i];
  sort_by_xmin(order, order + x.nseg, x.nseg);
  sweep_pairs(&x, order);
  if (x.oom) goto cleanup;
  result = (long)x.nhit;
  if (hits) {
    *hits = x.hits;
    x.hits = NULL;
  }
cleanup:
  km__free(order);
  km__free(x.segs);
  km__free(x.hits);
  km__h_free(&h);
  km__h_free(&bz);
  return result;
}
