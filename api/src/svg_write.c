/* svg_write.c - curves as SVG path data of cubic Beziers, exact where the
 * curve allows it and with a stated error bound where it does not.
 *
 * DESIGN. The curve is cut into its Bezier spans in homogeneous coordinates
 * (knot insertion). Polynomial spans of degree <= 3 are raised to cubics:
 * exact, so the only error is the printing of numbers. Rational spans and
 * spans of higher degree are replaced by cubic Hermite pieces (end points
 * and end derivatives of the span), halving the span until a rigorous bound
 * meets the tolerance: with the span N(u)/w(u) and the cubic H(u),
 *   C(u) - H(u) = (N(u) - w(u) H(u)) / w(u),
 * whose numerator is a polynomial of degree d + 3 in Bernstein form; the
 * largest of its coefficients over the smallest weight bounds the distance
 * at equal parameter, hence the distance between the traces. Numbers are
 * printed with the fewest digits that read back within a share of the
 * tolerance (num_print.c); the error committed by printing is measured,
 * not assumed, and added to the reported bound.
 */
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "km/alloc.h"
#include "km/limits.h"
#include "num_print.h"
#include "svg.h"

/* ---- string buffer ---------------------------------------------------- */

void api__svg_buf_init(api_svg_buf *b) {
  memset(b, 0, sizeof *b);
}

void api__svg_buf_free(api_svg_buf *b) {
  km__free(b->s);
  api__svg_buf_init(b);
}

static bool reserve(api_svg_buf *b, size_t extra) {
  if (b->failed) return false;
  if (b->len + extra + 1 <= b->cap) return true;
  size_t cap = b->cap ? b->cap : 256;
  while (cap < b->len + extra + 1) {
    if (cap > ((size_t)-1) / 2) {
      b->failed = true;
      return false;
    }
    cap *= 2;
  }
  char *s = km__realloc(b->s, cap);
  if (!s) {
    b->failed = true;
    return false;
  }
  b->s = s;
  b->cap = cap;
  return true;
}

char *api__svg_buf_room(api_svg_buf *b, size_t n) {
  return reserve(b, n) ? b->s + b->len : NULL;
}

void api__svg_buf_put_n(api_svg_buf *b, const char *str, size_t n) {
  if (!reserve(b, n)) return;
  memcpy(b->s + b->len, str, n);
  b->len += n;
  b->s[b->len] = '\0';
}

void api__svg_buf_put(api_svg_buf *b, const char *str) {
  size_t n = strlen(str);
  if (!reserve(b, n)) return;
  memcpy(b->s + b->len, str, n + 1);
  b->len += n;
}

void api__svg_buf_printf(api_svg_buf *b, const char *fmt, ...) {
  char small[256];
  va_list ap;
  va_start(ap, fmt);
  int n = vsnprintf(small, sizeof small, fmt, ap);
  va_end(ap);
  if (n < 0) {
    b->failed = true;
    return;
  }
  if ((size_t)n < sizeof small) {
    api__svg_buf_put(b, small);
    return;
  }
  if (!reserve(b, (size_t)n)) return;
  va_start(ap, fmt);
  vsnprintf(b->s + b->len, (size_t)n + 1, fmt, ap);
  va_end(ap);
  b->len += (size_t)n;
}

void api__svg_buf_escaped(api_svg_buf *b, const char *text) {
  for (const unsigned char *p = (const unsigned char *)text; p && *p; p++) {
    char one[2] = {(char)*p, '\0'};
    switch (*p) {
    case '&': api__svg_buf_put(b, "&amp;"); break;
    case '<': api__svg_buf_put(b, "&lt;"); break;
    case '>': api__svg_buf_put(b, "&gt;"); break;
    case '"': api__svg_buf_put(b, "&quot;"); break;
    case '\'': api__svg_buf_put(b, "&apos;"); break;
    default:
      /* XML 1.0 forbids most control characters, even escaped. */
      if (*p < 0x20 && *p != '\t' && *p != '\n') one[0] = ' ';
      api__svg_buf_put(b, one);
    }
  }
}

void api__svg_buf_num(api_svg_buf *b, double x, double budget, double *err) {
  char text[API_NUM_PRINT_MAX];
  double got;
  if (!isfinite(x)) x = 0.0;
  if (!(budget >= 0.0) || !isfinite(budget)) budget = 0.0;
  size_t n = api__num_print_within(text, x, budget, &got);
  if (err && fabs(got - x) > *err) *err = fabs(got - x);
  api__svg_buf_put_n(b, text, n);
}

