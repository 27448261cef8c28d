/* test_api_precision.c - "precision": "tolerance": control points printed
 * on a decimal grid of at most a tenth of the tolerance, knots on a grid
 * of their own that keeps the printed curve within that tenth, and the
 * answers still within their promises.
 *
 * Oracles: the same request answered with exact numbers (the exact
 * frame), the unit circle (the circle of radius 1 about (0, 1)), a
 * de Boor evaluator (api_testutil.h) span by span at matched local
 * parameters, a polyline length written here, and the grid itself (each
 * coordinate an integer number of steps).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../../api/src/json_write.h"
#include "api_testutil.h"
#include "fixtures.h"
#include "testmain.h"

/* A closed blob and an open wave, as points curves (fitted). */
static char *morph_body(const char *precision, double tol) {
  at_buf b = {0};
  at_printf(&b,
            "{\"from\":{\"type\":\"points\",\"closed\":true,\"points\":"
            "[[0,0],[3,-0.5],[5,1],[4.5,3.5],[2,4],[-0.5,2.5]]},"
            "\"to\":{\"type\":\"points\",\"closed\":true,\"points\":"
            "[[0,0],[2,-1],[5,0],[6,2],[3,5],[0,3]]},"
            "\"frames\":5,\"metrics\":false,\"tolerance\":%.17g%s%s%s}",
            tol, precision ? ",\"precision\":\"" : "",
            precision ? precision : "", precision ? "\"" : "");
  return b.s;
}

/* The coarsest 10^-d at most tol / 10, found by counting here. */
static double grid_step(double tol) {
  double step = 1.0;
  while (step > tol / 10) step /= 10;
  while (step * 10 <= tol / 10) step *= 10;
  return step;
}

/* Polyline length of c over many points: from below, to about 1e-9. */
static double polyline_length(const at_curve *c) {
  double total = 0, prev[2], p[2];
  double a = c->knots[c->degree], b = c->knots[c->n];
  const int m = 200000;
  at_curve_point(c, a, prev);
  for (int k = 1; k <= m; k++) {
    at_curve_point(c, a + (b - a) * k / m, p);
    total += hypot(p[0] - prev[0], p[1] - prev[1]);
    prev[0] = p[0];
    prev[1] = p[1];
  }
  return total;
}

/* The largest distance between e and g at the same local parameter of
 * each knot span (both have the same spans, knots apart): 64 points a
 * span, its ends (the joints) included. A bound on how far apart the two
 * curves are, sampled. */
static double span_distance(const at_curve *e, const at_curve *g) {
  double worst = 0;
  assert_int_equal(e->n, g->n);
  assert_int_equal(e->degree, g->degree);
  for (size_t j = (size_t)e->degree; j < e->n; j++) {
    double a = e->knots[j], b = e->knots[j + 1];
    double c = g->knots[j], d = g->knots[j + 1];
    if (!(b > a)) continue;
    for (int k = 0; k <= 64; k++) {
      double s = k / 64.0, p[2], q[2];
      /* just inside the span at its right end: de Boor takes the next
       * span there */
      if (k == 64) s = 1 - 1e-12;
      at_curve_point(e, a + (b - a) * s, p);
      at_curve_point(g, c + (d - c) * s, q);
      worst = fmax(worst, hypot(p[0] - q[0], p[1] - q[1]));
    }
  }
  return worst;
}

/* g's knots non-decreasing, equal exactly where e's are (multiplicities
 * kept, no span collapsed). */
static void assert_same_multiplicities(const at_curve *e, const at_curve *g) {
  size_t nk = e->n + (size_t)e->degree + 1;
  for (size_t k = 1; k < nk; k++) {
    assert_true(g->knots[k] >= g->knots[k - 1]);
    assert_int_equal(g->knots[k] == g->knots[k - 1],
                     e->knots[k] == e->knots[k - 1]);
  }
}

