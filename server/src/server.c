/* server.c - the kmorphd server object: its life cycle over
 * libmicrohttpd (see server.h), and the daemon-wide callbacks.
 *
 * DESIGN: MHD runs a small pool of I/O threads (auto-selected poll/epoll)
 * with suspend/resume allowed. A request's life is in request.c (headers,
 * body, dispatch) and request_done.c (metrics, access log); answers are
 * queued through reply.c, which adds X-Request-Id and, for allowed
 * origins, CORS headers to every one; compute.c hands requests that need
 * geometry to the compute pool and back; the endpoints answered on the
 * I/O thread are in job_endpoints.c and static_endpoints.c. I/O threads
 * never compute. The shared structs are in server_internal.h.
 */
#include "server.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "request.h"
#include "route.h"
#include "server_internal.h"
#include "util.h"

/* ------------------------------------------------- daemon callbacks */

/* Connections open and close: their watch records (watch.h). */
static void on_connection(void *cls, struct MHD_Connection *c,
                          void **socket_context,
                          enum MHD_ConnectionNotificationCode code) {
  srv_server *s = cls;
  if (code == MHD_CONNECTION_NOTIFY_STARTED) {
    const union MHD_ConnectionInfo *ci =
        MHD_get_connection_info(c, MHD_CONNECTION_INFO_CONNECTION_FD);
    *socket_context =
        ci ? srv_watch_open(s->watch, ci->connect_fd, srv_now()) : NULL;
  } else if (code == MHD_CONNECTION_NOTIFY_CLOSED) {
    srv_watch_close(s->watch, *socket_context);
    *socket_context = NULL;
  }
}

/* Seconds an I/O thread with no connection waits after accept failed for
 * want of descriptors (nginx pauses 500 ms). */
static const double ACCEPT_PAUSE = 0.25;

/* libmicrohttpd's messages, one line a second per kind (its format
 * string): accept failing with EMFILE repeats as fast as the loop spins.
 * With connections open, libmicrohttpd stops accepting by itself until one
 * closes; an I/O thread without any would retry at once for ever ("at
 * FIRST connection"), so that thread, having nothing else to serve,
 * pauses here. */
static void mhd_log(void *cls, const char *fmt, va_list ap) {
  srv_server *s = cls;
  /* Connections reach libmicrohttpd through a socket pair (front.h),
   * which has no TCP options to set or buffers to push; the front sets
   * TCP_NODELAY on the client's socket itself. */
  if (strncmp(fmt, "Setting %s option to %s state failed", 36) == 0 ||
      strncmp(fmt, "Failed to push the data from buffers", 36) == 0)
    return;
  char msg[512];
  vsnprintf(msg, sizeof msg, fmt, ap);
  size_t n = strlen(msg);
  while (n > 0 && msg[n - 1] == '\n') msg[--n] = '\0';
  unsigned long more = 0;
  if (srv_log_admit(s->logger, fmt, msg, &more)) {
    if (more > 0)
      srv_log_notice(s->log, "kmorphd: http: %s (%lu more suppressed)\n", msg,
                     more);
    else
      srv_log_notice(s->log, "kmorphd: http: %s\n", msg);
  }
  if (strstr(fmt, "resource limit at FIRST") != NULL) srv_sleep(ACCEPT_PAUSE);
}

/* -------------------------------------------------------- life cycle */

static bool yield_to_requests(void *pool) {
  return srv_pool_run_queued(pool);
}

/* --jobs: the Redis connections and the shared job runner. False (with
 * the reason logged) if the URL is malformed or memory is short; Redis
 * itself need not be up yet. */
static bool shared_jobs(srv_server *s) {
  char err[600];
  s->redis = srv_redis_create(s->cfg.jobs, err, sizeof err);
  if (s->redis == NULL) {
    srv_log_notice(s->log, "kmorphd: %s\n", err);
    return false;
  }
  srv_rjobs_config rc = {.api = s->api,
                         .max_job_frames = s->cfg.max_job_frames,
                         .max_jobs = s->cfg.max_jobs,
                         .job_time = s->cfg.job_time,
                         .job_ttl = s->cfg.job_ttl,
                         .visibility = s->cfg.job_reclaim};
  /* As plan_job prepares a job: held to the memory kept for results. */
  rc.api.max_output_bytes = s->cfg.result_memory;
  s->rjobs = srv_rjobs_create(s->redis, &rc);
  if (s->rjobs == NULL) return false;
  if (!srv_redis_ping(s->redis))
    srv_log_notice(s->log,
                   "kmorphd: jobs in Redis at %s, not reachable yet: "
                   "retrying\n",
                   srv_redis_name(s->redis));
  return true;
}

/* What idle workers do (the pool's background source): help with the
 * frames of a synchronous morph first, whose client is waiting, then the
 * frames of asynchronous jobs. */
