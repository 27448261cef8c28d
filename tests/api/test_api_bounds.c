/* test_api_bounds.c - the contract layer's bounds on work and output: a
 * request's stop ends every route with 503 /problems/stopped, and the
 * predicted size of a morph's or reconstruction's answer is an upper
 * bound on the real one, checked against max_output_bytes before any
 * frame is rendered.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdlib.h>

#include <cmocka.h>

#include "api_testutil.h"
#include "testmain.h"

/* ---- stop conditions ---- */

static int call_with_stop(api_route route, const char *body, countdown *cd,
                          api_response *res) {
  api_config cfg;
  api_request req;
  api_config_default(&cfg);
  memset(&req, 0, sizeof req);
  req.route = route;
  req.body = body;
  req.length = strlen(body);
  req.stop = countdown_stop;
  req.stop_ctx = cd;
  api_response_init(res);
  return api_handle(&cfg, &req, res);
}

/* The answer must be exactly the stopped problem of the contract. */
static void expect_stopped(const api_response *res) {
  assert_int_equal(res->status, 503);
  assert_string_equal(res->content_type, "application/problem+json");
  cJSON *j = cJSON_ParseWithLength(res->body, res->length);
  assert_non_null(j);
  assert_string_equal(cJSON_GetObjectItem(j, "type")->valuestring,
                      "/problems/stopped");
  assert_string_equal(cJSON_GetObjectItem(j, "title")->valuestring, "Stopped");
  assert_string_equal(cJSON_GetObjectItem(j, "detail")->valuestring,
                      "the computation was stopped before it finished");
  assert_int_equal(cJSON_GetObjectItem(j, "status")->valueint, 503);
  cJSON_Delete(j);
}

/* A curve with enough work to poll many times: a closed cubic B-spline
 * of n control points on a wavy circle. */
static char *wavy_curve_json(size_t n, int waves, double amp) {
  size_t cap = 64 * n + 256, len = 0;
  char *s = malloc(cap);
  assert_non_null(s);
  len += (size_t)snprintf(s + len, cap - len,
                          "{\"type\":\"bspline\",\"degree\":3,\"closed\":true,"
                          "\"knots\":[0,0,0,0");
  for (size_t i = 1; i < n - 3; i++)
    len += (size_t)snprintf(s + len, cap - len, ",%zu", i);
  len += (size_t)snprintf(s + len, cap - len, ",%zu,%zu,%zu,%zu],", n - 3,
                          n - 3, n - 3, n - 3);
  len += (size_t)snprintf(s + len, cap - len, "\"control_points\":[");
  for (size_t i = 0; i < n; i++) {
    double a =
        2 * 3.14159265358979323846 * (double)(i % (n - 1)) / (double)(n - 1);
    double r = 1 + amp * sin(waves * a);
    len += (size_t)snprintf(s + len, cap - len, "%s[%.17g,%.17g]", i ? "," : "",
                            r * cos(a), r * sin(a));
  }
  snprintf(s + len, cap - len, "]}");
  return s;
}

static char *morph_body(size_t n, const char *extra) {
  char *a = wavy_curve_json(n, 7, 0.2), *b = wavy_curve_json(n, 5, 0.3);
  size_t cap = strlen(a) + strlen(b) + strlen(extra) + 64;
  char *s = malloc(cap);
  assert_non_null(s);
  snprintf(s, cap, "{\"from\":%s,\"to\":%s%s}", a, b, extra);
  free(a);
  free(b);
  return s;
}

/* Given a stop that says stop at its k-th question, every route answers
 * 503 /problems/stopped, whatever k; and asks nothing more after it. */
