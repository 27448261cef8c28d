/* test_api_oom.c - every route of the contract answers out of memory at
 * each allocation in turn, cJSON's included, with 503 and an
 * out-of-memory problem (api.h), never another status, a crash or a leak
 * (the hook counts the blocks; the ASan build checks again), and 200 once
 * none fails. The allocations are failed one at a time, then each with
 * every later one too, where even the problem cannot be built: then 503
 * with the fixed fallback body or none.
 */
#include <stdbool.h>
#include <stdio.h>
#include <string.h>

#include "kmapi/api.h"
#include "testmain.h"
#include "oomhook.h"

/* Runs per loop at most: more than any request here allocates. */
#define OOM_MAX_RUNS 20000

static const char circle[] =
    "{\"type\":\"bspline\",\"degree\":2,"
    "\"knots\":[0,0,0,0.25,0.25,0.5,0.5,0.75,0.75,1,1,1],"
    "\"control_points\":[[1,0],[1,1],[0,1],[-1,1],[-1,0],[-1,-1],[0,-1],"
    "[1,-1],[1,0]],"
    "\"weights\":[1,0.7071067811865476,1,0.7071067811865476,1,"
    "0.7071067811865476,1,0.7071067811865476,1],\"closed\":true}";
static const char diamond[] =
    "{\"type\":\"svg\",\"d\":\"M 1 0 L 0 1 L -1 0 L 0 -1 Z\"}";
static const char arch[] =
    "{\"type\":\"bspline\",\"degree\":3,\"knots\":[0,0,0,0,0.5,1,1,1,1],"
    "\"control_points\":[[0,0],[0.2,0.8],[0.5,1.1],[0.8,0.8],[1,0]]}";
static const char wave[] =
    "{\"type\":\"svg\",\"d\":\"M 0 0 C 0.3 0.5 0.5 0 0.5 0 S 0.7 -0.5 1 0\"}";

typedef struct api_case {
  api_route route;
  const char *body;
  const char *accept;
  bool prepared; /* api_morph_prepare, each frame, api_morph_result */
} api_case;

/* Whether body is the out-of-memory problem of api.h. */
static bool oom_problem(const char *body) {
  return body != NULL &&
         strstr(body, "\"type\":\"/problems/out-of-memory\"") != NULL &&
         strstr(body, "\"title\":\"Out of memory\"") != NULL &&
         strstr(body, "\"status\":503") != NULL;
}

/* What an answer means for the loop; why names any other. */
static oom_outcome outcome_of(const api_response *r, char *why) {
  bool problem = r->content_type != NULL &&
                 strcmp(r->content_type, "application/problem+json") == 0;
  if (r->status == 200) return OOM_RAN_OK;
  /* one failed allocation leaves memory for the problem; with every later
   * one failing too it may be the fallback (type, title and status of a
   * 503) or, without a byte to hold that, no body */
  if (r->status == 503 && problem &&
      (oom_problem(r->body) ||
       (oom.persist &&
        (r->body == NULL || strstr(r->body, "\"status\":503") != NULL))))
    return OOM_RAN_NOMEM;
  snprintf(why, 160, "%d %.120s", r->status, r->body ? r->body : "(none)");
  return OOM_RAN_OTHER;
}

/* api_morph_prepare, every frame, api_morph_result: the path of the
 * daemon's jobs. */
static oom_outcome run_prepared(const api_request *req, char *why) {
  api_morph_plan *plan = NULL;
  api_response out;
  oom_outcome got;
  api_status st = api_morph_prepare(NULL, req, 1000, &plan, &out);
  if (st != API_STEP_DONE) {
    got = outcome_of(&out, why);
    api_response_free(&out);
    return got;
  }
  for (size_t i = 0; i < api_morph_frame_count(plan); i++)
    if (api_morph_render_frame(plan, i) != API_STEP_DONE)
      break; /* api_morph_result reports it */
  api_morph_result(plan, &out);
  api_morph_plan_free(plan);
  got = outcome_of(&out, why);
  api_response_free(&out);
  return got;
}

