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
                               double *dp, km__poll *poll) {
  size_t np = p->np, nc = p->ncorners;
  double *e = sum + 2 * np;
  double *tau = sum + km__plan_frame_scratch(p), *delta = tau + nc,
         *S = delta + nc;
  bool lsq = close_lsq && p->closed, by_corners = false;
  km_status st = KM_OK;
  for (size_t k = 0; k < np; k++) dp[k] = 0.0;
  if (lsq && p->by_corners) {
    st = km__plan_close_frame(p, t, theta0, false, false, c, sum, e, poll);
    if (!st)
      st = km__plan_corner_closure(p, t, sum, tau, delta, S, dp, &by_corners);
  }
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

/* The frame's cubic Hermite control points into *f (initialised, empty):
 * P0, then Q1 Q2 of every piece, with the junction point itself at
 * corners (triple knots; double elsewhere); ends as km__frame_plan_curve.
 * *P the end point. KM_EINVAL (*msg) if the counts disagree. */
static km_status hermite_points(const km__frame_plan *p, double t,
                                double theta0, const double *c,
                                const double *sum, const double *dp,
                                km_curve *f, double *ends, double P[2],
                                const char **msg) {
  double Lt = (1 - t) * p->La + t * p->Lb, al = 1 - t, be = t;
  size_t np = p->np, ncorner = 0;
  for (size_t k = 1; k < np; k++) ncorner += p->corner[k];
  size_t ncp = 2 * np + 2 + ncorner, nknots = ncp + 4;
  km_status st = km__curve_alloc(f, 3, ncp, false);
  if (st) return st;
  size_t cc = 0, kk = 0;
  P[0] = P[1] = 0.0;
  for (int r = 0; r < 4; r++) f->knots[kk++] = 0.0;
  f->cp[cc++] = 0.0;
  f->cp[cc++] = 0.0;
  if (ends) ends[0] = ends[1] = 0.0;
  /* the tangent a piece ends with is the next one's start but at corners
   * (theta is continuous there to 1e-12, and so is the turn dp) */
  double c1 = 0.0, s1 = 0.0;
  for (size_t k = 0; k < np; k++) {
    double h = Lt * (p->x[k + 1] - p->x[k]);
    double th1 = theta0 + al * p->ta_l[k + 1] + be * p->tb_l[k + 1] +
                 psi_at_break(p, c, k + 1) + dp[k];
    double Pn[2] = {P[0] + Lt * sum[2 * k], P[1] + Lt * sum[2 * k + 1]};
    if (k > 0 && p->corner[k]) {
      f->cp[cc++] = P[0];
      f->cp[cc++] = P[1];
    }
    double c0 = c1, s0 = s1;
    if (k == 0 || p->corner[k]) {
      double th0 = theta0 + al * p->ta_r[k] + be * p->tb_r[k] +
                   psi_at_break(p, c, k) + dp[k];
      km__sincos(th0, &s0, &c0);
    }
    km__sincos(th1, &s1, &c1);
    f->cp[cc++] = P[0] + h / 3.0 * c0;
    f->cp[cc++] = P[1] + h / 3.0 * s0;
    f->cp[cc++] = Pn[0] - h / 3.0 * c1;
    f->cp[cc++] = Pn[1] - h / 3.0 * s1;
    if (k + 1 < np) {
      int mult = p->corner[k + 1] ? 3 : 2;
      for (int r = 0; r < mult; r++) f->knots[kk++] = Lt * p->x[k + 1];
    }
    P[0] = Pn[0];
    P[1] = Pn[1];
    if (ends) {
      ends[2 * k + 2] = P[0];
      ends[2 * k + 3] = P[1];
    }
  }
  f->cp[cc++] = P[0];
  f->cp[cc++] = P[1];
  for (int r = 0; r < 4; r++) f->knots[kk++] = Lt;
  if (cc != 2 * ncp || kk != nknots) {
    *msg = "internal inconsistency building a frame";
    return KM_EINVAL;
  }
  return KM_OK;
}

km_status km__frame_plan_curve(const km__frame_plan *p, double t, double theta0,
                               bool close_lsq, km_curve *out, double *ends,
                               km__poll *poll, km_error *err) {
  double c[NF] = {0}, P[2];
  /* sums of the pieces, scratch of the nodes, and per corner its turn,
   * its change and the stretch sums; per piece the turn added before it */
  size_t nc = p->ncorners, scratch = km__plan_frame_scratch(p) + 4 * nc + 2;
  double *sum = km__malloc((scratch + p->np) * sizeof(double));
  if (!sum) return km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
  const char *msg = "closing the frame did not converge";
  km_curve f;
  km_curve_init(&f);
  km_status st =
      frame_closure(p, t, theta0, close_lsq, c, sum, sum + scratch, poll);
  if (st == KM_ECANCELLED || (poll && poll->stopped)) {
    st = KM_ECANCELLED;
    goto done;
  }
  if (st) goto done;
  msg = NULL;
  st = hermite_points(p, t, theta0, c, sum, sum + scratch, &f, ends, P, &msg);
  if (st) goto done;
  f.closed = false;
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

km_status km__frame_plan_closure(const km__frame_plan *p, double t,
                                 double theta0, double *c, double *gap0,
                                 bool *by_psi, km__poll *poll) {
  *by_psi = false;
  if (!p->closed || p->by_corners) return KM_OK;
  size_t nc = p->ncorners, scratch = km__plan_frame_scratch(p) + 4 * nc + 2;
  double *sum = km__malloc((scratch + p->np) * sizeof(double));
  if (!sum) return KM_ENOMEM;
  /* theta_t alone: its gap, as the general path measures it */
  double zero[NF + 6] = {0}, G[2], Lt = (1 - t) * p->La + t * p->Lb;
  frame_pass(p, t, theta0, zero, NULL, false, sum, sum + 2 * p->np, G, NULL,
             poll);
  km_status st = KM_OK;
  if (poll && poll->stopped) st = KM_ECANCELLED;
  double cf[NF] = {0};
  if (!st) st = frame_closure(p, t, theta0, true, cf, sum, sum + scratch, poll);
  if (!st && poll && poll->stopped) st = KM_ECANCELLED;
  if (!st) {
    memcpy(c, cf, sizeof cf);
    *gap0 = Lt * hypot(G[0], G[1]);
    *by_psi = true;
  }
  km__free(sum);
  return st;
}
