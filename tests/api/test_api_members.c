/* test_api_members.c - a member the contract does not define is a 422
 * naming it by its JSON pointer, in every object of every request (top
 * level, curves of each type, shape contours, signatures and their parts,
 * svg options), with a suggestion when the name is a near miss of a
 * known one; and every member the contract does define is still taken.
 */
#include "api_testutil.h"
#include "testmain.h"

#define SIG API_ROUTE_SIGNATURE
#define REC API_ROUTE_RECONSTRUCT
#define MOR API_ROUTE_MORPH

#define LINE_A "{\"type\":\"svg\",\"d\":\"M0 0 L1 0\"}"
#define LINE_B "{\"type\":\"svg\",\"d\":\"M0 0 L0 1\"}"
#define SQUARE "{\"type\":\"svg\",\"d\":\"M0 0 H1 V1 H0 Z\"}"
/* kappa = 1 over [0, 1]: an arc of a unit circle. */
#define ARC_SIG                                                                \
  "{\"length\":1,\"start\":{\"point\":[0,0],\"angle\":0},"                     \
  "\"kappa\":{\"degree\":0,\"knots\":[0,1],\"coefficients\":[1]}}"

/* The problem of body is a 422 at pointer whose message is exactly msg. */
static void expect_unknown(api_route route, const char *body,
                           const char *pointer, const char *msg) {
  cJSON *j = at_expect_problem(route, body, 422, pointer);
  const cJSON *e0 =
      cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(j, "errors"), 0);
  const cJSON *m = cJSON_GetObjectItemCaseSensitive(e0, "message");
  const cJSON *t = cJSON_GetObjectItemCaseSensitive(j, "type");
  const cJSON *d = cJSON_GetObjectItemCaseSensitive(j, "detail");
  char detail[512];
  assert_string_equal(m->valuestring, msg);
  assert_string_equal(t->valuestring, "/problems/invalid-request");
  snprintf(detail, sizeof detail, "%s: %s", pointer, msg);
  assert_string_equal(d->valuestring, detail);
  cJSON_Delete(j);
}

static void typo_at_the_top_level_is_named_with_a_suggestion(void **state) {
  (void)state;
  expect_unknown(
      MOR, "{\"from\":" LINE_A ",\"to\":" LINE_B ",\"blending\":\"paper\"}",
      "/blending", "unknown member; did you mean \"blend\"?");
  expect_unknown(MOR, "{\"from\":" LINE_A ",\"to\":" LINE_B ",\"frmaes\":3}",
                 "/frmaes", "unknown member; did you mean \"frames\"?");
  expect_unknown(SIG, "{\"curve\":" LINE_A ",\"tol\":0.1}", "/tol",
                 "unknown member; did you mean \"tolerance\"?");
  expect_unknown(REC, "{\"signature\":" ARC_SIG ",\"Degree\":5}", "/Degree",
                 "unknown member; did you mean \"degree\"?");
}

static void unrelated_name_is_named_without_a_suggestion(void **state) {
  (void)state;
  expect_unknown(MOR, "{\"from\":" LINE_A ",\"to\":" LINE_B ",\"zzz\":1}",
                 "/zzz", "unknown member");
  /* "include" is a member of morph and reconstruct, not of signature */
  expect_unknown(SIG, "{\"curve\":" LINE_A ",\"include\":[\"svg_d\"]}",
                 "/include", "unknown member");
}

static void unknown_member_is_found_in_every_kind_of_curve(void **state) {
  (void)state;
  expect_unknown(SIG,
                 "{\"curve\":{\"type\":\"svg\",\"d\":\"M0 0L1 0\",\"z\":1}}",
                 "/curve/z", "unknown member");
  expect_unknown(SIG,
                 "{\"curve\":{\"type\":\"points\",\"points\":[[0,0],[1,0]],"
                 "\"close\":true}}",
                 "/curve/close", "unknown member; did you mean \"closed\"?");
  expect_unknown(SIG,
                 "{\"curve\":{\"type\":\"bspline\",\"degree\":1,"
                 "\"knots\":[0,0,1,1],\"control_points\":[[0,0],[1,0]],"
                 "\"weight\":[1,1]}}",
                 "/curve/weight", "unknown member; did you mean \"weights\"?");
  /* members of another type of curve are unknown in this one */
  expect_unknown(SIG,
                 "{\"curve\":{\"type\":\"svg\",\"d\":\"M0 0L1 0\","
                 "\"closed\":false}}",
                 "/curve/closed", "unknown member");
  expect_unknown(MOR,
                 "{\"from\":{\"type\":\"signature\",\"signature\":" ARC_SIG
                 ",\"signatur\":1},\"to\":" LINE_B "}",
                 "/from/signatur",
                 "unknown member; did you mean \"signature\"?");
}

static void unknown_member_is_found_in_shapes_and_contours(void **state) {
  (void)state;
  expect_unknown(MOR,
                 "{\"from\":{\"type\":\"shape\",\"contours\":[" SQUARE
                 "],\"fillrule\":\"evenodd\"},\"to\":" SQUARE "}",
                 "/from/fillrule",
                 "unknown member; did you mean \"fill_rule\"?");
  expect_unknown(MOR,
                 "{\"from\":" SQUARE ",\"to\":{\"type\":\"shape\",\"contours\":"
                 "[" SQUARE ",{\"type\":\"svg\",\"d\":\"M3 3 H4 V4 H3 Z\","
                 "\"dd\":1}]}}",
                 "/to/contours/1/dd", "unknown member; did you mean \"d\"?");
}

