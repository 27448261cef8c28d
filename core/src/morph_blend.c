/* morph_blend.c - a frame's curvature blended from the inputs', along the
 * correspondence.
 *
 * DESIGN.
 * Correspondence: a monotone piecewise-linear map between the normalised
 * arc lengths r_a and r_b, given by match pairs (0,0), (r_a1, r_b1), ...,
 * (1,1). Segment k has lengths la_k, lb_k and, at time t, l_k = (1-t) la_k
 * + t lb_k, so every frame has length L_t = (1-t) La + t Lb.
 * Blend: on segment k the frame's tangent angle is
 *   turning (default): theta_t = (1-t) theta_a + t theta_b at corresponding
 *     points, i.e. kappa_t = ((1-t) la_k kappa_a + t lb_k kappa_b) / l_k,
 *     corner turns weighted (1-t) and t. A convex combination: |kappa_t| never
 *     exceeds the inputs' maximum, total turning is exact, circles stay
 *     circles, and with equal lengths it is the paper's formula.
 *   paper: kappa_t = (1-t) kappa_a + t kappa_b literally (corners as the
 *     Dirac deltas they are, scaled by l_k / la_k and l_k / lb_k).
 * theta is continuous across segments, which is the paper's G2 joining of
 * matched segments; proportional matches give exactly the global morph.
 * With matches the frames between the ends take the smooth correspondence
 * below where it stays monotone.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "km/alloc.h"
#include "morph_blend.h"

typedef struct corner_list {
  km_corner *c;
  size_t n, cap;
} corner_list;

static km_status corner_push(corner_list *cl, double s, double turn) {
  if (cl->n == cl->cap) {
    size_t cap = cl->cap ? 2 * cl->cap : 16;
    km_corner *c = km__realloc(cl->c, cap * sizeof *c);
    if (!c) return KM_ENOMEM;
    cl->c = c;
    cl->cap = cap;
  }
  cl->c[cl->n].s = s;
  cl->c[cl->n].turn = turn;
  cl->n++;
  return KM_OK;
}

/* ---- smooth correspondence ---------------------------------------------
 * With matches, a piecewise-linear correspondence makes ds_a/ds_t jump at
 * every match, and with it the blended curvature: the join would be G1
 * only. Here ds_a/ds_t = alpha(x) is piecewise linear in the frame's arc
 * length x - continuous at the matches (the mean of the neighbouring
 * segments' ratios; beside a segment under a thousandth of its
 * neighbour's length the neighbour keeps nearer its own, see influence),
 * with a middle node per segment chosen so the segment
 * still covers exactly its part of a - so s_a(x) is a C1 piecewise
 * quadratic and s_b(x) = (x - (1-t) s_a(x)) / t follows. Then
 *   kappa_t(x) = (1-t) kappa_a(s_a(x)) alpha(x) + t kappa_b(s_b(x)) beta(x)
 * (turning blend; beta = ds_b/ds_t, (1-t) alpha + t beta = 1, a convex
 * combination still) is continuous at matches and exactly a polynomial of
 * degree 2d+1 on each piece (kappa of degree d composed with a quadratic),
 * which is computed by interpolation at Chebyshev points. */

typedef struct quad_map {
  double x0, h;        /* frame interval [x0, x0 + h] */
  double a0, al0, al1; /* s_a(x0), alpha at both ends */
} quad_map;

static double qm_sa(const quad_map *q, double x) {
  double u = x - q->x0;
  return q->a0 + q->al0 * u + (q->al1 - q->al0) * u * u / (2 * q->h);
}

/* x in [x0, x0+h] with s_a(x) = y (s_a increasing there) */
static double qm_inv_a(const quad_map *q, double y) {
  double lo = q->x0, hi = q->x0 + q->h;
  for (int it = 0; it < 200 && hi - lo > 1e-15 * (fabs(lo) + q->h); it++) {
    double mid = 0.5 * (lo + hi);
    if (qm_sa(q, mid) < y)
      lo = mid;
    else
      hi = mid;
  }
  return 0.5 * (lo + hi);
}

