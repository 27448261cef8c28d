/* pp_internal.h - piecewise polynomials in Bernstein form, the numerics' working
 * form of functions (pp.c); internal.
 */
#ifndef KM_PP_INTERNAL_H
#define KM_PP_INTERNAL_H

#include <stdbool.h>
#include <stddef.h>

#include "km/fn.h"
#include "km/limits.h"
#include "km/status.h"

/*  * The numerics work on pieces: breaks x[0] < ... < x[m], and per piece the
 * d+1 Bernstein coefficients over [x[i], x[i+1]]. */
typedef struct km_pp {
  int degree;
  size_t m;  /* number of pieces */
  double *x; /* m + 1 breaks */
  double *c; /* m * (degree + 1) coefficients */
} km_pp;

void km__pp_init(km_pp *p);
void km__pp_free(km_pp *p);
km_status km__pp_alloc(km_pp *p, int degree, size_t m);
/* B-spline function -> pieces (exact, by knot insertion). */
km_status km__pp_from_fn(km_pp *out, const km_fn *f);
/* The pieces km__pp_from_fn makes, one at a time and in its order, on the
 * caller's stack: for the value functions (a maximum, an interval bound)
 * that have no status to report out of memory with. Start with
 * km__fn_pieces_start, then each km__fn_pieces_next writes the next
 * piece's interval [x[0], x[1]] and its degree + 1 Bernstein coefficients
 * c, or returns false when there is none left. */
typedef struct km__fn_pieces {
  const km_fn *f;
  bool bezier; /* f is piecewise Bezier already: its pieces are its coef */
  size_t i;    /* the next piece (Bezier) or knot span (otherwise) */
} km__fn_pieces;
void km__fn_pieces_start(km__fn_pieces *it, const km_fn *f);
bool km__fn_pieces_next(km__fn_pieces *it, double x[2], double *c);
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
/* Both halves of c (degree d) at once: what km__bern_restrict gives for
 * [0, 1/2] into L and for [1/2, 1] into R, by one de Casteljau pass. */
void km__bern_halves(const double *c, int d, double *L, double *R);
/* Derivative with respect to the piece variable scaled by 1/h (degree d-1
 * coefficients). */
void km__bern_derivative(const double *c, int d, double h, double *out);
/* Max |coefficient|: a bound on max |p| over the piece. */
double km__bern_abs_bound(const double *c, int d);
/* Index of the piece containing x (right-continuous, last piece at end). */
size_t km__pp_find(const km_pp *p, double x);
double km__pp_eval(const km_pp *p, double x);
double km__pp_max_abs(const km_pp *p);
/* The same to rel relative (the value returned is attained, at most rel
 * below the largest): a frame's metric needs no 1e-13, whose subdivision
 * costs most where the curvature is nearly constant. */
double km__pp_max_abs_within(const km_pp *p, double rel);
double km__pp_integral_sq(const km_pp *p);
/* Integral over [0, 1] of the product of two Bernstein polynomials of
 * degree d, with the weights km__bern_product_weights tables for d. */
typedef double km__bern_weights[KM_MAX_FN_DEGREE + 2][KM_MAX_FN_DEGREE + 2];
void km__bern_product_weights(int d, km__bern_weights w);
double km__bern_inner(km__bern_weights w, const double *f, const double *g,
                      int d);
/* p's pieces over the intervals [r[i], r[i + 1]] of its normalised domain
 * (r increasing in [0, 1], m intervals), each elevated to degree e >= p's:
 * m * (e + 1) Bernstein coefficients into out, exact. */
void km__pp_on_breaks(const km_pp *p, const double *r, size_t m, int e,
                      double *out);
/* out(u0 + r (u1-u0)) = wa a(r over a's domain) + wb b(r over b's), exact. */
km_status km__pp_blend(km_pp *out, const km_pp *a, double wa, const km_pp *b,
                       double wb, double u0, double u1);
/* Pieces merged into runs of degree max(degree, p's) that stay within delta
 * of p everywhere (a rigorous bound, from Bernstein coefficients); runs do
 * not cross a jump of p larger than delta / 4. The caller frees out. */
km_status km__pp_merge(const km_pp *p, int degree, double delta, km_pp *out);
/* Derivative of every piece (degree one lower; 0 stays 0). */
km_status km__pp_derivative(const km_pp *p, km_pp *out);

#endif
