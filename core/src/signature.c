/* signature.c - curvature signatures of B-spline / NURBS curves.
 *
 * DESIGN. kappa(s) is obtained as the derivative of a piecewise polynomial
 * interpolant of the tangent angle theta(s), not by sampling kappa itself:
 *   - theta(t) is smooth in the curve parameter even where a control leg is
 *     degenerate (C' = 0 at a span end), while kappa(s) there grows like
 *     1/sqrt(s); interpolating theta keeps the turning exact (the pieces
 *     meet the true theta at their ends) and bounds the position error
 *     directly: |C - C~| <= integral |theta - theta~| ds <= L max|dtheta|.
 *   - Nodes are Chebyshev-Lobatto points in t on each piece; their images
 *     in s (by Gauss-Legendre arc length) are the interpolation abscissae.
 *     Points midway between nodes check the interpolant; a piece that
 *     fails is bisected in t, which refines geometrically toward a
 *     degenerate end by itself.
 *   - Knots are always piece boundaries, so kappa's breakpoints include
 *     their arc-length images and curvature jumps at C1 knots survive.
 *   - Where the one-sided tangents at a knot differ, the turn is a corner;
 *     a turn of (nearly) pi is a cusp and is refused.
 *   - Everything computed from the curve carries the rounding of its
 *     coordinates: C' within a few times its rounding error gives no
 *     direction, lengths are asked no more precisely than that error
 *     allows, and the tolerance is raised to it (limits.h). A curve far
 *     from the origin is thus handled at the precision it has, not
 *     refined into noise.
 *   - The work is counted in evaluations of the curve, for the whole curve
 *     and for each span (limits.h): a span that would need more is refused
 *     with KM_ELIMIT quickly, whatever the rest of the curve.
 */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "km/limits.h"
#include "km/signature.h"

#define THETA_DEGREE 7               /* kappa pieces are of degree 6 */
#define NPTS (2 * THETA_DEGREE + 1)  /* nodes and check points */
#define CORNER_NOISE 1e-11           /* turns below this are rounding */
#define SPAN_CACHE 20000             /* spans kept in Bezier form */
/* |turn| > pi - this: a cusp. Tangent estimates beside a cusp are good to
 * about 1e-7 rad, so a hairpin must turn back within 1e-5 rad of pi to be
 * taken for a cusp. */
#define CUSP_MARGIN 1e-5

/* cos(m pi / 14), m = 0..14: the Chebyshev-Lobatto abscissae of NPTS = 15
 * points */
static const double COS14[NPTS] = {1.0, 0.9749279121818236, 0.9009688679024191, 0.7818314824680298, 0.6234898018587336, 0.4338837391175582, 0.22252093395631445, 6.123233995736766e-17, -0.22252093395631434, -0.43388373911755806, -0.6234898018587335, -0.7818314824680295, -0.900968867902419, -0.9749279121818237, -1.0};

void km_signature_init(km_signature *sig) {
  if (!sig) return;
  memset(sig, 0, sizeof *sig);
  km_fn_init(&sig->kappa);
}

void km_signature_free(km_signature *sig) {
  if (!sig) return;
  km_fn_free(&sig->kappa);
  free(sig->corners);
  km_signature_init(sig);
}

km_status km_signature_copy(km_signature *out, const km_signature *sig,
                            km_error *err) {
  return km_signature_create(out, sig->length, sig->start, sig->angle,
                             &sig->kappa, sig->corners, sig->ncorners,
                             sig->closed, err);
}

km_status km_signature_create(km_signature *out, double length,
                              const double start[2], double angle,
                              const km_fn *kappa, const km_corner *corners,
                              size_t ncorners, bool closed, km_error *err) {
  if (!isfinite(length))
    return km__fail(err, KM_ENONFINITE, KM_FIELD_LENGTH, -1, NAN,
                    "length is not finite");
  if (!(length > 0) || length > KM_MAX_COORDINATE)
    return km__fail(err, KM_ERANGE, KM_FIELD_LENGTH, -1, NAN,
                    "length must be positive and at most %g",
                    KM_MAX_COORDINATE);
  for (int k = 0; k < 2; k++) {
    if (!isfinite(start[k]))
      return km__fail(err, KM_ENONFINITE, KM_FIELD_START, k, NAN,
                      "start point is not finite");
    if (fabs(start[k]) > KM_MAX_COORDINATE)
      return km__fail(err, KM_ERANGE, KM_FIELD_START, k, NAN,
                      "start point exceeds %g in magnitude",
                      KM_MAX_COORDINATE);
  }
  if (!isfinite(angle) || fabs(angle) > 1e6)
    return km__fail(err, KM_ERANGE, KM_FIELD_ANGLE, -1, NAN,
                    "start angle must be finite and at most 1e6 radians");
  double a, b;
  km_fn_domain(kappa, &a, &b);
  if (fabs(a) > 1e-9 * length || fabs(b - length) > 1e-9 * length)
    return km__fail(err, KM_EKNOTS, KM_FIELD_KAPPA_KNOTS, -1, NAN,
                    "kappa must be defined on [0, length] = [0, %g], not "
                    "[%g, %g]",
                    length, a, b);
  for (size_t i = 0; i < ncorners; i++) {
    if (!isfinite(corners[i].s) || !isfinite(corners[i].turn))
      return km__fail(err, KM_ENONFINITE, KM_FIELD_CORNERS, (long)i, NAN,
                      "corner %zu is not finite", i);
    if (corners[i].s < 0 || corners[i].s > length * (1 + 1e-12))
      return km__fail(err, KM_ERANGE, KM_FIELD_CORNERS, (long)i, NAN,
                      "corner %zu lies outside [0, length]", i);
    if (!(fabs(corners[i].turn) < KM_PI))
      return km__fail(err, KM_ERANGE, KM_FIELD_CORNERS, (long)i, NAN,
                      "corner %zu turns by %g, outside (-pi, pi)", i,
                      corners[i].turn);
    if (i > 0 && corners[i].s < corners[i - 1].s)
      return km__fail(err, KM_EINVAL, KM_FIELD_CORNERS, (long)i, NAN,
                      "corners must be sorted by s (corner %zu)", i);
  }
  /* a bound on the integral of |kappa| plus |turn| at the corners */
  double abs_turning = 0.0;
  int p = kappa->degree;
  for (size_t i = 0; i < kappa->n; i++)
    abs_turning += fabs(kappa->coef[i]) *
                   (kappa->knots[i + (size_t)p + 1] - kappa->knots[i]) / (p + 1);
  for (size_t i = 0; i < ncorners; i++) abs_turning += fabs(corners[i].turn);
  double max_turns = KM_MAX_SIGNATURE_TURNS + 0.25 * (double)kappa->n;
  if (!(abs_turning <= 2 * KM_PI * max_turns))
    return km__fail(err, KM_ELIMIT, KM_FIELD_KAPPA_COEFFICIENTS, -1, NAN,
                    "the curve would turn up to %g times (|kappa| "
                    "integrates to %g rad); at most %g turns are traced",
                    abs_turning / (2 * KM_PI), abs_turning, max_turns);
  km_signature r;
  km_signature_init(&r);
  km_status st = km_fn_copy(&r.kappa, kappa, err);
  if (st) return st;
  /* snap the domain to [0, length] exactly */
  size_t nk = r.kappa.n + (size_t)r.kappa.degree + 1;
  for (size_t i = 0; i < nk; i++) {
    if (r.kappa.knots[i] < 0 || i <= (size_t)r.kappa.degree)
      r.kappa.knots[i] = 0.0;
    if (r.kappa.knots[i] > length || i >= r.kappa.n) r.kappa.knots[i] = length;
  }
  if (ncorners) {
    r.corners = malloc(ncorners * sizeof *r.corners);
    if (!r.corners) {
      km_fn_free(&r.kappa);
      return km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
    }
    memcpy(r.corners, corners, ncorners * sizeof *r.corners);
    for (size_t i = 0; i < ncorners; i++)
      if (r.corners[i].s > length) r.corners[i].s = length;
  }
  r.ncorners = ncorners;
  r.length = length;
  r.start[0] = start[0];
  r.start[1] = start[1];
  r.angle = angle;
  r.closed = closed;
  double turning = km_fn_integral(&r.kappa);
  for (size_t i = 0; i < ncorners; i++) turning += corners[i].turn;
  r.turning = turning;
  *out = r;
  return KM_OK;
}

