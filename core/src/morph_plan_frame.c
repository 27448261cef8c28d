/* morph_plan_frame.c - a frame built from its morph's plan (morph_plan.c).
 *
 * DESIGN. A frame is a pass of sin/cos over the plan's nodes, a pass
 * turning them by the closure's first change, a bounded first-order finish
 * (km__plan_close_frame) and the Hermite control points: no
 * piecewise-polynomial blending, no planning, no allocation but the
 * output. The closure is the one of morph_closure.c: interior uniform
 * cubic B-splines psi added to theta, minimum-norm steps in the metric
 * integral psi'^2 (the Gram matrix of their derivatives is Toeplitz with
 * entries 2/3, -1/8, -1/5, -1/120), so the seam stays G2; or, where the
 * plan says so, a turn of the frame's corners.
 *   The plan's pieces are sized for the worst t, within their share of the
 * tolerance; each frame then merges runs of them greedily into single
 * cubics (end points and tangents kept, legs by the circular-arc formula)
 * while a rigorous bound of the distance between the cubic and the pieces
 * it replaces (merge_distance: Bernstein coefficients of their difference
 * under a cubic reparametrisation) fits in the merge's share, never across
 * a corner the frame turns at. So a frame is within the pieces' share
 * plus the merge's of its exact curve, as point sets, and carries 1.0-2.6x
 * fewer control points than its pieces (the circle's arcs four to a
 * cubic). The bound costs some 1,200 instructions an evaluation, two
 * evaluations a run: more than printing the points it saves through the
 * CLI (bench/RESULTS.md).
 */
#include <math.h>
#include <string.h>

#include "internal.h"
#include "km/alloc.h"
#include "morph_plan_internal.h"

/* Gap (over the frame's length) at which the lsq closure stops: a tenth of
 * its promise, 1e-9 of the length (a hundredth costs a tenth more passes
 * over the nodes) */
#define CLOSED_GAP 1e-10

/* psi at break k, from the basis values there (computed once per plan). */
static double psi_at_break(const km__frame_plan *p, const double *c, size_t k) {
  const gnode *b = &p->at_break[k];
  double v = 0.0;
  for (int q = 0; q < 4; q++)
    if (b->bi + q >= 0 && b->bi + q < NF) v += c[b->bi + q] * b->bv[q];
  return v;
}

static double max_abs(const double *v, int n) {
  double m = 0.0;
  for (int i = 0; i < n; i++) m = fmax(m, fabs(v[i]));
  return m;
}

/* e^(i d) for |d| <= 0.1 by its Taylor series (the remainder is below
 * 0.1^10 / 10! < 3e-17), beyond that by sin and cos. */
static inline void exp_i_small(double d, double *cs, double *sn) {
  if (fabs(d) > 0.1) {
    km__sincos(d, sn, cs);
    return;
  }
  /* reciprocals, not divisions: a division takes some 15 cycles, and
   * these run at every node of every pass */
  double d2 = d * d;
  *cs =
      1 - d2 * 0.5 *
              (1 - d2 * (1.0 / 12) *
                       (1 - d2 * (1.0 / 30) *
                                (1 - d2 * (1.0 / 56) * (1 - d2 * (1.0 / 90)))));
  *sn = d * (1 - d2 * (1.0 / 6) *
                     (1 - d2 * (1.0 / 20) *
                              (1 - d2 * (1.0 / 42) * (1 - d2 * (1.0 / 72)))));
}

/* e^(i d) for |d| <= 0.01: the series to d^7 (the remainder is below
 * 0.01^8 / 8! < 3e-21), for passes whose change is bounded so. */
static inline void exp_i_tiny(double d, double *cs, double *sn) {
  double d2 = d * d;
  *cs = 1 - d2 * 0.5 * (1 - d2 * (1.0 / 12) * (1 - d2 * (1.0 / 30)));
  *sn =
      d * (1 - d2 * (1.0 / 6) * (1 - d2 * (1.0 / 20) * (1 - d2 * (1.0 / 42))));
}

/* One pass over the nodes: sum[2k], sum[2k+1] = integral over piece k of
 * e^(i (theta_t + psi)), G their total. On the first pass (e_known false)
 * e^(i theta) is computed at every node; later ones turn the stored e by
 * the change of psi (coefficients dcp), which is small. With J, d G / d c
 * is accumulated too. Coefficients are padded by three zeros each side, so
 * that every node reads its four basis functions without a test
 * (basis_at). */
