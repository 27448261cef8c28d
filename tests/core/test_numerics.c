/* test_numerics.c - the core's internal numerical kernels that public
 * results rest on without showing them: the signature's spectral
 * integration matrix, and merging of piecewise polynomials within a bound.
 *
 * Oracles: exact integrals of monomials and of exp, polynomials written
 * exactly in Bernstein form (restrictions of one polynomial are the same
 * polynomial), a kink in the third derivative like a cubic spline's knot,
 * and a jump like a corner of a tangent angle.
 */
#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "../../core/src/internal.h"
#include "../../core/src/morph_plan.h"
#include "km/curve.h"
#include "testutil.h"
#include "testmain.h"

#define PI 3.14159265358979323846

/* ---- spectral integration ---------------------------------------------- */

static void cheb_cumulative_integrates_monomials_exactly(void **state) {
  (void)state;
  for (int j = 0; j <= 14; j++) {
    double f[15], F[15];
    for (int k = 0; k < 15; k++) f[k] = pow(-cos(k * PI / 14), j);
    km__cheb_cumulative15(f, F);
    for (int k = 0; k < 15; k++) {
      double x = -cos(k * PI / 14);
      double want = (pow(x, j + 1) - pow(-1.0, j + 1)) / (j + 1);
      assert_close(F[k], want, 2e-15);
    }
  }
}

static void cheb_cumulative_of_exp_is_spectrally_accurate(void **state) {
  (void)state;
  /* the degree-14 interpolant of e^x on [-1, 1] errs by at most
   * e / (2^13 15!) ~ 2.5e-16: the integral is right to rounding */
  double f[15], F[15];
  for (int k = 0; k < 15; k++) f[k] = exp(-cos(k * PI / 14));
  km__cheb_cumulative15(f, F);
  for (int k = 0; k < 15; k++)
    assert_close(F[k], exp(-cos(k * PI / 14)) - exp(-1.0), 2e-15);
}

/* ---- Bernstein evaluation ---------------------------------------------- */

static void bern_eval_is_within_its_rounding_bound(void **state) {
  (void)state;
  /* against the defining sum in extended precision: the error stays below
   * (2d + 1) eps sum |c_j| B_j(u), the bound of de Casteljau's algorithm */
  uint64_t rng = 777;
  for (int d = 0; d <= 21; d++)
    for (int trial = 0; trial < 200; trial++) {
      double c[22];
      for (int j = 0; j <= d; j++) c[j] = tu_uniform(&rng, -3.0, 3.0);
      double u = trial == 0   ? 0.0
                 : trial == 1 ? 1.0
                 : trial == 2 ? 0.5
                              : tu_uniform(&rng, 0.0, 1.0);
      long double sum = 0.0L, abs_sum = 0.0L;
      for (int j = 0; j <= d; j++) {
        long double b = 1.0L;
        for (int q = 0; q < j; q++) b = b * (d - q) / (q + 1);
        for (int q = 0; q < j; q++) b *= u;
        for (int q = j; q < d; q++) b *= 1.0L - u;
        sum += c[j] * b;
        abs_sum += fabsl(c[j] * b);
      }
      double got = km__bern_eval(c, d, u);
      assert_true(fabsl(got - sum) <=
                  (2 * d + 2) * 1.12e-16L * abs_sum + 1e-300);
      if (trial == 0) assert_true(got == c[0]);
      if (trial == 1) assert_true(got == c[d]);
    }
}

/* ---- spans in Bezier form ---------------------------------------------- */

static void bezier_span_evaluation_agrees_with_de_boor(void **state) {
  (void)state;
  /* every degree, with and without weights, far from the origin too:
   * position and derivative of a span in Bezier form against de Boor's
   * algorithm on the B-spline (km_curve_eval) */
  uint64_t rng = 4242;
  for (int p = 1; p <= 9; p++)
    for (int rational = 0; rational < 2; rational++)
      for (int far = 0; far < 2; far++) {
        enum { N = 14 };
        double cp[2 * N], w[N], kn[N + 10];
        double off = far ? 1e6 : 0.0;
        for (int i = 0; i < N; i++) {
          cp[2 * i] = off + tu_uniform(&rng, -1, 1);
          cp[2 * i + 1] = off + tu_uniform(&rng, -1, 1);
          w[i] = tu_uniform(&rng, 0.3, 3.0);
        }
        size_t nk = N + (size_t)p + 1;
        for (size_t i = 0; i < nk; i++)
          kn[i] = i <= (size_t)p ? 0.0
                  : i >= N       ? (double)(N - p)
                                 : (double)(i - (size_t)p);
        km_curve c;
        km_curve_init(&c);
        assert_status(
            km_curve_create(&c, p, N, kn, cp, rational ? w : NULL, false, NULL),
            KM_OK);
        for (size_t i = (size_t)p; i < N; i++) {
          km__bspan sp;
          km__bspan_make(&sp, &c, i);
          for (int k = 0; k <= 10; k++) {
            double t = kn[i] + (kn[i + 1] - kn[i]) * k / 10.0, pos[2], der[2],
                   d[2][2];
            km__bspan_eval(&sp, t, pos, der, NULL);
            km_curve_eval_side(&c, t, k == 10 ? -1 : 1, 1, d);
            double scale = 1 + off;
            for (int q = 0; q < 2; q++) {
              assert_true(fabs(pos[q] - d[0][q]) <= 1e-13 * scale);
              assert_true(fabs(der[q] - d[1][q]) <=
                          1e-9 * (1 + fabs(d[1][q])) * scale);
            }
          }
        }
        km_curve_free(&c);
      }
}

