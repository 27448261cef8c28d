/* test_morph.c - curvature morphs of open curves: the paper's spiral pair,
 * the curvature bound, the length law, end frames, matched segments,
 * identity preservation, placement anchors and the errors of km_morph.
 *
 * Oracles: the Cornu spirals kappa = c s, whose tangent angle c s^2 / 2 is
 * integrated here by Gauss-Legendre (never by the code under test);
 * piecewise-linear curvature functions whose maximum is the largest
 * coefficient; convexity of the blend (|kappa_t| <= max of the inputs);
 * L_t = (1-t) L_a + t L_b; continuity of theta and kappa across matches;
 * arc-length centroids and end points computed here by quadrature.
 * Curves are compared as point sets (distance to the other curve's dense
 * polyline, plus that polyline's own measured chord error).
 */
#include <stdbool.h>
#include <stdio.h>
#include <string.h>

#include "fixtures.h"
#include "km/curve.h"
#include "km/morph.h"
#include "km/reconstruct.h"
#include "km/signature.h"
#include "curvecases.h"
#include "curvedist.h"
#include "testutil.h"
#include "morphutil.h"
#include "testmain.h"

/* ---- building inputs ---------------------------------------------------- */

/* A signature with piecewise-linear kappa on uniform breaks: coef[0..nc-1]
 * are kappa at s = L i / (nc - 1); corners (s, turn) optional. The exact
 * max |kappa| is the largest |coef|. */
static void pl_signature(km_signature *sig, double L, double x0, double y0,
                         double angle, const double *coef, size_t nc,
                         const km_corner *corners, size_t ncorners,
                         bool closed) {
  double knots[64];
  assert_true(nc >= 2 && nc + 2 <= 64);
  knots[0] = 0.0;
  for (size_t i = 0; i < nc; i++)
    knots[i + 1] = L * (double)i / (double)(nc - 1);
  knots[nc] = knots[nc + 1] = L; /* L i / (nc-1) may round off L */
  km_fn kappa;
  km_error err;
  km_fn_init(&kappa);
  assert_status(km_fn_create(&kappa, 1, nc, knots, coef, &err), KM_OK);
  const double start[2] = {x0, y0};
  km_signature_init(sig);
  assert_status(km_signature_create(sig, L, start, angle, &kappa, corners,
                                    ncorners, closed, &err),
                KM_OK);
  km_fn_free(&kappa);
}

/* The exact tangent angle of a pl_signature (independent of libkmorph). */
typedef struct pl_exact {
  double L, x0, y0, angle;
  const double *coef;
  size_t nc;
  const km_corner *corners;
  size_t ncorners;
} pl_exact;

/* integral of kappa over [0, s] in closed form (trapezoids are exact for a
 * piecewise-linear function on its breaks) */
static double pl_kappa_integral(const pl_exact *e, double s) {
  double h = e->L / (double)(e->nc - 1), acc = 0.0;
  for (size_t i = 0; i + 1 < e->nc; i++) {
    double a = h * (double)i, b = a + h;
    if (s <= a) break;
    double hi = s < b ? s : b, u = (hi - a) / h;
    double kh = e->coef[i] + u * (e->coef[i + 1] - e->coef[i]);
    acc += 0.5 * (e->coef[i] + kh) * (hi - a);
  }
  return acc;
}

static double pl_theta(double s, const void *ctx) {
  const pl_exact *e = ctx;
  double th = e->angle + pl_kappa_integral(e, s);
  for (size_t i = 0; i < e->ncorners; i++)
    if (e->corners[i].s <= s) th += e->corners[i].turn;
  return th;
}

static double pl_cos(double s, const void *ctx) {
  return cos(pl_theta(s, ctx));
}
static double pl_sin(double s, const void *ctx) {
  return sin(pl_theta(s, ctx));
}

/* n + 1 exact points at s = L j / n; corners must lie on that grid (their
 * turn applies from the right, so each sub-interval sees a smooth theta). */
static double *pl_points(const pl_exact *e, size_t n) {
  double *p = malloc(2 * (n + 1) * sizeof *p);
  assert_non_null(p);
  p[0] = e->x0;
  p[1] = e->y0;
  for (size_t j = 1; j <= n; j++) {
    double a = e->L * (double)(j - 1) / (double)n,
           b = e->L * (double)j / (double)n;
    /* a hair inside so a corner at b is not seen inside [a, b] */
    double bi = b - 1e-15 * e->L;
    p[2 * j] = p[2 * j - 2] + tu_integrate(pl_cos, e, a, bi, 1);
    p[2 * j + 1] = p[2 * j - 1] + tu_integrate(pl_sin, e, a, bi, 1);
  }
  return p;
}

/* A random regular open cubic B-spline of n control points. */
static void random_open_curve(km_curve *c, uint64_t *seed, size_t n, double x,
                              double y, double heading, double step) {
  double cp[2 * 64], knots[64 + 4];
  assert_true(n <= 64);
  for (int tries = 0; tries < 100; tries++) {
    tu_gentle_polygon(seed, n, x, y, heading, step, 0.6, cp);
    tu_clamped_knots(seed, 3, n, 0.3, knots);
    if (tu_is_regular(3, n, knots, cp)) break;
  }
  assert_true(tu_is_regular(3, n, knots, cp));
  make_curve(c, 3, n, knots, cp, NULL, false);
}

static void fixture_signature(const char *name, km_signature *sig) {
  tf_analytic a;
  assert_int_equal(tf_load_analytic(name, &a), 0);
  signature_of_analytic(&a, sig);
  tf_analytic_free(&a);
}

/* ---- geometry of results ------------------------------------------------ */

/* Two-sided distance between a curve and exact points (a polyline whose
 * chord error is qerr); the curve's own chord error is measured. Returns
 * the distance minus the polylines' own errors (an upper bound on the
 * distance between the traces, up to those). */
static double trace_distance(const km_curve *c, const double *Q, size_t nq,
                             double qerr) {
  size_t per = per_span(c, 1500), np;
  double *P = curve_points(c, per, &np);
  double perr = chord_error(c, per);
  double d1 = directed_dist(P, np, Q, nq) - qerr;
  double d2 = directed_dist(Q, nq, P, np) - perr;
  free(P);
  return d1 > d2 ? d1 : d2;
}

static void curve_end(const km_curve *c, int which, double p[2]) {
  double t0, t1, d[1][2];
  km_curve_domain(c, &t0, &t1);
  km_curve_eval(c, which ? t1 : t0, 0, d);
  p[0] = d[0][0];
  p[1] = d[0][1];
}

/* ---- the paper's spiral pair (Figs. 3, 5, 6) --------------------------- */

