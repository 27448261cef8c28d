/* internal.h - helpers shared inside libkmorph; not part of the API.
 *
 * Non-static internal symbols are prefixed km__ (public ones km_).
 */
#ifndef KM_INTERNAL_H
#define KM_INTERNAL_H

#include <math.h>
#include <stdbool.h>
#include <stddef.h>

#include "km/curve.h"
#include "km/fn.h"
#include "km/limits.h"
#include "km/status.h"
#include "km/stop.h"
#include "kernels.h"

#define KM_PI 3.14159265358979323846
#define KM__BSPAN_MAX 10 /* KM_MAX_DEGREE + 1 */

/* ---- stopping (km/stop.h) ------------------------------------------------
 * One call's poll of its caller's km_stop: loops count their work in units
 * and the callback is asked once every KM_STOP_POLL_UNITS of them. Once it
 * said stop every later check says so without asking again, so nested
 * loops unwind one after the other. A NULL km__poll never stops, so
 * helpers shared with callers that cannot stop take NULL. */
typedef struct km__poll {
  const km_stop *stop;
  long left;    /* units until the next question */
  bool stopped; /* the answer was yes */
  long asked;   /* questions asked (for tests and figures) */
} km__poll;

void km__poll_init(km__poll *p, const km_stop *stop);
/* Count units of work; true when the computation must end now. */
static inline bool km__poll_stop(km__poll *p, long units) {
  if (!p) return false;
  if (p->stopped) return true;
  if (!p->stop || !p->stop->requested) return false;
  p->left -= units;
  if (p->left > 0) return false;
  p->left = KM_STOP_POLL_UNITS;
  p->asked++;
  p->stopped = p->stop->requested(p->stop->ctx);
  return p->stopped;
}
/* The status of a stopped call, with its message in err. */
km_status km__stopped(km_error *err);

/* Record an error: code, field, element index, parameter and a message
 * formatted by km__format (a small printf subset: %s %d %ld %zu %g; no
 * locale, no stdio). Returns code so callers can `return km__fail(...)`. */
km_status km__fail(km_error *err, km_status code, km_field field, long index,
                   double param, const char *fmt, ...);

/* printf-like formatting into buf (always NUL-terminated): %s %d %ld %zu
 * and %g (six significant digits). */
void km__format(char *buf, size_t cap, const char *fmt, ...);

/* Allocate an empty curve of the given shape in one block (knots, points,
 * weights if rational). Contents uninitialised. */
km_status km__curve_alloc(km_curve *c, int degree, size_t n, bool rational);
km_status km__fn_alloc(km_fn *f, int degree, size_t n);

/* Gauss-Legendre rules on [-1, 1]. */
extern const double km__gl8_x[8], km__gl8_w[8];
extern const double km__gl16_x[16], km__gl16_w[16];

/* Speed |C'(t)| and the integral of the speed over [a, b], to about
 * rel_tol relative (adaptive Gauss-Legendre, 8 vs 16 points). */
double km__speed(const km_curve *c, double t);
double km__length_adaptive(const km_curve *c, double a, double b,
                           double abs_tol);
/* Adaptive Gauss-Legendre (8 vs 16 points, bisection) of f over [a, b];
 * NaN when the precision cannot be reached within a fixed amount of work
 * (an integrand that is rounding noise, or nearly singular), so that no
 * caller reports a length less precise than it promises. */
typedef double (*km__scalar_fn)(const void *ctx, double t);
double km__integrate_adaptive(km__scalar_fn f, const void *ctx, double a,
                              double b, double abs_tol);

/* One knot span of a curve in Bezier form (homogeneous x w, y w, w), for
 * fast evaluation of position and first derivative inside the span. */
typedef struct km__bspan {
  int degree;
  double a, b;                          /* parameter interval */
  double h[KM__BSPAN_MAX][3];           /* homogeneous control points */
  bool rational;
} km__bspan;
/* Fill sp with span [knots[i], knots[i+1]] of c (a non-empty span). */
void km__bspan_make(km__bspan *sp, const km_curve *c, size_t i);
/* Position and derivative with respect to t at t in [a, b]; in *wf (if
 * not NULL) the weight factor w0 w1 / w^2 of the last de Casteljau step
 * (1 without weights): the derivative carries km__bspan_noise times that
 * of rounding, which near a small weight beside a large one is many times
 * the polynomial share. */
void km__bspan_eval(const km__bspan *sp, double t, double pos[2],
                    double der[2], double *wf);