static void stop_gives_503_stopped_on_every_route(void **state) {
  (void)state;
  char *curve = wavy_curve_json(200, 7, 0.2);
  char sigbody[1 << 16];
  snprintf(sigbody, sizeof sigbody, "{\"curve\":%s,\"tolerance\":1e-9}", curve);
  char *morph = morph_body(200, ",\"tolerance\":1e-8,\"frames\":4");
  /* a signature to reconstruct, from the signature route itself */
  api_response res;
  cJSON *j = NULL;
  assert_int_equal(at_call(API_ROUTE_SIGNATURE, sigbody, &res, &j), 200);
  char *sig = cJSON_PrintUnformatted(cJSON_GetObjectItem(j, "signature"));
  cJSON_Delete(j);
  api_response_free(&res);
  size_t rcap = strlen(sig) + 64;
  char *rec = malloc(rcap);
  snprintf(rec, rcap, "{\"signature\":%s,\"tolerance\":1e-10}", sig);
  struct {
    api_route route;
    const char *body;
  } cases[] = {{API_ROUTE_SIGNATURE, sigbody},
               {API_ROUTE_RECONSTRUCT, rec},
               {API_ROUTE_MORPH, morph}};
  for (size_t c = 0; c < 3; c++) {
    /* how many questions the whole request asks when never stopped */
    countdown never = {1L << 40, 0};
    assert_int_equal(
        call_with_stop(cases[c].route, cases[c].body, &never, &res), 200);
    api_response_free(&res);
    assert_true(never.asked >= 2);
    long ks[3] = {0, never.asked / 2, never.asked - 1};
    for (int k = 0; k < 3; k++) {
      countdown cd = {ks[k], 0};
      call_with_stop(cases[c].route, cases[c].body, &cd, &res);
      expect_stopped(&res);
      /* the first "stop" is the last question */
      assert_int_equal(cd.asked, ks[k] + 1);
      api_response_free(&res);
    }
  }
  free(rec);
  free(sig);
  free(morph);
  free(curve);
}

/* A prepared plan's frames rendered under a stop: 503, and the result
 * says stopped, not a frame failure. */
static void stopped_frame_makes_the_result_stopped(void **state) {
  (void)state;
  char *morph = morph_body(200, ",\"tolerance\":1e-8,\"frames\":3");
  api_request req;
  api_response err, out;
  api_morph_plan *plan = NULL;
  memset(&req, 0, sizeof req);
  req.route = API_ROUTE_MORPH;
  req.body = morph;
  req.length = strlen(morph);
  assert_int_equal(api_morph_prepare(NULL, &req, 10, &plan, &err), 0);
  countdown cd = {0, 0};
  assert_int_equal(api_morph_render_frame_until(plan, 1, countdown_stop, &cd),
                   503);
  assert_int_equal(cd.asked, 1);
  api_morph_result(plan, &out);
  expect_stopped(&out);
  api_response_free(&out);
  /* rendered again without a stop, the same plan answers */
  assert_int_equal(api_morph_render_frame_until(plan, 1, NULL, NULL), 0);
  assert_int_equal(api_morph_result(plan, &out), 200);
  api_response_free(&out);
  api_morph_plan_free(plan);
  free(morph);
}

/* ---- predicted output size ---- */

static const char circle_square[] =
    "{\"from\":{\"type\":\"svg\",\"d\":\"M 20 100 A 80 80 0 1 1 180 100 A 80 "
    "80 0 1 1 20 100 Z\"},\"to\":{\"type\":\"svg\",\"d\":\"M 20 20 L 180 20 "
    "L 180 180 L 20 180 Z\"},\"tolerance\":1e-9,\"frames\":1000%s}";

/* A small request that asks for a huge answer (1,000 frames of a
 * circle-to-square morph at 1e-9) is refused before work with 422
 * limit-exceeded naming /frames or /tolerance, the message giving the
 * predicted size and the limit of 64 MiB. */
static void huge_answer_is_refused_before_work(void **state) {
  (void)state;
  const char *extras[] = {"", ",\"include\":[\"svg_d\"]", ",\"metrics\":false"};
  for (size_t k = 0; k < 3; k++) {
    char body[1024];
    snprintf(body, sizeof body, circle_square, extras[k]);
    assert_true(strlen(body) < 400);
    cJSON *j = at_expect_problem_cfg(NULL, API_ROUTE_MORPH, body, 422, NULL);
    assert_string_equal(cJSON_GetObjectItem(j, "type")->valuestring,
                        "/problems/limit-exceeded");
    const cJSON *e = cJSON_GetArrayItem(cJSON_GetObjectItem(j, "errors"), 0);
    const char *p = cJSON_GetObjectItem(e, "pointer")->valuestring;
    assert_true(strcmp(p, "/frames") == 0 || strcmp(p, "/tolerance") == 0);
    const char *msg = cJSON_GetObjectItem(e, "message")->valuestring;
    assert_non_null(strstr(msg, "67108864"));
    cJSON_Delete(j);
  }
}

