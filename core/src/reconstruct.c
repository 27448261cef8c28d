/* reconstruct.c - curves from curvature signatures.
 *
 * DESIGN. theta(s) = angle + integral of kappa + corner turns is exact: on
 * every piece of kappa it is a polynomial (the Bernstein antiderivative).
 * Positions C(s) = start + integral of (cos theta, sin theta) are integrated
 * by 8-point Gauss-Legendre on chunks over which theta moves at most half
 * a radian, which puts the quadrature error at rounding level.
 *
 * The output is a piecewise Hermite B-spline in the arc-length parameter:
 * cubic pieces match position and unit tangent at both ends (C1), quintic
 * pieces also curvature (C2). Because the exact curve has unit speed,
 * |C^(m)| <= B_{m-1}(|kappa|, |kappa'|, ...) (complete Bell polynomial),
 * and the Hermite remainder has a one-signed Peano kernel, so on a piece of
 * length h
 *     cubic:   |C - H| <= h^4 / 384   * B_3(k0, k1, k2)
 *     quintic: |C - H| <= h^6 / 46080 * B_5(k0, k1, k2, k3, k4)
 * with k_j bounds on |kappa^(j)| over the piece (Bernstein coefficients of
 * the restricted polynomial). That is a bound at equal s. A cubic piece
 * may instead take the end speeds of a circular arc of its turning
 * (shape_bound): its parameter then leaves arc length between the knots,
 * but its distance to the curve drops from O(h^4) to O(h^6) where kappa
 * varies little (the unit circle at 1e-9: 64 pieces, not 260). Pieces are
 * split until the bound meets the tolerance, each taking the smaller of
 * the two; the reported error is the largest bound plus rounding, so it is
 * never below the true error.
 */
#include <math.h>
#include <string.h>

#include "internal.h"
#include "km/alloc.h"
#include "km/limits.h"
#include "km/reconstruct.h"

#define MAXD (KM_MAX_FN_DEGREE + 2)

/* theta as pieces: breaks include kappa's and the corners' positions;
 * kappa pieces kept beside for the bounds. */
typedef struct theta_pieces {
  km_pp kappa; /* degree dk */
  km_pp theta; /* degree dk + 1, same breaks */
} theta_pieces;

static void theta_pieces_free(theta_pieces *tp) {
  km__pp_free(&tp->kappa);
  km__pp_free(&tp->theta);
}

km_status km__build_theta(const km_signature *sig, km_pp *kappa, km_pp *theta) {
  theta_pieces tps, *tp = &tps;
  km_pp k0;
  km__pp_init(&k0);
  km__pp_init(&tp->kappa);
  km__pp_init(&tp->theta);
  km_status st = km__pp_from_fn(&k0, &sig->kappa);
  if (st) return st;
  double L = sig->length;
  size_t nb = k0.m + 1 + sig->ncorners;
  double *br = km__malloc(nb * sizeof(double));
  if (!br) {
    km__pp_free(&k0);
    return KM_ENOMEM;
  }
  /* kappa's breaks and the corners are both sorted: merge them */
  size_t n = 0, ik = 0, ic = 0;
  while (ik <= k0.m || ic < sig->ncorners) {
    double xk = ik <= k0.m ? k0.x[ik] : INFINITY;
    double xc = ic < sig->ncorners ? sig->corners[ic].s : INFINITY;
    if (xk <= xc) {
      br[n++] = xk;
      ik++;
    } else {
      br[n++] = xc;
      ic++;
    }
  }
  size_t m = 0;
  for (size_t i = 0; i < n; i++) {
    double v = br[i] < 0 ? 0 : (br[i] > L ? L : br[i]);
    if (m == 0 || v > br[m - 1]) br[m++] = v;
  }
  br[0] = 0.0;
  if (br[m - 1] < L) br[m++] = L;
  int dk = k0.degree;
  st = km__pp_alloc(&tp->kappa, dk, m - 1);
  if (!st) st = km__pp_alloc(&tp->theta, dk + 1, m - 1);
  if (st) goto done;
  double th = sig->angle;
  size_t ci = 0;
  for (size_t i = 0; i + 1 < m; i++) {
    double a = br[i], b = br[i + 1], h = b - a;
    while (ci < sig->ncorners && sig->corners[ci].s <= a)
      th += sig->corners[ci++].turn;
    /* the kappa piece holding [a, b]: found by a, a break itself (the
     * midpoint of a piece one ulp wide rounds onto b, the next piece) */
    size_t j = km__pp_find(&k0, a);
    double ja = k0.x[j], jh = k0.x[j + 1] - ja;
    double *kc = tp->kappa.c + i * (size_t)(dk + 1);
    km__bern_restrict(k0.c + j * (size_t)(dk + 1), dk, (a - ja) / jh,
                      (b - ja) / jh, kc);
    double *tc = tp->theta.c + i * (size_t)(dk + 2);
    tc[0] = th;
    for (int k = 0; k <= dk; k++) tc[k + 1] = tc[k] + h * kc[k] / (dk + 1);
    th = tc[dk + 1];
    tp->kappa.x[i] = tp->theta.x[i] = a;
  }
  tp->kappa.x[m - 1] = tp->theta.x[m - 1] = L;
done:
  km__free(br);
  km__pp_free(&k0);
  if (st) {
    theta_pieces_free(tp);
    return st;
  }
  *kappa = tp->kappa;
  *theta = tp->theta;
  return KM_OK;
}

/* Integral of (cos theta, sin theta) over [u0, u1] (piece variable in
 * [0,1]) of theta piece i of length h. */
