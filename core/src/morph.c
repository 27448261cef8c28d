/* morph.c - curvature-interpolation morphs (paper section 3), closure,
 * placement, correspondence and the linear baseline.
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
 * Closed curves: the tangent closes by itself (equal turning numbers); the
 * position is closed by "lsq", the least change of curvature that closes
 * the frame, in one of two forms chosen once per morph (plan_frames):
 * frames with corners close by turning them (km__close_by_corners: least
 * sum of squared changes weighted by each corner's turn, total turning
 * kept), which leaves the curvature between corners the blend's - straight
 * edges stay straight, the bound holds; otherwise theta~ = theta_t + psi
 * with psi a combination of interior uniform cubic B-splines (psi and psi'
 * vanish at the seam, so the seam stays G2), minimising the L2 change of
 * curvature ||psi'||^2 subject to the two closure equations (Gauss-Newton),
 * after Saba, Schneider, Hormann and Scateni (2014). The paper's
 * control-polygon corrections (c0, c1, g2) remain selectable.
 * Frames of the default morph without metrics or signature come from a
 * plan made once per morph (morph_plan.c); the rest below blends the
 * signatures exactly and reconstructs.
 * Placement: curvature fixes a frame up to a rigid motion; "fit" takes the
 * rigid motion (2-D Procrustes, closed form) that best maps the frame onto
 * the linear blend of the two inputs at corresponding points, which keeps
 * frames where the eye expects them instead of swinging about the start.
 * Start of closed curves: without matches, `to` is rotated to the start
 * that best aligns the two turning functions (least squares over all
 * cyclic shifts, by FFT correlation; among the deepest minima the one whose
 * previewed frames do not cross themselves), and reversed first if the
 * orientations differ.
 * matches "auto": features (corners and curvature extrema, with the turning
 * they carry) are aligned by dynamic programming over both sequences,
 * rewarding pairs of like turning and penalising drift in r.
 */
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "km/limits.h"
#include "km/morph.h"
#include "km/reconstruct.h"
#include "morph_plan.h"

#define TABLE_N 512   /* samples per input for placement targets */
#define FIT_N 256     /* frame samples for the Procrustes fit */
#define ALIGN_N TABLE_N /* samples of theta for start alignment: its shifts
                          * then land on table points (see rotate_start) */
#define LSQ_INTERVALS KM__CLOSURE_INTERVALS

void km_morph_options_default(km_morph_options *o) {
  memset(o, 0, sizeof *o);
  o->method = KM_METHOD_CURVATURE;
  o->blend = KM_BLEND_TURNING;
  o->closure = KM_CLOSURE_AUTO;
  o->anchor = KM_ANCHOR_FIT;
  o->orient = KM_ORIENT_AUTO;
  o->tolerance = 0.0;
  o->degree = 3;
}

typedef struct input {
  km_curve curve;
  bool has_curve;
  km_signature sig;
  km_pp kappa, theta; /* theta pieces in s */
  double table[TABLE_N + 1][2]; /* positions at s = L j / TABLE_N */
  double centroid[2];
} input;

struct km_morph {
  km_morph_options opt;
  double tol;
  bool closed;
  input in[2];
  double *ra, *rb; /* correspondence knots, nm+2 of them incl. 0 and 1 */
  size_t nk;
  size_t nuser;    /* match pairs reported */
  km_curve lin[2]; /* compatible curves (linear method) */
  km__frame_plan *plan; /* frames planned once (morph_plan.c), or NULL */
  bool close_by_corners; /* lsq closure by the frames' corners */
  double kmax;           /* the inputs' largest |kappa|: the frames' bound */
  /* placement targets of planned frames: the inputs' points at the plan's
   * breaks (x, y of a, then of b) and the break's trapezoid weight; the
   * weights' sum and the weighted means */
  double (*place_ab)[5];
  double place_w_sum, place_qa[2], place_qb[2];
  /* the caller's stop condition while km_morph_create runs, NULL after:
   * frames take their own (km_morph_frame_until) */
  km__poll *poll;
};

static void input_free(input *in) {
  km_curve_free(&in->curve);
  km_signature_free(&in->sig);
  km__pp_free(&in->kappa);
  km__pp_free(&in->theta);
}

void km_morph_free(km_morph *m) {
  if (!m) return;
  for (int i = 0; i < 2; i++) {
    input_free(&m->in[i]);
    km_curve_free(&m->lin[i]);
  }
  free(m->ra);
  free(m->rb);
  km__frame_plan_free(m->plan);
  free(m->place_ab);
  free(m);
}

static km_status ensure_curve(input *in, double tol, size_t max_points,
                              km__poll *poll, km_error *err) {
  if (in->has_curve) return KM_OK;
  km_status st = km__reconstruct(&in->sig, 3, tol, max_points, poll,
                                 &in->curve, NULL, NULL, err);
  if (!st) in->has_curve = true;
  return st;
}

/* Integral of e^(i theta) over [u0, u1] of a theta piece (as
 * km__integrate_exp) by 4-point Gauss-Legendre on chunks where theta moves
 * at most 0.25 rad: its error bound K_4 h^9 max|f^(8)| is then about 1e-14
 * of the chunk's length, ample for placement targets at a fraction of the
 * work. */
