/* test_morph_matches.c - morphs whose matches lie next to the ends of the
 * curves or next to each other: every frame is a valid spline, the frames
 * at t = 0 and 1 are the inputs, and the frames tend to the morph without
 * those matches as they approach the ends, within milliseconds.
 *
 * Oracles: a circle of radius 1 into one of radius 2, both about the
 * origin and starting at angle 0, under the turning blend with a
 * correspondence that is the identity up to a length below the tolerance:
 * theta_t(r) = 2 pi r whatever t, so frame t is the circle of radius 1 + t,
 * and the placement ("fit" onto the linear blend of corresponding points,
 * which lie on that circle) keeps it about the origin. Half circles give
 * the arc of radius 1 + t the same way. The linear method blends the two
 * NURBS circles' control points (same knots and weights): the circle of
 * radius 1 + t exactly. Frames of other matches are compared with the
 * frames of the same matches moved a little further in (continuity).
 */
#include <stdbool.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "km/curve.h"
#include "km/fn.h"
#include "km/morph.h"
#include "km/signature.h"
#include "testutil.h"
#include "morphutil.h"
#include "testmain.h"

#define ONE_MINUS                                                              \
  0.99999999999999989 /* 1 - 2^-53, the largest double below 1 */

static const double TIMES[] = {0.0, 1e-300, 0.25, 0.5, 0.75, ONE_MINUS, 1.0};
#define NTIMES (sizeof TIMES / sizeof TIMES[0])

/* ---- inputs -------------------------------------------------------------- */

/* The NURBS circle of radius r about the origin (counter-clockwise from
 * angle 0), or its first half when open. */
static void circle_curve(km_curve *c, double r, bool open) {
  double k[12], cp[18], w[9];
  tu_circle_nurbs(0, 0, r, 1, k, cp, w);
  static const double half[8] = {0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.5};
  km_status st = open ? km_curve_create(c, 2, 5, half, cp, w, false, NULL)
                      : km_curve_create(c, 2, 9, k, cp, w, true, NULL);
  assert_status(st, KM_OK);
}

