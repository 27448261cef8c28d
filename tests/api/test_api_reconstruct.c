/* test_api_reconstruct.c - POST /v1/reconstruct through api_handle: curves
 * rebuilt from signatures whose curves are known exactly (the unit circle
 * and the Cornu spiral of tests/fixtures/analytic.json) land on them within
 * the tolerance, at the returned knots, which are arc length.
 */
#include "api_testutil.h"
#include "fixtures.h"
#include "testmain.h"

/* The fixture's signature as a request body. */
static char *request_for(const char *name, double tol, int degree) {
  tf_analytic a;
  at_buf b = {0};
  assert_int_equal(tf_load_analytic(name, &a), 0);
  at_printf(&b,
            "{\"signature\":{\"length\":%.17g,\"start\":{\"point\":[%.17g,"
            "%.17g],\"angle\":%.17g},\"kappa\":{\"degree\":%d,\"knots\":[",
            a.length, a.start[0], a.start[1], a.angle, a.kappa_degree);
  for (size_t i = 0; i < a.kappa_n + (size_t)a.kappa_degree + 1; i++)
    at_printf(&b, "%s%.17g", i ? "," : "", a.kappa_knots[i]);
  at_printf(&b, "],\"coefficients\":[");
  for (size_t i = 0; i < a.kappa_n; i++)
    at_printf(&b, "%s%.17g", i ? "," : "", a.kappa_coef[i]);
  at_printf(&b, "]},\"closed\":%s},\"tolerance\":%.17g,\"degree\":%d}",
            a.closed ? "true" : "false", tol, degree);
  tf_analytic_free(&a);
  return b.s;
}

/* Reconstruct and return the output curve and bound. */
static cJSON *reconstruct(const char *body, at_curve *c, double *bound) {
  cJSON *j = at_expect_json(API_ROUTE_RECONSTRUCT, body);
  at_curve_from_json(cJSON_GetObjectItemCaseSensitive(j, "curve"), c);
  const cJSON *eb = cJSON_GetObjectItemCaseSensitive(j, "error_bound");
  assert_true(cJSON_IsNumber(eb));
  *bound = eb->valuedouble;
  return j;
}

static void check_unit_circle(int degree, double tol) {
  char *body = request_for("unit_circle", tol, degree);
  at_curve c;
  double bound;
  cJSON *j = reconstruct(body, &c, &bound);
  assert_int_equal(c.degree, degree);
  assert_true(c.closed);
  assert_true(bound >= 0 && bound <= tol);
  /* The parameter is arc length: the domain is [0, 2 pi]. */
  assert_close(c.knots[0], 0, 1e-12);
  assert_close(c.knots[c.n + (size_t)degree], 2 * M_PI, 1e-9);
  /* At every knot, the point is the circle's x = sin s, y = 1 - cos s. */
  for (size_t i = (size_t)degree; i <= c.n; i++) {
    double s = c.knots[i], p[2];
    at_curve_point(&c, s, p);
    assert_le(hypot(p[0] - sin(s), p[1] - (1 - cos(s))), tol);
  }
  /* Between knots it stays within the tolerance of the circle itself. */
  for (int k = 0; k <= 1000; k++) {
    double s = 2 * M_PI * k / 1000.0, p[2];
    at_curve_point(&c, s, p);
    assert_le(fabs(hypot(p[0], p[1] - 1) - 1), tol);
  }
  assert_rel(c.length, 2 * M_PI, 1e-5);
  at_curve_free(&c);
  cJSON_Delete(j);
  free(body);
}

static void unit_circle_cubic_lands_on_the_circle(void **state) {
  (void)state;
  check_unit_circle(3, 1e-6);
}

static void unit_circle_quintic_lands_on_the_circle(void **state) {
  (void)state;
  check_unit_circle(5, 1e-8);
}

static double cornu_cos(double s, const void *ctx) {
  (void)ctx;
  return cos(0.5 * s * s);
}