static void spiral_inputs(km_signature *a, km_signature *b) {
  fixture_signature("spiral_a", a);
  fixture_signature("spiral_b", b);
  /* the fixture is what the paper says: kappa_a = s, kappa_b = -s/2 */
  assert_close(km_fn_value(&a->kappa, 3.0), 3.0, 1e-15);
  assert_close(km_fn_value(&b->kappa, 3.0), -1.5, 1e-15);
}

static void
spiral_curvature_frames_never_exceed_the_inputs_curvature(void **state) {
  (void)state;
  km_signature sa, sb;
  spiral_inputs(&sa, &sb);
  km_morph_input A = {NULL, &sa}, B = {NULL, &sb};
  const double kmax = 4.0; /* max(|kappa_a|, |kappa_b|) on [0, 4] */
  for (int blend = 0; blend < 2; blend++) {
    km_morph_options o;
    km_morph_options_default(&o);
    o.blend = blend ? KM_BLEND_PAPER : KM_BLEND_TURNING;
    km_morph *m = morph_new(&A, &B, &o);
    for (int i = 0; i <= 20; i++) {
      double t = i / 20.0;
      frame f;
      frame_get(m, t, &f);
      assert_le(f.mt.max_abs_kappa, kmax * (1 + 1e-9));
      /* the frame's signature itself, on a dense grid */
      for (int j = 0; j <= 400; j++) {
        double s = f.sig.length * j / 400.0;
        assert_le(fabs(km_fn_value(&f.sig.kappa, s)), kmax * (1 + 1e-9));
      }
      /* equal lengths: kappa_t is exactly (1-t) s - t s / 2 = (1 - 1.5 t) s */
      assert_close(km_fn_value(&f.sig.kappa, 2.5), (1 - 1.5 * t) * 2.5, 1e-12);
      if (f.mt.self_intersections != 0)
        print_error("blend %d: frame t = %g crosses itself %ld times\n", blend,
                    t, f.mt.self_intersections);
      assert_int_equal(f.mt.self_intersections, 0);
      assert_int_equal(km_curve_self_intersections(&f.c, 0), 0);
      frame_free(&f);
    }
    km_morph_free(m);
  }
  km_signature_free(&sa);
  km_signature_free(&sb);
}

/* Frames are held to max_points control points: within it, or refused on
 * the tolerance (when the morph is made for planned frames, when the frame
 * is made for the paper's blend). At 1e-10 the spiral kappa = s on [0, 4],
 * frame 0, is planned in cubic pieces no longer than h(s) = (384 tol' /
 * s^3)^(1/4) where they lie (the a-priori bound takes the largest |C''''|
 * >= kappa^3 over a piece, tol' the pieces' share): some 600 pieces, two
 * control points each. Frames merge runs of them into single cubics; a
 * cubic is off an arc of radius 1 / s turning phi by about phi^6 / (56000
 * s) at best (test_compact.c), so the cubics are no longer than (56000 tol
 * / s^5)^(1/6), and the integral of ds over that, 4^(11/6) / (11/6) /
 * (56000 tol)^(1/6), leaves 52 of them at least. */
static void frames_hold_to_a_number_of_points(void **state) {
  (void)state;
  km_signature sa, sb;
  spiral_inputs(&sa, &sb);
  km_morph_input A = {NULL, &sa}, B = {NULL, &sb};
  for (int blend = 0; blend < 2; blend++) {
    const size_t limits[] = {100000, 5000, 40};
    for (size_t k = 0; k < 3; k++) {
      km_morph_options o;
      km_morph_options_default(&o);
      o.blend = blend ? KM_BLEND_PAPER : KM_BLEND_TURNING;
      o.tolerance = 1e-10;
      o.max_points = limits[k];
      km_morph *m = NULL;
      km_error err;
      km_status st = km_morph_create(&m, &A, &B, &o, &err);
      for (int i = 0; i <= 4 && st == KM_OK; i++) {
        km_curve c;
        km_curve_init(&c);
        st = km_morph_frame(m, i / 4.0, &c, NULL, NULL, &err);
        if (st == KM_OK) {
          assert_true(c.n <= limits[k]);
          if (i == 0) assert_true(c.n >= 2 * 52);
        }
        km_curve_free(&c);
      }
      km_morph_free(m);
      if (limits[k] >= 5000) {
        assert_status(st, KM_OK);
      } else {
        assert_status(st, KM_ELIMIT);
        assert_int_equal(err.field, KM_FIELD_TOLERANCE);
      }
    }
  }
  km_signature_free(&sa);
  km_signature_free(&sb);
}

static void spiral_linear_baseline_exceeds_the_inputs_curvature(void **state) {
  (void)state;
  km_signature sa, sb;
  spiral_inputs(&sa, &sb);
  km_morph_input A = {NULL, &sa}, B = {NULL, &sb};
  km_morph_options o;
  km_morph_options_default(&o);
  o.method = KM_METHOD_LINEAR;
  km_morph *m = morph_new(&A, &B, &o);
  double worst = 0.0, worst_t = -1;
  for (int i = 0; i <= 20; i++) {
    double t = i / 20.0;
    frame f;
    frame_get(m, t, &f);
    if (f.mt.max_abs_kappa > worst) {
      worst = f.mt.max_abs_kappa;
      worst_t = t;
    }
    frame_free(&f);
  }
  /* Fig. 6: somewhere between the ends the baseline bends harder than
   * either input (the ends themselves stay near 4) */
  assert_true(worst_t > 0.0 && worst_t < 1.0);
  assert_le(4.0 * 1.05, worst);
  km_morph_free(m);
  km_signature_free(&sa);
  km_signature_free(&sb);
}

/* kappa = c s from (0,0), angle 0: exact points on a grid */
static double *cornu_points(double c, double L, size_t n, double *qerr) {
  pl_exact e = {L, 0, 0, 0, NULL, 2, NULL, 0};
  double coef[2] = {0.0, c * L};
  e.coef = coef;
  double *p = pl_points(&e, n);
  /* chord error of an arc of curvature <= |c| L and length h: h^2 k / 8 */
  double h = L / (double)n;
  *qerr = h * h * fabs(c) * L / 8.0;
  return p;
}