double km_signature_theta(const km_signature *sig, double s) {
  /* integral of kappa over [0, s] by the antiderivative on the fly */
  km_fn F;
  double th = sig->angle;
  if (km_fn_antiderivative(&F, &sig->kappa, 0.0, NULL) == KM_OK) {
    th += km_fn_value(&F, s);
    km_fn_free(&F);
  }
  for (size_t i = 0; i < sig->ncorners; i++)
    if (sig->corners[i].s <= s) th += sig->corners[i].turn;
  return th;
}

double km_signature_max_abs_kappa(const km_signature *sig) {
  return km_fn_max_abs(&sig->kappa);
}

double km_signature_bending_energy(const km_signature *sig) {
  return km_fn_integral_sq(&sig->kappa);
}

/* ---- computing a signature ------------------------------------------- */

typedef struct builder {
  const km_curve *c;
  double L;         /* total length */
  double tol;       /* allowed distance to the curve */
  double tol_theta; /* allowed |theta - theta~| */
  double span_t;    /* width in t of the span being processed */
  double span_speed; /* its mean speed: the scale of |C'| there */
  double span_len;  /* its arc length: estimated, then confirmed */
  double span_weight_ratio; /* largest over smallest weight (1 without) */
  /* pieces of theta: breaks s[0..m], coefficients th[m*(P+1)] */
  double *s, *th;
  size_t m, cap;
  km_corner *corners;
  size_t ncorners, ccap;
  double pending_start; /* theta the next piece must start from, or NAN */
  size_t span_first;    /* index of the current span's first piece */
  km__bspan span;       /* the current span in Bezier form */
  double deriv_noise;   /* rounding error of |C'| in this span */
  long work;            /* curve evaluations left for the whole curve */
  long span_work;       /* and for the span being processed */
  double free_len;      /* position error left for pieces taken as turning
                           uniformly (twice their length) */
  km__poll *poll;        /* the caller's stop condition, or NULL */
  km_error *err;
} builder;

