/* test_api_morph.c - POST /v1/morph and the prepared plans behind jobs:
 * request validation (each bad option named by its pointer, before any
 * geometry), and morphs whose frames are known in closed form (a circle
 * into a circle stays a circle under the turning blend).
 */
#include "api_testutil.h"
#include "testmain.h"

#define MORPH API_ROUTE_MORPH

/* Two open curves; validation tests add one bad option to them. */
#define FROM                                                                   \
  "\"from\":{\"type\":\"bspline\",\"degree\":1,\"knots\":[0,0,1,1],"           \
  "\"control_points\":[[0,0],[1,0]]}"
#define TO                                                                     \
  "\"to\":{\"type\":\"bspline\",\"degree\":1,\"knots\":[0,0,1,1],"             \
  "\"control_points\":[[0,0],[0,2]]}"
#define BOTH "{" FROM "," TO

static void frame_counts_are_validated(void **state) {
  (void)state;
  cJSON *j = at_expect_problem(MORPH, BOTH ",\"frames\":1001}", 422, "/frames");
  assert_string_equal(cJSON_GetObjectItem(j, "type")->valuestring,
                      "/problems/limit-exceeded");
  cJSON_Delete(j);
  at_problem(MORPH, BOTH ",\"frames\":1}", 422, "/frames");
  at_problem(MORPH, BOTH ",\"frames\":-5}", 422, "/frames");
  at_problem(MORPH, BOTH ",\"frames\":2.5}", 422, "/frames");
  at_problem(MORPH, BOTH ",\"frames\":\"11\"}", 422, "/frames");
  at_problem(MORPH, BOTH ",\"frames\":1e999}", 422, "/frames");
  at_problem(MORPH, BOTH ",\"times\":[0,1.5]}", 422, "/times/1");
  at_problem(MORPH, BOTH ",\"times\":[-0.1]}", 422, "/times/0");
  at_problem(MORPH, BOTH ",\"times\":[\"0\"]}", 422, "/times/0");
  at_problem(MORPH, BOTH ",\"times\":[]}", 422, "/times");
  at_problem(MORPH, BOTH ",\"times\":0.5}", 422, "/times");
  at_problem(MORPH, BOTH ",\"times\":[0,1],\"frames\":2}", 422, "/times");
}

static void job_frame_limit_is_the_callers(void **state) {
  (void)state;
  api_config cfg;
  api_request req;
  api_response err;
  api_morph_plan *plan = NULL;
  const char *body = BOTH ",\"frames\":6}";
  api_config_default(&cfg);
  memset(&req, 0, sizeof req);
  req.route = MORPH;
  req.body = body;
  req.length = strlen(body);
  assert_int_equal(api_morph_prepare(&cfg, &req, 5, &plan, &err), 422);
  assert_null(plan);
  assert_non_null(strstr(err.body, "\"/frames\""));
  api_response_free(&err);
}

static void unknown_enum_values_are_named(void **state) {
  (void)state;
  at_problem(MORPH, BOTH ",\"method\":\"spline\"}", 422, "/method");
  at_problem(MORPH, BOTH ",\"blend\":3}", 422, "/blend");
  at_problem(MORPH, BOTH ",\"closure\":\"c3\"}", 422, "/closure");
  at_problem(MORPH, BOTH ",\"anchor\":\"middle\"}", 422, "/anchor");
  at_problem(MORPH, BOTH ",\"orient\":\"flip\"}", 422, "/orient");
  at_problem(MORPH, BOTH ",\"format\":\"png\"}", 422, "/format");
  at_problem(MORPH, BOTH ",\"degree\":4}", 422, "/degree");
  at_problem(MORPH, BOTH ",\"metrics\":\"yes\"}", 422, "/metrics");
  at_problem(MORPH, BOTH ",\"include\":[\"svg_d\",\"png\"]}", 422,
             "/include/1");
  at_problem(MORPH, BOTH ",\"include\":\"svg_d\"}", 422, "/include");
  at_problem(MORPH, BOTH ",\"tolerance\":-1}", 422, "/tolerance");
}