char *api__svg_buf_take(api_svg_buf *b) {
  char *s = NULL;
  if (!b->failed) {
    if (!b->s) reserve(b, 0);
    if (!b->failed) {
      if (b->len == 0) b->s[0] = '\0';
      s = b->s;
      b->s = NULL;
    }
  }
  api__svg_buf_free(b);
  return s;
}

/* ---- Bezier spans ------------------------------------------------------ */

/* Homogeneous Bezier spans of c: nb spans of degree+1 points (wx, wy, w).
 * Piegl & Tiller, The NURBS Book, algorithm A5.6. */
typedef struct spans {
  int deg;
  size_t nb;
  double (*q)[3]; /* nb * (deg + 1) */
} spans;

static bool extract_spans(const km_curve *c, spans *out) {
  int p = c->degree;
  size_t n = c->n;
  const double *U = c->knots;
  size_t maxb = n; /* at most n - p spans; n is a safe bound */
  double(*q)[3] = km__malloc(maxb * (size_t)(p + 1) * sizeof *q);
  if (!q) return false;
  double alphas[KM_MAX_DEGREE + 1];
  size_t m = n + (size_t)p; /* last knot index */
  size_t a = (size_t)p, b = (size_t)p + 1, nb = 0;
#define PW(i, k)                                                               \
  ((k) < 2 ? c->cp[2 * (i) + (k)] * (c->w ? c->w[i] : 1.0)                     \
           : (c->w ? c->w[i] : 1.0))
#define Q(s, i) q[(s) * (size_t)(p + 1) + (size_t)(i)]
  for (int i = 0; i <= p; i++)
    for (int k = 0; k < 3; k++) Q(0, i)[k] = PW((size_t)i, k);
  while (b < m) {
    size_t i = b;
    while (b < m && U[b + 1] == U[b]) b++;
    int mult = (int)(b - i + 1);
    if (mult < p) {
      double numer = U[b] - U[a];
      for (int j = p; j > mult; j--)
        alphas[j - mult - 1] = numer / (U[a + (size_t)j] - U[a]);
      int r = p - mult;
      for (int j = 1; j <= r; j++) {
        int save = r - j, s = mult + j;
        for (int k = p; k >= s; k--) {
          double al = alphas[k - s];
          for (int t = 0; t < 3; t++)
            Q(nb, k)[t] = al * Q(nb, k)[t] + (1.0 - al) * Q(nb, k - 1)[t];
        }
        if (b < m)
          for (int t = 0; t < 3; t++) Q(nb + 1, save)[t] = Q(nb, p)[t];
      }
    }
    nb++;
    if (b < m) {
      for (int j = p - mult; j <= p; j++)
        for (int t = 0; t < 3; t++)
          Q(nb, j)[t] = PW(b - (size_t)p + (size_t)j, t);
      a = b;
      b++;
    }
  }
#undef PW
#undef Q
  out->deg = p;
  out->nb = nb;
  out->q = q;
  return true;
}

/* Degree elevation of homogeneous Bernstein coefficients, d -> e. */
static void elevate(const double (*in)[3], int d, int e, double (*out)[3]) {
  double h[KM_MAX_DEGREE + 4][3];
  for (int i = 0; i <= d; i++)
    for (int k = 0; k < 3; k++) h[i][k] = in[i][k];
  while (d < e) {
    double g[KM_MAX_DEGREE + 4][3];
    for (int k = 0; k < 3; k++) {
      g[0][k] = h[0][k];
      g[d + 1][k] = h[d][k];
    }
    for (int i = 1; i <= d; i++) {
      double al = (double)i / (d + 1);
      for (int k = 0; k < 3; k++)
        g[i][k] = al * h[i - 1][k] + (1.0 - al) * h[i][k];
    }
    d++;
    memcpy(h, g, sizeof h);
  }
  for (int i = 0; i <= e; i++)
    for (int k = 0; k < 3; k++) out[i][k] = h[i][k];
}

static double binom(int n, int k) {
  double r = 1.0;
  for (int i = 1; i <= k; i++) r = r * (n - k + i) / i;
  return r;
}

/* Cubic Hermite of a homogeneous Bezier span (degree d) and a rigorous
 * bound on its distance from the span at equal parameter. */
