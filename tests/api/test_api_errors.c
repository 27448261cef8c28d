/* test_api_errors.c - every documented way a request can be wrong gets the
 * documented status and a JSON pointer to the bad field, through
 * api_handle exactly as the daemon and the CLI call it.
 */
#include "api_testutil.h"
#include "testmain.h"

#define SIG API_ROUTE_SIGNATURE
#define REC API_ROUTE_RECONSTRUCT

/* A valid open cubic: 5 control points, knots 0,0,0,0,0.5,1,1,1,1. */
#define CURVE_HEAD "{\"curve\":{\"type\":\"bspline\",\"degree\":3,"
#define GOOD_KNOTS "\"knots\":[0,0,0,0,0.5,1,1,1,1]"
#define GOOD_CP "\"control_points\":[[0,0],[1,2],[3,3],[4,1],[5,0]]"

static void malformed_json_is_400(void **state) {
  (void)state;
  static const char *const bad[] = {
      "{",           "{\"curve\":}",    "[1,]",
      "{\"a\":1} x", "{\"a\":NaN}",     "{'a':1}",
      "{\"a\":01}",  "{\"a\":1.}",      "",
      "   ",         "{\"a\":\"\\x\"}", "{\"a\":tru}",
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    cJSON *j = at_expect_problem(SIG, bad[i], 400, NULL);
    const cJSON *d = cJSON_GetObjectItemCaseSensitive(j, "detail");
    assert_true(cJSON_IsString(d));
    /* The detail says where the syntax broke. */
    assert_non_null(strstr(d->valuestring, "byte"));
    cJSON_Delete(j);
  }
}

static void invalid_utf8_is_400(void **state) {
  (void)state;
  at_problem(SIG, "{\"curve\":\"\xc3\x28\"}", 400, NULL);
  at_problem(SIG, "{\"curve\":\"\xed\xa0\x80\"}", 400, NULL); /* surrogate */
}

static void string_escapes_are_decoded(void **state) {
  (void)state;
  /* "\u0062spline" is "bspline": the curve is read, and its (missing)
   * knots are what is reported. */
  at_problem(SIG,
             "{\"\\u0063urve\":{\"type\":\"\\u0062spline\",\"degree\":1,"
             "\"control_points\":[[0,0],[1,1]]}}",
             422, "/curve/knots");
  /* A member name with a surrogate pair, quotes and a solidus is decoded
   * and named by its pointer (RFC 6901 writes "/" as "~1"). */
  at_problem(SIG,
             "{\"\\ud83d\\ude00 \\\"q\\\" \\/\":1,"
             "\"curve\":{\"type\":\"svg\",\"d\":\"M0 0L1 0\"}}",
             422, "/\xf0\x9f\x98\x80 \"q\" ~1");
  at_problem(SIG, "{\"a\":\"\\ud83d\"}", 400, NULL);
  at_problem(SIG, "{\"a\":\"\\ude00\"}", 400, NULL);
  at_problem(SIG, "{\"a\":\"\\u0000\"}", 400, NULL);
  at_problem(SIG, "{\"a\":\"\\u12G4\"}", 400, NULL);
}

static void body_without_nul_is_read_to_its_length(void **state) {
  (void)state;
  /* The bytes after `length` must not be read: here they would make the
   * body malformed, so a 422 (missing curve) proves they were ignored. */
  static const char body[] = "{ \t\n\r }garbage";
  api_response res;
  cJSON *j;
  int st = at_call_cfg(NULL, SIG, body, 7, &res, &j);
  assert_int_equal(st, 422);
  const cJSON *p = cJSON_GetObjectItemCaseSensitive(
      cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(j, "errors"), 0),
      "pointer");
  assert_string_equal(p->valuestring, "/curve");
  cJSON_Delete(j);
  api_response_free(&res);
}

static char *nested(size_t depth) {
  char *s = malloc(2 * depth + 16);
  size_t n = 0;
  assert_non_null(s);
  n += (size_t)sprintf(s, "{\"curve\":");
  for (size_t i = 1; i < depth; i++) s[n++] = '[';
  s[n++] = '1';
  for (size_t i = 1; i < depth; i++) s[n++] = ']';
  s[n++] = '}';
  s[n] = '\0';
  return s;
}

