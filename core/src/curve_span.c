/* curve_span.c - one knot span of a curve in Bezier form: blossoming,
 * evaluation of position and derivative, the rounding of its speed, and
 * its arc length by quadrature that does not step over a boundary layer.
 */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "kernels.h"
#include "km/limits.h"

/* Bezier form of one span by blossoming the homogeneous control points:
 * b_k = f(a^(p-k), b^k). */
void km__bspan_make(km__bspan *sp, const km_curve *c, size_t i) {
  int p = c->degree;
  const double *U = c->knots;
  double a = U[i], b = U[i + 1];
  sp->degree = p;
  sp->a = a;
  sp->b = b;
  sp->rational = c->w != NULL;
  for (int k = 0; k <= p; k++) {
    double d[KM__BSPAN_MAX][3];
    for (int j = 0; j <= p; j++) {
      size_t g = i - (size_t)p + (size_t)j;
      double w = c->w ? c->w[g] : 1.0;
      d[j][0] = c->cp[2 * g] * w;
      d[j][1] = c->cp[2 * g + 1] * w;
      d[j][2] = w;
    }
    for (int r = 1; r <= p; r++) {
      double u = r <= p - k ? a : b;
      for (int j = p; j >= r; j--) {
        double lo = U[i - (size_t)p + (size_t)j];
        double hi = U[i + 1 + (size_t)j - (size_t)r];
        double al = (u - lo) / (hi - lo);
        for (int q = 0; q < 3; q++)
          d[j][q] = (1.0 - al) * d[j - 1][q] + al * d[j][q];
      }
    }
    for (int q = 0; q < 3; q++) sp->h[k][q] = d[p][q];
  }
}

/* de Casteljau on the homogeneous points of a rational span down to the
 * last step's two points, d[0] and d[1] (x w, y w, w) */
static void homogeneous_to_last_step(const km__bspan *sp, double u,
                                     double d[][3]) {
  int p = sp->degree;
  double v = 1.0 - u;
  memcpy(d, sp->h, sizeof(double) * 3 * (size_t)(p + 1));
  for (int r = 1; r < p; r++)
    for (int j = 0; j <= p - r; j++) {
      d[j][0] = v * d[j][0] + u * d[j + 1][0];
      d[j][1] = v * d[j][1] + u * d[j + 1][1];
      d[j][2] = v * d[j][2] + u * d[j + 1][2];
    }
}

/* km__bspan_eval_u, and in *wf (if not NULL) the factor by which the
 * rounding of the points reaches the derivative beyond its polynomial
 * share (see km__bspan_eval) */
