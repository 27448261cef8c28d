/* signature_builder.h - the state of one signature computation, shared
 * by the span walk and its corners (signature_walk.c) and the fit of theta
 * on pieces (signature_theta.c); internal to libkmorph.
 */
#ifndef KM_SIGNATURE_BUILDER_H
#define KM_SIGNATURE_BUILDER_H

#include <stdbool.h>
#include <stddef.h>

#include "internal.h"
#include "km/signature.h"

#define KM__THETA_DEGREE 7 /* kappa pieces are of degree 6 */
#define KM__THETA_NODES (2 * KM__THETA_DEGREE + 1) /* nodes and check points */
#define KM__CORNER_NOISE 1e-11 /* turns below this are rounding */
/* |turn| > pi - this: a cusp. Tangent estimates beside a cusp are good to
 * about 1e-7 rad, so a hairpin must turn back within 1e-5 rad of pi to be
 * taken for a cusp. */
#define KM__CUSP_MARGIN 1e-5

typedef struct km__sig_builder km__sig_builder;
struct km__sig_builder {
  const km_curve *c;
  double L;                 /* total length */
  double tol;               /* allowed distance to the curve */
  double tol_theta;         /* allowed |theta - theta~| */
  double span_t;            /* width in t of the span being processed */
  double span_speed;        /* its mean speed: the scale of |C'| there */
  double span_len;          /* its arc length: estimated, then confirmed */
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
  km__poll *poll;       /* the caller's stop condition, or NULL */
  km_error *err;
};

/* Append the theta piece [s0, s1] with Bernstein coefficients coef
 * (KM__THETA_DEGREE + 1 values, copied). KM_ELIMIT past KM_MAX_PIECES,
 * KM_ENOMEM; both also in b->err. */
km_status km__sig_push_piece(km__sig_builder *b, double s0, double s1,
                             const double *coef);
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
km_status km__sig_take_turn(km__sig_builder *b, double turn, double s,
                            double theta_before, double t, bool knot_corner);

/* Arc length of a span over [u0, u1] of its variable by the 16-point
 * Gauss-Legendre rule: exact to rounding where the speed is smooth, which
 * is checked (km__sig_fit_piece) before it is used as the length. */
double km__sig_gl16_length(const km__bspan *sp, double u0, double u1);

/* Interpolate theta on the piece [ua, ub] of the current span; bisect in t
 * until the check points agree. *s_at is the arc length at ua on entry
 * and at ub on exit; *theta is the unwrapped angle at ua on entry (whose
 * direction is dir_a) and at ub on exit (direction dir_b).
 * known_len is the piece's length when known (a whole span's estimate; 0
 * otherwise), depth the bisections so far. Returns KM_OK, or the
 * KM_ELIMIT, KM_ENOCONVERGE, KM_ECUSP, KM_ENOMEM or stopped status also
 * written to b->err. */
km_status km__sig_fit_piece(km__sig_builder *b, double ua, double ub,
                            double known_len, double *s_at, double *theta,
                            const double dir_a[2], const double dir_b[2],
                            int depth);

#endif
