/* curve_length_rel.c - arc length to a relative tolerance with a proven
 * error bound: the length printed beside every curve of an answer.
 *
 * DESIGN. km_curve_length asks each span for 1e-15 of the control
 * polygon's length and judges it by comparing Gauss rules: the precision
 * the morph's own arithmetic is built on, three 16-point rules and the
 * span's Bezier form a span. A printed curve's length is promised to
 * 1e-12 relative, and printed curves are polynomial cubics. On a cubic
 * span the velocity in the span's variable u is a quadratic D(u), taken
 * here from the hodograph's B-spline (differences of control points, so a
 * span far from the origin keeps its digits), and the speed is
 *     |D| = sqrt(F(u) G(u)),  F = Dx + i Dy,  G = Dx - i Dy,
 * a complex quadratic times its conjugate: the speed is analytic in the
 * complex plane except at F's two roots and their conjugates. For a
 * function analytic in the open Bernstein ellipse E_rho of [-1, 1] (foci
 * +-1, semi-axes summing to rho) and bounded there by M, the N-point
 * Gauss-Legendre rule errs by at most
 *     64 M rho^(2 - 2N) / (15 (rho^2 - 1))
 * (Trefethen, Approximation Theory and Approximation Practice, theorem
 * 19.3, whose n + 1 points are N here). E_rho is taken a tenth of the way
 * inside the ellipse through the nearest root (rounding of the roots
 * cannot reach that far where the bound can pass), where sqrt(F G) has an
 * analytic branch that is the speed on the interval, and |F|, |G| <=
 * sum |e_k| A^k for the coefficients e_k of D about the piece's middle
 * and A the ellipse's semi-major axis. A piece is accepted when that
 * bound is within rel_tol / 4 of the rule's value: one rule a piece and
 * no comparison of rules (two rules can agree on a wrong value). Where the
 * bound does not pass, a root lies near the piece (the speed nearly
 * vanishes: a hairpin) and the piece is halved; past a depth a piece's
 * error is bounded by its width times the speed's bound. The bounds are
 * summed, and a curve whose summed bound is not within rel_tol / 2 of its
 * length, or that is not a polynomial cubic, is measured by
 * km_curve_length instead.
 *
 * Rounding: D's Bezier points carry a few ulps of the largest of them,
 * and so does the speed at a node (the coefficients about a piece's
 * middle are at most 4 times D's points); a quadratic's integral of |D|
 * over [0, 1] is at least a ninth of its largest Bezier point's
 * magnitude over 3, so the span's length carries some 30 ulps of itself,
 * below 1e-14; the sum over pieces is compensated. Below 1e-13 a
 * rel_tol is not met by this argument: it is raised to 1e-13.
 */
#include <math.h>
#include <stdbool.h>
#include <stddef.h>

#include "internal.h"
#include "kernels.h"

#define REL_TOL_MIN 1e-13
#define RHO_MAX 1e3  /* no root nearer: the speed is all but constant */
#define DEPTH_MAX 48 /* a piece 2^-48 of its span wide */
#define PIECES_MAX 512

/* A complex number as two doubles: no Annex G semantics needed here. */
typedef struct cplx {
  double re, im;
} cplx;

/* One cubic span: its velocity's Bernstein points in u and the roots of
 * F = Dx + i Dy in u */
typedef struct cubic_span {
  double d[3][2];
  double c1[2], c2[2]; /* D(u) = D(0) + c1 u + c2 u^2 */
  cplx root[2];        /* found when first needed */
  int nroots;
  bool rooted;
  double tau; /* the relative bound a piece must meet */
  int pieces; /* left of PIECES_MAX */
} cubic_span;

typedef struct length_sum {
  double sum, comp, err;
} length_sum;

static void sum_add(length_sum *s, double x, double err) {
  double t = s->sum + x;
  /* Neumaier's compensated sum: the total carries a few ulps whatever the
   * number of pieces */
  if (fabs(s->sum) >= fabs(x))
    s->comp += (s->sum - t) + x;
  else
    s->comp += (x - t) + s->sum;
  s->sum = t;
  s->err += err;
}

static cplx csqrt_of(cplx z) {
  double r = sqrt(z.re * z.re + z.im * z.im);
  cplx s;
  if (r == 0.0) return (cplx){0.0, 0.0};
  if (z.re >= 0.0) {
    s.re = sqrt(0.5 * (r + z.re));
    s.im = z.im / (2.0 * s.re);
  } else {
    s.im = copysign(sqrt(0.5 * (r - z.re)), z.im);
    s.re = z.im / (2.0 * s.im);
  }
  return s;
}

static cplx cdiv(cplx a, cplx b) {
  double n = b.re * b.re + b.im * b.im;
  return (cplx){(a.re * b.re + a.im * b.im) / n,
                (a.im * b.re - a.re * b.im) / n};
}

/* The roots of g0 + g1 u + g2 u^2 that are finite (a leading coefficient
 * of zero has one or none), by the form that does not cancel. */