static double sb_of(const quad_map *q, double x, double t) {
  return (x - (1 - t) * qm_sa(q, x)) / t;
}

static double qm_inv_b(const quad_map *q, double y, double t) {
  double lo = q->x0, hi = q->x0 + q->h;
  for (int it = 0; it < 200 && hi - lo > 1e-15 * (fabs(lo) + q->h); it++) {
    double mid = 0.5 * (lo + hi);
    if (sb_of(q, mid, t) < y)
      lo = mid;
    else
      hi = mid;
  }
  return 0.5 * (lo + hi);
}

/* Solve the Bernstein interpolation system (n+1 points) in place. */
static bool bern_interp(const double *u, double *val, int n) {
  double A[(KM_MAX_FN_DEGREE + 1) * (KM_MAX_FN_DEGREE + 1)];
  for (int j = 0; j <= n; j++) km__bernstein_basis(u[j], n, A + j * (n + 1));
  return km__solve_dense(A, val, n + 1);
}

/* How much a segment of frame length lk moves alpha at the end of its
 * neighbour (length lj) at their common match: fully (one value there,
 * G2) unless it is shorter than SMOOTH_SHARE of the neighbour, then in
 * proportion (G1 there). A match next to an end or to another match makes
 * a segment 1e-300 of its neighbour, whose ratio to it may be anything:
 * fully shared, it would bend the neighbour's correspondence over half the
 * neighbour, and the frames would not tend to the morph without that match
 * as it approaches the end (a circle into a circle with the match (1e-9,
 * 1e-7) gave a frame 4.7e-2 off the circle of radius 1 + t). */
#define SMOOTH_SHARE 1e-3
static double influence(double lk, double lj) {
  return lk >= SMOOTH_SHARE * lj ? 1.0 : lk / (SMOOTH_SHARE * lj);
}

/* alpha at the end of a segment (ratio rho_k, length lk) beside a
 * neighbour (ratio rho_j, length lj): their mean, or toward rho_k as the
 * neighbour is shorter (see influence) */
static double end_value(double rho_k, double lk, double rho_j, double lj) {
  double w = influence(lj, lk), mean = 0.5 * (rho_k + rho_j);
  return w == 1.0 ? mean : rho_k + w * (mean - rho_k);
}

/* alpha = ds_a/ds_t at both ends of each segment (nl[k], nr[k]) and at its
 * middle (mid[k]), the middle chosen so the segment covers exactly its part
 * of a: (nl + 2 mid + nr) / 4 = rho[k]. Returns KM_EINVAL when alpha and
 * beta cannot be kept positive. */
