/* json_write.h - JSON answers written straight into one growing buffer
 * (an api_svg_buf), as cJSON_PrintUnformatted would print the same tree
 * but without building one: no node per number, no second pass.
 *
 * Every writer returns false when the answer cannot be written: a
 * non-finite number (422 no-convergence recorded in ctx, as the tree
 * writers of internal.h do). Out of memory is sticky in the buffer
 * (b->failed) and reported once by api__json_done.
 */
#ifndef KMAPI_JSON_WRITE_H
#define KMAPI_JSON_WRITE_H

#include "internal.h"
#include "svg.h"

/* Literal JSON text (punctuation, keys with their quotes and colon). */
static inline void api__json_raw(api_svg_buf *b, const char *text, size_t n) {
  api__svg_buf_put_n(b, text, n);
}
#define API_JSON_LIT(b, lit) api__json_raw((b), (lit), sizeof(lit) - 1)

/* A finite number in its shortest round-trip form; what names it in the
 * error when it is not finite. */
bool api__json_num(api_ctx *ctx, api_svg_buf *b, double v, const char *what);
/* A string, quoted and escaped as cJSON escapes it. */
void api__json_string(api_svg_buf *b, const char *s);
/* n values (stride 1) or n points (stride 2, [x,y] each) as an array. */
bool api__json_nums(api_ctx *ctx, api_svg_buf *b, const double *v, size_t n,
                    size_t stride);
/* How control points are printed: exactly (shortest round trip), or on
 * the decimal grid 10^-decimals ("precision": "tolerance"). */
typedef struct api_grid {
  bool on;
  int decimals;
  double share; /* of the tolerance the printed curve may move by */
} api_grid;

/* The grid of "precision": "tolerance" for a tolerance tol (> 0): the
 * coarsest 10^-d at most tol / 10, and the share tol / 10 the printed
 * curve may move by. A point so rounded moves by at most sqrt(2)/2 of it
 * (both coordinates by half a step), 0.071 tol, and so does the curve: a
 * B-spline point is a convex combination of its control points, with or
 * without (positive, unrounded) weights. The knots of a polynomial curve
 * go on a grid of their own, the coarsest found on which the whole
 * movement (api__json_curve) stays within the share. */
api_grid api__tolerance_grid(double tol);

/* A curve as the contract's Curve (output) object (degree, knots,
 * control_points, weights when rational, closed, length, svg_d when
 * asked), its control points on grid (NULL: exact) with the length of
 * the curve so printed (known_length, api__curve_length's, when printed
 * exactly and already measured; else NAN). On a grid, a polynomial
 * curve's knots go on the coarsest decimal grid (from an estimate, a
 * decade finer at a time, a few at most) that keeps every multiplicity
 * and on which the printed curve stays within grid->share of c: span by
 * span, the largest distance between the Bezier points of c and of the
 * printed curve (rounded knots and control points), which bounds every
 * point of the span at the same local parameter; else exact. *moved (may
 * be NULL) receives a bound on how far printing moved the curve (0 when
 * exact). Weights (and a rational curve's knots), length and svg_d's
 * source stay exact. */
bool api__json_curve(api_ctx *ctx, api_svg_buf *b, const km_curve *c,
                     bool svg_d, double tol, const api_grid *grid,
                     double known_length, double *moved);
/* The length a curve's "length" member gives, to the contract's 1e-12
 * relative (api__json_curve takes it as known_length when the curve is
 * printed exactly; NAN there: measured while printing). */
double api__curve_length(const km_curve *c);
/* A cJSON tree (consumed) printed into the buffer, for the parts of an
 * answer still built as trees. NULL item: false (the builder has recorded
 * its error). */
bool api__json_tree(api_ctx *ctx, api_svg_buf *b, cJSON *item);
/* true when everything was written; else records 503 out of memory. */
bool api__json_done(api_ctx *ctx, const api_svg_buf *b);

#endif
