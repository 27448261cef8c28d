/* shape.c - the compound shape value: contours copied and oriented per
 * role, the nesting tree from containment, and the polyline kernels of
 * shape_internal.h.
 *
 * DESIGN: containment, areas and crossings are decided on fixed
 * flattenings (KM_SHAPE_FLAT points a knot span) rather than on exact
 * Bezier roots: contours of a shape do not cross, so a point of one is
 * far from another compared with the chord error, and a majority vote of
 * KM_SHAPE_VOTES points makes one stray point near a touching contour
 * harmless. The parent of a contour is the smallest-area contour that
 * contains it, which is the innermost one when contours do not cross.
 */
#include <math.h>
#include <string.h>

#include "bspline_internal.h"
#include "km/alloc.h"
#include "km/limits.h"
#include "km/shape.h"
#include "shape_internal.h"
#include "status_internal.h"

/* ---- polyline kernels --------------------------------------------------- */

km_status km__shape_flatten(const km_curve *c, double **pts, size_t *np) {
  size_t spans = 0;
  for (size_t i = (size_t)c->degree; i < c->n; i++)
    if (c->knots[i + 1] > c->knots[i]) spans++;
  size_t n = spans * KM_SHAPE_FLAT + 1, k = 0;
  double *p = km__malloc(2 * n * sizeof *p), der[2];
  if (!p) return KM_ENOMEM;
  /* each span once in Bezier form, its points by Horner there (a valid
   * curve has a non-empty span, so sp is set at the end) */
  km__bspan sp = {0};
  for (size_t i = (size_t)c->degree; i < c->n; i++) {
    if (!(c->knots[i + 1] > c->knots[i])) continue;
    km__bspan_make(&sp, c, i);
    for (size_t j = 0; j < KM_SHAPE_FLAT; j++, k++)
      km__bspan_eval_u(&sp, (double)j / KM_SHAPE_FLAT, p + 2 * k, der);
  }
  km__bspan_eval_u(&sp, 1.0, p + 2 * k, der);
  *pts = p;
  *np = k + 1;
  return KM_OK;
}

int km__poly_winding(const double *P, size_t np, const double p[2]) {
  int w = 0;
  for (size_t i = 0; i < np; i++)
    w += km__edge_winding(P + 2 * i, P + 2 * ((i + 1) % np), p);
  return w;
}

static const double GL_X[8] = {-0.9602898564975363, -0.7966664774136267,
                               -0.5255324099163290, -0.1834346424956498,
                               0.1834346424956498,  0.5255324099163290,
                               0.7966664774136267,  0.9602898564975363};
static const double GL_W[8] = {0.1012285362903763, 0.2223810344533745,
                               0.3137066458778873, 0.3626837833783620,
                               0.3626837833783620, 0.3137066458778873,
                               0.2223810344533745, 0.1012285362903763};

/* Gauss-Legendre rules on [0, 1] for a polynomial span of degree p: the
 * ceil(3p / 2) points GLU_X[GLU_AT[p] .. GLU_AT[p + 1]), exact for
 * polynomials of degree 3p - 1, the highest of Green's integrands
 * (x^2 dy). Nodes and weights correctly rounded from 40 digits. */