static void matches_are_validated(void **state) {
  (void)state;
  at_problem(MORPH, BOTH ",\"matches\":\"nope\"}", 422, "/matches");
  at_problem(MORPH, BOTH ",\"matches\":{}}", 422, "/matches");
  at_problem(MORPH, BOTH ",\"matches\":[[0.5]]}", 422, "/matches/0");
  at_problem(MORPH, BOTH ",\"matches\":[[0,0.5]]}", 422, "/matches/0/0");
  at_problem(MORPH, BOTH ",\"matches\":[[0.5,1]]}", 422, "/matches/0/1");
  at_problem(MORPH, BOTH ",\"matches\":[[0.2,0.3],[0.1,0.5]]}", 422,
             "/matches/1/0");
  at_problem(MORPH, BOTH ",\"matches\":[[0.2,0.3],[0.4,0.3]]}", 422,
             "/matches/1/1");
}

static void svg_options_are_validated(void **state) {
  (void)state;
  at_problem(MORPH, BOTH ",\"svg\":[]}", 422, "/svg");
  at_problem(MORPH, BOTH ",\"svg\":{\"layout\":\"grid\"}}", 422, "/svg/layout");
  at_problem(MORPH, BOTH ",\"svg\":{\"width\":-1}}", 422, "/svg/width");
  at_problem(MORPH, BOTH ",\"svg\":{\"duration\":0}}", 422, "/svg/duration");
  /* Colours are copied into markup: nothing that could close an attribute
   * or open an element gets through. */
  at_problem(MORPH,
             BOTH ",\"svg\":{\"stroke\":\"red\\\"/><script>x</script>\"}}", 422,
             "/svg/stroke");
  at_problem(MORPH, BOTH ",\"svg\":{\"from_color\":\"\"}}", 422,
             "/svg/from_color");
}

static void curves_are_validated_under_their_side(void **state) {
  (void)state;
  at_problem(MORPH, "{" TO "}", 422, "/from");
  at_problem(MORPH, "{" FROM "}", 422, "/to");
  at_problem(MORPH,
             "{" FROM ",\"to\":{\"type\":\"bspline\",\"degree\":1,"
             "\"knots\":[0,0,1,1],\"control_points\":[[null,0],[0,2]]}}",
             422, "/to/control_points/0/0");
  at_problem(MORPH,
             "{" TO ",\"from\":{\"type\":\"signature\",\"signature\":{"
             "\"length\":-1}}}",
             422, "/from/signature/length");
  /* A cusp in `to` is reported under /to. */
  cJSON *j =
      at_expect_problem(MORPH,
                        "{" FROM ",\"to\":{\"type\":\"bspline\",\"degree\":3,"
                        "\"knots\":[0,0,0,0,1,1,1,1],"
                        "\"control_points\":[[0,0],[2,2],[0,2],[2,0]]}}",
                        422, NULL);
  const cJSON *p = cJSON_GetObjectItem(
      cJSON_GetArrayItem(cJSON_GetObjectItem(j, "errors"), 0), "pointer");
  assert_true(strncmp(p->valuestring, "/to", 3) == 0);
  cJSON_Delete(j);
}

/* ------------------------------------------------------------- success */

static char *circles_request(double r0, double r1, const char *extra) {
  at_buf b = {0};
  at_printf(&b, "{\"from\":");
  at_circle_json(&b, 0, 0, r0, 1);
  at_printf(&b, ",\"to\":");
  at_circle_json(&b, 0, 0, r1, 1);
  at_printf(&b, "%s}", extra);
  return b.s;
}

static cJSON *morph_ok(const char *body) {
  return at_expect_json(MORPH, body);
}

static double metric(const cJSON *frame, const char *key) {
  const cJSON *v =
      cJSON_GetObjectItem(cJSON_GetObjectItem(frame, "metrics"), key);
  assert_true(cJSON_IsNumber(v));
  return v->valuedouble;
}

/* Largest deviation of a frame's curve from a circle of radius r about
 * the centroid of its sampled polyline. */
static double circle_deviation(const cJSON *frame, double r) {
  at_curve c;
  double cx = 0, cy = 0, len = 0, dev = 0, p[2], q[2];
  const int m = 2000;
  at_curve_from_json(cJSON_GetObjectItem(frame, "curve"), &c);
  double t0 = c.knots[c.degree], t1 = c.knots[c.n];
  /* the centroid of the polyline's chords, weighted by their lengths (the
   * parameter need not be arc length) */
  at_curve_point(&c, t0, q);
  for (int k = 1; k <= m; k++) {
    at_curve_point(&c, t0 + (t1 - t0) * k / m, p);
    double w = hypot(p[0] - q[0], p[1] - q[1]);
    cx += w * 0.5 * (p[0] + q[0]);
    cy += w * 0.5 * (p[1] + q[1]);
    len += w;
    q[0] = p[0];
    q[1] = p[1];
  }
  cx /= len;
  cy /= len;
  for (int k = 0; k <= m; k++) {
    at_curve_point(&c, t0 + (t1 - t0) * k / m, p);
    dev = fmax(dev, fabs(hypot(p[0] - cx, p[1] - cy) - r));
  }
  at_curve_free(&c);
  return dev;
}