static bool idle_work(void *ctx) {
  srv_server *s = ctx;
  if (srv_frame_share_help(&s->shares)) return true;
  return s->rjobs != NULL ? srv_rjobs_work(s->rjobs) : srv_jobs_work(s->jobs);
}

srv_server *srv_server_create(const srv_config *cfg, srv_log *logger) {
  srv_server *s = calloc(1, sizeof *s);
  if (s == NULL) return NULL;
  s->cfg = *cfg;
  s->logger = logger;
  s->log = srv_log_stream(logger);
  atomic_init(&s->draining, false);
  atomic_init(&s->abort_compute, false);
  atomic_init(&s->suspended, 0);
  atomic_init(&s->inflight, 0);
  atomic_init(&s->body_bytes, 0);
  api_config_default(&s->api);
  s->api.max_body_bytes = cfg->max_body;
  s->api.max_control_points = cfg->max_points;
  s->api.max_contours = cfg->max_contours;
  s->api.max_frames_sync = cfg->max_frames;
  s->api.max_frames_job = cfg->max_job_frames;
  s->api.max_samples = cfg->max_samples;
  s->api.max_output_bytes = cfg->max_output;
  s->metrics = srv_metrics_create(srv__route_method_allowed);
  s->statics = srv_static_cache_create();
  atomic_init(&s->gz_streams, 0);
  srv_watch_limits wl = {.header_time = cfg->header_time,
                         .request_time = cfg->request_time,
                         .send_time = cfg->send_time,
                         .idle_time = (double)cfg->timeout,
                         /* a probe sends its few header bytes at once */
                         .reserved_header_time =
                             cfg->header_time < 1.0 ? cfg->header_time : 1.0,
                         .normal = cfg->max_connections};
  s->watch = srv_watch_create(&wl, s->log);
  s->store = srv_jobstore_memory_create(cfg->job_ttl, cfg->job_keep,
                                        cfg->result_memory);
  s->jobs =
      s->store ? srv_jobs_create(s->store, cfg->max_jobs, cfg->job_time) : NULL;
  if (cfg->jobs[0] != '\0' && !shared_jobs(s)) {
    srv_server_destroy(s);
    return NULL;
  }
  s->shares_ready = srv_frame_share_init(&s->shares) == 0;
  if (s->shares_ready && (s->rjobs != NULL || s->jobs != NULL))
    s->pool = srv_pool_create(cfg->workers, cfg->queue, idle_work, s);
  /* Batches of shared jobs appear without a kick from this process. */
  if (s->pool != NULL && s->rjobs != NULL) {
    srv_pool_set_poll(s->pool, 0.02);
    srv_rjobs_set_yield(s->rjobs, yield_to_requests, s->pool);
  }
  if (s->metrics == NULL || s->pool == NULL || s->watch == NULL ||
      s->statics == NULL) {
    srv_log_notice(s->log,
                   "kmorphd: cannot create the compute pool (%u workers)\n",
                   cfg->workers);
    srv_server_destroy(s);
    return NULL;
  }
  return s;
}

int srv_server_start(srv_server *s) {
  srv_front_options fo = {.bind = s->cfg.bind,
                          .port = s->cfg.port,
                          .threads = s->cfg.io_threads,
                          .max_connections =
                              s->cfg.max_connections + s->cfg.reserved,
                          .drain_time = s->cfg.send_time,
                          .access_log = s->cfg.access_log,
                          .logger = s->logger,
                          .log = s->log};
  s->front = srv_front_listen(&fo);
  if (s->front == NULL) return -1;
  unsigned flags = MHD_USE_AUTO_INTERNAL_THREAD | MHD_ALLOW_SUSPEND_RESUME |
                   MHD_USE_ERROR_LOG | MHD_USE_NO_LISTEN_SOCKET | MHD_USE_ITC;
  /* The front holds connections to --max-connections plus the reserved
   * ones; libmicrohttpd's own limit is twice that, so that it is never
   * the one reached: the front's count falls as soon as it closes a
   * connection, libmicrohttpd's only once it notices, and in 0.9.75 an
   * I/O thread at its share of the limit was seen to leave a request on
   * another of its connections unread for seconds. */
  s->daemon = MHD_start_daemon(
      flags, 0, NULL, NULL, &srv__on_request, s, MHD_OPTION_EXTERNAL_LOGGER,
      &mhd_log, s, MHD_OPTION_THREAD_POOL_SIZE, (unsigned int)s->cfg.io_threads,
      MHD_OPTION_CONNECTION_LIMIT,
      (unsigned int)(2 * (s->cfg.max_connections + s->cfg.reserved)),
      MHD_OPTION_PER_IP_CONNECTION_LIMIT, (unsigned int)s->cfg.per_ip,
      MHD_OPTION_CONNECTION_TIMEOUT, (unsigned int)s->cfg.timeout,
      MHD_OPTION_NOTIFY_CONNECTION, &on_connection, s,
      MHD_OPTION_NOTIFY_COMPLETED, &srv__on_completed, s,
      MHD_OPTION_URI_LOG_CALLBACK, &srv__on_uri, s, MHD_OPTION_END);
  if (s->daemon == NULL) {
    srv_log_notice(s->log, "kmorphd: cannot start the HTTP daemon\n");
    return -1;
  }
  s->port = srv_front_port(s->front);
  return srv_front_start(s->front, s->daemon);
}