/* clang-format off */
static const double GLU_X[70] = {
    /* p = 1: 2 points */
    0.21132486540518711, 0.78867513459481287,
    /* p = 2: 3 points */
    0.11270166537925831, 0.5, 0.8872983346207417,
    /* p = 3: 5 points */
    0.046910077030668004, 0.23076534494715845, 0.5, 0.7692346550528415,
    0.95308992296933204,
    /* p = 4: 6 points */
    0.033765242898423989, 0.16939530676686773, 0.38069040695840156,
    0.61930959304159849, 0.83060469323313224, 0.96623475710157603,
    /* p = 5: 8 points */
    0.019855071751231884, 0.10166676129318664, 0.2372337950418355,
    0.40828267875217511, 0.59171732124782495, 0.7627662049581645,
    0.89833323870681336, 0.98014492824876809,
    /* p = 6: 9 points */
    0.015919880246186954, 0.081984446336682101, 0.19331428364970479,
    0.33787328829809554, 0.5, 0.66212671170190451, 0.80668571635029518,
    0.91801555366331788, 0.98408011975381304,
    /* p = 7: 11 points */
    0.010885670926971503, 0.056468700115952349, 0.13492399721297535,
    0.2404519353965941, 0.36522842202382749, 0.5, 0.63477157797617245,
    0.75954806460340596, 0.86507600278702468, 0.9435312998840476,
    0.98911432907302854,
    /* p = 8: 12 points */
    0.0092196828766403748, 0.047941371814762573, 0.11504866290284765,
    0.20634102285669129, 0.31608425050090988, 0.43738329574426554,
    0.56261670425573451, 0.68391574949909006, 0.79365897714330869,
    0.88495133709715235, 0.95205862818523745, 0.99078031712335968,
    /* p = 9: 14 points */
    0.0068580956515938308, 0.035782558168213241, 0.086399342465117504,
    0.15635354759415726, 0.24237568182092295, 0.34044381553605513,
    0.44597252564632817, 0.55402747435367183, 0.65955618446394493,
    0.75762431817907705, 0.84364645240584268, 0.91360065753488251,
    0.9642174418317867, 0.99314190434840621
};
static const double GLU_W[70] = {
    /* p = 1: 2 points */
    0.5, 0.5,
    /* p = 2: 3 points */
    0.27777777777777779, 0.44444444444444442, 0.27777777777777779,
    /* p = 3: 5 points */
    0.11846344252809454, 0.23931433524968324, 0.28444444444444444,
    0.23931433524968324, 0.11846344252809454,
    /* p = 4: 6 points */
    0.085662246189585178, 0.1803807865240693, 0.23395696728634552,
    0.23395696728634552, 0.1803807865240693, 0.085662246189585178,
    /* p = 5: 8 points */
    0.050614268145188129, 0.11119051722668724, 0.15685332293894363,
    0.181341891689181, 0.181341891689181, 0.15685332293894363,
    0.11119051722668724, 0.050614268145188129,
    /* p = 6: 9 points */
    0.040637194180787206, 0.090324080347428698, 0.13030534820146772,
    0.15617353852000143, 0.16511967750062989, 0.15617353852000143,
    0.13030534820146772, 0.090324080347428698, 0.040637194180787206,
    /* p = 7: 11 points */
    0.027834283558086832, 0.062790184732452306, 0.093145105463867131,
    0.11659688229599524, 0.13140227225512333, 0.13646254338895031,
    0.13140227225512333, 0.11659688229599524, 0.093145105463867131,
    0.062790184732452306, 0.027834283558086832,
    /* p = 8: 12 points */
    0.023587668193255914, 0.053469662997659213, 0.080039164271673111,
    0.10158371336153296, 0.1167462682691774, 0.12457352290670139,
    0.12457352290670139, 0.1167462682691774, 0.10158371336153296,
    0.080039164271673111, 0.053469662997659213, 0.023587668193255914,
    /* p = 9: 14 points */
    0.01755973016587593, 0.040079043579880104, 0.060759285343951593,
    0.078601583579096773, 0.092769198738968911, 0.1025992318606478,
    0.1076319267315789, 0.1076319267315789, 0.1025992318606478,
    0.092769198738968911, 0.078601583579096773, 0.060759285343951593,
    0.040079043579880104, 0.01755973016587593
};
static const unsigned char GLU_AT[KM_MAX_DEGREE + 2] = {
    0, 0, 2, 5, 10, 16, 24, 33, 44, 56, 70};
/* clang-format on */

/* The sums of Green's integrands over a polynomial curve about the point
 * o, span by span in Bezier form: exact up to rounding. */
static void polynomial_green(const km_curve *c, const double o[2],
                             double s[3]) {
  int p = c->degree;
  const double *gx = GLU_X + GLU_AT[p], *gw = GLU_W + GLU_AT[p];
  int m = GLU_AT[p + 1] - GLU_AT[p];
  for (size_t i = (size_t)p; i < c->n; i++) {
    if (!(c->knots[i + 1] > c->knots[i])) continue;
    km__bspan sp;
    km__bspan_make(&sp, c, i);
    for (int k = 0; k < m; k++) {
      double pos[2], der[2];
      km__bspan_eval_u(&sp, gx[k], pos, der);
      double x = pos[0] - o[0], y = pos[1] - o[1], dx = der[0], dy = der[1];
      s[0] += gw[k] * (x * dy - y * dx);
      s[1] += gw[k] * x * x * dy;
      s[2] -= gw[k] * y * y * dx;
    }
  }
}

