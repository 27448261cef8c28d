/* interp.c - cubic B-spline interpolation of planar points with chord-length
 * parameterisation (open: not-a-knot ends; closed: periodic C2).
 *
 * DESIGN. Open curves solve the B-spline collocation system directly on the
 * not-a-knot knot vector (data sites 0 and 1 clamped, the sites next to the
 * ends not knots). Collocation matrices of B-splines at sites satisfying
 * Schoenberg-Whitney are totally positive, so banded Gaussian elimination
 * without pivoting is stable (de Boor). Closed curves solve for the end
 * slopes of the Hermite pieces instead: the periodic C2 conditions form a
 * strictly diagonally dominant cyclic tridiagonal system. The C2 spline is
 * then written with simple interior knots and a clamped seam: the de Boor
 * points follow from the Bezier points of each span, which divide the legs
 * of the control polygon in the ratio of neighbouring spans (blossoming),
 * taking per point the side whose ratio is <= 1.
 */
#include <math.h>
#include <string.h>

#include "internal.h"
#include "kernels.h"
#include "km/alloc.h"
#include "km/curve.h"
#include "km/limits.h"

/* Open, N >= 4: not-a-knot collocation. cp receives N points. */
static km_status solve_open(const double *Q, const double *u, size_t N,
                            double *T, double *cp) {
  /* knots: 0 x4, u[2..N-3], 1 x4 */
  for (int j = 0; j < 4; j++) {
    T[j] = 0.0;
    T[N + (size_t)j] = 1.0;
  }
  for (size_t j = 4; j < N; j++) T[j] = u[j - 2];
  /* band: row k holds columns k-3..k+3 at offsets 0..6 */
  double *A = km__calloc(N * 7, sizeof(double));
  if (!A) return KM_ENOMEM;
  memcpy(cp, Q, 2 * N * sizeof(double));
  for (size_t k = 0; k < N; k++) {
    size_t s = km__knot_span(T, N, 3, u[k]);
    double Nb[4];
    km__cubic_basis(T, s, u[k], Nb);
    for (int j = 0; j < 4; j++) {
      size_t col = s - 3 + (size_t)j;
      if (Nb[j] == 0.0) continue;
      /* Schoenberg-Whitney keeps every non-zero within three of the
       * diagonal */
      A[k * 7 + (col + 3 - k)] = Nb[j];
    }
  }
  km_status st = KM_OK;
  for (size_t i = 0; i < N; i++) {
    double piv = A[i * 7 + 3];
    if (!(fabs(piv) > 0) || !isfinite(piv)) {
      st = KM_ENOCONVERGE;
      goto cleanup;
    }
    for (size_t r = i + 1; r < N && r <= i + 3; r++) {
      double f = A[r * 7 + (i + 3 - r)] / piv;
      if (f == 0.0) continue;
      for (size_t c = i; c <= i + 3 && c < N; c++)
        A[r * 7 + (c + 3 - r)] -= f * A[i * 7 + (c + 3 - i)];
      cp[2 * r] -= f * cp[2 * i];
      cp[2 * r + 1] -= f * cp[2 * i + 1];
    }
  }
  for (size_t i = N; i-- > 0;) {
    double sx = cp[2 * i], sy = cp[2 * i + 1];
    for (size_t c = i + 1; c <= i + 3 && c < N; c++) {
      double a = A[i * 7 + (c + 3 - i)];
      sx -= a * cp[2 * c];
      sy -= a * cp[2 * c + 1];
    }
    cp[2 * i] = sx / A[i * 7 + 3];
    cp[2 * i + 1] = sy / A[i * 7 + 3];
  }
cleanup:
  km__free(A);
  return st;
}

/* Cyclic tridiagonal solve (Sherman-Morrison on the Thomas algorithm) for
 * two right-hand sides: sub[i] x[i-1] + dia[i] x[i] + sup[i] x[i+1] = r[i],
 * indices mod n, n >= 3, strictly diagonally dominant. r is overwritten with
 * the solution; work holds 5n doubles. */