void km__integrate_exp(const double *tc, int d, double h, double u0, double u1,
                       double kbound, double out[2]) {
  double len = (u1 - u0) * h;
  /* chunks over which theta moves at most 0.5 rad */
  int chunks = (int)ceil(kbound * len / 0.5);
  if (chunks < 1) chunks = 1;
  if (chunks > 1000000) chunks = 1000000;
  double sx = 0.0, sy = 0.0, du = (u1 - u0) / chunks;
  for (int c = 0; c < chunks; c++) {
    double a = u0 + c * du, m = a + 0.5 * du, hw = 0.5 * du;
    double cx = 0.0, cy = 0.0;
    /* theta moves <= 0.5 rad on a chunk: the Taylor terms of e^(i theta)
     * beyond degree 15 are below 1e-18, which 8 Gauss points integrate
     * exactly */
    for (int k = 0; k < 8; k++) {
      double th = km__bern_eval(tc, d, m + hw * km__gl8_x[k]);
      cx += km__gl8_w[k] * cos(th);
      cy += km__gl8_w[k] * sin(th);
    }
    sx += cx * hw;
    sy += cy * hw;
  }
  out[0] = sx * h;
  out[1] = sy * h;
}

/* Bounds on |kappa^(j)| for j = 0..nd-1 over [u0,u1] of kappa piece kc. */
void km__kappa_bounds(const double *kc, int dk, double h, double u0, double u1,
                      int nd, double *bnd) {
  double c[MAXD], dc[MAXD];
  km__bern_restrict(kc, dk, u0, u1, c);
  int d = dk;
  double hh = (u1 - u0) * h;
  for (int j = 0; j < nd; j++) {
    bnd[j] = d >= 0 ? km__bern_abs_bound(c, d) : 0.0;
    if (d <= 0) {
      for (int q = j + 1; q < nd; q++) bnd[q] = 0.0;
      break;
    }
    km__bern_derivative(c, d, hh, dc);
    d--;
    memcpy(c, dc, (size_t)(d + 1) * sizeof(double));
  }
}

static double hermite_bound(int degree, const double *k, double h) {
  if (degree == 3) {
    double m4 = k[0] * k[0] * k[0] + 3 * k[0] * k[1] + k[2];
    return m4 * pow(h, 4) / 384.0;
  }
  double x1 = k[0], x2 = k[1], x3 = k[2], x4 = k[3], x5 = k[4];
  double m6 = pow(x1, 5) + 10 * x1 * x1 * x1 * x2 + 15 * x1 * x2 * x2 +
              10 * x1 * x1 * x3 + 10 * x2 * x3 + 5 * x1 * x4 + x5;
  return m6 * pow(h, 6) / 46080.0;
}

typedef struct out_piece {
  size_t piece;     /* theta piece where it starts, at u0 */
  size_t piece_end; /* theta piece where it ends, at u1 (cubic merging) */
  double u0, u1;
  double bound;
  double m4;     /* bound on |C''''| over the piece */
  double h;      /* arc length */
  double j2, j3; /* sums of the jumps of |C''|, |C'''| inside */
  double a0, a1; /* cubics: |B'| at each end in the piece variable, h for
                  * a piece Hermite in arc length */
  double lambda; /* a shape piece's own a / h (0: Hermite in arc length) */
} out_piece;

/* sup over u of the integral of K(u, t) |t - u| dt, K the (nonnegative)
 * Peano kernel of two-point cubic Hermite interpolation on [0, 1]: 1/2560,
 * reached at u = 1/2 (rounded up here, so the bound errs high) */
#define PEANO_K_LEVER (1.0 / 2550.0)

/* The end speed of a cubic Bezier circular arc of length h turning phi:
 * tangent legs 4/3 tan(phi/4) of the radius. */
static double arc_speed(double h, double phi) {
  return fabs(phi) > 1e-4 ? 4.0 * h * tan(phi / 4.0) / phi
                          : h * (1.0 + phi * phi / 48.0);
}

/* A cubic piece that follows the curve's shape rather than its arc length.
 *
 * B is the cubic with the exact positions and unit tangents at both ends
 * and end speeds a0, a1 in its variable u in [0, 1]. For any smooth
 * increasing sigma with sigma(0) = s0, sigma(1) = s0 + h, sigma'(0) = a0,
 * sigma'(1) = a1, B is the cubic Hermite interpolant of D = C o sigma,
 * which runs along the exact curve. With the cubic sigma of those end data,
 * in the Frenet frame of C
 *   D'''' = Tg T + Nm N,
 *   Tg = -3 k k' s'^4 - 6 k^2 s'^2 s'',
 *   Nm = k'' s'^4 + 6 k' s'^2 s'' + 3 k s''^2 + k s' (4 s''' - k^2 s'^3)
 * (k and its derivatives at sigma(u), s = sigma). End speeds near those of
 * a circular arc (arc_speed) make 4 s''' cancel k^2 s'^3 up to the
 * variation of k, so on a circle Nm is O(h^6) where the arc-length
 * Hermite error is O(h^4). The Peano kernel K of the error e = B - D is
 * nonnegative, so in the frame at D(u)
 *   |e.N| <= max|Nm| / 384 + max|Tg| K0 max|s'| PEANO_K_LEVER,
 *   |e.T| <= max|Tg| / 384 + max|Nm| K0 max|s'| PEANO_K_LEVER
 * (T(t).N(u) = sin(theta(t) - theta(u)), |theta(t) - theta(u)| <=
 * K0 max|s'| |t - u|). B(u) lies e.T along the tangent and e.N across it
 * from the point D(u) of C; the point of C an arc length e.T further is
 * within K0 (e.T)^2 / 2 of D(u) + (e.T) T, so every B(u) is within
 *   |e.N| + K0 (e.T)^2 / 2
 * of a point of C, and by continuity (the ends match) every point of C on
 * the piece is as near a point of B. Returns that bound, or INFINITY where
 * the estimate does not apply (sigma not increasing). k's ranges come from
 * the Bernstein coefficients of kappa piece kc restricted to [u0, u1]
 * (length hp). */
