/* watch.c - deadlines of open connections (see watch.h). */
#include "watch.h"

#include <errno.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>

#include "log.h"
#include "util.h"

typedef enum conn_phase {
  CP_HEADER,  /* waiting for a request's header */
  CP_BODY,    /* header in, body arriving */
  CP_COMPUTE, /* request complete, answer being computed */
  CP_SENDING, /* answer queued, being delivered */
  CP_CUT      /* shut down by the sweep; libmicrohttpd closes it */
} conn_phase;

struct srv_conn {
  srv_conn *prev, *next;
  srv_watch *w;
  int fd;
  conn_phase phase;
  double start;    /* when the current request (or its wait) began */
  double deadline; /* of the current phase; 0 = none */
  bool reserved;
  bool kept_alive; /* a request before this one completed */
};

struct srv_watch {
  pthread_mutex_t mu;
  pthread_cond_t cv;
  srv_conn *first;
  size_t open;
  srv_watch_limits lim;
  FILE *log;
  bool stopping;
  size_t late_request, late_send;
  pthread_t thread;
};

/* The 408 written on a socket whose request is late, with a request id
 * of its own (nothing of the request is known): also in X-Request-Id and
 * the problem's instance, as for every other problem. */
static int late_text(char *out, size_t cap) {
  char rid[17];
  srv_random_hex(rid, 16);
  char body[400];
  int bn = snprintf(
      body, sizeof body,
      "{\"type\":\"/problems/request-timeout\",\"title\":\"Request "
      "timeout\",\"status\":408,\"detail\":\"the request did not arrive "
      "within the time allowed to send it (KMORPH_HEADER_TIME for the "
      "header, KMORPH_REQUEST_TIME for the whole request)\",\"request_id\":"
      "\"%s\",\"instance\":\"urn:kmorph:request:%s\"}",
      rid, rid);
  if (bn < 0 || (size_t)bn >= sizeof body) return 0;
  return snprintf(out, cap,
                  "HTTP/1.1 408 Request Timeout\r\n"
                  "Content-Type: application/problem+json\r\n"
                  "Connection: close\r\n"
                  "Cache-Control: no-store\r\n"
                  "X-Request-Id: %s\r\n"
                  "Content-Length: %d\r\n"
                  "\r\n%s",
                  rid, bn, body);
}

static void cut(srv_watch *w, srv_conn *c, bool answer) {
  if (answer) {
    char late[640];
    int len = late_text(late, sizeof late);
    ssize_t n =
        len > 0 && (size_t)len < sizeof late
            ? send(c->fd, late, (size_t)len, MSG_NOSIGNAL | MSG_DONTWAIT)
            : 0;
    (void)n; /* a full send buffer: the client is not reading anyway */
    w->late_request++;
  } else {
    w->late_send++;
  }
  /* libmicrohttpd sees end of input (or a failed send) and closes. */
  shutdown(c->fd, SHUT_RDWR);
  c->phase = CP_CUT;
  c->deadline = 0;
}

static void sweep(srv_watch *w, double now) {
  size_t requests = 0, sends = 0;
  for (srv_conn *c = w->first; c; c = c->next) {
    if (c->deadline == 0 || now < c->deadline) continue;
    bool late_request = c->phase == CP_HEADER || c->phase == CP_BODY;
    cut(w, c, late_request);
    if (late_request)
      requests++;
    else
      sends++;
  }
  if ((requests > 0 || sends > 0) && w->log != NULL)
    srv_log_notice(
        w->log,
        "kmorphd: cut %zu connections whose request was late (408) and "
        "%zu whose answer was not read in time\n",
        requests, sends);
}

static void *sweeper(void *arg) {
  srv_watch *w = arg;
  pthread_mutex_lock(&w->mu);
  while (!w->stopping) {
    sweep(w, srv_now());
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    ts.tv_nsec += 250 * 1000 * 1000;
    if (ts.tv_nsec >= 1000000000L) {
      ts.tv_sec++;
      ts.tv_nsec -= 1000000000L;
    }
    pthread_cond_timedwait(&w->cv, &w->mu, &ts);
  }
  pthread_mutex_unlock(&w->mu);
  return NULL;
}