static oom_outcome run_request(void *ctx, char *why) {
  const api_case *c = ctx;
  api_request req;
  api_response out;
  oom_outcome got;
  memset(&req, 0, sizeof req);
  req.route = c->route;
  req.body = c->body;
  req.length = strlen(c->body);
  req.accept = c->accept;
  req.request_id = "oom-1";
  if (c->prepared) return run_prepared(&req, why);
  api_handle(NULL, &req, &out);
  got = outcome_of(&out, why);
  api_response_free(&out);
  return got;
}

/* Both loops over one request: each allocation failing alone, then each
 * with every later one. */
static void both_loops(const char *name, api_route route, const char *accept,
                       bool prepared, const char *body) {
  api_case c = {route, body, accept, prepared};
  char label[96];
  oom_loop(name, run_request, &c, false, OOM_MAX_RUNS);
  snprintf(label, sizeof label, "%s, persistent", name);
  oom_loop(label, run_request, &c, true, OOM_MAX_RUNS);
}

static void signature_route_answers_503_when_out_of_memory(void **state) {
  char body[1024];
  (void)state;
  snprintf(body, sizeof body, "{\"curve\":%s,\"samples\":8}", circle);
  both_loops("POST /v1/signature", API_ROUTE_SIGNATURE, NULL, false, body);
}

static void reconstruct_route_answers_503_when_out_of_memory(void **state) {
  static const char body[] =
      "{\"signature\":{\"length\":5,\"start\":{\"point\":[0,0],\"angle\":0},"
      "\"kappa\":{\"degree\":1,\"knots\":[0,0,5,5],\"coefficients\":[0,5]},"
      "\"closed\":false},\"tolerance\":1e-4,\"include\":[\"svg_d\"]}";
  (void)state;
  both_loops("POST /v1/reconstruct", API_ROUTE_RECONSTRUCT, NULL, false, body);
}

static void morph_json_answers_503_when_out_of_memory(void **state) {
  char body[1024];
  (void)state;
  snprintf(body, sizeof body,
           "{\"from\":%s,\"to\":%s,\"frames\":3,\"metrics\":true,"
           "\"include\":[\"svg_d\"],\"tolerance\":1e-3}",
           circle, diamond);
  both_loops("POST /v1/morph closed", API_ROUTE_MORPH, NULL, false, body);
}

static void morph_open_matches_answers_503_when_out_of_memory(void **state) {
  char body[1024];
  (void)state;
  snprintf(body, sizeof body,
           "{\"from\":%s,\"to\":%s,\"frames\":3,\"metrics\":true,"
           "\"matches\":[[0.3,0.4]],\"tolerance\":1e-3}",
           arch, wave);
  both_loops("POST /v1/morph open matches", API_ROUTE_MORPH, NULL, false, body);
}

static void morph_linear_auto_answers_503_when_out_of_memory(void **state) {
  char body[1024];
  (void)state;
  snprintf(body, sizeof body,
           "{\"from\":%s,\"to\":%s,\"frames\":3,\"method\":\"linear\","
           "\"metrics\":true,\"tolerance\":1e-3}",
           circle, diamond);
  both_loops("POST /v1/morph linear", API_ROUTE_MORPH, NULL, false, body);
  snprintf(body, sizeof body,
           "{\"from\":%s,\"to\":%s,\"frames\":2,\"matches\":\"auto\","
           "\"tolerance\":1e-3}",
           circle, diamond);
  both_loops("POST /v1/morph auto matches", API_ROUTE_MORPH, NULL, false, body);
}

static void morph_svg_answers_503_when_out_of_memory(void **state) {
  char body[1024];
  (void)state;
  snprintf(body, sizeof body,
           "{\"from\":%s,\"to\":%s,\"frames\":3,\"tolerance\":1e-3}", circle,
           diamond);
  both_loops("POST /v1/morph SVG", API_ROUTE_MORPH, "image/svg+xml", false,
             body);
}