static void nesting_deeper_than_the_limit_is_400(void **state) {
  (void)state;
  api_config cfg;
  api_config_default(&cfg);
  char *at_limit = nested(cfg.max_json_depth);
  char *over = nested(cfg.max_json_depth + 1);
  char *huge = nested(100000); /* would overflow a recursive parser */
  /* At the limit the body is well-formed (and its curve is no object). */
  at_problem(SIG, at_limit, 422, "/curve");
  at_problem(SIG, over, 400, NULL);
  at_problem(SIG, huge, 400, NULL);
  free(at_limit);
  free(over);
  free(huge);
}

/* An array longer than any field may hold is refused by the scanner,
 * before a tree of a million items is built. */
static void overlong_array_is_refused_before_parsing(void **state) {
  (void)state;
  api_config cfg;
  api_config_default(&cfg);
  cfg.max_control_points = 10;
  cfg.max_samples = 10;
  cfg.max_frames_job = 10;
  const char *head = "{\"curve\":{\"type\":\"points\",\"points\":[";
  size_t n = 1000, cap = strlen(head) + n * 6 + 8;
  char *body = malloc(cap), *p = body;
  p += sprintf(p, "%s", head);
  for (size_t i = 0; i < n; i++) p += sprintf(p, "%s[0,1]", i ? "," : "");
  sprintf(p, "]}}");
  cJSON *j = at_expect_problem_cfg(&cfg, SIG, body, 422, NULL);
  assert_string_equal(cJSON_GetObjectItem(j, "type")->valuestring,
                      "/problems/limit-exceeded");
  cJSON_Delete(j);
  free(body);
}

static void non_object_body_is_422_at_root(void **state) {
  (void)state;
  at_problem(SIG, "[1,2]", 422, "");
  at_problem(SIG, "42", 422, "");
  at_problem(REC, "\"signature\"", 422, "");
}

static void body_over_the_limit_is_413(void **state) {
  (void)state;
  api_config cfg;
  api_config_default(&cfg);
  cfg.max_body_bytes = 16;
  cJSON_Delete(at_expect_problem_cfg(
      &cfg, SIG, "{\"curve\":{\"type\":\"points\"}}", 413, NULL));
}

static void unknown_route_is_404(void **state) {
  (void)state;
  api_response res;
  api_request req;
  api_config cfg;
  api_config_default(&cfg);
  memset(&req, 0, sizeof req);
  req.route = (api_route)99;
  req.body = "{}";
  req.length = 2;
  assert_int_equal(api_handle(&cfg, &req, &res), 404);
  assert_string_equal(res.content_type, "application/problem+json");
  api_response_free(&res);
}

static void missing_and_mistyped_fields_name_the_field(void **state) {
  (void)state;
  at_problem(SIG, "{}", 422, "/curve");
  at_problem(SIG, "{\"curve\":[]}", 422, "/curve");
  at_problem(SIG, "{\"curve\":{}}", 422, "/curve/type");
  at_problem(SIG, "{\"curve\":{\"type\":\"nurbs\"}}", 422, "/curve/type");
  at_problem(SIG, "{\"curve\":{\"type\":7}}", 422, "/curve/type");
  at_problem(SIG, CURVE_HEAD GOOD_CP "}}", 422, "/curve/knots");
  at_problem(SIG, CURVE_HEAD GOOD_KNOTS "}}", 422, "/curve/control_points");
  at_problem(SIG,
             "{\"curve\":{\"type\":\"bspline\",\"degree\":\"3\"," GOOD_KNOTS
             "," GOOD_CP "}}",
             422, "/curve/degree");
  at_problem(SIG,
             CURVE_HEAD GOOD_KNOTS
             ",\"control_points\":[[0,0],[1,2],[3,3],[4,\"1\"],[5,0]]}}",
             422, "/curve/control_points/3/1");
  at_problem(SIG,
             CURVE_HEAD GOOD_KNOTS
             ",\"control_points\":[[0,0],[1,2],[3],[4,1],[5,0]]}}",
             422, "/curve/control_points/2");
  at_problem(SIG, CURVE_HEAD "\"knots\":[0,0,0,0,null,1,1,1,1]," GOOD_CP "}}",
             422, "/curve/knots/4");
  at_problem(SIG, CURVE_HEAD GOOD_KNOTS "," GOOD_CP ",\"closed\":\"no\"}}", 422,
             "/curve/closed");
  at_problem(SIG, "{\"curve\":{\"type\":\"svg\",\"d\":5}}", 422, "/curve/d");
  at_problem(SIG, "{\"curve\":{\"type\":\"points\",\"points\":[[0,0]]}}", 422,
             "/curve/points");
  at_problem(SIG,
             "{\"curve\":{\"type\":\"points\",\"points\":[[0,0],[1,true]]}}",
             422, "/curve/points/1/1");
}

