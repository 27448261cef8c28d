/* test_api_signature.c - POST /v1/signature through api_handle: the
 * signatures of curves whose curvature is known in closed form (circles,
 * segments, polygons), sent and received as JSON.
 */
#include "api_testutil.h"
#include "testmain.h"

static cJSON *signature_of(const char *body) {
  return at_expect_json(API_ROUTE_SIGNATURE, body);
}

static double num(const cJSON *o, const char *key) {
  const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
  if (!cJSON_IsNumber(v)) print_error("member %s is not a number\n", key);
  assert_true(cJSON_IsNumber(v));
  return v->valuedouble;
}

static void circle_signature_has_kappa_one_over_r(void **state) {
  (void)state;
  const double r = 2.5;
  at_buf b = {0};
  at_printf(&b, "{\"curve\":");
  at_circle_json(&b, 1.0, -3.0, r, 1);
  at_printf(&b, ",\"samples\":64}");
  cJSON *j = signature_of(b.s);
  const cJSON *sig = cJSON_GetObjectItemCaseSensitive(j, "signature");
  assert_true(cJSON_IsObject(sig));

  /* Length 2 pi r, total turning 2 pi, closed, starting at (cx + r, cy)
   * heading straight up. */
  assert_rel(num(sig, "length"), 2 * M_PI * r, 1e-10);
  assert_close(num(sig, "turning"), 2 * M_PI, 1e-9);
  assert_true(cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(sig, "closed")));
  const cJSON *start = cJSON_GetObjectItemCaseSensitive(sig, "start");
  size_t np;
  double *pt =
      at_numbers(cJSON_GetObjectItemCaseSensitive(start, "point"), &np);
  assert_int_equal(np, 2);
  assert_close(pt[0], 1.0 + r, 1e-12);
  assert_close(pt[1], -3.0, 1e-12);
  free(pt);
  assert_close(tu_wrap(num(start, "angle") - M_PI / 2), 0, 1e-9);

  /* kappa(s) = 1/r everywhere, sampled evenly over [0, L]. */
  const cJSON *samples = cJSON_GetObjectItemCaseSensitive(j, "samples");
  assert_int_equal(cJSON_GetArraySize(samples), 64);
  size_t i = 0;
  const cJSON *e;
  cJSON_ArrayForEach(e, samples) {
    size_t n2;
    double *sk = at_numbers(e, &n2);
    assert_int_equal(n2, 2);
    assert_close(sk[0], 2 * M_PI * r * (double)i / 63.0, 1e-9);
    assert_close(sk[1], 1.0 / r, 1e-9);
    free(sk);
    i++;
  }

  /* The kappa spline is well-formed: len(knots) = n + degree + 1 over
   * [0, L]. */
  const cJSON *kappa = cJSON_GetObjectItemCaseSensitive(sig, "kappa");
  size_t nk, nc;
  double *k = at_numbers(cJSON_GetObjectItemCaseSensitive(kappa, "knots"), &nk);
  double *c =
      at_numbers(cJSON_GetObjectItemCaseSensitive(kappa, "coefficients"), &nc);
  assert_int_equal(nk, nc + (size_t)num(kappa, "degree") + 1);
  assert_close(k[0], 0, 0);
  assert_rel(k[nk - 1], 2 * M_PI * r, 1e-10);
  free(k);
  free(c);
  cJSON_Delete(j);
  free(b.s);
}

static void clockwise_circle_has_negative_kappa(void **state) {
  (void)state;
  const double r = 0.75;
  at_buf b = {0};
  at_printf(&b, "{\"curve\":");
  at_circle_json(&b, 0, 0, r, 0);
  at_printf(&b, ",\"samples\":9}");
  cJSON *j = signature_of(b.s);
  const cJSON *e;
  cJSON_ArrayForEach(e, cJSON_GetObjectItemCaseSensitive(j, "samples")) {
    assert_close(cJSON_GetArrayItem(e, 1)->valuedouble, -1.0 / r, 1e-9);
  }
  assert_close(num(cJSON_GetObjectItemCaseSensitive(j, "signature"), "turning"),
               -2 * M_PI, 1e-9);
  cJSON_Delete(j);
  free(b.s);
}

static void segment_signature_is_straight(void **state) {
  (void)state;
  cJSON *j = signature_of(
      "{\"curve\":{\"type\":\"bspline\",\"degree\":1,\"knots\":[0,0,1,1],"
      "\"control_points\":[[1,1],[4,5]]},\"samples\":5}");
  const cJSON *sig = cJSON_GetObjectItemCaseSensitive(j, "signature");
  assert_close(num(sig, "length"), 5.0, 1e-12);
  assert_close(num(sig, "turning"), 0.0, 1e-12);
  assert_close(num(cJSON_GetObjectItemCaseSensitive(sig, "start"), "angle"),
               atan2(4.0, 3.0), 1e-12);
  assert_false(cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(sig, "closed")));
  const cJSON *e;
  cJSON_ArrayForEach(e, cJSON_GetObjectItemCaseSensitive(j, "samples")) {
    assert_close(cJSON_GetArrayItem(e, 1)->valuedouble, 0.0, 1e-12);
  }
  cJSON_Delete(j);
}

