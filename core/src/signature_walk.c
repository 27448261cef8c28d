/* signature_walk.c - the signature of a curve: the walk over its spans,
 * the turns between them and the corners.
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
#include <string.h>

#include "internal.h"
#include "km/alloc.h"
#include "km/limits.h"
#include "km/signature.h"
#include "signature_builder.h"

#define SPAN_CACHE 20000 /* spans kept in Bezier form */

km_status km__sig_push_piece(km__sig_builder *b, double s0, double s1,
                             const double *coef) {
  if (b->m + 1 >= b->cap) {
    size_t cap = b->cap ? 2 * b->cap : 64;
    if (cap > KM_MAX_PIECES)
      return km__fail(b->err, KM_ELIMIT, KM_FIELD_NONE, -1, NAN,
                      "signature would need more than %d pieces",
                      KM_MAX_PIECES);
    double *s = km__realloc(b->s, (cap + 1) * sizeof(double));
    if (!s) return km__fail(b->err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
    b->s = s;
    double *th =
        km__realloc(b->th, cap * (KM__THETA_DEGREE + 1) * sizeof(double));
    if (!th) return km__fail(b->err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
    b->th = th;
    b->cap = cap;
  }
  if (b->m == 0) b->s[0] = s0;
  b->s[b->m + 1] = s1;
  memcpy(b->th + b->m * (KM__THETA_DEGREE + 1), coef,
         (KM__THETA_DEGREE + 1) * sizeof(double));
  b->m++;
  return KM_OK;
}

static km_status push_corner(km__sig_builder *b, double s, double turn,
                             double t) {
  if (b->ncorners > 0 && s - b->corners[b->ncorners - 1].s <= 1e-14 * b->L) {
    /* one corner seen in several steps: one turn, which may reverse */
    double sum = km__wrap_angle(b->corners[b->ncorners - 1].turn + turn);
    if (fabs(sum) > KM_PI - KM__CUSP_MARGIN)
      return km__fail(b->err, KM_ECUSP, KM_FIELD_CONTROL_POINTS, -1, t,
                      "the tangent reverses at parameter t = %g (a cusp): "
                      "the curve is not regular there",
                      t);
    b->corners[b->ncorners - 1].turn = sum;
    return KM_OK;
  }
  if (b->ncorners == b->ccap) {
    size_t cap = b->ccap ? 2 * b->ccap : 16;
    km_corner *c = km__realloc(b->corners, cap * sizeof *c);
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
static bool tangent_limit(const km__sig_builder *b, double t, int side,
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
    double floor_p =
        b->deriv_noise * (sp->b - sp->a); /* ~ rounding of points */
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
  bool small = knot_corner ? fabs(turn) <= KM__CORNER_NOISE : fabs(turn) < 1e-3;
  if (small && last_adjoins && fabs(turn) * prev_h <= 0.05 * tol) {
    b->th[(b->m - 1) * (KM__THETA_DEGREE + 1) + KM__THETA_DEGREE] += turn;
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

/* The turn between two spans at parameter t, arc length s: a cusp where
 * the tangent reverses. */
static km_status check_cusp(km__sig_builder *b, double turn, double t,
                            double s) {
  if (fabs(turn) > KM_PI - KM__CUSP_MARGIN)
    return km__fail(b->err, KM_ECUSP, KM_FIELD_KNOTS, -1, t,
                    "the tangent reverses at parameter t = %g (arc length "
                    "%g): a cusp, the curve is not regular there",
                    t, s);
  return KM_OK;
}

km_status km_signature_compute(const km_curve *c, double tol, km_signature *out,
                               km_error *err) {
  return km__signature_compute(c, tol, 1e-5, NULL, out, err);
}

km_status km_signature_compute_until(const km_curve *c, double tol,
                                     const km_stop *stop, km_signature *out,
                                     km_error *err) {
  km__poll poll;
  km__poll_init(&poll, stop);
  return km__signature_compute(c, tol, 1e-5, &poll, out, err);
}

/* ---- the phases of km__signature_compute -------------------------------
 * One walk over the curve: span lengths estimated, the tolerance set from
 * the total, every span fitted in order (its turn from the previous one
 * first), the turns left at the end and at a closed seam, then kappa as
 * the derivative of the theta pieces. */
typedef struct walk {
  const km_curve *c;
  double *span_len; /* per span: the estimate, then the confirmed length */
  km__bspan *spans; /* the spans in Bezier form, or NULL past SPAN_CACHE */
  double L;         /* total length: estimated, then confirmed */
  double extent;    /* largest |coordinate| of a control point */
  double point_len; /* twice the length left for spans taken as points */
  double s_at, theta, start_angle;
  double prev_dir[2], first_dir[2];
  bool have_prev; /* a span was fitted: prev_dir is its end direction */
} walk;

/* Span lengths by one 16-point rule first: they scale the tolerance and
 * are confirmed (or measured adaptively) while the span is fitted. A span
 * whose estimate is at the scale of its rounding is measured at once:
 * whether it is a point decides whether it is fitted at all. */
static km_status estimate_lengths(km__sig_builder *b, walk *w) {
  const km_curve *c = w->c;
  double poly = 0.0;
  for (size_t i = 1; i < c->n; i++)
    poly += hypot(c->cp[2 * i] - c->cp[2 * i - 2],
                  c->cp[2 * i + 1] - c->cp[2 * i - 1]);
  double L = 0.0;
  for (size_t i = 0; i < c->n; i++) w->span_len[i] = 0.0;
  for (size_t i = (size_t)c->degree; i < c->n && poly > 0; i++) {
    if (c->knots[i + 1] > c->knots[i]) {
      km__bspan local, *spp = w->spans ? &w->spans[i] : &local;
      km__bspan_make(spp, c, i);
      const km__bspan sp = *spp;
      long evals = 0;
      double est = km__sig_gl16_length(&sp, 0.0, 1.0);
      b->work -= 16;
      if (!(est > 1e-9 * poly) || !(est > 1e6 * km__bspan_noise(&sp)))
        est = km__bspan_length_counted(&sp, 0.0, 1.0, 1e-15 * poly, &evals);
      w->span_len[i] = est;
      b->work -= evals;
      if (km__poll_stop(b->poll, 16 + evals)) return km__stopped(b->err);
    }
    L += w->span_len[i];
    if (isnan(L)) break; /* reported below; no more work for this curve */
  }
  w->L = L;
  w->extent = 0.0;
  for (size_t i = 0; i < 2 * c->n; i++)
    w->extent = fmax(w->extent, fabs(c->cp[i]));
  return KM_OK;
}

/* The curve's length must be measurable and not zero; the tolerance is
 * the caller's, or rel_tol of the length, raised to the curve's rounding. */
static km_status set_tolerance(km__sig_builder *b, walk *w, double tol,
                               double rel_tol) {
  double L = w->L, extent = w->extent;
  if (isnan(L))
    return km__fail(b->err, KM_ENOCONVERGE, KM_FIELD_CONTROL_POINTS, -1, NAN,
                    "the arc length cannot be computed to full precision "
                    "(the speed nearly vanishes inside a span)");
  if (!(L > 1e-13 * extent) || !(L > 1e-300))
    return km__fail(b->err, KM_EDEGENERATE, KM_FIELD_CONTROL_POINTS, -1, NAN,
                    "the curve has zero length");
  b->L = L;
  if (!(tol > 0) || !isfinite(tol)) tol = rel_tol * L;
  /* Nor below the rounding of the curve itself (limits.h). A curve too
   * small for its distance from the origin to meet even the default
   * tolerance (1e-5 of its length) is refused: its shape is rounding
   * noise at that scale. */
  double tol_min =
      fmax(KM_MIN_RELATIVE_TOLERANCE * L,
           KM_MIN_TOLERANCE_ULPS * DBL_EPSILON * w->c->degree * extent);
  if (tol < tol_min) {
    if (tol_min > 1e-5 * L)
      return km__fail(b->err, KM_ERANGE, KM_FIELD_CONTROL_POINTS, -1, NAN,
                      "the curve (length %g) is too small for its distance "
                      "from the origin (coordinates up to %g): its shape is "
                      "known to less than a tolerance of %g; move it nearer "
                      "the origin",
                      L, extent, tol_min);
    tol = tol_min;
  }
  /* Where no interpolant meets the checks because the directions are
   * rounding noise (off by a tenth of a radian or more somewhere: a speed
   * within ten times its rounding error) but do not reverse (a cusp is
   * refused, not smoothed), a short piece may be taken as turning
   * uniformly between its end directions: that moves the curve by at most
   * twice its length, and all such pieces together may cost a twentieth
   * of the tolerance. */
  b->free_len = 0.05 * tol;
  w->point_len = 0.25 * tol; /* twice the length of spans taken as points,
                                see enter_span */
  b->tol = tol;
  b->tol_theta = fmin(0.25 * tol / L, 1e-3);
  return KM_OK;
}

/* Make span i the builder's current one; *skip when it is a point. A span
 * whose length is its rounding error (equal control points far from the
 * origin) is one too: the turn across it is checked as a corner. Each
 * such span is lost from the pieces (up to its length in position) and
 * its length then stretches the others (as much again), so together they
 * may cost a quarter of the tolerance; past that the spans are a real
 * curve whose shape its coordinates do not carry, refused rather than
 * taken for a point. */
static km_status enter_span(km__sig_builder *b, walk *w, size_t i, bool *skip) {
  const km_curve *c = w->c;
  double ua = c->knots[i], ub = c->knots[i + 1], len = w->span_len[i];
  *skip = true;
  if (!(ub > ua)) return KM_OK;
  if (!(len > 1e-15 * w->L)) return KM_OK; /* a span that is a single point */
  if (w->spans)
    b->span = w->spans[i];
  else
    km__bspan_make(&b->span, c, i);
  double noise = km__bspan_noise(&b->span);
  if (!(len > noise)) {
    if (2.0 * len <= w->point_len) {
      w->point_len -= 2.0 * len;
      return KM_OK;
    }
    return km__fail(b->err, KM_ERANGE, KM_FIELD_CONTROL_POINTS, -1, ua,
                    "the spans near parameter t = %g are no longer than "
                    "the rounding of their coordinates (%g, up to %g): "
                    "move the curve nearer the origin or use fewer, "
                    "longer spans",
                    ua, noise, w->extent);
  }
  b->span_t = ub - ua;
  b->span_speed = len / (ub - ua);
  double wlo = INFINITY, whi = 0.0;
  for (int q = 0; q <= b->span.degree; q++) {
    wlo = fmin(wlo, b->span.h[q][2]);
    whi = fmax(whi, b->span.h[q][2]);
  }
  b->span_weight_ratio = b->span.rational && wlo > 0 ? whi / wlo : 1.0;
  b->span_len = len;
  b->deriv_noise = noise / (ub - ua); /* of |C'| */
  b->span_work = KM_SIGNATURE_WORK_PER_SPAN;
  *skip = false;
  return KM_OK;
}

/* The span's pieces must end exactly at its arc length len: knots are
 * breakpoints at their exact images. Pieces m0.. and corners c0.. are
 * the span's, which started at s_start. */
static void fit_to_span_length(km__sig_builder *b, walk *w, size_t m0,
                               size_t c0, double s_start, double len) {
  if (!(b->m > m0 && w->s_at - s_start > 0)) return;
  double f = len / (w->s_at - s_start), s_end = s_start + len;
  for (size_t q = m0 + 1; q <= b->m; q++)
    b->s[q] = s_start + (b->s[q] - s_start) * f;
  /* a corner at the span's end (a turn hidden below resolution next to a
   * degenerate end) stays exactly on that break: one ulp off it would
   * leave a piece one ulp long where kappa may be huge */
  for (size_t q = c0; q < b->ncorners; q++)
    if (b->corners[q].s >= w->s_at)
      b->corners[q].s = s_end;
    else if (b->corners[q].s > s_start)
      b->corners[q].s = s_start + (b->corners[q].s - s_start) * f;
  w->s_at = s_end;
  b->s[b->m] = w->s_at;
}

/* Fit the current span i: its start direction sets theta (the first
 * span) or is a turn from the previous span's end, then its pieces. */
static km_status fit_span(km__sig_builder *b, walk *w, size_t i) {
  double ua = w->c->knots[i], ub = w->c->knots[i + 1], len = w->span_len[i];
  double da[2], db[2];
  if (!tangent_limit(b, ua, 1, da) || !tangent_limit(b, ub, -1, db))
    return km__fail(b->err, KM_EDEGENERATE, KM_FIELD_CONTROL_POINTS, -1, ua,
                    "no tangent direction near parameter t = %g", ua);
  if (!w->have_prev) {
    w->start_angle = atan2(da[1], da[0]);
    w->theta = w->start_angle;
    w->first_dir[0] = da[0];
    w->first_dir[1] = da[1];
    w->have_prev = true;
  } else {
    const double *pd = w->prev_dir;
    double turn =
        atan2(pd[0] * da[1] - pd[1] * da[0], pd[0] * da[0] + pd[1] * da[1]);
    km_status st = check_cusp(b, turn, ua, w->s_at);
    if (st) return st;
    st = km__sig_take_turn(b, turn, w->s_at, w->theta, ua, true);
    if (st) return st;
    w->theta += turn;
  }
  size_t m0 = b->m, c0 = b->ncorners;
  b->span_first = m0;
  double s_start = w->s_at;
  km_status st =
      km__sig_fit_piece(b, ua, ub, len, &w->s_at, &w->theta, da, db, 0);
  if (st) return st;
  w->L += b->span_len - len; /* the confirmed length replaces the estimate */
  fit_to_span_length(b, w, m0, c0, s_start, b->span_len);
  w->prev_dir[0] = db[0];
  w->prev_dir[1] = db[1];
  return KM_OK;
}

/* The turns no span carried: one handed on to a next piece that never
 * came (a piece below resolution at the curve's very end) is a corner at
 * the end, where its position costs nothing - the pieces must end on the
 * direction the curve ends with, or a closed curve's turning is off; and
 * at a closed curve's seam the turn back to the first direction (rounding
 * is dropped there). */
static km_status end_turns(km__sig_builder *b, walk *w, double t1) {
  km_status st;
  if (!isnan(b->pending_start) && b->m > 0) {
    double end = b->th[(b->m - 1) * (KM__THETA_DEGREE + 1) + KM__THETA_DEGREE];
    double turn = km__wrap_angle(w->theta - end);
    if (fabs(turn) > KM__CORNER_NOISE) {
      st = push_corner(b, w->s_at, turn, t1);
      if (st) return st;
    }
    b->pending_start = NAN;
  }
  if (b->m == 0)
    return km__fail(b->err, KM_EDEGENERATE, KM_FIELD_CONTROL_POINTS, -1, NAN,
                    "the curve has zero length");
  if (w->c->closed) {
    const double *pd = w->prev_dir, *fd = w->first_dir;
    double turn =
        atan2(pd[0] * fd[1] - pd[1] * fd[0], pd[0] * fd[0] + pd[1] * fd[1]);
    st = check_cusp(b, turn, t1, w->s_at);
    if (st) return st;
    if (fabs(turn) > KM__CORNER_NOISE) {
      st = push_corner(b, w->s_at, turn, t1);
      if (st) return st;
    }
  }
  return KM_OK;
}

/* The signature from the builder's pieces and corners: breaks snapped to
 * the total length, kappa = d theta / ds on every piece. On success the
 * corners move into *out (b->corners is then NULL). */
static km_status make_signature(km__sig_builder *b, walk *w,
                                km_signature *out) {
  double L = w->L;
  /* the pieces' arc lengths sum to the total up to rounding: snap */
  double s_last = b->s[b->m], scale = L / s_last;
  for (size_t i = 0; i <= b->m; i++) b->s[i] *= scale;
  for (size_t i = 0; i < b->ncorners; i++) /* the seam's corner is at L */
    b->corners[i].s =
        b->corners[i].s >= s_last ? L : fmin(b->corners[i].s * scale, L);
  b->s[b->m] = L;
  km_pp kp;
  km__pp_init(&kp);
  km_signature r;
  km_signature_init(&r);
  km_status st = km__pp_alloc(&kp, KM__THETA_DEGREE - 1, b->m);
  if (st) {
    st = km__fail(b->err, st, KM_FIELD_NONE, -1, NAN, NULL);
    goto cleanup;
  }
  for (size_t i = 0; i < b->m; i++) {
    kp.x[i] = b->s[i];
    km__bern_derivative(b->th + i * (KM__THETA_DEGREE + 1), KM__THETA_DEGREE,
                        b->s[i + 1] - b->s[i], kp.c + i * KM__THETA_DEGREE);
  }
  kp.x[b->m] = L;
  st = km__pp_to_fn(&r.kappa, &kp);
  if (st) {
    st = km__fail(b->err, st, KM_FIELD_NONE, -1, NAN, NULL);
    goto cleanup;
  }
  double t0, t1, d0[1][2];
  km_curve_domain(w->c, &t0, &t1);
  km_curve_eval(w->c, t0, 0, d0);
  r.length = L;
  r.start[0] = d0[0][0];
  r.start[1] = d0[0][1];
  r.angle = w->start_angle;
  r.closed = w->c->closed;
  r.corners = b->corners;
  r.ncorners = b->ncorners;
  b->corners = NULL;
  double turning = km_fn_integral(&r.kappa);
  for (size_t i = 0; i < r.ncorners; i++) turning += r.corners[i].turn;
  r.turning = turning;
  *out = r;
cleanup:
  km__pp_free(&kp);
  return st;
}

km_status km__signature_compute(const km_curve *c, double tol, double rel_tol,
                                km__poll *poll, km_signature *out,
                                km_error *err) {
  if (!c || !c->knots || !c->cp || c->degree < KM_MIN_DEGREE ||
      c->degree > KM_MAX_DEGREE || c->n < (size_t)c->degree + 1)
    return km__fail(err, KM_EINVAL, KM_FIELD_NONE, -1, NAN,
                    "not a valid curve (empty or never created)");
  km__sig_builder b;
  memset(&b, 0, sizeof b);
  b.c = c;
  b.err = err;
  b.poll = poll;
  b.pending_start = NAN;
  b.work = KM_SIGNATURE_WORK_BASE + KM_SIGNATURE_WORK_PER_POINT * (long)c->n;
  walk w;
  memset(&w, 0, sizeof w);
  w.c = c;
  km_status st = KM_OK;
  w.span_len = km__malloc(c->n * sizeof(double));
  if (!w.span_len) {
    st = km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
    goto cleanup;
  }
  /* the spans in Bezier form, made once for both passes (a few hundred
   * bytes each: kept for curves of up to SPAN_CACHE control points) */
  w.spans = c->n <= SPAN_CACHE ? km__malloc(c->n * sizeof *w.spans) : NULL;
  if (c->n <= SPAN_CACHE && !w.spans) {
    /* out of memory is reported, not worked around: a caller short of
     * memory is better told at once than slowed down */
    st = km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
    goto cleanup;
  }
  st = estimate_lengths(&b, &w);
  if (st) goto cleanup;
  st = set_tolerance(&b, &w, tol, rel_tol);
  if (st) goto cleanup;
  for (size_t i = (size_t)c->degree; i < c->n; i++) {
    bool skip;
    st = enter_span(&b, &w, i, &skip);
    if (st) goto cleanup;
    if (skip) continue;
    st = fit_span(&b, &w, i);
    if (st) goto cleanup;
  }
  double t0, t1;
  km_curve_domain(c, &t0, &t1);
  st = end_turns(&b, &w, t1);
  if (st) goto cleanup;
  st = make_signature(&b, &w, out);
cleanup:
  km__free(w.span_len);
  km__free(w.spans);
  km__free(b.s);
  km__free(b.th);
  km__free(b.corners);
  return st;
}