static void non_finite_numbers_are_422(void **state) {
  (void)state;
  /* 1e999 parses to infinity; the contract has none. */
  at_problem(SIG,
             CURVE_HEAD GOOD_KNOTS
             ",\"control_points\":[[0,0],[1e999,2],[3,3],[4,1],[5,0]]}}",
             422, "/curve/control_points/1/0");
  at_problem(SIG,
             CURVE_HEAD "\"knots\":[0,0,0,0,0.5,1,1,1,-1e999]," GOOD_CP "}}",
             422, "/curve/knots/8");
  at_problem(SIG, CURVE_HEAD GOOD_KNOTS "," GOOD_CP "},\"tolerance\":1e400}",
             422, "/tolerance");
}

static void bad_svg_path_names_d_and_the_offset(void **state) {
  (void)state;
  /* "L 1" lacks its y coordinate; the message says where. */
  cJSON *j = at_expect_problem(
      SIG, "{\"curve\":{\"type\":\"svg\",\"d\":\"M 0 0 L 1\"}}", 422,
      "/curve/d");
  const cJSON *m = cJSON_GetObjectItem(
      cJSON_GetArrayItem(cJSON_GetObjectItem(j, "errors"), 0), "message");
  assert_non_null(strstr(m->valuestring, "offset"));
  cJSON_Delete(j);
  at_problem(SIG, "{\"curve\":{\"type\":\"svg\",\"d\":\"Q\"}}", 422,
             "/curve/d");
  at_problem(SIG, "{\"curve\":{\"type\":\"svg\"}}", 422, "/curve/d");
}

static void decreasing_knot_is_named(void **state) {
  (void)state;
  cJSON *j = at_expect_problem(
      SIG,
      CURVE_HEAD "\"knots\":[0,0,0,0,0.6,0.5,1,1,1,1],"
                 "\"control_points\":[[0,0],[1,2],[3,3],[4,1],[5,0],"
                 "[6,1]]}}",
      422, "/curve/knots/5");
  assert_string_equal(cJSON_GetObjectItemCaseSensitive(j, "type")->valuestring,
                      "/problems/invalid-curve");
  cJSON_Delete(j);
}

static void wrong_knot_count_is_named(void **state) {
  (void)state;
  at_problem(SIG, CURVE_HEAD "\"knots\":[0,0,0,0,1,1,1,1]," GOOD_CP "}}", 422,
             "/curve/knots");
}

static void degree_out_of_range_is_named(void **state) {
  (void)state;
  at_problem(SIG,
             "{\"curve\":{\"type\":\"bspline\",\"degree\":0," GOOD_KNOTS
             "," GOOD_CP "}}",
             422, "/curve/degree");
  at_problem(SIG,
             "{\"curve\":{\"type\":\"bspline\",\"degree\":20," GOOD_KNOTS
             "," GOOD_CP "}}",
             422, "/curve/degree");
  at_problem(SIG,
             "{\"curve\":{\"type\":\"bspline\",\"degree\":2.5," GOOD_KNOTS
             "," GOOD_CP "}}",
             422, "/curve/degree");
}

static void non_positive_weight_is_named(void **state) {
  (void)state;
  at_problem(SIG,
             CURVE_HEAD GOOD_KNOTS "," GOOD_CP ",\"weights\":[1,1,0,1,1]}}",
             422, "/curve/weights/2");
  at_problem(SIG,
             CURVE_HEAD GOOD_KNOTS "," GOOD_CP ",\"weights\":[1,1,1,-2,1]}}",
             422, "/curve/weights/3");
  at_problem(SIG, CURVE_HEAD GOOD_KNOTS "," GOOD_CP ",\"weights\":[1,1,1]}}",
             422, "/curve/weights");
}

