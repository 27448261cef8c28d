/* morph_input.c - a morph's inputs made ready: copy, signature, theta
 * pieces and position table, orientation and start of closed curves.
 *
 * DESIGN. Start of closed curves: without matches, `to` is rotated to the
 * start that best aligns the two turning functions (least squares over all
 * cyclic shifts, by FFT correlation; among the deepest minima the one whose
 * previewed frames do not cross themselves, see morph.c), and reversed
 * first if the orientations differ. Both changes are exact: the signature
 * is shifted or mirrored, never computed again.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "km/alloc.h"
#include "km/reconstruct.h"
#include "morph_internal.h"

#define ALIGN_N                                                                \
  KM__TABLE_N /* samples of theta for start alignment: its
                             * shifts then land on table points (see
                             * km__input_rotate_start) */

void km__input_free(km__input *in) {
  km_curve_free(&in->curve);
  km_signature_free(&in->sig);
  km__pp_free(&in->kappa);
  km__pp_free(&in->theta);
}

km_status km__input_ensure_curve(km__input *in, double tol, size_t max_points,
                                 km__poll *poll, km_error *err) {
  if (in->has_curve) return KM_OK;
  km_status st = km__reconstruct(&in->sig, 3, tol, max_points, poll, &in->curve,
                                 NULL, NULL, err);
  if (!st) in->has_curve = true;
  return st;
}

/* Integral of e^(i theta) over [u0, u1] of a theta piece (as
 * km__integrate_exp) by 4-point Gauss-Legendre on chunks where theta moves
 * at most 0.25 rad: its error bound K_4 h^9 max|f^(8)| is then about 1e-14
 * of the chunk's length, ample for placement targets at a fraction of the
 * work. */
static void table_step(const double *tc, int d, double h, double u0, double u1,
                       double kbound, double out[2]) {
  static const double X[4] = {-0.86113631159405258, -0.33998104358485626,
                              0.33998104358485626, 0.86113631159405258};
  static const double W[4] = {0.34785484513745386, 0.65214515486254614,
                              0.65214515486254614, 0.34785484513745386};
  int chunks = (int)ceil(kbound * (u1 - u0) * h / 0.25);
  if (chunks < 1) chunks = 1;
  if (chunks > 1000000) chunks = 1000000;
  double sx = 0.0, sy = 0.0, du = (u1 - u0) / chunks;
  for (int c = 0; c < chunks; c++) {
    double mid = u0 + (c + 0.5) * du;
    for (int k = 0; k < 4; k++) {
      double th = km__bern_eval(tc, d, mid + 0.5 * du * X[k]), cs, sn;
      km__sincos(th, &sn, &cs);
      sx += W[k] * cs;
      sy += W[k] * sn;
    }
  }
  out[0] = sx * 0.5 * du * h;
  out[1] = sy * 0.5 * du * h;
}

/* theta pieces, and unless keep_table the position table and centroid, of
 * an input's signature */
