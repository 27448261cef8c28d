/* jobs_redis_internal.h - what the files of the Redis job runner share:
 * jobstore_redis.c (records: create, read, cancel, finish), jobs_redis.c
 * (batches: take, render, reclaim, hand back), jobs_plans.c (prepared
 * plans per instance) and jobs_redis_metrics.c (/metrics lines). */
#ifndef SRV_JOBS_REDIS_INTERNAL_H
#define SRV_JOBS_REDIS_INTERNAL_H

#include <pthread.h>
#include <stdatomic.h>

#include "jobs_redis.h"

#define RJ_STREAM "kmorph:work"
#define RJ_GROUP "workers"
#define RJ_LIVE "kmorph:live"
/* Every work stream: the shared one and each instance's own. */
#define RJ_STREAMS "kmorph:streams"
#define RJ_STREAMS_MAX 64
#define RJ_KEY_MAX 128

/* A prepared plan cached per job id in this instance. */
typedef struct rj_plan {
  struct rj_plan *next;
  char id[SRV_JOB_ID_LEN + 1];
  api_morph_plan *plan;
  size_t refs;
  double used; /* srv_now() of the last use, for eviction */
} rj_plan;

struct srv_rjobs {
  srv_redis *rd;
  srv_rjobs_config cfg;
  char consumer[96];      /* this instance in the consumer group */
  char local[RJ_KEY_MAX]; /* this instance's own stream: the solo batches
                           * of the jobs it accepted, which it takes
                           * first and the others only when idle */
  char streams[RJ_STREAMS_MAX][RJ_KEY_MAX]; /* RJ_STREAMS as last read */
  size_t nstreams;                          /* guarded by mu */
  pthread_mutex_t mu;
  rj_plan *plans; /* guarded by mu */
  size_t nplans;
  atomic_bool stopping;
  atomic_bool group_ok;      /* the consumer group is known to exist */
  atomic_size_t busy;        /* batches being rendered now */
  atomic_size_t frames;      /* frames rendered by this instance */
  atomic_size_t reclaimed;   /* batches claimed from a silent consumer */
  atomic_size_t handed;      /* batches handed back on stopping */
  atomic_size_t assembled;   /* results assembled by this instance */
  atomic_size_t prepared;    /* plans prepared from a stored request */
  _Atomic double next_claim; /* srv_now(): next XAUTOCLAIM */
  bool (*yield)(void *ctx);  /* run waiting requests between frames */
  void *yield_ctx;
};

/* Unix seconds (records are read by other hosts' instances). */
double srv__rj_wall(void);

/* Keys of job id into buf (cap bytes). */
void srv__rj_key(char *buf, size_t cap, const char *kind, const char *id);

/* A command on c; NULL when the connection failed (*broken set), else
 * the reply (an error reply included), which the caller frees. */
redisReply *srv__rj_cmd(redisContext *c, bool *broken, const char *fmt, ...);

/* Make the job final (done, failed or cancelled) if it is live: result
 * (may be NULL) stored for the ttl with its content type, the error
 * status and text (may be NULL). Returns 1 if it was live, 0 if not,
 * -1 on a broken connection. */
int srv__rj_finish(srv_rjobs *j, redisContext *c, const char *id,
                   srv_job_state state, const api_response *result,
                   int error_status, const char *error);

/* Keep plan (taken) as job id's prepared plan in this instance. */
void srv__rj_cache_put(srv_rjobs *j, const char *id, api_morph_plan *plan);
/* Drop job id's cached plan, if it is not in use. */
void srv__rj_cache_drop(srv_rjobs *j, const char *id);
/* Job id's cached plan with a reference held, or NULL. */
rj_plan *srv__rj_cache_ref(srv_rjobs *j, const char *id);
/* Job id's plan prepared from its stored request (body of len bytes,
 * accept "" for none), cached, with a reference held. NULL with the
 * problem's status in *status and the reason in why if it cannot be
 * prepared. */
rj_plan *srv__rj_cache_prepare(srv_rjobs *j, const char *id, const char *body,
                               size_t len, const char *accept, int *status,
                               char *why, size_t whycap);
/* Drop a reference from srv__rj_cache_ref or _prepare. */
void srv__rj_cache_release(srv_rjobs *j, rj_plan *p);

#endif