static void eval_u(const km__bspan *sp, double u, double pos[2],
                   double der_u[2], double *wf) {
  int p = sp->degree;
  double v = 1.0 - u;
  if (wf) *wf = 1.0;
  if (!sp->rational && p == 3) {
    /* cubics (every SVG curve): the same de Casteljau steps, unrolled */
    for (int q = 0; q < 2; q++) {
      double a = v * sp->h[0][q] + u * sp->h[1][q];
      double b = v * sp->h[1][q] + u * sp->h[2][q];
      double c = v * sp->h[2][q] + u * sp->h[3][q];
      double d = v * a + u * b, e = v * b + u * c;
      pos[q] = v * d + u * e;
      der_u[q] = 3.0 * (e - d);
    }
    return;
  }
  if (!sp->rational) {
    /* weights 1: Horner in s = u / (1 - u), or its reciprocal past the
     * middle so that s <= 1, on the control points and on the legs (the
     * hodograph): O(p) instead of de Casteljau's O(p^2), with the same
     * error bound (see km__bern_eval), and the derivative from the legs'
     * differences keeps its digits far from the origin */
    const double *bp = km__binomial[p], *bq = km__binomial[p - 1];
    for (int q = 0; q < 2; q++) {
      double a, b, f = 1.0;
      if (u <= 0.5) {
        double s = u / v;
        a = sp->h[p][q];
        b = sp->h[p][q] - sp->h[p - 1][q];
        for (int j = p - 1; j >= 0; j--) {
          a = a * s + sp->h[j][q] * bp[j];
          if (j < p - 1) b = b * s + (sp->h[j + 1][q] - sp->h[j][q]) * bq[j];
        }
        for (int j = 1; j < p; j++) f *= v;
        pos[q] = a * f * v;
      } else {
        double s = v / u;
        a = sp->h[0][q];
        b = sp->h[1][q] - sp->h[0][q];
        for (int j = 1; j <= p; j++) {
          a = a * s + sp->h[j][q] * bp[j];
          if (j < p) b = b * s + (sp->h[j + 1][q] - sp->h[j][q]) * bq[j];
        }
        for (int j = 1; j < p; j++) f *= u;
        pos[q] = a * f * u;
      }
      der_u[q] = p * b * f;
    }
    return;
  }
  double d[KM__BSPAN_MAX][3];
  homogeneous_to_last_step(sp, u, d);
  /* The last step joins two points P0, P1 of weights w0, w1: C = (v w0 P0
   * + u w1 P1) / w and C' = p w0 w1 / w^2 (P1 - P0), with w = v w0 + u w1.
   * Unlike the quotient rule (H' - C w') / w, no large terms cancel, so
   * the direction keeps its digits whatever the weights. */
  double w0 = d[0][2], w1 = d[1][2], w = v * w0 + u * w1;
  double f = p * (w0 / w) * (w1 / w);
  for (int q = 0; q < 2; q++) {
    pos[q] = (v * d[0][q] + u * d[1][q]) / w;
    der_u[q] = f * (d[1][q] / w1 - d[0][q] / w0);
  }
  if (wf) *wf = f / p;
}

void km__bspan_eval_u(const km__bspan *sp, double u, double pos[2],
                      double der_u[2]) {
  eval_u(sp, u, pos, der_u, NULL);
}

void km__bspan_eval(const km__bspan *sp, double t, double pos[2], double der[2],
                    double *wf) {
  double len = sp->b - sp->a;
  eval_u(sp, (t - sp->a) / len, pos, der, wf);
  der[0] /= len;
  der[1] /= len;
}

/* The legs h[j+1] - h[j] of a polynomial span: its hodograph over p. */
static void span_legs(const km__bspan *sp, double e[KM__BSPAN_MAX][2]) {
  for (int j = 0; j < sp->degree; j++) {
    e[j][0] = sp->h[j + 1][0] - sp->h[j][0];
    e[j][1] = sp->h[j + 1][1] - sp->h[j][1];
  }
}

/* |dC/du| without weights from the hodograph, p times the Bezier curve of
 * the legs (span_legs), at a third of the cost of position and
 * derivative. The cubic's de Casteljau steps are written out: the same
 * operations in the same order as the loop, a third of its time in the
 * quadrature of a frame's length. */
static double polynomial_speed_u(int p, const double legs[KM__BSPAN_MAX][2],
                                 double u) {
  double v = 1.0 - u, dx, dy;
  if (p == 3) {
    double a0 = v * legs[0][0] + u * legs[1][0];
    double a1 = v * legs[0][1] + u * legs[1][1];
    double b0 = v * legs[1][0] + u * legs[2][0];
    double b1 = v * legs[1][1] + u * legs[2][1];
    dx = p * (v * a0 + u * b0);
    dy = p * (v * a1 + u * b1);
  } else {
    double e[KM__BSPAN_MAX][2];
    memcpy(e, legs, (size_t)p * sizeof e[0]);
    for (int r = 1; r < p; r++)
      for (int j = 0; j < p - r; j++) {
        e[j][0] = v * e[j][0] + u * e[j + 1][0];
        e[j][1] = v * e[j][1] + u * e[j + 1][1];
      }
    dx = p * e[0][0];
    dy = p * e[0][1];
  }
  return sqrt(dx * dx + dy * dy);
}

/* |dC/du| of a rational span by km__bspan_eval_u's steps (the same
 * digits) without the position, and in *f the weight factor p w0 w1 / w^2
 * of its last step, by which the rounding of the points is multiplied. */
