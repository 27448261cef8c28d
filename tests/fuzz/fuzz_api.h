/* fuzz_api.h - the body of the libFuzzer targets for the JSON routes: any
 * byte string sent to api_handle (the entry point the daemon and the CLI
 * use) must come back as a well-formed answer: a 2xx result or a 4xx
 * problem+json, valid JSON when JSON is promised, never a 5xx, a crash, a
 * sanitizer report or a leak. Included by tests/fuzz/api_<route>/ with
 * FUZZ_ROUTE defined; built and run by `make fuzz` and `make test-fuzz`.
 *
 * The limits are the daemon's own except frames, control points and
 * samples, which are lowered so that every input stays within libFuzzer's
 * one-second budget under ASan: the time per request grows with them by
 * design, and the daemon bounds them before work starts.
 */
#ifndef FUZZ_API_H
#define FUZZ_API_H

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cJSON.h>

#include "kmapi/api.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void fuzz_api_config(api_config *cfg) {
  api_config_default(cfg);
  cfg->max_frames_sync = 12;
  cfg->max_frames_job = 12;
  cfg->max_control_points = 2000;
  cfg->max_samples = 2000;
}

/* Abort (libFuzzer records the input) with a reason on stderr. */
static void fuzz_fail(const char *why, const api_response *r) {
  fprintf(stderr, "fuzz_api: %s (status %d, content type %s)\n%.*s\n", why,
          r->status, r->content_type ? r->content_type : "(null)",
          r->body ? (int)(r->length < 2000 ? r->length : 2000) : 0,
          r->body ? r->body : "");
  abort();
}

/* The promises every answer keeps, whatever the request was. */
static void fuzz_check_response(const api_response *r) {
  if (r->status >= 500) fuzz_fail("server error for a client's request", r);
  if (r->status < 200 || (r->status >= 300 && r->status < 400))
    fuzz_fail("status outside 2xx/4xx", r);
  if (r->content_type == NULL || r->body == NULL)
    fuzz_fail("answer without a body or a content type", r);
  if (strlen(r->body) != r->length)
    fuzz_fail("body length disagrees with its NUL terminator", r);
  if (r->status >= 400 &&
      strcmp(r->content_type, "application/problem+json") != 0)
    fuzz_fail("an error that is not problem+json", r);
  if (strstr(r->content_type, "json") != NULL) {
    cJSON *doc = cJSON_ParseWithLength(r->body, r->length);
    if (doc == NULL) fuzz_fail("JSON answer does not parse", r);
    if (r->status >= 400) {
      const cJSON *st = cJSON_GetObjectItemCaseSensitive(doc, "status");
      const cJSON *ty = cJSON_GetObjectItemCaseSensitive(doc, "type");
      if (!cJSON_IsNumber(st) || st->valueint != r->status ||
          !cJSON_IsString(ty))
        fuzz_fail("problem lacks the status and type it must carry", r);
    }
    cJSON_Delete(doc);
  } else if (strncmp(r->content_type, "image/svg+xml", 13) == 0) {
    if (r->length < 5 || strstr(r->body, "<svg") == NULL)
      fuzz_fail("SVG answer without an <svg> element", r);
  }
}

/* A stop that fires at its n-th poll: the daemon's time limits, a client
 * leaving and the shutdown all stop computations this way, at any point
 * of their work. */
typedef struct fuzz_countdown {
  unsigned long left;
} fuzz_countdown;

static bool fuzz_stop_at(void *ctx) {
  fuzz_countdown *c = ctx;
  if (c->left == 0) return true;
  c->left--;
  return false;
}

/* The same request stopped part way: the answer is what the unstopped one
 * was, or the 503 "stopped" problem, and whatever was built is freed
 * (LeakSanitizer). The poll at which it stops comes from the input, so
 * that every stopping point can be reached. */
static void fuzz_stopped_request(const api_config *cfg, const uint8_t *data,
                                 size_t size, int unstopped) {
  unsigned long h = 5381;
  for (size_t i = 0; i < size; i++) h = h * 33 + data[i];
  fuzz_countdown c = {h % 64};
  api_request req = {.route = FUZZ_ROUTE,
                     .body = (const char *)data,
                     .length = size,
                     .request_id = "fuzz-2",
                     .stop = fuzz_stop_at,
                     .stop_ctx = &c};
  api_response out;
  api_response_init(&out);
  api_handle(cfg, &req, &out);
  if (out.status == 503) {
    if (out.body == NULL || strstr(out.body, "/problems/stopped") == NULL)
      fuzz_fail("a stopped request answered another 503", &out);
  } else {
    fuzz_check_response(&out);
    if (out.status != unstopped)
      fuzz_fail("a stop changed the answer without stopping it", &out);
  }
  api_response_free(&out);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  api_config cfg;
  fuzz_api_config(&cfg);
  api_request req = {.route = FUZZ_ROUTE,
                     .body = (const char *)data,
                     .length = size,
                     .request_id = "fuzz-1"};
  api_response out;
  api_response_init(&out);
  int st = api_handle(&cfg, &req, &out);
  if (st != out.status)
    fuzz_fail("returned status differs from the response's", &out);
  fuzz_check_response(&out);
  fuzz_stopped_request(&cfg, data, size, out.status);

#ifdef FUZZ_JOB_PATH
  /* The asynchronous path (POST /v1/jobs) prepares, renders frame by frame
   * and assembles: it must agree with the synchronous answer's status. */
  {
    api_morph_plan *plan = NULL;
    api_response perr;
    api_response_init(&perr);
    int pst = api_morph_prepare(&cfg, &req, cfg.max_frames_job, &plan, &perr);
    if (pst != 0) {
      fuzz_check_response(&perr);
      if (plan != NULL) fuzz_fail("failed prepare left a plan", &perr);
      if (pst != out.status)
        fuzz_fail("job prepare and synchronous morph disagree", &perr);
    } else {
      size_t n = api_morph_frame_count(plan);
      int fst = 0;
      if (n == 0 || n > cfg.max_frames_job)
        fuzz_fail("plan frame count outside the limit", &out);
      for (size_t i = 0; i < n && fst == 0; i++)
        fst = api_morph_render_frame(plan, i);
      if (fst == 0) {
        api_response res;
        api_response_init(&res);
        int rst = api_morph_result(plan, &res);
        if (rst != res.status)
          fuzz_fail("job result status differs from its response", &res);
        fuzz_check_response(&res);
        if (res.status != out.status)
          fuzz_fail("job result and synchronous morph disagree", &res);
        api_response_free(&res);
      } else if (fst != out.status) {
        fuzz_fail("job frame failure and synchronous morph disagree", &out);
      }
      api_morph_plan_free(plan);
    }
    api_response_free(&perr);
  }
#endif
  api_response_free(&out);
  return 0;
}

#endif
