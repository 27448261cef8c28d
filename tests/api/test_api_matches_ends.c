/* test_api_matches_ends.c - POST /v1/morph with matches next to the ends
 * of the curves or next to each other: 200 with valid splines, never a
 * 422 that blames the client for a spline the morph built.
 *
 * Oracles: knot vectors are checked here (non-decreasing, clamped,
 * interior multiplicity <= degree); the frames at t = 0 and 1 are the
 * inputs where they stand (circles of radius 1 and 2 about the origin);
 * with proportional matches a circle into a circle under the turning
 * blend stays the circle of radius 1 + t about the origin (its tangent
 * angle is 2 pi r at every t, and the placement fits it onto the linear
 * blend of corresponding points, which lie on that circle).
 */
#include "api_testutil.h"
#include "testmain.h"

#define MORPH API_ROUTE_MORPH

#define CIRCLE1                                                                \
  "{\"type\":\"svg\",\"d\":\"M 1 0 A 1 1 0 1 1 -1 0 A 1 1 0 1 1 1 0 Z\"}"
#define CIRCLE2                                                                \
  "{\"type\":\"svg\",\"d\":\"M 2 0 A 2 2 0 1 1 -2 0 A 2 2 0 1 1 2 0 Z\"}"

/* The default tolerance: 1e-5 of the longer input (the circle of radius 2). */
#define TOL (1e-5 * 4 * M_PI)

static cJSON *morph_ok(const char *body) {
  api_response res;
  cJSON *j = NULL;
  int st = at_call(MORPH, body, &res, &j);
  if (st != 200) print_error("status %d: %s\n", st, res.body);
  assert_int_equal(st, 200);
  api_response_free(&res);
  return j;
}

/* Clamped, non-decreasing, interior multiplicity <= degree. */
static void assert_valid_knots(const at_curve *c) {
  size_t nk = c->n + (size_t)c->degree + 1, run = 1;
  for (size_t i = 1; i < nk; i++) assert_true(c->knots[i] >= c->knots[i - 1]);
  for (int i = 1; i <= c->degree; i++) {
    assert_true(c->knots[i] == c->knots[0]);
    assert_true(c->knots[nk - 1 - (size_t)i] == c->knots[nk - 1]);
  }
  for (size_t i = (size_t)c->degree + 1; i < c->n; i++) {
    run = c->knots[i] == c->knots[i - 1] ? run + 1 : 1;
    assert_true(run <= (size_t)c->degree);
  }
  assert_true(c->knots[c->n] > c->knots[c->degree]);
}

/* Largest | |p| - r | over 400 points of a frame's curve. */
static double off_circle(const cJSON *frame, double r) {
  at_curve c;
  double worst = 0.0, p[2];
  at_curve_from_json(cJSON_GetObjectItem(frame, "curve"), &c);
  assert_valid_knots(&c);
  double t0 = c.knots[c.degree], t1 = c.knots[c.n];
  for (int k = 0; k <= 400; k++) {
    at_curve_point(&c, t0 + (t1 - t0) * k / 400.0, p);
    worst = fmax(worst, fabs(hypot(p[0], p[1]) - r));
  }
  at_curve_free(&c);
  return worst;
}

static const cJSON *frame_at(const cJSON *j, int i) {
  const cJSON *f = cJSON_GetArrayItem(cJSON_GetObjectItem(j, "frames"), i);
  assert_non_null(f);
  return f;
}

/* The finding: (1e-300, 1 - 2^-53) maps almost nothing of one circle onto
 * almost all of the other. Before, the frame at t = 1 was answered 422
 * "interior knot ... multiplicity above degree + 1". */