srv_watch *srv_watch_create(const srv_watch_limits *limits, FILE *log) {
  srv_watch *w = calloc(1, sizeof *w);
  if (w == NULL) return NULL;
  w->lim = *limits;
  w->log = log;
  pthread_mutex_init(&w->mu, NULL);
  pthread_cond_init(&w->cv, NULL);
  if (pthread_create(&w->thread, NULL, sweeper, w) != 0) {
    pthread_mutex_destroy(&w->mu);
    pthread_cond_destroy(&w->cv);
    free(w);
    return NULL;
  }
  return w;
}

void srv_watch_destroy(srv_watch *w) {
  if (w == NULL) return;
  pthread_mutex_lock(&w->mu);
  w->stopping = true;
  pthread_cond_broadcast(&w->cv);
  pthread_mutex_unlock(&w->mu);
  pthread_join(w->thread, NULL);
  while (w->first) {
    srv_conn *c = w->first;
    w->first = c->next;
    free(c);
  }
  pthread_mutex_destroy(&w->mu);
  pthread_cond_destroy(&w->cv);
  free(w);
}

static double header_time(const srv_conn *c) {
  return c->reserved ? c->w->lim.reserved_header_time : c->w->lim.header_time;
}

srv_conn *srv_watch_open(srv_watch *w, int fd, double now) {
  srv_conn *c = calloc(1, sizeof *c);
  if (c == NULL) return NULL;
  c->w = w;
  c->fd = fd;
  c->phase = CP_HEADER;
  c->start = now;
  pthread_mutex_lock(&w->mu);
  c->reserved = w->open >= w->lim.normal;
  c->deadline = now + header_time(c);
  c->next = w->first;
  if (w->first) w->first->prev = c;
  w->first = c;
  w->open++;
  pthread_mutex_unlock(&w->mu);
  return c;
}

void srv_watch_close(srv_watch *w, srv_conn *c) {
  if (c == NULL) return;
  pthread_mutex_lock(&w->mu);
  if (c->prev)
    c->prev->next = c->next;
  else
    w->first = c->next;
  if (c->next) c->next->prev = c->prev;
  w->open--;
  pthread_mutex_unlock(&w->mu);
  free(c);
}

bool srv_conn_reserved(const srv_conn *c) {
  return c != NULL && c->reserved;
}

/* Move c to phase p with deadline d (0 = none), unless the sweep cut it. */
static void set_phase(srv_conn *c, conn_phase p, double d) {
  if (c == NULL) return;
  pthread_mutex_lock(&c->w->mu);
  if (c->phase != CP_CUT) {
    c->phase = p;
    c->deadline = d;
  }
  pthread_mutex_unlock(&c->w->mu);
}

/* The request time counts from the connection's start for its first
 * request, and from the header's arrival for later ones (when their
 * first byte came is not known). */
void srv_watch_header_done(srv_conn *c, double now) {
  if (c != NULL)
    set_phase(c, CP_BODY,
              (c->kept_alive ? now : c->start) + c->w->lim.request_time);
}

void srv_watch_body_done(srv_conn *c) {
  set_phase(c, CP_COMPUTE, 0);
}

void srv_watch_answer_queued(srv_conn *c, double now) {
  if (c != NULL) set_phase(c, CP_SENDING, now + c->w->lim.send_time);
}

/* The next request on a kept-alive connection may wait the idle time
 * before its first byte (libmicrohttpd's timeout closes an idle one), and
 * then has the header time: libmicrohttpd does not say when that byte
 * came, so the deadline is their sum from the end of this request. */
void srv_watch_request_done(srv_conn *c, double now) {
  if (c == NULL) return;
  pthread_mutex_lock(&c->w->mu);
  if (c->phase != CP_CUT) {
    c->phase = CP_HEADER;
    c->start = now;
    c->kept_alive = true;
    c->deadline = now + c->w->lim.idle_time + header_time(c);
  }
  pthread_mutex_unlock(&c->w->mu);
}

void srv_watch_counts(srv_watch *w, size_t *late_request, size_t *late_send) {
  pthread_mutex_lock(&w->mu);
  *late_request = w->late_request;
  *late_send = w->late_send;
  pthread_mutex_unlock(&w->mu);
}
