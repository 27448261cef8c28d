/* compute.c - the compute hand-off and the worker's side of a request
 * (see compute.h): synchronous signature, reconstruct and morph within
 * their time limits, and the creation of asynchronous jobs.
 */
#include "compute.h"
#include "endpoints.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>

#include "frame_share.h"
#include "pool.h"
#include "reply.h"
#include "request.h"
#include "util.h"

/* ------------------------------------------------------ stop condition */

/* True if the client has reset its connection, or closed it, while its
 * request waited: its answer could not be delivered, so no work is done
 * for it. A FIN alone is not enough: a client that half-closed its
 * sending side still reads its answer; srv_http_fin_probe tells the two
 * apart (the probe goes out once; a closed peer's reset is then seen
 * here as an error). */
static bool client_gone(srv_req *r) {
  const union MHD_ConnectionInfo *ci =
      MHD_get_connection_info(r->conn, MHD_CONNECTION_INFO_CONNECTION_FD);
  if (ci == NULL) return false;
  char b;
  ssize_t n = recv(ci->connect_fd, &b, 1, MSG_PEEK | MSG_DONTWAIT);
  if (n == 0) return srv_http_fin_probe(ci->connect_fd, r->http11, &r->probed);
  return n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR;
}

/* The stop condition of a request's computation, polled by the core at
 * short intervals of work (api_request.stop): the shutdown's grace ran
 * out, the compute time limit passed, or the client left (looked at every
 * 20 ms: a recv on the socket). Runs on the worker that owns r. */
static bool request_should_stop(void *ctx) {
  srv_req *r = ctx;
  if (r->stopped != STOP_NONE) return true;
  if (atomic_load(&r->srv->abort_compute)) r->stopped = STOP_SHUTDOWN;
  double now = srv_now();
  if (r->stopped == STOP_NONE && now > r->deadline) r->stopped = STOP_TIME;
  if (r->stopped == STOP_NONE && now >= r->next_gone_check) {
    r->next_gone_check = now + 0.02;
    if (client_gone(r)) r->stopped = STOP_GONE;
  }
  return r->stopped != STOP_NONE;
}

/* The answer to a computation stopped by request_should_stop. limit and
 * name describe the time limit; pointer is the member that makes the
 * request long (a time limit is a limit like the frame limit: 422). */
static void stopped_problem(srv_req *r, double limit, const char *name,
                            const char *pointer, const char *message,
                            const char *progress) {
  api_response_free(&r->resp);
  if (r->stopped == STOP_GONE) {
    api_problem(&r->resp, 503, "/problems/client-gone", "Client gone",
                "the client closed the connection during the work", NULL, NULL,
                r->rid);
    return;
  }
  if (r->stopped == STOP_SHUTDOWN) {
    api_problem(&r->resp, 503, "/problems/shutting-down", "Shutting down",
                "the service stopped this computation at the end of its "
                "shutdown grace; retry on another instance",
                NULL, NULL, r->rid);
    return;
  }
  char detail[400];
  snprintf(detail, sizeof detail,
           "%s: the computation ran past its time limit of %g s (%s)%s%s",
           pointer, limit, name, progress,
           r->route == SRV_R_MORPH
               ? "; POST /v1/jobs computes long morphs asynchronously"
               : "");
  srv_metrics_reject(r->srv->metrics,
                     r->route == SRV_R_MORPH ? "morph_time" : "compute_time");
  api_problem(&r->resp, 422, "/problems/limit-exceeded", "Limit exceeded",
              detail, pointer, message, r->rid);
}

/* ------------------------------------------------------------- jobs */

static int job_created_body(api_response *out, const char *id, size_t total) {
  char tmp[512];
  int n = snprintf(tmp, sizeof tmp,
                   "{\"id\":\"%s\",\"state\":\"queued\",\"progress\":0,"
                   "\"frames_done\":0,\"frames_total\":%zu,"
                   "\"links\":{\"self\":\"/v1/jobs/%s\","
                   "\"result\":\"/v1/jobs/%s/result\"}}",
                   id, total, id, id);
  char *body = malloc((size_t)n + 1);
  if (body == NULL) return -1;
  memcpy(body, tmp, (size_t)n + 1);
  out->status = 202;
  out->content_type = SRV_JSON_TYPE;
  out->body = body;
  out->length = (size_t)n;
  return 0;
}