/* The same for a rational curve: 8 points on each quarter of a span. */
static void rational_green(const km_curve *c, const double o[2], double s[3]) {
  for (size_t i = (size_t)c->degree; i < c->n; i++) {
    double a = c->knots[i], b = c->knots[i + 1];
    if (!(b > a)) continue;
    for (int panel = 0; panel < 4; panel++) {
      double lo = a + (b - a) * panel / 4.0, h = (b - a) / 4.0;
      for (int k = 0; k < 8; k++) {
        double d[2][2];
        km__curve_eval_span(c, i, lo + 0.5 * h * (GL_X[k] + 1.0), 1, d);
        double wk = 0.5 * h * GL_W[k];
        double x = d[0][0] - o[0], y = d[0][1] - o[1];
        double dx = d[1][0], dy = d[1][1];
        s[0] += wk * (x * dy - y * dx);
        s[1] += wk * x * x * dy;
        s[2] -= wk * y * y * dx;
      }
    }
  }
}

/* Green: A = 1/2 closed integral (x dy - y dx), A cx = 1/2 integral x^2 dy,
 * A cy = -1/2 integral y^2 dx, with x and y taken from the start point:
 * the same on a closed curve (the integrals of dx and dy vanish), a
 * chord's closing of a small gap otherwise, and without the cancellation
 * of coordinates far larger than the contour (one that is vanishing). */
void km__curve_area(const km_curve *c, double *area, double centroid[2]) {
  double s[3] = {0.0, 0.0, 0.0}, o[2] = {c->cp[0], c->cp[1]};
  if (c->w)
    rational_green(c, o, s);
  else
    polynomial_green(c, o, s);
  double a2 = s[0];
  *area = 0.5 * a2;
  centroid[0] = a2 != 0.0 ? o[0] + s[1] / a2 : NAN;
  centroid[1] = a2 != 0.0 ? o[1] + s[2] / a2 : NAN;
}

long km__poly_crossings(const double *P, size_t np, const double *Q, size_t nq,
                        km__poll *poll) {
  long count = 0;
  for (size_t i = 0; i + 1 < np; i++) {
    const double *a = P + 2 * i, *b = a + 2;
    double x0 = fmin(a[0], b[0]), x1 = fmax(a[0], b[0]);
    double y0 = fmin(a[1], b[1]), y1 = fmax(a[1], b[1]);
    for (size_t j = 0; j + 1 < nq; j++) {
      const double *c = Q + 2 * j, *d = c + 2;
      if (fmax(c[0], d[0]) < x0 || fmin(c[0], d[0]) > x1 ||
          fmax(c[1], d[1]) < y0 || fmin(c[1], d[1]) > y1)
        continue;
      if (km__edge_crosses(a, b, c, d)) count++;
    }
    if (km__poll_stop(poll, (long)(nq / 64) + 1)) return -1;
  }
  return count;
}

/* ---- the shape value ---------------------------------------------------- */

void km_shape_init(km_shape *s) {
  if (s) memset(s, 0, sizeof *s);
}

void km_shape_free(km_shape *s) {
  if (!s) return;
  for (size_t i = 0; s->contours && i < s->ncontours; i++)
    km_curve_free(&s->contours[i]);
  km__free(s->contours);
  km__free(s->parent);
  km__free(s->depth);
  km__free(s->role);
  km__free(s->reversed);
  km__free(s->area);
  km__free(s->centroid);
  km__free(s->flat);
  km__free(s->flat_off);
  km_shape_init(s);
}

/* One block per array keeps the free path simple; all are sized by n. */
static km_status shape_alloc(km_shape *s, size_t n) {
  s->contours = km__calloc(n, sizeof *s->contours);
  s->parent = km__calloc(n, sizeof *s->parent);
  s->depth = km__calloc(n, sizeof *s->depth);
  s->role = km__calloc(n, sizeof *s->role);
  s->reversed = km__calloc(n, sizeof *s->reversed);
  s->area = km__calloc(n, sizeof *s->area);
  s->centroid = km__calloc(2 * n, sizeof *s->centroid);
  s->flat_off = km__calloc(n + 1, sizeof *s->flat_off);
  if (!s->contours || !s->parent || !s->depth || !s->role || !s->reversed ||
      !s->area || !s->centroid || !s->flat_off)
    return KM_ENOMEM;
  return KM_OK;
}

static bool is_curve(const km_curve *c) {
  return c && c->knots && c->cp && c->degree >= 1 &&
         c->degree <= KM_MAX_DEGREE && c->n >= (size_t)c->degree + 1;
}

