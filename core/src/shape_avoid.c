/* shape_avoid.c - intersections "avoid" for compound shapes: of the
 * choices the compound morph is free to make, keep one whose frames keep
 * holes inside and contours apart, and repair smoothly what remains.
 *
 * DESIGN. Each contour pair is a curvature morph whose frames are fitted
 * onto the pair's linear blend; a child follows its parent by the
 * similarity that best maps the parent's end frames onto its frame at t.
 * Where the parent changes shape a lot (b into d, g across fonts, a key's
 * bow into its outline) that whole-parent similarity carries a hole out
 * of it, and pairs of contours whose blends pass through each other (the
 * bars of pause into equal) cross. Two things are free: where a child is
 * placed, and a correction of each contour's placement that is zero at
 * t = 0 and 1 (the ends stay the inputs).
 *
 * The choice made today is previewed first: KM__PREVIEWS interior frames,
 * t = j / (KM__PREVIEWS + 1), counting mutual crossings and nesting
 * failures. When none fails, nothing changes: the frames are today's.
 * Otherwise the placements are previewed, the first clean one kept:
 *  - a child placed by the parent's points near it (the similarity fitted
 *    with Gaussian weights around the child's anchor) instead of by the
 *    whole parent;
 *  - a top-level unpaired contour's point left where its host's mapping
 *    puts it, rather than pulled inside the host's partner (where it
 *    grows out of, or shrinks into, a filled region: the middle bar of
 *    equal into menu);
 * and, where none is clean, the two best get corrections (below); of all
 * these the one whose previews fail least is kept, today's among equals.
 * Corrections: per contour, measured on the interior times of a grid
 * t = j / KM__FIX, level by level of the nesting (parents first, within
 * a level the larger contours first, so a smaller one gives way): at each
 * time the cheapest translation and scale about its centroid (cost: the
 * translation and the shrinking relative to its size, plus the change
 * from the previous time, so the choice stays on one side) under which
 * it, and it grown by MARGIN, lies in its parent and crosses none of the
 * contours already settled. The grid's values, zero at both ends, are
 * ramped (a change of at most RAMP of the shape's size, RAMP_SCALE of ln
 * scale, per grid interval) and joined by a monotone cubic in t
 * (Fritsch-Carlson), so the correction is C1 and cannot pop. An unpaired
 * contour's scale goes into its size schedule instead, so it still only
 * shrinks toward its missing side. The per-frame nudge of shape_frame.c
 * stays as the last resort, off while corrections are measured. Metrics
 * are measured on the frames returned, so they stay truthful.
 *
 * Measured on the 51 fixture pairs at 41 frames (frames with a mutual
 * crossing or a nesting failure, by the frames' own metrics; 307 under
 * allow): near placement alone 303, corrections alone 39, both 42;
 * corrections by translation only 95; without MARGIN 60 (a correction
 * just enough at the grid times is not enough between them); without the
 * ramp 32 but the bars of pause into equal jump by 0.15 of the size a
 * frame; scales down to 0.04 worse (59: a deep shrink spreads to the
 * neighbouring times). With the point choice: 30.
 *
 * Budget: at most CHOICES placements of KM__PREVIEWS frames each, each
 * placement re-planned (the schedule of unpaired children: KM__SCHED + 1
 * frames), three corrections (two tried and the one kept made again),
 * each per nesting level KM__FIX - 1 frames in which each failing contour
 * tries at most CANDIDATES placements on a polyline of at most
 * SEARCH_POINTS points against the settled contours' band indices, then
 * KM__PREVIEWS frames. Every frame polls the caller's stop, and the search
 * polls it once a candidate.
 *
 * Pairing: where the kept choice still fails and the pairing was not a
 * person's, km_shape_morph_create (shape_morph.c) morphs again with two
 * pairs' partners swapped and keeps the pairing whose frames fail least
 * (the bars of pause into equal, information into help-circle: the i's
 * dot went to the question mark's body). With it the 51 fixture pairs
 * fail on 22 frames, not 31, and 41 pairs are clean on every frame, not
 * 39; the sweep's time is unchanged within its noise (7.3 s against
 * 6.8-7.6 s of CPU, 21 frames a pair).
 *
 * What it cannot do: untangle contours that no
 * translation and shrinking within bounds separates (the contour then
 * keeps no correction at that time); see what the previews do not: a
 * dot that enters the stem only after t = 7/8 (i into l) is left as is,
 * and between grid times a correction may fall short by a frame or two.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "km/alloc.h"
#include "km/shape.h"
#include "kernels.h"
#include "shape_internal.h"
#include "status_internal.h"

#define SEARCH_POINTS 256
#define NDIR 8
#define NMAG 9
#define NSCALE 6
#define CANDIDATES ((NDIR + 1) * NMAG * NSCALE)
/* Weight of the change from the previous grid time in a candidate's cost. */
#define STEADY 0.5
/* The largest change of a correction between grid times: its translation
 * as a fraction of the shape's size (the fixture test's bound on a frame's
 * step is 0.1 of it at 41 frames, 0.25 a grid interval), and its ln
 * scale. */