/* ---- sin and cos ------------------------------------------------------- */

static void sincos_agrees_with_libm(void **state) {
  (void)state;
  uint64_t rng = 12345;
  double worst = 0.0;
  for (int k = 0; k < 400000; k++) {
    /* every scale up to the fast range, and the quadrant boundaries */
    double x = k < 200000 ? tu_uniform(&rng, -1.0, 1.0) *
                                pow(10.0, tu_uniform(&rng, -8, 5))
                          : (k - 300000) * (PI / 4) * (1 + 1e-16 * (k % 3 - 1));
    if (!(fabs(x) < 1e5)) continue;
    double s, c;
    km__sincos(x, &s, &c);
    worst = fmax(worst, fmax(fabs(s - sin(x)), fabs(c - cos(x))));
    assert_close(s * s + c * c, 1.0, 4e-16);
  }
  /* libm is correctly rounded to within an ulp; with the reduction, a few
   * ulps of 1 */
  assert_true(worst <= 6e-16);
  /* beyond the fast range it is libm's own */
  double s, c;
  km__sincos(3e7, &s, &c);
  assert_true(s == sin(3e7) && c == cos(3e7));
  km__sincos(0.0, &s, &c);
  assert_true(s == 0.0 && c == 1.0);
}

/* ---- the closure's metric ---------------------------------------------- */

/* Derivative of the uniform cubic B-spline on [0, 4], from its pieces
 * u^3/6, (-3u^3 + 12u^2 - 12u + 4)/6, (3u^3 - 24u^2 + 60u - 44)/6,
 * (4 - u)^3/6: the oracle for the closure's metric. */
static double bspline3_derivative(double a) {
  if (a <= 0 || a >= 4) return 0.0;
  if (a < 1) return a * a / 2;
  if (a < 2) return (-9 * a * a + 24 * a - 12) / 6;
  if (a < 3) return (9 * a * a - 48 * a + 60) / 6;
  return -(4 - a) * (4 - a) / 2;
}

static void weighted_closure_metric_is_the_gram_matrix(void **state) {
  (void)state;
  enum { NB = KM__CLOSURE_INTERVALS, NF = KM__CLOSURE_INTERVALS - 3 };
  double M[NF * NF], W[NF * NF], w[NB];
  /* unit weights: the Toeplitz band 2/3, -1/8, -1/5, -1/120 */
  for (int i = 0; i < NB; i++) w[i] = 1.0;
  km__closure_metric(M);
  km__closure_metric_weighted(w, W);
  for (int i = 0; i < NF * NF; i++) assert_close(W[i], M[i], 1e-15);
  assert_close(M[0], 2.0 / 3.0, 1e-15);
  assert_close(M[1], -1.0 / 8.0, 1e-15);
  /* a weight on one interval only: the integral of psi_i' psi_j' there,
   * by a fine midpoint rule on the derivative of the cubic B-spline */
  for (int i = 0; i < NB; i++) w[i] = i == 7 ? 3.0 : 0.0;
  km__closure_metric_weighted(w, W);
  for (int i = 0; i < NF; i++)
    for (int j = 0; j < NF; j++) {
      double sum = 0.0;
      const int n = 20000;
      for (int k = 0; k < n; k++) {
        double u = 7.0 + (k + 0.5) / n;
        sum += bspline3_derivative(u - i) * bspline3_derivative(u - j) / n;
      }
      assert_close(W[i * NF + j], 3.0 * sum, 1e-8);
    }
}

/* ---- merging pieces ---------------------------------------------------- */

/* Bernstein coefficients over [0, 1] of sum a_i x^i (degree d). */
static void power_to_bernstein(const double *a, int d, double *b) {
  for (int j = 0; j <= d; j++) {
    double s = 0.0;
    for (int i = 0; i <= j; i++) {
      double cji = 1.0, cdi = 1.0; /* C(j, i), C(d, i) */
      for (int q = 0; q < i; q++) {
        cji = cji * (j - q) / (q + 1);
        cdi = cdi * (d - q) / (q + 1);
      }
      s += cji / cdi * a[i];
    }
    b[j] = s;
  }
}