static void circle_to_circle_stays_a_circle(void **state) {
  (void)state;
  /* Turning blend: kappa_t = ((1-t) L_a kappa_a + t L_b kappa_b) / L_t, so
   * frame t is the circle of radius (1-t) r0 + t r1. */
  char *body = circles_request(1.0, 2.0, ",\"frames\":3,\"tolerance\":1e-6");
  cJSON *j = morph_ok(body);
  assert_string_equal(cJSON_GetObjectItem(j, "method")->valuestring,
                      "curvature");
  const cJSON *frames = cJSON_GetObjectItem(j, "frames");
  assert_int_equal(cJSON_GetArraySize(frames), 3);
  for (int i = 0; i < 3; i++) {
    const cJSON *f = cJSON_GetArrayItem(frames, i);
    double t = 0.5 * i, r = 1.0 + t;
    assert_close(cJSON_GetObjectItem(f, "t")->valuedouble, t, 0);
    assert_rel(metric(f, "length"), 2 * M_PI * r, 1e-6);
    assert_rel(metric(f, "max_abs_kappa"), 1 / r, 1e-6);
    assert_rel(metric(f, "bending_energy"), 2 * M_PI / r, 1e-6);
    assert_close(metric(f, "self_intersections"), 0, 0);
    assert_le(metric(f, "closure_gap"), 1e-6);
    assert_le(circle_deviation(f, r), 1e-5);
    assert_true(cJSON_IsTrue(
        cJSON_GetObjectItem(cJSON_GetObjectItem(f, "curve"), "closed")));
  }
  assert_true(cJSON_IsArray(cJSON_GetObjectItem(j, "matches_used")));
  cJSON_Delete(j);
  free(body);
}

static void times_choose_the_frames(void **state) {
  (void)state;
  char *body = circles_request(1.0, 3.0, ",\"times\":[0.25],\"metrics\":true");
  cJSON *j = morph_ok(body);
  const cJSON *frames = cJSON_GetObjectItem(j, "frames");
  assert_int_equal(cJSON_GetArraySize(frames), 1);
  const cJSON *f = cJSON_GetArrayItem(frames, 0);
  assert_close(cJSON_GetObjectItem(f, "t")->valuedouble, 0.25, 0);
  assert_rel(metric(f, "length"), 2 * M_PI * 1.5, 1e-6);
  cJSON_Delete(j);
  free(body);
}

static void metrics_false_omits_metrics(void **state) {
  (void)state;
  char *body = circles_request(1.0, 2.0, ",\"frames\":2,\"metrics\":false");
  cJSON *j = morph_ok(body);
  const cJSON *f;
  cJSON_ArrayForEach(f, cJSON_GetObjectItem(j, "frames")) {
    assert_null(cJSON_GetObjectItem(f, "metrics"));
    assert_non_null(cJSON_GetObjectItem(f, "curve"));
  }
  cJSON_Delete(j);
  free(body);
}

static void linear_method_starts_and_ends_at_the_inputs(void **state) {
  (void)state;
  char *body = circles_request(1.0, 2.0, ",\"frames\":5,\"method\":\"linear\"");
  cJSON *j = morph_ok(body);
  assert_string_equal(cJSON_GetObjectItem(j, "method")->valuestring, "linear");
  const cJSON *frames = cJSON_GetObjectItem(j, "frames");
  assert_int_equal(cJSON_GetArraySize(frames), 5);
  /* Two concentric circles with the same parameterisation: every
   * control point of frame t is (1 + t) times that of frame 0, and the
   * weights are those of frame 0. */
  const cJSON *c0 = cJSON_GetObjectItem(cJSON_GetArrayItem(frames, 0), "curve");
  for (int i = 1; i < 5; i++) {
    const cJSON *ci =
        cJSON_GetObjectItem(cJSON_GetArrayItem(frames, i), "curve");
    double scale = 1.0 + 0.25 * i;
    const cJSON *p0 = cJSON_GetObjectItem(c0, "control_points");
    const cJSON *pi = cJSON_GetObjectItem(ci, "control_points");
    assert_int_equal(cJSON_GetArraySize(p0), cJSON_GetArraySize(pi));
    for (int k = 0; k < cJSON_GetArraySize(p0); k++)
      for (int d = 0; d < 2; d++)
        assert_close(
            cJSON_GetArrayItem(cJSON_GetArrayItem(pi, k), d)->valuedouble,
            scale *
                cJSON_GetArrayItem(cJSON_GetArrayItem(p0, k), d)->valuedouble,
            1e-12);
    size_t n0, ni;
    double *w0 = at_numbers(cJSON_GetObjectItem(c0, "weights"), &n0);
    double *wi = at_numbers(cJSON_GetObjectItem(ci, "weights"), &ni);
    assert_int_equal(n0, ni);
    for (size_t k = 0; k < n0; k++) assert_close(wi[k], w0[k], 1e-15);
    free(w0);
    free(wi);
  }
  cJSON_Delete(j);
  free(body);
}

