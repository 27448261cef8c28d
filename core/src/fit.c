/* fit.c - cubic B-spline fitted to points within a tolerance, with few
 * control points.
 *
 * DESIGN. Chord-length parameters, corrected twice per round toward the
 * foot of each point on the current fit (Hoschek); the ends are
 * interpolated and the inner control points are the least-squares solution
 * for the current knots.
 * Every span in which some point is farther than the tolerance from its
 * image gets a knot at the median parameter of its points, until all
 * points are within the tolerance. Dense smooth samples (a drawn circle)
 * need a handful of spans; noisy input converges toward interpolation, and
 * when the fit would need about as many control points as there are
 * points, the interpolant is returned instead (it is exact).
 */
#include <math.h>
#include <string.h>

#include "internal.h"
#include "kernels.h"
#include "km/alloc.h"
#include "km/limits.h"

#define FIT_MAX_CP 400 /* dense normal equations beyond this cost too much */

/* One fit's data and workspaces: the points (closed loops extended back to
 * their first point), their parameters, the knots and the normal
 * equations of the current round. */
typedef struct fit_work {
  const double *pts; /* n points: the caller's, or ext */
  size_t n;
  bool seam; /* a closed loop: the control points beside the seam
                        are tied (P[m-2] = 2 P0 - P1) */
  double *ext, *u, *U, *newk, *cp, *A, *rhs;
  double total; /* chord length of the points */
  size_t nint;  /* interior knots */
  double interior[FIT_MAX_CP];
} fit_work;

/* The points as an open run (a loop back to its first point) and their
 * chord-length parameters in [0, 1] (not normalised when total is 0). */
static km_status prepare(fit_work *fw, const double *pts, size_t n, bool closed,
                         km_error *err) {
  if (closed) {
    fw->ext = km__malloc(2 * (n + 1) * sizeof(double));
    if (!fw->ext) return km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
    memcpy(fw->ext, pts, 2 * n * sizeof(double));
    fw->ext[2 * n] = pts[0];
    fw->ext[2 * n + 1] = pts[1];
    pts = fw->ext;
    n++;
  }
  fw->pts = pts;
  fw->n = n;
  fw->seam = closed;
  double *u = fw->u = km__malloc(n * sizeof(double));
  if (!u) return km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
  u[0] = 0.0;
  for (size_t i = 1; i < n; i++)
    u[i] = u[i - 1] +
           hypot(pts[2 * i] - pts[2 * i - 2], pts[2 * i + 1] - pts[2 * i - 1]);
  fw->total = u[n - 1];
  if (!(fw->total > 0)) return KM_OK;
  for (size_t i = 0; i < n; i++) u[i] /= fw->total;
  fw->U = km__malloc((FIT_MAX_CP + 8) * sizeof(double));
  fw->newk = km__malloc((FIT_MAX_CP + 8) * sizeof(double));
  fw->cp = km__malloc(2 * (FIT_MAX_CP + 4) * sizeof(double));
  fw->A = km__malloc((size_t)FIT_MAX_CP * FIT_MAX_CP * sizeof(double));
  fw->rhs = km__malloc(2 * (size_t)FIT_MAX_CP * sizeof(double));
  if (!fw->U || !fw->newk || !fw->cp || !fw->A || !fw->rhs)
    return km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
  return KM_OK;
}

/* Parameter correction (Hoschek): move each u to the foot of its point on
 * the current fit, keeping the order. False if the fit is not a curve. */
static bool correct_params(fit_work *fw, size_t ncp) {
  const double *pts = fw->pts;
  double *u = fw->u;
  km_curve tmp;
  if (km_curve_create(&tmp, 3, ncp, fw->U, fw->cp, NULL, false, NULL) != KM_OK)
    return false;
  for (size_t i = 1; i + 1 < fw->n; i++) {
    double t = u[i];
    for (int it = 0; it < 3; it++) {
      double d[3][2];
      km_curve_eval(&tmp, t, 2, d);
      double ex = d[0][0] - pts[2 * i], ey = d[0][1] - pts[2 * i + 1];
      double f = ex * d[1][0] + ey * d[1][1];
      double fp =
          d[1][0] * d[1][0] + d[1][1] * d[1][1] + ex * d[2][0] + ey * d[2][1];
      if (!(fp > 0)) break;
      t -= f / fp;
    }
    double lo = u[i - 1], hi = u[i + 1];
    if (t > lo && t < hi && isfinite(t)) u[i] = t;
  }
  km_curve_free(&tmp);
  return true;
}