#define RAMP 0.08
#define RAMP_SCALE 0.3
/* Growth of a contour that a correction must also clear. */
#define MARGIN 0.1

static const double magnitudes[NMAG] = {0,   0.05, 0.1,  0.2, 0.35,
                                        0.5, 0.75, 1.25, 2.0};
static const double scales[NSCALE] = {1.0, 0.85, 0.7, 0.55, 0.4, 0.25};

/* Monotone cubic (Fritsch-Carlson) through y[0..KM__FIX] at j / KM__FIX,
 * at t. */
static double pchip(const double *y, double t) {
  double x = t * KM__FIX;
  int j = (int)floor(x);
  if (j < 0) j = 0;
  if (j >= KM__FIX) j = KM__FIX - 1;
  double u = x - j, m[2];
  for (int e = 0; e < 2; e++) {
    int i = j + e;
    double dl = i > 0 ? y[i] - y[i - 1] : y[1] - y[0];
    double dr = i < KM__FIX ? y[i + 1] - y[i] : y[i] - y[i - 1];
    m[e] = dl * dr <= 0 ? 0.0 : 2.0 / (1.0 / dl + 1.0 / dr);
  }
  double u2 = u * u, u3 = u2 * u;
  return (2 * u3 - 3 * u2 + 1) * y[j] + (u3 - 2 * u2 + u) * m[0] +
         (-2 * u3 + 3 * u2) * y[j + 1] + (u3 - u2) * m[1];
}

bool km__shape_fix_at(const km_shape_morph *m, size_t k, double t, double d[2],
                      double *r) {
  if (!m->fixed || !m->fixed[k]) return false;
  const double *F = m->fix + 3 * (KM__FIX + 1) * k;
  double y[KM__FIX + 1];
  for (int c = 0; c < 3; c++) {
    for (int j = 0; j <= KM__FIX; j++) y[j] = F[3 * j + c];
    double v = pchip(y, t);
    if (c < 2)
      d[c] = v;
    else
      *r = exp(v);
  }
  return true;
}

/* Frames at t = j / (n + 1), j = 1..n: their mutual crossings plus
 * their nesting failures into *fails. */
static km_status preview(const km_shape_morph *m, int n, const km_stop *stop,
                         long *fails, km_error *err) {
  km_status st = km__shape_preview(m, n, false, stop, fails, err);
  /* and the ends' halves of the first and last gaps, where a vanishing
   * contour meets a growing one (the dot of i and the stem of l) */
  for (int e = 0; e < 2 && st == KM_OK; e++) {
    km_shape_frame f;
    km_shape_frame_init(&f);
    double t = e == 0 ? 0.5 / (n + 1) : 1 - 0.5 / (n + 1);
    st = km_shape_morph_frame_until(m, t, stop, &f, err);
    if (st == KM_OK) *fails += f.mutual_intersections + (f.nesting_ok ? 0 : 1);
    km_shape_frame_free(&f);
  }
  return st;
}