static void cyclic_solve(const double *sub, const double *dia,
                         const double *sup, double *r, size_t n, double *work) {
  double *bb = work, *cprime = work + n, *z = work + 2 * n;
  double *zr = work + 3 * n; /* 2n: the (x, y) pair solutions */
  double gamma = -dia[0];
  double alpha = sup[n - 1], beta = sub[0]; /* corners A[n-1][0], A[0][n-1] */
  for (size_t i = 0; i < n; i++) bb[i] = dia[i];
  bb[0] -= gamma;
  bb[n - 1] -= alpha * beta / gamma;
  /* factor once, solve for r (two columns) and for u = (gamma,0..,alpha) */
  cprime[0] = sup[0] / bb[0];
  for (size_t i = 1; i < n; i++) {
    double m = bb[i] - sub[i] * cprime[i - 1];
    cprime[i] = sup[i] / m;
    bb[i] = m; /* now the pivots */
  }
  /* forward substitution */
  for (int col = 0; col < 3; col++) {
    double prev = 0.0;
    for (size_t i = 0; i < n; i++) {
      double rhs;
      if (col < 2)
        rhs = r[2 * i + (size_t)col];
      else
        rhs = i == 0 ? gamma : (i == n - 1 ? alpha : 0.0);
      double v = (rhs - (i ? sub[i] * prev : 0.0)) / bb[i];
      if (col < 2)
        zr[2 * i + (size_t)col] = v;
      else
        z[i] = v;
      prev = v;
    }
    for (size_t i = n - 1; i-- > 0;) {
      if (col < 2)
        zr[2 * i + (size_t)col] -= cprime[i] * zr[2 * (i + 1) + (size_t)col];
      else
        z[i] -= cprime[i] * z[i + 1];
    }
  }
  double den = 1.0 + z[0] + beta * z[n - 1] / gamma;
  for (int col = 0; col < 2; col++) {
    double fact =
        (zr[(size_t)col] + beta * zr[2 * (n - 1) + (size_t)col] / gamma) / den;
    for (size_t i = 0; i < n; i++)
      r[2 * i + (size_t)col] = zr[2 * i + (size_t)col] - fact * z[i];
  }
}

/* Closed, N >= 3 distinct points (no repeat of the first): periodic C2. h
 * holds the N parameter spans (summing to 1), u the N+1 breaks. cp gets
 * N + 3 points, T the N + 7 knots. */
static km_status solve_closed(const double *Q, const double *h, const double *u,
                              size_t N, double *T, double *cp) {
  double *buf = km__malloc(N * 10 * sizeof(double));
  if (!buf) return KM_ENOMEM;
  double *sub = buf, *dia = buf + N, *sup = buf + 2 * N, *D = buf + 3 * N;
  double *work = buf + 5 * N;
  for (size_t k = 0; k < N; k++) {
    size_t km1 = (k + N - 1) % N, kp1 = (k + 1) % N;
    double hl = h[km1], hr = h[k];
    sub[k] = hr;
    dia[k] = 2.0 * (hl + hr);
    sup[k] = hl;
    for (int c = 0; c < 2; c++) {
      double dl = (Q[2 * k + (size_t)c] - Q[2 * km1 + (size_t)c]) / hl;
      double dr = (Q[2 * kp1 + (size_t)c] - Q[2 * k + (size_t)c]) / hr;
      D[2 * k + (size_t)c] = 3.0 * (hr * dl + hl * dr);
    }
  }
  cyclic_solve(sub, dia, sup, D, N, work);
  for (int j = 0; j < 4; j++) {
    T[j] = 0.0;
    T[N + 3 + (size_t)j] = 1.0;
  }
  for (size_t j = 1; j < N; j++) T[3 + j] = u[j];
  size_t last = N + 2;
  for (int c = 0; c < 2; c++) {
    cp[(size_t)c] = Q[(size_t)c];
    cp[2 * last + (size_t)c] = Q[(size_t)c];
    cp[2 + (size_t)c] = Q[(size_t)c] + h[0] * D[(size_t)c] / 3.0;
    cp[2 * (last - 1) + (size_t)c] =
        Q[(size_t)c] - h[N - 1] * D[(size_t)c] / 3.0;
  }
  for (size_t i = 1; i < N; i++) {
    /* de Boor point P[i+1], blossom at (u[i-1], u[i], u[i+1]) */
    for (int c = 0; c < 2; c++) {
      double qi = Q[2 * i + (size_t)c], di = D[2 * i + (size_t)c];
      double v;
      if (h[i - 1] <= h[i]) {
        /* from span i: b1 = Q_i + h_i D_i / 3, b2 = Q_{i+1} - h_i D_{i+1} / 3 */
        size_t ip1 = (i + 1) % N;
        double b1 = qi + h[i] * di / 3.0;
        double b2 =
            Q[2 * ip1 + (size_t)c] - h[i] * D[2 * ip1 + (size_t)c] / 3.0;
        v = b1 + (h[i - 1] / h[i]) * (b1 - b2);
      } else {
        /* from span i-1: b1 = Q_{i-1} + h_{i-1} D_{i-1} / 3, b2 = Q_i -
         * h_{i-1} D_i / 3 */
        double b1 = Q[2 * (i - 1) + (size_t)c] +
                    h[i - 1] * D[2 * (i - 1) + (size_t)c] / 3.0;
        double b2 = qi - h[i - 1] * di / 3.0;
        v = b2 + (h[i] / h[i - 1]) * (b2 - b1);
      }
      cp[2 * (i + 1) + (size_t)c] = v;
    }
  }
  km__free(buf);
  return KM_OK;
}