static void a_match_from_the_start_to_the_end_answers_200(void **state) {
  (void)state;
  const char *body = "{\"from\":" CIRCLE1 ",\"to\":" CIRCLE2
                     ",\"frames\":5,\"matches\":[[1e-300,0.9999999999999999]]}";
  cJSON *j = morph_ok(body);
  assert_int_equal(cJSON_GetArraySize(cJSON_GetObjectItem(j, "frames")), 5);
  for (int i = 0; i < 5; i++) {
    double t = cJSON_GetObjectItem(frame_at(j, i), "t")->valuedouble;
    double off = off_circle(frame_at(j, i), 1.0 + t); /* checks the knots */
    if (i == 0 || i == 4) assert_le(off, 2 * TOL);
  }
  const cJSON *used =
      cJSON_GetArrayItem(cJSON_GetObjectItem(j, "matches_used"), 0);
  assert_close(cJSON_GetArrayItem(used, 0)->valuedouble, 1e-300, 0);
  assert_close(cJSON_GetArrayItem(used, 1)->valuedouble, 0.9999999999999999, 0);
  cJSON_Delete(j);
}

/* Proportional matches next to 0, next to 1, and two 2^-53 apart are the
 * identity correspondence; uneven ones next to an end ((1e-9, 1e-7), ...)
 * move it by less than the tolerance: every frame is the circle of radius
 * 1 + t, "times" at 0 and 1 included, degree 3 and 5. Before, (1e-9, 1e-7)
 * bent the correspondence over half the circle (4.7e-2 off). */
static void matches_next_to_the_ends_keep_the_circle(void **state) {
  (void)state;
  static const char *const matches[] = {
      "[[1e-300,1e-300]]",
      "[[0.9999999999999999,0.9999999999999999]]",
      "[[0.5,0.5],[0.5000000000000001,0.5000000000000001]]",
      "[[1e-300,1e-300],[0.9999999999999999,0.9999999999999999]]",
      "[[1e-9,1e-7]]",
      "[[1e-300,1e-17],[0.9999999999999999,0.9999999999999998]]",
  };
  static const double times[] = {0, 1e-300, 0.5, 0.9999999999999999, 1};
  for (int deg = 3; deg <= 5; deg += 2)
    for (size_t k = 0; k < sizeof matches / sizeof matches[0]; k++) {
      char body[512];
      snprintf(body, sizeof body,
               "{\"from\":" CIRCLE1 ",\"to\":" CIRCLE2
               ",\"degree\":%d,\"times\":[0,1e-300,0.5,0.9999999999999999,1],"
               "\"matches\":%s}",
               deg, matches[k]);
      cJSON *j = morph_ok(body);
      for (int i = 0; i < 5; i++)
        assert_le(off_circle(frame_at(j, i), 1.0 + times[i]), 2 * TOL);
      cJSON_Delete(j);
    }
}

/* Paper blend: a corner of a segment scales with the frame's length over
 * the input's, some 1e292 beside a match at 1e-300; the SVG circle's arc
 * joins (turns of 2e-8) on both sides of the seam became two half turns at
 * one place, and the frame was answered 422 naming /corners/2. */
static void paper_blend_beside_an_end_answers_200(void **state) {
  (void)state;
  const char *body =
      "{\"from\":{\"type\":\"svg\",\"d\":\"M 0.05 0 A 0.05 0.05 0 1 1 -0.05 0 "
      "A 0.05 0.05 0 1 1 0.05 0 Z\"},\"to\":{\"type\":\"svg\",\"d\":\"M 0.1 0 "
      "A 0.1 0.1 0 1 1 -0.1 0 A 0.1 0.1 0 1 1 0.1 0 Z\"},\"frames\":5,"
      "\"blend\":\"paper\",\"matches\":[[1e-300,0.5],[0.5,0.9999999999999999]]"
      "}";
  cJSON *j = morph_ok(body);
  for (int i = 0; i < 5; i++) {
    double off = off_circle(frame_at(j, i), i == 0 ? 0.05 : 0.1);
    if (i == 0 || i == 4) assert_le(off, 2e-5 * 2 * M_PI * 0.1);
  }
  cJSON_Delete(j);
}

static const struct CMUnitTest tests[] = {
    cmocka_unit_test(a_match_from_the_start_to_the_end_answers_200),
    cmocka_unit_test(matches_next_to_the_ends_keep_the_circle),
    cmocka_unit_test(paper_blend_beside_an_end_answers_200),
};

TM_SUITE("api_matches_ends", tests, NULL, NULL);