static void frame_pass(const km__frame_plan *p, double t, double theta0,
                       const double *cp, const double *dcp, bool e_known,
                       double *sum, double *e, double G[2], double J[2][NF],
                       km__poll *poll) {
  double al = 1 - t, be = t, Jp[2][NF + 6];
  if (J) memset(Jp, 0, sizeof Jp);
  G[0] = G[1] = 0.0;
  /* nodes mostly share their basis functions with the previous one: the
   * Jacobian is summed in registers while they do */
  int run = -1;
  double ax[4] = {0, 0, 0, 0}, ay[4] = {0, 0, 0, 0};
  /* the change at a node is at most the largest coefficient's (the basis
   * is a partition of unity): most passes need only the short series */
  bool tiny = e_known && max_abs(dcp + 3, NF) <= 0.01;
  for (size_t k = 0; k < p->np; k++) {
    double sx = 0.0, sy = 0.0;
    /* the caller sees poll->stopped: what was summed is then unused */
    if (km__poll_stop(poll, (long)(p->first[k + 1] - p->first[k]) + 1)) return;
    for (size_t j = p->first[k]; j < p->first[k + 1]; j++) {
      const gnode *nd = &p->node[j];
      const double *bv = nd->bv;
      int o = nd->bi + 3;
      double cs, sn;
      if (!e_known) {
        double th = theta0 + al * nd->ta + be * nd->tb + cp[o] * bv[0] +
                    cp[o + 1] * bv[1] + cp[o + 2] * bv[2] + cp[o + 3] * bv[3];
        km__sincos(th, &sn, &cs);
      } else {
        double d = dcp[o] * bv[0] + dcp[o + 1] * bv[1] + dcp[o + 2] * bv[2] +
                   dcp[o + 3] * bv[3];
        double dx, dy;
        if (tiny)
          exp_i_tiny(d, &dx, &dy);
        else
          exp_i_small(d, &dx, &dy);
        cs = e[2 * j] * dx - e[2 * j + 1] * dy;
        sn = e[2 * j] * dy + e[2 * j + 1] * dx;
      }
      e[2 * j] = cs;
      e[2 * j + 1] = sn;
      double wc = nd->w * cs, ws = nd->w * sn;
      sx += wc;
      sy += ws;
      if (J) {
        if (o != run) {
          if (run >= 0)
            for (int q = 0; q < 4; q++) {
              Jp[0][run + q] += ax[q];
              Jp[1][run + q] += ay[q];
            }
          run = o;
          for (int q = 0; q < 4; q++) ax[q] = ay[q] = 0.0;
        }
        for (int q = 0; q < 4; q++) {
          ax[q] -= ws * bv[q];
          ay[q] += wc * bv[q];
        }
      }
    }
    sum[2 * k] = sx;
    sum[2 * k + 1] = sy;
    G[0] += sx;
    G[1] += sy;
  }
  if (J) {
    if (run >= 0)
      for (int q = 0; q < 4; q++) {
        Jp[0][run + q] += ax[q];
        Jp[1][run + q] += ay[q];
      }
    for (int r = 0; r < 2; r++) memcpy(J[r], Jp[r] + 3, sizeof J[r]);
  }
}

/* The pieces' sums moved to first order by a step of psi (padded
 * coefficients dcp) from where e was stored: sum_k += integral over piece
 * k of i e^(i theta) dpsi. */
static void linear_finish(const km__frame_plan *p, const double *dcp,
                          const double *e, double *sum) {
  for (size_t k = 0; k < p->np; k++) {
    double dx = 0.0, dy = 0.0;
    for (size_t j = p->first[k]; j < p->first[k + 1]; j++) {
      const gnode *nd = &p->node[j];
      const double *bv = nd->bv;
      int o = nd->bi + 3;
      double d = nd->w * (dcp[o] * bv[0] + dcp[o + 1] * bv[1] +
                          dcp[o + 2] * bv[2] + dcp[o + 3] * bv[3]);
      dx -= e[2 * j + 1] * d;
      dy += e[2 * j] * d;
    }
    sum[2 * k] += dx;
    sum[2 * k + 1] += dy;
  }
}

/* Y = M^-1 J^T (rows) and S = J M^-1 J^T for the closure metric M: what
 * minimum-norm steps with this J need, kept for a chord step. */
static void metric_rows(const km__frame_plan *p, double J[2][NF],
                        double Y[2][NF], double S[4]) {
  for (int r = 0; r < 2; r++) {
    memcpy(Y[r], J[r], sizeof Y[r]);
    km__closure_metric_solve(p->chol, Y[r]);
  }
  for (int r = 0; r < 2; r++)
    for (int k = 0; k < 2; k++) {
      double v = 0.0;
      for (int i = 0; i < NF; i++) v += J[r][i] * Y[k][i];
      S[r * 2 + k] = v;
    }
}

/* The minimum-norm step dc = M^-1 J^T lambda with J dc = rhs; false if J
 * is singular. */
static bool metric_step(double Y[2][NF], const double S[4], const double rhs[2],
                        double dc[NF]) {
  double A[4] = {S[0], S[1], S[2], S[3]}, l[2] = {rhs[0], rhs[1]};
  if (!km__solve_dense(A, l, 2)) return false;
  for (int i = 0; i < NF; i++) dc[i] = Y[0][i] * l[0] + Y[1][i] * l[1];
  return true;
}

/* theta_t plus the closure correction psi (coefficients c, started from
 * c), integrated over every piece: sum[2k], sum[2k+1] = integral of
 * e^(i theta) dr over piece k. scratch: e^(i theta) at the nodes (2 per
 * node).
 *
 * The lsq closure solves G(c) = 0 for the least change of curvature: with
 * project, a projection onto the linearised constraints (the minimum-norm
 * point of J c = J c_old - G in the metric integral psi'^2, whose Gram
 * matrix is Toeplitz with entries 2/3, -1/8, -1/5, -1/120) - how the
 * corrections frames start from are found - else a first step from c;
 * then steps dc = M^-1 J^T lambda with J dc = -G: with the first J (a
 * chord step) when the first change was at most 1e-3, else Newton steps
 * with fresh Jacobians, which converge quadratically. No pass follows the last
 * step when a bound on what it leaves says so:
 *   G(c + dc) = (J(c) - J(c0)) dc + R,
 * |J(c) - J(c0)| dc <= max|dc0| sum_i |dc_i| wb_i for the chord (|e^(i a)
 * - e^(i b)| <= |a - b|, and |psi change| <= max|dc| since the basis sums
 * to at most one; nothing for Newton), |R| <= max|dc|^2 / 2 (the Taylor
 * remainder of e^(i d), the weights summing to one). Below CLOSED_GAP the
 * pieces' sums take the linear change (linear_finish, each within its
 * share of the same bound) and the frame is closed to CLOSED_GAP of its
 * length, as by a further pass. */
