/* job_endpoints.c - GET and DELETE /v1/jobs/{id}, GET /v1/jobs/{id}/result
 * (see endpoints.h).
 */
#include "endpoints.h"

#include <string.h>

#include "reply.h"
#include "util.h"

/* 404 for a job never known (or deleted), 410 for one that was known and
 * is no longer kept, with why: a client must not take an expired or
 * evicted job for a mistyped id, nor resubmit blindly. */
static enum MHD_Result job_missing(srv_req *r, int rc, const srv_job_view *v) {
  if (rc == SRV_STORE_GONE) {
    char detail[400];
    snprintf(detail, sizeof detail, "job %s is no longer kept: %s", r->job_id,
             v->error);
    return srv__problem(r, 410, "/problems/job-gone", "Job gone", detail, NULL,
                        NULL);
  }
  return srv__problem(r, 404, "/problems/job-not-found", "Job not found",
                      "no such job", NULL, NULL);
}

#define STORE_DOWN_TYPE "/problems/job-store-unavailable"
#define STORE_DOWN_TITLE "Job store unavailable"
#define STORE_DOWN_DETAIL                                                      \
  "the job store (Redis, KMORPH_JOBS) cannot be reached now; synchronous "     \
  "routes still answer; retry after the time in Retry-After"

void srv__store_unavailable(api_response *out, const char *rid) {
  api_problem(out, 503, STORE_DOWN_TYPE, STORE_DOWN_TITLE, STORE_DOWN_DETAIL,
              NULL, NULL, rid);
}

enum MHD_Result srv__answer_store_down(srv_req *r) {
  return srv__problem(r, 503, STORE_DOWN_TYPE, STORE_DOWN_TITLE,
                      STORE_DOWN_DETAIL, NULL, NULL);
}

static enum MHD_Result delete_job(srv_req *r) {
  srv_server *s = r->srv;
  if (s->rjobs != NULL) {
    int rc = srv_rjobs_delete(s->rjobs, r->job_id);
    if (rc == SRV_RJOBS_DOWN) return srv__answer_store_down(r);
    if (rc == 0) return srv__answer(r, 204, NULL, (char *)"", 0, false);
    return srv__problem(r, 404, "/problems/job-not-found", "Job not found",
                        "no such job (finished jobs are forgotten after a "
                        "while)",
                        NULL, NULL);
  }
  if (srv_jobs_cancel(s->jobs, r->job_id) == 0)
    return srv__answer(r, 204, NULL, (char *)"", 0, false);
  /* Not live: a final job is forgotten; an unknown one is 404. */
  if (s->store->ops->remove(s->store, r->job_id) == 0)
    return srv__answer(r, 204, NULL, (char *)"", 0, false);
  return srv__problem(r, 404, "/problems/job-not-found", "Job not found",
                      "no such job (finished jobs are forgotten after a "
                      "while)",
                      NULL, NULL);
}

enum MHD_Result srv__serve_job(srv_req *r) {
  srv_server *s = r->srv;
  srv_job_view v;
  double now = srv_now();
  if (strcmp(r->method, "DELETE") == 0) return delete_job(r);
  int rc = s->rjobs != NULL ? srv_rjobs_get(s->rjobs, r->job_id, &v)
                            : s->store->ops->get(s->store, r->job_id, now, &v);
  if (rc == SRV_RJOBS_DOWN) return srv__answer_store_down(r);
  if (rc != SRV_STORE_OK) return job_missing(r, rc, &v);
  double progress =
      v.frames_total ? (double)v.frames_done / (double)v.frames_total : 0.0;
  if (v.state == SRV_JOB_DONE) progress = 1.0;
  r->poll_hint = !srv_job_state_final(v.state);
  char err[600] = "";
  if (v.state == SRV_JOB_FAILED) {
    char esc[520];
    srv_json_escape(esc, sizeof esc, v.error);
    snprintf(err, sizeof err, ",\"error\":{\"status\":%d,\"detail\":\"%s\"}",
             v.error_status, esc);
  }
  return srv__answer_json(
      r, 200,
      "{\"id\":\"%s\",\"state\":\"%s\",\"progress\":%.6g,"
      "\"frames_done\":%zu,\"frames_total\":%zu,\"age_seconds\":%.3f,"
      "\"links\":{\"self\":\"/v1/jobs/%s\",\"result\":\"/v1/jobs/%s/result\"}"
      "%s}",
      v.id, srv_job_state_name(v.state), progress, v.frames_done,
      v.frames_total, v.age, v.id, v.id, err);
}

/* A finished job's result is immutable: a client (a browser) may keep it
 * a day without asking again; private, since only whoever holds the job
 * id should see it. */
#define RESULT_CACHE_CONTROL "private, max-age=86400, immutable"

static void drop_result_ref(void *cls) {
  srv_result_unref(cls);
}

/* A job's result, sent from the store's own copy: the answer holds a
 * reference until libmicrohttpd has sent it, so a slow reader costs no
 * memory of its own and an eviction meanwhile frees nothing under it. */
static enum MHD_Result answer_result(srv_req *r, srv_result *res) {
  const char *type = srv_result_type(res);
  if (!srv__accepts_type(r, type)) {
    srv_result_unref(res);
    return srv__not_acceptable(r, type);
  }
  /* A job's result never changes: its id names the content, so the tag
   * is the id (and the gzip form's another), with no hash of megabytes. */
  char etag[SRV_JOB_ID_LEN + 3], gz_etag[SRV_JOB_ID_LEN + 6];
  snprintf(etag, sizeof etag, "\"%s\"", r->job_id);
  snprintf(gz_etag, sizeof gz_etag, "\"%s-gz\"", r->job_id);
  srv_body b = {.type = type,
                .data = srv_result_body(res),
                .len = srv_result_length(res),
                .stream_gzip = true,
                .etag = etag,
                .gz_etag = gz_etag,
                .cache_control = RESULT_CACHE_CONTROL,
                .release = drop_result_ref,
                .cls = res};
  return srv__answer_body(r, srv_result_status(res), &b);
}

enum MHD_Result srv__serve_result(srv_req *r) {
  srv_server *s = r->srv;
  srv_job_view v;
  srv_result *res = NULL;
  int rc = s->rjobs != NULL ? srv_rjobs_result(s->rjobs, r->job_id, &v, &res)
                            : s->store->ops->result(s->store, r->job_id,
                                                    srv_now(), &v, &res);
  if (rc == SRV_RJOBS_DOWN) return srv__answer_store_down(r);
  if (rc == SRV_RJOBS_NOMEM) {
    r->cut = "out of memory";
    return MHD_NO;
  }
  if (rc != SRV_STORE_OK) return job_missing(r, rc, &v);
  if (v.state == SRV_JOB_DONE && res != NULL) return answer_result(r, res);
  srv_result_unref(res);
  char detail[400];
  if (v.state == SRV_JOB_FAILED)
    snprintf(detail, sizeof detail, "the job failed: %s", v.error);
  else if (v.state == SRV_JOB_CANCELLED)
    snprintf(detail, sizeof detail, "the job was cancelled");
  else
    snprintf(detail, sizeof detail,
             "the job is %s (%zu of %zu frames done); poll /v1/jobs/%s",
             srv_job_state_name(v.state), v.frames_done, v.frames_total, v.id);
  return srv__problem(r, 409, "/problems/job-not-done", "Result not ready",
                      detail, NULL, NULL);
}