/* Validate and plan the job's morph within limit seconds from the
 * request's start. The plan (owned by the caller), or NULL with the
 * problem in r->resp. */
static api_morph_plan *plan_job(srv_req *r, api_request *req, double limit) {
  srv_server *s = r->srv;
  api_morph_plan *plan = NULL;
  api_response err;
  api_response_init(&err);
  /* A job's answer is kept, not sent at once: it is held to the memory
   * kept for job results (checked again with the others' reservations
   * when the job is admitted), not to the size of a synchronous answer. */
  api_config cfg = s->api;
  cfg.max_output_bytes = s->cfg.result_memory;
  int rc = api_morph_prepare(&cfg, req, s->cfg.max_job_frames, &plan, &err);
  if (rc == 0 && plan != NULL) {
    api_response_free(&err);
    return plan;
  }
  r->resp = err;
  if (r->stopped != STOP_NONE) {
    char message[160];
    snprintf(message, sizeof message,
             "preparing the morph takes longer than the %g s a job may "
             "take",
             limit);
    stopped_problem(r, limit, "KMORPH_JOB_TIME", "/tolerance", message,
                    " while preparing the morph");
  } else if (r->resp.body == NULL) {
    api_problem(&r->resp, rc >= 400 ? rc : 500, "/problems/internal",
                "Internal error", "the morph could not be prepared", NULL, NULL,
                r->rid);
  }
  return NULL;
}

/* False, with a 422 in r->resp, if a result of predicted bytes could
 * never be kept: a limit of the request, like its frames. */
static bool result_fits(srv_req *r, const api_morph_plan *plan,
                        size_t predicted) {
  size_t keep = r->srv->cfg.result_memory;
  if (predicted <= keep) return true;
  const char *ptr = api_morph_frames_pointer(plan);
  char message[200], detail[400];
  snprintf(message, sizeof message,
           "the result would take up to %zu bytes; job results are kept "
           "within %zu",
           predicted, keep);
  snprintf(detail, sizeof detail,
           "%s: the result would take up to %zu bytes, more than the %zu "
           "kept for job results (KMORPH_RESULT_MEMORY); ask for fewer "
           "frames or a looser tolerance",
           ptr, predicted, keep);
  api_problem(&r->resp, 422, "/problems/limit-exceeded", "Limit exceeded",
              detail, ptr, message, r->rid);
  return false;
}

/* The answer to srv_jobs_start's refusal st (not 0) in r->resp. */
static void job_refused(srv_req *r, int st) {
  srv_server *s = r->srv;
  if (st == -1) {
    srv_metrics_reject(s->metrics, "jobs_full");
    api_problem(&r->resp, 429, "/problems/too-many-jobs", "Too many jobs",
                "the job limit (KMORPH_MAX_JOBS) is reached; retry later", NULL,
                NULL, r->rid);
  } else if (st == -4) {
    srv_metrics_reject(s->metrics, "result_memory");
    api_problem(&r->resp, 503, "/problems/overloaded", "Overloaded",
                "the results of the jobs running now would fill the memory "
                "kept for job results (KMORPH_RESULT_MEMORY); retry later",
                NULL, NULL, r->rid);
  } else if (st == SRV_RJOBS_FULL) {
    job_refused(r, -1);
  } else if (st == SRV_RJOBS_DOWN) {
    srv__store_unavailable(&r->resp, r->rid);
  } else if (st == -3) {
    api_problem(&r->resp, 503, "/problems/shutting-down", "Shutting down",
                "the service is stopping; retry on another instance", NULL,
                NULL, r->rid);
  } else {
    api_problem(&r->resp, 500, "/problems/internal", "Out of memory", NULL,
                NULL, NULL, r->rid);
  }
}

/* POST /v1/jobs on a worker: validate and plan (within the job's time),
 * then admit the job with the rest of that time. */