static double cornu_sin(double s, const void *ctx) {
  (void)ctx;
  return sin(0.5 * s * s);
}

static void cornu_spiral_matches_fresnel_integrals(void **state) {
  (void)state;
  /* kappa = s, theta = s^2 / 2: C(s) = (int cos theta, int sin theta). */
  const double tol = 1e-7;
  char *body = request_for("cornu_5", tol, 3);
  at_curve c;
  double bound;
  cJSON *j = reconstruct(body, &c, &bound);
  assert_false(c.closed);
  assert_true(bound <= tol);
  for (size_t i = 3; i <= c.n; i++) {
    double s = c.knots[i], p[2];
    double x = tu_integrate(cornu_cos, NULL, 0, s, 64);
    double y = tu_integrate(cornu_sin, NULL, 0, s, 64);
    at_curve_point(&c, s, p);
    assert_le(hypot(p[0] - x, p[1] - y), tol);
  }
  at_curve_free(&c);
  cJSON_Delete(j);
  free(body);
}

static void svg_d_is_included_when_asked(void **state) {
  (void)state;
  char *body = request_for("unit_circle", 1e-5, 3);
  /* Insert "include" at the top level. */
  size_t n = strlen(body);
  char *with = malloc(n + 32);
  assert_non_null(with);
  memcpy(with, body, n - 1);
  strcpy(with + n - 1, ",\"include\":[\"svg_d\"]}");
  api_response res;
  cJSON *j;
  assert_int_equal(at_call(API_ROUTE_RECONSTRUCT, with, &res, &j), 200);
  const cJSON *d = cJSON_GetObjectItemCaseSensitive(
      cJSON_GetObjectItemCaseSensitive(j, "curve"), "svg_d");
  assert_true(cJSON_IsString(d));
  assert_true(d->valuestring[0] == 'M');
  /* A closed curve's path ends with Z. */
  assert_non_null(strchr(d->valuestring, 'Z'));
  cJSON_Delete(j);
  api_response_free(&res);
  free(with);
  free(body);
}

static void signature_then_reconstruct_round_trips(void **state) {
  (void)state;
  /* The signature of a circle of radius 3 about the origin, fed back,
   * rebuilds the same circle (start point and angle included). */
  at_buf b = {0};
  api_response res;
  cJSON *j;
  at_printf(&b, "{\"curve\":");
  at_circle_json(&b, 0, 0, 3, 1);
  at_printf(&b, ",\"tolerance\":1e-9}");
  assert_int_equal(at_call(API_ROUTE_SIGNATURE, b.s, &res, &j), 200);
  api_response_free(&res);
  cJSON *sig = cJSON_DetachItemFromObject(j, "signature");
  cJSON_Delete(j);
  cJSON *req = cJSON_CreateObject();
  cJSON_AddItemToObject(req, "signature", sig);
  cJSON_AddNumberToObject(req, "tolerance", 1e-6);
  char *text = cJSON_PrintUnformatted(req);
  cJSON_Delete(req);
  at_curve c;
  double bound;
  j = reconstruct(text, &c, &bound);
  assert_true(c.closed);
  for (int k = 0; k <= 500; k++) {
    double s = c.knots[c.n + 3] * k / 500.0, p[2];
    at_curve_point(&c, s, p);
    assert_le(fabs(hypot(p[0], p[1]) - 3), 1e-6);
  }
  at_curve_free(&c);
  cJSON_Delete(j);
  free(text);
  free(b.s);
}

static const struct CMUnitTest tests[] = {
    cmocka_unit_test(unit_circle_cubic_lands_on_the_circle),
    cmocka_unit_test(unit_circle_quintic_lands_on_the_circle),
    cmocka_unit_test(cornu_spiral_matches_fresnel_integrals),
    cmocka_unit_test(svg_d_is_included_when_asked),
    cmocka_unit_test(signature_then_reconstruct_round_trips),
};

TM_SUITE("api_reconstruct", tests, NULL, NULL);
