/* test_fn.c - scalar spline functions: evaluation, exact antiderivative,
 * integrals, blend over normalised domains and bounds on |f|.
 *
 * Oracles: polynomials written exactly on arbitrary knot vectors through
 * their blossoms, step functions, and the defining formula of the blend.
 */
#include <stdbool.h>
#include <string.h>

#include "km/fn.h"
#include "km/limits.h"
#include "testutil.h"
#include "testmain.h"

static void make_fn(km_fn *f, int p, size_t n, const double *knots,
                    const double *coef) {
  km_error err;
  km_fn_init(f);
  assert_status(km_fn_create(f, p, n, knots, coef, &err), KM_OK);
}

/* f(x) = 1 - 2x + x^2/2 + x^3/4 on [-1, 2] */
static const double F3[4] = {1.0, -2.0, 0.5, 0.25};
static const double KN3[12] = {-1,  -1,  -1,  -1,  -0.4, 0.3,
                               0.3, 1.1, 2.0, 2.0, 2.0,  2.0};

static void make_poly_fn(km_fn *f, const double *a, int deg, int p,
                         const double *knots, size_t nk) {
  double coef[64];
  size_t n = nk - (size_t)p - 1;
  tu_poly_to_bspline(a, deg, p, knots, n, coef, 1);
  make_fn(f, p, n, knots, coef);
}

static void fn_eval_matches_polynomial_and_its_derivatives(void **state) {
  (void)state;
  km_fn f;
  make_poly_fn(&f, F3, 3, 3, KN3, 12);
  double a, b;
  km_fn_domain(&f, &a, &b);
  assert_close(a, -1.0, 0.0);
  assert_close(b, 2.0, 0.0);
  for (int i = 0; i <= 300; i++) {
    double x = -1.0 + 3.0 * i / 300.0, d[5];
    km_fn_eval(&f, x, 4, d);
    for (int k = 0; k <= 3; k++)
      assert_close(d[k], tu_poly(F3, 3, x, k), 1e-13 * 8);
    assert_close(d[4], 0.0, 1e-12);
    assert_close(km_fn_value(&f, x), tu_poly(F3, 3, x, 0), 1e-13 * 8);
  }
  km_fn_free(&f);

  /* the same cubic as a degree-6 spline */
  const double k6[16] = {-1,  -1, -1, -1, -1, -1, -1, 0,
                         0.5, 2,  2,  2,  2,  2,  2,  2};
  make_poly_fn(&f, F3, 3, 6, k6, 16);
  for (int i = 0; i <= 100; i++) {
    double x = -1.0 + 3.0 * i / 100.0, d[4];
    km_fn_eval(&f, x, 3, d);
    for (int k = 0; k <= 3; k++)
      assert_close(d[k], tu_poly(F3, 3, x, k), 1e-12 * 8);
  }
  km_fn_free(&f);
}

static void fn_constant_is_constant_on_its_domain(void **state) {
  (void)state;
  km_fn f;
  km_error err;
  km_fn_init(&f);
  assert_status(km_fn_constant(&f, 0.5, 4.0, -2.25, &err), KM_OK);
  double a, b;
  km_fn_domain(&f, &a, &b);
  assert_close(a, 0.5, 0.0);
  assert_close(b, 4.0, 0.0);
  for (int i = 0; i <= 10; i++)
    assert_close(km_fn_value(&f, 0.5 + 0.35 * i), -2.25, 1e-15);
  assert_close(km_fn_integral(&f), -2.25 * 3.5, 1e-14);
  km_fn_free(&f);
}