static double power_eval(const double *a, int d, double x) {
  double v = 0.0;
  for (int i = d; i >= 0; i--) v = v * x + a[i];
  return v;
}

/* P(x) = 0.3 + x - 0.8 x^2 + 0.2 x^3 - 0.1 x^5 + 0.05 x^7 */
static const double P7[8] = {0.3, 1.0, -0.8, 0.2, 0.0, -0.1, 0.0, 0.05};
/* (x - 1/2)^3 */
static const double KINK[8] = {-0.125, 0.75, -1.5, 1.0, 0, 0, 0, 0};

/* f = P7 + kink_c (x - 1/2)_+^3 + jump_c [x >= jump_at] on m pieces of
 * [0, 1] (breaks uneven, and at 1/2 and jump_at), each exact. */
static double model(double x, double kink_c, double jump_c, double jump_at) {
  double v = power_eval(P7, 7, x);
  if (x >= 0.5) v += kink_c * power_eval(KINK, 3, x);
  if (x >= jump_at) v += jump_c;
  return v;
}

static void make_model(km_pp *p, size_t m, double kink_c, double jump_c,
                       double jump_at) {
  assert_int_equal(km__pp_alloc(p, 7, m), KM_OK);
  double bp[8], bk[8], bk3[4];
  power_to_bernstein(P7, 7, bp);
  power_to_bernstein(KINK, 3, bk3);
  km__bern_elevate(bk3, 3, 7, bk);
  for (size_t i = 0; i <= m; i++) {
    double u = (double)i / (double)m;
    p->x[i] = u + 0.3 * sin(7.0 * u) * u * (1 - u) / (double)m; /* uneven */
  }
  /* breaks exactly at 1/2 and at the jump */
  p->x[m / 2] = 0.5;
  size_t ij = (size_t)(jump_at * (double)m + 0.5);
  if (jump_at < 1.0 && ij != m / 2 && ij > 0 && ij < m) p->x[ij] = jump_at;
  for (size_t i = 0; i < m; i++) {
    double *c = p->c + i * 8, a = p->x[i], b = p->x[i + 1];
    km__bern_restrict(bp, 7, a, b, c);
    if (a >= 0.5) {
      double r[8];
      km__bern_restrict(bk, 7, a, b, r);
      for (int j = 0; j < 8; j++) c[j] += kink_c * r[j];
    }
    if (a >= jump_at)
      for (int j = 0; j < 8; j++) c[j] += jump_c;
  }
}

static double max_gap(const km_pp *a, const km_pp *b, int samples) {
  double g = 0.0;
  for (int k = 0; k <= samples; k++) {
    double x = (double)k / samples;
    g = fmax(g, fabs(km__pp_eval(a, x) - km__pp_eval(b, x)));
  }
  return g;
}

static void merge_of_one_polynomial_is_one_piece(void **state) {
  (void)state;
  km_pp p, q;
  km__pp_init(&q);
  make_model(&p, 40, 0.0, 0.0, 2.0);
  assert_int_equal(km__pp_merge(&p, 7, 1e-12, &q), KM_OK);
  assert_int_equal(q.m, 1);
  assert_true(q.x[0] == 0.0 && q.x[1] == p.x[p.m]);
  for (int k = 0; k <= 1000; k++) {
    double x = k / 1000.0;
    assert_close(km__pp_eval(&q, x), power_eval(P7, 7, x), 1e-13);
  }
  km__pp_free(&p);
  km__pp_free(&q);
}

static void merge_stays_within_delta_across_a_kink(void **state) {
  (void)state;
  /* a jump of f''' at 1/2, as at a cubic spline's knot: no polynomial
   * meets it exactly, so runs across it are taken only within delta */
  const double deltas[3] = {1e-4, 1e-7, 1e-10};
  for (int i = 0; i < 3; i++) {
    km_pp p, q;
    km__pp_init(&q);
    make_model(&p, 200, 0.7, 0.0, 2.0);
    assert_int_equal(km__pp_merge(&p, 7, deltas[i], &q), KM_OK);
    /* fewer pieces, the same domain, within delta of f everywhere */
    assert_true(q.m < p.m);
    assert_true(q.x[0] == p.x[0] && q.x[q.m] == p.x[p.m]);
    for (int k = 0; k <= 20000; k++) {
      double x = k / 20000.0;
      assert_true(fabs(km__pp_eval(&q, x) - model(x, 0.7, 0.0, 2.0)) <=
                  deltas[i] * (1 + 1e-9) + 1e-14);
    }
    /* breaks of q are breaks of p */
    for (size_t k = 0; k <= q.m; k++) {
      bool found = false;
      for (size_t j = 0; j <= p.m && !found; j++) found = q.x[k] == p.x[j];
      assert_true(found);
    }
    km__pp_free(&p);
    km__pp_free(&q);
  }
}