static void spiral_end_frames_are_the_exact_spirals(void **state) {
  (void)state;
  km_signature sa, sb;
  spiral_inputs(&sa, &sb);
  km_morph_input A = {NULL, &sa}, B = {NULL, &sb};
  double qa, qb;
  double *Pa = cornu_points(1.0, 4.0, 4000, &qa);
  double *Pb = cornu_points(-0.5, 4.0, 4000, &qb);
  const km_anchor anchors[3] = {KM_ANCHOR_FIT, KM_ANCHOR_START,
                                KM_ANCHOR_CENTROID};
  for (int an = 0; an < 3; an++) {
    km_morph_options o;
    km_morph_options_default(&o);
    o.anchor = anchors[an];
    km_morph *m = morph_new(&A, &B, &o);
    const double tol = 1e-5 * 4.0;
    frame f0, f1;
    frame_get(m, 0.0, &f0);
    frame_get(m, 1.0, &f1);
    assert_le(trace_distance(&f0.c, Pa, 4001, qa), tol);
    assert_le(trace_distance(&f1.c, Pb, 4001, qb), tol);
    /* and the frames run the same way: they start at the inputs' start */
    double p[2];
    curve_end(&f0.c, 0, p);
    assert_close(hypot(p[0], p[1]), 0.0, tol);
    curve_end(&f1.c, 1, p);
    assert_close(hypot(p[0] - Pb[8000], p[1] - Pb[8001]), 0.0, tol);
    frame_free(&f0);
    frame_free(&f1);
    km_morph_free(m);
  }
  free(Pa);
  free(Pb);
  km_signature_free(&sa);
  km_signature_free(&sb);
}

/* Frames without metrics or signature (the service's default answer) are
 * built from a plan made once per morph (core/src/morph_plan.c). With
 * equal lengths the turning blend of the spirals is exactly
 *   theta_t(s) = theta0 + ((1 - t) / 2 - t / 4) s^2,
 * and with anchor start the frame starts at the blended start point: the
 * planned frame must lie within the tolerance of that curve, as point sets
 * (runs of its pieces are merged into cubics whose parameter leaves arc
 * length between their knots): the exact curve's points against the
 * frame's polyline, the frame's points against the exact polyline, each
 * less that polyline's chord error (h^2 max|kappa| / 8 for the exact one,
 * |kappa| <= |c2| 2 s <= 4). */
typedef struct blended_spiral {
  double th0, c2;
} blended_spiral;

static double blended_spiral_cos(double s, const void *p) {
  const blended_spiral *b = p;
  return cos(b->th0 + b->c2 * s * s);
}

static double blended_spiral_sin(double s, const void *p) {
  const blended_spiral *b = p;
  return sin(b->th0 + b->c2 * s * s);
}

#define SPIRAL_SAMPLES 1600

static void planned_spiral_frames_are_the_exact_blended_spirals(void **state) {
  (void)state;
  km_signature sa, sb;
  spiral_inputs(&sa, &sb);
  km_morph_input A = {NULL, &sa}, B = {NULL, &sb};
  km_morph_options o;
  km_morph_options_default(&o);
  o.anchor = KM_ANCHOR_START;
  km_morph *m = morph_new(&A, &B, &o);
  const double tol = 1e-5 * 4.0, h = 4.0 / SPIRAL_SAMPLES;
  double phia = sa.angle, phib = phia + tu_wrap(sb.angle - phia);
  double *E = malloc(2 * (SPIRAL_SAMPLES + 1) * sizeof *E);
  assert_non_null(E);
  for (int i = 0; i <= 8; i++) {
    double t = i / 8.0;
    km_curve c;
    km_error err;
    assert_status(km_morph_frame(m, t, &c, NULL, NULL, &err), KM_OK);
    double t0, t1;
    km_curve_domain(&c, &t0, &t1);
    assert_close(t1 - t0, 4.0, 1e-12);
    blended_spiral bs = {(1 - t) * phia + t * phib, (1 - t) / 2 - t / 4};
    double x = (1 - t) * sa.start[0] + t * sb.start[0],
           y = (1 - t) * sa.start[1] + t * sb.start[1];
    for (int j = 0; j <= SPIRAL_SAMPLES; j++) {
      if (j > 0) {
        x += tu_integrate(blended_spiral_cos, &bs, h * (j - 1), h * j, 1);
        y += tu_integrate(blended_spiral_sin, &bs, h * (j - 1), h * j, 1);
      }
      E[2 * j] = x;
      E[2 * j + 1] = y;
    }
    size_t per = per_span(&c, 4 * SPIRAL_SAMPLES), nq;
    double *Q = curve_points(&c, per, &nq);
    double d1 = directed_dist(E, SPIRAL_SAMPLES + 1, Q, nq) -
                chord_error(&c, per),
           d2 = directed_dist(Q, nq, E, SPIRAL_SAMPLES + 1) - h * h * 4 / 8;
    double worst = fmax(d1, d2);
    free(Q);
    if (worst > tol)
      print_error("t = %g: %.3g from the exact frame\n", t, worst);
    assert_le(worst, tol);
    km_curve_free(&c);
  }
  free(E);
  km_morph_free(m);
  km_signature_free(&sa);
  km_signature_free(&sb);
}

/* ---- random pairs -------------------------------------------------------- */

/* A random open pl_signature of length L: nc coefficients in [-kmax, kmax]
 * (one of them exactly +-kmax) and corners at grid points s = L j / 64. */
typedef struct rsig {
  double coef[16];
  km_corner corners[3];
  size_t nc, ncorners;
  double L, x0, y0, angle, kmax;
} rsig;

static void rsig_random(rsig *r, uint64_t *seed) {
  r->nc = 2 + (size_t)(tu_rand(seed) * 10);
  r->L = tu_uniform(seed, 1.0, 6.0);
  r->kmax = tu_uniform(seed, 0.2, 2.0);
  for (size_t i = 0; i < r->nc; i++)
    r->coef[i] = tu_uniform(seed, -r->kmax, r->kmax);
  size_t peak = (size_t)(tu_rand(seed) * (double)r->nc);
  r->coef[peak] = tu_rand(seed) < 0.5 ? r->kmax : -r->kmax;
  r->ncorners = (size_t)(tu_rand(seed) * 3);
  int used = 0;
  for (size_t i = 0; i < r->ncorners; i++) {
    int j = used + 1 + (int)(tu_rand(seed) * 15);
    used = j;
    r->corners[i].s = r->L * j / 64.0;
    r->corners[i].turn = tu_uniform(seed, -1.2, 1.2);
  }
  r->x0 = tu_uniform(seed, -3, 3);
  r->y0 = tu_uniform(seed, -3, 3);
  r->angle = tu_uniform(seed, -3, 3);
}

static void rsig_make(const rsig *r, km_signature *sig) {
  pl_signature(sig, r->L, r->x0, r->y0, r->angle, r->coef, r->nc, r->corners,
               r->ncorners, false);
}

static size_t random_matches(uint64_t *seed, double *pairs) {
  size_t n = (size_t)(tu_rand(seed) * 5);
  double a = 0.0, b = 0.0;
  for (size_t i = 0; i < n; i++) {
    a += tu_uniform(seed, 0.02, 0.9 * (1 - a) / (double)(n - i));
    b += tu_uniform(seed, 0.02, 0.9 * (1 - b) / (double)(n - i));
    pairs[2 * i] = a;
    pairs[2 * i + 1] = b;
  }
  return n;
}