static void antiderivative_is_exact_for_a_polynomial_spline(void **state) {
  (void)state;
  km_fn f, F;
  km_error err;
  make_poly_fn(&f, F3, 3, 3, KN3, 12);
  km_fn_init(&F);
  const double c0 = 2.5;
  assert_status(km_fn_antiderivative(&F, &f, c0, &err), KM_OK);
  assert_int_equal(F.degree, 4);
  /* P(x) = x - x^2 + x^3/6 + x^4/16 */
  const double P[5] = {0, 1, -1, 1.0 / 6, 1.0 / 16};
  const double Pa = tu_poly(P, 4, -1.0, 0);
  assert_close(km_fn_value(&F, -1.0), c0, 1e-14);
  for (int i = 0; i <= 300; i++) {
    double x = -1.0 + 3.0 * i / 300.0, d[2];
    km_fn_eval(&F, x, 1, d);
    assert_close(d[0], c0 + tu_poly(P, 4, x, 0) - Pa, 1e-13 * 8);
    assert_close(d[1], tu_poly(F3, 3, x, 0), 1e-12 * 8);
  }
  assert_close(km_fn_integral(&f), tu_poly(P, 4, 2.0, 0) - Pa, 1e-13 * 8);
  km_fn_free(&F);
  km_fn_free(&f);
}

static void antiderivative_stays_continuous_across_a_jump(void **state) {
  (void)state;
  km_error err;
  km_fn f, F;
  /* degree 1 with a knot of multiplicity 2 = degree + 1: f = 1 on [0, 1),
   * 3 on [1, 2] */
  const double kn[6] = {0, 0, 1, 1, 2, 2}, c[4] = {1, 1, 3, 3};
  make_fn(&f, 1, 4, kn, c);
  assert_close(km_fn_value(&f, 1.0 - 1e-9), 1.0, 1e-12);
  assert_close(km_fn_value(&f, 1.0), 3.0, 1e-12); /* right-hand value */
  assert_close(km_fn_value(&f, 2.0), 3.0, 1e-12);
  km_fn_init(&F);
  assert_status(km_fn_antiderivative(&F, &f, -1.0, &err), KM_OK);
  for (int i = 0; i <= 200; i++) {
    double x = 2.0 * i / 200.0;
    double want = x <= 1.0 ? -1.0 + x : -1.0 + 1.0 + 3.0 * (x - 1.0);
    assert_close(km_fn_value(&F, x), want, 1e-13);
  }
  assert_close(km_fn_value(&F, 1.0 - 1e-12), km_fn_value(&F, 1.0), 1e-11);
  assert_close(km_fn_integral(&f), 4.0, 1e-14);
  km_fn_free(&F);
  km_fn_free(&f);

  /* a degree-0 step function 1, -2, 4 on [0,1), [1,2), [2,3] */
  const double k0[4] = {0, 1, 2, 3}, c0[3] = {1, -2, 4};
  make_fn(&f, 0, 3, k0, c0);
  km_fn_init(&F);
  assert_status(km_fn_antiderivative(&F, &f, 0.0, &err), KM_OK);
  assert_close(km_fn_value(&F, 0.5), 0.5, 1e-14);
  assert_close(km_fn_value(&F, 1.0), 1.0, 1e-14);
  assert_close(km_fn_value(&F, 1.5), 0.0, 1e-14);
  assert_close(km_fn_value(&F, 2.0), -1.0, 1e-14);
  assert_close(km_fn_value(&F, 3.0), 3.0, 1e-14);
  assert_close(km_fn_integral(&f), 3.0, 1e-14);
  km_fn_free(&F);
  km_fn_free(&f);

  /* a quadratic that jumps at 1: x^2 on [0,1), 5 - x on [1, 2] */
  const double k2[9] = {0, 0, 0, 1, 1, 1, 2, 2, 2};
  const double q1[3] = {0, 0, 1}, q2[3] = {5, -1, 0};
  double c2[6];
  tu_poly_to_bspline(q1, 2, 2, k2, 3, c2, 1);
  tu_poly_to_bspline(q2, 2, 2, k2 + 3, 3, c2 + 3, 1);
  make_fn(&f, 2, 6, k2, c2);
  km_fn_init(&F);
  assert_status(km_fn_antiderivative(&F, &f, 0.0, &err), KM_OK);
  for (int i = 0; i <= 100; i++) {
    double x = 2.0 * i / 100.0;
    double want =
        x <= 1.0 ? x * x * x / 3 : 1.0 / 3 + 5 * (x - 1) - 0.5 * (x * x - 1);
    assert_close(km_fn_value(&F, x), want, 1e-13);
  }
  km_fn_free(&F);
  km_fn_free(&f);
}