static km_status input_tables(km__input *in, bool keep_table, km__poll *poll) {
  km__pp_free(&in->kappa);
  km__pp_free(&in->theta);
  km_status st = km__build_theta(&in->sig, &in->kappa, &in->theta);
  if (st || keep_table) return st;
  double L = in->sig.length;
  int dk = in->kappa.degree, dt = dk + 1;
  double x = in->sig.start[0], y = in->sig.start[1];
  size_t piece = 0;
  double s_prev = 0.0;
  in->table[0][0] = x;
  in->table[0][1] = y;
  double cx = 0.0, cy = 0.0;
  for (int j = 1; j <= KM__TABLE_N; j++) {
    double s = L * j / KM__TABLE_N;
    /* integrate from s_prev to s across pieces */
    while (s_prev < s) {
      double a = in->theta.x[piece], b = in->theta.x[piece + 1], h = b - a;
      double e = fmin(s, b);
      double u0 = (s_prev - a) / h, u1 = (e - a) / h;
      if (u1 > u0) {
        double kb =
            km__bern_abs_bound(in->kappa.c + piece * (size_t)(dk + 1), dk);
        double d[2];
        table_step(in->theta.c + piece * (size_t)(dt + 1), dt, h, u0, u1, kb,
                   d);
        x += d[0];
        y += d[1];
        /* four nodes a chunk of a quarter radian (table_step) */
        if (km__poll_stop(poll, 4 + (long)fmin(16.0 * kb * (u1 - u0) * h, 4e6)))
          return KM_ECANCELLED;
      }
      s_prev = e;
      if (e >= b && piece + 1 < in->theta.m)
        piece++;
      else if (e >= b)
        break;
    }
    in->table[j][0] = x;
    in->table[j][1] = y;
  }
  /* arc-length centroid by the trapezoid rule on the table */
  for (int j = 0; j < KM__TABLE_N; j++) {
    cx += 0.5 * (in->table[j][0] + in->table[j + 1][0]);
    cy += 0.5 * (in->table[j][1] + in->table[j + 1][1]);
  }
  in->centroid[0] = cx / KM__TABLE_N;
  in->centroid[1] = cy / KM__TABLE_N;
  return KM_OK;
}

void km__input_point_at(const km__input *in, double r, double out[2]) {
  double u = r * KM__TABLE_N;
  if (u < 0) u = 0;
  if (u > KM__TABLE_N) u = KM__TABLE_N;
  int j = (int)u;
  if (j >= KM__TABLE_N) j = KM__TABLE_N - 1;
  double f = u - j;
  out[0] = (1 - f) * in->table[j][0] + f * in->table[j + 1][0];
  out[1] = (1 - f) * in->table[j][1] + f * in->table[j + 1][1];
}

double km__input_theta_at(const km__input *in, double s) {
  int dt = in->theta.degree;
  size_t i = km__pp_find(&in->theta, s);
  double a = in->theta.x[i], h = in->theta.x[i + 1] - a;
  double u = (s - a) / h;
  if (u < 0) u = 0;
  if (u > 1) u = 1;
  return km__bern_eval(in->theta.c + i * (size_t)(dt + 1), dt, u);
}

/* The signature of the same closed curve started at arc length s0: kappa
 * and the corners shifted cyclically (the seam's corner becomes an interior
 * one, a corner at s0 the seam's), the start point and angle those at s0.
 * Exact, so no new signature has to be computed. */
static km_status rotate_signature(const km__input *in, double s0,
                                  km_signature *out, km_error *err) {
  const km_signature *sig = &in->sig;
  double L = sig->length, start[2];
  km_pp k1, k2, kr;
  km__pp_init(&k1);
  km__pp_init(&k2);
  km__pp_init(&kr);
  km_corner *cs = km__malloc((sig->ncorners + 1) * sizeof *cs);
  km_fn kf;
  km_fn_init(&kf);
  km_status st = cs ? km_signature_point(sig, s0, start, NULL) : KM_ENOMEM;
  if (!st) st = km__pp_slice(&k1, &in->kappa, s0, L);
  if (!st) st = km__pp_slice(&k2, &in->kappa, 0.0, s0);
  if (!st) st = km__pp_alloc(&kr, k1.degree, k1.m + k2.m);
  if (st) goto done;
  size_t nc1 = (size_t)k1.degree + 1;
  for (size_t i = 0; i < k1.m; i++) kr.x[i] = k1.x[i] - s0;
  for (size_t i = 0; i < k2.m; i++) kr.x[k1.m + i] = k2.x[i] + (L - s0);
  kr.x[0] = 0.0;
  kr.x[kr.m] = L;
  memcpy(kr.c, k1.c, k1.m * nc1 * sizeof(double));
  memcpy(kr.c + k1.m * nc1, k2.c, k2.m * nc1 * sizeof(double));
  size_t n = 0;
  double eps = 1e-12 * L;
  for (size_t i = 0; i < sig->ncorners; i++) {
    double cs0 = sig->corners[i].s;
    if (fabs(cs0 - s0) <= eps)
      cs[n].s = L;
    else
      cs[n].s = cs0 > s0 ? cs0 - s0 : cs0 + (L - s0);
    cs[n++].turn = sig->corners[i].turn;
  }
  if (n > 1) qsort(cs, n, sizeof *cs, km__cmp_corner);
  st = km__pp_to_fn(&kf, &kr);
  if (st) goto done;
  st = km_signature_create(out, L, start, km__input_theta_at(in, s0), &kf, cs,
                           n, true, err);
done:
  if (st == KM_ENOMEM) km__fail(err, st, KM_FIELD_NONE, -1, NAN, NULL);
  km_fn_free(&kf);
  km__free(cs);
  km__pp_free(&k1);
  km__pp_free(&k2);
  km__pp_free(&kr);
  return st;
}