/* Checks of one input contour that need no copy. */
static km_status check_contour(const km_curve *c, size_t i, size_t *points,
                               size_t max_points, km_error *err) {
  long li = (long)i;
  if (!is_curve(c))
    return km__fail(err, KM_EINVAL, KM_FIELD_NONE, li, NAN,
                    "contour %zu is not a curve", i);
  *points += c->n;
  if (*points > max_points)
    return km__fail(err, KM_ELIMIT, KM_FIELD_CONTROL_POINTS, li, NAN,
                    "contours 0..%zu have %zu control points, above %zu", i,
                    *points, max_points);
  if (!c->closed)
    return km__fail(err, KM_ECLOSED, KM_FIELD_CLOSED, li, NAN,
                    "contour %zu is open: a shape's contours are closed", i);
  double len = km_curve_length(c);
  if (!isfinite(len))
    return km__fail(err, KM_ENONFINITE, KM_FIELD_CONTROL_POINTS, li, NAN,
                    "contour %zu: its length cannot be computed", i);
  if (!(len > 0.0))
    return km__fail(err, KM_EDEGENERATE, KM_FIELD_CONTROL_POINTS, li, NAN,
                    "contour %zu has zero length", i);
  return KM_OK;
}

/* Copy, measure and flatten contour i into s; the flattening goes to
 * *flat (the caller frees). */
static km_status take_contour(km_shape *s, const km_curve *c, size_t i,
                              double **flat, size_t *np, km_error *err) {
  km_status st = km_curve_copy(&s->contours[i], c, err);
  if (st != KM_OK) return st;
  double a;
  km__curve_area(c, &a, s->centroid + 2 * i);
  double len = km_curve_length(c);
  if (!isfinite(a))
    return km__fail(err, KM_ENONFINITE, KM_FIELD_CONTROL_POINTS, (long)i, NAN,
                    "contour %zu: its area is not finite", i);
  /* an area of rounding size beside length^2 encloses nothing */
  if (!(fabs(a) > 1e-12 * len * len))
    return km__fail(err, KM_EDEGENERATE, KM_FIELD_CONTROL_POINTS, (long)i, NAN,
                    "contour %zu encloses no area", i);
  s->area[i] = a; /* signed until the orientation is normalised */
  return km__shape_flatten(c, flat, np);
}

static bool contains(const km_shape *s, size_t i, size_t j) {
  const double *P = s->flat + 2 * s->flat_off[i];
  size_t np = s->flat_off[i + 1] - s->flat_off[i];
  const double *Q = s->flat + 2 * s->flat_off[j];
  size_t nq = s->flat_off[j + 1] - s->flat_off[j] - 1;
  int in = 0;
  for (size_t v = 0; v < KM_SHAPE_VOTES; v++)
    if (km__poly_winding(P, np, Q + 2 * (v * nq / KM_SHAPE_VOTES)) != 0) in++;
  return 2 * in > KM_SHAPE_VOTES;
}

/* Parents, depths and roles; the areas are still signed as given. */
static void build_tree(km_shape *s) {
  size_t n = s->ncontours;
  for (size_t j = 0; j < n; j++) {
    s->parent[j] = -1;
    for (size_t i = 0; i < n; i++) {
      if (i == j || !(fabs(s->area[i]) > fabs(s->area[j]))) continue;
      if (!contains(s, i, j)) continue;
      if (s->parent[j] < 0 ||
          fabs(s->area[i]) < fabs(s->area[(size_t)s->parent[j]]))
        s->parent[j] = (long)i;
    }
  }
  for (size_t j = 0; j < n; j++) {
    int d = 0, w = s->area[j] > 0 ? 1 : -1;
    for (long p = s->parent[j]; p >= 0; p = s->parent[(size_t)p]) {
      d++;
      w += s->area[(size_t)p] > 0 ? 1 : -1;
    }
    s->depth[j] = d;
    if (s->fill == KM_FILL_EVENODD)
      s->role[j] = d % 2 ? KM_ROLE_HOLE : KM_ROLE_OUTER;
    else
      s->role[j] = w == 0 ? KM_ROLE_HOLE : KM_ROLE_OUTER;
  }
}

static void reverse_points(double *p, size_t np) {
  for (size_t a = 0, b = np - 1; a < b; a++, b--) {
    double x = p[2 * a], y = p[2 * a + 1];
    p[2 * a] = p[2 * b];
    p[2 * a + 1] = p[2 * b + 1];
    p[2 * b] = x;
    p[2 * b + 1] = y;
  }
}