km_status km__plan_close_frame(const km__frame_plan *p, double t, double theta0,
                               bool close_lsq, bool project, double *c,
                               double *sum, double *scratch, km__poll *poll) {
  double Lt = (1 - t) * p->La + t * p->Lb;
  bool lsq = close_lsq && p->closed;
  double *e = scratch;
  double cp[NF + 6] = {0}, dcp[NF + 6] = {0}, dc[NF], G[2], J[2][NF];
  double Y[2][NF], S[4];
  memcpy(cp + 3, c, sizeof dc);
  frame_pass(p, t, theta0, cp, NULL, false, sum, e, G, lsq ? J : NULL, poll);
  if (poll && poll->stopped) return KM_ECANCELLED;
  /* With the projection a start that is closed already is the answer
   * only if it is zero: the projection from it leads elsewhere, and the
   * frames beside it take that (a closed start kept at t = 1/2 stood 1.4%
   * of U_to_S's length off its neighbours at 1/2 +- 1e-6). */
  bool closed = Lt * hypot(G[0], G[1]) <= CLOSED_GAP * Lt;
  if (!lsq || (closed && (!project || max_abs(c, NF) == 0))) return KM_OK;
  metric_rows(p, J, Y, S);
  double rhs[2] = {-G[0], -G[1]};
  if (project) {
    for (int r = 0; r < 2; r++)
      for (int i = 0; i < NF; i++) rhs[r] += J[r][i] * c[i];
    if (!metric_step(Y, S, rhs, dc)) return KM_ENOCONVERGE;
    for (int i = 0; i < NF; i++) {
      double ci = dc[i];
      dc[i] = ci - c[i];
      c[i] = ci;
    }
  } else {
    if (!metric_step(Y, S, rhs, dc)) return KM_ENOCONVERGE;
    for (int i = 0; i < NF; i++) c[i] += dc[i];
  }
  /* A small first change leaves so little that a chord step with this
   * Jacobian finishes (the bound below); a large one needs Newton steps
   * with fresh Jacobians, which converge quadratically. */
  double dc0 = max_abs(dc, NF);
  bool chord = dc0 <= 1e-3;
  for (int it = 0;; it++) {
    memcpy(dcp + 3, dc, sizeof dc);
    frame_pass(p, t, theta0, cp, dcp, true, sum, e, G, chord ? NULL : J, poll);
    if (poll && poll->stopped) return KM_ECANCELLED;
    if (Lt * hypot(G[0], G[1]) <= CLOSED_GAP * Lt) return KM_OK;
    if (it == 40) return KM_ENOCONVERGE;
    if (!chord) metric_rows(p, J, Y, S);
    double r[2] = {-G[0], -G[1]}, cross = 0.0;
    if (!metric_step(Y, S, r, dc)) return KM_ENOCONVERGE;
    if (chord)
      for (int i = 0; i < NF; i++) cross += fabs(dc[i]) * p->wb[i];
    for (int i = 0; i < NF; i++) c[i] += dc[i];
    double d = max_abs(dc, NF);
    if (dc0 * cross + 0.5 * d * d <= CLOSED_GAP && isfinite(d)) {
      memcpy(dcp + 3, dc, sizeof dc);
      linear_finish(p, dcp, e, sum);
      return KM_OK;
    }
    chord = false; /* from here on, Newton */
  }
}

/* Closes a frame by its corners (km__close_by_corners) given the pieces'
 * integrals sum (rotated in place when they close it); dp[k] receives the
 * turn added before piece k. Scratch: tau, delta (nc each), S (2 (nc + 1)). */
km_status km__plan_corner_closure(const km__frame_plan *p, double t,
                                  double *sum, double *tau, double *delta,
                                  double *S, double *dp, bool *closes) {
  size_t np = p->np, nc = p->ncorners, m = 0;
  S[0] = S[1] = 0.0;
  for (size_t k = 0; k < np; k++) {
    if (m < nc && p->corner_at[m] == k) {
      size_t b = p->corner_at[m];
      tau[m] =
          (1 - t) * (p->ta_r[b] - p->ta_l[b]) + t * (p->tb_r[b] - p->tb_l[b]);
      m++;
      S[2 * m] = S[2 * m + 1] = 0.0;
    }
    S[2 * m] += sum[2 * k];
    S[2 * m + 1] += sum[2 * k + 1];
  }
  km_status st = km__close_by_corners(S, tau, nc, delta, closes);
  if (st || !*closes) return st;
  double d = 0.0;
  m = 0;
  for (size_t k = 0; k < np; k++) {
    if (m < nc && p->corner_at[m] == k) d += delta[m++];
    dp[k] = d;
    double cs = cos(d), sn = sin(d), x = sum[2 * k], y = sum[2 * k + 1];
    sum[2 * k] = cs * x - sn * y;
    sum[2 * k + 1] = sn * x + cs * y;
  }
  return KM_OK;
}

/* The closure correction a frame at t starts from: the polynomial through
 * the kept corrections (smooth in t, exact at each: frames move smoothly
 * through them, where a piecewise cubic left a kink). */
static void warm_start(const km__frame_plan *p, double t, double *c) {
  double x = t * WARM_POINTS;
  for (int i = 0; i < NF; i++) c[i] = 0.0;
  for (int j = 1; j < WARM_POINTS; j++) { /* the ends are zero */
    double l = 1.0;
    for (int q = 0; q <= WARM_POINTS; q++)
      if (q != j) l *= (x - q) / (double)(j - q);
    for (int i = 0; i < NF; i++) c[i] += l * p->c_at[j][i];
  }
}