static double shape_bound(const double *kc, int dk, double hp, double u0,
                          double u1, double a0, double a1) {
  double c[MAXD], dc[MAXD];
  double h = (u1 - u0) * hp;
  km__bern_restrict(kc, dk, u0, u1, c);
  double klo = c[0], khi = c[0];
  for (int i = 1; i <= dk; i++) {
    klo = fmin(klo, c[i]);
    khi = fmax(khi, c[i]);
  }
  double k1 = 0.0, k2 = 0.0;
  if (dk >= 1) {
    km__bern_derivative(c, dk, h, dc);
    k1 = km__bern_abs_bound(dc, dk - 1);
    if (dk >= 2) {
      km__bern_derivative(dc, dk - 1, h, c);
      k2 = km__bern_abs_bound(c, dk - 2);
    }
  }
  double k0 = fmax(fabs(klo), fabs(khi));
  double ksq_lo = klo <= 0.0 && khi >= 0.0 ? 0.0 : fmin(klo * klo, khi * khi);
  /* sigma = s0 + h u + d0 u (1 - u)^2 - d1 u^2 (1 - u), d = a - h:
   * sigma' = h + d0 - (4 d0 + 2 d1) u + 3 (d0 + d1) u^2 (its range from
   * the ends and the vertex), sigma'' linear, sigma''' = 6 (d0 + d1) */
  double d0 = a0 - h, d1 = a1 - h;
  double sp_lo = fmin(a0, a1), sp_hi = fmax(a0, a1);
  double qa = 3.0 * (d0 + d1), qb = -(4.0 * d0 + 2.0 * d1);
  if (qa != 0.0) {
    double uv = -qb / (2.0 * qa);
    if (uv > 0.0 && uv < 1.0) {
      double v = h + d0 + qb * uv + qa * uv * uv;
      sp_lo = fmin(sp_lo, v);
      sp_hi = fmax(sp_hi, v);
    }
  }
  if (!(sp_lo > 0.0)) return INFINITY;
  double s2 = fmax(fabs(qb), fabs(qb + 2.0 * qa)), s3 = 2.0 * qa;
  double p2 = sp_hi * sp_hi, p4 = p2 * p2;
  double w = fmax(fabs(4.0 * s3 - k0 * k0 * p2 * sp_hi),
                  fabs(4.0 * s3 - ksq_lo * sp_lo * sp_lo * sp_lo));
  double nm =
      k2 * p4 + 6.0 * k1 * p2 * s2 + 3.0 * k0 * s2 * s2 + k0 * sp_hi * w;
  double tg = 3.0 * k0 * k1 * p4 + 6.0 * k0 * k0 * p2 * s2;
  double lever = k0 * sp_hi * PEANO_K_LEVER;
  double across = nm / 384.0 + tg * lever;
  double along = tg / 384.0 + nm * lever;
  return across + 0.5 * k0 * along * along;
}

typedef struct plan {
  out_piece *p;
  size_t n, cap;
  size_t limit;   /* pieces allowed (KM_MAX_OUTPUT_PIECES beyond the input's) */
  km__poll *poll; /* the caller's stop condition, or NULL */
  bool arc_length_only; /* no shape pieces: Hermite in arc length */
} plan;

static km_status plan_push(plan *pl, out_piece op) {
  /* a piece's bounds cost a few dozen operations, its output about as
   * many again: some 8 units */
  if (km__poll_stop(pl->poll, 8)) return KM_ECANCELLED;
  if (pl->n >= pl->limit) return KM_ELIMIT;
  if (pl->n == pl->cap) {
    size_t cap = pl->cap ? 2 * pl->cap : 64;
    if (cap > KM_MAX_PIECES) return KM_ELIMIT;
    out_piece *q = km__realloc(pl->p, cap * sizeof *q);
    if (!q) return KM_ENOMEM;
    pl->p = q;
    pl->cap = cap;
  }
  pl->p[pl->n++] = op;
  return KM_OK;
}

/* An output piece of theta piece i over [u0, u1]: a shape piece (end speeds
 * of the arc of its turning, shape_bound) where that bounds it closer than
 * arc-length Hermite, which it can for cubics turning less than 2 rad. */
static out_piece make_piece(const theta_pieces *tp, size_t i, double u0,
                            double u1, int degree, bool arc_length_only) {
  int dk = tp->kappa.degree;
  double hp = tp->kappa.x[i + 1] - tp->kappa.x[i], h = (u1 - u0) * hp;
  const double *kc = tp->kappa.c + i * (size_t)(dk + 1);
  double kb[5];
  km__kappa_bounds(kc, dk, hp, u0, u1, degree == 3 ? 3 : 5, kb);
  double e = hermite_bound(degree, kb, h);
  out_piece op = {i, i,   u0,  u1, e, e / fmax(pow(h, 4) / 384.0, 1e-300),
                  h, 0.0, 0.0, h,  h, 0.0};
  if (degree != 3 || arc_length_only) return op;
  const double *tc = tp->theta.c + i * (size_t)(dk + 2);
  double phi = km__bern_eval(tc, dk + 1, u1) - km__bern_eval(tc, dk + 1, u0);
  if (!(fabs(phi) < 2.0)) return op;
  double a = arc_speed(h, phi);
  double es = shape_bound(kc, dk, hp, u0, u1, a, a);
  if (!(es < e)) return op;
  op.bound = es;
  op.m4 = INFINITY; /* not merged across breaks of kappa */
  op.a0 = op.a1 = a;
  op.lambda = a / h;
  return op;
}

