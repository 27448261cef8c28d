/* redis_conn.c - a pool of hiredis contexts with timeouts and reconnect
 * backoff (see redis_conn.h). */
#include "redis_conn.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/time.h>

#include "util.h"

/* Idle contexts kept; more borrowed at once are connected and freed. */
#define IDLE_MAX 16
static const double CONNECT_TIMEOUT = 0.5; /* seconds */
static const double COMMAND_TIMEOUT = 2.0; /* seconds */
static const double BACKOFF_MIN = 0.1, BACKOFF_MAX = 2.0;

struct srv_redis {
  char host[256];
  int port;
  int db;
  char name[300];
  pthread_mutex_t mu;
  redisContext *idle[IDLE_MAX];
  size_t nidle;
  double next_try; /* srv_now(): no connection attempt before */
  double backoff;  /* seconds to wait after the next failed attempt */
  atomic_bool up;
};

static bool parse_url(srv_redis *r, const char *url, char *err, size_t errlen) {
  static const char scheme[] = "redis://";
  if (strncmp(url, scheme, sizeof scheme - 1) != 0) {
    snprintf(err, errlen, "--jobs wants redis://HOST:PORT/DB, not \"%s\"", url);
    return false;
  }
  const char *h = url + sizeof scheme - 1;
  size_t hl = strcspn(h, ":/");
  if (hl == 0 || hl >= sizeof r->host) {
    snprintf(err, errlen, "--jobs: no host in \"%s\"", url);
    return false;
  }
  memcpy(r->host, h, hl);
  r->host[hl] = '\0';
  const char *p = h + hl;
  r->port = 6379;
  r->db = 0;
  char *end;
  if (*p == ':') {
    long v = strtol(p + 1, &end, 10);
    if (end == p + 1 || v < 1 || v > 65535) {
      snprintf(err, errlen, "--jobs: bad port in \"%s\"", url);
      return false;
    }
    r->port = (int)v;
    p = end;
  }
  if (*p == '/' && p[1] != '\0') {
    long v = strtol(p + 1, &end, 10);
    if (end == p + 1 || *end != '\0' || v < 0 || v > 15) {
      snprintf(err, errlen, "--jobs: bad database number in \"%s\"", url);
      return false;
    }
    r->db = (int)v;
  } else if (*p != '\0' && strcmp(p, "/") != 0) {
    snprintf(err, errlen, "--jobs: cannot read \"%s\"", url);
    return false;
  }
  snprintf(r->name, sizeof r->name, "%s:%d/%d", r->host, r->port, r->db);
  return true;
}

srv_redis *srv_redis_create(const char *url, char *err, size_t errlen) {
  srv_redis *r = calloc(1, sizeof *r);
  if (r == NULL) {
    snprintf(err, errlen, "out of memory");
    return NULL;
  }
  if (!parse_url(r, url, err, errlen)) {
    free(r);
    return NULL;
  }
  pthread_mutex_init(&r->mu, NULL);
  r->backoff = BACKOFF_MIN;
  atomic_init(&r->up, true);
  return r;
}

static struct timeval tv_of(double s) {
  struct timeval tv = {(time_t)s, (suseconds_t)((s - (double)(time_t)s) * 1e6)};
  return tv;
}

/* A new context, connected, timed and on the right database; NULL if
 * any step failed. */
static redisContext *connect_one(const srv_redis *r) {
  redisContext *c =
      redisConnectWithTimeout(r->host, r->port, tv_of(CONNECT_TIMEOUT));
  if (c == NULL || c->err) goto fail;
  if (redisSetTimeout(c, tv_of(COMMAND_TIMEOUT)) != REDIS_OK) goto fail;
  if (r->db != 0) {
    redisReply *rep = redisCommand(c, "SELECT %d", r->db);
    bool ok = rep != NULL && rep->type == REDIS_REPLY_STATUS;
    if (rep) freeReplyObject(rep);
    if (!ok) goto fail;
  }
  return c;
fail:
  if (c) redisFree(c);
  return NULL;
}

redisContext *srv_redis_acquire(srv_redis *r) {
  pthread_mutex_lock(&r->mu);
  if (r->nidle > 0) {
    redisContext *c = r->idle[--r->nidle];
    pthread_mutex_unlock(&r->mu);
    return c;
  }
  double now = srv_now();
  if (now < r->next_try) {
    pthread_mutex_unlock(&r->mu);
    return NULL;
  }
  /* One attempt at a time while down: the others see next_try ahead. */
  bool was_up = atomic_load(&r->up);
  if (!was_up) r->next_try = now + r->backoff;
  pthread_mutex_unlock(&r->mu);

  redisContext *c = connect_one(r);

  pthread_mutex_lock(&r->mu);
  if (c != NULL) {
    r->backoff = BACKOFF_MIN;
    r->next_try = 0;
    atomic_store(&r->up, true);
  } else {
    atomic_store(&r->up, false);
    r->next_try = srv_now() + r->backoff;
    r->backoff = r->backoff * 2 > BACKOFF_MAX ? BACKOFF_MAX : r->backoff * 2;
  }
  pthread_mutex_unlock(&r->mu);
  return c;
}

void srv_redis_release(srv_redis *r, redisContext *c, bool broken) {
  if (c == NULL) return;
  if (broken || c->err) {
    redisFree(c);
    pthread_mutex_lock(&r->mu);
    /* Drop the idle ones too: after a server restart they are all dead. */
    for (size_t i = 0; i < r->nidle; i++) redisFree(r->idle[i]);
    r->nidle = 0;
    atomic_store(&r->up, false);
    pthread_mutex_unlock(&r->mu);
    return;
  }
  pthread_mutex_lock(&r->mu);
  if (r->nidle < IDLE_MAX) {
    r->idle[r->nidle++] = c;
    c = NULL;
  }
  pthread_mutex_unlock(&r->mu);
  if (c) redisFree(c);
}

bool srv_redis_up(const srv_redis *r) {
  return atomic_load(&r->up);
}

bool srv_redis_ping(srv_redis *r) {
  redisContext *c = srv_redis_acquire(r);
  if (c == NULL) return false;
  redisReply *rep = redisCommand(c, "PING");
  bool ok = rep != NULL && rep->type == REDIS_REPLY_STATUS;
  if (rep) freeReplyObject(rep);
  srv_redis_release(r, c, !ok);
  return ok;
}

const char *srv_redis_name(const srv_redis *r) {
  return r->name;
}

void srv_redis_destroy(srv_redis *r) {
  if (r == NULL) return;
  for (size_t i = 0; i < r->nidle; i++) redisFree(r->idle[i]);
  pthread_mutex_destroy(&r->mu);
  free(r);
}