static void curvature_bound_holds_for_random_pairs_and_matches(void **state) {
  (void)state;
  uint64_t seed = 0x5eed1234abcdULL;
  for (int trial = 0; trial < 24; trial++) {
    rsig ra, rb;
    rsig_random(&ra, &seed);
    rsig_random(&rb, &seed);
    km_signature sa, sb;
    rsig_make(&ra, &sa);
    rsig_make(&rb, &sb);
    double kmax = fmax(ra.kmax, rb.kmax);
    double pairs[10];
    km_morph_options o;
    km_morph_options_default(&o);
    o.nmatches = random_matches(&seed, pairs);
    o.matches = pairs;
    o.blend = trial % 2 ? KM_BLEND_PAPER : KM_BLEND_TURNING;
    km_morph_input A = {NULL, &sa}, B = {NULL, &sb};
    km_morph *m = morph_new(&A, &B, &o);
    for (int i = 0; i < 3; i++) {
      double t = tu_rand(&seed);
      frame f;
      frame_get(m, t, &f);
      assert_le(f.mt.max_abs_kappa, kmax * (1 + 1e-9));
      for (int j = 0; j <= 300; j++) {
        double s = f.sig.length * j / 300.0;
        assert_le(fabs(km_fn_value(&f.sig.kappa, s)), kmax * (1 + 1e-9));
      }
      frame_free(&f);
    }
    km_morph_free(m);
    km_signature_free(&sa);
    km_signature_free(&sb);
  }
}

static void curvature_bound_holds_for_curve_inputs(void **state) {
  (void)state;
  uint64_t seed = 0xc0ffee17ULL;
  for (int trial = 0; trial < 6; trial++) {
    km_curve ca, cb;
    random_open_curve(&ca, &seed, 8 + (size_t)trial, 0, 0, 0.3, 1.0);
    random_open_curve(&cb, &seed, 12, 2, 1, -0.5, 0.7);
    /* the inputs' own signatures, given with them, fix the bound */
    km_signature sa, sb;
    km_error err;
    double tol = 1e-5 * fmax(km_curve_length(&ca), km_curve_length(&cb));
    assert_status(km_signature_compute(&ca, 0.1 * tol, &sa, &err), KM_OK);
    assert_status(km_signature_compute(&cb, 0.1 * tol, &sb, &err), KM_OK);
    double kmax =
        fmax(km_signature_max_abs_kappa(&sa), km_signature_max_abs_kappa(&sb));
    double pairs[10];
    km_morph_options o;
    km_morph_options_default(&o);
    o.nmatches = random_matches(&seed, pairs);
    o.matches = pairs;
    km_morph_input A = {&ca, &sa}, B = {&cb, &sb};
    km_morph *m = morph_new(&A, &B, &o);
    for (int i = 1; i <= 3; i++) {
      frame f;
      frame_get(m, i / 4.0, &f);
      assert_le(f.mt.max_abs_kappa, kmax * (1 + 1e-9));
      frame_free(&f);
    }
    km_morph_free(m);
    km_signature_free(&sa);
    km_signature_free(&sb);
    km_curve_free(&ca);
    km_curve_free(&cb);
  }
}

static void every_frame_has_the_interpolated_length(void **state) {
  (void)state;
  uint64_t seed = 0x1e2d3c4bULL;
  for (int trial = 0; trial < 12; trial++) {
    rsig ra, rb;
    rsig_random(&ra, &seed);
    rsig_random(&rb, &seed);
    km_signature sa, sb;
    rsig_make(&ra, &sa);
    rsig_make(&rb, &sb);
    double pairs[10];
    km_morph_options o;
    km_morph_options_default(&o);
    o.nmatches = random_matches(&seed, pairs);
    o.matches = pairs;
    o.blend = trial % 2 ? KM_BLEND_PAPER : KM_BLEND_TURNING;
    o.anchor = (km_anchor)(trial % 3);
    km_morph_input A = {NULL, &sa}, B = {NULL, &sb};
    km_morph *m = morph_new(&A, &B, &o);
    double tol = 1e-5 * fmax(ra.L, rb.L);
    for (int i = 0; i <= 4; i++) {
      double t = i / 4.0, Lt = (1 - t) * ra.L + t * rb.L;
      frame f;
      frame_get(m, t, &f);
      assert_rel(f.mt.length, Lt, 1e-9);
      assert_rel(f.sig.length, Lt, 1e-9);
      /* the curve's parameter is arc length of the exact frame */
      double t0, t1;
      km_curve_domain(&f.c, &t0, &t1);
      assert_rel(t1 - t0, Lt, 1e-9);
      /* and the curve itself, within the tolerance, is that long: the
       * length of a curve within tol of another differs by far less than
       * its length times tol / (shortest feature); 1e-4 is loose */
      assert_rel(km_curve_length(&f.c), Lt, 1e-4 + 10 * tol / Lt);
      frame_free(&f);
    }
    km_morph_free(m);
    km_signature_free(&sa);
    km_signature_free(&sb);
  }
}

static void
end_frames_of_random_pairs_are_the_inputs_where_they_stand(void **state) {
  (void)state;
  uint64_t seed = 0xabcdef01ULL;
  for (int trial = 0; trial < 6; trial++) {
    rsig r[2];
    km_signature s[2];
    double *P[2], qerr[2];
    for (int k = 0; k < 2; k++) {
      rsig_random(&r[k], &seed);
      rsig_make(&r[k], &s[k]);
      pl_exact e = {r[k].L,    r[k].x0, r[k].y0,      r[k].angle,
                    r[k].coef, r[k].nc, r[k].corners, r[k].ncorners};
      P[k] = pl_points(&e, 64 * 40);
      double h = r[k].L / (64 * 40);
      qerr[k] = h * h * r[k].kmax / 8;
    }
    double pairs[10];
    km_morph_options o;
    km_morph_options_default(&o);
    o.nmatches = random_matches(&seed, pairs);
    o.matches = pairs;
    o.anchor = (km_anchor)(trial % 3);
    o.blend = trial % 2 ? KM_BLEND_PAPER : KM_BLEND_TURNING;
    km_morph_input A = {NULL, &s[0]}, B = {NULL, &s[1]};
    km_morph *m = morph_new(&A, &B, &o);
    double tol = 1e-5 * fmax(r[0].L, r[1].L);
    for (int k = 0; k < 2; k++) {
      frame f;
      frame_get(m, (double)k, &f);
      assert_le(trace_distance(&f.c, P[k], 64 * 40 + 1, qerr[k]), tol);
      double p[2];
      curve_end(&f.c, 0, p);
      assert_close(hypot(p[0] - r[k].x0, p[1] - r[k].y0), 0.0, tol);
      frame_free(&f);
      free(P[k]);
      km_signature_free(&s[k]);
    }
    km_morph_free(m);
  }
}