static double rational_speed_u(const km__bspan *sp, double u, double *f) {
  int p = sp->degree;
  double v = 1.0 - u, d[KM__BSPAN_MAX][3];
  homogeneous_to_last_step(sp, u, d);
  double w0 = d[0][2], w1 = d[1][2], w = v * w0 + u * w1;
  *f = p * (w0 / w) * (w1 / w);
  double dx = *f * (d[1][0] / w1 - d[0][0] / w0);
  double dy = *f * (d[1][1] / w1 - d[0][1] / w0);
  return sqrt(dx * dx + dy * dy);
}

double km__bspan_noise(const km__bspan *sp) {
  double M = 0.0;
  for (int q = 0; q <= sp->degree; q++)
    M = fmax(M, fmax(fabs(sp->h[q][0]), fabs(sp->h[q][1])) /
                    fmax(sp->h[q][2], 1e-300));
  return 8.0 * DBL_EPSILON * sp->degree * M;
}

/* A span's speed is computed from points of magnitude up to M: its
 * rounding, 8 eps M (unit) times the weight factor f of the last de
 * Casteljau step (rational_speed_u) - p without weights, but up to p times
 * the ratio of the extreme weights where a small weight meets a large one.
 * There f is large only over a stretch of u about as narrow as that ratio
 * is large (the curve leaves such a point in a boundary layer of the
 * parameter): the rounding is local, and so is the precision a length can
 * have. */
typedef struct span_quad {
  const km__bspan *sp;
  double unit;
  long evals;
  double legs[KM__BSPAN_MAX][2]; /* a polynomial span's (span_legs) */
} span_quad;

/* The 16-point rule on [a, b], and in *noise the rounding its sum may
 * carry: the largest rounding of the speed at its nodes over the width. */
static double span_gl16(span_quad *q, double a, double b, double *noise) {
  const km__bspan *sp = q->sp;
  double m = 0.5 * (a + b), h = 0.5 * (b - a), sum = 0.0, fmaxn;
  q->evals += 16;
  if (!sp->rational) {
    for (int k = 0; k < 16; k++)
      sum += km__gl16_w[k] *
             polynomial_speed_u(sp->degree, q->legs, m + h * km__gl16_x[k]);
    fmaxn = sp->degree;
  } else {
    /* Where small and large weights meet, the speed also varies so fast
     * (by a factor e per 1e-3 of u near the end of a rational cubic at
     * 1e15 whose end weight is 1e-4 of its neighbour's) that rounding the
     * nodes to doubles, by eps |u|, moves it by 1e-13 of itself: more than
     * the points' rounding, and as local. Bisection toward such a point
     * found halves and whole differing by that at every depth, and the
     * length of a part of the span came out NaN. The slope comes from
     * neighbouring nodes. */
    double v[16], slope = 0.0;
    fmaxn = 0.0;
    for (int k = 0; k < 16; k++) {
      double f;
      v[k] = rational_speed_u(sp, m + h * km__gl16_x[k], &f);
      sum += km__gl16_w[k] * v[k];
      fmaxn = fmax(fmaxn, f);
    }
    for (int k = 1; k < 16; k++)
      slope = fmax(slope, fabs(v[k] - v[k - 1]) /
                              (h * (km__gl16_x[k - 1] - km__gl16_x[k])));
    *noise = (q->unit * fmaxn + slope * DBL_EPSILON * fmax(fabs(a), fabs(b))) *
             (b - a);
    return sum * h;
  }
  *noise = q->unit * fmaxn * (b - a);
  return sum * h;
}

/* Adaptive quadrature as integrate_rec (the 16-point rule on [a, b]
 * against its halves, bisecting where they differ by more than the
 * tolerance), except that a difference within the rounding the rules
 * carry there is accepted: it cannot be refined, and it is local. Asking
 * the whole span instead for the rounding of its worst point (the ratio
 * of its extreme weights times the span's noise, wherever the uniform
 * request fails) lets the first rule through unrefined: both it and its
 * halves step over a boundary layer narrower than their nodes' spacing (a
 * degree-9 span at 1e6 whose weights jump from 0.1 to 100 at a
 * degenerate leg leaves its first point within about 1e-4 in u) and
 * agreed on a length 9.2e-6 (2e-5 of it) too long at a tolerance of
 * 1e-6, where the rounding over the span integrates to about 1e-8. */