static km_status plan_range(plan *pl, const theta_pieces *tp, size_t i,
                            double u0, double u1, int degree, double tol,
                            int depth) {
  out_piece op = make_piece(tp, i, u0, u1, degree, pl->arc_length_only);
  if (op.bound <= tol || depth > 60) return plan_push(pl, op);
  /* split into as many equal parts as the bound's order suggests */
  int order = op.lambda > 0.0 ? 6 : (degree == 3 ? 4 : 6);
  double parts = ceil(pow(op.bound / tol, 1.0 / order) * 1.05);
  if (op.lambda == 0.0 && degree == 3) {
    /* a turn of 2 rad or more: parts that turn less may be shape pieces */
    int dk = tp->kappa.degree;
    const double *tc = tp->theta.c + i * (size_t)(dk + 2);
    double phi = km__bern_eval(tc, dk + 1, u1) - km__bern_eval(tc, dk + 1, u0);
    if (fabs(phi) >= 2.0) {
      /* sized by the bound on the first of the parts turning < 2 rad */
      double p0 = ceil(fabs(phi) / 1.9);
      out_piece sub = make_piece(tp, i, u0, u0 + (u1 - u0) / p0, degree,
                                 pl->arc_length_only);
      double per = sub.lambda > 0.0 ? pow(sub.bound / tol, 1.0 / 6.0) : 1.0;
      parts = fmin(parts, ceil(p0 * fmax(per, 1.0) * 1.05));
    }
  }
  if (parts < 2) parts = 2;
  if (parts > 1e6) parts = 1e6;
  int np = (int)parts;
  for (int k = 0; k < np; k++) {
    double a = u0 + (u1 - u0) * k / np, b = u0 + (u1 - u0) * (k + 1) / np;
    if (k == np - 1) b = u1;
    km_status st = plan_range(pl, tp, i, a, b, degree, tol, depth + 1);
    if (st) return st;
  }
  return KM_OK;
}

static double kappa_end(const theta_pieces *tp, size_t i, int right_end,
                        double *slope) {
  int dk = tp->kappa.degree;
  const double *kc = tp->kappa.c + i * (size_t)(dk + 1);
  double h = tp->kappa.x[i + 1] - tp->kappa.x[i];
  if (dk == 0) {
    *slope = 0.0;
    return kc[0];
  }
  if (right_end) {
    *slope = dk * (kc[dk] - kc[dk - 1]) / h;
    return kc[dk];
  }
  *slope = dk * (kc[1] - kc[0]) / h;
  return kc[0];
}

/* Cubic pieces may span breakpoints of kappa where theta is continuous:
 * C is then C1 with jumps J2 in its second derivative and J3 in its third
 * there, and writing C = g + sum (J2 q2 + J3 q3) with g three times
 * continuously differentiable gives
 *   |C - H| <= h^4/384 max|g''''| + sum (a2 h^2 |J2| + a3 h^3 |J3|).
 * Neighbours are merged greedily while that bound meets the tolerance. */
static void merge_cubic(plan *pl, const theta_pieces *tp, double tol) {
  if (pl->n == 0) return;
  int dt = tp->theta.degree;
  size_t w = 0;
  out_piece cur = pl->p[0];
  for (size_t j = 1; j < pl->n; j++) {
    out_piece nx = pl->p[j];
    double j2 = 0.0, j3 = 0.0;
    bool ok = true;
    if (nx.piece != cur.piece_end) {
      /* a breakpoint of kappa between them: theta must be continuous */
      double tha = km__bern_eval(tp->theta.c + cur.piece_end * (size_t)(dt + 1),
                                 dt, 1.0);
      double thb =
          km__bern_eval(tp->theta.c + nx.piece * (size_t)(dt + 1), dt, 0.0);
      if (fabs(thb - tha) > 1e-13) ok = false;
      double sa, sb;
      double ka = kappa_end(tp, cur.piece_end, 1, &sa);
      double kb = kappa_end(tp, nx.piece, 0, &sb);
      j2 = fabs(kb - ka);
      j3 = fabs(sb - sa) + fabs(kb * kb - ka * ka);
    }
    if (ok) {
      double h = cur.h + nx.h, m4 = fmax(cur.m4, nx.m4);
      double s2 = cur.j2 + nx.j2 + j2, s3 = cur.j3 + nx.j3 + j3;
      double e = pow(h, 4) / 384.0 * m4 + KM__HERMITE_JUMP2 * h * h * s2 +
                 KM__HERMITE_JUMP3 * h * h * h * s3;
      if (e <= tol) {
        cur.piece_end = nx.piece_end;
        cur.u1 = nx.u1;
        cur.h = h;
        cur.m4 = m4;
        cur.j2 = s2;
        cur.j3 = s3;
        cur.bound = e;
        cur.a0 = cur.a1 = h;
        continue;
      }
    }
    pl->p[w++] = cur;
    cur = nx;
  }
  pl->p[w++] = cur;
  pl->n = w;
}

/* Neighbouring shape pieces of one theta piece merged greedily while the
 * merged piece's bound meets the tolerance: equal parts are too many
 * where the curvature varies along the piece. */
static km_status merge_shape(plan *pl, const theta_pieces *tp, double tol) {
  if (pl->n == 0) return KM_OK;
  size_t w = 0;
  out_piece cur = pl->p[0];
  for (size_t j = 1; j < pl->n; j++) {
    out_piece nx = pl->p[j];
    if (km__poll_stop(pl->poll, 8)) return KM_ECANCELLED;
    if (cur.lambda > 0.0 && nx.lambda > 0.0 && nx.piece == cur.piece &&
        nx.u0 == cur.u1) {
      out_piece m = make_piece(tp, cur.piece, cur.u0, nx.u1, 3, false);
      if (m.lambda > 0.0 && m.bound <= tol) {
        cur = m;
        continue;
      }
    }
    pl->p[w++] = cur;
    cur = nx;
  }
  pl->p[w++] = cur;
  pl->n = w;
  return KM_OK;
}