static void closed_curve_that_does_not_close_is_named(void **state) {
  (void)state;
  at_problem(SIG, CURVE_HEAD GOOD_KNOTS "," GOOD_CP ",\"closed\":true}}", 422,
             "/curve/closed");
}

static void cusp_is_422_invalid_curve(void **state) {
  (void)state;
  /* C'(1/2) = 0 and C' changes sign there: the tangent reverses. */
  cJSON *j = at_expect_problem(SIG,
                               "{\"curve\":{\"type\":\"bspline\",\"degree\":3,"
                               "\"knots\":[0,0,0,0,1,1,1,1],"
                               "\"control_points\":[[0,0],[2,2],[0,2],[2,0]]}}",
                               422, NULL);
  assert_string_equal(cJSON_GetObjectItemCaseSensitive(j, "type")->valuestring,
                      "/problems/invalid-curve");
  /* The curve, or a part of it, is named. */
  const cJSON *e0 =
      cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(j, "errors"), 0);
  const cJSON *p = cJSON_GetObjectItemCaseSensitive(e0, "pointer");
  assert_true(cJSON_IsString(p));
  assert_true(strncmp(p->valuestring, "/curve", 6) == 0);
  cJSON_Delete(j);
}

static void control_points_above_the_limit_are_422(void **state) {
  (void)state;
  api_config cfg;
  api_config_default(&cfg);
  cfg.max_control_points = 4;
  cJSON *j =
      at_expect_problem_cfg(&cfg, SIG, CURVE_HEAD GOOD_KNOTS "," GOOD_CP "}}",
                            422, "/curve/control_points");
  assert_string_equal(cJSON_GetObjectItemCaseSensitive(j, "type")->valuestring,
                      "/problems/limit-exceeded");
  cJSON_Delete(j);
}

/* Answers are held to the limit on curves too, and a signature to the
 * turns it may make: the unit circle at 1e-9 needs some 64 cubic pieces
 * (arc-shaped, their bound about h^6 / 2000), 130 control points, and no
 * cubic fewer than 34 pieces, 70 points (the best arc turning phi is off
 * by about phi^6 / 56000); a limit of 150 counts 3 points a piece, 49
 * pieces. A planned morph's frames are Hermite in arc length, some 250
 * pieces (h = (384 tol)^(1/4) = 0.025) at 1e-9. kappa falling from 1e5 to
 * -2 over 4 units turns (1e5 - 2) 2 / (2 pi) = 31,830 times. */
#define UNIT_CIRCLE_SIG                                                        \
  "{\"length\":6.283185307179586,\"start\":{\"point\":[1,0],"                  \
  "\"angle\":1.5707963267948966},\"kappa\":{\"degree\":0,\"knots\":[0,"        \
  "6.283185307179586],\"coefficients\":[1]},\"closed\":true}"
static void answers_and_turns_above_the_limits_are_422(void **state) {
  (void)state;
  api_config cfg;
  api_config_default(&cfg);
  cfg.max_control_points = 150;
  cJSON *j = at_expect_problem_cfg(&cfg, API_ROUTE_RECONSTRUCT,
                                   "{\"signature\":" UNIT_CIRCLE_SIG
                                   ",\"tolerance\":1e-9}",
                                   422, "/tolerance");
  assert_string_equal(cJSON_GetObjectItemCaseSensitive(j, "type")->valuestring,
                      "/problems/limit-exceeded");
  cJSON_Delete(j);
  cfg.max_control_points = 2000;
  api_response res;
  j = NULL;
  const char *ok = "{\"signature\":" UNIT_CIRCLE_SIG ",\"tolerance\":1e-9}";
  assert_int_equal(
      at_call_cfg(&cfg, API_ROUTE_RECONSTRUCT, ok, strlen(ok), &res, &j), 200);
  const cJSON *cp = cJSON_GetObjectItemCaseSensitive(
      cJSON_GetObjectItemCaseSensitive(j, "curve"), "control_points");
  assert_true(cJSON_GetArraySize(cp) >= 70 && cJSON_GetArraySize(cp) <= 150);
  cJSON_Delete(j);
  api_response_free(&res);
  /* a morph's frames likewise, refused before any frame is made */
  cfg.max_control_points = 400;
  cJSON_Delete(at_expect_problem_cfg(
      &cfg, API_ROUTE_MORPH,
      "{\"from\":{\"type\":\"signature\",\"signature\":" UNIT_CIRCLE_SIG
      "},\"to\":{\"type\":\"signature\",\"signature\":" UNIT_CIRCLE_SIG
      "},\"tolerance\":1e-9,\"frames\":3}",
      422, "/tolerance"));
  at_problem(API_ROUTE_RECONSTRUCT,
             "{\"signature\":{\"length\":4,\"start\":{\"point\":[0,0],"
             "\"angle\":0},\"kappa\":{\"degree\":1,\"knots\":[0,0,4,4],"
             "\"coefficients\":[1e5,-2]},\"closed\":false}}",
             422, "/signature/kappa/coefficients");
}

