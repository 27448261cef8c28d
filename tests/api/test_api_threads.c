/* test_api_threads.c - the contract layer is reentrant: requests handled
 * on many threads at once answer exactly as they do one at a time, and a
 * prepared morph renders distinct frames on distinct threads. (Meant to be
 * run under ThreadSanitizer too: make SAN=thread.)
 */
#include <pthread.h>

#include "api_testutil.h"
#include "testmain.h"

#define NTHREADS 4
#define ROUNDS 8

typedef struct job {
  const char *body;
  api_route route;
  const api_response *want;
  int mismatches;
} job;

static void *hammer(void *arg) {
  job *j = arg;
  api_config cfg;
  api_request req;
  api_config_default(&cfg);
  memset(&req, 0, sizeof req);
  req.route = j->route;
  req.body = j->body;
  req.length = strlen(j->body);
  req.request_id = "test-1"; /* as at_call sends */
  for (int r = 0; r < ROUNDS; r++) {
    api_response res;
    api_handle(&cfg, &req, &res);
    if (res.status != j->want->status || res.length != j->want->length ||
        memcmp(res.body, j->want->body, res.length) != 0)
      j->mismatches++;
    api_response_free(&res);
  }
  return NULL;
}

static void concurrent_requests_answer_as_sequential_ones(void **state) {
  (void)state;
  at_buf circle = {0};
  at_printf(&circle, "{\"curve\":");
  at_circle_json(&circle, 1, 2, 3, 1);
  at_printf(&circle, ",\"samples\":16}");
  /* Good and bad requests mixed: parse failures must not disturb
   * successful parses on other threads. */
  const char *bodies[NTHREADS] = {circle.s, "{\"curve\":", "[1,2]",
                                  "{\"curve\":{\"type\":\"svg\","
                                  "\"d\":\"M0 0 L 10 0 L 10 10\"}}"};
  api_response want[NTHREADS];
  job jobs[NTHREADS];
  pthread_t th[NTHREADS];
  for (int i = 0; i < NTHREADS; i++) {
    at_call(API_ROUTE_SIGNATURE, bodies[i], &want[i], NULL);
    jobs[i] = (job){bodies[i], API_ROUTE_SIGNATURE, &want[i], 0};
  }
  assert_int_equal(want[0].status, 200);
  assert_int_equal(want[1].status, 400);
  assert_int_equal(want[2].status, 422);
  assert_int_equal(want[3].status, 200);
  for (int i = 0; i < NTHREADS; i++)
    assert_int_equal(pthread_create(&th[i], NULL, hammer, &jobs[i]), 0);
  for (int i = 0; i < NTHREADS; i++) {
    assert_int_equal(pthread_join(th[i], NULL), 0);
    assert_int_equal(jobs[i].mismatches, 0);
    api_response_free(&want[i]);
  }
  free(circle.s);
}

typedef struct render_job {
  api_morph_plan *plan;
  size_t first, step;
  int failures;
} render_job;

static void *render(void *arg) {
  render_job *r = arg;
  size_t n = api_morph_frame_count(r->plan);
  for (size_t i = r->first; i < n; i += r->step)
    r->failures += api_morph_render_frame(r->plan, i) != 0;
  return NULL;
}

static void plan_frames_render_on_many_threads(void **state) {
  (void)state;
  at_buf b = {0};
  at_printf(&b, "{\"from\":");
  at_circle_json(&b, 0, 0, 1, 1);
  at_printf(&b, ",\"to\":{\"type\":\"svg\",\"d\":\"M 0 -2 L 2 0 L 0 2 "
                "L -2 0 Z\"},\"frames\":24}");
  api_config cfg;
  api_request req;
  api_response sync, err, job_res;
  api_morph_plan *plan = NULL;
  api_config_default(&cfg);
  memset(&req, 0, sizeof req);
  req.route = API_ROUTE_MORPH;
  req.body = b.s;
  req.length = b.n;
  assert_int_equal(api_handle(&cfg, &req, &sync), 200);
  assert_int_equal(
      api_morph_prepare(&cfg, &req, cfg.max_frames_job, &plan, &err), 0);
  render_job rj[NTHREADS];
  pthread_t th[NTHREADS];
  for (int i = 0; i < NTHREADS; i++) {
    rj[i] = (render_job){plan, (size_t)i, NTHREADS, 0};
    assert_int_equal(pthread_create(&th[i], NULL, render, &rj[i]), 0);
  }
  for (int i = 0; i < NTHREADS; i++) {
    assert_int_equal(pthread_join(th[i], NULL), 0);
    assert_int_equal(rj[i].failures, 0);
  }
  assert_int_equal(api_morph_result(plan, &job_res), 200);
  assert_int_equal(job_res.length, sync.length);
  assert_memory_equal(job_res.body, sync.body, sync.length);
  api_morph_plan_free(plan);
  api_response_free(&sync);
  api_response_free(&job_res);
  free(b.s);
}

static const struct CMUnitTest tests[] = {
    cmocka_unit_test(concurrent_requests_answer_as_sequential_ones),
    cmocka_unit_test(plan_frames_render_on_many_threads),
};

TM_SUITE("api_threads", tests, NULL, NULL);