static void create_job(srv_req *r, api_request *req) {
  srv_server *s = r->srv;
  double limit = srv_jobs_time_limit(s->jobs);
  r->deadline = r->t0 + limit;
  api_morph_plan *plan = plan_job(r, req, limit);
  if (plan == NULL) return;
  size_t total = api_morph_frame_count(plan);
  size_t predicted = api_morph_predicted_bytes(plan);
  if (!result_fits(r, plan, predicted)) {
    api_morph_plan_free(plan);
    return;
  }
  if (s->rjobs != NULL) {
    /* Shared: the record keeps the request, the plan stays in this
     * instance's cache for the batches it takes. */
    int st =
        srv_rjobs_start(s->rjobs, r->body, r->len, r->accept, plan, r->job_id);
    if (st != 0) {
      job_refused(r, st);
      return;
    }
  } else {
    /* Admitted, the job runner owns the plan; refused, it is still ours. */
    int st = srv_jobs_start(s->jobs, plan, r->deadline, predicted, r->job_id);
    if (st != 0) {
      api_morph_plan_free(plan);
      job_refused(r, st);
      return;
    }
  }
  if (job_created_body(&r->resp, r->job_id, total) != 0) {
    job_refused(r, 0);
    return;
  }
  r->location = true;
  srv_pool_kick(s->pool);
}

/* ------------------------------------------------ synchronous answers */

/* Synchronous answers up to this size are printed frame by frame by the
 * workers that render them (api_morph_print_while_rendering). */
#define SYNC_PRINT_WHILE_RENDERING ((size_t)16 << 20)

/* POST /v1/morph on a worker, frame by frame the way api_handle does it,
 * so that the work stops when the client leaves or the compute time limit
 * passes - between frames, and inside preparing and each frame through
 * the stop condition. The time counts from the start of the work. */
static void morph_sync(srv_req *r, api_request *req) {
  srv_server *s = r->srv;
  api_morph_plan *plan = NULL;
  double limit = s->cfg.morph_time;
  r->deadline = srv_now() + limit;
  char message[160];
  if (api_morph_prepare(&s->api, req, s->api.max_frames_sync, &plan,
                        &r->resp) != 0) {
    if (r->stopped != STOP_NONE) {
      snprintf(message, sizeof message,
               "preparing the morph takes longer than the %g s a "
               "synchronous morph may compute",
               limit);
      stopped_problem(r, limit, "KMORPH_MORPH_TIME", "/tolerance", message,
                      " while preparing the morph");
    }
    return;
  }
  size_t n = api_morph_frame_count(plan);
  /* Idle workers render frames beside this one (frame_share.h). A frame
   * that fails for its own reason leaves its problem in the plan for
   * api_morph_result; one that was stopped ends the work. */
  /* with other workers to help, frames print themselves where they are
   * rendered, for answers small enough to be held twice a moment */
  if (n > 1 && srv_pool_workers(s->pool) > 1)
    api_morph_print_while_rendering(plan, SYNC_PRINT_WHILE_RENDERING);
  srv_shared_frames sf;
  srv_frame_share_open(&s->shares, &sf, plan, n, r->deadline,
                       &s->abort_compute);
  if (n > 1) srv_pool_kick(s->pool);
  for (size_t i;
       !request_should_stop(r) && (i = srv_frame_share_take(&sf)) < n;) {
    api_morph_render_frame_until(plan, i, request_should_stop, r);
    if (r->stopped == STOP_NONE) atomic_fetch_add(&sf.done, 1);
  }
  if (r->stopped != STOP_NONE) atomic_store(&sf.halt, true);
  srv_frame_share_close(&s->shares, &sf);
  /* a helper's frame stopped by the time or the shutdown: this sees it */
  if (r->stopped == STOP_NONE && atomic_load(&sf.done) < n)
    request_should_stop(r);
  size_t done = atomic_load(&sf.done);
  if (r->stopped != STOP_NONE) {
    char progress[80];
    snprintf(message, sizeof message,
             "%zu frames take longer than the %g s a synchronous morph may "
             "compute",
             n, limit);
    snprintf(progress, sizeof progress, " with %zu of %zu frames done", done,
             n);
    stopped_problem(r, limit, "KMORPH_MORPH_TIME",
                    api_morph_frames_pointer(plan), message, progress);
  } else {
    api_morph_result(plan, &r->resp);
  }
  api_morph_plan_free(plan);
}