/* OUTER counter-clockwise, HOLE clockwise; areas made positive. */
static km_status orient(km_shape *s, km_error *err) {
  for (size_t i = 0; i < s->ncontours; i++) {
    bool ccw = s->area[i] > 0;
    s->area[i] = fabs(s->area[i]);
    if (ccw == (s->role[i] == KM_ROLE_OUTER)) continue;
    km_curve r;
    km_curve_init(&r);
    km_status st = km_curve_reverse(&r, &s->contours[i], err);
    if (st != KM_OK) return st;
    km_curve_free(&s->contours[i]);
    s->contours[i] = r;
    s->reversed[i] = true;
    reverse_points(s->flat + 2 * s->flat_off[i],
                   s->flat_off[i + 1] - s->flat_off[i]);
  }
  return KM_OK;
}

static void set_box(km_shape *s) {
  size_t np = s->flat_off[s->ncontours];
  s->box[0] = s->box[2] = s->flat[0];
  s->box[1] = s->box[3] = s->flat[1];
  for (size_t k = 1; k < np; k++) {
    s->box[0] = fmin(s->box[0], s->flat[2 * k]);
    s->box[1] = fmin(s->box[1], s->flat[2 * k + 1]);
    s->box[2] = fmax(s->box[2], s->flat[2 * k]);
    s->box[3] = fmax(s->box[3], s->flat[2 * k + 1]);
  }
}

/* Flattenings gathered into one block so a shape stays a few blocks. */
static km_status gather_flat(km_shape *s, double **flats, const size_t *nps) {
  size_t total = 0;
  for (size_t i = 0; i < s->ncontours; i++) {
    s->flat_off[i] = total;
    total += nps[i];
  }
  s->flat_off[s->ncontours] = total;
  s->flat = km__malloc(2 * total * sizeof *s->flat);
  if (!s->flat) return KM_ENOMEM;
  for (size_t i = 0; i < s->ncontours; i++)
    memcpy(s->flat + 2 * s->flat_off[i], flats[i], 2 * nps[i] * sizeof(double));
  return KM_OK;
}

static km_status check_args(const km_curve *contours, size_t n,
                            km_fill_rule fill, const km_shape_limits *lim,
                            km_error *err) {
  size_t maxc = lim && lim->max_contours ? lim->max_contours
                                         : KM_SHAPE_DEFAULT_MAX_CONTOURS;
  size_t maxp =
      lim && lim->max_points ? lim->max_points : KM_SHAPE_DEFAULT_MAX_POINTS;
  if (maxc > KM_SHAPE_MAX_CONTOURS) maxc = KM_SHAPE_MAX_CONTOURS;
  if (maxp > KM_SHAPE_MAX_POINTS) maxp = KM_SHAPE_MAX_POINTS;
  if (fill != KM_FILL_NONZERO && fill != KM_FILL_EVENODD)
    return km__fail(err, KM_EINVAL, KM_FIELD_NONE, -1, NAN,
                    "fill rule is neither nonzero nor evenodd");
  if (n == 0)
    return km__fail(err, KM_ECOUNT, KM_FIELD_NONE, -1, NAN,
                    "a shape needs at least one contour");
  if (!contours)
    return km__fail(err, KM_EINVAL, KM_FIELD_NONE, -1, NAN, "contours missing");
  if (n > maxc)
    return km__fail(err, KM_ELIMIT, KM_FIELD_NONE, (long)maxc, NAN,
                    "%zu contours, above the limit of %zu", n, maxc);
  size_t points = 0;
  for (size_t i = 0; i < n; i++) {
    km_status st = check_contour(&contours[i], i, &points, maxp, err);
    if (st != KM_OK) return st;
  }
  return KM_OK;
}