static void bad_tolerance_and_samples_are_named(void **state) {
  (void)state;
  at_problem(SIG, CURVE_HEAD GOOD_KNOTS "," GOOD_CP "},\"tolerance\":0}", 422,
             "/tolerance");
  at_problem(SIG, CURVE_HEAD GOOD_KNOTS "," GOOD_CP "},\"tolerance\":-1}", 422,
             "/tolerance");
  at_problem(SIG, CURVE_HEAD GOOD_KNOTS "," GOOD_CP "},\"tolerance\":\"1\"}",
             422, "/tolerance");
  at_problem(SIG, CURVE_HEAD GOOD_KNOTS "," GOOD_CP "},\"samples\":1}", 422,
             "/samples");
  at_problem(SIG, CURVE_HEAD GOOD_KNOTS "," GOOD_CP "},\"samples\":1e9}", 422,
             "/samples");
  at_problem(SIG, CURVE_HEAD GOOD_KNOTS "," GOOD_CP "},\"samples\":3.5}", 422,
             "/samples");
}

/* ---------------------------------------------------------- reconstruct */

#define SIG_HEAD "{\"signature\":{\"length\":6.283185307179586,"
#define KAPPA_OK                                                               \
  "\"kappa\":{\"degree\":1,\"knots\":[0,0,6.283185307179586,"                  \
  "6.283185307179586],\"coefficients\":[1,1]}"

static void signature_errors_are_named(void **state) {
  (void)state;
  at_problem(REC, "{}", 422, "/signature");
  at_problem(REC, "{\"signature\":7}", 422, "/signature");
  at_problem(REC, SIG_HEAD "\"closed\":true}}", 422, "/signature/kappa");
  at_problem(REC, "{\"signature\":{" KAPPA_OK "}}", 422, "/signature/length");
  at_problem(REC, "{\"signature\":{\"length\":0," KAPPA_OK "}}", 422,
             "/signature/length");
  at_problem(REC,
             SIG_HEAD "\"kappa\":{\"degree\":1,\"knots\":[0,0,1,2,3,3],"
                      "\"coefficients\":[1,1,1e999,1]}}}",
             422, "/signature/kappa/coefficients/2");
  at_problem(REC,
             SIG_HEAD "\"kappa\":{\"degree\":1,\"knots\":[0,0,2,1,3,3],"
                      "\"coefficients\":[1,1,1,1]}}}",
             422, "/signature/kappa/knots/3");
  at_problem(REC,
             SIG_HEAD "\"kappa\":{\"degree\":1,\"knots\":[0,0,3,3],"
                      "\"coefficients\":[1,1,1]}}}",
             422, "/signature/kappa/knots");
  at_problem(REC,
             SIG_HEAD "\"start\":{\"point\":[0],\"angle\":0}," KAPPA_OK "}}",
             422, "/signature/start/point");
  at_problem(REC,
             SIG_HEAD "\"start\":{\"point\":[0,0],\"angle\":\"x\"}," KAPPA_OK
                      "}}",
             422, "/signature/start/angle");
  at_problem(REC,
             SIG_HEAD KAPPA_OK ",\"corners\":[{\"s\":1,\"turn\":0.5},"
                               "{\"s\":2}]}}",
             422, "/signature/corners/1/turn");
}