static double span_rec(span_quad *q, double a, double b, double whole,
                       double whole_noise, double abs_tol, int depth,
                       long *budget) {
  double m = 0.5 * (a + b), nl, nr;
  double l = span_gl16(q, a, m, &nl), r = span_gl16(q, m, b, &nr);
  double sum = l + r;
  double rounding =
      fmax(64 * DBL_EPSILON * fabs(sum), fmax(whole_noise, nl + nr));
  /* nor where [a, b] is so narrow beside its position that the nodes are
   * rounded by a part in a thousand: halving it only moves them */
  if (fabs(sum - whole) <= fmax(abs_tol, rounding) ||
      b - a <= 1024 * DBL_EPSILON * fmax(fabs(a), fabs(b)))
    return sum;
  if (depth >= 40 || --*budget <= 0) return NAN; /* not to the precision */
  return span_rec(q, a, m, l, nl, 0.5 * abs_tol, depth + 1, budget) +
         span_rec(q, m, b, r, nr, 0.5 * abs_tol, depth + 1, budget);
}

/* ---- where the quadrature must not step over a feature ----------------
 *
 * Adaptive quadrature judges a length by comparing rules, and two rules
 * agree on a wrong value when the speed has a feature narrower than the
 * spacing of both rules' nodes. Two such features are found from the
 * span's Bernstein coefficients rather than by sampling:
 *   - A hairpin: C' passes close by zero, and |C'| has a V-shaped dip (the
 *     tangent turns by nearly pi within it). Where no node lands in the
 *     dip, every rule integrates the smooth branch on one side across it
 *     and the run into the tip and back is lost: an open cubic near 1e12
 *     whose span turns back 5e-4 of the span from its start was measured
 *     2,503 too short (1.6e-6 of it) at every depth, its nodes all beyond
 *     the tip. dC/du is N(u) / w(u)^2 with N a polynomial in Bernstein form
 *     (degree p - 1 without weights; 2p - 1 with them, N = A' w - A w' for
 *     the homogeneous numerator A taken about the span's first point,
 *     whose large coordinates would otherwise cancel). Where N's
 *     coefficients lie in a cone of half-angle 60 degrees, |C'| is at
 *     least half of a polynomial with non-negative coefficients over w^2
 *     and has no dip; elsewhere the interval is halved (de Casteljau)
 *     until its parts pass, and where a part fails whose halves pass,
 *     their common end is a break. A smooth turn (a semicircle) passes
 *     after a halving or two, and the first three halvings are wide
 *     enough for the rules' nodes to sample what lies in them; only a
 *     real dip goes deep. Split there, the dip's wrong branch (beyond the
 *     point where the tangent has turned through 60 degrees from its
 *     least speed) is some |C'|min / |C''| wide and costs about
 *     |C'|min^2 / |C''|: second order in the least speed.
 *   - A boundary layer: where a small weight meets a large one, w has a
 *     zero just outside the interval, and the curve leaves the small
 *     weight's point within a part of u about as narrow as their ratio is
 *     large: a degree-9 segment at 1e6 whose weights jump from 0.1 to 300
 *     at a degenerate leg was measured 7.7e-7 short (its nodes all beyond
 *     the layer). Where w's coefficients on a part differ by more than a
 *     factor 4, w's zero is at least about as far from the part as the
 *     part is wide, and the rules converge honestly; elsewhere the part is
 *     halved and every halving is a break, so parts shrink geometrically
 *     toward the layer. */
#define HODO_MAX (2 * KM__BSPAN_MAX)
#define PART_VISITS 4096
#define BREAKS_MAX 256

typedef struct part_search {
  double floor; /* N's coefficients below this are rounding: no direction */
  double tiny;  /* a part this short in length is not halved further */
  int dn, dw;   /* the degrees of N and of w */
  int visits;
  size_t n;
  double out[BREAKS_MAX];
} part_search;