static double now_seconds(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ---- checks --------------------------------------------------------------- */

/* The frame is a spline km_curve_create accepts (clamped, interior knots
 * of multiplicity <= degree, finite), and so is its curvature
 * (multiplicity <= degree + 1). */
static void assert_valid_frame(const frame *f) {
  km_curve copy;
  km_fn kcopy;
  km_error err;
  km_curve_init(&copy);
  km_fn_init(&kcopy);
  km_status st = km_curve_create(&copy, f->c.degree, f->c.n, f->c.knots,
                                 f->c.cp, f->c.w, f->c.closed, &err);
  if (st) print_error("frame curve: %s\n", err.message);
  assert_status(st, KM_OK);
  st = km_fn_copy(&kcopy, &f->sig.kappa, &err);
  if (st) print_error("frame curvature: %s\n", err.message);
  assert_status(st, KM_OK);
  km_curve_free(&copy);
  km_fn_free(&kcopy);
}

/* Largest | |p| - r | over points of the curve (dense in its parameter). */
static double off_circle(const km_curve *c, double r) {
  double t0, t1, worst = 0.0;
  km_curve_domain(c, &t0, &t1);
  for (int j = 0; j <= 2000; j++) {
    double p[1][2];
    km_curve_eval(c, t0 + (t1 - t0) * j / 2000.0, 0, p);
    worst = fmax(worst, fabs(hypot(p[0][0], p[0][1]) - r));
  }
  return worst;
}

/* Distance from p to curve c: the nearest of n samples, then a golden
 * section search of |c(u) - p| between its neighbours. */
static double point_to_curve(const km_curve *c, const double p[2], size_t n) {
  double t0, t1, best = INFINITY;
  km_curve_domain(c, &t0, &t1);
  size_t jb = 0;
  for (size_t j = 0; j <= n; j++) {
    double q[1][2];
    km_curve_eval(c, t0 + (t1 - t0) * (double)j / (double)n, 0, q);
    double d = hypot(q[0][0] - p[0], q[0][1] - p[1]);
    if (d < best) {
      best = d;
      jb = j;
    }
  }
  double lo = t0 + (t1 - t0) * (double)(jb > 0 ? jb - 1 : 0) / (double)n;
  double hi = t0 + (t1 - t0) * (double)(jb < n ? jb + 1 : n) / (double)n;
  const double g = 0.5 * (sqrt(5.0) - 1.0);
  for (int it = 0; it < 60; it++) {
    double u1 = hi - g * (hi - lo), u2 = lo + g * (hi - lo), q1[1][2], q2[1][2];
    km_curve_eval(c, u1, 0, q1);
    km_curve_eval(c, u2, 0, q2);
    double d1 = hypot(q1[0][0] - p[0], q1[0][1] - p[1]);
    double d2 = hypot(q2[0][0] - p[0], q2[0][1] - p[1]);
    best = fmin(best, fmin(d1, d2));
    if (d1 < d2)
      hi = u2;
    else
      lo = u1;
  }
  return best;
}

/* Distance between two curves as point sets: the largest distance of 200
 * points of either from the other curve. */
static double curve_distance(const km_curve *a, const km_curve *b) {
  double worst = 0.0;
  for (int w = 0; w < 2; w++) {
    const km_curve *c = w ? b : a, *o = w ? a : b;
    double t0, t1;
    km_curve_domain(c, &t0, &t1);
    for (int j = 0; j <= 200; j++) {
      double p[1][2];
      km_curve_eval(c, t0 + (t1 - t0) * j / 200.0, 0, p);
      worst = fmax(worst, point_to_curve(o, p[0], 200));
    }
  }
  return worst;
}

/* ---- a morph with its options --------------------------------------------- */

typedef struct setup {
  bool open;
  km_morph_method method;
  km_blend blend;
  int degree;
} setup;

static km_morph *circles_morph(const setup *s, const double *pairs, size_t n,
                               km_curve *ca, km_curve *cb, double *tol) {
  circle_curve(ca, 1.0, s->open);
  circle_curve(cb, 2.0, s->open);
  km_morph_input A = {ca, NULL}, B = {cb, NULL};
  km_morph_options o;
  km_morph_options_default(&o);
  o.method = s->method;
  o.blend = s->blend;
  o.degree = s->degree;
  o.matches = pairs;
  o.nmatches = n;
  *tol = 1e-5 * (s->open ? 2 * M_PI : 4 * M_PI); /* the default: 1e-5 L_b */
  return morph_new(&A, &B, &o);
}

/* Every frame of the circle morph with these matches is valid and within
 * slack tolerances of the circle (or half circle) of radius 1 + t about
 * the origin; the morph and its frames take under a quarter second (some
 * milliseconds at -O3; the bound leaves room for sanitizer builds). */
static void assert_circles(const setup *s, const double *pairs, size_t n,
                           double slack) {
  km_curve ca, cb;
  double tol;
  double t0 = now_seconds();
  km_morph *m = circles_morph(s, pairs, n, &ca, &cb, &tol);
  frame f[NTIMES];
  for (size_t i = 0; i < NTIMES; i++) frame_get(m, TIMES[i], &f[i]);
  assert_le(now_seconds() - t0, 0.25);
  for (size_t i = 0; i < NTIMES; i++) {
    assert_valid_frame(&f[i]);
    assert_le(off_circle(&f[i].c, 1.0 + TIMES[i]), slack * tol);
    frame_free(&f[i]);
  }
  km_morph_free(m);
  km_curve_free(&ca);
  km_curve_free(&cb);
}

/* Every frame of the morph with `pairs` is valid and within slack
 * tolerances of the frame of the morph with `near` (the same matches a
 * little further in); the frames at t = 0 and 1 are the inputs; the morph
 * and its frames take under a quarter second. */
static void assert_near(const setup *s, const double *pairs, const double *near,
                        size_t n, double slack) {
  km_curve ca, cb, ca2, cb2;
  double tol;
  double t0 = now_seconds();
  km_morph *m = circles_morph(s, pairs, n, &ca, &cb, &tol);
  frame f[NTIMES];
  for (size_t i = 0; i < NTIMES; i++) frame_get(m, TIMES[i], &f[i]);
  assert_le(now_seconds() - t0, 0.25);
  km_morph *r = circles_morph(s, near, n, &ca2, &cb2, &tol);
  for (size_t i = 0; i < NTIMES; i++) {
    frame g;
    frame_get(r, TIMES[i], &g);
    assert_valid_frame(&f[i]);
    assert_le(curve_distance(&f[i].c, &g.c), slack * tol);
    if (TIMES[i] == 0.0 || TIMES[i] == 1.0)
      assert_le(off_circle(&f[i].c, 1.0 + TIMES[i]), tol);
    frame_free(&f[i]);
    frame_free(&g);
  }
  km_morph_free(m);
  km_morph_free(r);
  km_curve_free(&ca);
  km_curve_free(&cb);
  km_curve_free(&ca2);
  km_curve_free(&cb2);
}

static const setup TURNING[] = {
    {false, KM_METHOD_CURVATURE, KM_BLEND_TURNING, 3},
    {false, KM_METHOD_CURVATURE, KM_BLEND_TURNING, 5},
    {true, KM_METHOD_CURVATURE, KM_BLEND_TURNING, 3},
    {true, KM_METHOD_CURVATURE, KM_BLEND_TURNING, 5},
    {false, KM_METHOD_LINEAR, KM_BLEND_TURNING, 3},
    {true, KM_METHOD_LINEAR, KM_BLEND_TURNING, 3},
};
#define NTURNING (sizeof TURNING / sizeof TURNING[0])

/* ---- tests ---------------------------------------------------------------- */

/* Proportional matches at 1e-300, at 1 - 2^-53 and two within 2^-53 of
 * each other are the identity correspondence: the circle of radius 1 + t. */
static void
proportional_matches_next_to_the_ends_keep_the_circle(void **state) {
  (void)state;
  const double at0[2] = {1e-300, 1e-300};
  const double at1[2] = {ONE_MINUS, ONE_MINUS};
  const double twin[4] = {0.5, 0.5, 0.50000000000000011, 0.50000000000000011};
  const double both[4] = {1e-300, 1e-300, ONE_MINUS, ONE_MINUS};
  for (size_t k = 0; k < NTURNING; k++) {
    assert_circles(&TURNING[k], at0, 1, 1.0);
    assert_circles(&TURNING[k], at1, 1, 1.0);
    assert_circles(&TURNING[k], twin, 2, 1.0);
    assert_circles(&TURNING[k], both, 2, 1.0);
  }
}

/* Matches (e_a, e_b) with e_a / e_b far from 1 but both next to an end
 * move the correspondence by at most e_b L from the identity: as they
 * approach the end the frames tend to the circle of radius 1 + t (the
 * match-free morph). Before, a segment of 1e-7 of the curve set the
 * correspondence over half of the other one (4.7e-2 off the circle), and
 * (1e-300, 1e-17) with (1 - 2^-53, 1 - 2^-52) ended the last knot of a
 * frame more than degree + 1 times. */
static void uneven_matches_next_to_the_ends_tend_to_the_circle(void **state) {
  (void)state;
  const double cases[][4] = {
      {1e-9, 1e-7, 0.0, 0.0},
      {1e-12, 1e-10, 0.0, 0.0},
      {1e-300, 1e-17, 0.0, 0.0},
      {1e-300, 1e-17, ONE_MINUS, 0.99999999999999978},
      {0.99999999999999978, ONE_MINUS, 0.0, 0.0},
      {5e-324, 1e-16, 0.0, 0.0},
  };
  for (size_t k = 0; k < NTURNING; k++)
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
      size_t n = cases[c][2] > 0 ? 2 : 1;
      assert_circles(&TURNING[k], cases[c], n, 2.0);
    }
}

