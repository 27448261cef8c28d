/* test_kappa_table.c - the curvature of planned frames tabled once per
 * morph (core/src/morph_kappa.c), from which every frame's metrics come.
 *
 * Oracles: a morph between two circles, whose frames are circles of
 * length L_t (constant curvature 2 pi / L_t, energy 4 pi^2 / L_t); and for
 * shape pairs the blended curvature evaluated point by point from the
 * blended signature (km__blend_signature, the general path's frame before
 * closure) plus psi' of given closure coefficients from the basis function
 * itself (km__bspline3_d), integrated by 8-point Gauss-Legendre on every
 * interval between the signature's knots and the basis breaks (exact for
 * the polynomials there, of degree below 16) and maximised over dense
 * samples.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../../core/src/morph_blend.h"
#include "../../core/src/morph_closure.h"
#include "../../core/src/morph_internal.h"
#include "fixtures.h"
#include "curvecases.h"
#include "testutil.h"
#include "morphutil.h"
#include "testmain.h"

#define PI 3.14159265358979323846
#define NB KM__CLOSURE_INTERVALS
#define NF (KM__CLOSURE_INTERVALS - 3)

static void circle_signature(double length, km_signature *s) {
  km_fn k;
  km_error err;
  km_fn_init(&k);
  assert_status(km_fn_constant(&k, 0.0, length, 2 * PI / length, &err), KM_OK);
  double start[2] = {0.0, 0.0};
  km_signature_init(s);
  assert_status(
      km_signature_create(s, length, start, 0.0, &k, NULL, 0, true, &err),
      KM_OK);
  km_fn_free(&k);
}

static void circles_have_the_circle_s_metrics(void **state) {
  (void)state;
  km_signature a, b;
  circle_signature(2 * PI, &a);
  circle_signature(6 * PI, &b);
  km_morph_input A = {NULL, &a}, B = {NULL, &b};
  km_morph_options o;
  km_morph_options_default(&o);
  km_morph *m = morph_new(&A, &B, &o);
  assert_non_null(m->frame_kappa);
  for (int i = 0; i <= 8; i++) {
    double t = i / 8.0, Lt = (1 - t) * 2 * PI + t * 6 * PI, mx, en;
    assert_status(km__kappa_table_metrics(m->frame_kappa, t, 2 * PI, 6 * PI,
                                          NULL, 1e-9, &mx, &en),
                  KM_OK);
    assert_close(mx, 2 * PI / Lt, 1e-13);
    assert_close(en, 4 * PI * PI / Lt, 1e-13);
    /* and through the public frame, with the frame's own closure */
    frame f;
    frame_get(m, t, &f);
    assert_close(f.mt.max_abs_kappa, 2 * PI / Lt, 1e-12);
    assert_close(f.mt.bending_energy, 4 * PI * PI / Lt, 1e-12);
    frame_free(&f);
  }
  km_morph_free(m);
  km_signature_free(&a);
  km_signature_free(&b);
}

static int cmp_double(const void *x, const void *y) {
  double a = *(const double *)x, b = *(const double *)y;
  return (a > b) - (a < b);
}

/* The frame's curvature at s of the blended signature, plus psi'. */
static double kappa_at(const km_signature *sig, const double *c, double s) {
  double k = km_fn_value(&sig->kappa, s), L = sig->length;
  if (c) {
    double u = NB * s / L, d = 0.0;
    for (int j = 0; j < NF; j++) d += c[j] * km__bspline3_d(u - j);
    k += NB * d / L;
  }
  return k;
}

static const double GX[8] = {-0.9602898564975363, -0.7966664774136267,
                             -0.5255324099163290, -0.1834346424956498,
                             0.1834346424956498,  0.5255324099163290,
                             0.7966664774136267,  0.9602898564975363};
static const double GW[8] = {0.1012285362903763, 0.2223810344533745,
                             0.3137066458778873, 0.3626837833783730,
                             0.3626837833783730, 0.3137066458778873,
                             0.2223810344533745, 0.1012285362903763};

/* Energy and largest |kappa| of sig's curvature plus psi' (c may be NULL),
 * independently of the table. */