/* N (x, y) and w in Bernstein form on a part of the span */
typedef struct part {
  double x[HODO_MAX], y[HODO_MAX], w[KM__BSPAN_MAX];
} part;

/* Whether N's coefficients above the floor lie within 60 degrees of their
 * sum (any axis serves the bound; this one needs no square roots), and in
 * *big the largest magnitude. */
static bool hodo_in_cone(const part *pt, int d, double floor, double *big) {
  double ex = 0.0, ey = 0.0, n2[HODO_MAX], big2 = 0.0, f2 = floor * floor;
  for (int j = 0; j <= d; j++) {
    n2[j] = pt->x[j] * pt->x[j] + pt->y[j] * pt->y[j];
    big2 = fmax(big2, n2[j]);
    if (n2[j] > f2) {
      ex += pt->x[j];
      ey += pt->y[j];
    }
  }
  *big = sqrt(big2);
  double e2 = ex * ex + ey * ey;
  for (int j = 0; j <= d; j++) {
    if (!(n2[j] > f2)) continue;
    double dot = pt->x[j] * ex + pt->y[j] * ey;
    if (!(dot > 0.0 && dot * dot >= 0.25 * n2[j] * e2)) return false;
  }
  return true;
}

static void restrict_part(const part_search *ps, const part *pt, bool weights,
                          double u0, double u1, part *out) {
  km__bern_restrict(pt->x, ps->dn, u0, u1, out->x);
  km__bern_restrict(pt->y, ps->dn, u0, u1, out->y);
  if (weights) km__bern_restrict(pt->w, ps->dw, u0, u1, out->w);
}

static void add_break(part_search *ps, double u) {
  if (ps->n < BREAKS_MAX) ps->out[ps->n++] = u;
}

/* The part [a, b] (weights: whether w counts): true where it needs no
 * break inside */
static bool find_breaks(part_search *ps, const part *pt, bool weights, double a,
                        double b, int depth) {
  double big, wlo = 1.0, whi = 1.0;
  if (weights) {
    wlo = whi = pt->w[0];
    for (int j = 1; j <= ps->dw; j++) {
      wlo = fmin(wlo, pt->w[j]);
      whi = fmax(whi, pt->w[j]);
    }
  }
  bool cone = hodo_in_cone(pt, ps->dn, ps->floor, &big);
  bool layer = whi > 4.0 * wlo;
  if ((cone && !layer) || ++ps->visits > PART_VISITS) return true;
  double m = 0.5 * (a + b);
  if ((b - a) * big / (wlo * wlo) <= ps->tiny || depth >= 60 ||
      b - a <= 1024 * DBL_EPSILON * fmax(fabs(a), fabs(b))) {
    if (depth >= 3 || layer) add_break(ps, m);
    return false;
  }
  part half;
  size_t before = ps->n;
  restrict_part(ps, pt, weights, 0.0, 0.5, &half);
  bool lp = find_breaks(ps, &half, weights, a, m, depth + 1);
  restrict_part(ps, pt, weights, 0.5, 1.0, &half);
  bool rp = find_breaks(ps, &half, weights, m, b, depth + 1);
  if (layer || (lp && rp && depth >= 3)) {
    /* in order: the left half's breaks stand before the right half's */
    size_t k = before;
    while (k < ps->n && ps->out[k] < m) k++;
    if (ps->n < BREAKS_MAX) {
      memmove(ps->out + k + 1, ps->out + k, (ps->n - k) * sizeof(double));
      ps->out[k] = m;
      ps->n++;
    }
  }
  return false;
}

/* The breaks of (u0, u1), in order, down to parts no longer than tiny,
 * where N's coefficients below floor are rounding: ps->out[0 .. ps->n). */