/* The prediction is >= the length of the real answer, and within 2.5x of
 * it, for varied requests (JSON and SVG, metrics on and off, svg_d,
 * animate_d, matches, degree 5, linear). */
static void prediction_bounds_the_real_answer(void **state) {
  (void)state;
  const char *extras[] = {
      ",\"frames\":11",
      ",\"frames\":11,\"metrics\":false",
      ",\"frames\":7,\"include\":[\"svg_d\",\"animate_d\"]",
      ",\"frames\":7,\"tolerance\":1e-9",
      ",\"frames\":5,\"degree\":5",
      ",\"frames\":5,\"matches\":[[0.3,0.4]]",
      ",\"frames\":5,\"matches\":\"auto\",\"tolerance\":1e-7",
      ",\"frames\":5,\"method\":\"linear\"",
      ",\"frames\":9,\"format\":\"svg\"",
      ",\"frames\":9,\"format\":\"svg\",\"svg\":{\"layout\":\"overlay\"}",
      ",\"frames\":9,\"format\":\"svg\",\"svg\":{\"layout\":\"animate\"}",
      (",\"frames\":4,\"format\":\"svg\",\"svg\":{\"layout\":"
       "\"curvature_plot\"}"),
  };
  for (size_t k = 0; k < sizeof extras / sizeof extras[0]; k++) {
    char *body = morph_body(40, extras[k]);
    api_request req;
    api_response err, out;
    api_morph_plan *plan = NULL;
    memset(&req, 0, sizeof req);
    req.route = API_ROUTE_MORPH;
    req.body = body;
    req.length = strlen(body);
    int st = api_morph_prepare(NULL, &req, 100, &plan, &err);
    if (st != 0) print_error("%s: %s\n", extras[k], err.body);
    assert_int_equal(st, 0);
    size_t predicted = api_morph_predicted_bytes(plan);
    assert_int_equal(api_morph_result(plan, &out), 200);
    print_message("%-70s real %8zu predicted %8zu ratio %.2f\n", extras[k],
                  out.length, predicted, (double)predicted / out.length);
    assert_true(predicted >= out.length);
    assert_true(predicted <= 2.5 * out.length + 8192);
    api_response_free(&out);
    api_morph_plan_free(plan);
    free(body);
  }
}

/* The reconstruction's answer is held to max_output_bytes too: with a
 * limit below its size it is 422 naming /tolerance; with the default it
 * is 200. */
static void reconstruct_answer_is_held_to_the_limit(void **state) {
  (void)state;
  const char body[] =
      "{\"signature\":{\"length\":100,\"start\":{\"point\":[0,0],\"angle\":0},"
      "\"kappa\":{\"degree\":1,\"knots\":[0,0,100,100],\"coefficients\":[0,"
      "1]},\"corners\":[],\"closed\":false},\"tolerance\":1e-9}";
  api_config cfg;
  api_response res;
  api_config_default(&cfg);
  assert_int_equal(cfg.max_output_bytes, 64u * 1024u * 1024u);
  assert_int_equal(
      at_call_cfg(&cfg, API_ROUTE_RECONSTRUCT, body, strlen(body), &res, NULL),
      200);
  size_t real = res.length;
  api_response_free(&res);
  cfg.max_output_bytes = real / 2;
  cJSON *j = at_expect_problem_cfg(&cfg, API_ROUTE_RECONSTRUCT, body, 422,
                                   "/tolerance");
  assert_string_equal(cJSON_GetObjectItem(j, "type")->valuestring,
                      "/problems/limit-exceeded");
  cJSON_Delete(j);
}

static const struct CMUnitTest tests[] = {
    cmocka_unit_test(stop_gives_503_stopped_on_every_route),
    cmocka_unit_test(stopped_frame_makes_the_result_stopped),
    cmocka_unit_test(huge_answer_is_refused_before_work),
    cmocka_unit_test(prediction_bounds_the_real_answer),
    cmocka_unit_test(reconstruct_answer_is_held_to_the_limit),
};

TM_SUITE("api_bounds", tests, NULL, NULL);