static void square_signature_has_four_right_angle_corners(void **state) {
  (void)state;
  /* A closed counter-clockwise square of side 2: straight sides, a turn of
   * pi/2 at every vertex (the seam's at s = length), turning 2 pi. */
  cJSON *j = signature_of("{\"curve\":{\"type\":\"bspline\",\"degree\":1,"
                          "\"knots\":[0,0,1,2,3,4,4],"
                          "\"control_points\":[[0,0],[2,0],[2,2],[0,2],[0,0]],"
                          "\"closed\":true}}");
  const cJSON *sig = cJSON_GetObjectItemCaseSensitive(j, "signature");
  assert_close(num(sig, "length"), 8.0, 1e-12);
  assert_close(num(sig, "turning"), 2 * M_PI, 1e-12);
  const cJSON *corners = cJSON_GetObjectItemCaseSensitive(sig, "corners");
  assert_int_equal(cJSON_GetArraySize(corners), 4);
  size_t i = 0;
  const cJSON *e;
  cJSON_ArrayForEach(e, corners) {
    assert_close(num(e, "s"), 2.0 * (double)(i + 1), 1e-12);
    assert_close(num(e, "turn"), M_PI / 2, 1e-12);
    i++;
  }
  cJSON_Delete(j);
}

static void signature_input_is_returned_as_given(void **state) {
  (void)state;
  /* A curve given by its signature has that signature. */
  cJSON *j = signature_of(
      "{\"curve\":{\"type\":\"signature\",\"signature\":{\"length\":5,"
      "\"start\":{\"point\":[1,2],\"angle\":0.5},"
      "\"kappa\":{\"degree\":1,\"knots\":[0,0,5,5],\"coefficients\":[0,5]}}},"
      "\"samples\":3}");
  const cJSON *sig = cJSON_GetObjectItemCaseSensitive(j, "signature");
  assert_close(num(sig, "length"), 5.0, 0);
  /* kappa = s on [0, 5]: turning = 25 / 2. */
  assert_close(num(sig, "turning"), 12.5, 1e-12);
  const cJSON *e =
      cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(j, "samples"), 1);
  assert_close(cJSON_GetArrayItem(e, 0)->valuedouble, 2.5, 1e-15);
  assert_close(cJSON_GetArrayItem(e, 1)->valuedouble, 2.5, 1e-12);
  cJSON_Delete(j);
}

static void svg_path_signature_has_its_corner(void **state) {
  (void)state;
  /* Two sides of a 3-4-5 right angle, drawn in SVG: length 7, straight
   * pieces, one corner of +pi/2 at s = 3 (y points down in SVG data, but
   * the service works in the coordinates as given). */
  cJSON *j =
      signature_of("{\"curve\":{\"type\":\"svg\",\"d\":\"M 0 0 h 3 v 4\"}}");
  const cJSON *sig = cJSON_GetObjectItemCaseSensitive(j, "signature");
  assert_close(num(sig, "length"), 7.0, 1e-12);
  const cJSON *corners = cJSON_GetObjectItemCaseSensitive(sig, "corners");
  assert_int_equal(cJSON_GetArraySize(corners), 1);
  assert_close(num(cJSON_GetArrayItem(corners, 0), "s"), 3.0, 1e-12);
  assert_close(num(cJSON_GetArrayItem(corners, 0), "turn"), M_PI / 2, 1e-12);
  assert_close(num(sig, "turning"), M_PI / 2, 1e-12);
  cJSON_Delete(j);
}

/* A member the contract does not define is never dropped silently: the
 * request is refused and the member named (test_api_members.c has the
 * other objects). */
static void unknown_fields_are_refused_by_name(void **state) {
  (void)state;
  at_problem(API_ROUTE_SIGNATURE,
             "{\"comment\":[1,{\"x\":null}],\"curve\":{\"type\":"
             "\"bspline\",\"degree\":1,\"knots\":[0,0,1,1],"
             "\"control_points\":[[0,0],[0,3]]}}",
             422, "/comment");
  at_problem(API_ROUTE_SIGNATURE,
             "{\"curve\":{\"type\":\"bspline\",\"degree\":1,"
             "\"knots\":[0,0,1,1],\"control_points\":[[0,0],[0,3]],"
             "\"colour\":\"red\"}}",
             422, "/curve/colour");
}

static void numbers_round_trip_through_json(void **state) {
  (void)state;
  /* A length that needs all 17 digits comes back bit for bit. */
  const double x = 0.1 + 0.2; /* 0.30000000000000004 */
  at_buf b = {0};
  at_printf(&b,
            "{\"curve\":{\"type\":\"signature\",\"signature\":{\"length\":"
            "%.17g,\"kappa\":{\"degree\":0,\"knots\":[0,%.17g],"
            "\"coefficients\":[0]}}}}",
            x, x);
  cJSON *j = signature_of(b.s);
  assert_true(num(cJSON_GetObjectItemCaseSensitive(j, "signature"), "length") ==
              x);
  cJSON_Delete(j);
  free(b.s);
}

static const struct CMUnitTest tests[] = {
    cmocka_unit_test(circle_signature_has_kappa_one_over_r),
    cmocka_unit_test(clockwise_circle_has_negative_kappa),
    cmocka_unit_test(segment_signature_is_straight),
    cmocka_unit_test(square_signature_has_four_right_angle_corners),
    cmocka_unit_test(signature_input_is_returned_as_given),
    cmocka_unit_test(svg_path_signature_has_its_corner),
    cmocka_unit_test(unknown_fields_are_refused_by_name),
    cmocka_unit_test(numbers_round_trip_through_json),
};

TM_SUITE("api_signature", tests, NULL, NULL);