/* The curve (if the input has one) split at s0 and joined the other way
 * round: the same closed curve started there. */
static km_status rotate_curve(km__input *in, double s0, km_error *err) {
  const km_curve *c = &in->curve;
  double t = km_curve_param_at_length(c, s0);
  double t0, t1;
  km_curve_domain(c, &t0, &t1);
  if (!(t > t0 + 1e-12 * (t1 - t0)) || !(t < t1 - 1e-12 * (t1 - t0)))
    return KM_OK;
  km_curve left, right, joined;
  km_curve_init(&left);
  km_curve_init(&right);
  km_curve_init(&joined);
  km_status st = km_curve_split(c, t, &left, &right, err);
  if (st) goto done;
  /* joined = right then left: knots of left shifted past right's end */
  int p = c->degree;
  size_t n = right.n + left.n - 1;
  bool rat = c->w != NULL;
  st = km__curve_alloc(&joined, p, n, rat);
  if (st) goto done;
  double rk0 = right.knots[0], rk1 = right.knots[right.n + (size_t)p];
  double lk0 = left.knots[0];
  size_t k = 0;
  for (size_t i = 0; i < right.n; i++) joined.knots[k++] = right.knots[i] - rk0;
  for (size_t i = 1; i <= (size_t)p; i++) joined.knots[k++] = rk1 - rk0;
  for (size_t i = (size_t)p + 1; i < left.n + (size_t)p + 1; i++)
    joined.knots[k++] = left.knots[i] - lk0 + (rk1 - rk0);
  double wscale = 1.0;
  if (rat) wscale = right.w[right.n - 1] / left.w[0];
  for (size_t i = 0; i < right.n; i++) {
    joined.cp[2 * i] = right.cp[2 * i];
    joined.cp[2 * i + 1] = right.cp[2 * i + 1];
    if (rat) joined.w[i] = right.w[i];
  }
  for (size_t i = 1; i < left.n; i++) {
    size_t j = right.n - 1 + i;
    joined.cp[2 * j] = left.cp[2 * i];
    joined.cp[2 * j + 1] = left.cp[2 * i + 1];
    if (rat) joined.w[j] = left.w[i] * wscale;
  }
  joined.cp[2 * (n - 1)] = joined.cp[0];
  joined.cp[2 * (n - 1) + 1] = joined.cp[1];
  if (rat) joined.w[n - 1] = joined.w[0];
  joined.closed = true;
  km_curve_free(&in->curve);
  in->curve = joined;
  km_curve_init(&joined);
done:
  km_curve_free(&left);
  km_curve_free(&right);
  km_curve_free(&joined);
  return st;
}