static bool theta_jumps(const theta_pieces *tp, const out_piece *a,
                        const out_piece *b) {
  int dt = tp->theta.degree;
  double tha =
      km__bern_eval(tp->theta.c + a->piece_end * (size_t)(dt + 1), dt, a->u1);
  double thb =
      km__bern_eval(tp->theta.c + b->piece * (size_t)(dt + 1), dt, b->u0);
  return fabs(thb - tha) > 1e-13;
}

/* The cubic B-spline is C1 at a smooth junction, so both sides' end speeds
 * are in proportion to their lengths: a0 / h of a piece equals a1 / h of
 * the one before. There it is the mean of the two pieces' own (a / h of a
 * shape piece, 1 of one Hermite in arc length), or 1 next to a piece that
 * spans breaks of kappa (its bound holds for a = h only). Every piece
 * within one piece of kappa is then bounded again with the speeds it got,
 * by shape_bound (which holds for any speeds) or, at a = h, the Hermite
 * bound if smaller; *over is set when one exceeds tol (that piece's bound
 * is then INFINITY). */
static km_status settle_speeds(plan *pl, const theta_pieces *tp, double tol,
                               bool *over) {
  *over = false;
  for (size_t j = 0; j < pl->n; j++) {
    if (km__poll_stop(pl->poll, 8)) return KM_ECANCELLED;
    out_piece *op = &pl->p[j];
    bool flexible = op->piece == op->piece_end;
    double own = op->lambda > 0.0 ? op->lambda : 1.0;
    double l0 = own, l1 = own;
    if (j > 0 && !theta_jumps(tp, &pl->p[j - 1], op)) {
      const out_piece *q = &pl->p[j - 1];
      l0 = flexible && q->piece == q->piece_end
               ? 0.5 * (own + (q->lambda > 0.0 ? q->lambda : 1.0))
               : 1.0;
    }
    if (j + 1 < pl->n && !theta_jumps(tp, op, &pl->p[j + 1])) {
      const out_piece *q = &pl->p[j + 1];
      l1 = flexible && q->piece == q->piece_end
               ? 0.5 * (own + (q->lambda > 0.0 ? q->lambda : 1.0))
               : 1.0;
    }
    if (!flexible) continue; /* a = h, bounded when merged */
    op->a0 = l0 * op->h;
    op->a1 = l1 * op->h;
    int dk = tp->kappa.degree;
    size_t i = op->piece;
    double hp = tp->kappa.x[i + 1] - tp->kappa.x[i];
    const double *kc = tp->kappa.c + i * (size_t)(dk + 1);
    double e = shape_bound(kc, dk, hp, op->u0, op->u1, op->a0, op->a1);
    if (l0 == 1.0 && l1 == 1.0) {
      double kb[3];
      km__kappa_bounds(kc, dk, hp, op->u0, op->u1, 3, kb);
      e = fmin(e, hermite_bound(3, kb, op->h));
    }
    op->bound = e;
    if (!(e <= tol)) {
      op->bound = INFINITY;
      *over = true;
    }
  }
  return KM_OK;
}

/* Pieces whose settled bound exceeds tol planned again in two halves. */
static km_status split_over(plan *pl, const theta_pieces *tp, double tol) {
  plan next = {NULL, 0, 0, pl->limit, pl->poll, pl->arc_length_only};
  km_status st = KM_OK;
  for (size_t j = 0; j < pl->n && !st; j++) {
    out_piece op = pl->p[j];
    if (op.bound <= tol) {
      st = plan_push(&next, op);
      continue;
    }
    double mid = 0.5 * (op.u0 + op.u1);
    st = plan_range(&next, tp, op.piece, op.u0, mid, 3, tol, 0);
    if (!st) st = plan_range(&next, tp, op.piece, mid, op.u1, 3, tol, 0);
  }
  if (st) {
    km__free(next.p);
    return st;
  }
  km__free(pl->p);
  *pl = next;
  return KM_OK;
}

km_status km_reconstruct(const km_signature *sig, int degree, double tol,
                         km_curve *out, double *error_bound, km_error *err) {
  return km__reconstruct(sig, degree, tol, 0, NULL, out, error_bound, NULL,
                         err);
}

km_status km_reconstruct_within(const km_signature *sig, int degree, double tol,
                                size_t max_points, km_curve *out,
                                double *error_bound, km_error *err) {
  return km__reconstruct(sig, degree, tol, max_points, NULL, out, error_bound,
                         NULL, err);
}

km_status km_reconstruct_until(const km_signature *sig, int degree, double tol,
                               size_t max_points, const km_stop *stop,
                               km_curve *out, double *error_bound,
                               km_error *err) {
  km__poll poll;
  km__poll_init(&poll, stop);
  return km__reconstruct(sig, degree, tol, max_points, &poll, out, error_bound,
                         NULL, err);
}

/* ---- the phases of km__reconstruct -------------------------------------
 * Output pieces planned over the theta pieces (and merged, for cubics),
 * the positions at their ends integrated, the continuity at every
 * junction decided (which sets the knots' multiplicities), then the
 * Hermite pieces' Bezier points written as one B-spline. */

/* The output pieces of every theta piece within tol. */
static km_status plan_all(plan *pl, const theta_pieces *tp, int degree,
                          double tol, const km_signature *sig, km_error *err) {
  for (size_t i = 0; i < tp->theta.m; i++) {
    km_status st = plan_range(pl, tp, i, 0.0, 1.0, degree, tol, 0);
    if (st == KM_ECANCELLED) {
      km__stopped(err);
      return st;
    }
    if (st)
      return km__fail(err, st, KM_FIELD_TOLERANCE, -1, NAN,
                      st == KM_ELIMIT ? "the curve needs more than %zu pieces "
                                        "of degree %d at this tolerance (it "
                                        "turns %g times): loosen the tolerance"
                                      : "out of memory",
                      pl->limit, degree, fabs(sig->turning) / (2 * KM_PI));
  }
  return KM_OK;
}