km_status km__shape_preview(const km_shape_morph *m, int n, bool between,
                            const km_stop *stop, long *fails, km_error *err) {
  *fails = 0;
  for (int j = 1; j <= n + (between ? 1 : 0); j++) {
    km_shape_frame f;
    km_shape_frame_init(&f);
    double t = between ? (j - 0.5) / (n + 1) : (double)j / (n + 1);
    km_status st = km_shape_morph_frame_until(m, t, stop, &f, err);
    if (st != KM_OK) return st;
    *fails += f.mutual_intersections + (f.nesting_ok ? 0 : 1);
    km_shape_frame_free(&f);
  }
  return KM_OK;
}

/* ---- the correction search --------------------------------------------- */

/* A frame's flattenings and their indices, and which slots are settled. */
typedef struct scene {
  size_t n;
  double **pt;
  size_t *np;
  km__poly_index *ix;
  bool *settled;
  double *buf; /* SEARCH_POINTS moved points */
} scene;

static void scene_free(scene *s) {
  for (size_t k = 0; s->pt && k < s->n; k++) km__free(s->pt[k]);
  for (size_t k = 0; s->ix && k < s->n; k++) km__poly_index_free(&s->ix[k]);
  km__free(s->pt);
  km__free(s->np);
  km__free(s->ix);
  km__free(s->settled);
  km__free(s->buf);
  memset(s, 0, sizeof *s);
}

static km_status scene_build(scene *s, const km_shape_frame *f) {
  s->n = f->ncontours;
  s->pt = km__calloc(s->n, sizeof *s->pt);
  s->np = km__calloc(s->n, sizeof *s->np);
  s->ix = km__calloc(s->n, sizeof *s->ix);
  s->settled = km__calloc(s->n, sizeof *s->settled);
  s->buf = km__malloc(2 * SEARCH_POINTS * sizeof *s->buf);
  if (!s->pt || !s->np || !s->ix || !s->settled || !s->buf) return KM_ENOMEM;
  for (size_t k = 0; k < s->n; k++) {
    km__poly_index_init(&s->ix[k]);
    if (!f->present[k]) continue;
    km_status st = km__shape_flatten(&f->contours[k], &s->pt[k], &s->np[k]);
    if (st == KM_OK) st = km__poly_index_build(&s->ix[k], s->pt[k], s->np[k]);
    if (st != KM_OK) return st;
  }
  return KM_OK;
}

static int depth_in(const km_shape_frame *f, size_t k) {
  int d = 0;
  for (long p = f->parent[k]; p >= 0 && (size_t)d <= f->ncontours;
       p = f->parent[p])
    d++;
  return d;
}

static bool is_ancestor(const km_shape_frame *f, size_t a, size_t k) {
  int d = 0;
  for (long p = f->parent[k]; p >= 0 && (size_t)d <= f->ncontours;
       p = f->parent[p], d++)
    if ((size_t)p == a) return true;
  return false;
}

/* Points of P (np, closed) under x -> g + r (x - g) + d, at most
 * SEARCH_POINTS of them (every step-th), into s->buf; their count. */
static size_t moved(scene *s, const double *P, size_t np, const double g[2],
                    double r, const double d[2]) {
  size_t step = (np + SEARCH_POINTS - 2) / (SEARCH_POINTS - 1), n = 0;
  if (step < 1) step = 1;
  for (size_t i = 0; i < np && n < SEARCH_POINTS - 1; i += step, n++) {
    s->buf[2 * n] = g[0] + r * (P[2 * i] - g[0]) + d[0];
    s->buf[2 * n + 1] = g[1] + r * (P[2 * i + 1] - g[1]) + d[1];
  }
  s->buf[2 * n] = s->buf[0]; /* closed */
  s->buf[2 * n + 1] = s->buf[1];
  return n + 1;
}

/* Violations of slot k moved as asked: points outside its parent, or
 * crossings with a settled slot. */
