/* morph_closure.c - closing the frames of closed morphs.
 *
 * DESIGN. The tangent closes by itself (equal turning numbers); the
 * position is closed by "lsq", the least change of curvature that closes
 * the frame, in one of two forms chosen once per morph (plan_frames in
 * morph.c): frames with corners close by turning them
 * (km__close_by_corners: least sum of squared changes weighted by each
 * corner's turn, total turning kept), which leaves the curvature between
 * corners the blend's - straight edges stay straight, the bound holds;
 * otherwise theta~ = theta_t + psi with psi a combination of interior
 * uniform cubic B-splines (psi and psi' vanish at the seam, so the seam
 * stays G2), minimising the L2 change of curvature ||psi'||^2 subject to
 * the two closure equations (Gauss-Newton), after Saba, Schneider,
 * Hormann and Scateni (2014). The Gram matrix of the basis derivatives is
 * Toeplitz with entries 2/3, -1/8, -1/5, -1/120. The paper's
 * control-polygon corrections (c0, c1, g2) remain selectable. Planned
 * frames (morph_plan_frame.c) close with the same basis and metric.
 */
#include <math.h>
#include <string.h>

#include "internal.h"
#include "km/alloc.h"
#include "km/limits.h"
#include "morph_closure.h"
#include "morph_internal.h"

#define NB KM__CLOSURE_INTERVALS
#define NF (KM__CLOSURE_INTERVALS - 3)

/* ---- basis and metric -------------------------------------------------- */

double km__bspline3_d(double u) {
  if (u <= 0 || u >= 4) return 0.0;
  if (u < 1) return u * u / 2.0;
  if (u < 2) return (-9 * u * u + 24 * u - 12) / 6.0;
  if (u < 3) return (9 * u * u - 48 * u + 60) / 6.0;
  double v = 4 - u;
  return -v * v / 2.0;
}

double km__bspline3(double u) {
  if (u <= 0 || u >= 4) return 0.0;
  if (u < 1) return u * u * u / 6.0;
  if (u < 2) return (-3 * u * u * u + 12 * u * u - 12 * u + 4) / 6.0;
  if (u < 3) return (3 * u * u * u - 24 * u * u + 60 * u - 44) / 6.0;
  double v = 4 - u;
  return v * v * v / 6.0;
}

void km__closure_metric_weighted(const double *w, double *M) {
  /* per interval the four basis derivatives are quadratics: three Gauss
   * points integrate their products exactly */
  static const double X[3] = {0.11270166537925831, 0.5, 0.88729833462074169};
  static const double W[3] = {5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0};
  memset(M, 0, NF * NF * sizeof(double));
  for (int iv = 0; iv < NB; iv++)
    for (int g = 0; g < 3; g++) {
      double u = iv + X[g], d[NF];
      for (int i = 0; i < NF; i++) d[i] = km__bspline3_d(u - i);
      for (int i = 0; i < NF; i++) {
        if (d[i] == 0.0) continue;
        for (int j = 0; j < NF; j++)
          M[i * NF + j] += w[iv] * W[g] * d[i] * d[j];
      }
    }
}

void km__closure_metric(double *M) {
  static const double band[4] = {2.0 / 3.0, -1.0 / 8.0, -1.0 / 5.0,
                                 -1.0 / 120.0};
  for (int i = 0; i < NF; i++)
    for (int j = 0; j < NF; j++) {
      int d = i > j ? i - j : j - i;
      M[i * NF + j] = d < 4 ? band[d] : 0.0;
    }
}

/* Cholesky of the Toeplitz metric (exact entries, see DESIGN). */
bool km__closure_metric_factor(double *Lc) {
  double M[NF * NF];
  km__closure_metric(M);
  memset(Lc, 0, NF * NF * sizeof(double));
  for (int i = 0; i < NF; i++)
    for (int j = 0; j <= i; j++) {
      double v = M[i * NF + j];
      for (int k = 0; k < j; k++) v -= Lc[i * NF + k] * Lc[j * NF + k];
      if (i == j) {
        if (!(v > 0)) return false;
        Lc[i * NF + i] = sqrt(v);
      } else {
        Lc[i * NF + j] = v / Lc[j * NF + j];
      }
    }
  return true;
}