static km_status smooth_nodes(const double *rho, const double *len, size_t K,
                              bool closed, double t, double *nl, double *nr,
                              double *mid) {
  for (size_t k = 0; k + 1 < K; k++) {
    nr[k] = end_value(rho[k], len[k], rho[k + 1], len[k + 1]);
    nl[k + 1] = end_value(rho[k + 1], len[k + 1], rho[k], len[k]);
  }
  if (closed) {
    nl[0] = end_value(rho[0], len[0], rho[K - 1], len[K - 1]);
    nr[K - 1] = end_value(rho[K - 1], len[K - 1], rho[0], len[0]);
  } else {
    nl[0] = rho[0];
    nr[K - 1] = rho[K - 1];
  }
  double amax = 1.0 / (1 - t);
  km_status st = KM_EINVAL;
  /* alpha and beta must stay positive at the middle nodes too: where a
   * segment's ratio differs much from its neighbours', pull its end nodes
   * toward its own ratio (at the ratio itself the segment is feasible), by
   * as many halvings of their distance as this segment alone needs (a
   * ratio 1e-300 of its neighbours' needs a thousand) */
  for (int round = 0; round < 64 && st; round++) {
    st = KM_OK;
    for (size_t k = 0; k < K; k++) {
      mid[k] = 2 * rho[k] - 0.5 * (nl[k] + nr[k]);
      double lo = 0.02 * fmin(rho[k], amax - rho[k]);
      if (mid[k] > lo && mid[k] < amax - lo) continue;
      st = KM_EINVAL;
      double dev = rho[k] - mid[k];
      double room = dev > 0 ? rho[k] - lo : amax - lo - rho[k];
      int halvings = 1;
      if (room > 0 && fabs(dev) > room) frexp(fabs(dev) / room, &halvings);
      if (halvings < 1) halvings = 1;
      double l0 = nl[k], r0 = nr[k];
      nl[k] = rho[k] + ldexp(nl[k] - rho[k], -halvings);
      nr[k] = rho[k] + ldexp(nr[k] - rho[k], -halvings);
      if (k > 0 || closed) {
        size_t j = k > 0 ? k - 1 : K - 1;
        double w = influence(len[k], len[j]);
        nr[j] = w == 1.0 ? nl[k] : nr[j] + w * (nl[k] - l0);
      }
      if (k + 1 < K || closed) {
        size_t j = k + 1 < K ? k + 1 : 0;
        double w = influence(len[k], len[j]);
        nl[j] = w == 1.0 ? nr[k] : nl[j] + w * (nr[k] - r0);
      }
    }
  }
  return st;
}

/* The smooth correspondence of frame t: per segment k its ratio rho[k] =
 * ds_a/ds_t, its frame length len[k] and start S[k] (S[K] the frame's
 * length), alpha's nodes (nl, mid, nr), and s_a as 2 K quadratic maps. */
typedef struct smooth_map {
  size_t K, nq;
  double *buf; /* the six arrays below in one block */
  double *rho, *len, *S, *nl, *nr, *mid;
  quad_map *qm;
} smooth_map;

static void smooth_map_free(smooth_map *sm) {
  km__free(sm->buf);
  km__free(sm->qm);
}

/* KM_EINVAL when alpha and beta cannot be kept positive, KM_ENOMEM. */
static km_status smooth_map_make(const km_morph *m, double t, smooth_map *sm) {
  double La = m->in[0].sig.length, Lb = m->in[1].sig.length;
  size_t K = sm->K = m->nk - 1;
  sm->nq = 2 * K;
  double *buf = sm->buf = km__malloc((6 * K + 1) * sizeof(double));
  if (!buf) return KM_ENOMEM;
  double *rho = sm->rho = buf, *len = sm->len = buf + K,
         *S = sm->S = buf + 2 * K;
  sm->nl = buf + 3 * K + 1;
  sm->nr = buf + 4 * K + 1;
  sm->mid = buf + 5 * K + 1;
  S[0] = 0.0;
  for (size_t k = 0; k < K; k++) {
    double la = (m->ra[k + 1] - m->ra[k]) * La,
           lb = (m->rb[k + 1] - m->rb[k]) * Lb;
    len[k] = (1 - t) * la + t * lb;
    rho[k] = la / len[k];
    S[k + 1] = S[k] + len[k];
  }
  km_status st =
      smooth_nodes(rho, len, K, m->closed, t, sm->nl, sm->nr, sm->mid);
  if (st) return st;
  quad_map *qm = sm->qm = km__malloc(2 * K * sizeof *qm);
  if (!qm) return KM_ENOMEM;
  double sa_at = 0.0;
  for (size_t k = 0; k < K; k++) {
    double h = 0.5 * len[k];
    qm[2 * k] = (quad_map){S[k], h, sa_at, sm->nl[k], sm->mid[k]};
    sa_at = qm_sa(&qm[2 * k], S[k] + h);
    qm[2 * k + 1] = (quad_map){S[k] + h, h, sa_at, sm->mid[k], sm->nr[k]};
    sa_at = m->ra[k + 1] * La; /* exact at the match */
  }
  return KM_OK;
}