/* The closure of frame t from the plan: by the corners where the plan
 * says so and they can (dp[k] then the turn added before piece k, else
 * left zero), else by the smooth curvature. c receives psi's
 * coefficients, sum the pieces' integrals (scratch: as
 * km__frame_plan_curve allocates it). */
static km_status frame_closure(const km__frame_plan *p, double t, double theta0,
                               bool close_lsq, double *c, double *sum,
                               double *dp, bool *corners, double *g0,
                               km__poll *poll) {
  size_t np = p->np, nc = p->ncorners;
  double *e = sum + 2 * np;
  double *tau = sum + km__plan_frame_scratch(p), *delta = tau + nc,
         *S = delta + nc;
  bool lsq = close_lsq && p->closed, by_corners = false;
  km_status st = KM_OK;
  for (size_t k = 0; k < np; k++) dp[k] = 0.0;
  if (lsq && p->by_corners) {
    st = km__plan_close_frame(p, t, theta0, false, false, c, sum, e, poll);
    /* that pass was theta_t's alone (c is zero): its gap, summed as the
     * pass sums it */
    if (!st && g0) {
      g0[0] = g0[1] = 0.0;
      for (size_t k = 0; k < np; k++) {
        g0[0] += sum[2 * k];
        g0[1] += sum[2 * k + 1];
      }
    }
    if (!st)
      st = km__plan_corner_closure(p, t, sum, tau, delta, S, dp, &by_corners);
  }
  if (corners) *corners = !st && by_corners;
  if (st || by_corners) return st;
  /* the smooth curvature takes the correction, by steps from the
   * cubic through the kept ones (warm_start): closed at those points
   * already, near it between them, so frames near each other take
   * nearly the same correction (continuous in t), and the ends none.
   * Should the steps fail, the projection from there, as the kept
   * corrections were found. */
  if (lsq) warm_start(p, t, c);
  st = km__plan_close_frame(p, t, theta0, close_lsq, false, c, sum, e, poll);
  if (st == KM_ENOCONVERGE && lsq) {
    warm_start(p, t, c);
    st = km__plan_close_frame(p, t, theta0, true, true, c, sum, e, poll);
  }
  return st;
}

/* The frame's cubic Hermite pieces: bz receives 8 values a piece (P0 Q1
 * Q2 P3), X its np + 1 knots (arc length), ends (if not NULL) the pieces'
 * end points from (0, 0) on, 2 (np + 1) values. */
static void hermite_pieces(const km__frame_plan *p, double t, double theta0,
                           const double *c, const double *sum, const double *dp,
                           double *bz, double *X, double *ends) {
  double Lt = (1 - t) * p->La + t * p->Lb, al = 1 - t, be = t;
  double P[2] = {0.0, 0.0};
  if (ends) ends[0] = ends[1] = 0.0;
  /* the tangent a piece ends with is the next one's start but at corners
   * (theta is continuous there to 1e-12, and so is the turn dp) */
  double c1 = 0.0, s1 = 0.0;
  for (size_t k = 0; k < p->np; k++) {
    double h = Lt * (p->x[k + 1] - p->x[k]), *B = bz + 8 * k;
    double th1 = theta0 + al * p->ta_l[k + 1] + be * p->tb_l[k + 1] +
                 psi_at_break(p, c, k + 1) + dp[k];
    double Pn[2] = {P[0] + Lt * sum[2 * k], P[1] + Lt * sum[2 * k + 1]};
    double c0 = c1, s0 = s1;
    if (k == 0 || p->corner[k]) {
      double th0 = theta0 + al * p->ta_r[k] + be * p->tb_r[k] +
                   psi_at_break(p, c, k) + dp[k];
      km__sincos(th0, &s0, &c0);
    }
    km__sincos(th1, &s1, &c1);
    X[k] = Lt * p->x[k];
    B[0] = P[0];
    B[1] = P[1];
    B[2] = P[0] + h / 3.0 * c0;
    B[3] = P[1] + h / 3.0 * s0;
    B[4] = Pn[0] - h / 3.0 * c1;
    B[5] = Pn[1] - h / 3.0 * s1;
    B[6] = Pn[0];
    B[7] = Pn[1];
    P[0] = Pn[0];
    P[1] = Pn[1];
    if (ends) {
      ends[2 * k + 2] = P[0];
      ends[2 * k + 3] = P[1];
    }
  }
  X[p->np] = Lt;
}

/* Bernstein coefficients of a polynomial of degree 9 on [0, 1] from its
 * values at i / 9, i = 0..9, by the inverse of the Bernstein collocation
 * matrix (its rows sum to at most 1368 in absolute value, which
 * multiplies the rounding of the values). Its first and last rows pick
 * the end values; row 9 - j is row j reversed, so rows 1..4 are kept as
 * their halves on the sums v_i + v_(9-i) (EVEN) and the differences v_i -
 * v_(9-i) (ODD), i = 0..4: coefficient j is EVEN.sum + ODD.diff, 9 - j
 * EVEN.sum - ODD.diff. */