/* Random spline of degree p on [a, b] with nint interior breakpoints, one
 * of them of multiplicity p + 1 (a jump) when jump is set. */
static void random_fn(km_fn *f, uint64_t *seed, int p, double a, double b,
                      int nint, bool jump) {
  double kn[64], coef[64];
  size_t nk = 0;
  for (int i = 0; i <= p; i++) kn[nk++] = a;
  for (int i = 0; i < nint; i++) {
    double x = a + (b - a) * (i + 0.2 + 0.6 * tu_rand(seed)) / nint;
    int mult = (jump && i == nint / 2) ? p + 1 : 1;
    for (int m = 0; m < mult; m++) kn[nk++] = x;
  }
  for (int i = 0; i <= p; i++) kn[nk++] = b;
  size_t n = nk - (size_t)p - 1;
  for (size_t i = 0; i < n; i++) coef[i] = tu_uniform(seed, -2, 2);
  make_fn(f, p, n, kn, coef);
}

static void blend_equals_pointwise_formula_on_different_knots(void **state) {
  (void)state;
  uint64_t seed = 7;
  struct {
    int pa, pb;
    double a0, a1, b0, b1, wa, wb, u0, u1;
    bool jump;
  } cases[] = {
      {3, 2, 0.0, 2.0, -1.0, 4.0, 0.3, 0.7, 5.0, 8.0, false},
      {1, 5, 0.0, 7.0, 0.0, 0.5, 1.5, -0.5, 0.0, 1.0, true},
      {0, 3, -2.0, -1.0, 10.0, 30.0, 1.0, 1.0, 0.0, 6.2, true},
      {4, 4, 0.0, 1.0, 0.0, 1.0, 0.0, 2.0, -3.0, -1.0, false},
  };
  for (size_t ci = 0; ci < sizeof cases / sizeof cases[0]; ci++) {
    km_fn a, b, out;
    km_error err;
    random_fn(&a, &seed, cases[ci].pa, cases[ci].a0, cases[ci].a1, 5,
              cases[ci].jump);
    random_fn(&b, &seed, cases[ci].pb, cases[ci].b0, cases[ci].b1, 7, false);
    km_fn_init(&out);
    const double u0 = cases[ci].u0, u1 = cases[ci].u1;
    const double wa = cases[ci].wa, wb = cases[ci].wb;
    assert_status(km_fn_blend(&out, &a, wa, &b, wb, u0, u1, &err), KM_OK);
    double d0, d1;
    km_fn_domain(&out, &d0, &d1);
    assert_close(d0, u0, 1e-12);
    assert_close(d1, u1, 1e-12);
    for (int i = 0; i <= 997; i++) {
      /* 997 is prime: the samples avoid the breakpoints' exact images */
      double r = i / 997.0;
      double want =
          wa * km_fn_value(&a,
                           cases[ci].a0 + r * (cases[ci].a1 - cases[ci].a0)) +
          wb *
              km_fn_value(&b, cases[ci].b0 + r * (cases[ci].b1 - cases[ci].b0));
      assert_close(km_fn_value(&out, u0 + r * (u1 - u0)), want, 1e-12 * 4);
    }
    km_fn_free(&out);
    km_fn_free(&a);
    km_fn_free(&b);
  }
}

