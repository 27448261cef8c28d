/* watch.h - deadlines of open connections that libmicrohttpd does not
 * enforce: the time to receive a request's header and body, and the time
 * to deliver an answer.
 *
 * DESIGN: libmicrohttpd's only clock is the idle timeout, and every byte
 * resets it, so a client sending one header byte a second (slowloris) or
 * reading one answer byte a second holds its slot for ever. Each
 * connection gets a record (libmicrohttpd's per-connection socket
 * context) whose phase and deadline the request handler updates; one
 * thread sweeps the records four times a second. A header or body past
 * its deadline is answered 408 on the socket directly (libmicrohttpd is
 * only reading then, never writing) and the socket is shut down, which
 * libmicrohttpd sees as the client closing; an answer past its deadline
 * is cut. Records are removed by libmicrohttpd's close notification,
 * which comes before it closes the socket, under the same lock as the
 * sweep: the sweep never touches a descriptor that was closed or reused.
 * A connection opened while more than `normal` are open takes a reserved
 * slot: it gets a short header deadline and may only ask for a probe
 * route (the caller checks srv_conn_reserved), so that /healthz answers
 * while ordinary slots are full.
 *
 * Thread-safety: every function may be called from any thread.
 */
#ifndef SRV_WATCH_H
#define SRV_WATCH_H

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

typedef struct srv_watch_limits {
  double header_time;  /* seconds from a request's start to its header */
  double request_time; /* seconds from a request's start to its body end */
  double send_time;    /* seconds to deliver one answer */
  double idle_time;    /* keep-alive wait before a next request starts */
  double reserved_header_time; /* header time on a reserved slot */
  unsigned normal; /* open connections beyond which slots are reserved */
} srv_watch_limits;

typedef struct srv_watch srv_watch;
typedef struct srv_conn srv_conn;

/* Start the sweeping thread. log receives one line per sweep that cut
 * connections. NULL if memory or a thread is short. */
srv_watch *srv_watch_create(const srv_watch_limits *limits, FILE *log);

/* Stop the thread and free the records. Accepts NULL. */
void srv_watch_destroy(srv_watch *w);

/* A connection on socket fd was accepted at now (seconds, srv_now()): its
 * first request's header is due. NULL if out of memory (the connection is
 * then not watched). */
srv_conn *srv_watch_open(srv_watch *w, int fd, double now);

/* The connection is closing (before its socket is closed). Accepts NULL. */
void srv_watch_close(srv_watch *w, srv_conn *c);

/* Whether the connection took a reserved slot. False for NULL. */
bool srv_conn_reserved(const srv_conn *c);

/* Phases of a request; each accepts NULL. The header arrived (the body is
 * due by the request time), the body arrived (the answer is computed: no
 * deadline here, compute has its own), the answer was queued (it is due
 * by the send time), the request completed (the next one may start). */
void srv_watch_header_done(srv_conn *c, double now);
void srv_watch_body_done(srv_conn *c);
void srv_watch_answer_queued(srv_conn *c, double now);
void srv_watch_request_done(srv_conn *c, double now);

/* Connections cut so far: header or body late (answered 408), answer
 * late. */
void srv_watch_counts(srv_watch *w, size_t *late_request, size_t *late_send);

#endif