static long violations_at(scene *s, const km_shape_frame *f, size_t k,
                          const double g[2], double r, const double d[2],
                          km__poll *poll) {
  size_t n = moved(s, s->pt[k], s->np[k], g, r, d);
  long p = f->parent[k];
  if (p >= 0 && f->present[p])
    for (size_t i = 0; i + 1 < n; i++)
      if (km__poly_index_winding(&s->ix[p], s->buf + 2 * i) == 0) return 1;
  for (size_t l = 0; l < s->n; l++) {
    if (l == k || !s->settled[l] || !f->present[l] || (long)l == p ||
        is_ancestor(f, l, k))
      continue;
    long c = km__poly_index_crossings(s->buf, n, &s->ix[l], poll);
    if (c != 0) return c;
  }
  return 0;
}

/* As violations_at, for the contour and for it grown by MARGIN about
 * its centroid: a correction found on the grid must hold between its
 * times too, where the contours have moved on a little. */
static long violations(scene *s, const km_shape_frame *f, size_t k,
                       const double g[2], double r, const double d[2],
                       km__poll *poll) {
  long v = violations_at(s, f, k, g, r, d, poll);
  if (v == 0) v = violations_at(s, f, k, g, r * (1 + MARGIN), d, poll);
  return v;
}

typedef struct cand {
  double v[3]; /* dx, dy, ln r */
  double cost;
} cand;

static int by_cost(const void *a, const void *b) {
  double x = ((const cand *)a)->cost, y = ((const cand *)b)->cost;
  return x < y ? -1 : x > y ? 1 : 0;
}

/* The cheapest feasible correction of slot k in this frame into fx[3]
 * (dx, dy, ln r; zero when none is feasible), given the previous grid
 * time's prev[3]. */
static km_status search(scene *s, const km_shape_frame *f, size_t k,
                        const double prev[3], double fx[3], km__poll *poll) {
  const double *P = s->pt[k];
  size_t np = s->np[k];
  double g[2] = {0, 0}, rr = 0;
  for (size_t i = 0; i + 1 < np; i++) {
    g[0] += P[2 * i] / (double)(np - 1);
    g[1] += P[2 * i + 1] / (double)(np - 1);
  }
  for (size_t i = 0; i + 1 < np; i++)
    rr += (pow(P[2 * i] - g[0], 2) + pow(P[2 * i + 1] - g[1], 2)) /
          (double)(np - 1);
  double R = sqrt(rr);
  fx[0] = fx[1] = fx[2] = 0.0;
  if (!(R > 0)) return KM_OK;
  const double zero[2] = {0, 0};
  long v = violations(s, f, k, g, 1.0, zero, poll);
  if (poll && poll->stopped) return KM_ECANCELLED;
  if (v == 0) return KM_OK;
  /* directions: the compass, and toward the parent's inside */
  double dir[NDIR + 1][2];
  for (int i = 0; i < NDIR; i++) {
    dir[i][0] = cos(2 * KM_PI * i / NDIR);
    dir[i][1] = sin(2 * KM_PI * i / NDIR);
  }
  dir[NDIR][0] = dir[NDIR][1] = 0;
  long p = f->parent[k];
  if (p >= 0 && f->present[p]) {
    double q[2];
    km__poly_interior_point(&s->ix[p], g, q);
    double l = hypot(q[0] - g[0], q[1] - g[1]);
    if (l > 0) {
      dir[NDIR][0] = (q[0] - g[0]) / l;
      dir[NDIR][1] = (q[1] - g[1]) / l;
    }
  }
  cand c[CANDIDATES];
  size_t nc = 0;
  for (int a = 0; a <= NDIR; a++)
    for (int b = 0; b < NMAG; b++)
      for (int e = 0; e < NSCALE; e++) {
        if ((b == 0 && a > 0) || (dir[a][0] == 0 && dir[a][1] == 0 && b > 0) ||
            (b == 0 && e == 0))
          continue;
        cand *x = &c[nc++];
        x->v[0] = magnitudes[b] * R * dir[a][0];
        x->v[1] = magnitudes[b] * R * dir[a][1];
        x->v[2] = log(scales[e]);
        x->cost = magnitudes[b] + (1 - scales[e]) +
                  STEADY * (hypot(x->v[0] - prev[0], x->v[1] - prev[1]) / R +
                            fabs(scales[e] - exp(prev[2])));
      }
  qsort(c, nc, sizeof *c, by_cost);
  for (size_t i = 0; i < nc; i++) {
    if (km__poll_stop(poll, 1)) return KM_ECANCELLED;
    v = violations(s, f, k, g, exp(c[i].v[2]), c[i].v, poll);
    if (poll && poll->stopped) return KM_ECANCELLED;
    if (v == 0) {
      memcpy(fx, c[i].v, sizeof c[i].v);
      return KM_OK;
    }
  }
  return KM_OK; /* none feasible: no correction */
}