static size_t commands(const char *d) {
  size_t n = 0;
  for (; *d; d++)
    n += (*d >= 'A' && *d <= 'Z') || (*d >= 'a' && *d <= 'z' && *d != 'e');
  return n;
}

/* numbers in a path (coordinates), whatever the separators */
static size_t numbers(const char *d) {
  size_t n = 0;
  while (*d) {
    char *end;
    strtod(d, &end);
    if (end != d && ((*d >= '0' && *d <= '9') || *d == '-' || *d == '.')) {
      n++;
      d = end;
    } else {
      d++;
    }
  }
  return n;
}

static void animate_d_paths_share_one_structure(void **state) {
  (void)state;
  char *body = circles_request(
      1.0, 2.0, ",\"frames\":4,\"include\":[\"svg_d\",\"animate_d\"]");
  cJSON *j = morph_ok(body);
  const cJSON *a = cJSON_GetObjectItem(j, "animate_d");
  assert_int_equal(cJSON_GetArraySize(a), 4);
  size_t n0 = commands(cJSON_GetArrayItem(a, 0)->valuestring);
  const cJSON *d;
  cJSON_ArrayForEach(d, a) {
    assert_true(cJSON_IsString(d));
    assert_int_equal(commands(d->valuestring), n0);
  }
  const cJSON *f;
  cJSON_ArrayForEach(f, cJSON_GetObjectItem(j, "frames")) {
    const cJSON *sd =
        cJSON_GetObjectItem(cJSON_GetObjectItem(f, "curve"), "svg_d");
    assert_true(cJSON_IsString(sd) && sd->valuestring[0] == 'M');
    /* a circle needs more than one cubic to stay within the tolerance:
     * the common piece count is at least what each frame's own path has */
    assert_true(numbers(cJSON_GetArrayItem(a, 0)->valuestring) >=
                numbers(sd->valuestring));
  }
  assert_true(numbers(cJSON_GetArrayItem(a, 0)->valuestring) >= 2 + 6 * 4);
  cJSON_Delete(j);
  free(body);
}

static void svg_is_returned_when_asked(void **state) {
  (void)state;
  char *body =
      circles_request(1.0, 2.0,
                      ",\"frames\":3,\"format\":\"svg\",\"svg\":{\"layout\":"
                      "\"overlay\",\"stroke\":\"#336699\"}");
  api_response res;
  assert_int_equal(at_call(MORPH, body, &res, NULL), 200);
  assert_string_equal(res.content_type, "image/svg+xml");
  assert_non_null(strstr(res.body, "<svg"));
  assert_non_null(strstr(res.body, "</svg>"));
  api_response_free(&res);
  free(body);

  /* The same through the Accept header. */
  api_config cfg;
  api_request req;
  body = circles_request(1.0, 2.0, ",\"frames\":2");
  api_config_default(&cfg);
  memset(&req, 0, sizeof req);
  req.route = MORPH;
  req.body = body;
  req.length = strlen(body);
  req.accept = "application/json;q=0.5, image/svg+xml";
  assert_int_equal(api_handle(&cfg, &req, &res), 200);
  assert_string_equal(res.content_type, "image/svg+xml");
  api_response_free(&res);
  /* ...and JSON when JSON is preferred. */
  req.accept = "image/svg+xml;q=0.1, */*";
  assert_int_equal(api_handle(&cfg, &req, &res), 200);
  assert_string_equal(res.content_type, "application/json");
  api_response_free(&res);
  free(body);
}