static void span_breaks(const km__bspan *sp, double u0, double u1, double floor,
                        double tiny, part_search *ps) {
  int p = sp->degree;
  part whole, pt;
  ps->n = 0;
  ps->visits = 0;
  for (int k = 0; k <= p; k++) whole.w[k] = sp->h[k][2];
  if (!sp->rational) {
    ps->dn = p - 1;
    for (int j = 0; j < p; j++) {
      whole.x[j] = p * (sp->h[j + 1][0] - sp->h[j][0]);
      whole.y[j] = p * (sp->h[j + 1][1] - sp->h[j][1]);
    }
  } else {
    /* N_k = sum over i + j = k of C(p-1, i) C(p, j) / C(2p-1, k)
     * (dA_i w_j - dw_i A_j), the product rule of Bernstein forms */
    const double *w = whole.w;
    double A[KM__BSPAN_MAX][2];
    double ox = sp->h[0][0] / sp->h[0][2], oy = sp->h[0][1] / sp->h[0][2];
    for (int j = 0; j <= p; j++) {
      A[j][0] = sp->h[j][0] - w[j] * ox;
      A[j][1] = sp->h[j][1] - w[j] * oy;
    }
    int d = ps->dn = 2 * p - 1;
    for (int k = 0; k <= d; k++) whole.x[k] = whole.y[k] = 0.0;
    for (int i = 0; i < p; i++) {
      double dax = p * (A[i + 1][0] - A[i][0]),
             day = p * (A[i + 1][1] - A[i][1]);
      double dw = p * (w[i + 1] - w[i]);
      for (int j = 0; j <= p; j++) {
        double f = km__binomial[p - 1][i] * km__binomial[p][j] /
                   km__binomial[d][i + j];
        whole.x[i + j] += f * (dax * w[j] - dw * A[j][0]);
        whole.y[i + j] += f * (day * w[j] - dw * A[j][1]);
      }
    }
  }
  ps->floor = floor;
  ps->tiny = tiny;
  ps->dw = p;
  restrict_part(ps, &whole, sp->rational, u0, u1, &pt);
  find_breaks(ps, &pt, sp->rational, u0, u1, 0);
}

double km__bspan_length_counted(const km__bspan *sp, double u0, double u1,
                                double abs_tol, long *evals) {
  if (!(u1 > u0)) return 0.0;
  /* Asking for more than the span's rounding (km__bspan_noise) over the
   * width only refines into noise (a short span far from the origin). A
   * rational span is granted up to four times that at once where its
   * weights vary by more than a factor 4 - a few units of the weight
   * factor over the span - and beyond that only where the rounding is
   * locally larger (span_rec). */
  double wmax = 0.0, wmin = INFINITY;
  for (int k = 0; k <= sp->degree; k++) {
    wmax = fmax(wmax, sp->h[k][2]);
    wmin = fmin(wmin, sp->h[k][2]);
  }
  double ratio = sp->rational ? wmax / wmin : 1.0;
  double noise = km__bspan_noise(sp);
  span_quad q = {sp, noise / sp->degree, 0, {{0}}};
  if (!sp->rational) span_legs(sp, q.legs);
  double tol = fmax(abs_tol, noise * (u1 - u0) * fmin(ratio, 4.0));
  /* the rules must not step over a hairpin's tip or a boundary layer:
   * parts end there */
  part_search ps;
  /* N's rounding: the points' (noise, over p) times p and the weights'
   * scale twice */
  span_breaks(sp, u0, u1, noise * (sp->rational ? wmax * wmax : 1.0),
              0.0625 * tol, &ps);
  double len = 0.0, a = u0;
  long budget = 256 + 8 * (long)ps.n;
  for (size_t i = 0; i <= ps.n; i++) {
    double b = i < ps.n ? ps.out[i] : u1, wn;
    if (!(b > a)) continue;
    double whole = span_gl16(&q, a, b, &wn);
    len +=
        span_rec(&q, a, b, whole, wn, tol * ((b - a) / (u1 - u0)), 0, &budget);
    a = b;
  }
  if (evals) *evals += q.evals;
  return len;
}

double km__bspan_length(const km__bspan *sp, double u0, double u1,
                        double abs_tol) {
  return km__bspan_length_counted(sp, u0, u1, abs_tol, NULL);
}