static const double BERN9_EVEN[4][5] = {
    {-0.85892857142857137, 3.9375, -6.4285714285714288, 7, -3.1499999999999999},
    {1.0780133928571429, -7.2210937499999996, 18.763392857142858,
     -22.681249999999999, 10.5609375},
    {-0.93035714285714288, 7.1779017857142859, -22.329241071428573,
     33.161383928571432, -16.579687499999999},
    {0.37070312500000002, -3.0159040178571428, 10.0546875, -16.400669642857142,
     9.4911830357142861},
};
static const double BERN9_ODD[4][5] = {
    {-0.97003968253968254, 5.0625, -11.571428571428571, 21,
     -28.350000000000001},
    {1.5352554563492065, -11.815513392857143, 39.559821428571432,
     -78.543750000000003, 109.2234375},
    {-2.0503295068027212, 18.271492346938775, -71.62146045918368,
     162.30736607142856, -236.76227678571428},
    {2.357827558106576, -22.211073022959184, 92.641167091836735,
     -223.72968750000001, 342.74029017857146},
};

/* The larger of w and e, NaN once either is: comparisons, not fmax (a
 * call into libm here, 4% of a frame), and a NaN fails the merge. */
static inline double max_nan(double w, double e) {
  return (isnan(w) || e <= w) ? w : e;
}

/* A point or vector of the plane, x and y side by side in one SSE2
 * register (a GCC and Clang extension; gcc -O3 would not pair them by
 * itself here). Each lane rounds as the scalar expression would, in the
 * same order: the bounds are those of the coordinates taken apart, to the
 * bit. */
typedef double vec2 __attribute__((vector_size(16)));

static inline vec2 vec2_at(const double *p) {
  return (vec2){p[0], p[1]};
}

/* x^2 + y^2 */
static inline double norm2(vec2 v) {
  vec2 s = v * v;
  return s[0] + s[1];
}

/* A cubic in power form about u = 0: c[k] the coefficient of u^k. */
typedef struct cubic {
  vec2 c[4];
} cubic;

static void cubic_of(const double *M, cubic *q) {
  vec2 m0 = vec2_at(M), m1 = vec2_at(M + 2), m2 = vec2_at(M + 4),
       m3 = vec2_at(M + 6);
  q->c[0] = m0;
  q->c[1] = 3.0 * (m1 - m0);
  q->c[2] = 3.0 * (m2 - 2.0 * m1 + m0);
  q->c[3] = m3 - 3.0 * m2 + 3.0 * m1 - m0;
}

static inline vec2 cubic_at(const cubic *q, double u) {
  return q->c[0] + u * (q->c[1] + u * (q->c[2] + u * q->c[3]));
}

/* q' at u */
static inline vec2 cubic_d1(const cubic *q, double u) {
  return q->c[1] + u * (2.0 * q->c[2] + u * 3.0 * q->c[3]);
}

/* The parameter of the point of cubic q nearest point x, by Newton from u
 * (clamped to [0, 1]); *speed2 receives |q'|^2 there, *dist2 the squared
 * distance. */
static double project(const cubic *q, const double x[2], double u,
                      double *speed2, double *dist2) {
  vec2 c0 = q->c[0] - vec2_at(x), p, p1;
  /* any increasing match keeps merge_distance a bound: two steps from a
   * guess near the point make it close enough to be tight */
  for (int it = 0; it < 2; it++) {
    p = c0 + u * (q->c[1] + u * (q->c[2] + u * q->c[3]));
    p1 = cubic_d1(q, u);
    vec2 p2 = 2.0 * q->c[2] + 6.0 * u * q->c[3], pp = p * p1,
         dd = p1 * p1 + p * p2;
    /* summed from 0.0 as the coordinates were: the sign of a zero */
    double f = 0.0 + pp[0] + pp[1], fp = 0.0 + dd[0] + dd[1];
    if (!(fp > 0)) break;
    double du = f / fp;
    u -= du;
    u = u < 0.0 ? 0.0 : (u > 1.0 ? 1.0 : u);
  }
  p = c0 + u * (q->c[1] + u * (q->c[2] + u * q->c[3]));
  *speed2 = norm2(cubic_d1(q, u));
  *dist2 = norm2(p);
  return u;
}

/* The end speeds (legs over a third of the knot span H) of the cubic in
 * place of pieces a .. b - 1 by the arc formula: legs 2 c^2 / (3 (c +
 * T.d)) for chord d, |d| = c, end tangent T (a circular arc's best); 1
 * (the pieces' own, Hermite in arc length) for a single piece. False
 * where an end turns too far from the chord. Inline, as merged_cubic:
 * the calls were some 5% of a bound. */
static inline bool run_speeds(const double *bz, const double *X, size_t a,
                              size_t b, double v[2]) {
  v[0] = v[1] = 1.0;
  if (b == a + 1) return true;
  const double *A = bz + 8 * a, *B = bz + 8 * (b - 1);
  double d[2] = {B[6] - A[0], B[7] - A[1]}, c = sqrt(d[0] * d[0] + d[1] * d[1]);
  double t0[2] = {A[2] - A[0], A[3] - A[1]}, t1[2] = {B[6] - B[4], B[7] - B[5]};
  double n0 = sqrt(t0[0] * t0[0] + t0[1] * t0[1]),
         n1 = sqrt(t1[0] * t1[0] + t1[1] * t1[1]);
  if (!(c > 0 && n0 > 0 && n1 > 0)) return false;
  double k0 = c + (t0[0] * d[0] + t0[1] * d[1]) / n0,
         k1 = c + (t1[0] * d[0] + t1[1] * d[1]) / n1;
  /* an end more than some 140 degrees off the chord */
  if (k0 < 0.25 * c || k1 < 0.25 * c) return false;
  double H = X[b] - X[a];
  v[0] = 2 * c * c / (k0 * H);
  v[1] = 2 * c * c / (k1 * H);
  return true;
}