void km__closure_metric_solve(const double *Lc, double *y) {
  for (int i = 0; i < NF; i++) {
    double v = y[i];
    for (int k = 0; k < i; k++) v -= Lc[i * NF + k] * y[k];
    y[i] = v / Lc[i * NF + i];
  }
  for (int i = NF - 1; i >= 0; i--) {
    double v = y[i];
    for (int k = i + 1; k < NF; k++) v -= Lc[k * NF + i] * y[k];
    y[i] = v / Lc[i * NF + i];
  }
}

km_status km__close_by_corners(const double *S, const double *tau, size_t nc,
                               double *delta, bool *closes) {
  *closes = false;
  if (nc < 3) return KM_OK;
  double *W = km__malloc((4 * nc + 1) * sizeof(double));
  if (!W) return KM_ENOMEM;
  double *D = W + nc, *J = W + 2 * nc + 1; /* J: 2 nc (suffix sums) */
  double wsum = 0.0;
  for (size_t k = 0; k < nc; k++) {
    W[k] = fabs(tau[k]);
    wsum += W[k];
    delta[k] = 0.0;
  }
  bool ok = false;
  for (int it = 0; it < 60 && wsum > 0; it++) {
    /* D_m = delta_1 + ... + delta_m; G = sum_m e^(i D_m) S_m and the
     * derivatives i sum_(m >= k) e^(i D_m) S_m (suffix sums) */
    D[0] = 0.0;
    for (size_t k = 0; k < nc; k++) D[k + 1] = D[k] + delta[k];
    double gx = 0.0, gy = 0.0;
    for (size_t m = nc + 1; m-- > 0;) {
      double c = cos(D[m]), sn = sin(D[m]);
      gx += c * S[2 * m] - sn * S[2 * m + 1];
      gy += sn * S[2 * m] + c * S[2 * m + 1];
      if (m >= 1) {
        J[2 * (m - 1)] = -gy;    /* d gx / d delta_m */
        J[2 * (m - 1) + 1] = gx; /* d gy / d delta_m */
      }
    }
    if (hypot(gx, gy) <= 1e-14) {
      ok = true;
      break;
    }
    /* least sum delta^2 / W with the linearised constraints
     * A delta = A delta_old - (gx, gy, 0), A = (Jx; Jy; 1 ... 1):
     * delta = W A^T (A W A^T)^-1 rhs */
    double M[9] = {0}, rhs[3] = {-gx, -gy, 0.0};
    for (size_t k = 0; k < nc; k++) {
      double a[3] = {J[2 * k], J[2 * k + 1], 1.0};
      for (int r = 0; r < 3; r++) {
        rhs[r] += a[r] * delta[k];
        for (int q = 0; q < 3; q++) M[r * 3 + q] += W[k] * a[r] * a[q];
      }
    }
    if (!km__solve_dense(M, rhs, 3)) break;
    for (size_t k = 0; k < nc; k++)
      delta[k] = W[k] * (J[2 * k] * rhs[0] + J[2 * k + 1] * rhs[1] + rhs[2]);
  }
  /* a corner may change by at most half its turn: beyond that the shape
   * would be closed by corners it hardly has */
  for (size_t k = 0; ok && k < nc; k++)
    if (fabs(delta[k]) > 0.5 * fabs(tau[k])) ok = false;
  km__free(W);
  *closes = ok;
  return KM_OK;
}

/* ---- closing a blended signature --------------------------------------- */

typedef struct qnode {
  double s, w, theta;
} qnode;

/* Gauss-Legendre nodes over the theta pieces, split at the uniform breaks
 * of the closure basis and chunked so theta moves <= 0.5 rad per 8-point
 * rule (exact to rounding there, see km__integrate_exp). */