/* Slot k's flattening in s moved by fx, its index rebuilt. */
static km_status settle(scene *s, size_t k, const double fx[3]) {
  double *P = s->pt[k], g[2] = {0, 0}, r = exp(fx[2]);
  size_t np = s->np[k];
  s->settled[k] = true;
  if (fx[0] == 0 && fx[1] == 0 && fx[2] == 0) return KM_OK;
  for (size_t i = 0; i + 1 < np; i++) {
    g[0] += P[2 * i] / (double)(np - 1);
    g[1] += P[2 * i + 1] / (double)(np - 1);
  }
  for (size_t i = 0; i < np; i++) {
    P[2 * i] = g[0] + r * (P[2 * i] - g[0]) + fx[0];
    P[2 * i + 1] = g[1] + r * (P[2 * i + 1] - g[1]) + fx[1];
  }
  return km__poly_index_build(&s->ix[k], P, np);
}

static double poly_area(const double *P, size_t np) {
  double a = 0;
  for (size_t i = 0; i + 1 < np; i++)
    a += P[2 * i] * P[2 * i + 3] - P[2 * i + 2] * P[2 * i + 1];
  return fabs(0.5 * a);
}

/* The corrections of the slots at nesting depth `level` of one grid
 * frame (slots above it settled, their corrections applied in it). */
static km_status measure_frame(km_shape_morph *m, int level, int j,
                               const km_stop *stop, double *size,
                               km_error *err) {
  km_shape_frame f;
  scene s;
  km__poll poll;
  km__poll_init(&poll, stop);
  km_shape_frame_init(&f);
  memset(&s, 0, sizeof s);
  km_status st =
      km_shape_morph_frame_until(m, (double)j / KM__FIX, stop, &f, err);
  if (st != KM_OK) return st;
  st = scene_build(&s, &f);
  size_t n = f.ncontours;
  double box[4] = {INFINITY, INFINITY, -INFINITY, -INFINITY};
  for (size_t k = 0; st == KM_OK && k < n; k++) {
    s.settled[k] = f.present[k] && depth_in(&f, k) < level;
    for (size_t i = 0; f.present[k] && i < s.np[k]; i++)
      for (int c = 0; c < 2; c++) {
        box[c] = fmin(box[c], s.pt[k][2 * i + c]);
        box[2 + c] = fmax(box[2 + c], s.pt[k][2 * i + c]);
      }
  }
  if (box[2] >= box[0])
    *size = fmax(*size, hypot(box[2] - box[0], box[3] - box[1]));
  /* the larger first: the smaller gives way */
  for (;;) {
    long pick = -1;
    double big = -1;
    for (size_t k = 0; st == KM_OK && k < n; k++) {
      if (!f.present[k] || s.settled[k] || depth_in(&f, k) != level) continue;
      double a = poly_area(s.pt[k], s.np[k]);
      if (a > big) {
        big = a;
        pick = (long)k;
      }
    }
    if (pick < 0 || st != KM_OK) break;
    double *F = m->fix + 3 * (KM__FIX + 1) * (size_t)pick;
    st = search(&s, &f, (size_t)pick, F + 3 * (j - 1), F + 3 * j, &poll);
    if (st == KM_OK) st = settle(&s, (size_t)pick, F + 3 * j);
  }
  if (st == KM_ENOMEM)
    km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, "out of memory");
  if (st == KM_ECANCELLED) km__stopped(err);
  scene_free(&s);
  km_shape_frame_free(&f);
  return st;
}