static void morph_frames_on_the_grid_stay_near_the_exact_frames(void **state) {
  (void)state;
  const double tol = 1e-4, step = grid_step(tol);
  char *exact_body = morph_body(NULL, tol);
  char *grid_body = morph_body("tolerance", tol);
  api_response er, gr;
  cJSON *ej, *gj;
  assert_int_equal(at_call(API_ROUTE_MORPH, exact_body, &er, &ej), 200);
  assert_int_equal(at_call(API_ROUTE_MORPH, grid_body, &gr, &gj), 200);
  /* fewer bytes: the digits beyond the tolerance are gone */
  assert_true(gr.length < er.length);
  const cJSON *ef = cJSON_GetObjectItemCaseSensitive(ej, "frames");
  const cJSON *gf = cJSON_GetObjectItemCaseSensitive(gj, "frames");
  assert_int_equal(cJSON_GetArraySize(ef), 5);
  assert_int_equal(cJSON_GetArraySize(gf), 5);
  for (int i = 0; i < 5; i++) {
    at_curve e, g;
    at_curve_from_json(
        cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(ef, i), "curve"),
        &e);
    at_curve_from_json(
        cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(gf, i), "curve"),
        &g);
    /* knots with their multiplicities, control points on the grid
     * within half a step */
    assert_int_equal(e.n, g.n);
    assert_same_multiplicities(&e, &g);
    for (size_t k = 0; k < 2 * e.n; k++) {
      double steps = g.cp[k] / step;
      assert_true(fabs(steps - nearbyint(steps)) <= 1e-6 + 1e-15 * fabs(steps));
      assert_true(fabs(g.cp[k] - e.cp[k]) <= 0.5 * step * (1 + 1e-9));
    }
    /* the curve moved by at most the printing's tenth of the tolerance,
     * the knots' rounding included */
    double worst = span_distance(&e, &g);
    if (worst > 0.1 * tol) fail_msg("frame %d moved %g", i, worst);
    /* the length printed is the printed curve's own */
    assert_rel(g.length, polyline_length(&g), 1e-8);
    at_curve_free(&e);
    at_curve_free(&g);
  }
  cJSON_Delete(ej);
  cJSON_Delete(gj);
  api_response_free(&er);
  api_response_free(&gr);
  free(exact_body);
  free(grid_body);
}

/* A cubic of double knots (smooth joins) and a triple one (a corner) on
 * spans of about 1e-3 with control points about 1 apart: a speed of
 * thousands, so that knots rounded to the control points' grid would move
 * the joints a hundred times the printing's share. */
static void fast_joints_are_kept_within_the_share(void **state) {
  (void)state;
  double knots[] = {0,
                    0,
                    0,
                    0,
                    1.23456789e-3,
                    1.23456789e-3,
                    2.71828183e-3,
                    2.71828183e-3,
                    2.71828183e-3,
                    4.1415926e-3,
                    4.1415926e-3,
                    5.57721566e-3,
                    5.57721566e-3,
                    5.57721566e-3,
                    5.57721566e-3};
  double cp[] = {0,   0,   1,   0.2, 1.7, 0.9, 2.3, 2.1, 3.1, 2.4, 3.3,
                 1.2, 4.1, 0.3, 5.2, 0.8, 5.9, 1.9, 6.4, 3.3, 7.0, 3.1};
  km_curve c = {3, 11, knots, cp, NULL, false};
  const double tol = 1e-3;
  api_grid grid = api__tolerance_grid(tol);
  api_ctx ctx;
  api_svg_buf b;
  double moved = -1;
  api__ctx_init(&ctx, NULL);
  api__svg_buf_init(&b);
  assert_true(api__json_curve(&ctx, &b, &c, false, tol, &grid, NAN, &moved));
  assert_false(b.failed);
  cJSON *j = cJSON_Parse(b.s);
  assert_non_null(j);
  at_curve g, e = {3, 11, knots, cp, 0, 0};
  at_curve_from_json(j, &g);
  /* the knots were rounded (fewer digits than exact), multiplicities
   * kept */
  int rounded = 0;
  for (size_t k = 0; k < 15; k++) rounded += g.knots[k] != knots[k];
  assert_true(rounded > 0);
  assert_same_multiplicities(&e, &g);
  /* within the share, and within the bound the writer reports */
  double worst = span_distance(&e, &g);
  if (worst > 0.1 * tol) fail_msg("moved %g, share %g", worst, 0.1 * tol);
  assert_true(worst <= moved * (1 + 1e-9));
  assert_true(moved <= 0.1 * tol);
  /* the same control points with knots on their own grid 1e-4: far off,
   * so the knots' share is what the writer accounted */
  at_curve naive = g;
  double nk[15];
  for (size_t k = 0; k < 15; k++) nk[k] = nearbyint(knots[k] * 1e4) / 1e4;
  naive.knots = nk;
  /* 1e-4 merges no knot of this curve */
  assert_same_multiplicities(&e, &naive);
  assert_true(span_distance(&e, &naive) > 10 * tol);
  at_curve_free(&g);
  cJSON_Delete(j);
  api__svg_buf_free(&b);
}