static km_status closure_nodes(const km_pp *kp, const km_pp *tp, double h,
                               km__poll *poll, qnode **out, size_t *nout) {
  size_t cap = 0, n = 0;
  qnode *q = NULL;
  int dk = kp->degree, dt = tp->degree;
  for (size_t i = 0; i < tp->m; i++) {
    double a = tp->x[i], b = tp->x[i + 1], len = b - a;
    if (!(len > 0)) continue;
    double kb = km__bern_abs_bound(kp->c + i * (size_t)(dk + 1), dk);
    double lo = a;
    while (lo < b) {
      double next_break = (floor(lo / h + 1e-12) + 1) * h;
      double hi = fmin(b, next_break);
      if (hi <= lo) hi = b;
      int chunks = (int)ceil(kb * (hi - lo) / 0.5);
      if (chunks < 1) chunks = 1;
      if (km__poll_stop(poll, 8L * chunks)) {
        km__free(q);
        return KM_ECANCELLED;
      }
      for (int c = 0; c < chunks; c++) {
        double ca = lo + (hi - lo) * c / chunks,
               cb = lo + (hi - lo) * (c + 1) / chunks;
        double mid = 0.5 * (ca + cb), hw = 0.5 * (cb - ca);
        if (n + 8 > cap) {
          cap = cap ? 2 * cap : 1024;
          if (cap > 64 * (size_t)KM_MAX_PIECES) {
            km__free(q);
            return KM_ELIMIT;
          }
          qnode *nq = km__realloc(q, cap * sizeof *nq);
          if (!nq) {
            km__free(q);
            return KM_ENOMEM;
          }
          q = nq;
        }
        for (int k = 0; k < 8; k++) {
          double s = mid + hw * km__gl8_x[k];
          q[n].s = s;
          q[n].w = hw * km__gl8_w[k];
          q[n].theta =
              km__bern_eval(tp->c + i * (size_t)(dt + 1), dt, (s - a) / len);
          n++;
        }
      }
      lo = hi;
    }
  }
  *out = q;
  *nout = n;
  return KM_OK;
}

/* The integrals of e^(i theta) over the stretches between the interior
 * corners of sig (nc of them: S has 2 (nc + 1) values, tau their turns;
 * delta room for nc changes, all in one block at S), and the gap they sum
 * to. */
typedef struct stretches {
  double *S, *tau, *delta;
  size_t nc;
} stretches;

static km_status stretch_sums(const km_signature *sig, const qnode *q,
                              size_t nq, stretches *sc, double *gap) {
  double L = sig->length;
  size_t nc = 0, m = 0, ci = 0;
  for (size_t k = 0; k < sig->ncorners; k++)
    if (sig->corners[k].s > 0 && sig->corners[k].s < L) nc++;
  double *S = sc->S = km__malloc((4 * nc + 2) * sizeof(double));
  if (!S) return KM_ENOMEM;
  sc->nc = nc;
  sc->tau = S + 2 * (nc + 1);
  sc->delta = sc->tau + nc;
  S[0] = S[1] = 0.0;
  for (size_t n = 0; n < nq; n++) {
    while (ci < sig->ncorners && sig->corners[ci].s <= q[n].s) {
      if (sig->corners[ci].s > 0 && sig->corners[ci].s < L) {
        sc->tau[m++] = sig->corners[ci].turn;
        S[2 * m] = S[2 * m + 1] = 0.0;
      }
      ci++;
    }
    S[2 * m] += q[n].w * cos(q[n].theta);
    S[2 * m + 1] += q[n].w * sin(q[n].theta);
  }
  double gx = 0.0, gy = 0.0;
  for (size_t k = 0; k <= nc; k++) {
    gx += S[2 * k];
    gy += S[2 * k + 1];
  }
  *gap = hypot(gx, gy);
  return KM_OK;
}

/* sig with its interior corners turned by delta more (in order). */
static km_status turn_corners(const km_signature *sig, const double *delta,
                              km_signature *out, km_error *err) {
  double L = sig->length;
  km_corner *cs = km__malloc((sig->ncorners + 1) * sizeof *cs);
  if (!cs) return KM_ENOMEM;
  for (size_t k = 0, m = 0; k < sig->ncorners; k++) {
    cs[k] = sig->corners[k];
    if (cs[k].s > 0 && cs[k].s < L) cs[k].turn += delta[m++];
  }
  km_status st =
      km_signature_create(out, L, sig->start, sig->angle, &sig->kappa, cs,
                          sig->ncorners, sig->closed, err);
  km__free(cs);
  return st;
}

/* The closure's residual G = integral of e^(i (theta + psi)) over the
 * nodes and its Jacobian J in the coefficients c; true when poll says
 * stop (G and J then unusable). */
static bool closure_residual(const qnode *q, size_t nq, double h,
                             const double *c, double G[2], double J[2][NF],
                             km__poll *poll) {
  G[0] = G[1] = 0.0;
  memset(J, 0, 2 * sizeof *J);
  for (size_t n = 0; n < nq; n++) {
    if ((n & 255) == 0 && km__poll_stop(poll, 512)) return true;
    double u = q[n].s / h, th = q[n].theta;
    int i0 = (int)floor(u) - 3;
    double bv[4];
    for (int k = 0; k < 4; k++) {
      int i = i0 + k;
      bv[k] = (i >= 0 && i < NF) ? km__bspline3(u - i) : 0.0;
      th += (i >= 0 && i < NF) ? c[i] * bv[k] : 0.0;
    }
    double cs = cos(th), sn = sin(th);
    G[0] += q[n].w * cs;
    G[1] += q[n].w * sn;
    for (int k = 0; k < 4; k++) {
      int i = i0 + k;
      if (i < 0 || i >= NF) continue;
      J[0][i] -= q[n].w * sn * bv[k];
      J[1][i] += q[n].w * cs * bv[k];
    }
  }
  return false;
}

