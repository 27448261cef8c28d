/* shape_pair.c - pairing the contours of two shapes: the cost of a pair,
 * an exact assignment level by level of the nesting trees, and the check
 * of a caller's pairing.
 *
 * DESIGN: a level is the children of one pair of paired contours (or the
 * two shapes' top-level contours). Its n contours of one side and m of
 * the other make an (n + m) square assignment: the n x m pair costs, a
 * diagonal of no-partner costs for each side, zeros where two no-partner
 * slots meet (the usual reduction of an assignment with optional partners
 * to a square one), solved exactly by the Hungarian method with
 * potentials in O((n + m)^3). A contour that finds no partner takes its
 * whole subtree with it: its holes have no parent to be paired under.
 */
#include <math.h>
#include <string.h>

#include "km/alloc.h"
#include "km/shape.h"
#include "kernels.h"
#include "shape_internal.h"
#include "status_internal.h"

#define TURN_SAMPLES 64
#define BIG 1e12

void km_shape_pair_costs_default(km_shape_pair_costs *c) {
  c->w_position = 1.0;
  c->w_size = 0.5;
  c->w_turning = 0.5;
  c->unpaired = 1.0;
}

void km_shape_pairs_free(km_shape_pair *pairs) {
  km__free(pairs);
}

/* Tangent angle less the uniform turn 2 pi r at TURN_SAMPLES equal
 * arc-length fractions of contour i's flattening (unwrapped). */
static void turning_samples(const km_shape *s, size_t i, double *out) {
  const double *P = s->flat + 2 * s->flat_off[i];
  size_t np = s->flat_off[i + 1] - s->flat_off[i];
  double total = 0.0;
  for (size_t k = 0; k + 1 < np; k++)
    total += hypot(P[2 * k + 2] - P[2 * k], P[2 * k + 3] - P[2 * k + 1]);
  double turn = s->role[i] == KM_ROLE_OUTER ? 2 * KM_PI : -2 * KM_PI;
  double acc = 0.0, prev = 0.0, unwrap = 0.0;
  size_t k = 0;
  for (int q = 0; q < TURN_SAMPLES; q++) {
    double want = total * q / TURN_SAMPLES, seg = 0.0;
    for (; k + 1 < np; k++) {
      seg = hypot(P[2 * k + 2] - P[2 * k], P[2 * k + 3] - P[2 * k + 1]);
      if (acc + seg > want || k + 2 == np) break;
      acc += seg;
    }
    double a = atan2(P[2 * k + 3] - P[2 * k + 1], P[2 * k + 2] - P[2 * k]);
    if (q > 0) {
      double d = a - prev;
      while (d > KM_PI) d -= 2 * KM_PI;
      while (d < -KM_PI) d += 2 * KM_PI;
      unwrap += d;
    } else {
      unwrap = a;
    }
    prev = a;
    out[q] = unwrap - turn * q / TURN_SAMPLES;
  }
}

/* min over cyclic shifts and a constant of the rms difference */
static double turning_distance(const double *ta, const double *tb) {
  double best = INFINITY;
  for (int sh = 0; sh < TURN_SAMPLES; sh++) {
    double sum = 0.0, sq = 0.0;
    for (int q = 0; q < TURN_SAMPLES; q++) {
      int r = q + sh;
      /* past the end the periodic part repeats; the uniform turn is gone */
      double d = ta[q] - tb[r % TURN_SAMPLES];
      sum += d;
      sq += d * d;
    }
    double mean = sum / TURN_SAMPLES;
    double var = sq / TURN_SAMPLES - mean * mean;
    if (var < best) best = var;
  }
  return sqrt(best > 0 ? best : 0.0);
}

static void unit_centroid(const km_shape *s, size_t i, double out[2]) {
  double w = s->box[2] - s->box[0], h = s->box[3] - s->box[1];
  double side = w > h ? w : h;
  out[0] = (s->centroid[2 * i] - s->box[0]) / side;
  out[1] = (s->centroid[2 * i + 1] - s->box[1]) / side;
}