static void prepared_plan_renders_the_same_result(void **state) {
  (void)state;
  /* Frames rendered one by one, out of order, give the very bytes of the
   * synchronous answer. */
  char *body = circles_request(1.0, 2.0, ",\"frames\":6");
  api_config cfg;
  api_request req;
  api_response sync, err, job;
  api_morph_plan *plan = NULL;
  api_config_default(&cfg);
  memset(&req, 0, sizeof req);
  req.route = MORPH;
  req.body = body;
  req.length = strlen(body);
  assert_int_equal(api_handle(&cfg, &req, &sync), 200);
  assert_int_equal(
      api_morph_prepare(&cfg, &req, cfg.max_frames_job, &plan, &err), 0);
  assert_non_null(plan);
  assert_int_equal(api_morph_frame_count(plan), 6);
  for (size_t i = 6; i-- > 0;)
    assert_int_equal(api_morph_render_frame(plan, i), 0);
  assert_int_equal(api_morph_result(plan, &job), 200);
  assert_int_equal(job.length, sync.length);
  assert_memory_equal(job.body, sync.body, sync.length);
  api_morph_plan_free(plan);
  api_response_free(&sync);
  api_response_free(&job);
  free(body);
}

/* A limit the caller finds while rendering (the daemon's compute time) is
 * named by the member that chose the frames. */
static void plan_names_the_member_that_chose_the_frames(void **state) {
  (void)state;
  static const char *const bodies[][2] = {
      {BOTH ",\"frames\":3}", "/frames"},
      {BOTH "}", "/frames"},
      {BOTH ",\"times\":[0,0.5]}", "/times"}};
  api_config cfg;
  api_config_default(&cfg);
  for (size_t k = 0; k < sizeof bodies / sizeof bodies[0]; k++) {
    api_request req;
    api_morph_plan *plan = NULL;
    api_response err;
    api_response_init(&err);
    memset(&req, 0, sizeof req);
    req.route = MORPH;
    req.body = bodies[k][0];
    req.length = strlen(bodies[k][0]);
    assert_int_equal(
        api_morph_prepare(&cfg, &req, cfg.max_frames_sync, &plan, &err), 0);
    assert_string_equal(api_morph_frames_pointer(plan), bodies[k][1]);
    api_morph_plan_free(plan);
    api_response_free(&err);
  }
}

static void open_into_closed_is_not_morphable(void **state) {
  (void)state;
  at_buf b = {0};
  at_printf(&b, "{" FROM ",\"to\":");
  at_circle_json(&b, 0, 0, 1, 1);
  at_printf(&b, "}");
  cJSON *j = at_expect_problem(MORPH, b.s, 422, NULL);
  assert_string_equal(cJSON_GetObjectItem(j, "type")->valuestring,
                      "/problems/not-morphable");
  cJSON_Delete(j);
  free(b.s);
}

static void opposite_turning_kept_is_not_morphable(void **state) {
  (void)state;
  /* Counter-clockwise (turning number 1) into clockwise (-1) with the
   * orientation kept: the turning numbers differ. */
  at_buf b = {0};
  at_printf(&b, "{\"orient\":\"keep\",\"from\":");
  at_circle_json(&b, 0, 0, 1, 1);
  at_printf(&b, ",\"to\":");
  at_circle_json(&b, 0, 0, 1, 0);
  at_printf(&b, "}");
  cJSON *j = at_expect_problem(MORPH, b.s, 422, NULL);
  assert_string_equal(cJSON_GetObjectItem(j, "type")->valuestring,
                      "/problems/not-morphable");
  cJSON_Delete(j);
  free(b.s);
}

static const struct CMUnitTest tests[] = {
    cmocka_unit_test(frame_counts_are_validated),
    cmocka_unit_test(job_frame_limit_is_the_callers),
    cmocka_unit_test(unknown_enum_values_are_named),
    cmocka_unit_test(matches_are_validated),
    cmocka_unit_test(svg_options_are_validated),
    cmocka_unit_test(curves_are_validated_under_their_side),
    cmocka_unit_test(circle_to_circle_stays_a_circle),
    cmocka_unit_test(times_choose_the_frames),
    cmocka_unit_test(metrics_false_omits_metrics),
    cmocka_unit_test(linear_method_starts_and_ends_at_the_inputs),
    cmocka_unit_test(animate_d_paths_share_one_structure),
    cmocka_unit_test(svg_is_returned_when_asked),
    cmocka_unit_test(prepared_plan_renders_the_same_result),
    cmocka_unit_test(plan_names_the_member_that_chose_the_frames),
    cmocka_unit_test(open_into_closed_is_not_morphable),
    cmocka_unit_test(opposite_turning_kept_is_not_morphable),
};

TM_SUITE("api_morph", tests, NULL, NULL);