/* Two rings (circle in circle), the second squashed: compound frames with
 * their contours on the grids, within the printing's share each. */
static char *ring_body(const char *precision, double tol) {
  at_buf b = {0};
  at_printf(
      &b,
      "{\"from\":{\"type\":\"svg\",\"d\":\"M 0 -2 A 2 2 0 1 1 0 2 A 2 2 0 1 1 "
      "0 -2 Z M 0 -1 A 1 1 0 1 0 0 1 A 1 1 0 1 0 0 -1 Z\"},"
      "\"to\":{\"type\":\"svg\",\"d\":\"M 0 -2 A 3 2 0 1 1 0 2 A 3 2 0 1 1 "
      "0 -2 Z M 0.5 -1 L 1 0 L 0.5 1 L -0.5 1 L -1 0 L -0.5 -1 Z\"},"
      "\"frames\":4,\"metrics\":false,\"tolerance\":%.17g%s%s%s}",
      tol, precision ? ",\"precision\":\"" : "", precision ? precision : "",
      precision ? "\"" : "");
  return b.s;
}

static void
compound_frames_on_the_grid_stay_near_the_exact_frames(void **state) {
  (void)state;
  const double tol = 1e-4;
  char *exact_body = ring_body(NULL, tol),
       *grid_body = ring_body("tolerance", tol);
  api_response er, gr;
  cJSON *ej, *gj;
  assert_int_equal(at_call(API_ROUTE_MORPH, exact_body, &er, &ej), 200);
  assert_int_equal(at_call(API_ROUTE_MORPH, grid_body, &gr, &gj), 200);
  assert_true(gr.length < er.length * 0.6);
  const cJSON *ef = cJSON_GetObjectItemCaseSensitive(ej, "frames");
  const cJSON *gf = cJSON_GetObjectItemCaseSensitive(gj, "frames");
  assert_int_equal(cJSON_GetArraySize(ef), 4);
  assert_int_equal(cJSON_GetArraySize(gf), 4);
  int contours = 0;
  for (int i = 0; i < 4; i++) {
    const cJSON *ec =
        cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(ef, i), "contours");
    const cJSON *gc =
        cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(gf, i), "contours");
    assert_int_equal(cJSON_GetArraySize(ec), cJSON_GetArraySize(gc));
    for (int k = 0; k < cJSON_GetArraySize(ec); k++) {
      const cJSON *a = cJSON_GetArrayItem(ec, k),
                  *c = cJSON_GetArrayItem(gc, k);
      assert_int_equal(cJSON_IsNull(a), cJSON_IsNull(c));
      if (cJSON_IsNull(a)) continue;
      at_curve e, g;
      at_curve_from_json(a, &e);
      at_curve_from_json(c, &g);
      assert_same_multiplicities(&e, &g);
      double worst = span_distance(&e, &g);
      if (worst > 0.1 * tol)
        fail_msg("frame %d contour %d moved %g", i, k, worst);
      contours++;
      at_curve_free(&e);
      at_curve_free(&g);
    }
  }
  assert_true(contours >= 8);
  cJSON_Delete(ej);
  cJSON_Delete(gj);
  api_response_free(&er);
  api_response_free(&gr);
  free(exact_body);
  free(grid_body);
}