/* Closed input starting at arc length s0 instead of 0. */
km_status km__input_rotate_start(km__input *in, double s0, km__poll *poll,
                                 km_error *err) {
  double L = in->sig.length;
  if (!(s0 > 1e-12 * L) || !(s0 < L - 1e-12 * L)) return KM_OK;
  km_status st = in->has_curve ? rotate_curve(in, s0, err) : KM_OK;
  km_signature r;
  if (!st) st = rotate_signature(in, s0, &r, err);
  if (st) return st;
  km_signature_free(&in->sig);
  in->sig = r;
  /* a start on a table point (the alignment's shifts are) turns the table
   * cyclically: the same points of the same curve */
  double steps = s0 / L * KM__TABLE_N;
  long k = lround(steps);
  bool on_table = fabs(steps - (double)k) < 1e-9 && k > 0 && k < KM__TABLE_N;
  if (on_table) {
    double old[KM__TABLE_N][2];
    memcpy(old, in->table, sizeof old);
    for (int j = 0; j < KM__TABLE_N; j++) {
      in->table[j][0] = old[(j + k) % KM__TABLE_N][0];
      in->table[j][1] = old[(j + k) % KM__TABLE_N][1];
    }
    in->table[KM__TABLE_N][0] = in->table[0][0];
    in->table[KM__TABLE_N][1] = in->table[0][1];
  }
  return input_tables(in, on_table, poll);
}

/* The signature of the same closed curve traced backwards, exactly:
 * kappa_r(s) = -kappa(L - s) (knots mirrored, coefficients reversed and
 * negated), a corner at s turning by tau becomes one at L - s turning by
 * -tau (the seam's, at L, stays there), the start is the old end and the
 * start angle the old end tangent's plus pi. */
static km_status reverse_signature(const km_signature *sig, km_signature *out,
                                   km_error *err) {
  double L = sig->length;
  const km_fn *f = &sig->kappa;
  size_t n = f->n, nk = n + (size_t)f->degree + 1, nc = sig->ncorners;
  double *buf =
      km__malloc((nk + n) * sizeof(double) + (nc + 1) * sizeof(km_corner));
  if (!buf) return km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
  double *knots = buf, *coef = buf + nk;
  km_corner *cr = (km_corner *)(coef + n);
  for (size_t i = 0; i < nk; i++) knots[i] = L - f->knots[nk - 1 - i];
  for (size_t i = 0; i < n; i++) coef[i] = -f->coef[n - 1 - i];
  knots[0] = 0.0;
  knots[nk - 1] = L;
  double end_angle = sig->angle + km_fn_integral(f);
  size_t m = 0;
  for (size_t i = nc; i-- > 0;) {
    const km_corner *c = &sig->corners[i];
    bool seam = sig->closed && c->s >= L;
    if (!seam) end_angle += c->turn;
    if (seam) continue;
    cr[m].s = L - c->s;
    cr[m].turn = -c->turn;
    m++;
  }
  for (size_t i = 0; i < nc; i++)
    if (sig->closed && sig->corners[i].s >= L) {
      cr[m].s = L;
      cr[m].turn = -sig->corners[i].turn;
      m++;
    }
  /* only closed inputs are reversed: the old end is the start */
  const double *start = sig->start;
  km_fn kr;
  km_fn_init(&kr);
  km_status st = km_fn_create(&kr, f->degree, n, knots, coef, err);
  if (!st)
    st = km_signature_create(out, L, start, km__wrap_angle(end_angle + KM_PI),
                             &kr, cr, m, sig->closed, err);
  km_fn_free(&kr);
  km__free(buf);
  return st;
}

/* `to` traced backwards: its signature exactly, its curve (if kept) by
 * reversing the control points. */
km_status km__input_reverse(km__input *in, km__poll *poll, km_error *err) {
  km_signature r;
  km_status st = reverse_signature(&in->sig, &r, err);
  if (st) return st;
  km_signature_free(&in->sig);
  in->sig = r;
  if (in->has_curve) {
    km_curve c;
    st = km_curve_reverse(&c, &in->curve, err);
    if (st) return st;
    km_curve_free(&in->curve);
    in->curve = c;
  }
  return input_tables(in, false, poll);
}

/* Best cyclic shift of b's start (fraction of Lb): least squares over
 * ALIGN_N samples of the turning functions (up to a constant: the rotation
 * is free) plus the positions about the centroids, scaled to radians by the
 * mean radius L / 2 pi. The position term decides where the turning term
 * cannot (a circle's every start is equally good by turning, but only one
 * keeps a square's corners on the circle's diagonals). */