static void reconstruct_degree_must_be_3_or_5(void **state) {
  (void)state;
  at_problem(REC, SIG_HEAD KAPPA_OK "},\"degree\":4}", 422, "/degree");
  at_problem(REC, SIG_HEAD KAPPA_OK "},\"degree\":2}", 422, "/degree");
  at_problem(REC, SIG_HEAD KAPPA_OK "},\"degree\":\"3\"}", 422, "/degree");
  at_problem(REC, SIG_HEAD KAPPA_OK "},\"include\":[\"png\"]}", 422,
             "/include/0");
}

/* --------------------------------------------------------------- problems */

static void problem_bodies_follow_rfc9457(void **state) {
  (void)state;
  api_response res;
  api_problem(&res, 429, NULL, NULL, "queue full", NULL, NULL, "req-42");
  assert_int_equal(res.status, 429);
  assert_string_equal(res.content_type, "application/problem+json");
  cJSON *j = cJSON_Parse(res.body);
  assert_non_null(j);
  assert_string_equal(cJSON_GetObjectItem(j, "type")->valuestring,
                      "/problems/too-many-requests");
  assert_int_equal(cJSON_GetObjectItem(j, "status")->valueint, 429);
  assert_string_equal(cJSON_GetObjectItem(j, "detail")->valuestring,
                      "queue full");
  assert_string_equal(cJSON_GetObjectItem(j, "request_id")->valuestring,
                      "req-42");
  assert_null(cJSON_GetObjectItem(j, "errors"));
  cJSON_Delete(j);
  api_response_free(&res);

  /* A pointer makes an errors[] entry; a request id with control bytes is
   * not echoed. */
  api_problem(&res, 422, "/problems/x", "X", "d", "/a/0", "m", "bad\nid");
  j = cJSON_Parse(res.body);
  assert_non_null(j);
  const cJSON *e0 = cJSON_GetArrayItem(cJSON_GetObjectItem(j, "errors"), 0);
  assert_string_equal(cJSON_GetObjectItem(e0, "pointer")->valuestring, "/a/0");
  assert_string_equal(cJSON_GetObjectItem(e0, "message")->valuestring, "m");
  assert_null(cJSON_GetObjectItem(j, "request_id"));
  cJSON_Delete(j);
  api_response_free(&res);
}

static void request_id_is_echoed_in_problems(void **state) {
  (void)state;
  cJSON *j = at_expect_problem(SIG, "{", 400, NULL);
  assert_string_equal(cJSON_GetObjectItem(j, "request_id")->valuestring,
                      "test-1");
  cJSON_Delete(j);
}

static const struct CMUnitTest tests[] = {
    cmocka_unit_test(malformed_json_is_400),
    cmocka_unit_test(invalid_utf8_is_400),
    cmocka_unit_test(string_escapes_are_decoded),
    cmocka_unit_test(body_without_nul_is_read_to_its_length),
    cmocka_unit_test(nesting_deeper_than_the_limit_is_400),
    cmocka_unit_test(overlong_array_is_refused_before_parsing),
    cmocka_unit_test(non_object_body_is_422_at_root),
    cmocka_unit_test(body_over_the_limit_is_413),
    cmocka_unit_test(unknown_route_is_404),
    cmocka_unit_test(missing_and_mistyped_fields_name_the_field),
    cmocka_unit_test(non_finite_numbers_are_422),
    cmocka_unit_test(bad_svg_path_names_d_and_the_offset),
    cmocka_unit_test(decreasing_knot_is_named),
    cmocka_unit_test(wrong_knot_count_is_named),
    cmocka_unit_test(degree_out_of_range_is_named),
    cmocka_unit_test(non_positive_weight_is_named),
    cmocka_unit_test(closed_curve_that_does_not_close_is_named),
    cmocka_unit_test(cusp_is_422_invalid_curve),
    cmocka_unit_test(control_points_above_the_limit_are_422),
    cmocka_unit_test(answers_and_turns_above_the_limits_are_422),
    cmocka_unit_test(bad_tolerance_and_samples_are_named),
    cmocka_unit_test(signature_errors_are_named),
    cmocka_unit_test(reconstruct_degree_must_be_3_or_5),
    cmocka_unit_test(problem_bodies_follow_rfc9457),
    cmocka_unit_test(request_id_is_echoed_in_problems),
};

TM_SUITE("api_errors", tests, NULL, NULL);