/* The frame's breaks (*br, *nbr of them, sorted, distinct; the caller
 * frees *br): segment ends, middles, and the images of both inputs'
 * breaks. */
static km_status smooth_breaks(const km_morph *m, double t,
                               const smooth_map *sm, double **br_out,
                               size_t *nbr) {
  const km__input *a = &m->in[0], *b = &m->in[1];
  const quad_map *qm = sm->qm;
  size_t K = sm->K, nq = sm->nq, nb = 0;
  size_t cap = 2 * K + 1 + a->kappa.m + b->kappa.m + 2;
  double *br = km__malloc(cap * sizeof(double));
  if (!br) return KM_ENOMEM;
  for (size_t q = 0; q < nq; q++) br[nb++] = qm[q].x0;
  br[nb++] = sm->S[K];
  for (size_t i = 1; i < a->kappa.m; i++) {
    double y = a->kappa.x[i];
    for (size_t q = 0; q < nq; q++) {
      double y0 = qm[q].a0, y1 = qm_sa(&qm[q], qm[q].x0 + qm[q].h);
      if (y > y0 && y < y1) {
        br[nb++] = qm_inv_a(&qm[q], y);
        break;
      }
    }
  }
  for (size_t i = 1; i < b->kappa.m; i++) {
    double y = b->kappa.x[i];
    for (size_t q = 0; q < nq; q++) {
      double y0 = sb_of(&qm[q], qm[q].x0, t),
             y1 = sb_of(&qm[q], qm[q].x0 + qm[q].h, t);
      if (y > y0 && y < y1) {
        br[nb++] = qm_inv_b(&qm[q], y, t);
        break;
      }
    }
  }
  qsort(br, nb, sizeof(double), km__cmp_double);
  size_t mb = 0;
  for (size_t i = 0; i < nb; i++)
    if (mb == 0 || br[i] - br[mb - 1] > 1e-13 * sm->S[K]) br[mb++] = br[i];
  br[mb - 1] = sm->S[K];
  *br_out = br;
  *nbr = mb;
  return KM_OK;
}

/* The blended curvature on the pieces between the breaks br (mb of
 * them), each exactly a polynomial of degree 2d + 1, by interpolation at
 * Chebyshev points. KM_ENOCONVERGE when an interpolation is singular. */
static km_status smooth_pieces(const km_morph *m, double t,
                               const smooth_map *sm, const double *br,
                               size_t mb, km_pp *o) {
  const km__input *a = &m->in[0], *b = &m->in[1];
  double La = a->sig.length, Lb = b->sig.length;
  int da = a->kappa.degree, db = b->kappa.degree;
  int dd = 2 * (da > db ? da : db) + 1;
  if (dd > KM_MAX_FN_DEGREE) dd = KM_MAX_FN_DEGREE;
  km_status st = km__pp_alloc(o, dd, mb - 1);
  if (st) return st;
  size_t q = 0;
  for (size_t i = 0; i + 1 < mb; i++) {
    double x0 = br[i], x1 = br[i + 1], xm = 0.5 * (x0 + x1);
    while (q + 1 < sm->nq && xm > sm->qm[q].x0 + sm->qm[q].h) q++;
    const quad_map *Q = &sm->qm[q];
    double u[KM_MAX_FN_DEGREE + 1], v[KM_MAX_FN_DEGREE + 1];
    for (int j = 0; j <= dd; j++) {
      u[j] = 0.5 - 0.5 * cos(KM_PI * (j + 0.5) / (dd + 1));
      double x = x0 + u[j] * (x1 - x0);
      double al = Q->al0 + (Q->al1 - Q->al0) * (x - Q->x0) / Q->h;
      double be = (1 - (1 - t) * al) / t;
      double sa = qm_sa(Q, x), sb = (x - (1 - t) * sa) / t;
      double ka = km__pp_eval(&a->kappa, fmin(fmax(sa, 0.0), La));
      double kb = km__pp_eval(&b->kappa, fmin(fmax(sb, 0.0), Lb));
      v[j] = m->opt.blend == KM_BLEND_PAPER ? (1 - t) * ka + t * kb
                                            : (1 - t) * ka * al + t * kb * be;
    }
    if (!bern_interp(u, v, dd)) return KM_ENOCONVERGE;
    memcpy(o->c + i * (size_t)(dd + 1), v, (size_t)(dd + 1) * sizeof(double));
    o->x[i] = x0;
  }
  o->x[0] = 0.0;
  o->x[mb - 1] = sm->S[sm->K];
  return KM_OK;
}