/* The finding: the match (1e-300, 1 - 2^-53) maps almost nothing of the
 * circle of radius 1 onto almost all of the other. Its frames are valid
 * and those of (1e-9, 1 - 1e-9) within the tolerance of them; before, the
 * frame at t = 1 was refused (a knot of multiplicity 8 in its curvature). */
static void the_match_from_the_start_to_the_end_is_continuous(void **state) {
  (void)state;
  const setup all[] = {
      {false, KM_METHOD_CURVATURE, KM_BLEND_TURNING, 3},
      {false, KM_METHOD_CURVATURE, KM_BLEND_TURNING, 5},
      {false, KM_METHOD_CURVATURE, KM_BLEND_PAPER, 3},
      {true, KM_METHOD_CURVATURE, KM_BLEND_TURNING, 3},
      {true, KM_METHOD_CURVATURE, KM_BLEND_PAPER, 5},
      {false, KM_METHOD_LINEAR, KM_BLEND_TURNING, 3},
  };
  const double pairs[2] = {1e-300, ONE_MINUS}, near[2] = {1e-9, 1 - 1e-9};
  const double back[2] = {ONE_MINUS, 1e-300}, bnear[2] = {1 - 1e-9, 1e-9};
  const double two[4] = {0.3, 0.6, 0.30000000000000004, 0.9};
  const double tnear[4] = {0.3, 0.6, 0.3 + 1e-9, 0.9};
  for (size_t k = 0; k < sizeof all / sizeof all[0]; k++) {
    assert_near(&all[k], pairs, near, 1, 2.0);
    assert_near(&all[k], back, bnear, 1, 2.0);
    assert_near(&all[k], two, tnear, 2, 2.0);
  }
}

static const struct CMUnitTest tests[] = {
    cmocka_unit_test(proportional_matches_next_to_the_ends_keep_the_circle),
    cmocka_unit_test(uneven_matches_next_to_the_ends_tend_to_the_circle),
    cmocka_unit_test(the_match_from_the_start_to_the_end_is_continuous),
};

TM_SUITE("morph_matches", tests, NULL, NULL);