/* One Gauss-Newton step of c in the metric M: with project, the
 * projection (the least change of curvature that meets the linearised
 * constraints), else a minimum-norm step (quadratic convergence); as in
 * morph_plan_frame.c. False when a system is singular. */
static bool closure_step(const double *M, double J[2][NF], const double G[2],
                         bool project, double *c) {
  double Y[2][NF];
  for (int r = 0; r < 2; r++) {
    double A[NF * NF];
    memcpy(A, M, sizeof A);
    memcpy(Y[r], J[r], sizeof Y[r]);
    if (!km__solve_dense(A, Y[r], NF)) return false;
  }
  double S2[4] = {0, 0, 0, 0};
  for (int r = 0; r < 2; r++)
    for (int k = 0; k < 2; k++)
      for (int i = 0; i < NF; i++) S2[r * 2 + k] += J[r][i] * Y[k][i];
  double rhs[2];
  for (int r = 0; r < 2; r++) {
    rhs[r] = -G[r];
    if (project)
      for (int i = 0; i < NF; i++) rhs[r] += J[r][i] * c[i];
  }
  if (!km__solve_dense(S2, rhs, 2)) return false;
  for (int i = 0; i < NF; i++)
    c[i] = (project ? 0.0 : c[i]) + Y[0][i] * rhs[0] + Y[1][i] * rhs[1];
  return true;
}

/* The coefficients c of psi (from zero) that close the frame to 1e-12 of
 * its length L, in the metric of the basis derivatives in s (weighted by
 * weights when not NULL). */
static km_status closure_coefficients(const qnode *q, size_t nq, double L,
                                      const double *weights, double *c,
                                      km__poll *poll) {
  double h = L / NB, M[NF * NF];
  if (weights)
    km__closure_metric_weighted(weights, M);
  else
    km__closure_metric(M);
  for (int i = 0; i < NF * NF; i++) M[i] /= h;
  for (int it = 0;; it++) {
    double G[2], J[2][NF];
    if (closure_residual(q, nq, h, c, G, J, poll)) return KM_ECANCELLED;
    if (hypot(G[0], G[1]) <= 1e-12 * L) return KM_OK;
    if (it == 40) return KM_ENOCONVERGE;
    if (!closure_step(M, J, G, it == 0, c)) return KM_ENOCONVERGE;
  }
}

/* sig with kappa~ = kappa + psi' (psi' is quadratic on each basis
 * interval, so exact in Bernstein form from three values). */
km_status km__closure_kappa(const km_pp *kappa, double L, const double *c,
                            km_pp *out) {
  double h = L / NB;
  km_pp dpsi;
  km__pp_init(&dpsi);
  km_status st = km__pp_alloc(&dpsi, 2, NB);
  if (st) return st;
  for (int iv = 0; iv < NB; iv++) {
    double f[3];
    for (int k = 0; k < 3; k++) {
      double u = iv + 0.5 * k, v = 0.0;
      /* only B(u - i) with 0 < u - i < 4 is not zero: four of them */
      int lo = iv - 4 > 0 ? iv - 4 : 0, hi = iv + 1 < NF ? iv + 1 : NF - 1;
      for (int i = lo; i <= hi; i++) v += c[i] * km__bspline3_d(u - i);
      f[k] = v / h;
    }
    double *bc = dpsi.c + (size_t)iv * 3;
    bc[0] = f[0];
    bc[2] = f[2];
    bc[1] = 2 * f[1] - 0.5 * (f[0] + f[2]);
    dpsi.x[iv] = iv * h;
  }
  dpsi.x[NB] = L;
  st = km__pp_blend(out, kappa, 1.0, &dpsi, 1.0, 0.0, L);
  km__pp_free(&dpsi);
  return st;
}