static void end_frames_of_curve_inputs_trace_the_inputs(void **state) {
  (void)state;
  uint64_t seed = 0x77aa55ULL;
  for (int trial = 0; trial < 3; trial++) {
    km_curve ca, cb;
    random_open_curve(&ca, &seed, 10, 0, 0, 0.3, 1.0);
    random_open_curve(&cb, &seed, 14, 3, -2, 2.0, 0.6);
    km_morph_options o;
    km_morph_options_default(&o);
    o.anchor = (km_anchor)trial;
    km_morph_input A = {&ca, NULL}, B = {&cb, NULL};
    km_morph *m = morph_new(&A, &B, &o);
    double tol = 1e-5 * fmax(km_curve_length(&ca), km_curve_length(&cb));
    frame f0, f1;
    frame_get(m, 0.0, &f0);
    frame_get(m, 1.0, &f1);
    assert_le(curves_distance(&f0.c, &ca, 1500), tol);
    assert_le(curves_distance(&f1.c, &cb, 1500), tol);
    frame_free(&f0);
    frame_free(&f1);
    km_morph_free(m);
    km_curve_free(&ca);
    km_curve_free(&cb);
  }
}

/* ---- matched segments --------------------------------------------------- */

/* Frame arc length of match i at time t: the segments before it have
 * lengths (1-t) la_k + t lb_k. */
static double match_s(const double *pairs, size_t i, double La, double Lb,
                      double t) {
  return (1 - t) * pairs[2 * i] * La + t * pairs[2 * i + 1] * Lb;
}

/* theta and kappa of the frame on both sides of each match */
static void check_g2_at_matches(km_blend blend) {
  uint64_t seed = 0x9a2b3c4dULL;
  long kappa_jumps = 0, checked = 0;
  double worst_jump = 0.0;
  for (int trial = 0; trial < 10; trial++) {
    rsig ra, rb;
    rsig_random(&ra, &seed);
    rsig_random(&rb, &seed);
    ra.ncorners = rb.ncorners = 0; /* corners away from the matches only */
    km_signature sa, sb;
    rsig_make(&ra, &sa);
    rsig_make(&rb, &sb);
    double pairs[10];
    size_t n = random_matches(&seed, pairs);
    if (n == 0) {
      pairs[0] = 0.3;
      pairs[1] = 0.6;
      n = 1;
    }
    km_morph_options o;
    km_morph_options_default(&o);
    o.nmatches = n;
    o.matches = pairs;
    o.blend = blend;
    km_morph_input A = {NULL, &sa}, B = {NULL, &sb};
    km_morph *m = morph_new(&A, &B, &o);
    double kmax = fmax(ra.kmax, rb.kmax);
    for (int it = 1; it <= 3; it++) {
      double t = it / 4.0;
      frame f;
      frame_get(m, t, &f);
      for (size_t i = 0; i < n; i++) {
        double s = match_s(pairs, i, ra.L, rb.L, t);
        double eps = 1e-7 * f.sig.length;
        double thl = km_signature_theta(&f.sig, s - eps);
        double thr = km_signature_theta(&f.sig, s + eps);
        /* G1: theta moves by at most kmax * 2 eps across the match */
        assert_le(fabs(thr - thl), 2 * eps * kmax + 1e-12);
        /* G2: kappa on both sides agrees up to its slope times 2 eps (the
         * inputs' kappa has slope <= 2 kmax nc / L) */
        double kl = km_fn_value(&f.sig.kappa, s - eps);
        double kr = km_fn_value(&f.sig.kappa, s + eps);
        double slope =
            4 * kmax * 12 / fmin(ra.L, rb.L) * (1 + ra.L / rb.L + rb.L / ra.L);
        double jump = fabs(kr - kl);
        checked++;
        if (jump > 2 * eps * slope + 1e-9 * kmax) {
          kappa_jumps++;
          if (jump > worst_jump) worst_jump = jump;
        }
      }
      frame_free(&f);
    }
    km_morph_free(m);
    km_signature_free(&sa);
    km_signature_free(&sb);
  }
  if (kappa_jumps)
    print_error("blend %s: curvature jumps at %ld of %ld matched points "
                "(largest jump %.3g)\n",
                blend == KM_BLEND_PAPER ? "paper" : "turning", kappa_jumps,
                checked, worst_jump);
  assert_int_equal(kappa_jumps, 0);
}

static void matched_segments_join_with_g2_under_the_paper_blend(void **state) {
  (void)state;
  check_g2_at_matches(KM_BLEND_PAPER);
}

static void
matched_segments_join_with_g2_under_the_turning_blend(void **state) {
  (void)state;
  check_g2_at_matches(KM_BLEND_TURNING);
}

/* the smallest case of the above, with numbers: a circle of radius 1 and
 * one of radius 2 (both open, a quarter turn each way) matched at
 * (1/4, 1/2): kappa_a = 1, kappa_b = 1/2 everywhere, so any blend that is
 * G2 must have continuous kappa at the match. (Weighting by segment
 * lengths, ((1-t) la kappa_a + t lb kappa_b) / l, gives 3/5 before and 5/7
 * after it at t = 1/2: la, lb = pi/8, pi/2 and then 3 pi/8, pi/2.) */
static void matched_arcs_have_continuous_curvature(void **state) {
  (void)state;
  km_signature sa, sb;
  double ka[2] = {1.0, 1.0}, kb[2] = {0.5, 0.5};
  pl_signature(&sa, M_PI / 2, 0, 0, 0, ka, 2, NULL, 0, false);
  pl_signature(&sb, M_PI, 0, 0, 0, kb, 2, NULL, 0, false);
  double pairs[2] = {0.25, 0.5}, kl[2], kr[2];
  for (int blend = 0; blend < 2; blend++) {
    km_morph_options o;
    km_morph_options_default(&o);
    o.nmatches = 1;
    o.matches = pairs;
    o.blend = blend ? KM_BLEND_PAPER : KM_BLEND_TURNING;
    km_morph_input A = {NULL, &sa}, B = {NULL, &sb};
    km_morph *m = morph_new(&A, &B, &o);
    frame f;
    frame_get(m, 0.5, &f);
    double s = match_s(pairs, 0, M_PI / 2, M_PI, 0.5);
    kl[blend] = km_fn_value(&f.sig.kappa, s * (1 - 1e-9));
    kr[blend] = km_fn_value(&f.sig.kappa, s * (1 + 1e-9));
    if (fabs(kl[blend] - kr[blend]) > 1e-9)
      print_error("blend %s: kappa %.17g before the match, %.17g after\n",
                  blend ? "paper" : "turning", kl[blend], kr[blend]);
    frame_free(&f);
    km_morph_free(m);
  }
  km_signature_free(&sa);
  km_signature_free(&sb);
  /* asserted after freeing, so a failure leaks nothing */
  for (int blend = 0; blend < 2; blend++)
    assert_close(kl[blend], kr[blend], 1e-9);
  /* the paper's formula gives (1-t) 1 + t / 2 on both sides */
  assert_close(kl[1], 0.75, 1e-12);
}