static double hermite(const double (*h)[3], int d, double cub[4][2]) {
  double p0[2] = {h[0][0] / h[0][2], h[0][1] / h[0][2]};
  double p1[2] = {h[1][0] / h[1][2], h[1][1] / h[1][2]};
  double pe[2] = {h[d][0] / h[d][2], h[d][1] / h[d][2]};
  double pm[2] = {h[d - 1][0] / h[d - 1][2], h[d - 1][1] / h[d - 1][2]};
  double s0 = d * h[1][2] / h[0][2] / 3.0;
  double s1 = d * h[d - 1][2] / h[d][2] / 3.0;
  for (int k = 0; k < 2; k++) {
    cub[0][k] = p0[k];
    cub[1][k] = p0[k] + s0 * (p1[k] - p0[k]);
    cub[2][k] = pe[k] - s1 * (pe[k] - pm[k]);
    cub[3][k] = pe[k];
  }
  int e = d + 3;
  double nel[KM_MAX_DEGREE + 4][3];
  elevate(h, d, e, nel);
  double wmin = INFINITY, bound = 0.0;
  for (int i = 0; i <= d; i++)
    if (h[i][2] < wmin) wmin = h[i][2];
  for (int k = 0; k <= e; k++) {
    double ex = nel[k][0], ey = nel[k][1];
    double ck = binom(e, k);
    for (int i = 0; i <= d; i++) {
      int j = k - i;
      if (j < 0 || j > 3) continue;
      double f = binom(d, i) * binom(3, j) / ck * h[i][2];
      ex -= f * cub[j][0];
      ey -= f * cub[j][1];
    }
    double m = hypot(ex, ey);
    if (m > bound) bound = m;
  }
  return wmin > 0 ? bound / wmin : INFINITY;
}

/* Split a homogeneous Bezier at u = 1/2 (de Casteljau). */
static void halve(const double (*h)[3], int d, double (*l)[3], double (*r)[3]) {
  double t[KM_MAX_DEGREE + 1][3];
  for (int i = 0; i <= d; i++)
    for (int k = 0; k < 3; k++) t[i][k] = h[i][k];
  for (int k = 0; k < 3; k++) {
    l[0][k] = t[0][k];
    r[d][k] = t[d][k];
  }
  for (int lev = 1; lev <= d; lev++) {
    for (int i = 0; i <= d - lev; i++)
      for (int k = 0; k < 3; k++) t[i][k] = 0.5 * (t[i][k] + t[i + 1][k]);
    for (int k = 0; k < 3; k++) {
      l[lev][k] = t[0][k];
      r[d - lev][k] = t[d - lev][k];
    }
  }
}

typedef struct writer {
  api_svg_buf buf;
  double budget;    /* per printed number */
  double print_err; /* largest printing error committed */
  double approx;    /* largest approximation bound */
  double target;    /* approximation target per piece */
  size_t pieces;
} writer;

/* Beyond this depth halving gains nothing (rounding dominates), and it
 * bounds the output for adversarial curves. */
#define MAX_HALVINGS 16
#define MAX_OUT_PIECES 2000000

static void put_pt(writer *w, const double p[2]) {
  api__svg_buf_num(&w->buf, p[0], w->budget, &w->print_err);
  api__svg_buf_put(&w->buf, ",");
  api__svg_buf_num(&w->buf, p[1], w->budget, &w->print_err);
}

static void put_cubic(writer *w, const double cub[4][2]) {
  api__svg_buf_put(&w->buf, w->pieces == 0 ? "C" : " ");
  put_pt(w, cub[1]);
  api__svg_buf_put(&w->buf, " ");
  put_pt(w, cub[2]);
  api__svg_buf_put(&w->buf, " ");
  put_pt(w, cub[3]);
  w->pieces++;
}

/* parent: the bound of the piece this one was halved from. Halving cuts
 * the Hermite error by about 16; when it no longer halves it, rounding
 * dominates and more pieces would only add bytes. */
static void approx_span(writer *w, const double (*h)[3], int d, int depth,
                        double parent) {
  double cub[4][2];
  double bnd = hermite(h, d, cub);
  if (bnd > w->target && depth < MAX_HALVINGS && w->pieces < MAX_OUT_PIECES &&
      bnd < 0.5 * parent) {
    double l[KM_MAX_DEGREE + 1][3], r[KM_MAX_DEGREE + 1][3];
    halve(h, d, l, r);
    approx_span(w, (const double(*)[3])l, d, depth + 1, bnd);
    approx_span(w, (const double(*)[3])r, d, depth + 1, bnd);
    return;
  }
  if (bnd > w->approx) w->approx = bnd;
  put_cubic(w, (const double(*)[2])cub);
}