unsigned srv_server_port(const srv_server *s) {
  return s->port;
}

/* Wait until cond(s) holds or the deadline passes; true if it held. */
static bool wait_until(srv_server *s, bool (*cond)(srv_server *),
                       double deadline) {
  for (;;) {
    if (cond(s)) return true;
    if (srv_now() >= deadline) return false;
    srv_sleep(0.01);
  }
}

static bool compute_idle(srv_server *s) {
  return atomic_load(&s->suspended) == 0 && srv_jobs_live(s->jobs) == 0 &&
         (s->rjobs == NULL || srv_rjobs_busy(s->rjobs) == 0) &&
         srv_pool_depth(s->pool) == 0;
}

static bool requests_done(srv_server *s) {
  return atomic_load(&s->inflight) == 0;
}

/* Seconds the computations still running when the grace ends get, once
 * told to stop (abort_compute), to answer 503 and resume their
 * connection: they check the flag between frames and within their long
 * loops, far more often than this. */
static const double ABORT_WAIT = 2.0;

/* Refuse new connections at once, so that load balancers and clients
 * move on: the front's listening socket leaves the LISTEN state (connect
 * gets ECONNREFUSED, connections not yet accepted are reset). */
static void stop_listening(srv_server *s) {
  srv_front_stop_listening(s->front);
}

int srv_server_shutdown(srv_server *s) {
  double deadline = srv_now() + s->cfg.shutdown_grace;
  atomic_store(&s->draining, true);
  if (s->daemon == NULL) return 0;
  stop_listening(s);
  /* Jobs stop between frames; queued requests are answered 503 by the
   * workers; requests already computing have the grace to finish. */
  srv_jobs_cancel_all(s->jobs);
  /* Shared jobs are not cancelled: their batches go back to the stream
   * for the other instances, or for this one once it is started again. */
  if (s->rjobs != NULL) srv_rjobs_stop(s->rjobs);
  srv_pool_stop(s->pool);
  if (!wait_until(s, compute_idle, deadline)) {
    srv_log_notice(
        s->log,
        "kmorphd: shutdown grace of %g s passed with %zu requests still "
        "computing: stopping them\n",
        s->cfg.shutdown_grace, (size_t)atomic_load(&s->suspended));
    atomic_store(&s->abort_compute, true);
    deadline = srv_now() + ABORT_WAIT;
    if (!wait_until(s, compute_idle, deadline)) {
      srv_log_notice(s->log,
                     "kmorphd: %zu requests still computing %g s after being "
                     "stopped\n",
                     (size_t)atomic_load(&s->suspended), ABORT_WAIT);
      return -1;
    }
  }
  /* Give answers already queued (or bodies still arriving) until the
   * deadline to complete; idle keep-alive connections do not count. */
  if (!wait_until(s, requests_done, deadline))
    srv_log_notice(s->log, "kmorphd: closing %zu unfinished requests\n",
                   (size_t)atomic_load(&s->inflight));
  MHD_stop_daemon(s->daemon);
  s->daemon = NULL;
  return 0;
}

void srv_server_destroy(srv_server *s) {
  if (s == NULL) return;
  if (s->daemon != NULL) MHD_stop_daemon(s->daemon);
  srv_front_destroy(s->front); /* after: it flushes what the daemon wrote */
  srv_pool_destroy(s->pool);
  if (s->shares_ready) srv_frame_share_destroy(&s->shares);
  if (s->rjobs != NULL) {
    size_t n = srv_rjobs_hand_back_all(s->rjobs);
    if (n > 0)
      srv_log_notice(s->log,
                     "kmorphd: handed %zu batches of shared jobs back\n", n);
  }
  srv_rjobs_destroy(s->rjobs);
  srv_redis_destroy(s->redis);
  srv_jobs_destroy(s->jobs);
  if (s->store) s->store->ops->destroy(s->store);
  srv_metrics_destroy(s->metrics);
  srv_static_cache_destroy(s->statics);
  srv_watch_destroy(s->watch); /* after the HTTP daemon: it closes records */
  free(s);
}