km_status km__signature_with_kappa(const km_signature *sig, const km_pp *kt,
                                   km_signature *out, km_error *err) {
  km_fn kf;
  km_fn_init(&kf);
  km_status st = km__pp_to_fn(&kf, kt);
  if (st) st = km__fail(err, st, KM_FIELD_NONE, -1, NAN, NULL);
  if (!st)
    st = km_signature_create(out, sig->length, sig->start, sig->angle, &kf,
                             sig->corners, sig->ncorners, sig->closed, err);
  km_fn_free(&kf);
  return st;
}

km_status km__closure_add(const km_signature *sig, const double *c,
                          km_signature *out, km_error *err) {
  km_pp k0, kt;
  km__pp_init(&k0);
  km__pp_init(&kt);
  km_status st = km__pp_from_fn(&k0, &sig->kappa);
  if (!st) st = km__closure_kappa(&k0, sig->length, c, &kt);
  if (!st) st = km__signature_with_kappa(sig, &kt, out, err);
  km__pp_free(&k0);
  km__pp_free(&kt);
  return st;
}

/* The closure by the corners, else by psi (see the DESIGN note). */
km_status km__close_lsq(const km_signature *sig, bool by_corners,
                        const double *weights, km_signature *out, double *gap0,
                        bool *used_corners, km__poll *poll, km_error *err) {
  double L = sig->length, c[NF] = {0};
  km_pp kp, tp;
  km__pp_init(&kp);
  km__pp_init(&tp);
  qnode *q = NULL;
  size_t nq = 0;
  stretches sc = {NULL, NULL, NULL, 0};
  bool closed = false, corners_close = false;
  km_status st = km__build_theta(sig, &kp, &tp);
  if (!st) st = closure_nodes(&kp, &tp, L / NB, poll, &q, &nq);
  if (!st) st = stretch_sums(sig, q, nq, &sc, gap0);
  if (!st) closed = *gap0 <= 1e-12 * L;
  if (!st && !closed && by_corners)
    st = km__close_by_corners(sc.S, sc.tau, sc.nc, sc.delta, &corners_close);
  if (st) goto done;
  if (closed) {
    /* closed already: either closure would change nothing */
    if (used_corners) *used_corners = by_corners;
    st = km_signature_copy(out, sig, err);
  } else if (corners_close) {
    st = turn_corners(sig, sc.delta, out, err);
    if (used_corners) *used_corners = st == KM_OK;
  } else {
    st = closure_coefficients(q, nq, L, weights, c, poll);
    if (!st) st = km__closure_add(sig, c, out, err);
  }
done:
  km__free(q);
  km__free(sc.S);
  km__pp_free(&kp);
  km__pp_free(&tp);
  if (st == KM_ECANCELLED) return km__stopped(err);
  if (st == KM_ENOMEM || st == KM_ENOCONVERGE || st == KM_ELIMIT)
    km__fail(err, st, KM_FIELD_NONE, -1, NAN,
             st == KM_ENOCONVERGE ? "closing the frame did not converge"
                                  : NULL);
  return st;
}

/* The paper's corrections of the control polygon (section 3.2). */
void km__close_polygon(km_curve *c, km_closure how) {
  size_t n = c->n - 1;
  double *P = c->cp;
  double e[2] = {P[2 * n] - P[0], P[2 * n + 1] - P[1]};
  for (size_t i = 0; i <= n; i++) {
    P[2 * i] -= (double)i / n * e[0];
    P[2 * i + 1] -= (double)i / n * e[1];
  }
  if (how != KM_CLOSURE_C0 && n >= 3) {
    double v[2] = {P[2 * (n - 1)] - (2 * P[0] - P[2]),
                   P[2 * (n - 1) + 1] - (2 * P[1] - P[3])};
    for (size_t i = 1; i <= n - 1; i++) {
      double f = (double)(i - 1) / (double)(n - 2);
      P[2 * i] -= f * v[0];
      P[2 * i + 1] -= f * v[1];
    }
  }
  if (how == KM_CLOSURE_G2 && n >= 4) {
    /* curvature at the end is affine in P[n-2] moved along the normal:
     * solve for the move that makes it equal the start curvature */
    double t0, t1, d[3][2];
    km_curve_domain(c, &t0, &t1);
    km_curve_eval(c, t0, 2, d);
    double k0 = (d[1][0] * d[2][1] - d[1][1] * d[2][0]) /
                pow(hypot(d[1][0], d[1][1]), 3);
    double tx = P[2 * n] - P[2 * (n - 1)],
           ty = P[2 * n + 1] - P[2 * (n - 1) + 1];
    double tn = hypot(tx, ty);
    if (tn > 0) {
      double N[2] = {-ty / tn, tx / tn};
      km_curve_eval_side(c, t1, -1, 2, d);
      double ka = (d[1][0] * d[2][1] - d[1][1] * d[2][0]) /
                  pow(hypot(d[1][0], d[1][1]), 3);
      P[2 * (n - 2)] += N[0];
      P[2 * (n - 2) + 1] += N[1];
      km_curve_eval_side(c, t1, -1, 2, d);
      double kb = (d[1][0] * d[2][1] - d[1][1] * d[2][0]) /
                  pow(hypot(d[1][0], d[1][1]), 3);
      double lam = (kb != ka && isfinite(kb)) ? (k0 - ka) / (kb - ka) : 0.0;
      P[2 * (n - 2)] += (lam - 1) * N[0];
      P[2 * (n - 2) + 1] += (lam - 1) * N[1];
    }
  }
  P[2 * n] = P[0];
  P[2 * n + 1] = P[1];
  c->closed = true;
}