/* Frame position of input w's arc length y (0 <= y <= L): the first
 * segment whose image reaches y - the ends of neighbouring images agree
 * only up to rounding, and a corner at a match (as "auto" puts them) must
 * not fall between them. */
static double smooth_image(const smooth_map *sm, int w, double y, double L,
                           double t) {
  const quad_map *qm = sm->qm;
  if (y >= L * (1 - 1e-12)) return sm->S[sm->K];
  if (y <= 0) return 0.0;
  for (size_t k = 0; k < sm->nq; k++) {
    double y1 = w ? sb_of(&qm[k], qm[k].x0 + qm[k].h, t)
                  : qm_sa(&qm[k], qm[k].x0 + qm[k].h);
    if (y <= y1 + 1e-12 * L || k + 1 == sm->nq)
      return w ? qm_inv_b(&qm[k], y, t) : qm_inv_a(&qm[k], y);
  }
  return -1.0;
}

/* Corners at the images of the inputs' corners. */
static km_status smooth_corners(const km_morph *m, double t,
                                const smooth_map *sm, corner_list *cl) {
  const quad_map *qm = sm->qm;
  km_status st = KM_OK;
  for (int w = 0; w < 2 && !st; w++) {
    const km__input *in = &m->in[w];
    double cw = w ? t : 1 - t, L = in->sig.length;
    for (size_t i = 0; i < in->sig.ncorners && !st; i++) {
      double x = smooth_image(sm, w, in->sig.corners[i].s, L, t);
      if (x < 0) continue;
      double turn = cw * in->sig.corners[i].turn;
      if (m->opt.blend == KM_BLEND_PAPER) {
        /* the delta scales with dx/ds of that input */
        size_t k = 0;
        while (k + 1 < sm->nq && x > qm[k].x0 + qm[k].h) k++;
        double al =
            qm[k].al0 + (qm[k].al1 - qm[k].al0) * (x - qm[k].x0) / qm[k].h;
        double be = (1 - (1 - t) * al) / t;
        turn /= w ? be : al;
        if (turn >= KM_PI) turn = KM_PI - 1e-9;
        if (turn <= -KM_PI) turn = -KM_PI + 1e-9;
      }
      st = corner_push(cl, x, turn);
    }
  }
  return st;
}

/* The frame's curvature pieces (*out) and corners (into cl) under the
 * smooth correspondence. Returns KM_EINVAL when the smooth map is not
 * monotone for these matches (the caller then keeps the piecewise-linear
 * correspondence). */
static km_status blend_smooth(const km_morph *m, double t, km_pp *out,
                              corner_list *cl) {
  smooth_map sm = {0, 0, NULL, NULL, NULL, NULL, NULL, NULL, NULL, NULL};
  double *br = NULL;
  size_t mb = 0;
  km_pp o;
  km__pp_init(&o);
  km_status st = smooth_map_make(m, t, &sm);
  if (!st) st = smooth_breaks(m, t, &sm, &br, &mb);
  if (!st) st = smooth_pieces(m, t, &sm, br, mb, &o);
  if (!st) st = smooth_corners(m, t, &sm, cl);
  if (!st) {
    *out = o;
    km__pp_init(&o);
  }
  km__pp_free(&o);
  km__free(br);
  smooth_map_free(&sm);
  return st;
}

