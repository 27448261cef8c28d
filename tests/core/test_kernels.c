/* test_kernels.c - the small numeric kernels every B-spline and piecewise
 * polynomial in the core rests on: the knot-span search, the bisection
 * under it, the cubic B-spline basis and the dense solver.
 *
 * Oracles: the definition of a knot span (U[i] <= u < U[i+1], never
 * empty), a linear scan, the closed form of the uniform cubic B-spline
 * (1/6, 2/3, 1/6 at a knot; 1/48, 23/48, 23/48, 1/48 at a midpoint),
 * partition of unity, and a system with a known integer solution.
 */
#include <math.h>
#include <stdbool.h>
#include <stddef.h>

#include "../../core/src/kernels.h"
#include "testutil.h"
#include "testmain.h"

/* ---- knot spans ---------------------------------------------------------- */

/* Degree 3, 9 control points; a double and a triple interior knot, so
 * spans 4, 6 and 7 are empty. */
static const double REPEATED[13] = {0, 0, 0, 0, 1, 1, 2, 2, 2, 4, 4, 4, 4};
enum { REP_N = 9, REP_P = 3 };

static void check_span(const double *U, size_t n, int p, double u) {
  size_t i = km__knot_span(U, n, p, u);
  assert_true(i >= (size_t)p && i <= n - 1);
  assert_true(U[i + 1] > U[i]); /* never an empty span */
  if (u <= U[p]) {
    assert_true(U[i] == U[p]);
  } else if (u >= U[n]) {
    assert_true(U[i + 1] == U[n]);
  } else {
    assert_true(U[i] <= u && u < U[i + 1]);
  }
}

static void knot_span_contains_u_and_is_never_empty(void **state) {
  (void)state;
  /* at every knot, between knots and beyond both ends */
  for (int k = -4; k <= 20; k++) check_span(REPEATED, REP_N, REP_P, 0.25 * k);
  for (size_t k = 0; k < REP_N + REP_P + 1; k++)
    check_span(REPEATED, REP_N, REP_P, REPEATED[k]);
}

static void knot_span_steps_over_empty_spans_at_the_ends(void **state) {
  (void)state;
  /* the last span [2, 4] at and past the end, and at the triple knot */
  assert_int_equal(km__knot_span(REPEATED, REP_N, REP_P, 4.0), 8);
  assert_int_equal(km__knot_span(REPEATED, REP_N, REP_P, 9.0), 8);
  assert_int_equal(km__knot_span(REPEATED, REP_N, REP_P, 2.0), 8);
  assert_int_equal(km__knot_span(REPEATED, REP_N, REP_P, 1.0), 5);
  /* an interior knot equal to the end: span 4 = [1, 1] is empty, the
   * last non-empty one is 3 = [0, 1] */
  static const double E[9] = {0, 0, 0, 0, 1, 1, 1, 1, 1};
  assert_int_equal(km__knot_span(E, 5, 3, 1.0), 3);
  /* one equal to the start: span 3 = [0, 0] is empty, the first
   * non-empty one is 4 = [0, 1] */
  static const double S[9] = {0, 0, 0, 0, 0, 1, 1, 1, 1};
  assert_int_equal(km__knot_span(S, 5, 3, 0.0), 4);
  assert_int_equal(km__knot_span(S, 5, 3, -1.0), 4);
}

static void knot_span_of_degree_zero_is_the_piece(void **state) {
  (void)state;
  static const double U[4] = {0, 1, 2, 3}; /* three constant pieces */
  assert_int_equal(km__knot_span(U, 3, 0, -1.0), 0);
  assert_int_equal(km__knot_span(U, 3, 0, 1.0), 1);
  assert_int_equal(km__knot_span(U, 3, 0, 2.5), 2);
  assert_int_equal(km__knot_span(U, 3, 0, 3.0), 2);
}

static void bracket_agrees_with_a_linear_scan(void **state) {
  (void)state;
  double x[64];
  for (int i = 0; i < 64; i++) x[i] = i * i * 0.01; /* sorted, uneven */
  for (int k = 0; k < 400; k++) {
    double v = 0.1 * k;
    if (!(v >= x[0] && v < x[63])) continue;
    size_t want = 0;
    while (want + 1 < 63 && x[want + 1] <= v) want++;
    assert_int_equal(km__bracket(x, 0, 63, v), want);
  }
}

/* ---- the cubic basis ---------------------------------------------------- */

static void cubic_basis_of_uniform_knots_is_the_closed_form(void **state) {
  (void)state;
  static const double U[12] = {-3, -2, -1, 0, 1, 2, 3, 4, 5, 6, 7, 8};
  double N[4];
  /* at the knot u = 2 (span 5 = [2, 3]) */
  km__cubic_basis(U, 5, 2.0, N);
  assert_close(N[0], 1.0 / 6, 1e-15);
  assert_close(N[1], 2.0 / 3, 1e-15);
  assert_close(N[2], 1.0 / 6, 1e-15);
  assert_close(N[3], 0.0, 1e-15);
  /* at the midpoint u = 2.5 */
  km__cubic_basis(U, 5, 2.5, N);
  assert_close(N[0], 1.0 / 48, 1e-15);
  assert_close(N[1], 23.0 / 48, 1e-15);
  assert_close(N[2], 23.0 / 48, 1e-15);
  assert_close(N[3], 1.0 / 48, 1e-15);
}

static void cubic_basis_is_a_partition_of_unity(void **state) {
  (void)state;
  for (int k = 0; k <= 40; k++) {
    double u = 4.0 * k / 40, N[4], sum = 0.0;
    size_t i = km__knot_span(REPEATED, REP_N, REP_P, u);
    km__cubic_basis(REPEATED, i, u, N);
    for (int j = 0; j < 4; j++) {
      assert_true(N[j] >= -1e-15);
      sum += N[j];
    }
    assert_close(sum, 1.0, 1e-14);
  }
}

/* ---- the dense solver ----------------------------------------------------- */

static void solve_dense_recovers_an_integer_solution(void **state) {
  (void)state;
  /* A x = y for x = (1, -2, 3, 0), with a zero first pivot (row swaps) */
  double A[16] = {0, 2, 1, 1, 1, 1, 0, 2, 3, 0, 1, 1, 2, 1, 1, 0};
  static const double x[4] = {1, -2, 3, 0};
  double y[4];
  for (int r = 0; r < 4; r++) {
    y[r] = 0.0;
    for (int c = 0; c < 4; c++) y[r] += A[4 * r + c] * x[c];
  }
  assert_true(km__solve_dense(A, y, 4));
  for (int r = 0; r < 4; r++) assert_close(y[r], x[r], 1e-14);
  double S[4] = {1, 2, 2, 4}, z[2] = {1, 2}; /* rank 1 */
  assert_false(km__solve_dense(S, z, 2));
}

static const struct CMUnitTest tests[] = {
    cmocka_unit_test(knot_span_contains_u_and_is_never_empty),
    cmocka_unit_test(knot_span_steps_over_empty_spans_at_the_ends),
    cmocka_unit_test(knot_span_of_degree_zero_is_the_piece),
    cmocka_unit_test(bracket_agrees_with_a_linear_scan),
    cmocka_unit_test(cubic_basis_of_uniform_knots_is_the_closed_form),
    cmocka_unit_test(cubic_basis_is_a_partition_of_unity),
    cmocka_unit_test(solve_dense_recovers_an_integer_solution),
};

TM_SUITE("kernels", tests, NULL, NULL);