static void proportional_matches_give_the_global_morph(void **state) {
  (void)state;
  uint64_t seed = 0x3141592653ULL;
  for (int trial = 0; trial < 6; trial++) {
    km_signature sa, sb;
    double La, Lb;
    if (trial == 0) {
      spiral_inputs(&sa, &sb);
      La = Lb = 4.0;
    } else {
      rsig ra, rb;
      rsig_random(&ra, &seed);
      rsig_random(&rb, &seed);
      rsig_make(&ra, &sa);
      rsig_make(&rb, &sb);
      La = ra.L;
      Lb = rb.L;
    }
    double pairs[8];
    size_t n = 1 + (size_t)(tu_rand(&seed) * 4);
    double r = 0.0;
    for (size_t i = 0; i < n; i++) {
      r += tu_uniform(&seed, 0.05, 0.9 * (1 - r) / (double)(n - i));
      pairs[2 * i] = pairs[2 * i + 1] = r;
    }
    double tol = 1e-5 * fmax(La, Lb);
    km_morph_input A = {NULL, &sa}, B = {NULL, &sb};
    for (int blend = 0; blend < 2; blend++) {
      km_morph_options o;
      km_morph_options_default(&o);
      o.blend = blend ? KM_BLEND_PAPER : KM_BLEND_TURNING;
      o.anchor = (km_anchor)(trial % 3);
      km_morph *plain = morph_new(&A, &B, &o);
      o.nmatches = n;
      o.matches = pairs;
      km_morph *matched = morph_new(&A, &B, &o);
      for (int i = 0; i <= 4; i++) {
        frame f, g;
        frame_get(plain, i / 4.0, &f);
        frame_get(matched, i / 4.0, &g);
        /* each within tol of the exact frame, as point sets */
        assert_le(curves_distance(&f.c, &g.c, 1200), 2 * tol);
        for (int j = 0; j <= 50; j++) {
          double s = f.sig.length * j / 50.0;
          assert_close(km_fn_value(&g.sig.kappa, s),
                       km_fn_value(&f.sig.kappa, s),
                       1e-9 * (1 + fabs(km_fn_value(&f.sig.kappa, s))));
        }
        frame_free(&f);
        frame_free(&g);
      }
      km_morph_free(plain);
      km_morph_free(matched);
    }
    km_signature_free(&sa);
    km_signature_free(&sb);
  }
}

static void matches_used_reports_the_given_pairs(void **state) {
  (void)state;
  km_signature sa, sb;
  spiral_inputs(&sa, &sb);
  const double pairs[6] = {0.1, 0.3, 0.5, 0.4, 0.9, 0.95};
  km_morph_options o;
  km_morph_options_default(&o);
  o.matches = pairs;
  o.nmatches = 3;
  km_morph_input A = {NULL, &sa}, B = {NULL, &sb};
  km_morph *m = morph_new(&A, &B, &o);
  double got[6];
  assert_int_equal(km_morph_matches_used(m, got, 3), 3);
  for (int i = 0; i < 6; i++) assert_close(got[i], pairs[i], 0.0);
  assert_int_equal(km_morph_matches_used(m, NULL, 0), 3);
  km_morph_free(m);
  km_signature_free(&sa);
  km_signature_free(&sb);
}

/* A U (two legs and a half circle) into an S: auto matches are strictly
 * increasing pairs in (0, 1), and a morph made with them works. */
static void auto_matches_are_a_valid_correspondence(void **state) {
  (void)state;
  km_signature sa, sb;
  double ku[7] = {0, 0, 2, 2, 2, 0, 0}, ks[7] = {2, 2, 2, 0, -2, -2, -2};
  pl_signature(&sa, 4.0, 0, 0, -M_PI / 2, ku, 7, NULL, 0, false);
  pl_signature(&sb, 4.5, 0, 0, 0.0, ks, 7, NULL, 0, false);
  km_morph_options o;
  km_morph_options_default(&o);
  o.auto_matches = true;
  km_morph_input A = {NULL, &sa}, B = {NULL, &sb};
  km_morph *m = morph_new(&A, &B, &o);
  size_t n = km_morph_matches_used(m, NULL, 0);
  double *p = malloc((2 * n + 2) * sizeof *p);
  assert_int_equal(km_morph_matches_used(m, p, n), n);
  double pa = 0.0, pb = 0.0;
  for (size_t i = 0; i < n; i++) {
    assert_true(p[2 * i] > pa && p[2 * i] < 1.0);
    assert_true(p[2 * i + 1] > pb && p[2 * i + 1] < 1.0);
    pa = p[2 * i];
    pb = p[2 * i + 1];
  }
  free(p);
  frame f;
  frame_get(m, 0.5, &f);
  assert_rel(f.mt.length, 4.25, 1e-9);
  assert_le(f.mt.max_abs_kappa, 2.0 * (1 + 1e-9));
  frame_free(&f);
  km_morph_free(m);
  km_signature_free(&sa);
  km_signature_free(&sb);
}

/* ---- placement ---------------------------------------------------------- */

/* Two placed spirals: a at (0,0) heading 0, b at (5, 2) heading 1.2. */
static void placed_spirals(km_signature *sa, km_signature *sb) {
  double ka[2] = {0.0, 4.0}, kb[2] = {0.0, -2.0};
  pl_signature(sa, 4.0, 0, 0, 0.0, ka, 2, NULL, 0, false);
  pl_signature(sb, 3.0, 5, 2, 1.2, kb, 2, NULL, 0, false);
}

static void
anchor_start_moves_the_start_point_on_a_straight_line(void **state) {
  (void)state;
  km_signature sa, sb;
  placed_spirals(&sa, &sb);
  km_morph_options o;
  km_morph_options_default(&o);
  o.anchor = KM_ANCHOR_START;
  km_morph_input A = {NULL, &sa}, B = {NULL, &sb};
  km_morph *m = morph_new(&A, &B, &o);
  double tol = 1e-5 * 4.0;
  for (int i = 0; i <= 8; i++) {
    double t = i / 8.0, p[2];
    frame f;
    frame_get(m, t, &f);
    curve_end(&f.c, 0, p);
    /* on the line from (0,0) to (5,2), at the linear position */
    assert_close(fabs(p[0] * 2 - p[1] * 5) / hypot(5, 2), 0.0, tol);
    assert_close(p[0], 5 * t, tol);
    assert_close(p[1], 2 * t, tol);
    /* start angle interpolated linearly too (paper) */
    assert_close(tu_wrap(f.sig.angle - 1.2 * t), 0.0, 1e-9);
    frame_free(&f);
  }
  km_morph_free(m);
  km_signature_free(&sa);
  km_signature_free(&sb);
}