static void unknown_member_is_found_in_signatures(void **state) {
  (void)state;
  expect_unknown(REC,
                 "{\"signature\":{\"length\":1,\"lenght\":1,\"kappa\":"
                 "{\"degree\":0,\"knots\":[0,1],\"coefficients\":[1]}}}",
                 "/signature/lenght",
                 "unknown member; did you mean \"length\"?");
  expect_unknown(REC,
                 "{\"signature\":{\"length\":1,\"start\":{\"point\":[0,0],"
                 "\"angel\":0},\"kappa\":{\"degree\":0,\"knots\":[0,1],"
                 "\"coefficients\":[1]}}}",
                 "/signature/start/angel",
                 "unknown member; did you mean \"angle\"?");
  expect_unknown(REC,
                 "{\"signature\":{\"length\":1,\"kappa\":{\"degree\":0,"
                 "\"knots\":[0,1],\"coefficient\":[1]}}}",
                 "/signature/kappa/coefficient",
                 "unknown member; did you mean \"coefficients\"?");
  expect_unknown(REC,
                 "{\"signature\":{\"length\":2,\"kappa\":{\"degree\":0,"
                 "\"knots\":[0,2],\"coefficients\":[0]},\"corners\":"
                 "[{\"s\":1,\"turn\":1,\"trun\":1}]}}",
                 "/signature/corners/0/trun",
                 "unknown member; did you mean \"turn\"?");
}

static void unknown_svg_option_is_named(void **state) {
  (void)state;
  expect_unknown(MOR,
                 "{\"from\":" LINE_A ",\"to\":" LINE_B
                 ",\"format\":\"svg\",\"svg\":{\"stroke_with\":2}}",
                 "/svg/stroke_with",
                 "unknown member; did you mean \"stroke_width\"?");
}

/* RFC 6901: "~" is written "~0" and "/" "~1" in a reference token. */
static void pointer_escapes_slash_and_tilde(void **state) {
  (void)state;
  expect_unknown(MOR, "{\"from\":" LINE_A ",\"to\":" LINE_B ",\"a/b~c\":1}",
                 "/a~1b~0c", "unknown member");
}

static void the_unknown_member_is_reported_before_other_errors(void **state) {
  (void)state;
  /* frames is out of range too, but the typo is the root cause */
  expect_unknown(MOR,
                 "{\"from\":" LINE_A ",\"to\":" LINE_B
                 ",\"frames\":1,\"methd\":\"linear\"}",
                 "/methd", "unknown member; did you mean \"method\"?");
}

/* Every member the contract defines, at once, is taken. */
static void every_documented_member_is_accepted(void **state) {
  (void)state;
  cJSON *j = at_expect_json(
      MOR, "{\"from\":" SQUARE ",\"to\":" SQUARE
           ",\"frames\":3,\"method\":\"curvature\",\"blend\":\"turning\","
           "\"matches\":\"auto\",\"closure\":\"auto\",\"anchor\":\"fit\","
           "\"orient\":\"auto\",\"intersections\":\"allow\","
           "\"tolerance\":0.001,\"degree\":3,\"metrics\":true,"
           "\"precision\":\"exact\",\"include\":[\"svg_d\"],"
           "\"format\":\"json\",\"svg\":{\"layout\":\"overlay\","
           "\"width\":100,\"height\":100,\"stroke_width\":1,\"duration\":2,"
           "\"stroke\":\"black\",\"from_color\":\"red\","
           "\"to_color\":\"blue\"}}");
  cJSON_Delete(j);
  /* a signature as the signature route answers it, turning and closed
   * included, goes back into reconstruct */
  j = at_expect_json(REC, "{\"signature\":{\"length\":1,\"start\":{\"point\":"
                          "[0,0],\"angle\":0},\"kappa\":{\"degree\":0,"
                          "\"knots\":[0,1],\"coefficients\":[1]},"
                          "\"corners\":[],\"turning\":1,\"closed\":false},"
                          "\"tolerance\":0.001,\"degree\":5,"
                          "\"include\":[\"svg_d\"],\"precision\":\"exact\"}");
  cJSON_Delete(j);
  j = at_expect_json(SIG, "{\"curve\":{\"type\":\"bspline\",\"degree\":1,"
                          "\"knots\":[0,0,1,1],\"control_points\":[[0,0],"
                          "[1,0]],\"weights\":[1,1],\"closed\":false},"
                          "\"tolerance\":0.001,\"samples\":3}");
  cJSON_Delete(j);
}

static const struct CMUnitTest tests[] = {
    cmocka_unit_test(typo_at_the_top_level_is_named_with_a_suggestion),
    cmocka_unit_test(unrelated_name_is_named_without_a_suggestion),
    cmocka_unit_test(unknown_member_is_found_in_every_kind_of_curve),
    cmocka_unit_test(unknown_member_is_found_in_shapes_and_contours),
    cmocka_unit_test(unknown_member_is_found_in_signatures),
    cmocka_unit_test(unknown_svg_option_is_named),
    cmocka_unit_test(pointer_escapes_slash_and_tilde),
    cmocka_unit_test(the_unknown_member_is_reported_before_other_errors),
    cmocka_unit_test(every_documented_member_is_accepted),
};

TM_SUITE("api_members", tests, NULL, NULL);
