/* server_internal.h - the server object and the request record, shared by
 * the files of the HTTP layer (server.c, request.c, request_done.c,
 * reply.c, route.c, compute.c, job_endpoints.c, info_endpoints.c).
 *
 * DESIGN: libmicrohttpd calls the access handler several times per
 * request (headers, body chunks, the final call, and once more after a
 * worker resumed the connection), so a request's state lives in one
 * srv_req that libmicrohttpd keeps as the request's closure. Ownership
 * moves with the phase: the I/O thread owns the record in PH_BODY and
 * PH_READY/PH_ANSWERED, the compute worker in PH_WAIT (the connection is
 * suspended, so libmicrohttpd never calls back in that phase). Fields
 * written by the worker are read by the I/O thread only after
 * MHD_resume_connection, which orders them.
 */
#ifndef SRV_SERVER_INTERNAL_H
#define SRV_SERVER_INTERNAL_H

#include <microhttpd.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

#include "config.h"
#include "frame_share.h"
#include "front.h"
#include "http_guard.h"
#include "jobs.h"
#include "jobs_redis.h"
#include "jobstore.h"
#include "kmapi/api.h"
#include "log.h"
#include "metrics.h"
#include "pool.h"
#include "static_cache.h"
#include "server.h"
#include "watch.h"

struct srv_server {
  srv_config cfg;  /* the configuration, copied at creation */
  api_config api;  /* the api layer's limits, derived from cfg */
  FILE *log;       /* srv_log_stream(logger): the same FILE for life */
  srv_log *logger; /* rate-limits libmicrohttpd's messages */
  struct MHD_Daemon *daemon; /* written by the main thread after start:
                              * I/O threads get theirs from the connection */
  srv_front *front;          /* accepts, frames and relays (front.h) */
  unsigned port;             /* the port bound (cfg.port may be 0) */
  srv_pool *pool;            /* compute workers and their bounded queue */
  srv_frame_share shares;    /* synchronous morphs' frames, for idle workers
                              * to help with (frame_share.h) */
  bool shares_ready;         /* shares initialised (destroy once) */
  srv_jobstore *store;       /* jobs' states and results */
  srv_jobs *jobs;            /* admission and running of asynchronous jobs */
  srv_redis *redis;          /* --jobs: connections to Redis, else NULL */
  srv_rjobs *rjobs;          /* --jobs: jobs shared through Redis (then
                              * they, not store and jobs, hold every job),
                              * else NULL */
  srv_metrics *metrics;      /* counters and histograms for /metrics */
  srv_watch *watch;          /* deadlines libmicrohttpd does not enforce */
  atomic_bool draining;      /* shutdown began: refuse new work, close */
  atomic_bool abort_compute; /* grace over: every computation stops now */
  atomic_size_t suspended;   /* connections waiting for a worker */
  atomic_size_t inflight;    /* requests begun and not yet completed */
  atomic_size_t body_bytes;  /* buffers of request bodies held now */
  srv_static_cache *statics; /* the page's files and the contract, with
                              * entity tags and gzip forms (made once) */
  atomic_size_t gz_streams;  /* answers being gzip-coded as sent (gzip.h) */
};

/* Where a request is in its life; srv_req.phase. */
typedef enum srv_phase {
  PH_BODY,    /* headers seen, body arriving */
  PH_WAIT,    /* suspended, a worker owns the request */
  PH_READY,   /* the worker filled resp and resumed the connection */
  PH_ANSWERED /* a response is queued: later calls do nothing */
} srv_phase;

/* Why a computation's stop condition fired; srv_req.stopped. */
enum { STOP_NONE, STOP_TIME, STOP_GONE, STOP_SHUTDOWN };

/* Sizes of the request record's text fields, terminator included. */
enum {
  SRV_METHOD_MAX = 12, /* longer methods are cut: only known ones route */
  SRV_PATH_MAX = 160,  /* the path as logged (cut, made printable) */
  SRV_RID_MAX = 65,    /* 64 characters (srv_request_id_ok) */
  SRV_STATIC_MAX = 104 /* static names are at most 100 characters */
};

typedef struct srv_req {
  srv_server *srv;                  /* the server (borrowed) */
  struct MHD_Connection *conn;      /* the request's connection (borrowed) */
  srv_route route;                  /* what the target names (route.h) */
  char method[SRV_METHOD_MAX];      /* the request method, as sent */
  char path[SRV_PATH_MAX];          /* the target for the access log */
  char rid[SRV_RID_MAX];            /* X-Request-Id: the client's or ours */
  char job_id[SRV_JOB_ID_LEN + 1];  /* the job a /v1/jobs/{id} target names,
                                    * or the one POST /v1/jobs created */
  char static_name[SRV_STATIC_MAX]; /* file under the web root (STATIC) */
  char *accept;           /* the Accept header of a compute request (owned) */
  char *body;             /* the body collected so far (owned, NUL-ended) */
  size_t len;             /* bytes in body */
  size_t cap;             /* bytes allocated for body */
  size_t seen;            /* body bytes received, kept or not */
  size_t held;            /* bytes of body buffer counted in srv->body_bytes */
  bool no_memory;         /* the body did not fit the budget of bodies */
  bool too_large;         /* the body is over cfg.max_body: answered 413 */
  double t0;              /* srv_now() when the headers were in */
  atomic_int phase;       /* srv_phase */
  api_response resp;      /* written by the worker before resuming */
  bool location;          /* add Location for a created job */
  bool counted;           /* included in srv->suspended */
  double deadline;        /* compute stops here (srv_now() seconds) */
  double next_gone_check; /* when the stop condition next looks at the
                           * socket (srv_now() seconds) */
  int stopped;            /* why the compute stop condition fired: STOP_* */
  int status;             /* the status queued, for the log; 0 if none */
  size_t bytes;           /* the length of the body queued, for the log */
  const char *cut;        /* why the connection was closed without an answer */
  srv_http_target target; /* the raw request target (URI log callback) */
  bool begun;             /* req_new has run: the handler saw the headers */
  bool must_close;        /* the framing was refused: no keep-alive */
  bool http11;            /* the client may be sent an interim 1xx */
  bool probed;            /* a FIN was seen and answered with a probe */
  bool poll_hint;         /* a job not final: Retry-After says when to poll */
} srv_req;

/* The watch record of r's connection (NULL if it is not watched). */
srv_conn *srv__req_conn(const srv_req *r);

#endif
