/* signature_theta.c - theta(s) on one piece of a span: nodes, arc
 * lengths, the degree-7 interpolant and its checks, bisection.
 *
 * DESIGN. A piece's nodes are the 15 Chebyshev-Lobatto points in t; their
 * arc lengths come from spectral integration of the speed there, trusted
 * where they agree with a 16-point Gauss-Legendre length, and otherwise
 * measured adaptively. theta is interpolated at the even nodes and
 * checked at the odd ones; a piece that fails is bisected in t.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "km/limits.h"
#include "signature_builder.h"

/* cos(m pi / 14), m = 0..14: the Chebyshev-Lobatto abscissae of
 * KM__THETA_NODES = 15 points */
static const double COS14[KM__THETA_NODES] = {1.0,
                                              0.9749279121818236,
                                              0.9009688679024191,
                                              0.7818314824680298,
                                              0.6234898018587336,
                                              0.4338837391175582,
                                              0.22252093395631445,
                                              6.123233995736766e-17,
                                              -0.22252093395631434,
                                              -0.43388373911755806,
                                              -0.6234898018587335,
                                              -0.7818314824680295,
                                              -0.900968867902419,
                                              -0.9749279121818237,
                                              -1.0};

double km__sig_gl16_length(const km__bspan *sp, double u0, double u1) {
  double len = 0.0, mid = 0.5 * (u0 + u1), half = 0.5 * (u1 - u0);
  for (int k = 0; k < 16; k++) {
    double pos[2], d[2];
    km__bspan_eval_u(sp, mid + half * km__gl16_x[k], pos, d);
    len += half * km__gl16_w[k] * sqrt(d[0] * d[0] + d[1] * d[1]);
  }
  return len;
}