static void morph_svg_layouts_answer_503_when_out_of_memory(void **state) {
  static const char *const layouts[] = {"overlay", "animate", "curvature_plot"};
  char body[1024], name[64];
  (void)state;
  for (size_t i = 0; i < sizeof layouts / sizeof layouts[0]; i++) {
    snprintf(body, sizeof body,
             "{\"from\":%s,\"to\":%s,\"frames\":3,\"format\":\"svg\","
             "\"svg\":{\"layout\":\"%s\"},\"tolerance\":1e-3}",
             circle, diamond, layouts[i]);
    snprintf(name, sizeof name, "POST /v1/morph SVG %s", layouts[i]);
    both_loops(name, API_ROUTE_MORPH, NULL, false, body);
  }
  snprintf(body, sizeof body,
           "{\"from\":%s,\"to\":%s,\"frames\":3,"
           "\"include\":[\"animate_d\"],\"tolerance\":1e-3}",
           circle, diamond);
  both_loops("POST /v1/morph animate_d", API_ROUTE_MORPH, NULL, false, body);
}

/* A compound morph whose second square vanishes: its SVG layouts and its
 * animate_d, where the collapsed square is drawn at its point. */
static void shape_svg_layouts_answer_503_when_out_of_memory(void **state) {
  static const char *const layouts[] = {"filmstrip", "overlay", "animate",
                                        "curvature_plot"};
  static const char two[] = "{\"type\":\"svg\",\"d\":\"M 0 0 H 1 V 1 H 0 Z "
                            "M 3 0 H 4 V 1 H 3 Z\"}";
  static const char one[] = "{\"type\":\"svg\",\"d\":\"M 0 0 H 1 V 1 H 0 Z\"}";
  char body[1024], name[64];
  (void)state;
  for (size_t i = 0; i < sizeof layouts / sizeof layouts[0]; i++) {
    snprintf(body, sizeof body,
             "{\"from\":%s,\"to\":%s,\"frames\":3,\"format\":\"svg\","
             "\"svg\":{\"layout\":\"%s\"},\"tolerance\":1e-3}",
             two, one, layouts[i]);
    snprintf(name, sizeof name, "POST /v1/morph shapes SVG %s", layouts[i]);
    both_loops(name, API_ROUTE_MORPH, NULL, false, body);
  }
  snprintf(body, sizeof body,
           "{\"from\":%s,\"to\":%s,\"frames\":3,"
           "\"include\":[\"animate_d\"],\"tolerance\":1e-3}",
           two, one);
  both_loops("POST /v1/morph shapes animate_d", API_ROUTE_MORPH, NULL, false,
             body);
}

static void prepared_morph_answers_503_when_out_of_memory(void **state) {
  char body[1024];
  (void)state;
  snprintf(body, sizeof body,
           "{\"from\":%s,\"to\":%s,\"frames\":3,\"metrics\":true,"
           "\"tolerance\":1e-3}",
           arch, wave);
  both_loops("prepared morph", API_ROUTE_MORPH, NULL, true, body);
}

static const struct CMUnitTest tests[] = {
    cmocka_unit_test(signature_route_answers_503_when_out_of_memory),
    cmocka_unit_test(reconstruct_route_answers_503_when_out_of_memory),
    cmocka_unit_test(morph_json_answers_503_when_out_of_memory),
    cmocka_unit_test(morph_open_matches_answers_503_when_out_of_memory),
    cmocka_unit_test(morph_linear_auto_answers_503_when_out_of_memory),
    cmocka_unit_test(morph_svg_answers_503_when_out_of_memory),
    cmocka_unit_test(morph_svg_layouts_answer_503_when_out_of_memory),
    cmocka_unit_test(shape_svg_layouts_answer_503_when_out_of_memory),
    cmocka_unit_test(prepared_morph_answers_503_when_out_of_memory),
};

TM_SUITE("api_oom", tests, NULL, NULL);