static int slot_depth(const km_shape_morph *m, size_t k) {
  int best = 0;
  for (int e = 0; e < 2; e++) {
    int d = 0;
    const long *par = e ? m->parent_to : m->parent_from;
    for (long p = par[k]; p >= 0 && (size_t)d <= m->npairs; p = par[p]) d++;
    if (d > best) best = d;
  }
  return best;
}

/* An unpaired slot's scale goes into its schedule (it keeps shrinking
 * toward its missing side only); its correction keeps the translation. */
static void fold_scale(km_shape_morph *m, size_t k) {
  double *F = m->fix + 3 * (KM__FIX + 1) * k, y[KM__FIX + 1];
  double *S = m->sched + (KM__SCHED + 1) * k;
  for (int j = 0; j <= KM__FIX; j++) y[j] = F[3 * j + 2];
  for (int i = 0; i <= KM__SCHED; i++)
    S[i] *= fmin(1.0, exp(pchip(y, (double)i / KM__SCHED)));
  for (int j = 0; j <= KM__FIX; j++) F[3 * j + 2] = 0.0;
  km__shape_sched_monotone(m, k);
}

/* Start a schedule where the morph has none: every slot its nominal. */
static void nominal_schedule(km_shape_morph *m) {
  if (m->scheduled) return;
  for (size_t k = 0; k < m->npairs; k++)
    for (int i = 0; i <= KM__SCHED; i++) {
      double t = (double)i / KM__SCHED;
      m->sched[(KM__SCHED + 1) * k + (size_t)i] =
          m->kind[k] == KM__VANISH   ? 1.0 - t
          : m->kind[k] == KM__APPEAR ? t
                                     : 1.0;
    }
  m->scheduled = true;
}

/* Bound the correction's change between grid times: its translation by
 * step and its ln scale by RAMP_SCALE, each time taking the largest of
 * the neighbours' values shrunk by their distance (a ramp toward a large
 * correction rather than a jump). */
static void ramp(double *F, double step) {
  double v[KM__FIX + 1][3];
  memcpy(v, F, sizeof v);
  for (int j = 1; j < KM__FIX; j++) {
    double bd = hypot(v[j][0], v[j][1]), bx = v[j][0], by = v[j][1];
    double lr = v[j][2];
    for (int i = 1; i < KM__FIX; i++) {
      double a = hypot(v[i][0], v[i][1]), far = abs(i - j);
      double keep = a > 0 ? fmax(0.0, a - far * step) / a : 0.0;
      if (a * keep > bd) {
        bd = a * keep;
        bx = v[i][0] * keep;
        by = v[i][1] * keep;
      }
      lr = fmin(lr, fmin(0.0, v[i][2] + far * RAMP_SCALE));
    }
    /* and back to zero at the ends */
    double reach = fmin(j, KM__FIX - j) * step;
    double keep = bd > reach ? reach / bd : 1.0;
    F[3 * j] = bx * keep;
    F[3 * j + 1] = by * keep;
    F[3 * j + 2] = fmax(lr, -fmin(j, KM__FIX - j) * RAMP_SCALE);
  }
}

/* Level by level: measure on the grid, widen the shrinking to the
 * neighbouring times (the cubic between them stays below it), fold the
 * unpaired slots' scale into their schedules, and switch the level on. */
static km_status measure(km_shape_morph *m, const km_stop *stop,
                         km_error *err) {
  size_t n = m->npairs;
  int maxd = 0;
  for (size_t k = 0; k < n; k++)
    if (slot_depth(m, k) > maxd) maxd = slot_depth(m, k);
  nominal_schedule(m);
  for (int level = 0; level <= maxd; level++) {
    double size = 0;
    for (int j = 1; j < KM__FIX; j++) {
      km_status st = measure_frame(m, level, j, stop, &size, err);
      if (st != KM_OK) return st;
    }
    for (size_t k = 0; k < n; k++) {
      if (m->fixed[k]) continue;
      double *F = m->fix + 3 * (KM__FIX + 1) * k, lr[KM__FIX + 1];
      for (int j = 0; j <= KM__FIX; j++) lr[j] = F[3 * j + 2];
      for (int j = 1; j < KM__FIX; j++)
        F[3 * j + 2] = fmin(lr[j], fmin(lr[j - 1], lr[j + 1]));
      ramp(F, RAMP * size);
      if (m->kind[k] != KM__PAIRED) fold_scale(m, k);
      bool any = false;
      for (int j = 0; j <= KM__FIX; j++)
        any = any || F[3 * j] != 0 || F[3 * j + 1] != 0 || F[3 * j + 2] != 0;
      m->fixed[k] = any;
    }
  }
  return KM_OK;
}