/* Cubic through n points (x0, y0, x1, y1, ...) on [0, 1] with chord-length
 * parameters. Open: not-a-knot, n = 2 gives the segment at uniform speed, 3
 * the parabola. Closed: periodic C2, stored clamped with the first point
 * repeated at the end. Consecutive duplicates (and, closed, repeats of the
 * first point at the end) are dropped first. Returns KM_OK, KM_EINVAL (pts
 * NULL), KM_ENONFINITE / KM_ERANGE (a point; err->index names it),
 * KM_EDEGENERATE (fewer than 2 distinct points, 3 when closed; field
 * KM_FIELD_POINTS), KM_ELIMIT (n absurdly large), KM_ENOMEM. out owned by
 * the caller. Thread-safe. */
/* ---- the phases of km_curve_interpolate -------------------------------- */

/* Every coordinate finite and within KM_MAX_COORDINATE. */
static km_status check_points(const double *pts, size_t n, km_error *err) {
  for (size_t i = 0; i < n; i++) {
    for (int k = 0; k < 2; k++) {
      double v = pts[2 * i + (size_t)k];
      if (!isfinite(v))
        return km__fail(err, KM_ENONFINITE, KM_FIELD_POINTS, (long)i, NAN,
                        "point %zu is not finite", i);
      if (fabs(v) > KM_MAX_COORDINATE)
        return km__fail(err, KM_ERANGE, KM_FIELD_POINTS, (long)i, NAN,
                        "point %zu exceeds %g in magnitude", i,
                        KM_MAX_COORDINATE);
    }
  }
  return KM_OK;
}

/* The points into Q without consecutive duplicates (and, closed, a repeat
 * of the first point at the end): a zero chord has no parameter interval
 * to live in. Returns the number kept. */
static size_t distinct_points(const double *pts, size_t n, bool closed,
                              double *Q) {
  size_t N = 0;
  for (size_t i = 0; i < n; i++) {
    double x = pts[2 * i], y = pts[2 * i + 1];
    if (N > 0 && hypot(x - Q[2 * N - 2], y - Q[2 * N - 1]) == 0.0) continue;
    Q[2 * N] = x;
    Q[2 * N + 1] = y;
    N++;
  }
  if (closed)
    while (N > 1 && hypot(Q[2 * N - 2] - Q[0], Q[2 * N - 1] - Q[1]) == 0.0) N--;
  return N;
}

/* Chord-length breaks u[0..nspan] in [0, 1] and the spans h between them
 * (closed adds the closing chord); KM_EDEGENERATE when two breaks do not
 * separate. */
