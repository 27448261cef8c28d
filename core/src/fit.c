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
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "kernels.h"
#include "km/limits.h"

#define FIT_MAX_CP 400 /* dense normal equations beyond this cost too much */

km_status km_curve_fit_points(km_curve *out, const double *pts, size_t n,
                              bool closed, double tol, km_error *err) {
  if (n < 8 || !(tol > 0) || !isfinite(tol))
    return km_curve_interpolate(out, pts, n, closed, err);
  const double *orig = pts;
  size_t norig = n;
  double *ext = NULL;
  if (closed) {
    /* the loop as an open run back to its first point; the control
     * points beside the seam are tied (P[m-2] = 2 P0 - P1) so the tangent
     * is continuous there */
    ext = malloc(2 * (n + 1) * sizeof(double));
    if (!ext) return km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
    memcpy(ext, pts, 2 * n * sizeof(double));
    ext[2 * n] = pts[0];
    ext[2 * n + 1] = pts[1];
    pts = ext;
    n++;
  }
  const bool seam = closed;
  km_status st = KM_OK;
  double *u = malloc(n * sizeof(double));
  double *U = NULL, *A = NULL, *rhs = NULL, *cp = NULL, *newk = NULL;
  if (!u) {
    free(ext);
    return km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
  }
  u[0] = 0.0;
  for (size_t i = 1; i < n; i++)
    u[i] = u[i - 1] + hypot(pts[2 * i] - pts[2 * i - 2], pts[2 * i + 1] - pts[2 * i - 1]);
  double total = u[n - 1];
  if (!(total > 0)) {
    free(u);
    free(ext);
    return km_curve_interpolate(out, orig, norig, closed, err);
  }
  for (size_t i = 0; i < n; i++) u[i] /= total;
  size_t nint = 1; /* interior knots */
  U = malloc((FIT_MAX_CP + 8) * sizeof(double));
  newk = malloc((FIT_MAX_CP + 8) * sizeof(double));
  cp = malloc(2 * (FIT_MAX_CP + 4) * sizeof(double));
  A = malloc((size_t)FIT_MAX_CP * FIT_MAX_CP * sizeof(double));
  rhs = malloc(2 * (size_t)FIT_MAX_CP * sizeof(double));
  if (!U || !newk || !cp || !A || !rhs) {
    st = km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
    goto done;
  }
  double interior[FIT_MAX_CP];
  interior[0] = u[n / 2];
  for (;;) {
    size_t ncp = nint + 4; /* unknowns: inner points, less a tied one */
    size_t nu = ncp - 2 - (seam ? 1 : 0);
    if (ncp >= n || ncp > FIT_MAX_CP) break; /* interpolation is as small */
    for (int k = 0; k < 4; k++) {
      U[k] = 0.0;
      U[ncp + (size_t)k] = 1.0;
    }
    for (size_t k = 0; k < nint; k++) U[4 + k] = interior[k];
    bool ok = true;
    for (int pass = 0; pass < 3 && ok; pass++) {
    if (pass > 0) {
      /* parameter correction (Hoschek): move each u to the foot of its
       * point on the current fit, keeping the order */
      km_curve tmp;
      if (km_curve_create(&tmp, 3, ncp, U, cp, NULL, false, NULL) != KM_OK) break;
      for (size_t i = 1; i + 1 < n; i++) {
        double t = u[i];
        for (int it = 0; it < 3; it++) {
          double d[3][2];
          km_curve_eval(&tmp, t, 2, d);
          double ex = d[0][0] - pts[2 * i], ey = d[0][1] - pts[2 * i + 1];
          double f = ex * d[1][0] + ey * d[1][1];
          double fp = d[1][0] * d[1][0] + d[1][1] * d[1][1] + ex * d[2][0] +
                      ey * d[2][1];
          if (!(fp > 0)) break;
          t -= f / fp;
        }
        double lo = u[i - 1], hi = u[i + 1];
        if (t > lo && t < hi && isfinite(t)) u[i] = t;
      }
      km_curve_free(&tmp);
    }
    /* normal equations for the inner control points, ends fixed */
    memset(A, 0, nu * nu * sizeof(double));
    memset(rhs, 0, 2 * nu * sizeof(double));
    for (size_t i = 0; i < n; i++) {
      size_t s = km__knot_span(U, ncp, 3, u[i]);
      double N[4];
      km__cubic_basis(U, s, u[i], N);
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
        } else if (seam && g == ncp - 2) {
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
    /* two right-hand sides: solve twice on copies */
    double *A2 = malloc(nu * nu * sizeof(double));
    if (!A2) {
      st = km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
      goto done;
    }
    memcpy(A2, A, nu * nu * sizeof(double));
    ok = km__solve_dense(A, rhs, (int)nu) &&
         km__solve_dense(A2, rhs + nu, (int)nu);
    free(A2);
    if (!ok) break; /* a span without points: interpolate instead */
    cp[0] = pts[0];
    cp[1] = pts[1];
    for (size_t k = 0; k < nu; k++) {
      cp[2 * (k + 1)] = rhs[k];
      cp[2 * (k + 1) + 1] = rhs[nu + k];
    }
    if (seam) {
      cp[2 * (ncp - 2)] = 2 * pts[0] - cp[2];
      cp[2 * (ncp - 2) + 1] = 2 * pts[1] - cp[3];
    }
    cp[2 * (ncp - 1)] = pts[2 * n - 2];
    cp[2 * (ncp - 1) + 1] = pts[2 * n - 1];
    }
    if (!ok) break;
    /* worst point per span; split the spans that miss */
    size_t nnew = 0;
    size_t first_in_span = 0;
    bool span_bad = false;
    for (size_t i = 0; i <= n; i++) {
      size_t s = i < n ? km__knot_span(U, ncp, 3, u[i]) : (size_t)-1;
      size_t s_prev = i > 0 ? km__knot_span(U, ncp, 3, u[i - 1]) : s;
      if (i > 0 && s != s_prev) {
        if (span_bad) {
          size_t cnt = i - first_in_span;
          if (cnt < 2) {
            nnew = (size_t)-1; /* cannot split further */
            break;
          }
          double k = u[first_in_span + cnt / 2];
          if (k > U[s_prev] && k < U[s_prev + 1]) newk[nnew++] = k;
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
    if (nnew == (size_t)-1) break;
    if (nnew == 0) {
      /* every point within tol: the fit */
      st = km_curve_create(out, 3, ncp, U, cp, NULL, closed, err);
      goto done;
    }
    if (nint + nnew + 4 > FIT_MAX_CP) break;
    /* merge the new knots into the interior ones */
    size_t a = 0, b = 0, m = 0;
    double merged[FIT_MAX_CP];
    while (a < nint || b < nnew) {
      if (b >= nnew || (a < nint && interior[a] <= newk[b]))
        merged[m++] = interior[a++];
      else
        merged[m++] = newk[b++];
    }
    memcpy(interior, merged, m * sizeof(double));
    nint = m;
  }
  st = km_curve_interpolate(out, orig, norig, closed, err);
done:
  free(ext);
  free(u);
  free(U);
  free(newk);
  free(cp);
  free(A);
  free(rhs);
  return st;
}