/* Samples of both inputs for the alignment cost, at the midpoints of
 * ALIGN_N equal parts: turning functions ta, tb (and copies ar, br for the
 * FFT, with zero imaginary parts ai, bi) and positions about the
 * centroids in units of the mean radius R (xr + i xi, yr + i yi), with
 * their sums (s[0..5]: sum ta, sum tb, sum ta^2, sum tb^2, sum |pa|^2,
 * sum |pb|^2). */
typedef struct shift_work {
  double *ta, *tb, *cost, *tw, *ar, *ai, *br, *bi, *xr, *xi, *yr, *yi;
  double *suffix_a, *prefix_b;
  double s[6];
} shift_work;

static void shift_samples(const km__input *a, const km__input *b,
                          shift_work *w) {
  enum { N = ALIGN_N };
  double La = a->sig.length, Lb = b->sig.length;
  double R = 0.5 * (La + Lb) / (2 * KM_PI);
  double sa = 0.0, sb = 0.0, saa = 0.0, sbb = 0.0, spa = 0.0, spb = 0.0;
  for (int j = 0; j < N; j++) {
    double r = (j + 0.5) / N, q[2];
    w->ta[j] = km__input_theta_at(a, La * r);
    w->tb[j] = km__input_theta_at(b, Lb * r);
    km__input_point_at(a, r, q);
    w->xr[j] = (q[0] - a->centroid[0]) / R;
    w->xi[j] = (q[1] - a->centroid[1]) / R;
    km__input_point_at(b, r, q);
    w->yr[j] = (q[0] - b->centroid[0]) / R;
    w->yi[j] = (q[1] - b->centroid[1]) / R;
    w->ar[j] = w->ta[j];
    w->br[j] = w->tb[j];
    w->ai[j] = w->bi[j] = 0.0;
    sa += w->ta[j];
    sb += w->tb[j];
    saa += w->ta[j] * w->ta[j];
    sbb += w->tb[j] * w->tb[j];
    spa += w->xr[j] * w->xr[j] + w->xi[j] * w->xi[j];
    spb += w->yr[j] * w->yr[j] + w->yi[j] * w->yi[j];
  }
  double s[6] = {sa, sb, saa, sbb, spa, spb};
  memcpy(w->s, s, sizeof s);
}

/* The cost of every shift k (see km__best_shifts) into w->cost; T is b's
 * total turning. */
static void shift_costs(shift_work *w, double T) {
  enum { N = ALIGN_N };
  double sa = w->s[0], sb = w->s[1], saa = w->s[2], sbb = w->s[3];
  double spa = w->s[4], spb = w->s[5];
  double *ar = w->ar, *ai = w->ai, *br = w->br, *bi = w->bi;
  double *xr = w->xr, *xi = w->xi, *yr = w->yr, *yi = w->yi;
  w->suffix_a[0] = 0.0; /* suffix_a[k]: sum of the last k of ta */
  w->prefix_b[0] = 0.0; /* prefix_b[k]: sum of the first k of tb */
  for (int k = 1; k < N; k++) {
    w->suffix_a[k] = w->suffix_a[k - 1] + w->ta[N - k];
    w->prefix_b[k] = w->prefix_b[k - 1] + w->tb[k - 1];
  }
  /* correlations: IFFT(conj(FFT u) FFT v)[k] = sum_j conj(u_j) v_(j+k) */
  km__fft_twiddles(N, w->tw);
  km__fft(ar, ai, N, w->tw, false);
  km__fft(br, bi, N, w->tw, false);
  km__fft(xr, xi, N, w->tw, false);
  km__fft(yr, yi, N, w->tw, false);
  for (int m = 0; m < N; m++) {
    double r1 = ar[m] * br[m] + ai[m] * bi[m],
           i1 = ar[m] * bi[m] - ai[m] * br[m];
    double r2 = xr[m] * yr[m] + xi[m] * yi[m],
           i2 = xr[m] * yi[m] - xi[m] * yr[m];
    ar[m] = r1;
    ai[m] = i1;
    xr[m] = r2;
    xi[m] = i2;
  }
  km__fft(ar, ai, N, w->tw, true); /* ar[k] = sum_j ta_j tb_(j+k) */
  km__fft(xr, xi, N, w->tw, true); /* xr[k] = sum_j pa_j . pb_(j+k) */
  for (int k = 0; k < N; k++) {
    double sum = sa - sb - T * k;
    double cross = ar[k] + T * w->suffix_a[k];
    double vv = sbb + 2 * T * w->prefix_b[k] + k * T * T;
    double sum2 = saa - 2 * cross + vv;
    double pos = spa + spb - 2 * xr[k];
    w->cost[k] = sum2 - sum * sum / N + pos;
  }
}