static void table_step(const double *tc, int d, double h, double u0,
                       double u1, double kbound, double out[2]) {
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
static km_status input_tables(input *in, bool keep_table, km__poll *poll) {
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
  for (int j = 1; j <= TABLE_N; j++) {
    double s = L * j / TABLE_N;
    /* integrate from s_prev to s across pieces */
    while (s_prev < s) {
      double a = in->theta.x[piece], b = in->theta.x[piece + 1], h = b - a;
      double e = fmin(s, b);
      double u0 = (s_prev - a) / h, u1 = (e - a) / h;
      if (u1 > u0) {
        double kb = km__bern_abs_bound(in->kappa.c + piece * (size_t)(dk + 1), dk);
        double d[2];
        table_step(in->theta.c + piece * (size_t)(dt + 1), dt, h, u0, u1, kb, d);
        x += d[0];
        y += d[1];
        /* four nodes a chunk of a quarter radian (table_step) */
        if (km__poll_stop(poll, 4 + (long)fmin(16.0 * kb * (u1 - u0) * h, 4e6)))
          return KM_ECANCELLED;
      }
      s_prev = e;
      if (e >= b && piece + 1 < in->theta.m) piece++;
      else if (e >= b) break;
    }
    in->table[j][0] = x;
    in->table[j][1] = y;
  }
  /* arc-length centroid by the trapezoid rule on the table */
  for (int j = 0; j < TABLE_N; j++) {
    cx += 0.5 * (in->table[j][0] + in->table[j + 1][0]);
    cy += 0.5 * (in->table[j][1] + in->table[j + 1][1]);
  }
  in->centroid[0] = cx / TABLE_N;
  in->centroid[1] = cy / TABLE_N;
  return KM_OK;
}

static void table_at(const input *in, double r, double out[2]) {
  double u = r * TABLE_N;
  if (u < 0) u = 0;
  if (u > TABLE_N) u = TABLE_N;
  int j = (int)u;
  if (j >= TABLE_N) j = TABLE_N - 1;
  double f = u - j;
  out[0] = (1 - f) * in->table[j][0] + f * in->table[j + 1][0];
  out[1] = (1 - f) * in->table[j][1] + f * in->table[j + 1][1];
}

static double theta_at(const input *in, double s) {
  int dt = in->theta.degree;
  size_t i = km__pp_find(&in->theta, s);
  double a = in->theta.x[i], h = in->theta.x[i + 1] - a;
  double u = (s - a) / h;
  if (u < 0) u = 0;
  if (u > 1) u = 1;
  return km__bern_eval(in->theta.c + i * (size_t)(dt + 1), dt, u);
}

static km_status pp_slice(km_pp *out, const km_pp *p, double x0, double x1);
static int cmp_corner(const void *x, const void *y);

/* The signature of the same closed curve started at arc length s0: kappa
 * and the corners shifted cyclically (the seam's corner becomes an interior
 * one, a corner at s0 the seam's), the start point and angle those at s0.
 * Exact, so no new signature has to be computed. */
static km_status rotate_signature(const input *in, double s0,
                                  km_signature *out, km_error *err) {
  const km_signature *sig = &in->sig;
  double L = sig->length, start[2];
  km_pp k1, k2, kr;
  km__pp_init(&k1);
  km__pp_init(&k2);
  km__pp_init(&kr);
  km_corner *cs = malloc((sig->ncorners + 1) * sizeof *cs);
  km_fn kf;
  km_fn_init(&kf);
  km_status st = cs ? km_signature_point(sig, s0, start, NULL) : KM_ENOMEM;
  if (!st) st = pp_slice(&k1, &in->kappa, s0, L);
  if (!st) st = pp_slice(&k2, &in->kappa, 0.0, s0);
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
  if (n > 1) qsort(cs, n, sizeof *cs, cmp_corner);
  st = km__pp_to_fn(&kf, &kr);
  if (st) goto done;
  st = km_signature_create(out, L, start, theta_at(in, s0), &kf, cs, n, true,
                           err);
done:
  if (st == KM_ENOMEM) km__fail(err, st, KM_FIELD_NONE, -1, NAN, NULL);
  km_fn_free(&kf);
  free(cs);
  km__pp_free(&k1);
  km__pp_free(&k2);
  km__pp_free(&kr);
  return st;
}

/* The curve (if the input has one) split at s0 and joined the other way
 * round: the same closed curve started there. */
static km_status rotate_curve(input *in, double s0, km_error *err) {
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
static km_status rotate_start(input *in, double s0, km__poll *poll,
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
  double steps = s0 / L * TABLE_N;
  long k = lround(steps);
  bool on_table = fabs(steps - (double)k) < 1e-9 && k > 0 && k < TABLE_N;
  if (on_table) {
    double old[TABLE_N][2];
    memcpy(old, in->table, sizeof old);
    for (int j = 0; j < TABLE_N; j++) {
      in->table[j][0] = old[(j + k) % TABLE_N][0];
      in->table[j][1] = old[(j + k) % TABLE_N][1];
    }
    in->table[TABLE_N][0] = in->table[0][0];
    in->table[TABLE_N][1] = in->table[0][1];
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
  double *buf = malloc((nk + n) * sizeof(double) + (nc + 1) * sizeof(km_corner));
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
    st = km_signature_create(out, L, start, km__wrap_angle(end_angle + KM_PI), &kr,
                             cr, m, sig->closed, err);
  km_fn_free(&kr);
  free(buf);
  return st;
}

/* `to` traced backwards: its signature exactly, its curve (if kept) by
 * reversing the control points. */
static km_status reverse_input(input *in, km__poll *poll, km_error *err) {
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
#define SHIFT_CANDIDATES 4

/* Fills cand[] with up to SHIFT_CANDIDATES shifts, best first: the
 * deepest local minima of the cost over all shifts. Returns the count.
 * The cost of shift k,
 *   sum_j (d_j - mean d)^2 + |pa_j - pb_(j+k)|^2,  d_j = ta_j - tb'_(j+k)
 * (tb' continued by the total turning past the end), expands into sums of
 * squares, prefix sums and the cyclic correlations sum_j ta_j tb_(j+k) and
 * sum_j pa_j . pb_(j+k), which the FFT gives for all k at once. */
static size_t best_shifts(const input *a, const input *b, double *cand) {
  static const int N = ALIGN_N;
  double *buf = malloc(14 * (size_t)N * sizeof(double));
  if (!buf) {
    cand[0] = 0.0;
    return 1;
  }
  double *ta = buf, *tb = buf + N, *cost = buf + 2 * N, *tw = buf + 3 * N;
  double *ar = buf + 4 * N, *ai = buf + 5 * N, *br = buf + 6 * N, *bi = buf + 7 * N;
  double *xr = buf + 8 * N, *xi = buf + 9 * N, *yr = buf + 10 * N, *yi = buf + 11 * N;
  double *suffix_a = buf + 12 * N, *prefix_b = buf + 13 * N;
  double La = a->sig.length, Lb = b->sig.length;
  double R = 0.5 * (La + Lb) / (2 * KM_PI);
  double sa = 0.0, sb = 0.0, saa = 0.0, sbb = 0.0, spa = 0.0, spb = 0.0;
  for (int j = 0; j < N; j++) {
    double r = (j + 0.5) / N, q[2];
    ta[j] = theta_at(a, La * r);
    tb[j] = theta_at(b, Lb * r);
    table_at(a, r, q);
    xr[j] = (q[0] - a->centroid[0]) / R;
    xi[j] = (q[1] - a->centroid[1]) / R;
    table_at(b, r, q);
    yr[j] = (q[0] - b->centroid[0]) / R;
    yi[j] = (q[1] - b->centroid[1]) / R;
    ar[j] = ta[j];
    br[j] = tb[j];
    ai[j] = bi[j] = 0.0;
    sa += ta[j];
    sb += tb[j];
    saa += ta[j] * ta[j];
    sbb += tb[j] * tb[j];
    spa += xr[j] * xr[j] + xi[j] * xi[j];
    spb += yr[j] * yr[j] + yi[j] * yi[j];
  }
  suffix_a[0] = 0.0; /* suffix_a[k]: sum of the last k of ta */
  prefix_b[0] = 0.0; /* prefix_b[k]: sum of the first k of tb */
  for (int k = 1; k < N; k++) {
    suffix_a[k] = suffix_a[k - 1] + ta[N - k];
    prefix_b[k] = prefix_b[k - 1] + tb[k - 1];
  }
  /* correlations: IFFT(conj(FFT u) FFT v)[k] = sum_j conj(u_j) v_(j+k) */
  km__fft_twiddles(N, tw);
  km__fft(ar, ai, N, tw, false);
  km__fft(br, bi, N, tw, false);
  km__fft(xr, xi, N, tw, false);
  km__fft(yr, yi, N, tw, false);
  for (int m = 0; m < N; m++) {
    double r1 = ar[m] * br[m] + ai[m] * bi[m], i1 = ar[m] * bi[m] - ai[m] * br[m];
    double r2 = xr[m] * yr[m] + xi[m] * yi[m], i2 = xr[m] * yi[m] - xi[m] * yr[m];
    ar[m] = r1;
    ai[m] = i1;
    xr[m] = r2;
    xi[m] = i2;
  }
  km__fft(ar, ai, N, tw, true); /* ar[k] = sum_j ta_j tb_(j+k) */
  km__fft(xr, xi, N, tw, true); /* xr[k] = sum_j pa_j . pb_(j+k) */
  double T = b->sig.turning;
  for (int k = 0; k < N; k++) {
    double sum = sa - sb - T * k;
    double cross = ar[k] + T * suffix_a[k];
    double vv = sbb + 2 * T * prefix_b[k] + k * T * T;
    double sum2 = saa - 2 * cross + vv;
    double pos = spa + spb - 2 * xr[k];
    cost[k] = sum2 - sum * sum / N + pos;
  }
  /* local minima, deepest first; the given start wins ties */
  size_t n = 0;
  int idx[SHIFT_CANDIDATES];
  for (int k = 0; k < N; k++) {
    double c = cost[k], l = cost[(k + N - 1) % N], r = cost[(k + 1) % N];
    if (!(c <= l && c <= r)) continue;
    if (k > 0 && c >= cost[0] - 1e-9 * (1.0 + fabs(cost[0]))) continue;
    size_t pos = n;
    while (pos > 0 && cost[idx[pos - 1]] > c) pos--;
    if (pos >= SHIFT_CANDIDATES) continue;
    if (n < SHIFT_CANDIDATES) n++;
    for (size_t q = n - 1; q > pos; q--) idx[q] = idx[q - 1];
    idx[pos] = k;
  }
  if (n == 0) {
    idx[0] = 0;
    n = 1;
  }
  for (size_t q = 0; q < n; q++) cand[q] = (double)idx[q] / N;
  free(buf);
  return n;
}

/* ---- correspondence ---------------------------------------------------- */

typedef struct feature {
  double r;    /* position, fraction of length */
  double turn; /* turning carried (corner turn, or integral of kappa over the
                  extremum's neighbourhood) */
} feature;

static size_t find_features(const input *in, feature *f, size_t cap) {
  size_t n = 0;
  double L = in->sig.length;
  for (size_t i = 0; i < in->sig.ncorners && n < cap; i++) {
    if (in->sig.corners[i].s >= L * (1 - 1e-12)) continue;
    if (fabs(in->sig.corners[i].turn) > 0.2) {
      f[n].r = in->sig.corners[i].s / L;
      f[n].turn = in->sig.corners[i].turn;
      n++;
    }
  }
  /* curvature extrema: local maxima of |kappa| on a grid, with the turning
   * within a window around them */
  enum { G = 400 };
  double kv[G + 1];
  for (int j = 0; j <= G; j++) kv[j] = km__pp_eval(&in->kappa, L * j / G);
  double kmax = 0.0;
  for (int j = 0; j <= G; j++) kmax = fmax(kmax, fabs(kv[j]));
  for (int j = 1; j < G && n < cap; j++) {
    double v = fabs(kv[j]);
    if (v > fabs(kv[j - 1]) && v >= fabs(kv[j + 1]) && v > 0.3 * kmax &&
        v * L > 4.0) {
      int w = 10;
      double lo = L * fmax(0, j - w) / G, hi = L * fmin(G, j + w) / G;
      double turn = theta_at(in, hi) - theta_at(in, lo);
      if (fabs(turn) > 0.2) {
        f[n].r = (double)j / G;
        f[n].turn = turn;
        n++;
      }
    }
  }
  /* sort by r */
  for (size_t i = 1; i < n; i++)
    for (size_t j = i; j > 0 && f[j].r < f[j - 1].r; j--) {
      feature t = f[j];
      f[j] = f[j - 1];
      f[j - 1] = t;
    }
  return n;
}

/* Align feature sequences by dynamic programming (longest-path over pairs
 * with a score for like turning and a penalty for drift in r). */
static size_t auto_matches(const input *a, const input *b, double *pairs,
                           size_t cap) {
  enum { F = 64 };
  feature fa[F], fb[F];
  size_t na = find_features(a, fa, F), nb = find_features(b, fb, F);
  if (na == 0 || nb == 0) return 0;
  double score[F + 1][F + 1];
  int move[F + 1][F + 1];
  for (size_t i = 0; i <= na; i++)
    for (size_t j = 0; j <= nb; j++) {
      if (i == 0 || j == 0) {
        score[i][j] = 0;
        move[i][j] = 0;
        continue;
      }
      double best = score[i - 1][j];
      int mv = 1;
      if (score[i][j - 1] > best) {
        best = score[i][j - 1];
        mv = 2;
      }
      const feature *x = &fa[i - 1], *y = &fb[j - 1];
      double like = (x->turn * y->turn > 0)
                        ? fmin(fabs(x->turn), fabs(y->turn)) /
                              fmax(fabs(x->turn), fabs(y->turn))
                        : -1.0;
      double gain = like - 4.0 * fabs(x->r - y->r);
      if (gain > 0 && score[i - 1][j - 1] + gain > best) {
        best = score[i - 1][j - 1] + gain;
        mv = 3;
      }
      score[i][j] = best;
      move[i][j] = mv;
    }
  /* backtrack */
  double tmp[2 * F];
  size_t n = 0;
  size_t i = na, j = nb;
  while (i > 0 && j > 0) {
    if (move[i][j] == 3) {
      tmp[2 * n] = fa[i - 1].r;
      tmp[2 * n + 1] = fb[j - 1].r;
      n++;
      i--;
      j--;
    } else if (move[i][j] == 1) {
      i--;
    } else {
      j--;
    }
  }
  /* reverse into pairs, keep strictly increasing pairs inside (0,1) */
  size_t m = 0;
  double pa = 0.0, pb = 0.0;
  for (size_t k = n; k-- > 0 && m < cap;) {
    double x = tmp[2 * k], y = tmp[2 * k + 1];
    if (x > pa + 1e-6 && y > pb + 1e-6 && x < 1 - 1e-6 && y < 1 - 1e-6) {
      pairs[2 * m] = x;
      pairs[2 * m + 1] = y;
      pa = x;
      pb = y;
      m++;
    }
  }
  return m;
}

/* ---- creation ---------------------------------------------------------- */

/* An input's copy, signature and tables; a signature computed from its
 * curve is held to tol, or without one to 1e-6 of its own length. */
static km_status prepare_input(input *in, const km_morph_input *src,
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

static void table_at(const input *in, double r, double out[2]);

/* A planned frame is placed by its pieces' ends, at the plan's breaks x_k
 * of normalised arc length with trapezoid weights: the same fractions of
 * both inputs whatever t (no matches), so their points A_k, B_k and means
 * are taken once here, and "fit" needs per frame only sums over the
 * frame's own points (see planned_placement). */
static km_status plan_placement(km_morph *m, km_error *err) {
  size_t nb = km__frame_plan_pieces(m->plan) + 1;
  const double *x = km__frame_plan_breaks(m->plan);
  m->place_ab = malloc(nb * sizeof *m->place_ab);
  if (!m->place_ab) return km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
  double W = 0.0, qa[2] = {0, 0}, qb[2] = {0, 0};
  for (size_t k = 0; k < nb; k++) {
    double w = 0.5 * ((k + 1 < nb ? x[k + 1] : x[k]) - (k > 0 ? x[k - 1] : x[k]));
    m->place_ab[k][4] = w;
    table_at(&m->in[0], x[k], m->place_ab[k]);
    table_at(&m->in[1], x[k], m->place_ab[k] + 2);
    for (int c = 0; c < 2; c++) {
      qa[c] += w * m->place_ab[k][c];
      qb[c] += w * m->place_ab[k][2 + c];
    }
    W += w;
  }
  m->place_w_sum = W;
  for (int c = 0; c < 2; c++) {
    m->place_qa[c] = qa[c] / W;
    m->place_qb[c] = qb[c] / W;
  }
  return KM_OK;
}

/* Frames of the default morph (turning blend, no matches, cubic output)
 * are planned once: see morph_plan.c. Others are blended piece by piece
 * and reconstructed frame by frame. */
static km_status blend_signature(const km_morph *m, double t,
                                 km_signature *out, km_error *err);
static km_status close_lsq(const km_signature *sig, bool by_corners,
                           const double *weights, km_signature *out,
                           double *gap0, bool *used_corners, km__poll *poll,
                           km_error *err);

/* Whether the lsq closure goes by the frames' corners: so if it can at
 * t = 1/4, 1/2 and 3/4, for every frame of the morph (a sequence must not
 * switch between closures). */
static bool corners_close(const km_morph *m) {
  for (int k = 1; k <= 3; k++) {
    km_signature blended, closed;
    km_signature_init(&blended);
    km_signature_init(&closed);
    double gap;
    bool used = false;
    bool ok = blend_signature(m, k / 4.0, &blended, NULL) == KM_OK &&
              close_lsq(&blended, true, NULL, &closed, &gap, &used, m->poll,
                        NULL) == KM_OK;
    km_signature_free(&blended);
    km_signature_free(&closed);
    if (!ok || !used) return false;
  }
  return true;
}

/* Frames of the default morph (turning blend, no matches, cubic output)
 * are planned once: see morph_plan.c. Others are blended piece by piece
 * and reconstructed frame by frame. Either way the kind of closure is
 * chosen here, once. */
static km_status plan_frames(km_morph *m, km_error *err) {
  const input *a = &m->in[0], *b = &m->in[1];
  km_closure how = m->opt.closure == KM_CLOSURE_AUTO ? KM_CLOSURE_LSQ : m->opt.closure;
  bool lsq = m->closed && how == KM_CLOSURE_LSQ;
  if (m->opt.method != KM_METHOD_CURVATURE) return KM_OK;
  if (m->opt.blend != KM_BLEND_TURNING || m->nk != 2 || m->opt.degree != 3) {
    bool corners = a->sig.ncorners + b->sig.ncorners > 0;
    m->close_by_corners = lsq && corners && corners_close(m);
    return KM_OK;
  }
  const km_pp tp[2] = {a->theta, b->theta};
  double len[2] = {a->sig.length, b->sig.length};
  double ang[2] = {a->sig.angle, b->sig.angle};
  /* a planned frame has two control points a piece and two more (a corner
   * one more); 0 is no bound, so a bound below a piece's worth is one */
  size_t max_pieces = 0;
  if (m->opt.max_points > 0)
    max_pieces = m->opt.max_points >= 4 ? (m->opt.max_points - 2) / 2 : 1;
  km_status st = km__frame_plan_build(&m->plan, tp, len, ang, m->closed,
                                      m->tol, max_pieces, m->poll, err);
  if (st == KM_ELIMIT && max_pieces > 0)
    return km__fail(err, KM_ELIMIT, KM_FIELD_TOLERANCE, -1, NAN,
                    "the frames need more than %zu control points at this "
                    "tolerance, the most allowed a curve: loosen the "
                    "tolerance",
                    m->opt.max_points);
  if (!st) m->close_by_corners = lsq && km__frame_plan_by_corners(m->plan);
  if (!st) st = plan_placement(m, err);
  return st;
}

static km_status pp_copy(km_pp *out, const km_pp *p) {
  km_status st = km__pp_alloc(out, p->degree, p->m);
  if (st) return st;
  memcpy(out->x, p->x, (p->m + 1) * sizeof(double));
  memcpy(out->c, p->c, p->m * (size_t)(p->degree + 1) * sizeof(double));
  return KM_OK;
}

static km_status input_copy(input *out, const input *in, km_error *err) {
  memcpy(out->table, in->table, sizeof out->table);
  memcpy(out->centroid, in->centroid, sizeof out->centroid);
  out->has_curve = in->has_curve;
  km_status st = in->has_curve ? km_curve_copy(&out->curve, &in->curve, err) : KM_OK;
  if (!st) st = km_signature_copy(&out->sig, &in->sig, err);
  if (!st) st = pp_copy(&out->kappa, &in->kappa);
  if (!st) st = pp_copy(&out->theta, &in->theta);
  if (st == KM_ENOMEM) km__fail(err, st, KM_FIELD_NONE, -1, NAN, NULL);
  return st;
}

/* The morph of a closed pair without matches with `to` started a further
 * fraction dshift of its length along: its inputs are copied, not
 * computed again. */
static km_status morph_shifted(const km_morph *base, double dshift,
                               km__poll *poll, km_morph **out, km_error *err) {
  km_morph *m = calloc(1, sizeof *m);
  if (!m) return km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
  for (int i = 0; i < 2; i++) {
    km_curve_init(&m->in[i].curve);
    km_signature_init(&m->in[i].sig);
    km__pp_init(&m->in[i].kappa);
    km__pp_init(&m->in[i].theta);
    km_curve_init(&m->lin[i]);
  }
  m->opt = base->opt;
  m->tol = base->tol;
  m->closed = base->closed;
  m->kmax = base->kmax;
  m->poll = poll;
  m->ra = malloc(2 * sizeof(double));
  m->rb = malloc(2 * sizeof(double));
  km_status st = m->ra && m->rb ? KM_OK
                                : km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
  if (!st) {
    m->ra[0] = m->rb[0] = 0.0;
    m->ra[1] = m->rb[1] = 1.0;
    m->nk = 2;
    st = input_copy(&m->in[0], &base->in[0], err);
  }
  if (!st) st = input_copy(&m->in[1], &base->in[1], err);
  if (!st)
    st = rotate_start(&m->in[1], dshift * m->in[1].sig.length, poll, err);
  if (!st) st = plan_frames(m, err);
  if (st) {
    km_morph_free(m);
    return st;
  }
  *out = m;
  return KM_OK;
}

/* The start of a closed `to` is chosen by the alignment cost; the
 * candidates are returned in cand/ncand, best first. */
static km_status create_impl(km_morph **out, const km_morph_input *from,
                             const km_morph_input *to,
                             const km_morph_options *opt,
                             double *cand,
                             size_t *ncand, km__poll *poll, km_error *err) {
  km_morph *m = calloc(1, sizeof *m);
  if (!m) return km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
  m->poll = poll;
  for (int i = 0; i < 2; i++) {
    km_curve_init(&m->in[i].curve);
    km_signature_init(&m->in[i].sig);
    km_curve_init(&m->lin[i]);
  }
  km_status st = KM_OK;
  m->opt = *opt;
  m->opt.matches = NULL;
  if (m->opt.degree != 5) m->opt.degree = 3;
  /* Inputs' signatures at a tenth of the tolerance: their error adds to
   * the frames'. The default tolerance, 1e-5 of the longer length, is
   * known only with both lengths; a tenth of 1e-5 of each curve's own is
   * at least as tight, and needs no length before the signature. */
  double tol = opt->tolerance > 0 ? opt->tolerance : 0.0;
  st = prepare_input(&m->in[0], from, 0.1 * tol, poll, err);
  if (st) goto fail;
  st = prepare_input(&m->in[1], to, 0.1 * tol, poll, err);
  if (st) goto fail;
  input *a = &m->in[0], *b = &m->in[1];
  if (!(opt->tolerance > 0)) tol = 1e-5 * fmax(a->sig.length, b->sig.length);
  m->tol = tol;
  /* Curvature frames need the signatures only: the curves would be turned
   * and copied with every change of start for nothing. */
  if (opt->method == KM_METHOD_CURVATURE)
    for (int i = 0; i < 2; i++) {
      km_curve_free(&m->in[i].curve);
      m->in[i].has_curve = false;
    }
  if (a->sig.closed != b->sig.closed) {
    st = km__fail(err, KM_EMIXED, KM_FIELD_CLOSED, -1, NAN,
                  "cannot morph an open curve into a closed one (from is %s, "
                  "to is %s)",
                  a->sig.closed ? "closed" : "open",
                  b->sig.closed ? "closed" : "open");
    goto fail;
  }
  m->closed = a->sig.closed;
  if (m->closed) {
    double na = a->sig.turning / (2 * KM_PI), nb = b->sig.turning / (2 * KM_PI);
    long ta = lround(na), tb = lround(nb);
    if (ta == -tb && ta != 0 && opt->orient == KM_ORIENT_AUTO) {
      st = reverse_input(b, poll, err);
      if (st) goto fail;
      tb = lround(b->sig.turning / (2 * KM_PI));
    }
    if (ta != tb) {
      st = km__fail(err, KM_ETURNING, KM_FIELD_NONE, -1, NAN,
                    "closed curves must have equal turning numbers: from "
                    "turns %ld times, to turns %ld times",
                    ta, tb);
      goto fail;
    }
    if (opt->nmatches == 0) {
      double shift = 0.0;
      *ncand = best_shifts(a, b, cand);
      shift = cand[0];
      if (shift > 0) {
        st = rotate_start(b, shift * b->sig.length, poll, err);
        if (st) goto fail;
      }
    }
  }
  /* correspondence */
  size_t nm = opt->nmatches;
  double auto_pairs[2 * 64];
  const double *pairs = opt->matches;
  if (opt->auto_matches && nm == 0) {
    nm = auto_matches(a, b, auto_pairs, 64);
    pairs = auto_pairs;
  }
  m->ra = malloc((nm + 2) * sizeof(double));
  m->rb = malloc((nm + 2) * sizeof(double));
  if (!m->ra || !m->rb) {
    st = km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
    goto fail;
  }
  m->ra[0] = m->rb[0] = 0.0;
  for (size_t i = 0; i < nm; i++) {
    double x = pairs[2 * i], y = pairs[2 * i + 1];
    if (!(x > m->ra[i]) || !(y > m->rb[i]) || !(x < 1) || !(y < 1) ||
        !isfinite(x) || !isfinite(y)) {
      st = km__fail(err, KM_EMATCH, KM_FIELD_MATCHES, (long)i, NAN,
                    "match %zu must lie strictly inside (0, 1) and strictly "
                    "after the previous match on both curves",
                    i);
      goto fail;
    }
    m->ra[i + 1] = x;
    m->rb[i + 1] = y;
  }
  m->ra[nm + 1] = m->rb[nm + 1] = 1.0;
  m->nk = nm + 2;
  m->nuser = nm;
  if (opt->method == KM_METHOD_LINEAR) {
    st = ensure_curve(a, 0.1 * tol, opt->max_points, poll, err);
    if (!st) st = ensure_curve(b, 0.1 * tol, opt->max_points, poll, err);
    if (!st)
      st = km_curve_make_compatible(&a->curve, &b->curve, &m->lin[0],
                                    &m->lin[1], err);
    if (st) goto fail;
  }
  m->kmax = fmax(km_signature_max_abs_kappa(&a->sig), km_signature_max_abs_kappa(&b->sig));
  /* Frames of the default morph (turning blend, no matches, cubic output)
   * are planned once: see morph_plan.c. Others are blended piece by piece
   * and reconstructed frame by frame. */
  st = plan_frames(m, err);
  if (st) goto fail;
  *out = m;
  return KM_OK;
fail:
  km_morph_free(m);
  return st;
}

/* Self-crossings of five frames (t = 1/6 .. 5/6), counted until they
 * reach cap: a candidate that has as many as the best one so far loses. */
static km_status frame_impl(const km_morph *m, double t, km__poll *poll,
                            km_curve *out, km_frame_metrics *metrics,
                            km_signature *sig_out, km_error *err);

static long preview_crossings(const km_morph *m, long cap) {
  long total = 0;
  static const double T[5] = {3 / 6.0, 2 / 6.0, 4 / 6.0, 1 / 6.0, 5 / 6.0};
  for (int k = 0; k < 5 && total < cap; k++) {
    km_curve c;
    if (frame_impl(m, T[k], m->poll, &c, NULL, NULL, NULL) != KM_OK) return LONG_MAX;
    long x = km__self_intersections(&c, m->tol, m->poll);
    km_curve_free(&c);
    if (x > 0) total += x;
  }
  return total;
}

km_status km_morph_create(km_morph **out, const km_morph_input *from,
                          const km_morph_input *to,
                          const km_morph_options *opt, km_error *err) {
  double cand[SHIFT_CANDIDATES];
  size_t ncand = 0;
  km_morph *m = NULL;
  km__poll poll;
  km__poll_init(&poll, opt->stop);
  km_status st = create_impl(&m, from, to, opt, cand, &ncand, &poll, err);
  if (st == KM_ECANCELLED || (st && poll.stopped)) return km__stopped(err);
  if (st) return st;
  /* Among starts that align about as well, prefer one whose frames do not
   * cross themselves: the first candidate, in order of alignment, none of
   * whose five preview frames crosses (each stops at its first crossing);
   * failing that the one with the fewest crossings, the better aligned
   * among equals. Only planned morphs preview (the default: turning
   * blend, cubic output): a frame of any other costs a blend and a
   * reconstruction, twenty of them more than the whole morph. */
  if (ncand > 1 && opt->method == KM_METHOD_CURVATURE && m->plan) {
    km_morph *alts[SHIFT_CANDIDATES] = {m};
    size_t n = 1, pick = SIZE_MAX;
    if (preview_crossings(m, 1) == 0) pick = 0;
    for (size_t i = 1; i < ncand && pick == SIZE_MAX; i++) {
      km_morph *alt = NULL;
      double d = cand[i] - cand[0];
      if (morph_shifted(m, d < 0 ? d + 1.0 : d, &poll, &alt, NULL) != KM_OK)
        continue;
      alts[n++] = alt;
      if (preview_crossings(alt, 1) == 0) pick = n - 1;
    }
    if (pick == SIZE_MAX) {
      long best = LONG_MAX;
      for (size_t k = 0; k < n; k++) {
        long x = preview_crossings(alts[k], best);
        if (x < best || pick == SIZE_MAX) {
          best = x;
          pick = k;
        }
      }
    }
    for (size_t k = 0; k < n; k++)
      if (k != pick) km_morph_free(alts[k]);
    m = alts[pick];
  }
  if (poll.stopped) {
    km_morph_free(m);
    return km__stopped(err);
  }
  m->poll = NULL;
  m->opt.stop = NULL;
  *out = m;
  return KM_OK;
}

size_t km_morph_matches_used(const km_morph *m, double *pairs, size_t cap) {
  for (size_t i = 0; i < m->nuser && i < cap && pairs; i++) {
    pairs[2 * i] = m->ra[i + 1];
    pairs[2 * i + 1] = m->rb[i + 1];
  }
  return m->nuser;
}

void km_morph_inputs(const km_morph *m, double length[2], double turning[2]) {
  for (int i = 0; i < 2; i++) {
    length[i] = m->in[i].sig.length;
    turning[i] = m->in[i].sig.turning;
  }
}

/* ---- frames ------------------------------------------------------------ */

/* pieces of p restricted to [x0, x1] */
static km_status pp_slice(km_pp *out, const km_pp *p, double x0, double x1) {
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

typedef struct corner_list {
  km_corner *c;
  size_t n, cap;
} corner_list;

static km_status corner_push(corner_list *cl, double s, double turn) {
  if (cl->n == cl->cap) {
    size_t cap = cl->cap ? 2 * cl->cap : 16;
    km_corner *c = realloc(cl->c, cap * sizeof *c);
    if (!c) return KM_ENOMEM;
    cl->c = c;
    cl->cap = cap;
  }
  cl->c[cl->n].s = s;
  cl->c[cl->n].turn = turn;
  cl->n++;
  return KM_OK;
}

static int cmp_corner(const void *x, const void *y) {
  double a = ((const km_corner *)x)->s, b = ((const km_corner *)y)->s;
  return (a > b) - (a < b);
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
  double x0, h;      /* frame interval [x0, x0 + h] */
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

/* Returns KM_EINVAL when the smooth map is not monotone for these matches
 * (the caller then keeps the piecewise-linear correspondence). */
static km_status blend_smooth(const km_morph *m, double t, km_pp *out,
                              corner_list *cl) {
  const input *a = &m->in[0], *b = &m->in[1];
  double La = a->sig.length, Lb = b->sig.length;
  size_t K = m->nk - 1; /* segments */
  double *buf = malloc((6 * K + 1) * sizeof(double));
  if (!buf) return KM_ENOMEM;
  double *rho = buf, *len = buf + K, *S = buf + 2 * K, *nl = buf + 3 * K + 1,
         *nr = buf + 4 * K + 1, *mid = buf + 5 * K + 1;
  S[0] = 0.0;
  for (size_t k = 0; k < K; k++) {
    double la = (m->ra[k + 1] - m->ra[k]) * La, lb = (m->rb[k + 1] - m->rb[k]) * Lb;
    len[k] = (1 - t) * la + t * lb;
    rho[k] = la / len[k];
    S[k + 1] = S[k] + len[k];
  }
  km_status st = smooth_nodes(rho, len, K, m->closed, t, nl, nr, mid);
  if (st) {
    free(buf);
    return st;
  }
  /* frame breaks: segment ends, middles, and the images of both inputs'
   * breaks and corners */
  size_t cap = 2 * K + 1 + a->kappa.m + b->kappa.m + 2, nb = 0;
  double *br = malloc(cap * sizeof(double));
  quad_map *qm = malloc(2 * K * sizeof *qm);
  km_pp o;
  km__pp_init(&o);
  if (!br || !qm) {
    st = KM_ENOMEM;
    goto done;
  }
  double sa_at = 0.0;
  for (size_t k = 0; k < K; k++) {
    double h = 0.5 * len[k];
    qm[2 * k] = (quad_map){S[k], h, sa_at, nl[k], mid[k]};
    sa_at = qm_sa(&qm[2 * k], S[k] + h);
    qm[2 * k + 1] = (quad_map){S[k] + h, h, sa_at, mid[k], nr[k]};
    sa_at = m->ra[k + 1] * La; /* exact at the match */
    br[nb++] = S[k];
    br[nb++] = S[k] + h;
  }
  br[nb++] = S[K];
  size_t nq = 2 * K;
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
      double y0 = sb_of(&qm[q], qm[q].x0, t), y1 = sb_of(&qm[q], qm[q].x0 + qm[q].h, t);
      if (y > y0 && y < y1) {
        br[nb++] = qm_inv_b(&qm[q], y, t);
        break;
      }
    }
  }
  qsort(br, nb, sizeof(double), km__cmp_double);
  size_t mb = 0;
  for (size_t i = 0; i < nb; i++)
    if (mb == 0 || br[i] - br[mb - 1] > 1e-13 * S[K]) br[mb++] = br[i];
  br[mb - 1] = S[K];
  int da = a->kappa.degree, db = b->kappa.degree;
  int dd = 2 * (da > db ? da : db) + 1;
  if (dd > KM_MAX_FN_DEGREE) dd = KM_MAX_FN_DEGREE;
  st = km__pp_alloc(&o, dd, mb - 1);
  if (st) goto done;
  size_t q = 0;
  for (size_t i = 0; i + 1 < mb; i++) {
    double x0 = br[i], x1 = br[i + 1], xm = 0.5 * (x0 + x1);
    while (q + 1 < nq && xm > qm[q].x0 + qm[q].h) q++;
    const quad_map *Q = &qm[q];
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
    if (!bern_interp(u, v, dd)) {
      st = KM_ENOCONVERGE;
      goto done;
    }
    memcpy(o.c + i * (size_t)(dd + 1), v, (size_t)(dd + 1) * sizeof(double));
    o.x[i] = x0;
  }
  o.x[0] = 0.0;
  o.x[mb - 1] = S[K];
  /* corners at the images of the inputs' corners */
  for (int w = 0; w < 2 && !st; w++) {
    const input *in = w ? b : a;
    double cw = w ? t : 1 - t;
    for (size_t i = 0; i < in->sig.ncorners && !st; i++) {
      double y = in->sig.corners[i].s, x = -1.0;
      double L = w ? Lb : La;
      if (y >= L * (1 - 1e-12)) {
        x = S[K];
      } else if (y <= 0) {
        x = 0.0;
      } else {
        /* the first segment whose image reaches y: the ends of
         * neighbouring images agree only up to rounding, and a corner at a
         * match (as "auto" puts them) must not fall between them */
        for (size_t k = 0; k < nq; k++) {
          double y1 = w ? sb_of(&qm[k], qm[k].x0 + qm[k].h, t)
                        : qm_sa(&qm[k], qm[k].x0 + qm[k].h);
          if (y <= y1 + 1e-12 * L || k + 1 == nq) {
            x = w ? qm_inv_b(&qm[k], y, t) : qm_inv_a(&qm[k], y);
            break;
          }
        }
      }
      if (x < 0) continue;
      double turn = cw * in->sig.corners[i].turn;
      if (m->opt.blend == KM_BLEND_PAPER) {
        /* the delta scales with dx/ds of that input */
        size_t k = 0;
        while (k + 1 < nq && x > qm[k].x0 + qm[k].h) k++;
        double al = qm[k].al0 + (qm[k].al1 - qm[k].al0) * (x - qm[k].x0) / qm[k].h;
        double be = (1 - (1 - t) * al) / t;
        turn /= w ? be : al;
        if (turn >= KM_PI) turn = KM_PI - 1e-9;
        if (turn <= -KM_PI) turn = -KM_PI + 1e-9;
      }
      st = corner_push(cl, x, turn);
    }
  }
  if (!st) {
    *out = o;
    km__pp_init(&o);
  }
done:
  km__pp_free(&o);
  free(br);
  free(qm);
  free(buf);
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
  if (x1 > x0) return pp_slice(out, p, x0, x1);
  km_status st = km__pp_alloc(out, 0, 1);
  if (st) return st;
  out->x[0] = 0.0;
  out->x[1] = 1.0;
  out->c[0] = km__pp_eval(p, x0);
  return KM_OK;
}

/* The blended curvature on segment k of frame t, over [S, S + l] of the
 * frame (l > 0), under the piecewise-linear correspondence. */
static km_status blend_segment(const km_morph *m, double t, size_t k,
                               double S, double l, km_pp *out) {
  const input *a = &m->in[0], *b = &m->in[1];
  double La = a->sig.length, Lb = b->sig.length;
  double la = (m->ra[k + 1] - m->ra[k]) * La, lb = (m->rb[k + 1] - m->rb[k]) * Lb;
  double wa = 1 - t, wb = t;
  if (m->opt.blend != KM_BLEND_PAPER) {
    wa = (1 - t) * la / l;
    wb = t * lb / l;
  }
  km_pp sa, sb;
  km__pp_init(&sa);
  km__pp_init(&sb);
  km_status st = slice_or_point(&sa, &a->kappa, m->ra[k] * La, m->ra[k + 1] * La);
  if (!st) st = slice_or_point(&sb, &b->kappa, m->rb[k] * Lb, m->rb[k + 1] * Lb);
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
    if (q != i) memmove(p->c + q * stride, p->c + i * stride, stride * sizeof(double));
    q++;
  }
  if (q == 0) q = 1; /* all short (a frame of rounding's length) */
  p->x[q] = end;
  p->m = q;
}

/* The blended signature of frame t (before closure), placed at the origin
 * with the blended start angle. */
static km_status blend_signature(const km_morph *m, double t,
                                 km_signature *out, km_error *err) {
  const input *a = &m->in[0], *b = &m->in[1];
  double La = a->sig.length, Lb = b->sig.length;
  double Lt = (1 - t) * La + t * Lb;
  km_pp *segs = calloc(m->nk - 1, sizeof *segs);
  corner_list cl = {NULL, 0, 0};
  km_pp whole;
  km__pp_init(&whole);
  km_status st = segs ? KM_OK : KM_ENOMEM;
  double S = 0.0;
  size_t total = 0;
  int deg = 0;
  bool smooth = false;
  if (!st && m->nk > 2 && t > 0 && t < 1) {
    km_status ss = blend_smooth(m, t, &whole, &cl);
    if (ss == KM_OK)
      smooth = true;
    else if (ss != KM_EINVAL)
      st = ss;
  }
  for (size_t k = 0; !st && !smooth && k + 1 < m->nk; k++) {
    double la = (m->ra[k + 1] - m->ra[k]) * La, lb = (m->rb[k + 1] - m->rb[k]) * Lb;
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
    /* corners of both inputs inside this segment */
    double cwa = m->opt.blend == KM_BLEND_PAPER ? (1 - t) * corner_scale(l, la) : (1 - t);
    double cwb = m->opt.blend == KM_BLEND_PAPER ? t * corner_scale(l, lb) : t;
    for (int w = 0; w < 2 && !st; w++) {
      const input *in = w ? b : a;
      double L = w ? Lb : La, r0 = w ? m->rb[k] : m->ra[k], r1 = w ? m->rb[k + 1] : m->ra[k + 1];
      double cw = w ? cwb : cwa;
      if (cw == 0) continue;
      for (size_t i = 0; i < in->sig.ncorners && !st; i++) {
        double r = in->sig.corners[i].s / L;
        bool last = k + 2 == m->nk;
        if (r < r0 || r > r1 || (r == r1 && !last) ) continue;
        double turn = cw * in->sig.corners[i].turn;
        if (turn >= KM_PI) turn = KM_PI - 1e-9;
        if (turn <= -KM_PI) turn = -KM_PI + 1e-9;
        st = corner_push(&cl, point ? S : S + (r - r0) / (r1 - r0) * l, turn);
      }
    }
    S += l;
  }
  if (!st && !smooth) st = km__pp_alloc(&whole, deg, total);
  if (!st && !smooth) {
    size_t q = 0;
    for (size_t k = 0; k + 1 < m->nk; k++) {
      for (size_t i = 0; i < segs[k].m; i++, q++) {
        whole.x[q] = segs[k].x[i];
        km__bern_elevate(segs[k].c + i * (size_t)(segs[k].degree + 1),
                         segs[k].degree, deg, whole.c + q * (size_t)(deg + 1));
      }
    }
    whole.x[0] = 0.0;
    whole.x[total] = Lt;
  }
  if (segs)
    for (size_t k = 0; k + 1 < m->nk; k++) km__pp_free(&segs[k]);
  free(segs);
  if (st) goto done;
  /* merge corners at the same place */
  if (cl.n > 1) qsort(cl.c, cl.n, sizeof *cl.c, cmp_corner);
  size_t nc = 0;
  for (size_t i = 0; i < cl.n; i++) {
    if (cl.c[i].s > Lt) cl.c[i].s = Lt;
    if (nc > 0 && cl.c[i].s - cl.c[nc - 1].s <= 1e-12 * Lt)
      cl.c[nc - 1].turn += cl.c[i].turn;
    else
      cl.c[nc++] = cl.c[i];
  }
  /* the paper blend's deltas are clamped below a half turn one by one;
   * two at one place (where a segment of one input has almost no length
   * and scales its corners past any bound) must not sum beyond it */
  for (size_t i = 0; i < nc; i++)
    cl.c[i].turn = fmax(fmin(cl.c[i].turn, KM_PI - 1e-9), -KM_PI + 1e-9);
  size_t keep = 0;
  for (size_t i = 0; i < nc; i++)
    if (fabs(cl.c[i].turn) > 1e-15) cl.c[keep++] = cl.c[i];
  km_fn kf;
  km_fn_init(&kf);
  drop_short_pieces(&whole, SHORT_PIECE * Lt);
  st = km__pp_to_fn(&kf, &whole);
  if (st) goto done;
  double phia = a->sig.angle, phib = b->sig.angle;
  phib = phia + km__wrap_angle(phib - phia);
  double origin[2] = {0, 0};
  st = km_signature_create(out, Lt, origin, (1 - t) * phia + t * phib, &kf,
                           cl.c, keep, m->closed, err);
  km_fn_free(&kf);
done:
  km__pp_free(&whole);
  free(cl.c);
  if (st == KM_ENOMEM) km__fail(err, st, KM_FIELD_NONE, -1, NAN, NULL);
  return st;
}

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
        free(q);
        return KM_ECANCELLED;
      }
      for (int c = 0; c < chunks; c++) {
        double ca = lo + (hi - lo) * c / chunks, cb = lo + (hi - lo) * (c + 1) / chunks;
        double mid = 0.5 * (ca + cb), hw = 0.5 * (cb - ca);
        if (n + 8 > cap) {
          cap = cap ? 2 * cap : 1024;
          if (cap > 64 * (size_t)KM_MAX_PIECES) {
            free(q);
            return KM_ELIMIT;
          }
          qnode *nq = realloc(q, cap * sizeof *nq);
          if (!nq) {
            free(q);
            return KM_ENOMEM;
          }
          q = nq;
        }
        for (int k = 0; k < 8; k++) {
          double s = mid + hw * km__gl8_x[k];
          q[n].s = s;
          q[n].w = hw * km__gl8_w[k];
          q[n].theta = km__bern_eval(tp->c + i * (size_t)(dt + 1), dt, (s - a) / len);
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

/* Closed curve nearest in curvature (L2, weighted by weights[iv] on the
 * basis interval iv when given) to sig: see the DESIGN note. With
 * by_corners, the interior corners take the whole correction when they can
 * (km__close_by_corners: the smooth curvature keeps its bound, straight
 * edges stay straight; *used_corners then true), else the smooth curvature
 * does. On success *out is the corrected signature and *gap0 the gap
 * before. */
static km_status close_lsq(const km_signature *sig, bool by_corners,
                           const double *weights, km_signature *out,
                           double *gap0, bool *used_corners, km__poll *poll,
                           km_error *err) {
  enum { NB = LSQ_INTERVALS, NF = LSQ_INTERVALS - 3 };
  double L = sig->length, h = L / NB;
  km_pp kp, tp, dpsi, kt;
  km__pp_init(&kp);
  km__pp_init(&tp);
  km__pp_init(&dpsi);
  km__pp_init(&kt);
  qnode *q = NULL;
  size_t nq = 0;
  double c[NF] = {0};
  km_status st = km__build_theta(sig, &kp, &tp);
  if (!st) st = closure_nodes(&kp, &tp, h, poll, &q, &nq);
  if (st) goto done;
  /* the gap before any correction, and the integrals of the stretches
   * between interior corners (for the closure by corners) */
  size_t nc = 0;
  double *S = NULL, *tau = NULL, *delta = NULL;
  for (size_t k = 0; k < sig->ncorners; k++)
    if (sig->corners[k].s > 0 && sig->corners[k].s < L) nc++;
  S = malloc((4 * nc + 2) * sizeof(double));
  if (!S) {
    st = KM_ENOMEM;
    goto done;
  }
  tau = S + 2 * (nc + 1);
  delta = tau + nc;
  {
    size_t m = 0, ci = 0;
    S[0] = S[1] = 0.0;
    for (size_t n = 0; n < nq; n++) {
      while (ci < sig->ncorners && sig->corners[ci].s <= q[n].s) {
        if (sig->corners[ci].s > 0 && sig->corners[ci].s < L) {
          tau[m++] = sig->corners[ci].turn;
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
    *gap0 = hypot(gx, gy);
    if (*gap0 <= 1e-12 * L) {
      /* closed already: either closure would change nothing */
      free(S);
      if (used_corners) *used_corners = by_corners;
      st = km_signature_copy(out, sig, err);
      goto done;
    }
  }
  if (by_corners && km__close_by_corners(S, tau, nc, delta)) {
    km_corner *cs = malloc((sig->ncorners + 1) * sizeof *cs);
    if (!cs) {
      free(S);
      st = KM_ENOMEM;
      goto done;
    }
    for (size_t k = 0, m = 0; k < sig->ncorners; k++) {
      cs[k] = sig->corners[k];
      if (cs[k].s > 0 && cs[k].s < L) cs[k].turn += delta[m++];
    }
    free(S);
    st = km_signature_create(out, L, sig->start, sig->angle, &sig->kappa, cs,
                             sig->ncorners, sig->closed, err);
    free(cs);
    if (used_corners) *used_corners = st == KM_OK;
    goto done;
  }
  free(S);
  /* the metric: Gram matrix of the basis derivatives in s (see
   * morph_plan.c) */
  double M[NF * NF];
  if (weights)
    km__closure_metric_weighted(weights, M);
  else
    km__closure_metric(M);
  for (int i = 0; i < NF * NF; i++) M[i] /= h;
  for (int it = 0;; it++) {
    double G[2] = {0, 0}, J[2][NF];
    memset(J, 0, sizeof J);
    for (size_t n = 0; n < nq; n++) {
      if ((n & 255) == 0 && km__poll_stop(poll, 512)) {
        st = KM_ECANCELLED;
        goto done;
      }
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
    if (hypot(G[0], G[1]) <= 1e-12 * L) break;
    if (it == 40) {
      st = KM_ENOCONVERGE;
      goto done;
    }
    /* Gauss-Newton in the metric M: project once (the least change of
     * curvature that meets the linearised constraints), then minimum-norm
     * steps (quadratic convergence); as in morph_plan.c */
    bool project = it == 0;
    double Y[2][NF];
    for (int r = 0; r < 2; r++) {
      double A[NF * NF];
      memcpy(A, M, sizeof A);
      memcpy(Y[r], J[r], sizeof Y[r]);
      if (!km__solve_dense(A, Y[r], NF)) {
        st = KM_ENOCONVERGE;
        goto done;
      }
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
    if (!km__solve_dense(S2, rhs, 2)) {
      st = KM_ENOCONVERGE;
      goto done;
    }
    for (int i = 0; i < NF; i++)
      c[i] = (project ? 0.0 : c[i]) + Y[0][i] * rhs[0] + Y[1][i] * rhs[1];
  }
  /* kappa~ = kappa + psi' (psi' is quadratic on each basis interval) */
  st = km__pp_alloc(&dpsi, 2, NB);
  if (st) goto done;
  for (int iv = 0; iv < NB; iv++) {
    double f[3];
    for (int k = 0; k < 3; k++) {
      double u = iv + 0.5 * k, v = 0.0;
      for (int i = 0; i < NF; i++) v += c[i] * km__bspline3_d(u - i);
      f[k] = v / h;
    }
    double *bc = dpsi.c + (size_t)iv * 3;
    bc[0] = f[0];
    bc[2] = f[2];
    bc[1] = 2 * f[1] - 0.5 * (f[0] + f[2]);
    dpsi.x[iv] = iv * h;
  }
  dpsi.x[NB] = L;
  km_pp k0;
  km__pp_init(&k0);
  st = km__pp_from_fn(&k0, &sig->kappa);
  if (!st) st = km__pp_blend(&kt, &k0, 1.0, &dpsi, 1.0, 0.0, L);
  km__pp_free(&k0);
  if (st) goto done;
  km_fn kf;
  km_fn_init(&kf);
  st = km__pp_to_fn(&kf, &kt);
  if (st) goto done;
  st = km_signature_create(out, L, sig->start, sig->angle, &kf, sig->corners,
                           sig->ncorners, sig->closed, err);
  km_fn_free(&kf);
done:
  free(q);
  km__pp_free(&kp);
  km__pp_free(&tp);
  km__pp_free(&dpsi);
  km__pp_free(&kt);
  if (st == KM_ECANCELLED) return km__stopped(err);
  if (st == KM_ENOMEM || st == KM_ENOCONVERGE || st == KM_ELIMIT)
    km__fail(err, st, KM_FIELD_NONE, -1, NAN,
             st == KM_ENOCONVERGE ? "closing the frame did not converge"
                                  : NULL);
  return st;
}

/* The paper's corrections of the control polygon (section 3.2). */
static void close_polygon(km_curve *c, km_closure how) {
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
    double tx = P[2 * n] - P[2 * (n - 1)], ty = P[2 * n + 1] - P[2 * (n - 1) + 1];
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

/* frame arc length s -> normalised positions on a and b */
static void corresponding(const km_morph *m, double t, double s, double *ra,
                          double *rb) {
  double La = m->in[0].sig.length, Lb = m->in[1].sig.length, S = 0.0;
  for (size_t k = 0; k + 1 < m->nk; k++) {
    double la = (m->ra[k + 1] - m->ra[k]) * La, lb = (m->rb[k + 1] - m->rb[k]) * Lb;
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

/* Rigid motion (rotation about the origin by *rot, then translation) that
 * places a frame given by samples F at frame arc lengths s[j] (weights w,
 * arc length the samples stand for): "fit" maps them in the least-squares
 * sense onto the linear blend Q of the inputs at corresponding points. */
static void place_samples(const km_morph *m, double t, const double (*F)[2],
                          const double *s, const double *w, size_t n,
                          double *rot, double T[2]) {
  const input *a = &m->in[0], *b = &m->in[1];
  *rot = 0.0;
  T[0] = (1 - t) * a->sig.start[0] + t * b->sig.start[0];
  T[1] = (1 - t) * a->sig.start[1] + t * b->sig.start[1];
  if (t == 0.0 || t == 1.0 || m->opt.anchor == KM_ANCHOR_START || n == 0)
    return;
  double fc[2] = {0, 0}, qc[2] = {0, 0}, W = 0.0;
  double (*Q)[2] = malloc(n * sizeof *Q);
  if (!Q) return;
  for (size_t j = 0; j < n; j++) {
    double ra, rb, pa[2], pb[2];
    corresponding(m, t, s[j], &ra, &rb);
    table_at(a, ra, pa);
    table_at(b, rb, pb);
    Q[j][0] = (1 - t) * pa[0] + t * pb[0];
    Q[j][1] = (1 - t) * pa[1] + t * pb[1];
    for (int k = 0; k < 2; k++) {
      fc[k] += w[j] * F[j][k];
      qc[k] += w[j] * Q[j][k];
    }
    W += w[j];
  }
  for (int k = 0; k < 2; k++) {
    fc[k] /= W;
    qc[k] /= W;
  }
  if (m->opt.anchor == KM_ANCHOR_CENTROID) {
    /* the blended start angle is kept; the wire centroid follows the
     * line between the inputs' centroids */
    T[0] = (1 - t) * a->centroid[0] + t * b->centroid[0] - fc[0];
    T[1] = (1 - t) * a->centroid[1] + t * b->centroid[1] - fc[1];
    free(Q);
    return;
  }
  double sx = 0.0, sy = 0.0;
  for (size_t j = 0; j < n; j++) {
    double fx = F[j][0] - fc[0], fy = F[j][1] - fc[1];
    double qx = Q[j][0] - qc[0], qy = Q[j][1] - qc[1];
    sx += w[j] * (fx * qx + fy * qy);
    sy += w[j] * (fx * qy - fy * qx);
  }
  *rot = atan2(sy, sx);
  double cr = cos(*rot), sr = sin(*rot);
  T[0] = qc[0] - (cr * fc[0] - sr * fc[1]);
  T[1] = qc[1] - (sr * fc[0] + cr * fc[1]);
  free(Q);
}

/* Placement of a frame curve whose parameter is arc length: samples at the
 * midpoints of FIT_N equal parts. */
static void placement(const km_morph *m, double t, const km_curve *f,
                      double Lt, double *rot, double T[2]) {
  static const size_t N = FIT_N;
  double (*F)[2] = malloc(N * sizeof *F);
  double *s = malloc(2 * N * sizeof(double));
  if (!F || !s) {
    free(F);
    free(s);
    place_samples(m, t, NULL, NULL, NULL, 0, rot, T); /* by the start */
    return;
  }
  double *w = s + N;
  for (size_t j = 0; j < N; j++) {
    double d[1][2];
    s[j] = Lt * ((double)j + 0.5) / (double)N;
    w[j] = 1.0;
    km_curve_eval(f, s[j], 0, d);
    F[j][0] = d[0][0];
    F[j][1] = d[0][1];
  }
  place_samples(m, t, (const double (*)[2])F, s, w, N, rot, T);
  free(F);
  free(s);
}

static double curve_kappa(const km_curve *c, double t, double *speed) {
  double d[3][2];
  km_curve_eval(c, t, 2, d);
  double sp = hypot(d[1][0], d[1][1]);
  *speed = sp;
  return (d[1][0] * d[2][1] - d[1][1] * d[2][0]) / (sp * sp * sp);
}

/* Metrics of a curve measured directly (linear frames may have cusps, so
 * no signature is assumed): dense Gauss-Legendre per span. */
static void curve_metrics(const km_curve *c, double tol, km__poll *poll,
                          km_frame_metrics *mt) {
  double L = 0.0, kmax = 0.0, bend = 0.0;
  for (size_t i = (size_t)c->degree; i < c->n; i++) {
    double a = c->knots[i], b = c->knots[i + 1];
    if (!(b > a)) continue;
    for (int sub = 0; sub < 8; sub++) {
      double sa = a + (b - a) * sub / 8, sb = a + (b - a) * (sub + 1) / 8;
      double mid = 0.5 * (sa + sb), hw = 0.5 * (sb - sa);
      for (int k = 0; k < 16; k++) {
        double sp, kap = curve_kappa(c, mid + hw * km__gl16_x[k], &sp);
        double w = hw * km__gl16_w[k] * sp;
        L += w;
        if (isfinite(kap)) {
          bend += w * kap * kap;
          kmax = fmax(kmax, fabs(kap));
        }
      }
    }
  }
  mt->length = km_curve_length(c);
  (void)L;
  mt->max_abs_kappa = kmax;
  mt->bending_energy = bend;
  mt->self_intersections = km__self_intersections(c, tol, poll);
  mt->closure_gap = 0.0;
}

static km_status linear_frame(const km_morph *m, double t, km_curve *out,
                              km_frame_metrics *metrics, km_signature *sig_out,
                              km__poll *poll, km_error *err) {
  const km_curve *a = &m->lin[0], *b = &m->lin[1];
  km_curve f;
  km_status st = km_curve_copy(&f, a, err);
  if (st) return st;
  for (size_t i = 0; i < 2 * f.n; i++) f.cp[i] = (1 - t) * a->cp[i] + t * b->cp[i];
  if (f.w)
    for (size_t i = 0; i < f.n; i++) f.w[i] = (1 - t) * a->w[i] + t * b->w[i];
  f.closed = a->closed && b->closed;
  if (metrics) curve_metrics(&f, m->tol, poll, metrics);
  if (sig_out) {
    km_signature_init(sig_out);
    /* a linear frame may be singular (cusp): then no signature */
    if (km__signature_compute(&f, m->tol, 1e-5, poll, sig_out, NULL) != KM_OK)
      km_signature_init(sig_out);
  }
  if (poll && poll->stopped) {
    km_curve_free(&f);
    km_signature_free(sig_out);
    return km__stopped(err);
  }
  *out = f;
  return KM_OK;
}

/* place_samples for a planned frame given by its points F at the plan's
 * breaks: the targets Q_k = (1 - t) A_k + t B_k are linear in t, so the
 * fit's sums split into a part of each input. */
static void planned_placement(const km_morph *m, double t, const double (*F)[2],
                              size_t nb, double *rot, double T[2]) {
  const input *a = &m->in[0], *b = &m->in[1];
  *rot = 0.0;
  T[0] = (1 - t) * a->sig.start[0] + t * b->sig.start[0];
  T[1] = (1 - t) * a->sig.start[1] + t * b->sig.start[1];
  if (t == 0.0 || t == 1.0 || m->opt.anchor == KM_ANCHOR_START) return;
  double fc[2] = {0, 0};
  for (size_t k = 0; k < nb; k++) {
    double w = m->place_ab[k][4];
    fc[0] += w * F[k][0];
    fc[1] += w * F[k][1];
  }
  fc[0] /= m->place_w_sum;
  fc[1] /= m->place_w_sum;
  if (m->opt.anchor == KM_ANCHOR_CENTROID) {
    T[0] = (1 - t) * a->centroid[0] + t * b->centroid[0] - fc[0];
    T[1] = (1 - t) * a->centroid[1] + t * b->centroid[1] - fc[1];
    return;
  }
  /* sum w (F - fc) . (Q - qc) = sum w (F - fc) . Q, as sum w (F - fc) = 0 */
  double sa = 0.0, ca = 0.0, sb = 0.0, cb = 0.0;
  for (size_t k = 0; k < nb; k++) {
    const double *q = m->place_ab[k];
    double fx = q[4] * (F[k][0] - fc[0]), fy = q[4] * (F[k][1] - fc[1]);
    sa += fx * q[0] + fy * q[1];
    ca += fx * q[1] - fy * q[0];
    sb += fx * q[2] + fy * q[3];
    cb += fx * q[3] - fy * q[2];
  }
  *rot = atan2((1 - t) * ca + t * cb, (1 - t) * sa + t * sb);
  double cr = cos(*rot), sr = sin(*rot);
  double qc[2] = {(1 - t) * m->place_qa[0] + t * m->place_qb[0],
                  (1 - t) * m->place_qa[1] + t * m->place_qb[1]};
  T[0] = qc[0] - (cr * fc[0] - sr * fc[1]);
  T[1] = qc[1] - (sr * fc[0] + cr * fc[1]);
}

/* A frame from the plan: the curve only (metrics and signatures take the
 * general path, which yields them exactly). */
static km_status planned_frame(const km_morph *m, double t, km_closure how,
                               km__poll *poll, km_curve *out, km_error *err) {
  const input *a = &m->in[0], *b = &m->in[1];
  double phia = a->sig.angle, phib = phia + km__wrap_angle(b->sig.angle - phia);
  double rot, T[2];
  size_t nb = km__frame_plan_pieces(m->plan) + 1;
  double *buf = malloc(2 * nb * sizeof(double));
  if (!buf) return km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
  double (*P)[2] = (double (*)[2])buf;
  km_curve f;
  km_curve_init(&f);
  km_status st = km__frame_plan_curve(m->plan, t, (1 - t) * phia + t * phib,
                                      how == KM_CLOSURE_LSQ, &f, buf, poll, err);
  if (st) goto done;
  if (m->closed && !f.closed && how != KM_CLOSURE_NONE)
    close_polygon(&f, how == KM_CLOSURE_LSQ ? KM_CLOSURE_C0 : how);
  planned_placement(m, t, (const double (*)[2])P, nb, &rot, T);
  st = km__curve_transform_in_place(&f, rot, T[0], T[1], err);
  if (!st) {
    *out = f;
    km_curve_init(&f);
  }
done:
  km_curve_free(&f);
  free(buf);
  return st;
}

/* Largest |kappa| over each basis interval of the closure (a bound from
 * the pieces' Bernstein coefficients). */
static void interval_max(const km_fn *kappa, double L, double *out) {
  enum { NB = LSQ_INTERVALS };
  for (int iv = 0; iv < NB; iv++) out[iv] = 0.0;
  km_pp p;
  km__pp_init(&p);
  if (km__pp_from_fn(&p, kappa)) {
    double k = km_fn_max_abs(kappa); /* no memory: one bound for all */
    for (int iv = 0; iv < NB; iv++) out[iv] = k;
    return;
  }
  double h = L / NB;
  int d = p.degree;
  for (size_t i = 0; i < p.m; i++) {
    double a = p.x[i], b = p.x[i + 1], w = b - a;
    if (!(w > 0)) continue;
    int iv0 = (int)floor(a / h), iv1 = (int)floor(b / h);
    for (int iv = iv0 < 0 ? 0 : iv0; iv <= iv1 && iv < NB; iv++) {
      double lo = fmax(a, iv * h), hi = fmin(b, (iv + 1) * h), r[KM_MAX_FN_DEGREE + 2];
      if (!(hi > lo)) continue;
      km__bern_restrict(p.c + i * (size_t)(d + 1), d, (lo - a) / w, (hi - a) / w, r);
      out[iv] = fmax(out[iv], km__bern_abs_bound(r, d));
    }
  }
  km__pp_free(&p);
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
static km_status close_within_bound(const km_morph *m, const km_signature *blended,
                                    km_signature *out, double *gap,
                                    km__poll *poll, km_error *err) {
  enum { NB = LSQ_INTERVALS };
  bool used = false;
  km_status st = close_lsq(blended, m->close_by_corners, NULL, out, gap, &used,
                           poll, err);
  double bound = m->kmax * (1 + 1e-9);
  if (st || used || m->nuser == 0 || km_signature_max_abs_kappa(out) <= bound) return st;
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
    if (close_lsq(blended, false, w, &trial, &g, NULL, poll, NULL) != KM_OK) break;
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

km_status km_morph_frame(const km_morph *m, double t, km_curve *out,
                         km_frame_metrics *metrics, km_signature *sig_out,
                         km_error *err) {
  return frame_impl(m, t, NULL, out, metrics, sig_out, err);
}

km_status km_morph_frame_until(const km_morph *m, double t,
                               const km_stop *stop, km_curve *out,
                               km_frame_metrics *metrics,
                               km_signature *sig_out, km_error *err) {
  km__poll poll;
  km__poll_init(&poll, stop);
  return frame_impl(m, t, &poll, out, metrics, sig_out, err);
}

static km_status frame_impl(const km_morph *m, double t, km__poll *poll,
                            km_curve *out, km_frame_metrics *metrics,
                            km_signature *sig_out, km_error *err) {
  if (!(t >= 0.0 && t <= 1.0))
    return km__fail(err, KM_ERANGE, KM_FIELD_TIMES, -1, t,
                    "time %g is outside [0, 1]", t);
  if (m->opt.method == KM_METHOD_LINEAR)
    return linear_frame(m, t, out, metrics, sig_out, poll, err);
  km_closure how = m->opt.closure == KM_CLOSURE_AUTO ? KM_CLOSURE_LSQ : m->opt.closure;
  if (m->plan && !metrics && !sig_out)
    return planned_frame(m, t, how, poll, out, err);
  km_signature blended, closed;
  km_signature_init(&blended);
  km_signature_init(&closed);
  km_curve f, placed;
  km_curve_init(&f);
  km_curve_init(&placed);
  const km_signature *use = &blended;
  double gap = 0.0, bound = 0.0;
  km_status st = blend_signature(m, t, &blended, err);
  /* the blend is linear in the pieces: a few units each */
  if (!st && km__poll_stop(poll, 4 * (long)blended.kappa.n))
    st = km__stopped(err);
  if (st) goto done;
  if (m->closed && how == KM_CLOSURE_LSQ) {
    /* close_lsq measures the gap itself (its first residual) */
    st = close_within_bound(m, &blended, &closed, &gap, poll, err);
    if (st) goto done;
    use = &closed;
  } else if (m->closed) {
    double end[2];
    st = km_signature_point(&blended, blended.length, end, NULL);
    if (st) goto done;
    gap = hypot(end[0] - blended.start[0], end[1] - blended.start[1]);
  }
  st = km__reconstruct(use, m->opt.degree, 0.9 * m->tol, m->opt.max_points,
                       poll, &f, &bound, NULL, err);
  if (st) goto done;
  if (m->closed && !f.closed && how != KM_CLOSURE_NONE && how != KM_CLOSURE_LSQ)
    close_polygon(&f, how);
  else if (m->closed && !f.closed && how == KM_CLOSURE_LSQ)
    close_polygon(&f, KM_CLOSURE_C0); /* residual below rounding */
  double rot, T[2];
  placement(m, t, &f, use->length, &rot, T);
  st = km_curve_transform(&placed, &f, rot, T[0], T[1], err);
  if (st) goto done;
  placed.closed = f.closed;
  if (metrics) {
    metrics->length = use->length;
    metrics->max_abs_kappa = km_signature_max_abs_kappa(use);
    metrics->bending_energy = km_signature_bending_energy(use);
    metrics->self_intersections = km__self_intersections(&placed, m->tol, poll);
    metrics->closure_gap = m->closed ? gap : 0.0;
    if (poll && poll->stopped) {
      st = km__stopped(err);
      goto done;
    }
  }
  if (sig_out) {
    double cr = cos(rot), sr = sin(rot);
    double start[2] = {cr * use->start[0] - sr * use->start[1] + T[0],
                       sr * use->start[0] + cr * use->start[1] + T[1]};
    st = km_signature_create(sig_out, use->length, start, use->angle + rot,
                             &use->kappa, use->corners, use->ncorners,
                             use->closed, err);
    if (st) goto done;
  }
  *out = placed;
  km_curve_init(&placed);
done:
  km_signature_free(&blended);
  km_signature_free(&closed);
  km_curve_free(&f);
  km_curve_free(&placed);
  return st;
}

/* The frame's closed signature as frame_impl makes it, without the curve
 * (the blend and the closure of the general path). */
static km_status frame_signature(const km_morph *m, double t, km__poll *poll,
                                 km_signature *out, km_error *err) {
  km_closure how = m->opt.closure == KM_CLOSURE_AUTO ? KM_CLOSURE_LSQ : m->opt.closure;
  km_signature blended;
  km_signature_init(&blended);
  km_status st = blend_signature(m, t, &blended, err);
  if (!st && km__poll_stop(poll, 4 * (long)blended.kappa.n)) st = km__stopped(err);
  if (!st && m->closed && how == KM_CLOSURE_LSQ) {
    double gap;
    st = close_within_bound(m, &blended, out, &gap, poll, err);
    km_signature_free(&blended);
    return st;
  }
  if (!st) {
    *out = blended;
    return KM_OK;
  }
  km_signature_free(&blended);
  return st;
}

km_status km_morph_frame_points(const km_morph *m, double t,
                                km_frame_parts parts, const km_stop *stop,
                                size_t *points, km_error *err) {
  if (!(t >= 0.0 && t <= 1.0))
    return km__fail(err, KM_ERANGE, KM_FIELD_TIMES, -1, t,
                    "time %g is outside [0, 1]", t);
  if (m->opt.method == KM_METHOD_LINEAR) {
    *points = m->lin[0].n;
    return KM_OK;
  }
  if (m->plan && parts == KM_FRAME_CURVE) {
    *points = km__frame_plan_points(m->plan);
    return KM_OK;
  }
  km__poll poll;
  km__poll_init(&poll, stop);
  km_signature sig;
  km_signature_init(&sig);
  size_t n = 0;
  km_status st = frame_signature(m, t, &poll, &sig, err);
  if (!st)
    st = km__reconstruct(&sig, m->opt.degree, 0.9 * m->tol, m->opt.max_points,
                         &poll, NULL, NULL, &n, err);
  km_signature_free(&sig);
  if (!st) *points = n;
  return st;
}