static void reference(const km_signature *sig, const double *c, double *max,
                      double *energy) {
  const km_fn *k = &sig->kappa;
  double L = sig->length;
  size_t nk = k->n + (size_t)k->degree + 1, nb = nk + NB + 1, n = 0;
  double *br = malloc(nb * sizeof *br);
  assert_non_null(br);
  for (size_t i = 0; i < nk; i++) br[n++] = k->knots[i];
  for (int i = 0; i <= NB; i++) br[n++] = L * i / NB;
  qsort(br, n, sizeof *br, cmp_double);
  double e = 0.0, mx = 0.0;
  for (size_t i = 0; i + 1 < n; i++) {
    double a = fmax(br[i], 0.0), b = fmin(br[i + 1], L);
    if (!(b > a)) continue;
    /* the ends of every piece from inside: a jump's larger side */
    mx = fmax(mx, fabs(kappa_at(sig, c, nextafter(a, b))));
    mx = fmax(mx, fabs(kappa_at(sig, c, nextafter(b, a))));
    for (int g = 0; g < 8; g++) {
      double s = 0.5 * (a + b) + 0.5 * (b - a) * GX[g], v = kappa_at(sig, c, s);
      e += 0.5 * (b - a) * GW[g] * v * v;
    }
  }
  /* samples, then every local maximum among them near the largest
   * refined by ternary search between its neighbours (a peak narrower
   * than the samples' spacing) */
  enum { NS = 200000 };
  double *v = malloc((NS + 1) * sizeof *v);
  assert_non_null(v);
  for (int i = 0; i <= NS; i++) {
    v[i] = fabs(kappa_at(sig, c, L * i / NS));
    mx = fmax(mx, v[i]);
  }
  double top = mx;
  for (int i = 1; i < NS; i++) {
    if (!(v[i] >= v[i - 1] && v[i] >= v[i + 1] && v[i] >= 0.99 * top)) continue;
    double lo = L * (i - 1) / NS, hi = L * (i + 1) / NS;
    for (int it = 0; it < 100; it++) {
      double m1 = lo + (hi - lo) / 3, m2 = hi - (hi - lo) / 3;
      if (fabs(kappa_at(sig, c, m1)) < fabs(kappa_at(sig, c, m2)))
        lo = m1;
      else
        hi = m2;
    }
    mx = fmax(mx, fabs(kappa_at(sig, c, 0.5 * (lo + hi))));
  }
  free(v);
  free(br);
  *max = mx;
  *energy = e;
}

static void shape_curve(const char *pair, char which, km_curve *c) {
  tf_bspline b;
  assert_int_equal(tf_load_shape(pair, which, &b), 0);
  make_curve(c, b.degree, b.n, b.knots, b.cp, b.w, b.closed);
  tf_bspline_free(&b);
}

static void table_agrees_with_the_blend_point_by_point(void **state) {
  (void)state;
  static const char *pairs[] = {"circle_to_star", "square_to_circle", "U_to_S",
                                "crescent_to_heart", "spiral_open"};
  for (size_t p = 0; p < sizeof pairs / sizeof pairs[0]; p++) {
    km_curve a, b;
    shape_curve(pairs[p], 'a', &a);
    shape_curve(pairs[p], 'b', &b);
    km_morph_input A = {&a, NULL}, B = {&b, NULL};
    km_morph_options o;
    km_morph_options_default(&o);
    km_morph *m = morph_new(&A, &B, &o);
    assert_non_null(m->frame_kappa);
    double La = m->in[0].sig.length, Lb = m->in[1].sig.length;
    /* some closure coefficients of the size closures take */
    double c[NF];
    for (int j = 0; j < NF; j++) c[j] = 0.02 * sin(1.7 * j + 0.3);
    for (int i = 0; i <= 4; i++) {
      double t = i / 4.0;
      km_signature sig;
      km_signature_init(&sig);
      km_error err;
      assert_status(km__blend_signature(m, t, &sig, &err), KM_OK);
      for (int with = 0; with < 2; with++) {
        const double *cc = with ? c : NULL;
        double mx, en, rmx, ren;
        assert_status(km__kappa_table_metrics(m->frame_kappa, t, La, Lb, cc,
                                              1e-9, &mx, &en),
                      KM_OK);
        reference(&sig, cc, &rmx, &ren);
        print_message("%-18s t = %.2f psi %d: energy %.15g (reference "
                      "%.15g), max |kappa| %.15g (sampled %.15g)\n",
                      pairs[p], t, with, en, ren, mx, rmx);
        /* a straight frame's curvature is rounding: measured against
         * the turning of a circle as long, 2 pi / L_t */
        double floor = 1e-9 * 2 * PI / sig.length;
        assert_close(en, ren, 1e-11 * ren + floor * floor * sig.length);
        /* attained, and at most the table's 1e-9 below the largest */
        assert_true(mx >= rmx * (1 - 1e-9) - floor);
        assert_true(mx <= rmx * (1 + 1e-12) + floor);
      }
      km_signature_free(&sig);
    }
    km_morph_free(m);
    km_curve_free(&a);
    km_curve_free(&b);
  }
}

static const struct CMUnitTest tests[] = {
    cmocka_unit_test(circles_have_the_circle_s_metrics),
    cmocka_unit_test(table_agrees_with_the_blend_point_by_point),
};

TM_SUITE("kappa_table", tests, NULL, NULL);