/* Pieces of a frame's curvature shorter than this fraction of its length
 * are merged into a neighbour: ten times below the smallest tolerance
 * honoured (KM_MIN_RELATIVE_TOLERANCE), some forty ulps of the length, so
 * the breaks kept are distinct after rounding (a knot of the curvature
 * that repeated would have multiplicity 2 (d + 1), an invalid spline). */
#define SHORT_PIECE 1e-14

/* Pieces of p restricted to [x0, x1], or where a match difference
 * underflows to x1 == x0 (a subnormal fraction of a length below 1) the
 * one value there as a constant: its length is only a ratio to the
 * blend. */
static km_status slice_or_point(km_pp *out, const km_pp *p, double x0,
                                double x1) {
  if (x1 > x0) return km__pp_slice(out, p, x0, x1);
  km_status st = km__pp_alloc(out, 0, 1);
  if (st) return st;
  out->x[0] = 0.0;
  out->x[1] = 1.0;
  out->c[0] = km__pp_eval(p, x0);
  return KM_OK;
}

/* The blended curvature on segment k of frame t, over [S, S + l] of the
 * frame (l > 0), under the piecewise-linear correspondence. */
static km_status blend_segment(const km_morph *m, double t, size_t k, double S,
                               double l, km_pp *out) {
  const km__input *a = &m->in[0], *b = &m->in[1];
  double La = a->sig.length, Lb = b->sig.length;
  double la = (m->ra[k + 1] - m->ra[k]) * La,
         lb = (m->rb[k + 1] - m->rb[k]) * Lb;
  double wa = 1 - t, wb = t;
  if (m->opt.blend != KM_BLEND_PAPER) {
    wa = (1 - t) * la / l;
    wb = t * lb / l;
  }
  km_pp sa, sb;
  km__pp_init(&sa);
  km__pp_init(&sb);
  km_status st =
      slice_or_point(&sa, &a->kappa, m->ra[k] * La, m->ra[k + 1] * La);
  if (!st)
    st = slice_or_point(&sb, &b->kappa, m->rb[k] * Lb, m->rb[k + 1] * Lb);
  if (!st) st = km__pp_blend(out, &sa, wa, &sb, wb, S, S + l);
  km__pp_free(&sa);
  km__pp_free(&sb);
  return st;
}

/* Paper blend: a corner's delta scales with the frame's length over the
 * input's on its segment; an input segment of no length (a subnormal
 * match difference) scales it past any bound, which the caller clamps. */
static double corner_scale(double l, double lin) {
  return lin > 0 ? l / lin : INFINITY;
}

/* Merge pieces of p shorter than h into a neighbour (the one before, or
 * after for the first): the neighbour's polynomial covers them, stretched
 * by at most h, which moves the function by under h times its slope. */
static void drop_short_pieces(km_pp *p, double h) {
  size_t q = 0, stride = (size_t)(p->degree + 1);
  double end = p->x[p->m];
  for (size_t i = 0; i < p->m; i++) {
    if (!(p->x[i + 1] - p->x[i] > h)) continue;
    p->x[q] = q == 0 ? p->x[0] : p->x[i];
    if (q != i)
      memmove(p->c + q * stride, p->c + i * stride, stride * sizeof(double));
    q++;
  }
  if (q == 0) q = 1; /* all short (a frame of rounding's length) */
  p->x[q] = end;
  p->m = q;
}

/* Corners of both inputs on segment k of frame t (at [S, S + l] of the
 * frame, la and lb long on the inputs; a point of the frame when
 * point), weighted by the blend. */