/* The same in the span's variable u = (t - a) / (b - a) in [0, 1]. */
void km__bspan_eval_u(const km__bspan *sp, double u, double pos[2],
                      double der_u[2]);
/* Arc length between u0 and u1 to abs_tol, or to the rounding of the
 * speed where that is larger (NaN where neither can be reached within a
 * fixed amount of work, as km__integrate_adaptive); the _counted form adds
 * the speed evaluations it made to *evals (if not NULL). */
double km__bspan_length(const km__bspan *sp, double u0, double u1,
                        double abs_tol);
double km__bspan_length_counted(const km__bspan *sp, double u0, double u1,
                                double abs_tol, long *evals);
/* Rounding error of a span's speed |dC/du| without weights, 8 p eps M for
 * points of magnitude up to M (a rational span's is larger where its
 * weights vary widely, see km__bspan_length): it bounds the precision of
 * any length and direction computed there. */
double km__bspan_noise(const km__bspan *sp);

/* Span index i with knots[i] <= t < knots[i+1] (last non-empty span at the
 * domain end); side < 0 picks knots[i] < t <= knots[i+1]. */
size_t km__find_span(const km_curve *c, double t, int side);

/* F[k] = integral from -1 to x_k of the degree-14 interpolant of f at the
 * 15 Chebyshev-Lobatto points x_k = -cos(k pi / 14) of [-1, 1] (the
 * signature's nodes). */
void km__cheb_cumulative15(const double *f, double *F);

/* sin x and cos x together, for the innermost loops of morph frames (one
 * pair per quadrature node): x - n pi/2 by a three-part split of pi/2
 * (33 + 33 + 53 bits, so n times each leading part is exact for |n| <
 * 2^20), then the Taylor series of sin and cos on |r| <= pi/4 to r^17 and
 * r^18, whose remainders are below 1e-19. Agrees with libm to a few units
 * in the last place (tests/core/test_numerics.c); |x| >= 1e5 goes to libm. */
static inline void km__sincos(double x, double *sn, double *cs) {
  if (!(fabs(x) < 1e5)) {
    *sn = sin(x);
    *cs = cos(x);
    return;
  }
  const double shift = 6755399441055744.0; /* 1.5 * 2^52: rounds to an integer */
  double n = (x * 0.6366197723675814 + shift) - shift;
  double r = ((x - n * 1.5707963267341256) - n * 6.077100506303966e-11) -
             n * 2.0222662487959506e-21;
  double z = r * r;
  double sr = r + r * z * (-1.0 / 6 + z * (1.0 / 120 + z * (-1.0 / 5040 +
              z * (1.0 / 362880 + z * (-1.0 / 39916800 + z * (1.0 / 6227020800.0 +
              z * (-1.0 / 1307674368000.0 + z * (1.0 / 355687428096000.0))))))));
  double cr = 1.0 + z * (-0.5 + z * (1.0 / 24 + z * (-1.0 / 720 + z * (1.0 / 40320 +
              z * (-1.0 / 3628800 + z * (1.0 / 479001600 + z * (-1.0 / 87178291200.0 +
              z * (1.0 / 20922789888000.0 + z * (-1.0 / 6402373705728000.0)))))))));
  switch ((long)n & 3) {
  case 0: *sn = sr; *cs = cr; break;
  case 1: *sn = cr; *cs = -sr; break;
  case 2: *sn = -sr; *cs = -cr; break;
  default: *sn = -cr; *cs = sr; break;
  }
}

/* km_curve_transform on c itself (a valid curve): rotation about the
 * origin by rot, then translation; KM_ERANGE past KM_MAX_COORDINATE (c is
 * then partly moved). */
km_status km__curve_transform_in_place(struct km_curve *c, double rot, double tx,
                                      double ty, km_error *err);

/* Wrap an angle to (-pi, pi]. */
double km__wrap_angle(double a);

/* ---- piecewise polynomials in Bernstein form ----------------------------
 * The numerics work on pieces: breaks x[0] < ... < x[m], and per piece the
 * d+1 Bernstein coefficients over [x[i], x[i+1]]. */
typedef struct km_pp {
  int degree;
  size_t m;    /* number of pieces */
  double *x;   /* m + 1 breaks */
  double *c;   /* m * (degree + 1) coefficients */
} km_pp;