/* The cubic M (8 values, as bz) in place of pieces a .. b - 1: their end
 * points and end tangents, legs v[0] H / 3 and v[1] H / 3 over its knot
 * span H (speeds v in the arc-length knots). */
static inline void merged_cubic(const double *bz, const double *X, size_t a,
                                size_t b, const double v[2], double M[8]) {
  const double *A = bz + 8 * a, *B = bz + 8 * (b - 1);
  double H = X[b] - X[a], fa = v[0] * H / (X[a + 1] - X[a]),
         fb = v[1] * H / (X[b] - X[b - 1]);
  M[0] = A[0];
  M[1] = A[1];
  M[2] = A[0] + fa * (A[2] - A[0]);
  M[3] = A[1] + fa * (A[3] - A[1]);
  M[4] = B[6] + fb * (B[4] - B[6]);
  M[5] = B[7] + fb * (B[5] - B[7]);
  M[6] = B[6];
  M[7] = B[7];
}

/* The Bernstein weights of a cubic at i / 9, i = 0..9 */
static const double BERN3_AT_NINTHS[10][4] = {
    {1, 0, 0, 0},
    {512.0 / 729, 192.0 / 729, 24.0 / 729, 1.0 / 729},
    {343.0 / 729, 294.0 / 729, 84.0 / 729, 8.0 / 729},
    {216.0 / 729, 324.0 / 729, 162.0 / 729, 27.0 / 729},
    {125.0 / 729, 300.0 / 729, 240.0 / 729, 64.0 / 729},
    {64.0 / 729, 240.0 / 729, 300.0 / 729, 125.0 / 729},
    {27.0 / 729, 162.0 / 729, 324.0 / 729, 216.0 / 729},
    {8.0 / 729, 84.0 / 729, 294.0 / 729, 343.0 / 729},
    {1.0 / 729, 24.0 / 729, 192.0 / 729, 512.0 / 729},
    {0, 0, 0, 1}};

/* The parameters u[k - a] of M's points nearest the junctions of pieces
 * a .. b - 1 (u[0] = 0, u[b - a] = 1) and M's speed there over the
 * pieces' (slope[k - a], du / ds in the knot parameter s), from a first
 * guess in proportion to arc length; false if they do not increase, or
 * if a junction is past budget from M (slack added, as merges does:
 * merge_distance's bound is at least that). */
static bool match_junctions(const double *bz, const double *X, size_t a,
                            size_t b, const cubic *q, double budget,
                            double slack, double *u, double *slope) {
  double H = X[b] - X[a], sp2, d2, worst = 0.0, lim = budget - slack;
  u[0] = 0.0;
  u[b - a] = 1.0;
  for (size_t k = a + 1; k < b; k++) {
    u[k - a] = project(q, bz + 8 * k, (X[k] - X[a]) / H, &sp2, &d2);
    if (!(u[k - a] > u[k - a - 1] && sp2 > 0)) return false;
    /* the pieces' speed at a junction is 1 in s (legs a third of the
     * span): du / ds = 1 / |M'(u)| */
    slope[k - a] = 1.0 / sqrt(sp2);
    /* past the budget already (d2 > lim^2 only saves the root): the
     * largest distance can only grow */
    if (d2 > lim * lim && sqrt(d2) + slack > budget) return false;
    worst = max_nan(worst, d2);
  }
  if (!(u[b - a] > u[b - a - 1])) return false;
  for (size_t e = 0; e < 2; e++) {
    size_t i = e ? b - a : 0;
    double sp = sqrt(norm2(cubic_d1(q, u[i])));
    if (!(sp > 0)) return false;
    slope[i] = 1.0 / sp;
  }
  return !(sqrt(worst) + slack > budget);
}

/* A bound on the distance between cubic M (power form q) and pieces a ..
 * b - 1 (Frechet, so both ways), junctions matched by match_junctions:
 * piece k is matched with M over [u_k, u_k+1] by the cubic Hermite
 * reparametrisation g with those ends and slopes (increasing: its
 * Bernstein coefficients are), the difference P_k(s) - M(g(s)) is a
 * polynomial of degree 9, and its largest Bernstein coefficient bounds it
 * (a quadratic g left a tangential mismatch of some 3x the normal
 * distance). Stops (returning more) once past budget.
 *   A piece's value at 0 is the last one's at 1 (the same point, the same
 * u), and at 0 and 1 the weights (1, 0, 0, 0) leave g and the piece at
 * their ends: each piece works out nine values and one cubic at the
 * ends, to the bit what all ten would give. */