/* The normal equations for the nu inner control points, ends fixed. */
static void normal_equations(fit_work *fw, size_t ncp, size_t nu) {
  const double *pts = fw->pts, *U = fw->U;
  size_t n = fw->n;
  double *A = fw->A, *rhs = fw->rhs;
  memset(A, 0, nu * nu * sizeof(double));
  memset(rhs, 0, 2 * nu * sizeof(double));
  for (size_t i = 0; i < n; i++) {
    size_t s = km__knot_span(U, ncp, 3, fw->u[i]);
    double N[4];
    km__cubic_basis(U, s, fw->u[i], N);
    double px = pts[2 * i], py = pts[2 * i + 1];
    size_t idx[4];
    double val[4];
    int cnt = 0;
    for (int a = 0; a < 4; a++) {
      size_t g = s - 3 + (size_t)a;
      if (g == 0) {
        px -= N[a] * pts[0];
        py -= N[a] * pts[1];
      } else if (g == ncp - 1) {
        px -= N[a] * pts[2 * n - 2];
        py -= N[a] * pts[2 * n - 1];
      } else if (fw->seam && g == ncp - 2) {
        px -= N[a] * 2 * pts[0];
        py -= N[a] * 2 * pts[1];
        idx[cnt] = 0;
        val[cnt++] = -N[a];
      } else {
        idx[cnt] = g - 1;
        val[cnt++] = N[a];
      }
    }
    for (int a = 0; a < cnt; a++) {
      rhs[idx[a]] += val[a] * px;
      rhs[nu + idx[a]] += val[a] * py;
      for (int b = 0; b < cnt; b++) A[idx[a] * nu + idx[b]] += val[a] * val[b];
    }
  }
}

/* Least-squares control points for the current knots into fw->cp; *ok
 * false when the system is singular (a span without points). */
static km_status solve_points(fit_work *fw, size_t ncp, size_t nu, bool *ok,
                              km_error *err) {
  const double *pts = fw->pts;
  size_t n = fw->n;
  double *cp = fw->cp, *rhs = fw->rhs;
  normal_equations(fw, ncp, nu);
  /* two right-hand sides: solve twice on copies */
  double *A2 = km__malloc(nu * nu * sizeof(double));
  if (!A2) return km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
  memcpy(A2, fw->A, nu * nu * sizeof(double));
  *ok = km__solve_dense(fw->A, rhs, (int)nu) &&
        km__solve_dense(A2, rhs + nu, (int)nu);
  km__free(A2);
  if (!*ok) return KM_OK;
  cp[0] = pts[0];
  cp[1] = pts[1];
  for (size_t k = 0; k < nu; k++) {
    cp[2 * (k + 1)] = rhs[k];
    cp[2 * (k + 1) + 1] = rhs[nu + k];
  }
  if (fw->seam) {
    cp[2 * (ncp - 2)] = 2 * pts[0] - cp[2];
    cp[2 * (ncp - 2) + 1] = 2 * pts[1] - cp[3];
  }
  cp[2 * (ncp - 1)] = pts[2 * n - 2];
  cp[2 * (ncp - 1) + 1] = pts[2 * n - 1];
  return KM_OK;
}

/* New knots into fw->newk at the median parameter of every span in which
 * some point misses by more than tol; (size_t)-1 when such a span has
 * fewer than two points (it cannot be split further). */