static int quadratic_roots(cplx g0, cplx g1, cplx g2, cplx out[2]) {
  if (g2.re == 0.0 && g2.im == 0.0) {
    if (g1.re == 0.0 && g1.im == 0.0) return 0;
    out[0] = cdiv((cplx){-g0.re, -g0.im}, g1);
    return 1;
  }
  cplx disc = {g1.re * g1.re - g1.im * g1.im -
                   4.0 * (g0.re * g2.re - g0.im * g2.im),
               2.0 * g1.re * g1.im - 4.0 * (g0.re * g2.im + g0.im * g2.re)};
  cplx s = csqrt_of(disc);
  if (g1.re * s.re + g1.im * s.im < 0.0) {
    s.re = -s.re;
    s.im = -s.im;
  }
  cplx q = {-0.5 * (g1.re + s.re), -0.5 * (g1.im + s.im)};
  if (q.re == 0.0 && q.im == 0.0) { /* g1 = 0 and g0 g2 = 0: g0 = 0 */
    out[0] = out[1] = (cplx){0.0, 0.0};
    return 2;
  }
  out[0] = cdiv(q, g2);
  out[1] = cdiv(g0, q);
  return 2;
}

/* Span i of a polynomial cubic (non-empty): its velocity in u from the
 * hodograph, a quadratic B-spline of points 3 (P[j+1] - P[j]) /
 * (U[j+4] - U[j+1]); on the span its Bezier points are blossoms whose
 * middle one is the hodograph's point i - 2 itself. Times the span's
 * width: no factor exceeds 1, so nothing overflows. */
static void cubic_span_make(cubic_span *cs, const km_curve *c, size_t i,
                            double tau) {
  const double *U = c->knots, *P = c->cp;
  double a = U[i], b = U[i + 1], w = b - a, q[3][2];
  for (int k = 0; k < 3; k++) {
    size_t j = i - 3 + (size_t)k;
    double f = 3.0 * (w / (U[j + 4] - U[j + 1]));
    q[k][0] = f * (P[2 * j + 2] - P[2 * j]);
    q[k][1] = f * (P[2 * j + 3] - P[2 * j + 1]);
  }
  double al0 = (a - U[i - 1]) / (b - U[i - 1]), al2 = w / (U[i + 2] - a);
  for (int x = 0; x < 2; x++) {
    cs->d[0][x] = q[0][x] + al0 * (q[1][x] - q[0][x]);
    cs->d[1][x] = q[1][x];
    cs->d[2][x] = q[1][x] + al2 * (q[2][x] - q[1][x]);
    cs->c1[x] = 2.0 * (cs->d[1][x] - cs->d[0][x]);
    cs->c2[x] = cs->d[0][x] - 2.0 * cs->d[1][x] + cs->d[2][x];
  }
  cs->rooted = false;
  cs->tau = tau;
  cs->pieces = PIECES_MAX;
}

/* h times the N-point rule (N = 8 or 16) of |e0 + e1 x + e2 x^2| over
 * x in [-1, 1]; nodes in symmetric pairs */
static double piece_rule(const double e[3][2], double h, int N) {
  const double *X = N == 8 ? km__gl8_x : km__gl16_x;
  const double *W = N == 8 ? km__gl8_w : km__gl16_w;
  double sum = 0.0;
  for (int k = 0; k < N / 2; k++) {
    double x = X[k], x2 = x * x;
    double ax = e[0][0] + e[2][0] * x2, ay = e[0][1] + e[2][1] * x2;
    double bx = e[1][0] * x, by = e[1][1] * x;
    double p = (ax + bx) * (ax + bx) + (ay + by) * (ay + by);
    double m = (ax - bx) * (ax - bx) + (ay - by) * (ay - by);
    sum += W[k] * (sqrt(p) + sqrt(m));
  }
  return sum * h;
}

/* |(x, y)|: not hypot, whose care costs a third of a piece; the speed's
 * coefficients stay below 1e17 (coordinates <= KM_MAX_COORDINATE), and
 * a root's distance that overflows is only farther than RHO_MAX */
static double norm2(double x, double y) {
  return sqrt(x * x + y * y);
}

/* rho of the Bernstein ellipse of [-1, 1] through z */
static double ellipse_rho(double zr, double zi) {
  double a = 0.5 * (norm2(zr - 1.0, zi) + norm2(zr + 1.0, zi));
  if (!(a > 1.0)) return 1.0;
  return a + sqrt(a * a - 1.0);
}

/* The error bounds of the 8- and 16-point rules times h on E_rho where
 * |speed| <= M: 64 M rho^(2 - 2N) / (15 (rho^2 - 1)); infinite unless
 * rho > 1 */
static void gauss_bounds(double h, double M, double rho, double b[2]) {
  if (!(rho > 1.0)) {
    b[0] = b[1] = INFINITY;
    return;
  }
  if (rho > RHO_MAX) rho = RHO_MAX;
  double r2 = rho * rho, r6 = r2 * r2 * r2, r14 = r6 * r6 * r2;
  double k = 64.0 / 15.0 * h * M / (r2 - 1.0);
  b[0] = k / r14;
  b[1] = k / (r14 * r14 * r2);
}