static void merge_never_crosses_a_jump(void **state) {
  (void)state;
  /* a corner in a tangent angle: f jumps by 0.4 at 0.3 */
  km_pp p, q;
  km__pp_init(&q);
  make_model(&p, 100, 0.0, 0.4, 0.3);
  assert_int_equal(km__pp_merge(&p, 7, 1e-6, &q), KM_OK);
  /* the smooth runs each side merge into one piece each */
  assert_int_equal(q.m, 2);
  assert_true(q.x[1] == 0.3);
  assert_close(km__pp_eval(&q, 0.3 - 1e-12), model(0.3 - 1e-12, 0, 0.4, 0.3),
               1e-11);
  assert_close(km__pp_eval(&q, 0.3), model(0.3, 0, 0.4, 0.3), 1e-12);
  assert_true(max_gap(&p, &q, 5000) <= 1e-6);
  km__pp_free(&p);
  km__pp_free(&q);
}

static void derivative_of_pieces_is_exact(void **state) {
  (void)state;
  km_pp p, d;
  km__pp_init(&d);
  make_model(&p, 13, 0.0, 0.0, 2.0);
  assert_int_equal(km__pp_derivative(&p, &d), KM_OK);
  assert_int_equal(d.degree, 6);
  assert_int_equal(d.m, p.m);
  double dp[7];
  for (int i = 0; i < 7; i++) dp[i] = (i + 1) * P7[i + 1];
  for (int k = 0; k <= 1000; k++) {
    double x = k / 1000.0;
    assert_close(km__pp_eval(&d, x), power_eval(dp, 6, x), 1e-12);
  }
  km__pp_free(&p);
  km__pp_free(&d);
}

/* q(x) = s (2 - 3 (x - x0)^2 + (x - x0)^4 / 2): |q| is concave on [0, 1]
 * for x0 in [0, 1] (|q''| >= 3) with its largest value 2 at x0. Eight
 * pieces with their maxima at different places and of equal height, as
 * a nearly constant curvature has them: found to rounding (a Newton step
 * on q'), not to the 1e-9 asked, and never above 2. */
static void max_abs_of_concave_pieces_is_found_to_rounding(void **state) {
  (void)state;
  for (int sign = -1; sign <= 1; sign += 2) {
    km_pp p;
    km__pp_init(&p);
    assert_int_equal(km__pp_alloc(&p, 4, 8), KM_OK);
    for (size_t i = 0; i < 8; i++) {
      double x0 = 0.1 + 0.1 * (double)i, a[5];
      /* (x - x0)^2 = x^2 - 2 x0 x + x0^2, and its square */
      double q2[3] = {x0 * x0, -2 * x0, 1.0};
      double q4[5] = {q2[0] * q2[0], 2 * q2[0] * q2[1],
                      q2[1] * q2[1] + 2 * q2[0] * q2[2], 2 * q2[1] * q2[2],
                      q2[2] * q2[2]};
      for (int j = 0; j <= 4; j++)
        a[j] = sign *
               ((j == 0 ? 2.0 : 0.0) - 3 * (j < 3 ? q2[j] : 0.0) + 0.5 * q4[j]);
      power_to_bernstein(a, 4, p.c + 5 * i);
      p.x[i] = (double)i;
    }
    p.x[8] = 8.0;
    double m9 = km__pp_max_abs_within(&p, 1e-9), m13 = km__pp_max_abs(&p);
    assert_true(fabs(m9 - 2.0) <= 4e-16 * 2 && m9 <= 2.0 * (1 + 1e-15));
    assert_true(fabs(m13 - 2.0) <= 4e-16 * 2);
    km__pp_free(&p);
  }
}

static const struct CMUnitTest tests[] = {
    cmocka_unit_test(max_abs_of_concave_pieces_is_found_to_rounding),
    cmocka_unit_test(cheb_cumulative_integrates_monomials_exactly),
    cmocka_unit_test(cheb_cumulative_of_exp_is_spectrally_accurate),
    cmocka_unit_test(bern_eval_is_within_its_rounding_bound),
    cmocka_unit_test(bezier_span_evaluation_agrees_with_de_boor),
    cmocka_unit_test(sincos_agrees_with_libm),
    cmocka_unit_test(weighted_closure_metric_is_the_gram_matrix),
    cmocka_unit_test(merge_of_one_polynomial_is_one_piece),
    cmocka_unit_test(merge_stays_within_delta_across_a_kink),
    cmocka_unit_test(merge_never_crosses_a_jump),
    cmocka_unit_test(derivative_of_pieces_is_exact),
};

TM_SUITE("numerics", tests, NULL, NULL);