static size_t split_spans(fit_work *fw, size_t ncp, double tol) {
  const double *pts = fw->pts, *U = fw->U, *u = fw->u, *cp = fw->cp;
  size_t n = fw->n, nnew = 0, first_in_span = 0;
  bool span_bad = false;
  for (size_t i = 0; i <= n; i++) {
    size_t s = i < n ? km__knot_span(U, ncp, 3, u[i]) : (size_t)-1;
    size_t s_prev = i > 0 ? km__knot_span(U, ncp, 3, u[i - 1]) : s;
    if (i > 0 && s != s_prev) {
      if (span_bad) {
        size_t cnt = i - first_in_span;
        if (cnt < 2) return (size_t)-1;
        double k = u[first_in_span + cnt / 2];
        if (k > U[s_prev] && k < U[s_prev + 1]) fw->newk[nnew++] = k;
      }
      first_in_span = i;
      span_bad = false;
    }
    if (i == n) break;
    double N[4], x = 0, y = 0;
    km__cubic_basis(U, s, u[i], N);
    for (int a = 0; a < 4; a++) {
      x += N[a] * cp[2 * (s - 3 + (size_t)a)];
      y += N[a] * cp[2 * (s - 3 + (size_t)a) + 1];
    }
    if (hypot(x - pts[2 * i], y - pts[2 * i + 1]) > tol) span_bad = true;
  }
  return nnew;
}

/* The new knots merged into the interior ones, in order. */
static void merge_knots(fit_work *fw, size_t nnew) {
  size_t a = 0, b = 0, m = 0, nint = fw->nint;
  double merged[FIT_MAX_CP];
  while (a < nint || b < nnew) {
    if (b >= nnew || (a < nint && fw->interior[a] <= fw->newk[b]))
      merged[m++] = fw->interior[a++];
    else
      merged[m++] = fw->newk[b++];
  }
  memcpy(fw->interior, merged, m * sizeof(double));
  fw->nint = m;
}

/* Rounds of knots: each fits the control points (three passes with
 * parameter correction between them) and splits the spans that miss.
 * *fitted when every point is within tol (then *out is the fit); false
 * when interpolation is as small or a span cannot be split. */
static km_status fit_rounds(fit_work *fw, double tol, bool closed,
                            km_curve *out, bool *fitted, km_error *err) {
  *fitted = false;
  fw->nint = 1;
  fw->interior[0] = fw->u[fw->n / 2];
  for (;;) {
    size_t ncp = fw->nint + 4; /* unknowns: inner points, less a tied one */
    size_t nu = ncp - 2 - (fw->seam ? 1 : 0);
    if (ncp >= fw->n || ncp > FIT_MAX_CP)
      return KM_OK; /* interpolation is as small */
    for (int k = 0; k < 4; k++) {
      fw->U[k] = 0.0;
      fw->U[ncp + (size_t)k] = 1.0;
    }
    for (size_t k = 0; k < fw->nint; k++) fw->U[4 + k] = fw->interior[k];
    bool ok = true;
    for (int pass = 0; pass < 3 && ok; pass++) {
      if (pass > 0 && !correct_params(fw, ncp)) break;
      km_status st = solve_points(fw, ncp, nu, &ok, err);
      if (st) return st;
    }
    if (!ok) return KM_OK; /* a span without points: interpolate instead */
    size_t nnew = split_spans(fw, ncp, tol);
    if (nnew == (size_t)-1) return KM_OK;
    if (nnew == 0) {
      /* every point within tol: the fit */
      *fitted = true;
      return km_curve_create(out, 3, ncp, fw->U, fw->cp, NULL, closed, err);
    }
    if (fw->nint + nnew + 4 > FIT_MAX_CP) return KM_OK;
    merge_knots(fw, nnew);
  }
}

km_status km_curve_fit_points(km_curve *out, const double *pts, size_t n,
                              bool closed, double tol, km_error *err) {
  if (n < 8 || !(tol > 0) || !isfinite(tol))
    return km_curve_interpolate(out, pts, n, closed, err);
  fit_work fw;
  fw.ext = fw.u = fw.U = fw.newk = fw.cp = fw.A = fw.rhs = NULL;
  bool fitted = false;
  km_status st = prepare(&fw, pts, n, closed, err);
  if (!st && fw.total > 0) st = fit_rounds(&fw, tol, closed, out, &fitted, err);
  if (!st && !fitted) st = km_curve_interpolate(out, pts, n, closed, err);
  km__free(fw.ext);
  km__free(fw.u);
  km__free(fw.U);
  km__free(fw.newk);
  km__free(fw.cp);
  km__free(fw.A);
  km__free(fw.rhs);
  return st;
}