static km_status chord_breaks(const double *Q, size_t N, size_t nspan,
                              double *u, double *h, km_error *err) {
  double total = 0.0;
  for (size_t k = 0; k < nspan; k++) {
    size_t k1 = (k + 1) % N;
    h[k] = hypot(Q[2 * k1] - Q[2 * k], Q[2 * k1 + 1] - Q[2 * k + 1]);
    total += h[k];
  }
  if (!(total > 0) || !isfinite(total))
    return km__fail(err, KM_EDEGENERATE, KM_FIELD_POINTS, -1, NAN, NULL);
  /* breaks as cumulative chord / total: each is rounded once, not
   * accumulated */
  double cum = 0.0;
  u[0] = 0.0;
  for (size_t k = 0; k < nspan; k++) {
    cum += h[k];
    u[k + 1] = cum / total;
  }
  u[nspan] = 1.0;
  for (size_t k = 0; k < nspan; k++) {
    /* spans measured on the rounded breaks, so that they agree with the
     * knots */
    h[k] = u[k + 1] - u[k];
    if (!(h[k] > 0))
      return km__fail(err, KM_EDEGENERATE, KM_FIELD_POINTS, (long)k, NAN,
                      "points %zu and %zu are too close to separate", k,
                      (k + 1) % N);
  }
  return KM_OK;
}

/* One cubic piece through N = 2 or 3 points: the segment (uniform speed)
 * or the parabola through three points, degree-elevated. */
static void one_piece(const double *Q, const double *u, size_t N, km_curve *c) {
  for (int j = 0; j < 4; j++) {
    c->knots[j] = 0.0;
    c->knots[4 + j] = 1.0;
  }
  for (int k = 0; k < 2; k++) {
    double q0 = Q[k], qe = Q[2 * (N - 1) + (size_t)k], b1;
    if (N == 2) {
      b1 = 0.5 * (q0 + qe);
    } else {
      double t = u[1], q1 = Q[2 + k];
      b1 = (q1 - (1 - t) * (1 - t) * q0 - t * t * qe) / (2.0 * t * (1 - t));
    }
    c->cp[k] = q0;
    c->cp[2 + k] = (q0 + 2.0 * b1) / 3.0;
    c->cp[4 + k] = (2.0 * b1 + qe) / 3.0;
    c->cp[6 + k] = qe;
  }
}

km_status km_curve_interpolate(km_curve *out, const double *pts, size_t n,
                               bool closed, km_error *err) {
  double *Q = NULL, *u = NULL, *h = NULL;
  km_curve c;
  km_curve_init(&c);
  if (n > 0 && !pts)
    return km__fail(err, KM_EINVAL, KM_FIELD_POINTS, -1, NAN,
                    "points array is missing");
  if (n > ((size_t)-1) / (16 * sizeof(double)))
    return km__fail(err, KM_ELIMIT, KM_FIELD_POINTS, -1, NAN,
                    "too many points");
  km_status st = check_points(pts, n, err);
  if (st) return st;
  Q = km__malloc((2 * n + 2) * sizeof(double));
  u = km__malloc((n + 2) * sizeof(double));
  h = km__malloc((n + 2) * sizeof(double));
  if (!Q || !u || !h) {
    st = km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
    goto cleanup;
  }
  size_t N = distinct_points(pts, n, closed, Q);
  if (N < 2 || (closed && N < 3)) {
    st = km__fail(err, KM_EDEGENERATE, KM_FIELD_POINTS, -1, NAN,
                  closed ? "a closed curve needs at least 3 distinct points"
                         : "an open curve needs at least 2 distinct points");
    goto cleanup;
  }
  st = chord_breaks(Q, N, closed ? N : N - 1, u, h, err);
  if (st) goto cleanup;
  size_t ncp = closed ? N + 3 : (N < 4 ? 4 : N);
  st = km__curve_alloc(&c, 3, ncp, false);
  if (st) {
    km__fail(err, st, KM_FIELD_NONE, -1, NAN, NULL);
    goto cleanup;
  }
  if (closed)
    st = solve_closed(Q, h, u, N, c.knots, c.cp);
  else if (N >= 4)
    st = solve_open(Q, u, N, c.knots, c.cp);
  else
    one_piece(Q, u, N, &c);
  if (st) {
    km__fail(err, st, KM_FIELD_POINTS, -1, NAN, NULL);
    goto cleanup;
  }
  for (size_t i = 0; i < 2 * ncp; i++) {
    if (!isfinite(c.cp[i]) || fabs(c.cp[i]) > KM_MAX_COORDINATE) {
      st = km__fail(err, KM_ERANGE, KM_FIELD_POINTS, -1, NAN,
                    "interpolating curve overflows: points too close");
      goto cleanup;
    }
  }
  c.closed = closed;
  *out = c;
  km_curve_init(&c);
cleanup:
  km_curve_free(&c);
  km__free(Q);
  km__free(u);
  km__free(h);
  return st;
}