/* The plan's end speeds settled, pieces that then break the bound split
 * in two and settled again, for a few rounds; KM_ENOCONVERGE should that
 * not end. */
static km_status settle_plan(plan *pl, const theta_pieces *tp, double tol,
                             km_error *err) {
  for (int round = 0; round < 12; round++) {
    bool over;
    if (settle_speeds(pl, tp, tol, &over)) return km__stopped(err);
    if (!over) return KM_OK;
    km_status st = split_over(pl, tp, tol);
    if (st == KM_ECANCELLED) return km__stopped(err);
    if (st)
      return km__fail(err, st, KM_FIELD_TOLERANCE, -1, NAN,
                      st == KM_ELIMIT ? "the curve needs more than %zu pieces "
                                        "of degree 3 at this tolerance: "
                                        "loosen the tolerance"
                                      : "out of memory",
                      pl->limit);
  }
  return KM_ENOCONVERGE;
}

/* The output pieces within 0.9 tol, arc-length Hermite throughout: a
 * cubic's neighbours merged across breaks of kappa where the bound allows
 * (a signature breaks at every knot of its curve), then their speeds
 * settled. */
static km_status plan_arc_length(plan *pl, const theta_pieces *tp, int degree,
                                 double tol, const km_signature *sig,
                                 km_error *err) {
  pl->n = 0;
  pl->arc_length_only = true;
  km_status st = plan_all(pl, tp, degree, 0.9 * tol, sig, err);
  if (st || degree != 3) return st;
  merge_cubic(pl, tp, 0.9 * tol);
  return settle_plan(pl, tp, 0.9 * tol, err);
}

/* The output pieces with arc-shaped cubics where they bound closer, their
 * neighbours merged where the bound allows and their end speeds settled. */
static km_status plan_shaped(plan *pl, const theta_pieces *tp, double tol,
                             const km_signature *sig, km_error *err) {
  km_status st = plan_all(pl, tp, 3, 0.9 * tol, sig, err);
  if (st) return st;
  if (merge_shape(pl, tp, 0.9 * tol)) return km__stopped(err);
  merge_cubic(pl, tp, 0.9 * tol);
  return settle_plan(pl, tp, 0.9 * tol, err);
}

/* The fewer pieces of the two plans for cubics: arc-shaped pieces cannot
 * span breaks of kappa, so where a curve's breaks are dense (a frame's
 * signature, a spline's) the merged arc-length plan may be the smaller. */
static km_status plan_pieces(plan *pl, const theta_pieces *tp, int degree,
                             double tol, const km_signature *sig,
                             km_error *err) {
  if (degree != 3) return plan_arc_length(pl, tp, degree, tol, sig, err);
  plan alt = {NULL, 0, 0, pl->limit, pl->poll, true};
  km_error alt_err;
  km_status st = plan_shaped(pl, tp, tol, sig, err);
  if (st == KM_ECANCELLED || st == KM_ENOMEM) {
    km__free(alt.p);
    return st;
  }
  km_status sa = plan_arc_length(&alt, tp, degree, tol, sig, &alt_err);
  if (sa == KM_ECANCELLED || sa == KM_ENOMEM) {
    km__free(alt.p);
    if (err) *err = alt_err;
    return sa;
  }
  if (sa == KM_OK && (st != KM_OK || alt.n < pl->n)) {
    km__free(pl->p);
    *pl = alt;
    return KM_OK;
  }
  km__free(alt.p);
  if (st == KM_ENOCONVERGE) {
    if (err) *err = alt_err;
    return sa;
  }
  return st;
}

/* pos[2 j], pos[2 j + 1]: the position at the start of output piece j
 * (np + 1 points), by integrating e^(i theta) over the theta pieces it
 * covers; *max_bound the largest of the pieces' bounds. */
static km_status integrate_positions(const plan *pl, const theta_pieces *tp,
                                     const km_signature *sig, km__poll *poll,
                                     double *pos, double *max_bound,
                                     km_error *err) {
  int dk = tp->kappa.degree, dt = dk + 1;
  pos[0] = sig->start[0];
  pos[1] = sig->start[1];
  *max_bound = 0.0;
  for (size_t j = 0; j < pl->n; j++) {
    const out_piece *op = &pl->p[j];
    double sx = 0.0, sy = 0.0;
    for (size_t i = op->piece; i <= op->piece_end; i++) {
      double h = tp->theta.x[i + 1] - tp->theta.x[i];
      double u0 = i == op->piece ? op->u0 : 0.0;
      double u1 = i == op->piece_end ? op->u1 : 1.0;
      double kb[1], d[2];
      km__kappa_bounds(tp->kappa.c + i * (size_t)(dk + 1), dk, h, u0, u1, 1,
                       kb);
      km__integrate_exp(tp->theta.c + i * (size_t)(dt + 1), dt, h, u0, u1,
                        kb[0], d);
      sx += d[0];
      sy += d[1];
      /* 16 nodes a chunk of at most half a radian (km__integrate_exp) */
      if (km__poll_stop(poll,
                        16 + (long)fmin(32.0 * kb[0] * (u1 - u0) * h, 1e9)))
        return km__stopped(err);
    }
    pos[2 * j + 2] = pos[2 * j] + sx;
    pos[2 * j + 3] = pos[2 * j + 1] + sy;
    *max_bound = fmax(*max_bound, op->bound);
  }
  return KM_OK;
}

/* Junction continuity cont[j] between output pieces j - 1 and j: 0 = a
 * corner (C0), 1 = a jump of kappa (C1; also every cubic junction, the
 * Hermite pieces being C1), 2 = C2. Returns the knot count of the
 * B-spline. */