static double pair_cost(const km_shape *a, size_t i, const double *ta,
                        const km_shape *b, size_t j, const double *tb,
                        const km_shape_pair_costs *c) {
  if (a->role[i] != b->role[j]) return BIG;
  double ca[2], cb[2];
  unit_centroid(a, i, ca);
  unit_centroid(b, j, cb);
  return c->w_position * hypot(ca[0] - cb[0], ca[1] - cb[1]) +
         c->w_size * fabs(log(a->area[i] / b->area[j])) +
         c->w_turning * turning_distance(ta, tb) / KM_PI;
}

/* Hungarian method with potentials (1-based internally): cost is N x N
 * row-major; *assign (out) gets the column of each row. Scratch of
 * 4 (N + 1) values. */
static km_status hungarian(const double *cost, size_t N, size_t *assign) {
  double *u = km__calloc(N + 1, sizeof *u), *v = km__calloc(N + 1, sizeof *v);
  double *minv = km__malloc((N + 1) * sizeof *minv);
  size_t *p = km__calloc(N + 1, sizeof *p),
         *way = km__calloc(N + 1, sizeof *way);
  bool *used = km__malloc((N + 1) * sizeof *used);
  km_status st = (u && v && minv && p && way && used) ? KM_OK : KM_ENOMEM;
  for (size_t i = 1; st == KM_OK && i <= N; i++) {
    p[0] = i;
    size_t j0 = 0;
    for (size_t j = 0; j <= N; j++) {
      minv[j] = INFINITY;
      used[j] = false;
    }
    do {
      used[j0] = true;
      size_t i0 = p[j0], j1 = 0;
      double delta = INFINITY;
      for (size_t j = 1; j <= N; j++) {
        if (used[j]) continue;
        double cur = cost[(i0 - 1) * N + (j - 1)] - u[i0] - v[j];
        if (cur < minv[j]) {
          minv[j] = cur;
          way[j] = j0;
        }
        if (minv[j] < delta) {
          delta = minv[j];
          j1 = j;
        }
      }
      for (size_t j = 0; j <= N; j++) {
        if (used[j]) {
          u[p[j]] += delta;
          v[j] -= delta;
        } else {
          minv[j] -= delta;
        }
      }
      j0 = j1;
    } while (p[j0] != 0);
    do {
      size_t j1 = way[j0];
      p[j0] = p[j1];
      j0 = j1;
    } while (j0);
  }
  for (size_t j = 1; st == KM_OK && j <= N; j++) assign[p[j] - 1] = j - 1;
  km__free(u);
  km__free(v);
  km__free(minv);
  km__free(p);
  km__free(way);
  km__free(used);
  return st;
}

/* The work of one pairing: both shapes' turning samples and the pairs
 * found so far. */
typedef struct pairing {
  const km_shape *a, *b;
  const km_shape_pair_costs *costs;
  double *ta, *tb;
  km_shape_pair *pairs;
  size_t npairs;
  km__poll poll;
} pairing;

static void add_pair(pairing *w, long i, long j) {
  w->pairs[w->npairs].from = i;
  w->pairs[w->npairs].to = j;
  w->npairs++;
}

/* contour i of s and all it contains, unpaired on side `from` */
static void add_subtree(pairing *w, const km_shape *s, size_t i, bool from) {
  add_pair(w, from ? (long)i : -1, from ? -1 : (long)i);
  for (size_t k = 0; k < s->ncontours; k++)
    if (s->parent[k] == (long)i) add_subtree(w, s, k, from);
}

static size_t children(const km_shape *s, long parent, size_t *out) {
  size_t n = 0;
  for (size_t k = 0; k < s->ncontours; k++)
    if (s->parent[k] == parent) out[n++] = k;
  return n;
}

static km_status level_matrix(pairing *w, const size_t *ia, size_t n,
                              const size_t *ib, size_t m, double *cost) {
  size_t N = n + m;
  for (size_t r = 0; r < N; r++)
    for (size_t c = 0; c < N; c++) {
      double x;
      if (r < n && c < m)
        x = pair_cost(w->a, ia[r], w->ta + TURN_SAMPLES * ia[r], w->b, ib[c],
                      w->tb + TURN_SAMPLES * ib[c], w->costs);
      else if (r < n)
        x = c - m == r ? w->costs->unpaired : BIG;
      else if (c < m)
        x = r - n == c ? w->costs->unpaired : BIG;
      else
        x = 0.0;
      cost[r * N + c] = x;
      if (km__poll_stop(&w->poll, TURN_SAMPLES / 4)) return KM_ECANCELLED;
    }
  return KM_OK;
}