/* POST /v1/signature or /v1/reconstruct on a worker, within the compute
 * time limit. */
static void compute_sync(srv_req *r, api_request *req) {
  double limit = r->srv->cfg.compute_time;
  r->deadline = srv_now() + limit;
  api_handle(&r->srv->api, req, &r->resp);
  if (r->stopped != STOP_NONE) {
    char message[160];
    snprintf(message, sizeof message,
             "the computation takes longer than the %g s a request may "
             "compute",
             limit);
    stopped_problem(r, limit, "KMORPH_COMPUTE_TIME", "/tolerance", message, "");
  }
}

/* ------------------------------------------------------------ hand-off */

/* Run r's computation on this worker, by route. */
static void compute_request(srv_req *r) {
  api_request req;
  memset(&req, 0, sizeof req);
  req.body = r->body ? r->body : "";
  req.length = r->len;
  req.accept = r->accept;
  req.request_id = r->rid;
  req.stop = request_should_stop;
  req.stop_ctx = r;
  r->next_gone_check = srv_now() + 0.02;
  if (r->route == SRV_R_JOBS) {
    req.route = API_ROUTE_MORPH;
    create_job(r, &req);
  } else if (r->route == SRV_R_SIGNATURE || r->route == SRV_R_RECONSTRUCT) {
    req.route = r->route == SRV_R_SIGNATURE ? API_ROUTE_SIGNATURE
                                            : API_ROUTE_RECONSTRUCT;
    compute_sync(r, &req);
  } else {
    req.route = API_ROUTE_MORPH;
    morph_sync(r, &req);
  }
}

/* The pool's task (pool.h): cancelled when the pool stops before the
 * request was started. */
static void compute_task(void *arg, bool cancelled) {
  srv_req *r = arg;
  api_response_init(&r->resp);
  if (!cancelled && client_gone(r)) {
    api_problem(&r->resp, 503, "/problems/client-gone", "Client gone",
                "the client closed the connection before the work started",
                NULL, NULL, r->rid);
  } else if (cancelled) {
    api_problem(&r->resp, 503, "/problems/shutting-down", "Shutting down",
                "the service is stopping; retry on another instance", NULL,
                NULL, r->rid);
  } else {
    compute_request(r);
  }
  /* The body is no longer needed: give its memory back to the budget of
   * bodies in flight before the answer is sent. */
  srv__body_release(r);
  atomic_store(&r->phase, PH_READY);
  MHD_resume_connection(r->conn);
}

enum MHD_Result srv__hand_off(srv_req *r) {
  srv_server *s = r->srv;
  if (atomic_load(&s->draining))
    return srv__problem(r, 503, "/problems/shutting-down", "Shutting down",
                        "the service is stopping; retry on another instance",
                        NULL, NULL);
  if (r->route == SRV_R_JOBS && s->rjobs != NULL && !srv_rjobs_up(s->rjobs) &&
      !srv_rjobs_ready(s->rjobs))
    return srv__answer_store_down(r);
  if (r->route == SRV_R_JOBS && srv_jobs_full(s->jobs)) {
    srv_metrics_reject(s->metrics, "jobs_full");
    return srv__problem(r, 429, "/problems/too-many-jobs", "Too many jobs",
                        "the job limit (KMORPH_MAX_JOBS) is reached; retry "
                        "later",
                        NULL, NULL);
  }
  if (!srv_pool_reserve(s->pool)) {
    srv_metrics_reject(s->metrics, "queue_full");
    return srv__problem(r, 503, "/problems/overloaded", "Overloaded",
                        "every compute worker is busy and the queue is full; "
                        "retry after the time in Retry-After",
                        NULL, NULL);
  }
  /* Suspend before submitting so the worker's resume always comes after. */
  atomic_store(&r->phase, PH_WAIT);
  atomic_fetch_add(&s->suspended, 1);
  r->counted = true;
  srv_watch_body_done(srv__req_conn(r));
  MHD_suspend_connection(r->conn);
  srv_pool_submit(s->pool, compute_task, r);
  return MHD_YES;
}