km_status km_shape_create(km_shape *out, const km_curve *contours, size_t n,
                          km_fill_rule fill, const km_shape_limits *lim,
                          km_error *err) {
  km_shape s;
  km_shape_init(&s);
  double **flats = NULL;
  size_t *nps = NULL;
  km_status st = check_args(contours, n, fill, lim, err);
  if (st != KM_OK) return st;
  s.ncontours = n;
  s.fill = fill;
  flats = km__calloc(n, sizeof *flats);
  nps = km__calloc(n, sizeof *nps);
  st = (flats && nps) ? shape_alloc(&s, n) : KM_ENOMEM;
  for (size_t i = 0; st == KM_OK && i < n; i++)
    st = take_contour(&s, &contours[i], i, &flats[i], &nps[i], err);
  if (st == KM_OK) st = gather_flat(&s, flats, nps);
  if (st != KM_OK) goto cleanup;
  build_tree(&s);
  st = orient(&s, err);
  if (st != KM_OK) goto cleanup;
  set_box(&s);
  *out = s;
  km_shape_init(&s);
cleanup:
  for (size_t i = 0; flats && i < n; i++) km__free(flats[i]);
  km__free(flats);
  km__free(nps);
  km_shape_free(&s);
  if (st == KM_ENOMEM)
    km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, "out of memory");
  return st;
}

int km_shape_winding(const km_shape *s, size_t i, const double p[2]) {
  return km__poly_winding(s->flat + 2 * s->flat_off[i],
                          s->flat_off[i + 1] - s->flat_off[i], p);
}

km_status km_shape_copy(km_shape *out, const km_shape *s, km_error *err) {
  if (!s || !s->ncontours || !s->contours)
    return km__fail(err, KM_EINVAL, KM_FIELD_NONE, -1, NAN, "empty shape");
  km_shape c;
  km_shape_init(&c);
  size_t n = s->ncontours, nflat = s->flat_off[n];
  c.ncontours = n;
  c.fill = s->fill;
  memcpy(c.box, s->box, sizeof c.box);
  km_status st = shape_alloc(&c, n);
  if (st == KM_OK) {
    c.flat = km__malloc(2 * nflat * sizeof *c.flat);
    if (!c.flat) st = KM_ENOMEM;
  }
  for (size_t i = 0; st == KM_OK && i < n; i++)
    st = km_curve_copy(&c.contours[i], &s->contours[i], err);
  if (st != KM_OK) goto cleanup;
  memcpy(c.parent, s->parent, n * sizeof *c.parent);
  memcpy(c.depth, s->depth, n * sizeof *c.depth);
  memcpy(c.role, s->role, n * sizeof *c.role);
  memcpy(c.reversed, s->reversed, n * sizeof *c.reversed);
  memcpy(c.area, s->area, n * sizeof *c.area);
  memcpy(c.centroid, s->centroid, 2 * n * sizeof *c.centroid);
  memcpy(c.flat_off, s->flat_off, (n + 1) * sizeof *c.flat_off);
  memcpy(c.flat, s->flat, 2 * nflat * sizeof *c.flat);
  *out = c;
  km_shape_init(&c);
cleanup:
  km_shape_free(&c);
  if (st == KM_ENOMEM)
    km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, "out of memory");
  return st;
}

/* The point nearest x among points set in from the closed polyline P by
 * 3% of its extent along each edge's normal, on the side whose winding
 * is not 0: a point well inside a region of any shape, near x. */
void km__poly_interior_point(const km__poly_index *ix, const double x[2],
                             double out[2]) {
  const double *P = ix->P;
  size_t np = ix->np;
  double x0 = P[0], x1 = P[0], y0 = P[1], y1 = P[1];
  for (size_t i = 1; i < np; i++) {
    x0 = fmin(x0, P[2 * i]);
    x1 = fmax(x1, P[2 * i]);
    y0 = fmin(y0, P[2 * i + 1]);
    y1 = fmax(y1, P[2 * i + 1]);
  }
  double delta = 0.03 * hypot(x1 - x0, y1 - y0), best = INFINITY;
  out[0] = x[0];
  out[1] = x[1];
  for (size_t i = 0; i + 1 < np; i++) {
    const double *a = P + 2 * i, *b = a + 2;
    double dx = b[0] - a[0], dy = b[1] - a[1], l = hypot(dx, dy);
    if (!(l > 0)) continue;
    for (int side = -1; side <= 1; side += 2) {
      double q[2] = {0.5 * (a[0] + b[0]) - side * delta * dy / l,
                     0.5 * (a[1] + b[1]) + side * delta * dx / l};
      double d = hypot(q[0] - x[0], q[1] - x[1]);
      /* of points at the same distance within rounding (x on a symmetry
       * axis of P) the last, whatever the rounding of x */
      if (d <= best * (1.0 + 1e-9) && km__poly_index_winding(ix, q) != 0) {
        best = d;
        out[0] = q[0];
        out[1] = q[1];
      }
    }
  }
}