/* arc length inside the current span, in its own variable u */
static double span_length(km__sig_builder *b, double ua, double ub) {
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
  for (int j = 0; j <= KM__THETA_DEGREE; j++)
    coef[j] = th0 + (th1 - th0) * j / KM__THETA_DEGREE;
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
static const double CHEB_CUMULATIVE[KM__THETA_NODES][KM__THETA_NODES] = {
    {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0},
    {0.010165958539869667, 0.016168943650997653, -0.0017426011461854757,
     0.00073470309120945033, -0.00041562931584010953, 0.00027345764196991614,
     -0.00019797355730203698, 0.00015339668143268933, -0.00012520518137240758,
     0.00010659709039090615, -9.4057211937823273e-05, 8.5643559655247662e-05,
     -8.0242848903362829e-05, 7.7219916975469793e-05, -3.8123092783393159e-05},
    {0.00025392597973738687, 0.061179346046896198, 0.042163385264573888,
     -0.00657770893780096, 0.0031896133336474096, -0.0019730710018307312,
     0.0013843904236156676, -0.0010534607975982116, 0.00085021279144489176,
     -0.00071853154374692813, 0.00063087740724977878, -0.00057254817687236125,
     0.0005353088890466376, -0.00051453356051918062, 0.00025392597973738687},
    {0.0096708394893214797, 0.038522573231919863, 0.11332431699797674,
     0.063722467275636782, -0.010288696756490013, 0.0051641537924224309,
     -0.0033056373940770372, 0.0023938803451811789, -0.0018753464907965221,
     0.0015549965401955627, -0.0013482426952070505, 0.0012134467177146019,
     -0.0011285309144058566, 0.0010815395359096221, -0.00053324214333158235},
    {0.00096541076446478584, 0.05759006960318009, 0.086730153422042711,
     0.15775918938658226, 0.08305795091608717, -0.014124033656766092,
     0.007370361024812081, -0.0048821463479791034, 0.0036454918811243413,
     -0.0029372460175106003, 0.0025009001724028363, -0.0022247301897770967,
     0.0020540093607697286, -0.0019605929426314336, 0.00096541076446478584},
    {0.0087786657884228337, 0.041070190032571618, 0.10661037121824991,
     0.12806490814887653, 0.19535668159003727, 0.097663954420820903,
     -0.01692659501392841, 0.0090159303062376881, -0.0061062566302965962,
     0.0046645635380488347, -0.003846587576747025, 0.0033543071464960921,
     -0.0030593580623831428, 0.0029009018202655816, -0.0014254158442302278},
    {0.0019935360667786809, 0.055171939780111937, 0.090664765624963936,
     0.14827893721930271, 0.16383412160411831, 0.22264740870339461,
     0.10774215660382649, -0.019183172333439105, 0.010479848902336072,
     -0.0072815138191276918, 0.0057071332440078847, -0.0048316533541268641,
     0.0043308988422540509, -0.0040688771074941215, 0.0019935360667786809},
    {0.0076661433804290947, 0.043495299033051216, 0.10344298329768975,
     0.13320810165423211, 0.18363941237617912, 0.1907462248285427,
     0.23917986038092862, 0.11214816929102643, -0.02029834875035522,
     0.011305242653840881, -0.0080336233751123597, 0.0064569768413722034,
     -0.0056225916216375953, 0.0052040882620370214, -0.0025379382522239665},
    {0.0031346690614264473, 0.052768264402582359, 0.093489492833798107,
     0.14449673184973119, 0.16989865575705887, 0.20933298130151126,
     0.20840166272823732, 0.24347951091549197, 0.11113935502674691,
     -0.020595941221011032, 0.011771667396948434, -0.0086138587236983949,
     0.007155626051088217, -0.0064725524850237004, 0.0031346690614264473},
    {0.0065536209724353558, 0.04579848547482266, 0.1008797497384353,
     0.13631077134910824, 0.17945237657781377, 0.19738690394433475,
     0.22498776826087, 0.21528040827581518, 0.2358081066445018,
     0.10438751306156267, -0.019750892588970538, 0.011600170346727791,
     -0.0087899795421977588, 0.007629197262516622, -0.0036504606602177055},
    {0.0041627943637403426, 0.050659980237719671, 0.095766382315282436,
     0.14188980868538142, 0.1731048888286639, 0.20498871349989417,
     0.21523601974944906, 0.22917848493003198, 0.21151115060576131,
     0.21617550113914966, 0.092547838084979572, -0.018094110890977937,
     0.011090238254009444, -0.0088906823080918528, 0.0041627943637403426},
    {0.0056614472715367107, 0.047617847759178614, 0.098948922590458011,
     0.13845163177788972, 0.1769540316962738, 0.200496470942188,
     0.22075685812136991, 0.22190245823687169, 0.22218714902465045,
     0.19688731368996115, 0.18589448575755677, 0.075942611219967537,
     -0.015503925321924572, 0.010176814063168373, -0.0045426343611163506},
    {0.0048742791484677412, 0.04921392085560742, 0.097285082787005525,
     0.14023762667247669, 0.17497491159381698, 0.20276999902613049,
     0.2180312988391285, 0.22534979937965108, 0.21749712120695774,
     0.20402453848421431, 0.17241617566741935, 0.14624278743340527,
     0.05565700641147827, -0.012479958751807959, 0.0048742791484677412},
    {0.0051663282209885213, 0.048622167378112771, 0.097900634524955524,
     0.13957943493594907, 0.17569984621300458, 0.20194487039199266,
     0.21900671681194581, 0.22414294190062017, 0.21907948518787543,
     0.20177800984041366, 0.17602141831690685, 0.13893037540439487,
     0.099562992822237628, 0.032530443644090586, -0.00503775341166454},
    {0.0051282051282051282, 0.048699387295088235, 0.097820391676052165,
     0.13966507849560431, 0.17560578900106674, 0.20205146748238356,
     0.2188815116305734, 0.22429633858205286, 0.2188815116305734,
     0.20205146748238356, 0.17560578900106674, 0.13966507849560431,
     0.097820391676052165, 0.048699387295088235, 0.0051282051282051282}};

void km__cheb_cumulative15(const double *f, double *F) {
  for (int k = 0; k < KM__THETA_NODES; k++) {
    double v = 0.0;
    for (int j = 0; j < KM__THETA_NODES; j++) v += CHEB_CUMULATIVE[k][j] * f[j];
    F[k] = v;
  }
}

/* The allowed |theta - theta~| on a piece of length h whose directions
 * carry a relative rounding error noise: the noise allowance may not cost
 * more than a twentieth of the tolerance in position (|dC| <= h
 * |d theta|). */
static double theta_tol(const km__sig_builder *b, double noise, double h) {
  return b->tol_theta +
         fmin(2.0 * noise, 0.05 * 4.0 * b->tol_theta * b->L / fmax(h, 1e-300));
}

/* Bernstein coefficients of theta on a piece of length h from its values
 * th at the arc lengths s of the nodes (from the piece's start): the
 * degree-7 interpolant of the even points if it meets the odd ones within
 * tol_here, else theta linear in s if that meets every point. False if
 * neither does. */
/* The Bernstein basis of degree KM__THETA_DEGREE at u in [0, 1] from powers of
 * u and 1 - u (each value to a few ulps, as the recurrence; a quarter of
 * its work, at every node of every fit). */
static void bernstein_row(double u, double row[KM__THETA_DEGREE + 1]) {
  _Static_assert(KM__THETA_DEGREE == 7,
                 "bernstein_row's binomials are of degree 7");
  static const double binom[KM__THETA_DEGREE + 1] = {1,  7,  21, 35,
                                                     35, 21, 7,  1};
  double v = 1.0 - u, up[KM__THETA_DEGREE + 1], vp[KM__THETA_DEGREE + 1];
  up[0] = vp[0] = 1.0;
  for (int k = 1; k <= KM__THETA_DEGREE; k++) {
    up[k] = up[k - 1] * u;
    vp[k] = vp[k - 1] * v;
  }
  for (int k = 0; k <= KM__THETA_DEGREE; k++)
    row[k] = binom[k] * up[k] * vp[KM__THETA_DEGREE - k];
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
  enum { NI = KM__THETA_DEGREE - 1 };
  double A[NI * NI], d[NI], row[KM__THETA_DEGREE + 1];
  double th0 = th[0], dth = th[KM__THETA_NODES - 1] - th[0];
  for (int j = 0; j < NI; j++) {
    double u = (s[2 * (j + 1)] - s[0]) / h;
    bernstein_row(u, row);
    for (int k = 0; k < NI; k++) A[j * NI + k] = row[k + 1];
    d[j] = th[2 * (j + 1)] - (th0 + dth * u);
  }
  bool ok = km__solve_dense(A, d, NI);
  coef[0] = th0;
  coef[KM__THETA_DEGREE] = th[KM__THETA_NODES - 1];
  for (int k = 1; ok && k < KM__THETA_DEGREE; k++)
    coef[k] = th0 + dth * ((double)k / KM__THETA_DEGREE) + d[k - 1];
  /* A strongly varying speed (rational spans with unequal weights)
   * crowds the nodes' images in s, and the interpolant can swing far
   * between them while meeting every check point: its coefficient hull,
   * which bounds it, must stay near the data's range. */
  if (ok) {
    double dlo = th[0], dhi = th[0], clo = coef[0], chi = coef[0];
    for (int k = 1; k < KM__THETA_NODES; k++) {
      dlo = fmin(dlo, th[k]);
      dhi = fmax(dhi, th[k]);
    }
    for (int j = 1; j <= KM__THETA_DEGREE; j++) {
      clo = fmin(clo, coef[j]);
      chi = fmax(chi, coef[j]);
    }
    if (chi - clo > 1.001 * (dhi - dlo) + 4 * tol_here) ok = false;
  }
  for (int k = 1; ok && k < KM__THETA_NODES; k += 2) {
    double u = (s[k] - s[0]) / h;
    if (fabs(km__bern_eval(coef, KM__THETA_DEGREE, u) - th[k]) > tol_here)
      ok = false;
  }
  if (!ok) {
    /* Where theta moves less than its rounding noise (a speed near zero,
     * coordinates far from the origin) the interpolant through noisy
     * values swings and bisecting only samples more noise: theta linear
     * in s is accepted when it meets every node and check point. */
    bool lin = true;
    for (int k = 1; lin && k < KM__THETA_NODES - 1; k++)
      lin =
          fabs(th[0] + (th[KM__THETA_NODES - 1] - th[0]) * ((s[k] - s[0]) / h) -
               th[k]) <= tol_here;
    if (lin) {
      linear_theta(th[0], th[KM__THETA_NODES - 1], coef);
      ok = true;
    }
  }
  return ok;
}

/* ---- the phases of km__sig_fit_piece ----------------------------------- */
enum { N = KM__THETA_NODES };

/* One piece's samples at its nodes. */
typedef struct piece {
  double ua, ub, mid, half;
  double t[N], th[N], s[N], dir[N][2], speed[N], rounding[N];
  double noise;     /* relative rounding of the directions, at most 0.1 */
  bool coarse;      /* a step between nodes too large to interpolate */
  double big_step;  /* the largest |step| of theta between nodes */
  double h;         /* the piece's length: spectral, then confirmed */
  bool tiny_t;      /* too short in t to be bisected further */
  double tol_here;  /* the allowed |theta - theta~| on it */
  bool nodes_exact; /* s[] are the nodes' arc lengths to rounding */
} piece;

/* The work a piece costs, refused once the span's or the curve's budget
 * is spent, and the caller's stop. */
static km_status charge_piece(km__sig_builder *b, double ua) {
  if (km__poll_stop(b->poll, 2 * N)) return km__stopped(b->err);
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
  b->work -= 2 * N;
  b->span_work -= 2 * N;
  return KM_OK;
}

/* Speeds and directions at the nodes, the noise of those directions. */
static void sample_directions(km__sig_builder *b, piece *pc) {
  for (int k = 0; k < N; k++) {
    double d[2][2], wf;
    km__bspan_eval(&b->span, pc->t[k], d[0], d[1], &wf);
    double n = sqrt(d[1][0] * d[1][0] + d[1][1] * d[1][1]);
    pc->speed[k] = n;
    /* the rounding of C' here: the points' times the weight factor of a
     * rational span (at 1e6, where a weight of 0.1 meets one of 100, a
     * thousand times the polynomial share: directions there spun three
     * whole turns within 1e-10 of t and were refused as a cusp) */
    pc->rounding[k] = b->deriv_noise * fmax(wf, 1.0);
    if (k == 0 || k == N - 1) continue;
    /* C' well above its rounding error is the tangent, however small;
     * below that its direction is noise (the speed vanishes there in
     * exact arithmetic, or nearly), and the last reliable direction
     * stands in: across such a stretch, far shorter than the rounding of
     * the coordinates, only the turn between its ends counts */
    if (n > 16.0 * pc->rounding[k]) {
      pc->dir[k][0] = d[1][0] / n;
      pc->dir[k][1] = d[1][1] / n;
    } else {
      pc->dir[k][0] = pc->dir[k - 1][0];
      pc->dir[k][1] = pc->dir[k - 1][1];
    }
  }
  /* Directions from C' carry rounding error deriv_noise / |C'|: where the
   * speed nearly vanishes that exceeds any tolerance, and asking for more
   * would only bisect into noise. */
  pc->noise = 0.0;
  for (int k = 0; k < N; k++)
    if (pc->speed[k] > 0)
      pc->noise = fmax(pc->noise, pc->rounding[k] / pc->speed[k]);
  if (pc->noise > 0.1) pc->noise = 0.1;
}

/* The nodes of [ua, ub], their directions, theta unwrapped from theta0
 * and their arc lengths by spectral integration of the speed. */
static void sample_piece(km__sig_builder *b, double ua, double ub,
                         const double dir_a[2], const double dir_b[2],
                         double theta0, piece *pc) {
  pc->ua = ua;
  pc->ub = ub;
  pc->mid = 0.5 * (ua + ub);
  pc->half = 0.5 * (ub - ua);
  for (int k = 0; k < N; k++) pc->t[k] = pc->mid - pc->half * COS14[k];
  pc->t[0] = ua;
  pc->t[N - 1] = ub;
  pc->dir[0][0] = dir_a[0];
  pc->dir[0][1] = dir_a[1];
  pc->dir[N - 1][0] = dir_b[0];
  pc->dir[N - 1][1] = dir_b[1];
  sample_directions(b, pc);
  /* unwrap, watching for steps too large to interpolate */
  pc->coarse = false;
  pc->big_step = 0.0;
  pc->th[0] = theta0;
  for (int k = 1; k < N; k++) {
    const double *p = pc->dir[k - 1], *q = pc->dir[k];
    double step = atan2(p[0] * q[1] - p[1] * q[0], p[0] * q[0] + p[1] * q[1]);
    pc->th[k] = pc->th[k - 1] + step;
    if (fabs(step) > 0.5 * KM_PI) pc->coarse = true;
    pc->big_step = fmax(pc->big_step, fabs(step));
  }
  /* arc length at every point: spectral integration of the speed at the
   * nodes, checked against adaptive quadrature of the whole piece */
  double F[N];
  km__cheb_cumulative15(pc->speed, F);
  /* s[] holds arc length from the piece's start: near a sharp tip a piece
   * can be shorter than the rounding unit of the absolute arc length */
  for (int k = 0; k < N; k++) pc->s[k] = pc->half * F[k];
  pc->h = pc->s[N - 1] - pc->s[0];
  pc->tiny_t = (ub - ua) < 1e-13 * b->span_t;
}

/* The piece's length, confirmed. A whole span comes with its length by
 * 16-point Gauss-Legendre (known_len), and a piece inside it is measured
 * by the same rule: where the spectral length at these 15 other nodes
 * agrees to 1e-13 both rules have resolved the speed, and that is the
 * length; elsewhere it is measured adaptively, for the span too. *bisect
 * when the piece is to be halved before that measurement. */
static km_status measure_piece(km__sig_builder *b, piece *pc, double known_len,
                               int depth, bool *bisect) {
  double ua = pc->ua, ub = pc->ub, h = pc->h, ref = known_len;
  *bisect = false;
  if (!(known_len > 0)) {
    double w = b->span.b - b->span.a;
    ref = km__sig_gl16_length(&b->span, (ua - b->span.a) / w,
                              (ub - b->span.a) / w);
    b->work -= 16;
    b->span_work -= 16;
  }
  /* Two rules can agree and both miss a feature narrower than their nodes'
   * spacing: a speed that dips toward zero between nodes (a near-cusp,
   * a degenerate leg) or peaks (weights varying by decades). The
   * agreement counts only where the speed is of one scale over the nodes
   * and the weights are too. */
  double smin = INFINITY, smax = 0.0;
  for (int k = 0; k < N; k++) {
    smin = fmin(smin, pc->speed[k]);
    smax = fmax(smax, pc->speed[k]);
  }
  bool agree = smax <= 4.0 * smin && b->span_weight_ratio <= 2.0 &&
               fabs(h - ref) <= 1e-13 * ref + b->deriv_noise * (ub - ua);
  /* Where they disagree the speed is not resolved over the piece, and
   * theta seldom is: a piece inside the span that fails with the 16-point
   * length and the nodes' spectral positions is bisected before adaptive
   * quadrature measures it (work its halves would repeat). Only a piece
   * that could be taken is measured: not one that cannot be bisected, has
   * noisy directions, or may be of zero length. */
  if (!agree && !(known_len > 0) && depth < KM_MAX_REFINE_DEPTH &&
      !pc->tiny_t && pc->noise < 0.1 && fmin(h, ref) > 1e-12 * b->L) {
    double sa[N], ca[KM__THETA_DEGREE + 1];
    for (int k = 0; k < N; k++) sa[k] = pc->s[k] * (ref / h);
    if (pc->coarse ||
        !fit_theta(pc->th, sa, ref, theta_tol(b, pc->noise, ref), ca)) {
      *bisect = true;
      return KM_OK;
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
   * only approximate until measured one by one (choose_theta) */
  pc->nodes_exact =
      fabs(h - ref) <= 1e-12 * ref + 1e-16 * b->L + b->deriv_noise * (ub - ua);
  if (!pc->nodes_exact && h > 0)
    for (int k = 1; k < N - 1; k++) pc->s[k] *= ref / h;
  pc->s[N - 1] = ref;
  pc->h = ref;
  pc->tol_here = theta_tol(b, pc->noise, ref);
  return KM_OK;
}

/* A piece of (numerically) zero length: whatever turn it hides acts as a
 * corner at this point. Bisection toward a degenerate end ends in such
 * pieces: the turning they carry is real (kappa ~ 1/sqrt(s) there) but
 * concentrated in a length below resolution; a small one goes into a
 * neighbour. */
static km_status take_zero_piece(km__sig_builder *b, const piece *pc,
                                 double s_at, double *theta) {
  double turn = pc->th[N - 1] - pc->th[0];
  if (fabs(turn) > KM_PI - KM__CUSP_MARGIN)
    return km__fail(b->err, KM_ECUSP, KM_FIELD_CONTROL_POINTS, -1, pc->mid,
                    "the tangent reverses at parameter t = %g (a cusp): "
                    "the curve is not regular there",
                    pc->mid);
  km_status st = km__sig_take_turn(b, turn, s_at, pc->th[0], pc->mid, false);
  if (st) return st;
  *theta = pc->th[N - 1];
  return KM_OK;
}

/* The theta coefficients of a measured piece into coef; *ok false when it
 * must be bisected. */
static km_status choose_theta(km__sig_builder *b, piece *pc, int depth,
                              double coef[KM__THETA_DEGREE + 1], bool *ok) {
  const double *th = pc->th;
  double *s = pc->s, h = pc->h, tol_here = pc->tol_here;
  if (pc->coarse && pc->tiny_t && pc->big_step > KM_PI - 1e-3)
    return km__fail(b->err, KM_ECUSP, KM_FIELD_CONTROL_POINTS, -1, pc->mid,
                    "the tangent reverses at parameter t = %g (a cusp): the "
                    "curve is not regular there",
                    pc->mid);
  *ok = !pc->coarse && fit_theta(th, s, h, tol_here, coef);
  /* Measuring the nodes one by one costs fourteen adaptive quadratures: a
   * piece whose theta fails at their approximate positions is bisected
   * without them (where the speed is unresolved theta nearly always is,
   * and halves resolve both). A piece about to be taken, or that cannot
   * be bisected, or whose directions are noise, is judged at the exact
   * positions. */
  if (!pc->nodes_exact && !pc->coarse &&
      (*ok || pc->noise >= 0.1 || depth >= KM_MAX_REFINE_DEPTH || pc->tiny_t)) {
    for (int k = 1; k < N - 1; k++)
      s[k] = s[k - 1] + span_length(b, pc->t[k - 1], pc->t[k]);
    if (isnan(s[N - 2]))
      return km__fail(b->err, KM_ENOCONVERGE, KM_FIELD_CONTROL_POINTS, -1,
                      pc->ua,
                      "the arc length near parameter t = %g cannot be "
                      "computed to full precision",
                      pc->ua);
    *ok = fit_theta(th, s, h, tol_here, coef);
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
   * bisected, which brings its parts to one scale of speed; Chebyshev
   * nodes of a speed within a factor 4 leave gaps below a fifth of the
   * length. */
  if (*ok && depth < KM_MAX_REFINE_DEPTH && !pc->tiny_t) {
    double gap = 0.0;
    for (int k = 1; k < N; k++) gap = fmax(gap, s[k] - s[k - 1]);
    if (gap > 0.25 * h) *ok = false;
  }
  if (!*ok && pc->noise >= 0.1 && pc->big_step < KM_PI - 0.5 &&
      2.0 * h <= b->free_len) {
    /* directions that are noise, on a piece short enough (see free_len) */
    b->free_len -= 2.0 * h;
    linear_theta(th[0], th[N - 1], coef);
    *ok = true;
  }
  if (!*ok && (depth >= KM_MAX_REFINE_DEPTH || pc->tiny_t)) {
    /* cannot resolve further: acceptable only if theta barely moves */
    double lo = th[0], hi = th[0];
    for (int k = 1; k < N; k++) {
      lo = fmin(lo, th[k]);
      hi = fmax(hi, th[k]);
    }
    if (hi - lo > 4 * tol_here)
      return km__fail(b->err, KM_ENOCONVERGE, KM_FIELD_CONTROL_POINTS, -1,
                      pc->mid,
                      "curvature could not be resolved near parameter t = "
                      "%g",
                      pc->mid);
    linear_theta(th[0], th[N - 1], coef);
    *ok = true;
  }
  return KM_OK;
}

km_status km__sig_fit_piece(km__sig_builder *b, double ua, double ub,
                            double known_len, double *s_at, double *theta,
                            const double dir_a[2], const double dir_b[2],
                            int depth) {
  km_status st = charge_piece(b, ua);
  if (st) return st;
  piece pc;
  sample_piece(b, ua, ub, dir_a, dir_b, *theta, &pc);
  bool bisect = false;
  st = measure_piece(b, &pc, known_len, depth, &bisect);
  if (st) return st;
  if (!bisect) {
    if (!(pc.h > 1e-15 * b->L)) return take_zero_piece(b, &pc, *s_at, theta);
    double coef[KM__THETA_DEGREE + 1];
    bool ok = false;
    st = choose_theta(b, &pc, depth, coef, &ok);
    if (st) return st;
    if (ok) {
      if (!isnan(b->pending_start)) {
        coef[0] = b->pending_start;
        b->pending_start = NAN;
      }
      st = km__sig_push_piece(b, *s_at, *s_at + pc.h, coef);
      if (st) return st;
      *s_at += pc.h;
      *theta = pc.th[N - 1];
      return KM_OK;
    }
  }
  /* bisect in t, at the node at mid */
  double dm[2] = {pc.dir[N / 2][0], pc.dir[N / 2][1]};
  st = km__sig_fit_piece(b, ua, pc.mid, 0.0, s_at, theta, dir_a, dm, depth + 1);
  if (st) return st;
  return km__sig_fit_piece(b, pc.mid, ub, 0.0, s_at, theta, dm, dir_b,
                           depth + 1);
}