static size_t junctions(const plan *pl, const theta_pieces *tp, int p, double L,
                        int *cont) {
  int dk = tp->kappa.degree, dt = dk + 1;
  size_t nknots = 2 * (size_t)(p + 1);
  double kscale = km__pp_max_abs(&tp->kappa) + 1.0 / L;
  for (size_t j = 1; j < pl->n; j++) {
    const out_piece *a = &pl->p[j - 1], *b = &pl->p[j];
    double tha =
        km__bern_eval(tp->theta.c + a->piece_end * (size_t)(dt + 1), dt, a->u1);
    double thb =
        km__bern_eval(tp->theta.c + b->piece * (size_t)(dt + 1), dt, b->u0);
    double ka =
        km__bern_eval(tp->kappa.c + a->piece_end * (size_t)(dk + 1), dk, a->u1);
    double kb =
        km__bern_eval(tp->kappa.c + b->piece * (size_t)(dk + 1), dk, b->u0);
    if (fabs(thb - tha) > 1e-13)
      cont[j] = 0;
    else if (fabs(kb - ka) > 1e-12 * kscale)
      cont[j] = 1;
    else
      cont[j] = 2;
    if (p == 3 && cont[j] == 2) cont[j] = 1; /* cubic Hermite is C1 */
    nknots += (size_t)(p - cont[j]);
  }
  return nknots;
}

/* The Bezier points Q[0..p] of output piece j: Hermite data (position,
 * tangent, and for quintics curvature) at both ends. */
static void piece_bezier(const plan *pl, const theta_pieces *tp,
                         const double *pos, size_t j, int p, double Q[6][2]) {
  int dk = tp->kappa.degree, dt = dk + 1;
  const out_piece *op = &pl->p[j];
  size_t i = op->piece, ie = op->piece_end;
  const double *tc = tp->theta.c + i * (size_t)(dt + 1);
  const double *kc = tp->kappa.c + i * (size_t)(dk + 1);
  const double *tce = tp->theta.c + ie * (size_t)(dt + 1);
  const double *kce = tp->kappa.c + ie * (size_t)(dk + 1);
  double h = op->h;
  double t0 = km__bern_eval(tc, dt, op->u0),
         t1 = km__bern_eval(tce, dt, op->u1);
  double T0[2] = {cos(t0), sin(t0)}, T1[2] = {cos(t1), sin(t1)};
  double P0[2] = {pos[2 * j], pos[2 * j + 1]};
  double P1[2] = {pos[2 * j + 2], pos[2 * j + 3]};
  if (p == 3) {
    for (int a = 0; a < 2; a++) {
      Q[0][a] = P0[a];
      Q[1][a] = P0[a] + op->a0 / 3.0 * T0[a];
      Q[2][a] = P1[a] - op->a1 / 3.0 * T1[a];
      Q[3][a] = P1[a];
    }
    return;
  }
  double k0 = km__bern_eval(kc, dk, op->u0),
         k1 = km__bern_eval(kce, dk, op->u1);
  double N0[2] = {-T0[1], T0[0]}, N1[2] = {-T1[1], T1[0]};
  for (int a = 0; a < 2; a++) {
    Q[0][a] = P0[a];
    Q[1][a] = P0[a] + h / 5.0 * T0[a];
    Q[2][a] = 2 * Q[1][a] - Q[0][a] + h * h / 20.0 * k0 * N0[a];
    Q[5][a] = P1[a];
    Q[4][a] = P1[a] - h / 5.0 * T1[a];
    Q[3][a] = 2 * Q[4][a] - Q[5][a] + h * h / 20.0 * k1 * N1[a];
  }
}

static void put_point(km_curve *c, size_t *cc, const double q[2]) {
  c->cp[2 * *cc] = q[0];
  c->cp[2 * *cc + 1] = q[1];
  (*cc)++;
}

/* The B-spline's knots and control points from the pieces' Bezier points,
 * junction by junction (c allocated for them). *ncp_out and *nk_out
 * receive the counts written, for the caller's consistency check. */
static void write_bspline(const plan *pl, const theta_pieces *tp,
                          const double *pos, const int *cont, int p, double L,
                          km_curve *c, size_t *ncp_out, size_t *nk_out) {
  size_t kk = 0, cc = 0;
  double s_at = 0.0;
  for (int r = 0; r <= p; r++) c->knots[kk++] = 0.0;
  double prevQ[6][2] = {{0}};
  double prev_h = 0.0;
  for (size_t j = 0; j < pl->n; j++) {
    double h = pl->p[j].h, Q[6][2];
    piece_bezier(pl, tp, pos, j, p, Q);
    int cin = j == 0 ? -1 : cont[j];
    if (j == 0) {
      put_point(c, &cc, Q[0]);
    } else {
      /* close the previous piece according to the junction type: at C0
       * its Q(p-1) and the shared point, at C1 its Q(p-1) (the shared
       * point is implied); at a quintic's C2 Q4 of the left piece, the
       * junction and Q1 of the right piece collapse into one point
       * (blossom f(a,u,u,u,b)) */
      if (cin == 0) {
        put_point(c, &cc, prevQ[p - 1]);
        put_point(c, &cc, Q[0]);
      } else if (cin == 1) {
        put_point(c, &cc, prevQ[p - 1]);
      } else {
        for (int a = 0; a < 2; a++)
          c->cp[2 * cc + (size_t)a] =
              prevQ[4][a] + (h / prev_h) * (prevQ[4][a] - prevQ[3][a]);
        cc++;
      }
      for (int r = 0; r < p - cin; r++) c->knots[kk++] = s_at;
    }
    /* interior points of this piece, except those a C2 junction owns;
     * Q(p-1) is emitted at the next junction or the end */
    int first = (j > 0 && cin == 2) ? 2 : 1;
    for (int q = first; q < p - 1; q++) put_point(c, &cc, Q[q]);
    memcpy(prevQ, Q, sizeof Q);
    prev_h = h;
    s_at += h;
  }
  put_point(c, &cc, prevQ[p - 1]);
  put_point(c, &cc, prevQ[p]);
  for (int r = 0; r <= p; r++) c->knots[kk++] = L;
  *ncp_out = cc;
  *nk_out = kk;
}