/* Pair the children of pa (in a) with those of pb (in b), then recurse. */
static km_status pair_level(pairing *w, long pa, long pb) {
  size_t na = w->a->ncontours, nb = w->b->ncontours;
  size_t *ia = km__malloc((na + nb) * sizeof *ia);
  size_t *ib = km__malloc((nb + 1) * sizeof *ib), *as = NULL;
  double *cost = NULL;
  km_status st = (ia && ib) ? KM_OK : KM_ENOMEM;
  if (st != KM_OK) goto cleanup;
  size_t n = children(w->a, pa, ia), m = children(w->b, pb, ib), N = n + m;
  if (N == 0) goto cleanup;
  cost = km__malloc(N * N * sizeof *cost);
  as = km__malloc(N * sizeof *as);
  st = (cost && as) ? level_matrix(w, ia, n, ib, m, cost) : KM_ENOMEM;
  if (st == KM_OK) st = hungarian(cost, N, as);
  for (size_t r = 0; st == KM_OK && r < n; r++) {
    if (as[r] < m && cost[r * N + as[r]] < BIG) {
      add_pair(w, (long)ia[r], (long)ib[as[r]]);
      st = pair_level(w, (long)ia[r], (long)ib[as[r]]);
    } else {
      add_subtree(w, w->a, ia[r], true);
    }
  }
  for (size_t r = n; st == KM_OK && r < N; r++)
    if (as[r] < m) add_subtree(w, w->b, ib[as[r]], false);
cleanup:
  km__free(ia);
  km__free(ib);
  km__free(cost);
  km__free(as);
  return st;
}

static int pair_class(const km_shape_pair *p) {
  return p->from >= 0 && p->to >= 0 ? 0 : p->to < 0 ? 1 : 2;
}

static bool pair_before(const km_shape_pair *x, const km_shape_pair *y) {
  int cx = pair_class(x), cy = pair_class(y);
  if (cx != cy) return cx < cy;
  return cx == 2 ? x->to < y->to : x->from < y->from;
}

/* insertion sort: a few dozen pairs, and a stable order */
static void sort_pairs(km_shape_pair *p, size_t n) {
  for (size_t i = 1; i < n; i++) {
    km_shape_pair x = p[i];
    size_t j = i;
    for (; j > 0 && pair_before(&x, &p[j - 1]); j--) p[j] = p[j - 1];
    p[j] = x;
  }
}

static bool costs_ok(const km_shape_pair_costs *c) {
  return isfinite(c->w_position) && c->w_position >= 0 && isfinite(c->w_size) &&
         c->w_size >= 0 && isfinite(c->w_turning) && c->w_turning >= 0 &&
         isfinite(c->unpaired) && c->unpaired >= 0 && c->unpaired < BIG / 4;
}

km_status km_shape_pair_auto(const km_shape *a, const km_shape *b,
                             const km_shape_pair_costs *costs,
                             const km_stop *stop, km_shape_pair **pairs,
                             size_t *npairs, km_error *err) {
  km_shape_pair_costs def;
  km_shape_pair_costs_default(&def);
  if (!costs) costs = &def;
  if (!a || !b || !a->ncontours || !b->ncontours || !a->flat || !b->flat)
    return km__fail(err, KM_EINVAL, KM_FIELD_NONE, -1, NAN, "empty shape");
  if (!costs_ok(costs))
    return km__fail(err, KM_EINVAL, KM_FIELD_NONE, -1, NAN,
                    "pairing costs must be finite and not negative");
  pairing w;
  memset(&w, 0, sizeof w);
  w.a = a;
  w.b = b;
  w.costs = costs;
  km__poll_init(&w.poll, stop);
  w.ta = km__malloc(a->ncontours * TURN_SAMPLES * sizeof *w.ta);
  w.tb = km__malloc(b->ncontours * TURN_SAMPLES * sizeof *w.tb);
  w.pairs = km__malloc((a->ncontours + b->ncontours) * sizeof *w.pairs);
  km_status st = (w.ta && w.tb && w.pairs) ? KM_OK : KM_ENOMEM;
  for (size_t i = 0; st == KM_OK && i < a->ncontours; i++)
    turning_samples(a, i, w.ta + TURN_SAMPLES * i);
  for (size_t j = 0; st == KM_OK && j < b->ncontours; j++)
    turning_samples(b, j, w.tb + TURN_SAMPLES * j);
  if (st == KM_OK) st = pair_level(&w, -1, -1);
  if (st != KM_OK) goto cleanup;
  sort_pairs(w.pairs, w.npairs);
  *pairs = w.pairs;
  *npairs = w.npairs;
  w.pairs = NULL;
cleanup:
  km__free(w.ta);
  km__free(w.tb);
  km__free(w.pairs);
  if (st == KM_ENOMEM)
    km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, "out of memory");
  if (st == KM_ECANCELLED) km__stopped(err);
  return st;
}