/* The same on the ellipse a tenth inside the nearest root of F or its
 * conjugate's (rounding moves a root by far less where a bound can pass),
 * where |F| and |G| are at most sum |e_k| A^k on the ellipse's semi-major
 * axis A */
static void root_bounds(const cubic_span *cs, double m, double h,
                        const double n[3], double b[2]) {
  double rho = RHO_MAX;
  for (int k = 0; k < cs->nroots; k++) {
    double zr = (cs->root[k].re - m) / h, zi = cs->root[k].im / h;
    double r = ellipse_rho(zr, zi);
    if (r < rho) rho = r;
  }
  rho = 1.0 + 0.9 * (rho - 1.0);
  double A = 0.5 * (rho + 1.0 / rho);
  gauss_bounds(h, n[0] + A * (n[1] + A * n[2]), rho, b);
}

/* The same from the coefficients alone (no roots): where |e1| A + |e2|
 * A^2 <= |e0| / 2, F and G have no root in the disc |z| < A (the constant
 * term dominates), nor in the ellipse of semi-major axis A inside it, and
 * there |F|, |G| <= 3 |e0| / 2. Passes for every span whose speed varies
 * by a few tens of percent. */
static void disc_bounds(double h, const double n[3], double b[2]) {
  double A = n[0] / (n[1] + sqrt(n[1] * n[1] + 2.0 * n[2] * n[0]));
  gauss_bounds(h, 1.5 * n[0], A + sqrt(fmax(A * A - 1.0, 0.0)), b);
}

/* The length of [ua, ub] of the span into *s with its error bound. */
static void piece_length(cubic_span *cs, double ua, double ub, int depth,
                         length_sum *s) {
  double m = 0.5 * (ua + ub), h = 0.5 * (ub - ua), v = 1.0 - m, e[3][2];
  for (int x = 0; x < 2; x++) {
    e[0][x] =
        v * v * cs->d[0][x] + 2.0 * m * v * cs->d[1][x] + m * m * cs->d[2][x];
    e[1][x] = h * (cs->c1[x] + 2.0 * m * cs->c2[x]);
    e[2][x] = h * h * cs->c2[x];
  }
  double n[3], b[2], r[2], tau = cs->tau;
  for (int k = 0; k < 3; k++) n[k] = norm2(e[k][0], e[k][1]);
  /* a lower bound of the length: the chord, the integral of D; an upper
   * bound of both the length and any rule's value */
  double chord =
      2.0 * h * norm2(e[0][0] + e[2][0] / 3.0, e[0][1] + e[2][1] / 3.0);
  double upper = 2.0 * h * (n[0] + n[1] + n[2]);
  disc_bounds(h, n, b);
  if (b[0] <= tau * chord) {
    sum_add(s, piece_rule(e, h, 8), b[0]);
    return;
  }
  if (!cs->rooted) {
    cs->nroots = quadratic_roots((cplx){cs->d[0][0], cs->d[0][1]},
                                 (cplx){cs->c1[0], cs->c1[1]},
                                 (cplx){cs->c2[0], cs->c2[1]}, cs->root);
    cs->rooted = true;
  }
  root_bounds(cs, m, h, n, r);
  if (r[0] < b[0]) b[0] = r[0];
  if (r[1] < b[1]) b[1] = r[1];
  if (b[0] <= tau * chord) {
    sum_add(s, piece_rule(e, h, 8), b[0]);
    return;
  }
  if (b[1] <= tau * upper) {
    double g = piece_rule(e, h, 16);
    if (b[1] * (1.0 + tau) <= tau * g) {
      sum_add(s, g, b[1]);
      return;
    }
  }
  if (depth >= DEPTH_MAX || (cs->pieces -= 2) < 0) {
    /* the rule's value and the length both lie in [0, upper] */
    sum_add(s, piece_rule(e, h, 16), upper < b[1] ? upper : b[1]);
    return;
  }
  piece_length(cs, ua, m, depth + 1, s);
  piece_length(cs, m, ub, depth + 1, s);
}

double km_curve_length_within(const km_curve *c, double rel_tol) {
  if (c->degree != 3 || c->w != NULL) return km_curve_length(c);
  if (!(rel_tol >= REL_TOL_MIN)) rel_tol = REL_TOL_MIN;
  length_sum s = {0.0, 0.0, 0.0};
  for (size_t i = 3; i < c->n; i++) {
    if (!(c->knots[i + 1] > c->knots[i])) continue;
    cubic_span cs;
    cubic_span_make(&cs, c, i, 0.25 * rel_tol);
    piece_length(&cs, 0.0, 1.0, 0, &s);
  }
  double L = s.sum + s.comp;
  if (!(s.err <= 0.5 * rel_tol * (L - s.err))) return km_curve_length(c);
  return L;
}