/* Largest |kappa| over each basis interval of the closure (a bound from
 * the pieces' Bernstein coefficients). */
static void interval_max(const km_fn *kappa, double L, double *out) {
  for (int iv = 0; iv < NB; iv++) out[iv] = 0.0;
  /* piece by piece on the stack: there is no status for out of memory */
  km__fn_pieces it;
  double x[2], c[KM_MAX_FN_DEGREE + 1];
  double h = L / NB;
  int d = kappa->degree;
  km__fn_pieces_start(&it, kappa);
  while (km__fn_pieces_next(&it, x, c)) {
    double a = x[0], b = x[1], w = b - a;
    if (!(w > 0)) continue;
    int iv0 = (int)floor(a / h), iv1 = (int)floor(b / h);
    for (int iv = iv0 < 0 ? 0 : iv0; iv <= iv1 && iv < NB; iv++) {
      double lo = fmax(a, iv * h), hi = fmin(b, (iv + 1) * h),
             r[KM_MAX_FN_DEGREE + 2];
      if (!(hi > lo)) continue;
      km__bern_restrict(c, d, (lo - a) / w, (hi - a) / w, r);
      out[iv] = fmax(out[iv], km__bern_abs_bound(r, d));
    }
  }
}

/* The lsq closure of a blended frame, kept within the inputs' largest
 * |kappa| where the least change would cross it. The blend is a convex
 * combination, so the bound holds before closing; a matched frame can
 * leave a large gap, and its least L2 change of curvature may push past
 * the bound where the blend is already close to it. Then the change is
 * weighted away from there: by 1 / margin^2 on each basis interval, the
 * margin being how far the blend stays below the bound there, and by a
 * hundred times more wherever the result still crosses it, for a few
 * rounds. The closure keeps closing the frame to the same precision; only
 * where the curvature changes moves. Frames without matches change too
 * little to need this (and their planned form must agree with this one). */
km_status km__close_within_bound(const km_morph *m, const km_signature *blended,
                                 km_signature *out, double *gap, km__poll *poll,
                                 km_error *err) {
  bool used = false;
  km_status st = km__close_lsq(blended, m->close_by_corners, NULL, out, gap,
                               &used, poll, err);
  double bound = m->kmax * (1 + 1e-9);
  if (st || used || m->nuser == 0 || km_signature_max_abs_kappa(out) <= bound)
    return st;
  double w[NB], kb[NB], best = km_signature_max_abs_kappa(out);
  interval_max(&blended->kappa, blended->length, kb);
  for (int iv = 0; iv < NB; iv++) {
    double margin = fmax((m->kmax - kb[iv]) / m->kmax, 1e-3);
    w[iv] = 1.0 / (margin * margin);
  }
  for (int round = 0; round < 6; round++) {
    km_signature trial;
    double g;
    km_signature_init(&trial);
    if (km__close_lsq(blended, false, w, &trial, &g, NULL, poll, NULL) != KM_OK)
      break;
    double k = km_signature_max_abs_kappa(&trial);
    interval_max(&trial.kappa, trial.length, kb);
    for (int iv = 0; iv < NB; iv++)
      if (kb[iv] > bound) w[iv] *= 100.0;
    if (k < best) {
      best = k;
      km_signature_free(out);
      *out = trial;
      if (k <= bound) return KM_OK;
    } else {
      km_signature_free(&trial);
    }
  }
  if (poll && poll->stopped) {
    km_signature_free(out);
    return km__stopped(err);
  }
  return KM_OK; /* the closed frame nearest to the bound */
}