static void
anchor_centroid_moves_the_centroid_on_a_straight_line(void **state) {
  (void)state;
  km_signature sa, sb;
  placed_spirals(&sa, &sb);
  km_morph_options o;
  km_morph_options_default(&o);
  o.anchor = KM_ANCHOR_CENTROID;
  km_morph_input A = {NULL, &sa}, B = {NULL, &sb};
  km_morph *m = morph_new(&A, &B, &o);
  double tol = 1e-5 * 4.0;
  double c0[2], c1[2];
  frame f0, f1;
  frame_get(m, 0.0, &f0);
  frame_get(m, 1.0, &f1);
  curve_centroid(&f0.c, c0);
  curve_centroid(&f1.c, c1);
  frame_free(&f0);
  frame_free(&f1);
  for (int i = 1; i < 8; i++) {
    double t = i / 8.0, c[2];
    frame f;
    frame_get(m, t, &f);
    curve_centroid(&f.c, c);
    double want[2] = {(1 - t) * c0[0] + t * c1[0], (1 - t) * c0[1] + t * c1[1]};
    if (hypot(c[0] - want[0], c[1] - want[1]) > 2 * tol)
      print_error(
          "t = %g: centroid (%.9f, %.9f), the line's point (%.9f, %.9f)\n", t,
          c[0], c[1], want[0], want[1]);
    assert_le(hypot(c[0] - want[0], c[1] - want[1]), 2 * tol);
    frame_free(&f);
  }
  km_morph_free(m);
  km_signature_free(&sa);
  km_signature_free(&sb);
}

/* fit: the end frames are the inputs where they stand (not moved toward
 * each other), here for inputs far apart and turned. */
static void
anchor_fit_keeps_the_end_frames_where_the_inputs_stand(void **state) {
  (void)state;
  km_signature sa, sb;
  placed_spirals(&sa, &sb);
  km_morph_input A = {NULL, &sa}, B = {NULL, &sb};
  km_morph_options o;
  km_morph_options_default(&o);
  assert_int_equal(o.anchor, KM_ANCHOR_FIT);
  km_morph *m = morph_new(&A, &B, &o);
  double ka[2] = {0.0, 4.0}, kb[2] = {0.0, -2.0};
  pl_exact ea = {4.0, 0, 0, 0.0, ka, 2, NULL, 0},
           eb = {3.0, 5, 2, 1.2, kb, 2, NULL, 0};
  double *Pa = pl_points(&ea, 3000), *Pb = pl_points(&eb, 3000);
  double qa = pow(4.0 / 3000, 2) * 4 / 8, qb = pow(3.0 / 3000, 2) * 2 / 8;
  double tol = 1e-5 * 4.0;
  frame f0, f1;
  frame_get(m, 0.0, &f0);
  frame_get(m, 1.0, &f1);
  assert_le(trace_distance(&f0.c, Pa, 3001, qa), tol);
  assert_le(trace_distance(&f1.c, Pb, 3001, qb), tol);
  /* and a middle frame lies between them: its centroid is within the hull
   * of the two inputs' centroids widened by their sizes */
  frame fm;
  frame_get(m, 0.5, &fm);
  double c[2], ca[2], cb[2];
  curve_centroid(&fm.c, c);
  curve_centroid(&f0.c, ca);
  curve_centroid(&f1.c, cb);
  assert_le(hypot(c[0] - 0.5 * (ca[0] + cb[0]), c[1] - 0.5 * (ca[1] + cb[1])),
            0.5 * hypot(ca[0] - cb[0], ca[1] - cb[1]));
  frame_free(&fm);
  frame_free(&f0);
  frame_free(&f1);
  free(Pa);
  free(Pb);
  km_morph_free(m);
  km_signature_free(&sa);
  km_signature_free(&sb);
}

/* ---- errors ------------------------------------------------------------- */

/* closed circle signature of radius r turning `turns` times (sign =
 * orientation) */
static void circle_signature(km_signature *sig, double r, int turns) {
  double k[2] = {(turns > 0 ? 1 : -1) / r, (turns > 0 ? 1 : -1) / r};
  pl_signature(sig, 2 * M_PI * r * abs(turns), 0, 0, 0, k, 2, NULL, 0, true);
}

static void different_turning_numbers_are_rejected_naming_both(void **state) {
  (void)state;
  km_signature once, twice;
  circle_signature(&once, 1.0, 1);
  circle_signature(&twice, 0.7, 2);
  km_morph_options o;
  km_morph_options_default(&o);
  km_morph_input A = {NULL, &once}, B = {NULL, &twice};
  km_morph *m = NULL;
  km_error err;
  assert_status(km_morph_create(&m, &A, &B, &o, &err), KM_ETURNING);
  assert_null(m);
  assert_int_equal(err.code, KM_ETURNING);
  if (!message_has_integer(err.message, 1) ||
      !message_has_integer(err.message, 2))
    print_error("message: %s\n", err.message);
  assert_true(message_has_integer(err.message, 1));
  assert_true(message_has_integer(err.message, 2));
  /* the other way round, too */
  assert_status(km_morph_create(&m, &B, &A, &o, &err), KM_ETURNING);
  assert_true(message_has_integer(err.message, 1));
  assert_true(message_has_integer(err.message, 2));
  km_signature_free(&once);
  km_signature_free(&twice);
}

static void opposite_orientations_are_matched_unless_kept(void **state) {
  (void)state;
  km_signature ccw, cw;
  circle_signature(&ccw, 1.0, 1);
  circle_signature(&cw, 1.5, -1);
  km_morph_options o;
  km_morph_options_default(&o);
  km_morph_input A = {NULL, &ccw}, B = {NULL, &cw};
  km_morph *m = morph_new(&A, &B, &o);
  double len[2], turning[2];
  km_morph_inputs(m, len, turning);
  assert_close(turning[0], turning[1], 1e-6);
  /* the reversed `to` still ends the morph: frame 1 is the circle of radius
   * 1.5 through (0,0) with its centre at (0, -1.5) */
  frame f;
  frame_get(m, 1.0, &f);
  size_t np;
  double *P = curve_points(&f.c, 64, &np);
  for (size_t i = 0; i < np; i++)
    assert_close(hypot(P[2 * i], P[2 * i + 1] + 1.5), 1.5, 1e-5 * 3 * M_PI);
  free(P);
  frame_free(&f);
  km_morph_free(m);
  o.orient = KM_ORIENT_KEEP;
  km_error err;
  m = NULL;
  assert_status(km_morph_create(&m, &A, &B, &o, &err), KM_ETURNING);
  assert_true(message_has_integer(err.message, 1));
  assert_true(message_has_integer(err.message, -1));
  km_signature_free(&ccw);
  km_signature_free(&cw);
}