static km_status push_piece(builder *b, double s0, double s1,
                            const double *coef) {
  if (b->m + 1 >= b->cap) {
    size_t cap = b->cap ? 2 * b->cap : 64;
    if (cap > KM_MAX_PIECES)
      return km__fail(b->err, KM_ELIMIT, KM_FIELD_NONE, -1, NAN,
                      "signature would need more than %d pieces",
                      KM_MAX_PIECES);
    double *s = realloc(b->s, (cap + 1) * sizeof(double));
    if (!s) return km__fail(b->err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
    b->s = s;
    double *th = realloc(b->th, cap * (THETA_DEGREE + 1) * sizeof(double));
    if (!th) return km__fail(b->err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
    b->th = th;
    b->cap = cap;
  }
  if (b->m == 0) b->s[0] = s0;
  b->s[b->m + 1] = s1;
  memcpy(b->th + b->m * (THETA_DEGREE + 1), coef,
         (THETA_DEGREE + 1) * sizeof(double));
  b->m++;
  return KM_OK;
}

static km_status push_corner(builder *b, double s, double turn, double t) {
  if (b->ncorners > 0 && s - b->corners[b->ncorners - 1].s <= 1e-14 * b->L) {
    /* one corner seen in several steps: one turn, which may reverse */
    double sum = km__wrap_angle(b->corners[b->ncorners - 1].turn + turn);
    if (fabs(sum) > KM_PI - CUSP_MARGIN)
      return km__fail(b->err, KM_ECUSP, KM_FIELD_CONTROL_POINTS, -1, t,
                      "the tangent reverses at parameter t = %g (a cusp): "
                      "the curve is not regular there",
                      t);
    b->corners[b->ncorners - 1].turn = sum;
    return KM_OK;
  }
  if (b->ncorners == b->ccap) {
    size_t cap = b->ccap ? 2 * b->ccap : 16;
    km_corner *c = realloc(b->corners, cap * sizeof *c);
    if (!c) return km__fail(b->err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
    b->corners = c;
    b->ccap = cap;
  }
  b->corners[b->ncorners].s = s;
  b->corners[b->ncorners].turn = turn;
  b->ncorners++;
  return KM_OK;
}

/* Unit tangent at t as a one-sided limit (side > 0: from the right). When
 * C'(t) vanishes the first non-vanishing higher derivative gives the
 * direction (C'(t + sh) ~ (sh)^(k-1) C^(k)(t)); failing that, a short
 * chord. Returns false if no direction exists (a point curve). */
static bool tangent_limit(const builder *b, double t, int side,
                          double dir[2]) {
  double d[4][2];
  km_curve_eval_side(b->c, t, side, 3, d);
  double scale = b->span_speed;
  double tiny = 1e-10 * scale;
  /* and above the rounding of the derivative: at a point where C' vanishes
   * to high order its computed value is noise, whatever its size beside
   * the span's speed */
  double noise = 16.0 * b->deriv_noise;
  for (int k = 1; k <= 3; k++) {
    double n = hypot(d[k][0], d[k][1]);
    if (n > fmax(tiny, noise)) {
      double sg = (side < 0 && (k % 2 == 0)) ? -1.0 : 1.0;
      dir[0] = sg * d[k][0] / n;
      dir[1] = sg * d[k][1] / n;
      return true;
    }
    tiny /= fmax(b->span_t, 1e-300);
    noise *= b->c->degree / fmax(b->span_t, 1e-300);
  }
  /* At an end of the current span the first control point of its Bezier
   * form that differs from the end point gives the direction: C - P0 is
   * dominated by (P_k - P0) t^k however many legs are degenerate, where
   * both the derivatives above and a chord are lost in rounding. */
  const km__bspan *sp = &b->span;
  int p = sp->degree;
  if ((side > 0 && t == sp->a) || (side < 0 && t == sp->b)) {
    int e = side > 0 ? 0 : p, step = side > 0 ? 1 : -1;
    double ex = sp->h[e][0] / sp->h[e][2], ey = sp->h[e][1] / sp->h[e][2];
    double floor_p = b->deriv_noise * (sp->b - sp->a); /* ~ rounding of points */
    for (int k = e + step; k >= 0 && k <= p; k += step) {
      double vx = (sp->h[k][0] / sp->h[k][2] - ex) * step;
      double vy = (sp->h[k][1] / sp->h[k][2] - ey) * step;
      double n = hypot(vx, vy);
      if (n > floor_p) {
        dir[0] = vx / n;
        dir[1] = vy / n;
        return true;
      }
    }
  }
  /* chord over a small step inside the span */
  double t0, t1;
  km_curve_domain(b->c, &t0, &t1);
  double h = 1e-6 * b->span_t;
  double q[1][2];
  double tq = side > 0 ? fmin(t + h, t1) : fmax(t - h, t0);
  km_curve_eval(b->c, tq, 0, q);
  double vx = (q[0][0] - d[0][0]) * (side > 0 ? 1 : -1);
  double vy = (q[0][1] - d[0][1]) * (side > 0 ? 1 : -1);
  double n = hypot(vx, vy);
  if (!(n > 0)) return false;
  dir[0] = vx / n;
  dir[1] = vy / n;
  return true;
}

/* Arc length of a span over [u0, u1] of its variable by the 16-point
 * Gauss-Legendre rule: exact to rounding where the speed is smooth, which
 * is checked (fit_piece) before it is used as the length. */
static double gl16_length(const km__bspan *sp, double u0, double u1) {
  double len = 0.0, mid = 0.5 * (u0 + u1), half = 0.5 * (u1 - u0);
  for (int k = 0; k < 16; k++) {
    double pos[2], d[2];
    km__bspan_eval_u(sp, mid + half * km__gl16_x[k], pos, d);
    len += half * km__gl16_w[k] * sqrt(d[0] * d[0] + d[1] * d[1]);
  }
  return len;
}

/* arc length inside the current span, in its own variable u */
static double span_length(builder *b, double ua, double ub) {
  /* relative to the piece, not the curve: near a sharp tip pieces are
   * many orders of magnitude shorter than the curve and their node
   * positions need their own digits */
  double a = b->span.a, w = b->span.b - a;
  long evals = 0;
  double len =
      km__bspan_length_counted(&b->span, (ua - a) / w, (ub - a) / w,
                               1e-14 * (ub - ua) * b->span_speed, &evals);
  b->work -= evals;
  b->span_work -= evals;
  return len;
}

/* Bernstein coefficients of theta linear in s from th0 to th1. */
static void linear_theta(double th0, double th1, double *coef) {
  for (int j = 0; j <= THETA_DEGREE; j++)
    coef[j] = th0 + (th1 - th0) * j / THETA_DEGREE;
}

/* Cumulative integral of f sampled at the Chebyshev-Lobatto points
 * x_k = -cos(k pi / 14) of [-1, 1] (k = 0..14): F_k = integral from -1 to
 * x_k of the degree-14 interpolant (spectral integration; exact for
 * polynomials of degree 14). The map f -> F is linear: CHEB_CUMULATIVE is
 * its matrix, computed once in extended precision from the Chebyshev
 * series (coefficients by the cosine transform of the samples, integrated
 * term by term with int T_j = T_(j+1) / (2 (j+1)) - T_(j-1) / (2 (j-1)))
 * and rounded to double: applying it costs 225 products where the series
 * cost four transforms. Row k integrates x^j exactly for j <= 14
 * (tests/core/test_numerics.c). */
static const double CHEB_CUMULATIVE[NPTS][NPTS] = {
    {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0},
    {0.010165958539869667, 0.016168943650997653, -0.0017426011461854757, 0.00073470309120945033, -0.00041562931584010953, 0.00027345764196991614, -0.00019797355730203698, 0.00015339668143268933, -0.00012520518137240758, 0.00010659709039090615, -9.4057211937823273e-05, 8.5643559655247662e-05, -8.0242848903362829e-05, 7.7219916975469793e-05, -3.8123092783393159e-05},
    {0.00025392597973738687, 0.061179346046896198, 0.042163385264573888, -0.00657770893780096, 0.0031896133336474096, -0.0019730710018307312, 0.0013843904236156676, -0.0010534607975982116, 0.00085021279144489176, -0.00071853154374692813, 0.00063087740724977878, -0.00057254817687236125, 0.0005353088890466376, -0.00051453356051918062, 0.00025392597973738687},
    {0.0096708394893214797, 0.038522573231919863, 0.11332431699797674, 0.063722467275636782, -0.010288696756490013, 0.0051641537924224309, -0.0033056373940770372, 0.0023938803451811789, -0.0018753464907965221, 0.0015549965401955627, -0.0013482426952070505, 0.0012134467177146019, -0.0011285309144058566, 0.0010815395359096221, -0.00053324214333158235},
    {0.00096541076446478584, 0.05759006960318009, 0.086730153422042711, 0.15775918938658226, 0.08305795091608717, -0.014124033656766092, 0.007370361024812081, -0.0048821463479791034, 0.0036454918811243413, -0.0029372460175106003, 0.0025009001724028363, -0.0022247301897770967, 0.0020540093607697286, -0.0019605929426314336, 0.00096541076446478584},
    {0.0087786657884228337, 0.041070190032571618, 0.10661037121824991, 0.12806490814887653, 0.19535668159003727, 0.097663954420820903, -0.01692659501392841, 0.0090159303062376881, -0.0061062566302965962, 0.0046645635380488347, -0.003846587576747025, 0.0033543071464960921, -0.0030593580623831428, 0.0029009018202655816, -0.0014254158442302278},
    {0.0019935360667786809, 0.055171939780111937, 0.090664765624963936, 0.14827893721930271, 0.16383412160411831, 0.22264740870339461, 0.10774215660382649, -0.019183172333439105, 0.010479848902336072, -0.0072815138191276918, 0.0057071332440078847, -0.0048316533541268641, 0.0043308988422540509, -0.0040688771074941215, 0.0019935360667786809},
    {0.0076661433804290947, 0.043495299033051216, 0.10344298329768975, 0.13320810165423211, 0.18363941237617912, 0.1907462248285427, 0.23917986038092862, 0.11214816929102643, -0.02029834875035522, 0.011305242653840881, -0.0080336233751123597, 0.0064569768413722034, -0.0056225916216375953, 0.0052040882620370214, -0.0025379382522239665},
    {0.0031346690614264473, 0.052768264402582359, 0.093489492833798107, 0.14449673184973119, 0.16989865575705887, 0.20933298130151126, 0.20840166272823732, 0.24347951091549197, 0.11113935502674691, -0.020595941221011032, 0.011771667396948434, -0.0086138587236983949, 0.007155626051088217, -0.0064725524850237004, 0.0031346690614264473},
    {0.0065536209724353558, 0.04579848547482266, 0.1008797497384353, 0.13631077134910824, 0.17945237657781377, 0.19738690394433475, 0.22498776826087, 0.21528040827581518, 0.2358081066445018, 0.10438751306156267, -0.019750892588970538, 0.011600170346727791, -0.0087899795421977588, 0.007629197262516622, -0.0036504606602177055},
    {0.0041627943637403426, 0.050659980237719671, 0.095766382315282436, 0.14188980868538142, 0.1731048888286639, 0.20498871349989417, 0.21523601974944906, 0.22917848493003198, 0.21151115060576131, 0.21617550113914966, 0.092547838084979572, -0.018094110890977937, 0.011090238254009444, -0.0088906823080918528, 0.0041627943637403426},
    {0.0056614472715367107, 0.047617847759178614, 0.098948922590458011, 0.13845163177788972, 0.1769540316962738, 0.200496470942188, 0.22075685812136991, 0.22190245823687169, 0.22218714902465045, 0.19688731368996115, 0.18589448575755677, 0.075942611219967537, -0.015503925321924572, 0.010176814063168373, -0.0045426343611163506},
    {0.0048742791484677412, 0.04921392085560742, 0.097285082787005525, 0.14023762667247669, 0.17497491159381698, 0.20276999902613049, 0.2180312988391285, 0.22534979937965108, 0.21749712120695774, 0.20402453848421431, 0.17241617566741935, 0.14624278743340527, 0.05565700641147827, -0.012479958751807959, 0.0048742791484677412},
    {0.0051663282209885213, 0.048622167378112771, 0.097900634524955524, 0.13957943493594907, 0.17569984621300458, 0.20194487039199266, 0.21900671681194581, 0.22414294190062017, 0.21907948518787543, 0.20177800984041366, 0.17602141831690685, 0.13893037540439487, 0.099562992822237628, 0.032530443644090586, -0.00503775341166454},
    {0.0051282051282051282, 0.048699387295088235, 0.097820391676052165, 0.13966507849560431, 0.17560578900106674, 0.20205146748238356, 0.2188815116305734, 0.22429633858205286, 0.2188815116305734, 0.20205146748238356, 0.17560578900106674, 0.13966507849560431, 0.097820391676052165, 0.048699387295088235, 0.0051282051282051282}
};

void km__cheb_cumulative15(const double *f, double *F) {
  for (int k = 0; k < NPTS; k++) {
    double v = 0.0;
    for (int j = 0; j < NPTS; j++) v += CHEB_CUMULATIVE[k][j] * f[j];
    F[k] = v;
  }
}

/* The allowed |theta - theta~| on a piece of length h whose directions
 * carry a relative rounding error noise: the noise allowance may not cost
 * more than a twentieth of the tolerance in position (|dC| <= h
 * |d theta|). */
static double theta_tol(const builder *b, double noise, double h) {
  return b->tol_theta +
         fmin(2.0 * noise, 0.05 * 4.0 * b->tol_theta * b->L / fmax(h, 1e-300));
}

/* Bernstein coefficients of theta on a piece of length h from its values
 * th at the arc lengths s of the nodes (from the piece's start): the
 * degree-7 interpolant of the even points if it meets the odd ones within
 * tol_here, else theta linear in s if that meets every point. False if
 * neither does. */
/* The Bernstein basis of degree THETA_DEGREE at u in [0, 1] from powers of
 * u and 1 - u (each value to a few ulps, as the recurrence; a quarter of
 * its work, at every node of every fit). */
static void bernstein_row(double u, double row[THETA_DEGREE + 1]) {
  _Static_assert(THETA_DEGREE == 7, "bernstein_row's binomials are of degree 7");
  static const double binom[THETA_DEGREE + 1] = {1, 7, 21, 35, 35, 21, 7, 1};
  double v = 1.0 - u, up[THETA_DEGREE + 1], vp[THETA_DEGREE + 1];
  up[0] = vp[0] = 1.0;
  for (int k = 1; k <= THETA_DEGREE; k++) {
    up[k] = up[k - 1] * u;
    vp[k] = vp[k - 1] * v;
  }
  for (int k = 0; k <= THETA_DEGREE; k++)
    row[k] = binom[k] * up[k] * vp[THETA_DEGREE - k];
}

static bool fit_theta(const double *th, const double *s, double h,
                      double tol_here, double *coef) {
  /* The ends are the first and last nodes, where the interpolant is the
   * end coefficient itself: pinned exactly (theta is continuous across
   * pieces). The rest is the interpolant of theta less the line between
   * the ends, zero at both, whose interior coefficients solve a system of
   * the interior nodes at a fixed size (it runs at every piece of every
   * signature); a straight stretch (theta constant, or linear in s) has
   * exactly zero there, so its kappa is exactly zero. */
  enum { NI = THETA_DEGREE - 1 };
  double A[NI][NI], y[NI], row[THETA_DEGREE + 1], d[NI];
  double th0 = th[0], dth = th[NPTS - 1] - th[0];
  for (int j = 0; j < NI; j++) {
    double u = (s[2 * (j + 1)] - s[0]) / h;
    bernstein_row(u, row);
    for (int k = 0; k < NI; k++) A[j][k] = row[k + 1];
    y[j] = th[2 * (j + 1)] - (th0 + dth * u);
  }
  bool ok = true;
  for (int c = 0; c < NI && ok; c++) {
    int piv = c;
    for (int r = c + 1; r < NI; r++)
      if (fabs(A[r][c]) > fabs(A[piv][c])) piv = r;
    if (!(fabs(A[piv][c]) > 1e-300)) {
      ok = false;
      break;
    }
    if (piv != c) {
      for (int k = 0; k < NI; k++) {
        double tmp = A[c][k];
        A[c][k] = A[piv][k];
        A[piv][k] = tmp;
      }
      double tmp = y[c];
      y[c] = y[piv];
      y[piv] = tmp;
    }
    for (int r = c + 1; r < NI; r++) {
      double f = A[r][c] / A[c][c];
      for (int k = c; k < NI; k++) A[r][k] -= f * A[c][k];
      y[r] -= f * y[c];
    }
  }
  for (int r = NI - 1; ok && r >= 0; r--) {
    double v = y[r];
    for (int k = r + 1; k < NI; k++) v -= A[r][k] * d[k];
    d[r] = v / A[r][r];
  }
  coef[0] = th0;
  coef[THETA_DEGREE] = th[NPTS - 1];
  for (int k = 1; ok && k < THETA_DEGREE; k++)
    coef[k] = th0 + dth * ((double)k / THETA_DEGREE) + d[k - 1];
  /* A strongly varying speed (rational spans with unequal weights)
   * crowds the nodes' images in s, and the interpolant can swing far
   * between them while meeting every check point: its coefficient hull,
   * which bounds it, must stay near the data's range. */
  if (ok) {
    double dlo = th[0], dhi = th[0], clo = coef[0], chi = coef[0];
    for (int k = 1; k < NPTS; k++) {
      dlo = fmin(dlo, th[k]);
      dhi = fmax(dhi, th[k]);
    }
    for (int j = 1; j <= THETA_DEGREE; j++) {
      clo = fmin(clo, coef[j]);
      chi = fmax(chi, coef[j]);
    }
    if (chi - clo > 1.001 * (dhi - dlo) + 4 * tol_here) ok = false;
  }
  for (int k = 1; ok && k < NPTS; k += 2) {
    double u = (s[k] - s[0]) / h;
    if (fabs(km__bern_eval(coef, THETA_DEGREE, u) - th[k]) > tol_here)
      ok = false;
  }
  if (!ok) {
    /* Where theta moves less than its rounding noise (a speed near zero,
     * coordinates far from the origin) the interpolant through noisy
     * values swings and bisecting only samples more noise: theta linear
     * in s is accepted when it meets every node and check point. */
    bool lin = true;
    for (int k = 1; lin && k < NPTS - 1; k++)
      lin = fabs(th[0] + (th[NPTS - 1] - th[0]) * ((s[k] - s[0]) / h) - th[k]) <=
            tol_here;
    if (lin) {
      linear_theta(th[0], th[NPTS - 1], coef);
      ok = true;
    }
  }
  return ok;
}

/* Interpolate theta on the piece [ua, ub] of the current span; bisect in t
 * until the check points agree. *s_at is the arc length at ua on entry
 * and at ub on exit; *theta is the unwrapped angle at ua on entry (whose
 * direction is dir_a) and at ub on exit (direction dir_b). */
/* A turn at arc length s that no piece carries: at a knot, or one
 * concentrated in a length below resolution beside a degenerate end;
 * theta_before is theta just before it. A small turn is handed to a
 * neighbouring piece, so a smooth curve reports no corner: the last
 * piece, if it ends here with no corner between, takes it in its end
 * value (tilting its theta by up to |turn| over its length), or else the
 * next piece starts from theta_before and rises through it (over at most
 * the rest of the curve). Either only where the tilt stays within a
 * twentieth of the tolerance in position; otherwise the turn is a corner,
 * which is exact however small - a turn of 4.2e-12 rad at a knot of a
 * degree-9 curve, dropped as rounding, left its end 1.5e-12 of the length
 * off at a tolerance of 1e-13 of it.
 * At a knot (knot_corner) a turn above rounding is always a corner: a
 * break of the tangent between spans is the curve's shape, however slight.
 * A turn already handed on (pending_start, the end value of the last
 * piece) is in the next piece's rise from there to its own end: a later
 * turn absorbed by the last piece or made a corner moves the value the
 * next piece starts from with it, or it would be counted twice - once
 * there and once in that rise (a hairpin at 1e6 whose tip is rounding
 * noise turned 7.4e-4 rad too far, 1.5e-3 off at the end at a tolerance
 * of 1e-3). */
static km_status take_turn(builder *b, double turn, double s,
                           double theta_before, double t, bool knot_corner) {
  double tol = 4.0 * b->tol_theta * b->L;
  double prev_end = b->m > 0 ? b->s[b->m] : -1.0;
  double prev_h = b->m > 0 ? b->s[b->m] - b->s[b->m - 1] : INFINITY;
  /* inside a span its pieces follow one another; across a knot the last
   * piece is the previous span's, whose end may carry a corner already */
  bool last_adjoins =
      prev_end == s &&
      (knot_corner ? b->ncorners == 0 || b->corners[b->ncorners - 1].s < s
                   : b->m > b->span_first);
  bool small = knot_corner ? fabs(turn) <= CORNER_NOISE : fabs(turn) < 1e-3;
  if (small && last_adjoins && fabs(turn) * prev_h <= 0.05 * tol) {
    b->th[(b->m - 1) * (THETA_DEGREE + 1) + THETA_DEGREE] += turn;
    if (!isnan(b->pending_start)) b->pending_start += turn;
    return KM_OK;
  }
  if ((small || !knot_corner) && fabs(turn) * (b->L - s) <= 0.05 * tol) {
    if (isnan(b->pending_start)) b->pending_start = theta_before;
    return KM_OK;
  }
  turn = km__wrap_angle(turn);
  km_status st = push_corner(b, s, turn, t);
  if (st) return st;
  if (!isnan(b->pending_start)) b->pending_start += turn;
  return KM_OK;
}

static km_status fit_piece(builder *b, double ua, double ub, double known_len,
                           double *s_at, double *theta, const double dir_a[2],
                           const double dir_b[2], int depth) {
  if (km__poll_stop(b->poll, 2 * NPTS)) return km__stopped(b->err);
  if (b->span_work < 0)
    return km__fail(b->err, KM_ELIMIT, KM_FIELD_TOLERANCE, -1, ua,
                    "the curve needs too much work at tolerance %g near "
                    "parameter t = %g (its directions there are not "
                    "resolved in double precision): loosen the tolerance",
                    b->tol, ua);
  if (b->work < 0)
    return km__fail(b->err, KM_ELIMIT, KM_FIELD_TOLERANCE, -1, ua,
                    "the curve needs too many pieces at tolerance %g (the "
                    "work ran out near parameter t = %g): loosen the "
                    "tolerance",
                    b->tol, ua);
  /* the nodes' evaluations, and the fit, which costs about as much again
   * (an 8 x 8 solve, the checks, an arc tangent a node) */
  b->work -= 2 * NPTS;
  b->span_work -= 2 * NPTS;
  double t[NPTS], th[NPTS], s[NPTS], dir[NPTS][2];
  double mid = 0.5 * (ua + ub), half = 0.5 * (ub - ua);
  for (int k = 0; k < NPTS; k++)
    t[k] = mid - half * COS14[k];
  t[0] = ua;
  t[NPTS - 1] = ub;
  dir[0][0] = dir_a[0];
  dir[0][1] = dir_a[1];
  dir[NPTS - 1][0] = dir_b[0];
  dir[NPTS - 1][1] = dir_b[1];
  double speed[NPTS], F[NPTS], rounding[NPTS];
  for (int k = 0; k < NPTS; k++) {
    double d[2][2], wf;
    km__bspan_eval(&b->span, t[k], d[0], d[1], &wf);
    double n = sqrt(d[1][0] * d[1][0] + d[1][1] * d[1][1]);
    speed[k] = n;
    /* the rounding of C' here: the points' times the weight factor of a
     * rational span (at 1e6, where a weight of 0.1 meets one of 100, a
     * thousand times the polynomial share: directions there spun three
     * whole turns within 1e-10 of t and were refused as a cusp) */
    rounding[k] = b->deriv_noise * fmax(wf, 1.0);
    if (k == 0 || k == NPTS - 1) continue;
    /* C' well above its rounding error is the tangent, however small;
     * below that its direction is noise (the speed vanishes there in
     * exact arithmetic, or nearly), and the last reliable direction
     * stands in: across such a stretch, far shorter than the rounding of
     * the coordinates, only the turn between its ends counts */
    if (n > 16.0 * rounding[k]) {
      dir[k][0] = d[1][0] / n;
      dir[k][1] = d[1][1] / n;
    } else {
      dir[k][0] = dir[k - 1][0];
      dir[k][1] = dir[k - 1][1];
    }
  }
  /* Directions from C' carry rounding error deriv_noise / |C'|: where the
   * speed nearly vanishes that exceeds any tolerance, and asking for more
   * would only bisect into noise. */
  double noise = 0.0;
  for (int k = 0; k < NPTS; k++)
    if (speed[k] > 0) noise = fmax(noise, rounding[k] / speed[k]);
  if (noise > 0.1) noise = 0.1;
  /* unwrap, watching for steps too large to interpolate */
  bool coarse = false;
  double big_step = 0.0;
  th[0] = *theta;
  for (int k = 1; k < NPTS; k++) {
    double step = atan2(dir[k - 1][0] * dir[k][1] - dir[k - 1][1] * dir[k][0],
                        dir[k - 1][0] * dir[k][0] + dir[k - 1][1] * dir[k][1]);
    th[k] = th[k - 1] + step;
    if (fabs(step) > 0.5 * KM_PI) coarse = true;
    big_step = fmax(big_step, fabs(step));
  }
  /* arc length at every point: spectral integration of the speed at the
   * nodes, checked against adaptive quadrature of the whole piece */
  km__cheb_cumulative15(speed, F);
  /* s[] holds arc length from the piece's start: near a sharp tip a piece
   * can be shorter than the rounding unit of the absolute arc length */
  for (int k = 0; k < NPTS; k++) s[k] = half * F[k];
  double h = s[NPTS - 1] - s[0];
  /* A whole span comes with its length by 16-point Gauss-Legendre
   * (known_len), and a piece inside it is measured by the same rule:
   * where the spectral length at these 15 other nodes agrees to 1e-13
   * both rules have resolved the speed, and that is the length; elsewhere
   * it is measured adaptively, for the span too. */
  double ref = known_len;
  if (!(known_len > 0)) {
    double w = b->span.b - b->span.a;
    ref = gl16_length(&b->span, (ua - b->span.a) / w, (ub - b->span.a) / w);
    b->work -= 16;
    b->span_work -= 16;
  }
  /* Two rules can agree and both miss a feature narrower than their nodes'
   * spacing: a speed that dips toward zero between nodes (a near-cusp,
   * a degenerate leg) or peaks (weights varying by decades). The
   * agreement counts only where the speed is of one scale over the nodes
   * and the weights are too. */
  double smin = INFINITY, smax = 0.0;
  for (int k = 0; k < NPTS; k++) {
    smin = fmin(smin, speed[k]);
    smax = fmax(smax, speed[k]);
  }
  bool agree = smax <= 4.0 * smin && b->span_weight_ratio <= 2.0 &&
               fabs(h - ref) <= 1e-13 * ref + b->deriv_noise * (ub - ua);
  bool tiny_t = (ub - ua) < 1e-13 * b->span_t;
  /* Where they disagree the speed is not resolved over the piece, and
   * theta seldom is: a piece inside the span that fails with the 16-point
   * length and the nodes' spectral positions is bisected before adaptive
   * quadrature measures it (work its halves would repeat). Only a piece
   * that could be taken is measured: not one that cannot be bisected, has
   * noisy directions, or may be of zero length. */
  if (!agree && !(known_len > 0) && depth < KM_MAX_REFINE_DEPTH && !tiny_t &&
      noise < 0.1 && fmin(h, ref) > 1e-12 * b->L) {
    double sa[NPTS], ca[THETA_DEGREE + 1];
    for (int k = 0; k < NPTS; k++) sa[k] = s[k] * (ref / h);
    if (coarse || !fit_theta(th, sa, ref, theta_tol(b, noise, ref), ca)) {
      double dm[2] = {dir[NPTS / 2][0], dir[NPTS / 2][1]};
      km_status st =
          fit_piece(b, ua, mid, 0.0, s_at, theta, dir_a, dm, depth + 1);
      if (st) return st;
      return fit_piece(b, mid, ub, 0.0, s_at, theta, dm, dir_b, depth + 1);
    }
  }
  if (!agree) {
    ref = span_length(b, ua, ub);
    if (known_len > 0) b->span_len = ref;
  }
  if (isnan(ref))
    return km__fail(b->err, KM_ENOCONVERGE, KM_FIELD_CONTROL_POINTS, -1, ua,
                    "the arc length near parameter t = %g cannot be computed "
                    "to full precision",
                    ua);
  /* the lengths agree to their rounding: the speed's, deriv_noise, over
   * the piece, and a few ulps; otherwise the speed is not resolved by the
   * nodes (a near-degenerate leg, a sharp tip) and their positions are
   * only approximate until measured one by one, below */
  bool nodes_exact =
      fabs(h - ref) <= 1e-12 * ref + 1e-16 * b->L + b->deriv_noise * (ub - ua);
  if (!nodes_exact && h > 0)
    for (int k = 1; k < NPTS - 1; k++) s[k] *= ref / h;
  s[NPTS - 1] = ref;
  h = ref;
  double tol_here = theta_tol(b, noise, h);
  if (!(h > 1e-15 * b->L)) {
    /* a piece of (numerically) zero length: whatever turn it hides acts
     * as a corner at this point */
    double turn = th[NPTS - 1] - th[0];
    if (fabs(turn) > KM_PI - CUSP_MARGIN)
      return km__fail(b->err, KM_ECUSP, KM_FIELD_CONTROL_POINTS, -1, mid,
                      "the tangent reverses at parameter t = %g (a cusp): "
                      "the curve is not regular there",
                      mid);
    /* Bisection toward a degenerate end ends in such pieces: the turning
     * they carry is real (kappa ~ 1/sqrt(s) there) but concentrated in a
     * length below resolution; a small one goes into a neighbour. */
    km_status st = take_turn(b, turn, *s_at, th[0], mid, false);
    if (st) return st;
    *theta = th[NPTS - 1];
    return KM_OK;
  }
  if (coarse && tiny_t && big_step > KM_PI - 1e-3)
    return km__fail(b->err, KM_ECUSP, KM_FIELD_CONTROL_POINTS, -1, mid,
                    "the tangent reverses at parameter t = %g (a cusp): the "
                    "curve is not regular there",
                    mid);
  double coef[THETA_DEGREE + 1];
  bool ok = !coarse && fit_theta(th, s, h, tol_here, coef);
  /* Measuring the nodes one by one costs fourteen adaptive quadratures: a
   * piece whose theta fails at their approximate positions is bisected
   * without them (where the speed is unresolved theta nearly always is,
   * and halves resolve both). A piece about to be taken, or that cannot
   * be bisected, or whose directions are noise, is judged at the exact
   * positions. */
  if (!nodes_exact && !coarse &&
      (ok || noise >= 0.1 || depth >= KM_MAX_REFINE_DEPTH || tiny_t)) {
    for (int k = 1; k < NPTS - 1; k++)
      s[k] = s[k - 1] + span_length(b, t[k - 1], t[k]);
    if (isnan(s[NPTS - 2]))
      return km__fail(b->err, KM_ENOCONVERGE, KM_FIELD_CONTROL_POINTS, -1, ua,
                      "the arc length near parameter t = %g cannot be "
                      "computed to full precision",
                      ua);
    ok = fit_theta(th, s, h, tol_here, coef);
  }
  /* The checks hold theta only near the nodes, which are Chebyshev in t:
   * where the speed varies by decades over the piece (a rational end
   * whose weight is small beside its neighbour's, which the curve leaves
   * in a boundary layer of the parameter) nearly all of the length lies
   * between two nodes, and the interpolant is free there within the range
   * of theta. A rational cubic hairpin at 1e15 with weights 0.01 to 100
   * put nearly all of a 7.5e14 piece past its last interior nodes, and
   * its theta stayed 8e-6 rad behind the curve's (1.3e-6 asked) over most
   * of it: the end missed by 3.4e9 at a tolerance of 1e9. Such a piece is
   * bisected,
   * which brings its parts to one scale of speed; Chebyshev nodes of a
   * speed within a factor 4 leave gaps below a fifth of the length. */
  if (ok && depth < KM_MAX_REFINE_DEPTH && !tiny_t) {
    double gap = 0.0;
    for (int k = 1; k < NPTS; k++) gap = fmax(gap, s[k] - s[k - 1]);
    if (gap > 0.25 * h) ok = false;
  }
  if (!ok && noise >= 0.1 && big_step < KM_PI - 0.5 &&
      2.0 * h <= b->free_len) {
    /* directions that are noise, on a piece short enough (see free_len) */
    b->free_len -= 2.0 * h;
    linear_theta(th[0], th[NPTS - 1], coef);
    ok = true;
  }
  if (!ok && (depth >= KM_MAX_REFINE_DEPTH || tiny_t)) {
    /* cannot resolve further: acceptable only if theta barely moves */
    double lo = th[0], hi = th[0];
    for (int k = 1; k < NPTS; k++) {
      lo = fmin(lo, th[k]);
      hi = fmax(hi, th[k]);
    }
    if (hi - lo > 4 * tol_here)
      return km__fail(b->err, KM_ENOCONVERGE, KM_FIELD_CONTROL_POINTS, -1,
                      mid,
                      "curvature could not be resolved near parameter t = "
                      "%g",
                      mid);
    linear_theta(th[0], th[NPTS - 1], coef);
    ok = true;
  }
  if (ok) {
    if (!isnan(b->pending_start)) {
      coef[0] = b->pending_start;
      b->pending_start = NAN;
    }
    km_status st = push_piece(b, *s_at, *s_at + h, coef);
    if (st) return st;
    *s_at += h;
    *theta = th[NPTS - 1];
    return KM_OK;
  }
  /* bisect in t */
  double dm[2] = {dir[NPTS / 2][0], dir[NPTS / 2][1]}; /* the node at mid */
  km_status st = fit_piece(b, ua, mid, 0.0, s_at, theta, dir_a, dm, depth + 1);
  if (st) return st;
  return fit_piece(b, mid, ub, 0.0, s_at, theta, dm, dir_b, depth + 1);
}

/* The turn between two spans at parameter t, arc length s: a cusp where
 * the tangent reverses. */
static km_status check_cusp(builder *b, double turn, double t, double s) {
  if (fabs(turn) > KM_PI - CUSP_MARGIN)
    return km__fail(b->err, KM_ECUSP, KM_FIELD_KNOTS, -1, t,
                    "the tangent reverses at parameter t = %g (arc length "
                    "%g): a cusp, the curve is not regular there",
                    t, s);
  return KM_OK;
}

km_status km_signature_compute(const km_curve *c, double tol,
                               km_signature *out, km_error *err) {
  return km__signature_compute(c, tol, 1e-5, NULL, out, err);
}

km_status km_signature_compute_until(const km_curve *c, double tol,
                                     const km_stop *stop, km_signature *out,
                                     km_error *err) {
  km__poll poll;
  km__poll_init(&poll, stop);
  return km__signature_compute(c, tol, 1e-5, &poll, out, err);
}

km_status km__signature_compute(const km_curve *c, double tol, double rel_tol,
                                km__poll *poll, km_signature *out,
                                km_error *err) {
  if (!c || !c->knots || !c->cp || c->degree < KM_MIN_DEGREE ||
      c->degree > KM_MAX_DEGREE || c->n < (size_t)c->degree + 1)
    return km__fail(err, KM_EINVAL, KM_FIELD_NONE, -1, NAN,
                    "not a valid curve (empty or never created)");
  builder b;
  memset(&b, 0, sizeof b);
  b.c = c;
  b.err = err;
  b.poll = poll;
  b.pending_start = NAN;
  b.work = KM_SIGNATURE_WORK_BASE + KM_SIGNATURE_WORK_PER_POINT * (long)c->n;
  km_status st = KM_OK;
  km_pp kp;
  km__pp_init(&kp);
  double t0, t1;
  double *span_len = malloc(c->n * sizeof(double));
  if (!span_len)
    return km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
  /* the spans in Bezier form, made once for both passes (a few hundred
   * bytes each: kept for curves of up to SPAN_CACHE control points) */
  km__bspan *spans = c->n <= SPAN_CACHE ? malloc(c->n * sizeof *spans) : NULL;
  double poly = 0.0;
  for (size_t i = 1; i < c->n; i++)
    poly += hypot(c->cp[2 * i] - c->cp[2 * i - 2],
                  c->cp[2 * i + 1] - c->cp[2 * i - 1]);
  /* Span lengths by one 16-point rule first: they scale the tolerance and
   * are confirmed (or measured adaptively) while the span is fitted. A
   * span whose estimate is at the scale of its rounding is measured at
   * once: whether it is a point decides whether it is fitted at all. */
  double L = 0.0;
  for (size_t i = 0; i < c->n; i++) span_len[i] = 0.0;
  for (size_t i = (size_t)c->degree; i < c->n && poly > 0; i++) {
    if (c->knots[i + 1] > c->knots[i]) {
      km__bspan local, *spp = spans ? &spans[i] : &local;
      km__bspan_make(spp, c, i);
      const km__bspan sp = *spp;
      long evals = 0;
      double est = gl16_length(&sp, 0.0, 1.0);
      b.work -= 16;
      if (!(est > 1e-9 * poly) || !(est > 1e6 * km__bspan_noise(&sp)))
        est = km__bspan_length_counted(&sp, 0.0, 1.0, 1e-15 * poly,
                                       &evals);
      span_len[i] = est;
      b.work -= evals;
      if (km__poll_stop(poll, 16 + evals)) {
        st = km__stopped(err);
        goto cleanup;
      }
    }
    L += span_len[i];
    if (isnan(L)) break; /* reported below; no more work for this curve */
  }
  km_curve_domain(c, &t0, &t1);
  double extent = 0.0;
  for (size_t i = 0; i < 2 * c->n; i++) extent = fmax(extent, fabs(c->cp[i]));
  if (isnan(L)) {
    st = km__fail(err, KM_ENOCONVERGE, KM_FIELD_CONTROL_POINTS, -1, NAN,
                  "the arc length cannot be computed to full precision (the "
                  "speed nearly vanishes inside a span)");
    goto cleanup;
  }
  if (!(L > 1e-13 * extent) || !(L > 1e-300)) {
    st = km__fail(err, KM_EDEGENERATE, KM_FIELD_CONTROL_POINTS, -1, NAN,
                  "the curve has zero length");
    goto cleanup;
  }
  b.L = L;
  if (!(tol > 0) || !isfinite(tol)) tol = rel_tol * L;
  /* Nor below the rounding of the curve itself (limits.h). A curve too
   * small for its distance from the origin to meet even the default
   * tolerance (1e-5 of its length) is refused: its shape is rounding
   * noise at that scale. */
  double tol_min = fmax(KM_MIN_RELATIVE_TOLERANCE * L,
                        KM_MIN_TOLERANCE_ULPS * DBL_EPSILON * c->degree * extent);
  if (tol < tol_min) {
    if (tol_min > 1e-5 * L) {
      st = km__fail(err, KM_ERANGE, KM_FIELD_CONTROL_POINTS, -1, NAN,
                    "the curve (length %g) is too small for its distance "
                    "from the origin (coordinates up to %g): its shape is "
                    "known to less than a tolerance of %g; move it nearer "
                    "the origin",
                    L, extent, tol_min);
      goto cleanup;
    }
    tol = tol_min;
  }
  /* Where no interpolant meets the checks because the directions are
   * rounding noise (off by a tenth of a radian or more somewhere: a speed
   * within ten times its rounding error) but do not reverse (a cusp is
   * refused, not smoothed), a short piece may be taken as turning
   * uniformly between its end directions: that moves the curve by at most
   * twice its length, and all such pieces together may cost a twentieth
   * of the tolerance. */
  b.free_len = 0.05 * tol;
  double point_len = 0.25 * tol; /* twice the length of spans taken as
                                    points, see below */
  b.tol = tol;
  b.tol_theta = fmin(0.25 * tol / L, 1e-3);

  double s_at = 0.0, theta = 0.0, start_angle = 0.0;
  double prev_dir[2] = {0, 0}, first_dir[2] = {0, 0};
  bool have_prev = false;
  size_t p = (size_t)c->degree;
  for (size_t i = p; i < c->n; i++) {
    double ua = c->knots[i], ub = c->knots[i + 1];
    if (!(ub > ua)) continue;
    double len = span_len[i];
    if (!(len > 1e-15 * L)) continue; /* a span that is a single point */
    if (spans)
      b.span = spans[i];
    else
      km__bspan_make(&b.span, c, i);
    /* or one whose length is its rounding error: equal control points
     * far from the origin; the turn across it is checked as a corner.
     * Each such span is lost from the pieces (up to its length in
     * position) and its length then stretches the others (as much
     * again), so together they may cost a quarter of the tolerance;
     * past that the spans are a real curve whose shape its coordinates
     * do not carry, refused rather than taken for a point. */
    double noise = km__bspan_noise(&b.span);
    if (!(len > noise)) {
      if (2.0 * len <= point_len) {
        point_len -= 2.0 * len;
        continue;
      }
      st = km__fail(err, KM_ERANGE, KM_FIELD_CONTROL_POINTS, -1, ua,
                    "the spans near parameter t = %g are no longer than "
                    "the rounding of their coordinates (%g, up to %g): "
                    "move the curve nearer the origin or use fewer, "
                    "longer spans",
                    ua, noise, extent);
      goto cleanup;
    }
    b.span_t = ub - ua;
    b.span_speed = len / (ub - ua);
    {
      double wlo = INFINITY, whi = 0.0;
      for (int q = 0; q <= b.span.degree; q++) {
        wlo = fmin(wlo, b.span.h[q][2]);
        whi = fmax(whi, b.span.h[q][2]);
      }
      b.span_weight_ratio = b.span.rational && wlo > 0 ? whi / wlo : 1.0;
    }
    b.span_len = len;
    b.deriv_noise = noise / (ub - ua); /* of |C'| */
    b.span_work = KM_SIGNATURE_WORK_PER_SPAN;
    double da[2], db[2];
    if (!tangent_limit(&b, ua, 1, da) || !tangent_limit(&b, ub, -1, db)) {
      st = km__fail(err, KM_EDEGENERATE, KM_FIELD_CONTROL_POINTS, -1, ua,
                    "no tangent direction near parameter t = %g", ua);
      goto cleanup;
    }
    if (!have_prev) {
      start_angle = atan2(da[1], da[0]);
      theta = start_angle;
      first_dir[0] = da[0];
      first_dir[1] = da[1];
      have_prev = true;
    } else {
      double turn = atan2(prev_dir[0] * da[1] - prev_dir[1] * da[0],
                          prev_dir[0] * da[0] + prev_dir[1] * da[1]);
      st = check_cusp(&b, turn, ua, s_at);
      if (st) goto cleanup;
      st = take_turn(&b, turn, s_at, theta, ua, true);
      if (st) goto cleanup;
      theta += turn;
    }
    size_t m0 = b.m, c0 = b.ncorners;
    b.span_first = m0;
    double s_start = s_at;
    st = fit_piece(&b, ua, ub, len, &s_at, &theta, da, db, 0);
    if (st) goto cleanup;
    L += b.span_len - len; /* the confirmed length replaces the estimate */
    len = b.span_len;
    /* the span's pieces must end exactly at its arc length: knots are
     * breakpoints at their exact images */
    if (b.m > m0 && s_at - s_start > 0) {
      double f = len / (s_at - s_start), s_end = s_start + len;
      for (size_t q = m0 + 1; q <= b.m; q++) b.s[q] = s_start + (b.s[q] - s_start) * f;
      /* a corner at the span's end (a turn hidden below resolution next
       * to a degenerate end) stays exactly on that break: one ulp off it
       * would leave a piece one ulp long where kappa may be huge */
      for (size_t q = c0; q < b.ncorners; q++)
        if (b.corners[q].s >= s_at)
          b.corners[q].s = s_end;
        else if (b.corners[q].s > s_start)
          b.corners[q].s = s_start + (b.corners[q].s - s_start) * f;
      s_at = s_end;
      b.s[b.m] = s_at;
    }
    prev_dir[0] = db[0];
    prev_dir[1] = db[1];
  }
  if (!isnan(b.pending_start) && b.m > 0) {
    /* a turn handed on to a next piece that never came (a piece below
     * resolution at the curve's very end): it is a corner at the end,
     * where its position costs nothing - the pieces must end on the
     * direction the curve ends with, or a closed curve's turning is off */
    double end = b.th[(b.m - 1) * (THETA_DEGREE + 1) + THETA_DEGREE];
    double turn = km__wrap_angle(theta - end);
    if (fabs(turn) > CORNER_NOISE) {
      st = push_corner(&b, s_at, turn, t1);
      if (st) goto cleanup;
    }
    b.pending_start = NAN;
  }
  if (b.m == 0) {
    st = km__fail(err, KM_EDEGENERATE, KM_FIELD_CONTROL_POINTS, -1, NAN,
                  "the curve has zero length");
    goto cleanup;
  }
  if (c->closed) {
    double turn = atan2(prev_dir[0] * first_dir[1] - prev_dir[1] * first_dir[0],
                        prev_dir[0] * first_dir[0] + prev_dir[1] * first_dir[1]);
    /* at the seam a turn's position costs nothing: rounding is dropped */
    st = check_cusp(&b, turn, t1, s_at);
    if (st) goto cleanup;
    if (fabs(turn) > CORNER_NOISE) {
      st = push_corner(&b, s_at, turn, t1);
      if (st) goto cleanup;
    }
  }
  /* the pieces' arc lengths sum to the total up to rounding: snap */
  double s_last = b.s[b.m], scale = L / s_last;
  for (size_t i = 0; i <= b.m; i++) b.s[i] *= scale;
  for (size_t i = 0; i < b.ncorners; i++) /* the seam's corner is at L */
    b.corners[i].s = b.corners[i].s >= s_last ? L : fmin(b.corners[i].s * scale, L);
  b.s[b.m] = L;
  /* kappa = d theta / ds on every piece */
  st = km__pp_alloc(&kp, THETA_DEGREE - 1, b.m);
  if (st) {
    st = km__fail(err, st, KM_FIELD_NONE, -1, NAN, NULL);
    goto cleanup;
  }
  for (size_t i = 0; i < b.m; i++) {
    kp.x[i] = b.s[i];
    km__bern_derivative(b.th + i * (THETA_DEGREE + 1), THETA_DEGREE,
                        b.s[i + 1] - b.s[i], kp.c + i * THETA_DEGREE);
  }
  kp.x[b.m] = L;
  km_signature r;
  km_signature_init(&r);
  st = km__pp_to_fn(&r.kappa, &kp);
  if (st) {
    st = km__fail(err, st, KM_FIELD_NONE, -1, NAN, NULL);
    goto cleanup;
  }
  double d0[1][2];
  km_curve_eval(c, t0, 0, d0);
  r.length = L;
  r.start[0] = d0[0][0];
  r.start[1] = d0[0][1];
  r.angle = start_angle;
  r.closed = c->closed;
  r.corners = b.corners;
  r.ncorners = b.ncorners;
  b.corners = NULL;
  double turning = km_fn_integral(&r.kappa);
  for (size_t i = 0; i < r.ncorners; i++) turning += r.corners[i].turn;
  r.turning = turning;
  *out = r;
cleanup:
  km__pp_free(&kp);
  free(span_len);
  free(spans);
  free(b.s);
  free(b.th);
  free(b.corners);
  return st;
}