static void drop_fix(km_shape_morph *m) {
  km__free(m->fix);
  km__free(m->fixed);
  m->fix = NULL;
  m->fixed = NULL;
}

/* Corrections measured for m as it stands (no_adjust while measuring). */
static km_status correct(km_shape_morph *m, const km_stop *stop,
                         km_error *err) {
  size_t n = m->npairs;
  m->fix = km__calloc(3 * (KM__FIX + 1) * n, sizeof *m->fix);
  m->fixed = km__calloc(n, sizeof *m->fixed);
  if (!m->fix || !m->fixed) {
    drop_fix(m);
    return km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, "out of memory");
  }
  m->no_adjust = true;
  km_status st = measure(m, stop, err);
  m->no_adjust = false;
  return st;
}

/* The free choices: bit 0 places children by the part of the parent near
 * them, bit 1 leaves top-level unpaired contours' points outside their
 * host; bit 2 adds the corrections. Choice 0 is the morph as made. */
enum { LOCAL = 1, FREE_TOP = 2, CORRECTED = 4, CHOICES = 4 };

static km_status set_choice(km_shape_morph *m, const km_shape *a,
                            const km_shape *b, int c, const km_stop *stop,
                            km_error *err) {
  drop_fix(m);
  m->local_follow = (c & LOCAL) != 0;
  m->free_top_points = (c & FREE_TOP) != 0;
  km_status st = km__shape_replan(m, a, b, stop, err);
  if (st == KM_OK && (c & CORRECTED)) st = correct(m, stop, err);
  return st;
}

km_status km__shape_avoid(km_shape_morph *m, const km_shape *a,
                          const km_shape *b, const km_stop *stop,
                          km_error *err) {
  long fails[2 * CHOICES];
  for (int c = 0; c < 2 * CHOICES; c++) fails[c] = -1;
  km_status st = preview(m, KM__PREVIEWS, stop, &fails[0], err);
  m->preview_fails = fails[0];
  if (st != KM_OK || fails[0] == 0) return st;
  bool follows = false, tops = false;
  for (size_t k = 0; k < m->npairs; k++) {
    follows = follows || m->has_ref[k];
    tops = tops || (m->kind[k] != KM__PAIRED && m->parent_from[k] < 0 &&
                    m->parent_to[k] < 0);
  }
  /* the placements by their previews, the first clean one kept */
  int best = 0, second = -1, now = 0;
  for (int c = 1; c < CHOICES && fails[best] > 0; c++) {
    if (((c & LOCAL) && !follows) || ((c & FREE_TOP) && !tops)) continue;
    st = set_choice(m, a, b, c, stop, err);
    if (st == KM_OK) st = preview(m, KM__PREVIEWS, stop, &fails[c], err);
    if (st != KM_OK) return st;
    now = c;
    if (fails[c] < fails[best]) {
      second = best;
      best = c;
    } else if (second < 0 || fails[c] < fails[second]) {
      second = c;
    }
  }
  /* corrections on the two best placements, kept when they help */
  int keep = best;
  for (int e = 0; e < 2 && fails[best] > 0; e++) {
    int c = e == 0 ? best : second;
    if (c < 0) break;
    st = set_choice(m, a, b, c | CORRECTED, stop, err);
    if (st == KM_OK)
      st = preview(m, KM__PREVIEWS, stop, &fails[c | CORRECTED], err);
    if (st != KM_OK) return st;
    now = c | CORRECTED;
    if (fails[c | CORRECTED] < fails[keep]) keep = c | CORRECTED;
  }
  m->preview_fails = fails[keep];
  return keep == now ? KM_OK : set_choice(m, a, b, keep, stop, err);
}