static double merge_distance(const double *bz, const double *X, size_t a,
                             size_t b, const cubic *q, const double *u,
                             const double *slope, double budget) {
  double worst = 0.0, b2 = budget * budget;
  vec2 D[10];
  D[9] = vec2_at(bz + 8 * a) - cubic_at(q, u[0]);
  worst = max_nan(worst, norm2(D[9]));
  for (size_t k = a; k < b && worst <= b2; k++) {
    const double *Pk = bz + 8 * k;
    double h = X[k + 1] - X[k], u0 = u[k - a], u1 = u[k - a + 1];
    double gb[4] = {u0, u0 + slope[k - a] * h / 3,
                    u1 - slope[k - a + 1] * h / 3, u1};
    if (!(gb[0] <= gb[1] && gb[1] <= gb[2] && gb[2] <= gb[3])) return INFINITY;
    vec2 P[4] = {vec2_at(Pk), vec2_at(Pk + 2), vec2_at(Pk + 4),
                 vec2_at(Pk + 6)};
    D[0] = D[9];
    /* values i and 9 - i, whose weights are each other's reversed: g at
     * both side by side */
    for (int i = 1; i < 5; i++) {
      const double *w = BERN3_AT_NINTHS[i], *v = BERN3_AT_NINTHS[9 - i];
      vec2 g = (vec2){w[0], v[0]} * gb[0] + (vec2){w[1], v[1]} * gb[1] +
               (vec2){w[2], v[2]} * gb[2] + (vec2){w[3], v[3]} * gb[3];
      D[i] = w[0] * P[0] + w[1] * P[1] + w[2] * P[2] + w[3] * P[3] -
             cubic_at(q, g[0]);
      D[9 - i] = v[0] * P[0] + v[1] * P[1] + v[2] * P[2] + v[3] * P[3] -
                 cubic_at(q, g[1]);
    }
    D[9] = P[3] - cubic_at(q, u1);
    vec2 S[5], T[5];
    for (int i = 0; i < 5; i++) {
      S[i] = D[i] + D[9 - i];
      T[i] = D[i] - D[9 - i];
    }
    /* coefficients j and 9 - j, their squared norms side by side in V[j];
     * their largest, and their sum to catch a NaN (which the largest
     * drops) */
    vec2 V[4], all = {0.0, 0.0};
    for (int j = 0; j < 4; j++) {
      vec2 e = {0.0, 0.0}, o = {0.0, 0.0};
      for (int i = 0; i < 5; i++) {
        e += BERN9_EVEN[j][i] * S[i];
        o += BERN9_ODD[j][i] * T[i];
      }
      vec2 l = e + o, r = e - o;
      l *= l;
      r *= r;
      V[j] = (vec2){l[0], r[0]} + (vec2){l[1], r[1]};
      all += V[j];
    }
    if (isnan(all[0] + all[1])) return NAN;
    double top = V[0][0];
    for (int j = 0; j < 4; j++)
      for (int s = 0; s < 2; s++) top = V[j][s] > top ? V[j][s] : top;
    worst = max_nan(worst, top);
    worst = max_nan(worst, norm2(D[9]));
  }
  return sqrt(worst);
}

/* Whether the frame's tangent is continuous at a corner k of the plan
 * (one input's, which this frame does not turn at: frames 0 and 1). */
static bool turns_not(const double *bz, size_t k) {
  const double *A = bz + 8 * (k - 1), *B = bz + 8 * k;
  double ax = A[6] - A[4], ay = A[7] - A[5], bx = B[2] - B[0], by = B[3] - B[1];
  double cross = ax * by - ay * bx, dot = ax * bx + ay * by;
  return dot > 0 && fabs(cross) <= 1e-12 * dot;
}

/* Whether pieces a .. b - 1 merge into one cubic within budget
 * (merge_distance). u and slope are scratch (b - a + 1 each). */
static bool merges(const double *bz, const double *X, size_t a, size_t b,
                   double budget, double slack, double *u, double *slope) {
  double M[8], v[2];
  cubic q;
  if (!run_speeds(bz, X, a, b, v)) return false;
  merged_cubic(bz, X, a, b, v, M);
  cubic_of(M, &q);
  if (!match_junctions(bz, X, a, b, &q, budget, slack, u, slope)) return false;
  return merge_distance(bz, X, a, b, &q, u, slope, budget) + slack <= budget;
}

/* The frame's pieces merged into runs, each one cubic with its own end
 * speeds (run_speeds): run[j] the first piece of run j (run[nr] = np).
 * Runs grow greedily while the bound allows (merges), never across a
 * corner the frame turns at. Returns nr. u, slope:
 * scratch, np + 1 each. */
static size_t merge_runs(const km__frame_plan *p, const double *bz,
                         const double *X, double budget, size_t *run, double *u,
                         double *slope) {
  size_t np = p->np, nr = 0, a = 0;
  /* the bound is computed in the frame's coordinates (within its length
   * of the origin): rounding there is some units of the last place of
   * the length, times the 1368 of the collocation inverse (BERN9_EVEN,
   * BERN9_ODD) */
  double slack = 1e-11 * X[np];
  /* runs of a frame are of similar lengths: each starts from the last
   * one's and grows or shrinks by the bound */
  size_t guess = 2, stop = 0;
  while (a < np) {
    /* the first corner past a the frame turns at: the same for every run
     * before it */
    if (stop <= a) {
      stop = a + 1;
      while (stop < np && (!p->corner[stop] || turns_not(bz, stop))) stop++;
    }
    size_t b = a + guess < stop ? a + guess : stop;
    while (b > a + 1 && !merges(bz, X, a, b, budget, slack, u, slope)) b--;
    if (b == a + guess)
      while (b < stop && merges(bz, X, a, b + 1, budget, slack, u, slope)) b++;
    run[nr++] = a;
    guess = b - a + 1;
    a = b;
  }
  run[nr] = np;
  return nr;
}

/* The frame's control points into *f (initialised, empty) from its
 * pieces bz at knots X merged by runs run[0 .. nr]: P0, then Q1 Q2 of
 * every run, with the junction point itself at corners (triple knots;
 * double elsewhere). A run's own end speeds differ from its neighbours',
 * and the B-spline is C1 at a double knot: its legs either side are in
 * the ratio of the knot spans. So the spans follow the legs (a run's span
 * is 3 l0 / w for its first leg l0 and the speed w the join before it
 * takes, the next join's speed w l1 / l0), from speed 1 at the start and
 * after every corner, and all are then scaled to the frame's length: a
 * circle's knots stay at arc length, others within the ratios of their
 * runs' end speeds (a few percent at most). KM_EINVAL (*msg) if the
 * counts disagree. */