void km__pp_init(km_pp *p);
void km__pp_free(km_pp *p);
km_status km__pp_alloc(km_pp *p, int degree, size_t m);
/* B-spline function -> pieces (exact, by knot insertion). */
km_status km__pp_from_fn(km_pp *out, const km_fn *f);
/* Pieces -> B-spline function (breaks of multiplicity degree+1). */
km_status km__pp_to_fn(km_fn *out, const km_pp *p);
/* C(d, j) for d <= KM_MAX_FN_DEGREE + 1 (pp.c). */
extern const double km__binomial[KM_MAX_FN_DEGREE + 2][KM_MAX_FN_DEGREE + 2];
/* Value of a Bernstein polynomial of degree d at u in [0,1]. */
double km__bern_eval(const double *c, int d, double u);
/* Coefficients over the sub-interval [u0, u1] of [0, 1]. */
void km__bern_restrict(const double *c, int d, double u0, double u1,
                       double *out);
/* Degree elevation from d to e >= d. */
void km__bern_elevate(const double *c, int d, int e, double *out);
/* Derivative with respect to the piece variable scaled by 1/h (degree d-1
 * coefficients). */
void km__bern_derivative(const double *c, int d, double h, double *out);
/* Max |coefficient|: a bound on max |p| over the piece. */
double km__bern_abs_bound(const double *c, int d);
/* Index of the piece containing x (right-continuous, last piece at end). */
size_t km__pp_find(const km_pp *p, double x);
double km__pp_eval(const km_pp *p, double x);
double km__pp_max_abs(const km_pp *p);
double km__pp_integral_sq(const km_pp *p);
/* out(u0 + r (u1-u0)) = wa a(r over a's domain) + wb b(r over b's), exact. */
km_status km__pp_blend(km_pp *out, const km_pp *a, double wa, const km_pp *b,
                       double wb, double u0, double u1);
/* Pieces merged into runs of degree max(degree, p's) that stay within delta
 * of p everywhere (a rigorous bound, from Bernstein coefficients); runs do
 * not cross a jump of p larger than delta / 4. The caller frees out. */
km_status km__pp_merge(const km_pp *p, int degree, double delta, km_pp *out);
/* Derivative of every piece (degree one lower; 0 stays 0). */
km_status km__pp_derivative(const km_pp *p, km_pp *out);


/* km_signature_compute_until, with rel_tol times the curve's length as the
 * tolerance where tol is not positive (the public default is 1e-5). */
struct km_signature;
km_status km__signature_compute(const km_curve *c, double tol, double rel_tol,
                                km__poll *poll, struct km_signature *out,
                                km_error *err);

/* km_curve_self_intersections with the caller's poll: -1 also when
 * stopped (then poll->stopped). */
long km__self_intersections(const km_curve *c, double tol, km__poll *poll);

/* km_reconstruct_until with the caller's poll (NULL: never stops). With
 * points_only not NULL nothing is built: *points_only receives the number
 * of control points the curve would have (out, error_bound unused). */
km_status km__reconstruct(const struct km_signature *sig, int degree,
                          double tol, size_t max_points, km__poll *poll,
                          km_curve *out, double *error_bound,
                          size_t *points_only, km_error *err);

/* theta(s) of a signature as pieces (breaks at kappa's breaks and at the
 * corners; corner turns folded into the pieces' start values) beside the
 * matching kappa pieces. */
struct km_signature;
km_status km__build_theta(const struct km_signature *sig, km_pp *kappa,
                          km_pp *theta);
/* Integral of (cos theta, sin theta) over [u0,u1] of a theta piece (degree
 * d Bernstein coefficients tc, piece length h); kbound bounds |kappa| there
 * and sets the chunking (theta moves <= 0.5 rad per 16-point rule). */
void km__integrate_exp(const double *tc, int d, double h, double u0,
                       double u1, double kbound, double out[2]);
/* Bounds bnd[j] >= |kappa^(j)| (j < nd, derivatives in arc length) over
 * [u0, u1] of a kappa piece (degree dk Bernstein coefficients kc, piece
 * length h), from the Bernstein coefficients of the restricted piece. */
void km__kappa_bounds(const double *kc, int dk, double h, double u0,
                      double u1, int nd, double *bnd);
/* Sup over the jump position c and s in [0, 1] of |q - Hq| for the cubic
 * Hermite interpolant H of q = (s - c)_+^2 / 2 and (s - c)_+^3 / 6, rounded
 * up (0.016151 and 1/192 measured on a fine grid): a cubic Hermite piece of
 * length h across jumps J2, J3 of C'', C''' adds KM__HERMITE_JUMP2 h^2 |J2|
 * + KM__HERMITE_JUMP3 h^3 |J3| to its error. */
#define KM__HERMITE_JUMP2 0.0165
#define KM__HERMITE_JUMP3 0.0053

#endif