static double extent(const km_curve *c) {
  double e = 0.0;
  for (size_t i = 0; i < 2 * c->n; i++)
    if (fabs(c->cp[i]) > e) e = fabs(c->cp[i]);
  return e;
}

char *api_svg_path_d(const km_curve *c, double tol, double *err_bound) {
  if (!c || c->n == 0 || !c->cp || !c->knots) return NULL;
  spans sp;
  if (!extract_spans(c, &sp)) return NULL;
  double ext = extent(c);
  /* Arithmetic on coordinates of size ext is good to a few ulps. */
  double rounding = 16.0 * DBL_EPSILON * (ext > 0 ? ext : 1.0);
  writer w;
  memset(&w, 0, sizeof w);
  api__svg_buf_init(&w.buf);
  bool good_tol = tol > 0 && isfinite(tol);
  /* Half the tolerance for the shape, a quarter per printed coordinate
   * (a point moves by at most sqrt(2)/4 of it). */
  w.target = good_tol ? 0.5 * tol : 1e-9 * (ext > 0 ? ext : 1.0);
  if (w.target < 4.0 * rounding) w.target = 4.0 * rounding;
  w.budget = good_tol ? 0.25 * tol : 0.0;
  int d = sp.deg;
  bool exact = c->w == NULL && d <= 3;
  double p0[2] = {sp.q[0][0] / sp.q[0][2], sp.q[0][1] / sp.q[0][2]};
  api__svg_buf_put(&w.buf, "M");
  put_pt(&w, p0);
  for (size_t s = 0; s < sp.nb; s++) {
    const double(*h)[3] = (const double(*)[3])(sp.q + s * (size_t)(d + 1));
    if (exact) {
      double e3[4][3], cub[4][2];
      elevate(h, d, 3, e3);
      for (int i = 0; i < 4; i++) {
        cub[i][0] = e3[i][0];
        cub[i][1] = e3[i][1];
      }
      put_cubic(&w, (const double(*)[2])cub);
    } else {
      approx_span(&w, h, d, 0, INFINITY);
    }
  }
  if (c->closed) api__svg_buf_put(&w.buf, " Z");
  km__free(sp.q);
  char *out = api__svg_buf_take(&w.buf);
  if (out && err_bound)
    *err_bound = w.approx + sqrt(2.0) * w.print_err + rounding;
  return out;
}

/* ---- arc length for the fixed-count paths ------------------------------
 * The core's length functions walk the whole curve per call; animation
 * needs n inversions on curves of 10^5 spans, so the spans' lengths are
 * integrated once here and inverted within one span. */

static const double GL_X[8] = {0.96028985649753623,  0.79666647741362674,
                               0.52553240991632899,  0.18343464249564980,
                               -0.18343464249564980, -0.52553240991632899,
                               -0.79666647741362674, -0.96028985649753623};
static const double GL_W[8] = {0.10122853629037626, 0.22238103445337447,
                               0.31370664587788729, 0.36268378337836198,
                               0.36268378337836198, 0.31370664587788729,
                               0.22238103445337447, 0.10122853629037626};

static double speed(const km_curve *c, double t) {
  double d[2][2];
  km_curve_eval(c, t, 1, d);
  return hypot(d[1][0], d[1][1]);
}

static double gl8(const km_curve *c, double a, double b) {
  double m = 0.5 * (a + b), h = 0.5 * (b - a), s = 0.0;
  for (int k = 0; k < 8; k++) s += GL_W[k] * speed(c, m + h * GL_X[k]);
  return s * h;
}

static double seg_len(const km_curve *c, double a, double b, double whole,
                      double tol, int depth) {
  double m = 0.5 * (a + b);
  double l = gl8(c, a, m), r = gl8(c, m, b);
  if (depth >= 12 || fabs(l + r - whole) <= tol) return l + r;
  return seg_len(c, a, m, l, 0.5 * tol, depth + 1) +
         seg_len(c, m, b, r, 0.5 * tol, depth + 1);
}

static double len_between(const km_curve *c, double a, double b, double tol) {
  if (!(b > a)) return 0.0;
  return seg_len(c, a, b, gl8(c, a, b), tol, 0);
}