static km_status frame_points_of_runs(const km__frame_plan *p, const double *bz,
                                      const double *X, const size_t *run,
                                      size_t nr, km_curve *f,
                                      const char **msg) {
  size_t ncorner = 0;
  for (size_t j = 1; j < nr; j++) ncorner += p->corner[run[j]];
  size_t ncp = 2 * nr + 2 + ncorner, nknots = ncp + 4;
  km_status st = km__curve_alloc(f, 3, ncp, false);
  if (st) return st;
  size_t cc = 0, kk = 0;
  double w = 1.0, total = 0.0;
  for (int r = 0; r < 4; r++) f->knots[kk++] = 0.0;
  f->cp[cc++] = bz[0];
  f->cp[cc++] = bz[1];
  for (size_t j = 0; j < nr; j++) {
    double M[8], v[2];
    run_speeds(bz, X, run[j], run[j + 1], v);
    merged_cubic(bz, X, run[j], run[j + 1], v, M);
    if (j > 0 && p->corner[run[j]]) {
      f->cp[cc++] = M[0];
      f->cp[cc++] = M[1];
      w = 1.0;
    }
    for (int q = 2; q < 6; q++) f->cp[cc++] = M[q];
    double l0 = hypot(M[2] - M[0], M[3] - M[1]),
           l1 = hypot(M[6] - M[4], M[7] - M[5]);
    total += 3 * l0 / w;
    w *= l1 / l0;
    if (j + 1 < nr) {
      int mult = p->corner[run[j + 1]] ? 3 : 2;
      for (int r = 0; r < mult; r++) f->knots[kk++] = total;
    }
  }
  f->cp[cc++] = bz[8 * p->np - 2];
  f->cp[cc++] = bz[8 * p->np - 1];
  for (int r = 0; r < 4; r++) f->knots[kk++] = X[p->np];
  if (cc != 2 * ncp || kk != nknots || !(total > 0)) {
    *msg = "internal inconsistency building a frame";
    return KM_EINVAL;
  }
  double scale = X[p->np] / total;
  for (size_t i = 4; i + 4 < nknots; i++) f->knots[i] *= scale;
  return KM_OK;
}

km_status km__frame_plan_curve(const km__frame_plan *p, double t, double theta0,
                               bool close_lsq, bool merge, km_curve *out,
                               double *ends, km__plan_closure *closure,
                               km__poll *poll, km_error *err) {
  double c[NF] = {0};
  /* sums of the pieces, scratch of the nodes, and per corner its turn,
   * its change and the stretch sums; per piece the turn added before it,
   * its Bezier points and knot, and the runs merged */
  size_t np = p->np, nc = p->ncorners,
         scratch = km__plan_frame_scratch(p) + 4 * nc + 2;
  size_t ndouble = scratch + np + 8 * np + 3 * (np + 1);
  double *sum =
      km__malloc(ndouble * sizeof(double) + (np + 1) * sizeof(size_t));
  if (!sum) return km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
  double *dp = sum + scratch, *bz = dp + np, *X = bz + 8 * np, *u = X + np + 1,
         *slope = u + np + 1;
  size_t *run = (size_t *)(sum + ndouble);
  const char *msg = "closing the frame did not converge";
  km_curve f;
  km_curve_init(&f);
  km_status st = KM_OK;
  /* the gap of theta_t alone, as the general path measures it: the first
   * pass of a closure by the corners is that pass already */
  double G[2] = {NAN, NAN};
  bool gap_from_closure = close_lsq && p->closed && p->by_corners;
  if (closure) {
    memset(closure, 0, sizeof *closure);
    if (p->closed && !gap_from_closure) {
      double zero[NF + 6] = {0};
      frame_pass(p, t, theta0, zero, NULL, false, sum, sum + 2 * np, G, NULL,
                 poll);
    }
  }
  if (!(poll && poll->stopped))
    st = frame_closure(p, t, theta0, close_lsq, c, sum, dp,
                       closure ? &closure->by_corners : NULL,
                       closure && gap_from_closure ? G : NULL, poll);
  if (closure && p->closed && !isnan(G[0]))
    closure->gap0 = ((1 - t) * p->La + t * p->Lb) * hypot(G[0], G[1]);
  if (st == KM_ECANCELLED || (poll && poll->stopped)) {
    st = KM_ECANCELLED;
    goto done;
  }
  if (st) goto done;
  msg = NULL;
  if (closure) memcpy(closure->c, c, sizeof closure->c);
  hermite_pieces(p, t, theta0, c, sum, dp, bz, X, ends);
  size_t nr = np;
  if (merge)
    nr = merge_runs(p, bz, X, KM__PLAN_MERGE_SHARE * p->tol, run, u, slope);
  else
    for (size_t k = 0; k <= np; k++) run[k] = k;
  st = frame_points_of_runs(p, bz, X, run, nr, &f, &msg);
  if (st) goto done;
  f.closed = false;
  const double *P = bz + 8 * np - 2;
  if (p->closed && hypot(P[0], P[1]) <= p->tol) {
    size_t ncp = f.n;
    f.cp[2 * (ncp - 1)] = f.cp[0];
    f.cp[2 * (ncp - 1) + 1] = f.cp[1];
    f.closed = true;
  }
  *out = f;
  km_curve_init(&f);
done:
  km__free(sum);
  km_curve_free(&f);
  if (st == KM_ECANCELLED) return km__stopped(err);
  if (st) return km__fail(err, st, KM_FIELD_NONE, -1, NAN, msg);
  return KM_OK;
}