static char *circle_body(double tol, const char *precision) {
  tf_analytic c;
  at_buf b = {0};
  assert_int_equal(tf_load_analytic("unit_circle", &c), 0);
  at_printf(&b,
            "{\"signature\":{\"length\":%.17g,\"start\":{\"point\":[%.17g,"
            "%.17g],\"angle\":%.17g},\"kappa\":{\"degree\":%d,\"knots\":[",
            c.length, c.start[0], c.start[1], c.angle, c.kappa_degree);
  for (size_t i = 0; i < c.kappa_n + (size_t)c.kappa_degree + 1; i++)
    at_printf(&b, "%s%.17g", i ? "," : "", c.kappa_knots[i]);
  at_printf(&b, "],\"coefficients\":[");
  for (size_t i = 0; i < c.kappa_n; i++)
    at_printf(&b, "%s%.17g", i ? "," : "", c.kappa_coef[i]);
  at_printf(&b, "]},\"closed\":true},\"tolerance\":%.17g,\"precision\":\"%s\"}",
            tol, precision);
  tf_analytic_free(&c);
  return b.s;
}

static void reconstruct_on_the_grid_stays_within_its_bound(void **state) {
  (void)state;
  const double tols[] = {1e-3, 1e-6, 1e-9};
  for (size_t t = 0; t < 3; t++) {
    double tol = tols[t], step = grid_step(tol);
    char *body = circle_body(tol, "tolerance");
    cJSON *j = at_expect_json(API_ROUTE_RECONSTRUCT, body);
    at_curve c;
    at_curve_from_json(cJSON_GetObjectItemCaseSensitive(j, "curve"), &c);
    double bound =
        cJSON_GetObjectItemCaseSensitive(j, "error_bound")->valuedouble;
    assert_true(bound <= tol);
    for (size_t k = 0; k < 2 * c.n; k++) {
      double steps = c.cp[k] / step;
      assert_true(fabs(steps - nearbyint(steps)) <= 1e-6 + 1e-15 * fabs(steps));
    }
    /* the exact curve is the circle of radius 1 about (0, 1): a point's
     * distance to it is | |p - (0, 1)| - 1 | */
    double worst = 0;
    for (int k = 0; k <= 20000; k++) {
      double s = 2 * M_PI * k / 20000, p[2];
      at_curve_point(&c, s, p);
      worst = fmax(worst, fabs(hypot(p[0], p[1] - 1) - 1));
    }
    if (worst > bound)
      fail_msg("tol %g: error %g above bound %g", tol, worst, bound);
    at_curve_free(&c);
    cJSON_Delete(j);
    free(body);
  }
}

static void precision_names_are_exact_or_tolerance(void **state) {
  (void)state;
  char *body = morph_body("fast", 1e-4);
  at_problem(API_ROUTE_MORPH, body, 422, "/precision");
  free(body);
  body = circle_body(1e-6, "digits");
  at_problem(API_ROUTE_RECONSTRUCT, body, 422, "/precision");
  free(body);
  body = morph_body("exact", 1e-4);
  cJSON_Delete(at_expect_json(API_ROUTE_MORPH, body));
  free(body);
}

static const struct CMUnitTest tests[] = {
    cmocka_unit_test(morph_frames_on_the_grid_stay_near_the_exact_frames),
    cmocka_unit_test(fast_joints_are_kept_within_the_share),
    cmocka_unit_test(compound_frames_on_the_grid_stay_near_the_exact_frames),
    cmocka_unit_test(reconstruct_on_the_grid_stays_within_its_bound),
    cmocka_unit_test(precision_names_are_exact_or_tolerance),
};

TM_SUITE("api_precision", tests, NULL, NULL);