/* The deepest local minima of cost, at most KM__SHIFT_CANDIDATES, as
 * fractions into cand; the given start wins ties. */
static size_t deepest_minima(const double *cost, double *cand) {
  enum { N = ALIGN_N };
  size_t n = 0;
  int idx[KM__SHIFT_CANDIDATES];
  for (int k = 0; k < N; k++) {
    double c = cost[k], l = cost[(k + N - 1) % N], r = cost[(k + 1) % N];
    if (!(c <= l && c <= r)) continue;
    if (k > 0 && c >= cost[0] - 1e-9 * (1.0 + fabs(cost[0]))) continue;
    size_t pos = n;
    while (pos > 0 && cost[idx[pos - 1]] > c) pos--;
    if (pos >= KM__SHIFT_CANDIDATES) continue;
    if (n < KM__SHIFT_CANDIDATES) n++;
    for (size_t q = n - 1; q > pos; q--) idx[q] = idx[q - 1];
    idx[pos] = k;
  }
  if (n == 0) {
    idx[0] = 0;
    n = 1;
  }
  for (size_t q = 0; q < n; q++) cand[q] = (double)idx[q] / N;
  return n;
}

/* The best aligned start in each of nsec equal sectors of the length but
 * the one about the given start (centred on it), best first: fractions
 * into cand, costs into costs; returns how many (nsec - 1). */
static size_t sector_minima(const double *cost, size_t nsec, double *cand,
                            double *costs) {
  enum { N = ALIGN_N };
  size_t n = 0;
  for (size_t q = 1; q < nsec; q++) {
    int lo = (int)((2 * q - 1) * N / (2 * nsec)),
        hi = (int)((2 * q + 1) * N / (2 * nsec));
    int k = lo;
    for (int j = lo + 1; j < hi && j < N; j++)
      if (cost[j] < cost[k]) k = j;
    size_t pos = n++;
    while (pos > 0 && costs[pos - 1] > cost[k]) {
      cand[pos] = cand[pos - 1];
      costs[pos] = costs[pos - 1];
      pos--;
    }
    cand[pos] = (double)k / N;
    costs[pos] = cost[k];
  }
  return n;
}

/* The cost of shift k,
 *   sum_j (d_j - mean d)^2 + |pa_j - pb_(j+k)|^2,  d_j = ta_j - tb'_(j+k)
 * (tb' continued by the total turning past the end), expands into sums of
 * squares, prefix sums and the cyclic correlations sum_j ta_j tb_(j+k) and
 * sum_j pa_j . pb_(j+k), which the FFT gives for all k at once. */
/* Either the deepest minima (nsec 0) or the sectors' best starts. */
static km_status shift_minima(const km__input *a, const km__input *b,
                              double *cand, double *costs, size_t nsec,
                              size_t *n) {
  enum { N = ALIGN_N };
  double *buf = km__malloc(14 * (size_t)N * sizeof(double));
  if (!buf) return KM_ENOMEM;
  shift_work w = {buf,          buf + N,      buf + 2 * N,       buf + 3 * N,
                  buf + 4 * N,  buf + 5 * N,  buf + 6 * N,       buf + 7 * N,
                  buf + 8 * N,  buf + 9 * N,  buf + 10 * N,      buf + 11 * N,
                  buf + 12 * N, buf + 13 * N, {0, 0, 0, 0, 0, 0}};
  shift_samples(a, b, &w);
  shift_costs(&w, b->sig.turning);
  if (nsec == 0) {
    *n = deepest_minima(w.cost, cand);
  } else {
    *n = sector_minima(w.cost, nsec, cand, costs);
    costs[*n] = w.cost[0];
  }
  km__free(buf);
  return KM_OK;
}