static void max_abs_and_bound_agree_with_known_maximum(void **state) {
  (void)state;
  /* f = x^3 - 3x on [-1.8, 1.5]: |f| peaks at 2 (x = -1 and x = 1) */
  const double p[4] = {0, -3, 0, 1};
  const double kn[10] = {-1.8, -1.8, -1.8, -1.8, -0.2, 0.3, 1.5, 1.5, 1.5, 1.5};
  km_fn f;
  make_poly_fn(&f, p, 3, 3, kn, 10);
  assert_close(km_fn_max_abs(&f), 2.0, 2e-12);
  assert_le(2.0, km_fn_abs_bound(&f, -1.8, 1.5));
  /* on [0, 0.5] the maximum is |f(0.5)| = 1.375, which the bound must
   * cover without falling back to the global maximum */
  double bnd = km_fn_abs_bound(&f, 0.0, 0.5);
  assert_le(1.375, bnd);
  assert_le(bnd, 1.375 + 0.25);
  km_fn_free(&f);

  /* a maximum strictly inside a span and off every coefficient:
   * g = 1 - (x - 0.37)^2 on [0, 1] */
  const double g[3] = {1 - 0.37 * 0.37, 0.74, -1};
  const double kg[8] = {0, 0, 0, 0.5, 0.8, 1, 1, 1};
  make_poly_fn(&f, g, 2, 2, kg, 8);
  assert_close(km_fn_max_abs(&f), 1.0, 1e-12);
  assert_le(1.0, km_fn_abs_bound(&f, 0.0, 1.0));
  assert_le(1.0, km_fn_abs_bound(&f, 0.3, 0.45));
  km_fn_free(&f);

  /* a step: the largest piece wins */
  const double k0[4] = {0, 1, 2, 3}, c0[3] = {1, -5, 4};
  make_fn(&f, 0, 3, k0, c0);
  assert_close(km_fn_max_abs(&f), 5.0, 1e-12);
  assert_le(5.0, km_fn_abs_bound(&f, 0.0, 3.0));
  assert_le(4.0, km_fn_abs_bound(&f, 2.2, 2.9));
  assert_le(km_fn_abs_bound(&f, 2.2, 2.9), 4.0 + 1e-12);
  km_fn_free(&f);
}

static void abs_bound_covers_dense_samples_of_random_splines(void **state) {
  (void)state;
  uint64_t seed = 99;
  for (int trial = 0; trial < 40; trial++) {
    km_fn f;
    int p = trial % 6;
    random_fn(&f, &seed, p, -1.0, 3.0, 6, trial % 3 == 0);
    double dense = 0.0;
    for (int i = 0; i <= 4000; i++) {
      double v = fabs(km_fn_value(&f, -1.0 + 4.0 * i / 4000.0));
      if (v > dense) dense = v;
    }
    /* left limits at the breakpoints (a jump's left value is a supremum
     * that sampling on a grid approaches only linearly) */
    for (size_t j = (size_t)p + 1; j < f.n; j++) {
      double v = fabs(km_fn_value(&f, f.knots[j] - 1e-13));
      if (v > dense) dense = v;
    }
    double m = km_fn_max_abs(&f);
    assert_le(dense - 1e-12, m);
    /* dense sampling misses a maximum by at most |f''| h^2 / 8 */
    assert_le(m, dense * (1 + 1e-3) + 1e-9);
    assert_le(m, km_fn_abs_bound(&f, -1.0, 3.0) + 1e-12);
    for (int k = 0; k < 5; k++) {
      double x0 = tu_uniform(&seed, -1.0, 3.0);
      double x1 = x0 + tu_uniform(&seed, 0.0, 3.0 - x0);
      double local = 0.0;
      for (int i = 0; i <= 500; i++) {
        double v = fabs(km_fn_value(&f, x0 + (x1 - x0) * i / 500.0));
        if (v > local) local = v;
      }
      assert_le(local, km_fn_abs_bound(&f, x0, x1) * (1 + 1e-12));
    }
    km_fn_free(&f);
  }
}