static km_status segment_corners(const km_morph *m, double t, size_t k,
                                 double S, double l, double la, double lb,
                                 bool point, corner_list *cl) {
  double cwa =
      m->opt.blend == KM_BLEND_PAPER ? (1 - t) * corner_scale(l, la) : (1 - t);
  double cwb = m->opt.blend == KM_BLEND_PAPER ? t * corner_scale(l, lb) : t;
  km_status st = KM_OK;
  for (int w = 0; w < 2 && !st; w++) {
    const km__input *in = &m->in[w];
    double L = in->sig.length, r0 = w ? m->rb[k] : m->ra[k],
           r1 = w ? m->rb[k + 1] : m->ra[k + 1];
    double cw = w ? cwb : cwa;
    if (cw == 0) continue;
    for (size_t i = 0; i < in->sig.ncorners && !st; i++) {
      double r = in->sig.corners[i].s / L;
      bool last = k + 2 == m->nk;
      if (r < r0 || r > r1 || (r == r1 && !last)) continue;
      double turn = cw * in->sig.corners[i].turn;
      if (turn >= KM_PI) turn = KM_PI - 1e-9;
      if (turn <= -KM_PI) turn = -KM_PI + 1e-9;
      st = corner_push(cl, point ? S : S + (r - r0) / (r1 - r0) * l, turn);
    }
  }
  return st;
}

/* The frame's curvature pieces (*whole) and corners (into cl) under the
 * piecewise-linear correspondence, segment by segment (segs: room for
 * nk - 1 of them, initialised; the caller frees them). */
static km_status blend_linear(const km_morph *m, double t, km_pp *segs,
                              km_pp *whole, corner_list *cl) {
  double La = m->in[0].sig.length, Lb = m->in[1].sig.length;
  double Lt = (1 - t) * La + t * Lb, S = 0.0;
  size_t total = 0;
  int deg = 0;
  km_status st = KM_OK;
  for (size_t k = 0; !st && k + 1 < m->nk; k++) {
    double la = (m->ra[k + 1] - m->ra[k]) * La,
           lb = (m->rb[k + 1] - m->rb[k]) * Lb;
    double l = (1 - t) * la + t * lb;
    /* a segment shorter than the frame resolves (a match next to an end or
     * to another match, on the side t weighs) is a point of the frame:
     * its corners stay, its pieces would end within rounding of where
     * they start */
    bool point = !(l > SHORT_PIECE * Lt);
    if (!point) {
      st = blend_segment(m, t, k, S, l, &segs[k]);
      if (st) break;
      total += segs[k].m;
      if (segs[k].degree > deg) deg = segs[k].degree;
    }
    st = segment_corners(m, t, k, S, l, la, lb, point, cl);
    S += l;
  }
  if (!st) st = km__pp_alloc(whole, deg, total);
  if (st) return st;
  size_t q = 0;
  for (size_t k = 0; k + 1 < m->nk; k++) {
    for (size_t i = 0; i < segs[k].m; i++, q++) {
      whole->x[q] = segs[k].x[i];
      km__bern_elevate(segs[k].c + i * (size_t)(segs[k].degree + 1),
                       segs[k].degree, deg, whole->c + q * (size_t)(deg + 1));
    }
  }
  whole->x[0] = 0.0;
  whole->x[total] = Lt;
  return KM_OK;
}

/* Corners at the same place (within 1e-12 Lt) merged, clamped below a
 * half turn and those of no turn dropped; returns how many stay. */
