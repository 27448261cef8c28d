/* bspline_internal.h - curves and functions inside libkmorph: allocation, spans in
 * Bezier form, speed and length, the span of a parameter, in-place
 * transforms and the self-intersection count (curve.c, curve_ops.c,
 * fn.c, intersect.c); internal.
 */
#ifndef KM_BSPLINE_INTERNAL_H
#define KM_BSPLINE_INTERNAL_H

#include <stdbool.h>
#include <stddef.h>

#include "km/curve.h"
#include "km/fn.h"
#include "km/limits.h"
#include "km/status.h"
#include "stop_internal.h"

#define KM__BSPAN_MAX 10 /* KM_MAX_DEGREE + 1 */

/* Allocate an empty curve of the given shape in one block (knots, points,
 * weights if rational). Contents uninitialised. */
km_status km__curve_alloc(km_curve *c, int degree, size_t n, bool rational);
km_status km__fn_alloc(km_fn *f, int degree, size_t n);

/* Speed |C'(t)| and the integral of the speed over [a, b], to about
 * rel_tol relative (adaptive Gauss-Legendre, 8 vs 16 points). */
double km__speed(const km_curve *c, double t);
double km__length_adaptive(const km_curve *c, double a, double b,
                           double abs_tol);
/* One knot span of a curve in Bezier form (homogeneous x w, y w, w), for
 * fast evaluation of position and first derivative inside the span. */
typedef struct km__bspan {
  int degree;
  double a, b;                /* parameter interval */
  double h[KM__BSPAN_MAX][3]; /* homogeneous control points */
  bool rational;
} km__bspan;
/* Fill sp with span [knots[i], knots[i+1]] of c (a non-empty span). */
void km__bspan_make(km__bspan *sp, const km_curve *c, size_t i);
/* Position and derivative with respect to t at t in [a, b]; in *wf (if
 * not NULL) the weight factor w0 w1 / w^2 of the last de Casteljau step
 * (1 without weights): the derivative carries km__bspan_noise times that
 * of rounding, which near a small weight beside a large one is many times
 * the polynomial share. */
void km__bspan_eval(const km__bspan *sp, double t, double pos[2], double der[2],
                    double *wf);
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
/* km_curve_eval_side on span i, found by the caller (the same digits as
 * when km__find_span finds it): t in the span's closure, nder in 0..3. */
void km__curve_eval_span(const km_curve *c, size_t i, double t, int nder,
                         double out[][2]);

/* km_curve_transform on c itself (a valid curve): rotation about the
 * origin by rot, then translation; KM_ERANGE past KM_MAX_COORDINATE (c is
 * then partly moved). */
km_status km__curve_transform_in_place(struct km_curve *c, double rot,
                                       double tx, double ty, km_error *err);

/* km_curve_self_intersections with the caller's poll: -1 also when
 * stopped (then poll->stopped). */
long km__self_intersections(const km_curve *c, double tol, km__poll *poll);
/* The same count, with the crossings' parameters: *hits (when hits is not
 * NULL) receives an array of count pairs (ta, tb), ta < tb, owned by the
 * caller (km__free; NULL when there are none or on -1). */
long km__self_intersection_params(const km_curve *c, double tol, km__poll *poll,
                                  double **hits);

#endif