static void integral_sq_is_exact_for_polynomials(void **state) {
  (void)state;
  km_fn f;
  make_poly_fn(&f, F3, 3, 3, KN3, 12);
  /* f^2 as a polynomial, integrated exactly over [-1, 2] */
  double sq[7] = {0}, P[8] = {0};
  for (int i = 0; i <= 3; i++)
    for (int j = 0; j <= 3; j++) sq[i + j] += F3[i] * F3[j];
  for (int i = 0; i <= 6; i++) P[i + 1] = sq[i] / (i + 1);
  double want = tu_poly(P, 7, 2.0, 0) - tu_poly(P, 7, -1.0, 0);
  assert_close(km_fn_integral_sq(&f), want, 1e-13 * want);
  km_fn_free(&f);

  /* a genuine quintic on interior knots: x^5 - 2x^2 + 1 on [0, 2] */
  const double a5[6] = {1, 0, -2, 0, 0, 1};
  const double k5[14] = {0, 0, 0, 0, 0, 0, 0.5, 1.3, 2, 2, 2, 2, 2, 2};
  make_poly_fn(&f, a5, 5, 5, k5, 14);
  double sq5[11] = {0}, P5[12] = {0};
  for (int i = 0; i <= 5; i++)
    for (int j = 0; j <= 5; j++) sq5[i + j] += a5[i] * a5[j];
  for (int i = 0; i <= 10; i++) P5[i + 1] = sq5[i] / (i + 1);
  want = tu_poly(P5, 11, 2.0, 0);
  assert_close(km_fn_integral_sq(&f), want, 1e-13 * want);
  km_fn_free(&f);

  /* a jump: x^2 on [0,1), 5 - x on [1, 2]; 1/5 + 37/3 */
  const double k2[9] = {0, 0, 0, 1, 1, 1, 2, 2, 2};
  const double q1[3] = {0, 0, 1}, q2[3] = {5, -1, 0};
  double c2[6];
  tu_poly_to_bspline(q1, 2, 2, k2, 3, c2, 1);
  tu_poly_to_bspline(q2, 2, 2, k2 + 3, 3, c2 + 3, 1);
  make_fn(&f, 2, 6, k2, c2);
  assert_close(km_fn_integral_sq(&f), 0.2 + 37.0 / 3, 1e-13 * 12.6);
  km_fn_free(&f);
}

static void fn_create_rejects_bad_input(void **state) {
  (void)state;
  km_fn f;
  km_error err;
  km_fn_init(&f);
  const double kn[8] = {0, 0, 0, 0, 1, 1, 1, 1}, c[4] = {1, 2, 3, 4};
  assert_status(km_fn_create(&f, KM_MAX_FN_DEGREE + 1, 4, kn, c, &err),
                KM_EDEGREE);
  assert_status(km_fn_create(&f, -1, 4, kn, c, &err), KM_EDEGREE);
  assert_status(km_fn_create(&f, 3, 3, kn, c, &err), KM_ECOUNT);
  const double bad[8] = {0, 0, 0, 0, 1, 1, 1, 0.5};
  assert_status(km_fn_create(&f, 3, 4, bad, c, &err), KM_EKNOTS);
  assert_int_equal(err.field, KM_FIELD_KAPPA_KNOTS);
  const double cn[4] = {1, NAN, 3, 4};
  assert_status(km_fn_create(&f, 3, 4, kn, cn, &err), KM_ENONFINITE);
  const double empty[8] = {1, 1, 1, 1, 1, 1, 1, 1};
  assert_status(km_fn_create(&f, 3, 4, empty, c, &err), KM_EKNOTS);
  /* out is written only on success */
  assert_null(f.coef);
  assert_null(f.knots);
}

static const struct CMUnitTest tests[] = {
    cmocka_unit_test(fn_eval_matches_polynomial_and_its_derivatives),
    cmocka_unit_test(fn_constant_is_constant_on_its_domain),
    cmocka_unit_test(antiderivative_is_exact_for_a_polynomial_spline),
    cmocka_unit_test(antiderivative_stays_continuous_across_a_jump),
    cmocka_unit_test(blend_equals_pointwise_formula_on_different_knots),
    cmocka_unit_test(max_abs_and_bound_agree_with_known_maximum),
    cmocka_unit_test(abs_bound_covers_dense_samples_of_random_splines),
    cmocka_unit_test(integral_sq_is_exact_for_polynomials),
    cmocka_unit_test(fn_create_rejects_bad_input),
};

TM_SUITE("fn", tests, NULL, NULL);