static km_status bad_pair(km_error *err, size_t k, const char *why) {
  return km__fail(err, KM_EMATCH, KM_FIELD_MATCHES, (long)k, NAN,
                  "pair %zu: %s", k, why);
}

/* the partner of contour i of side `from` in pairs, -2 if in none */
static long partner(const km_shape_pair *pairs, size_t npairs, long i,
                    bool from) {
  for (size_t k = 0; k < npairs; k++)
    if ((from ? pairs[k].from : pairs[k].to) == i)
      return from ? pairs[k].to : pairs[k].from;
  return -2;
}

static km_status check_one(const km_shape *a, const km_shape *b,
                           const km_shape_pair *pairs, size_t npairs, size_t k,
                           int *seen_a, int *seen_b, km_error *err) {
  long i = pairs[k].from, j = pairs[k].to;
  if (i < -1 || j < -1 || i >= (long)a->ncontours || j >= (long)b->ncontours)
    return bad_pair(err, k, "a contour index out of range");
  if (i < 0 && j < 0) return bad_pair(err, k, "no contour on either side");
  if ((i >= 0 && seen_a[i]++) || (j >= 0 && seen_b[j]++))
    return bad_pair(err, k, "a contour in two pairs");
  if (i < 0 || j < 0) return KM_OK;
  if (a->role[i] != b->role[j])
    return bad_pair(err, k, "an outer contour paired with a hole");
  long pa = a->parent[i], pb = b->parent[j];
  if ((pa < 0) != (pb < 0) ||
      (pa >= 0 && partner(pairs, npairs, pa, true) != pb))
    return bad_pair(err, k, "the parents of the contours are not paired");
  return KM_OK;
}

km_status km_shape_pair_check(const km_shape *a, const km_shape *b,
                              const km_shape_pair *pairs, size_t npairs,
                              km_error *err) {
  if (!a || !b || !a->ncontours || !b->ncontours || (!pairs && npairs))
    return km__fail(err, KM_EINVAL, KM_FIELD_MATCHES, -1, NAN,
                    "shapes or pairs missing");
  int *seen_a = km__calloc(a->ncontours, sizeof *seen_a);
  int *seen_b = km__calloc(b->ncontours, sizeof *seen_b);
  km_status st = (seen_a && seen_b) ? KM_OK : KM_ENOMEM;
  if (st == KM_ENOMEM)
    km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, "out of memory");
  for (size_t k = 0; st == KM_OK && k < npairs; k++)
    st = check_one(a, b, pairs, npairs, k, seen_a, seen_b, err);
  for (size_t i = 0; st == KM_OK && i < a->ncontours; i++)
    if (!seen_a[i])
      st = km__fail(err, KM_EMATCH, KM_FIELD_MATCHES, (long)npairs, NAN,
                    "contour %zu of the first shape is in no pair", i);
  for (size_t j = 0; st == KM_OK && j < b->ncontours; j++)
    if (!seen_b[j])
      st = km__fail(err, KM_EMATCH, KM_FIELD_MATCHES, (long)npairs, NAN,
                    "contour %zu of the second shape is in no pair", j);
  km__free(seen_a);
  km__free(seen_b);
  return st;
}