km_status km__best_shifts(const km__input *a, const km__input *b, double *cand,
                          size_t *n) {
  return shift_minima(a, b, cand, NULL, 0, n);
}

km_status km__sector_shifts(const km__input *a, const km__input *b, size_t nsec,
                            double *cand, double *costs, size_t *n) {
  return shift_minima(a, b, cand, costs, nsec, n);
}

/* An input's copy, signature and tables; a signature computed from its
 * curve is held to tol, or without one to 1e-6 of its own length. */
km_status km__input_prepare(km__input *in, const km_morph_input *src,
                            double tol, km__poll *poll, km_error *err) {
  memset(in, 0, sizeof *in);
  km_curve_init(&in->curve);
  km_signature_init(&in->sig);
  km__pp_init(&in->kappa);
  km__pp_init(&in->theta);
  km_status st;
  if (src->curve) {
    st = km_curve_copy(&in->curve, src->curve, err);
    if (st) return st;
    in->has_curve = true;
  }
  if (src->sig)
    st = km_signature_copy(&in->sig, src->sig, err);
  else if (src->curve)
    st = km__signature_compute(&in->curve, tol, 1e-6, poll, &in->sig, err);
  else
    st = km__fail(err, KM_EINVAL, KM_FIELD_NONE, -1, NAN, "missing input");
  if (st) return st;
  return input_tables(in, false, poll);
}

static km_status pp_copy(km_pp *out, const km_pp *p) {
  km_status st = km__pp_alloc(out, p->degree, p->m);
  if (st) return st;
  memcpy(out->x, p->x, (p->m + 1) * sizeof(double));
  memcpy(out->c, p->c, p->m * (size_t)(p->degree + 1) * sizeof(double));
  return KM_OK;
}

km_status km__input_copy(km__input *out, const km__input *in, km_error *err) {
  memcpy(out->table, in->table, sizeof out->table);
  memcpy(out->centroid, in->centroid, sizeof out->centroid);
  out->has_curve = in->has_curve;
  km_status st =
      in->has_curve ? km_curve_copy(&out->curve, &in->curve, err) : KM_OK;
  if (!st) st = km_signature_copy(&out->sig, &in->sig, err);
  if (!st) st = pp_copy(&out->kappa, &in->kappa);
  if (!st) st = pp_copy(&out->theta, &in->theta);
  if (st == KM_ENOMEM) km__fail(err, st, KM_FIELD_NONE, -1, NAN, NULL);
  return st;
}

/* pieces of p restricted to [x0, x1] */
km_status km__pp_slice(km_pp *out, const km_pp *p, double x0, double x1) {
  size_t i0 = km__pp_find(p, x0), i1 = km__pp_find(p, x1);
  if (i1 > i0 && p->x[i1] >= x1) i1--;
  size_t m = i1 - i0 + 1;
  int d = p->degree;
  km_status st = km__pp_alloc(out, d, m);
  if (st) return st;
  for (size_t k = 0; k < m; k++) {
    size_t i = i0 + k;
    double a = p->x[i], b = p->x[i + 1], h = b - a;
    double lo = fmax(a, x0), hi = fmin(b, x1);
    km__bern_restrict(p->c + i * (size_t)(d + 1), d, (lo - a) / h, (hi - a) / h,
                      out->c + k * (size_t)(d + 1));
    out->x[k] = lo;
  }
  out->x[m] = x1;
  out->x[0] = x0;
  return KM_OK;
}

int km__cmp_corner(const void *x, const void *y) {
  double a = ((const km_corner *)x)->s, b = ((const km_corner *)y)->s;
  return (a > b) - (a < b);
}