km_status km__reconstruct(const km_signature *sig, int degree, double tol,
                          size_t max_points, km__poll *poll, km_curve *out,
                          double *error_bound, size_t *points_only,
                          km_error *err) {
  if (degree != 3 && degree != 5)
    return km__fail(err, KM_EDEGREE, KM_FIELD_DEGREE, -1, NAN,
                    "reconstruction degree must be 3 or 5, not %d", degree);
  double L = sig->length;
  if (!(tol > 0) || !isfinite(tol)) tol = 1e-5 * L;
  if (tol < KM_MIN_RELATIVE_TOLERANCE * L) tol = KM_MIN_RELATIVE_TOLERANCE * L;
  theta_pieces tp;
  plan pl = {NULL, 0, 0, 0, poll, false};
  double *pos = NULL;
  int *cont = NULL;
  km_curve c;
  km_curve_init(&c);
  km_status st = km__build_theta(sig, &tp.kappa, &tp.theta);
  if (st) return km__fail(err, st, KM_FIELD_NONE, -1, NAN, NULL);
  pl.limit = KM_MAX_OUTPUT_PIECES + 2 * tp.theta.m;
  if (pl.limit > KM_MAX_PIECES) pl.limit = KM_MAX_PIECES;
  /* a piece adds `degree` control points to the one the curve starts
   * with, so n pieces take n * degree + 1 */
  if (max_points > 0 && (max_points - 1) / (size_t)degree < pl.limit)
    pl.limit = (max_points - 1) / (size_t)degree;
  st = plan_pieces(&pl, &tp, degree, tol, sig, err);
  if (st) goto cleanup;
  size_t np = pl.n;
  pos = km__malloc((np + 1) * 2 * sizeof(double));
  cont = km__malloc((np + 1) * sizeof(int));
  if (!pos || !cont) {
    st = km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
    goto cleanup;
  }
  double max_bound = 0.0;
  if (!points_only) {
    st = integrate_positions(&pl, &tp, sig, poll, pos, &max_bound, err);
    if (st) goto cleanup;
  }
  int p = degree;
  size_t nknots = junctions(&pl, &tp, p, L, cont);
  size_t ncp = nknots - (size_t)p - 1;
  if (points_only) {
    *points_only = ncp;
    goto cleanup;
  }
  st = km__curve_alloc(&c, p, ncp, false);
  if (st) {
    st = km__fail(err, st, KM_FIELD_NONE, -1, NAN, NULL);
    goto cleanup;
  }
  size_t cc, kk;
  write_bspline(&pl, &tp, pos, cont, p, L, &c, &cc, &kk);
  if (cc != ncp || kk != nknots) {
    st = km__fail(err, KM_EINVAL, KM_FIELD_NONE, -1, NAN,
                  "internal inconsistency building the B-spline");
    goto cleanup;
  }
  /* the ends' positions carry the rounding of every integral before them */
  double bound =
      max_bound + 8e-16 * (double)(np + 1) *
                      (L + fabs(sig->start[0]) + fabs(sig->start[1]));
  c.closed = false;
  if (sig->closed) {
    double gx = c.cp[2 * (ncp - 1)] - c.cp[0],
           gy = c.cp[2 * (ncp - 1) + 1] - c.cp[1];
    double gap = hypot(gx, gy);
    if (gap <= tol) {
      c.cp[2 * (ncp - 1)] = c.cp[0];
      c.cp[2 * (ncp - 1) + 1] = c.cp[1];
      c.closed = true;
      bound += gap;
    }
  }
  *out = c;
  km_curve_init(&c);
  if (error_bound) *error_bound = bound;
cleanup:
  km_curve_free(&c);
  km__free(cont);
  km__free(pos);
  km__free(pl.p);
  theta_pieces_free(&tp);
  return st;
}

km_status km_signature_point(const km_signature *sig, double s, double pos[2],
                             double *theta) {
  theta_pieces tp;
  km_status st = km__build_theta(sig, &tp.kappa, &tp.theta);
  if (st) return st;
  if (s < 0) s = 0;
  if (s > sig->length) s = sig->length;
  int dk = tp.kappa.degree, dt = dk + 1;
  double x = sig->start[0], y = sig->start[1], th = sig->angle;
  for (size_t i = 0; i < tp.theta.m; i++) {
    double a = tp.theta.x[i], b = tp.theta.x[i + 1], h = b - a;
    if (a >= s && i > 0) break;
    double u1 = s >= b ? 1.0 : (s - a) / h;
    double kb[1], d[2];
    km__kappa_bounds(tp.kappa.c + i * (size_t)(dk + 1), dk, h, 0.0, u1, 1, kb);
    const double *tc = tp.theta.c + i * (size_t)(dt + 1);
    km__integrate_exp(tc, dt, h, 0.0, u1, kb[0], d);
    x += d[0];
    y += d[1];
    th = km__bern_eval(tc, dt, u1);
    if (s < b) break;
  }
  /* corners exactly at s count from the right */
  for (size_t i = 0; i < sig->ncorners; i++)
    if (sig->corners[i].s == s && s > 0 && s < sig->length) th += 0.0;
  pos[0] = x;
  pos[1] = y;
  if (theta) *theta = th;
  theta_pieces_free(&tp);
  return KM_OK;
}