static void open_and_closed_inputs_are_rejected(void **state) {
  (void)state;
  km_signature closed, open;
  circle_signature(&closed, 1.0, 1);
  double k[2] = {1.0, 1.0};
  pl_signature(&open, 2.0, 0, 0, 0, k, 2, NULL, 0, false);
  km_morph_options o;
  km_morph_options_default(&o);
  km_morph_input A = {NULL, &open}, B = {NULL, &closed};
  km_morph *m = NULL;
  km_error err;
  assert_status(km_morph_create(&m, &A, &B, &o, &err), KM_EMIXED);
  assert_null(m);
  assert_non_null(strstr(err.message, "open"));
  assert_non_null(strstr(err.message, "closed"));
  assert_status(km_morph_create(&m, &B, &A, &o, &err), KM_EMIXED);
  km_signature_free(&closed);
  km_signature_free(&open);
}

static void invalid_matches_are_rejected_with_their_index(void **state) {
  (void)state;
  km_signature sa, sb;
  spiral_inputs(&sa, &sb);
  km_morph_input A = {NULL, &sa}, B = {NULL, &sb};
  const struct {
    double p[6];
    size_t n;
    long bad;
  } cases[] = {
      {{0.5, 0.5, 0.4, 0.6, 0, 0}, 2, 1},      /* decreasing on a */
      {{0.2, 0.5, 0.4, 0.5, 0, 0}, 2, 1},      /* repeated on b */
      {{0.0, 0.5, 0, 0, 0, 0}, 1, 0},          /* r = 0 */
      {{0.3, 0.3, 0.6, 1.0, 0, 0}, 2, 1},      /* r = 1 */
      {{0.3, 0.3, 0.6, 0.7, 1.2, 0.8}, 3, 2},  /* outside */
      {{0.3, -0.1, 0, 0, 0, 0}, 1, 0},         /* negative */
      {{0.3, 0.3, NAN, 0.5, 0, 0}, 2, 1},      /* not a number */
      {{0.3, 0.3, 0.5, INFINITY, 0, 0}, 2, 1}, /* infinite */
  };
  for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
    km_morph_options o;
    km_morph_options_default(&o);
    o.matches = cases[c].p;
    o.nmatches = cases[c].n;
    km_morph *m = NULL;
    km_error err;
    assert_status(km_morph_create(&m, &A, &B, &o, &err), KM_EMATCH);
    assert_null(m);
    assert_int_equal(err.field, KM_FIELD_MATCHES);
    assert_int_equal(err.index, cases[c].bad);
  }
  km_signature_free(&sa);
  km_signature_free(&sb);
}

static void a_cusp_in_an_input_is_rejected(void **state) {
  (void)state;
  /* control points (0,0), (1,1), (0,1), (1,0): C'(u) = 3 ((1-2u)^2, 1-2u)
   * vanishes at u = 1/2 and its direction turns from (0,1) to (0,-1) */
  const double knots[8] = {0, 0, 0, 0, 1, 1, 1, 1};
  const double cp[8] = {0, 0, 1, 1, 0, 1, 1, 0};
  km_curve cusp, ok;
  make_curve(&cusp, 3, 4, knots, cp, NULL, false);
  uint64_t seed = 42;
  random_open_curve(&ok, &seed, 6, 0, 0, 0, 1);
  km_morph_options o;
  km_morph_options_default(&o);
  km_morph_input A = {&cusp, NULL}, B = {&ok, NULL};
  km_morph *m = NULL;
  km_error err;
  assert_status(km_morph_create(&m, &A, &B, &o, &err), KM_ECUSP);
  assert_null(m);
  km_curve_free(&cusp);
  km_curve_free(&ok);
}

static void times_outside_the_unit_interval_are_rejected(void **state) {
  (void)state;
  km_signature sa, sb;
  spiral_inputs(&sa, &sb);
  km_morph_input A = {NULL, &sa}, B = {NULL, &sb};
  km_morph_options o;
  km_morph_options_default(&o);
  km_morph *m = morph_new(&A, &B, &o);
  const double bad[4] = {-1e-9, 1.0 + 1e-9, NAN, INFINITY};
  for (int i = 0; i < 4; i++) {
    km_curve c;
    km_curve_init(&c);
    km_error err;
    assert_status(km_morph_frame(m, bad[i], &c, NULL, NULL, &err), KM_ERANGE);
    assert_int_equal(err.field, KM_FIELD_TIMES);
  }
  km_morph_free(m);
  km_signature_free(&sa);
  km_signature_free(&sb);
}

static const struct CMUnitTest tests[] = {
    cmocka_unit_test(spiral_curvature_frames_never_exceed_the_inputs_curvature),
    cmocka_unit_test(frames_hold_to_a_number_of_points),
    cmocka_unit_test(spiral_linear_baseline_exceeds_the_inputs_curvature),
    cmocka_unit_test(spiral_end_frames_are_the_exact_spirals),
    cmocka_unit_test(planned_spiral_frames_are_the_exact_blended_spirals),
    cmocka_unit_test(curvature_bound_holds_for_random_pairs_and_matches),
    cmocka_unit_test(curvature_bound_holds_for_curve_inputs),
    cmocka_unit_test(every_frame_has_the_interpolated_length),
    cmocka_unit_test(
        end_frames_of_random_pairs_are_the_inputs_where_they_stand),
    cmocka_unit_test(end_frames_of_curve_inputs_trace_the_inputs),
    cmocka_unit_test(matched_segments_join_with_g2_under_the_paper_blend),
    cmocka_unit_test(matched_segments_join_with_g2_under_the_turning_blend),
    cmocka_unit_test(matched_arcs_have_continuous_curvature),
    cmocka_unit_test(proportional_matches_give_the_global_morph),
    cmocka_unit_test(matches_used_reports_the_given_pairs),
    cmocka_unit_test(auto_matches_are_a_valid_correspondence),
    cmocka_unit_test(anchor_start_moves_the_start_point_on_a_straight_line),
    cmocka_unit_test(anchor_centroid_moves_the_centroid_on_a_straight_line),
    cmocka_unit_test(anchor_fit_keeps_the_end_frames_where_the_inputs_stand),
    cmocka_unit_test(different_turning_numbers_are_rejected_naming_both),
    cmocka_unit_test(opposite_orientations_are_matched_unless_kept),
    cmocka_unit_test(open_and_closed_inputs_are_rejected),
    cmocka_unit_test(invalid_matches_are_rejected_with_their_index),
    cmocka_unit_test(a_cusp_in_an_input_is_rejected),
    cmocka_unit_test(times_outside_the_unit_interval_are_rejected),
};

TM_SUITE("morph", tests, NULL, NULL);