/* Parameters t[0..n] at arc lengths j L / n. Returns false on OOM. */
static bool uniform_params(const km_curve *c, size_t n, double *t) {
  double t0, t1;
  km_curve_domain(c, &t0, &t1);
  size_t ns = 0;
  for (size_t i = (size_t)c->degree; i < c->n; i++)
    if (c->knots[i + 1] > c->knots[i]) ns++;
  double *cum = km__malloc((ns + 1) * sizeof *cum);
  double *ka = km__malloc((ns + 1) * sizeof *ka);
  if (!cum || !ka) {
    km__free(cum);
    km__free(ka);
    return false;
  }
  double ext = extent(c);
  double tol = 1e-13 * (ext > 0 ? ext : 1.0);
  size_t k = 0;
  cum[0] = 0.0;
  for (size_t i = (size_t)c->degree; i < c->n; i++) {
    if (!(c->knots[i + 1] > c->knots[i])) continue;
    ka[k] = c->knots[i];
    cum[k + 1] = cum[k] + len_between(c, c->knots[i], c->knots[i + 1], tol);
    k++;
  }
  ka[ns] = t1;
  double L = cum[ns];
  t[0] = t0;
  t[n] = t1;
  size_t span = 0;
  for (size_t j = 1; j < n; j++) {
    double s = L * (double)j / (double)n;
    if (!(L > 0) || !isfinite(L)) {
      t[j] = t0 + (t1 - t0) * (double)j / (double)n;
      continue;
    }
    while (span + 1 < ns && cum[span + 1] < s) span++;
    double a = ka[span], b = ka[span + 1], target = s - cum[span];
    double lo = a, hi = b, span_len = cum[span + 1] - cum[span];
    double x = span_len > 0 ? a + (b - a) * (target / span_len) : a;
    /* Newton on length(a, x) - target, kept inside [lo, hi]. */
    for (int it = 0; it < 60; it++) {
      double f = len_between(c, a, x, tol) - target;
      if (fabs(f) <= 1e-12 * L) break;
      if (f > 0)
        hi = x;
      else
        lo = x;
      double sp = speed(c, x);
      double nx = sp > 0 ? x - f / sp : 0.5 * (lo + hi);
      if (!(nx > lo && nx < hi)) nx = 0.5 * (lo + hi);
      x = nx;
    }
    t[j] = x;
  }
  km__free(cum);
  km__free(ka);
  return true;
}

char *api_svg_path_d_fixed_z(const km_curve *c, size_t n_pieces, bool with_z) {
  if (!c || c->n == 0 || !c->cp || !c->knots) return NULL;
  if (n_pieces < 1) n_pieces = 1;
  double *ts = km__malloc((n_pieces + 1) * sizeof *ts);
  if (!ts || !uniform_params(c, n_pieces, ts)) {
    km__free(ts);
    return NULL;
  }
  double ext = extent(c);
  writer w;
  memset(&w, 0, sizeof w);
  api__svg_buf_init(&w.buf);
  /* Animation frames need no more than a millionth of the drawing. */
  w.budget = 1e-6 * (ext > 0 ? ext : 1.0);
  double pa[2][2];
  km_curve_eval_side(c, ts[0], 1, 0, pa);
  api__svg_buf_put(&w.buf, "M");
  put_pt(&w, pa[0]);
  for (size_t i = 1; i <= n_pieces; i++) {
    double ta = ts[i - 1], tb = ts[i] < ta ? ta : ts[i];
    double pb[2][2], ra[2][2];
    km_curve_eval_side(c, ta, 1, 1, ra);
    km_curve_eval_side(c, tb, -1, 1, pb);
    double h = (tb - ta) / 3.0, cub[4][2];
    for (int k = 0; k < 2; k++) {
      cub[0][k] = ra[0][k];
      cub[1][k] = ra[0][k] + h * ra[1][k];
      cub[2][k] = pb[0][k] - h * pb[1][k];
      cub[3][k] = pb[0][k];
    }
    put_cubic(&w, (const double(*)[2])cub);
  }
  km__free(ts);
  if (with_z) api__svg_buf_put(&w.buf, " Z");
  return api__svg_buf_take(&w.buf);
}

char *api_svg_path_d_fixed(const km_curve *c, size_t n_pieces) {
  if (!c) return NULL;
  return api_svg_path_d_fixed_z(c, n_pieces, c->closed);
}