static size_t merge_corners(corner_list *cl, double Lt) {
  if (cl->n > 1) qsort(cl->c, cl->n, sizeof *cl->c, km__cmp_corner);
  size_t nc = 0;
  for (size_t i = 0; i < cl->n; i++) {
    if (cl->c[i].s > Lt) cl->c[i].s = Lt;
    if (nc > 0 && cl->c[i].s - cl->c[nc - 1].s <= 1e-12 * Lt)
      cl->c[nc - 1].turn += cl->c[i].turn;
    else
      cl->c[nc++] = cl->c[i];
  }
  /* the paper blend's deltas are clamped below a half turn one by one;
   * two at one place (where a segment of one input has almost no length
   * and scales its corners past any bound) must not sum beyond it */
  for (size_t i = 0; i < nc; i++)
    cl->c[i].turn = fmax(fmin(cl->c[i].turn, KM_PI - 1e-9), -KM_PI + 1e-9);
  size_t keep = 0;
  for (size_t i = 0; i < nc; i++)
    if (fabs(cl->c[i].turn) > 1e-15) cl->c[keep++] = cl->c[i];
  return keep;
}

/* The blend's curvature into *whole and its corners into *cl (the
 * caller frees both); statuses as km__blend_signature, no message. */
static km_status blend_parts(const km_morph *m, double t, km_pp *whole,
                             corner_list *cl) {
  const km__input *a = &m->in[0], *b = &m->in[1];
  double Lt = (1 - t) * a->sig.length + t * b->sig.length;
  km_pp *segs = km__calloc(m->nk - 1, sizeof *segs);
  km_status st = segs ? KM_OK : KM_ENOMEM;
  bool smooth = false;
  if (!st && m->nk > 2 && t > 0 && t < 1) {
    km_status ss = blend_smooth(m, t, whole, cl);
    if (ss == KM_OK)
      smooth = true;
    else if (ss != KM_EINVAL)
      st = ss;
  }
  if (!st && !smooth) st = blend_linear(m, t, segs, whole, cl);
  if (!st) drop_short_pieces(whole, SHORT_PIECE * Lt);
  if (segs)
    for (size_t k = 0; k + 1 < m->nk; k++) km__pp_free(&segs[k]);
  km__free(segs);
  return st;
}

km_status km__blend_signature(const km_morph *m, double t, km_signature *out,
                              km_error *err) {
  const km__input *a = &m->in[0], *b = &m->in[1];
  double Lt = (1 - t) * a->sig.length + t * b->sig.length;
  corner_list cl = {NULL, 0, 0};
  km_pp whole;
  km__pp_init(&whole);
  km_fn kf;
  km_fn_init(&kf);
  km_status st = blend_parts(m, t, &whole, &cl);
  if (st) goto done;
  size_t keep = merge_corners(&cl, Lt);
  st = km__pp_to_fn(&kf, &whole);
  if (st) goto done;
  double phia = a->sig.angle, phib = b->sig.angle;
  phib = phia + km__wrap_angle(phib - phia);
  double origin[2] = {0, 0};
  st = km_signature_create(out, Lt, origin, (1 - t) * phia + t * phib, &kf,
                           cl.c, keep, m->closed, err);
done:
  km_fn_free(&kf);
  km__pp_free(&whole);
  km__free(cl.c);
  if (st == KM_ENOMEM) km__fail(err, st, KM_FIELD_NONE, -1, NAN, NULL);
  return st;
}

/* frame arc length s -> normalised positions on a and b */
void km__corresponding(const km_morph *m, double t, double s, double *ra,
                       double *rb) {
  double La = m->in[0].sig.length, Lb = m->in[1].sig.length, S = 0.0;
  for (size_t k = 0; k + 1 < m->nk; k++) {
    double la = (m->ra[k + 1] - m->ra[k]) * La,
           lb = (m->rb[k + 1] - m->rb[k]) * Lb;
    double l = (1 - t) * la + t * lb;
    if (s <= S + l || k + 2 == m->nk) {
      double f = l > 0 ? (s - S) / l : 0.0;
      if (f < 0) f = 0;
      if (f > 1) f = 1;
      *ra = m->ra[k] + f * (m->ra[k + 1] - m->ra[k]);
      *rb = m->rb[k] + f * (m->rb[k + 1] - m->rb[k]);
      return;
    }
    S += l;
  }
  *ra = *rb = 1.0;
}
