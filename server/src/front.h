/* front.h - the daemon's listening socket and a relay in front of
 * libmicrohttpd that frames every request itself (framing.h).
 *
 * DESIGN: libmicrohttpd 0.9.75 answers some malformed framing on its own
 * before any handler runs, and wrongly (a first Content-Length of -1 gets
 * its 400 with the header block written twice; a chunk-size line longer
 * than its read buffer gets 500). So the front accepts each connection,
 * hands libmicrohttpd one end of a socket pair (MHD_add_connection, with
 * the client's address, so that the per-address limit and the log see the
 * client) and relays bytes between the client and the other end: client
 * to server only as far as the framing parser passed them, server to
 * client as they come. A request framed wrongly never reaches
 * libmicrohttpd: the front lets it finish the requests before (it sees
 * end of input after them), then writes its own problem+json answer with
 * Connection: close, closes its sending side and reads what the client
 * still sends for a moment, so that the answer is not lost to a reset.
 *
 * A few threads (one epoll set each) serve every connection; each
 * direction has a bounded buffer, and a full one stops reading its source
 * (the kernel's buffers then push back on the sender). A client's FIN is
 * passed on as a FIN (shutdown), a reset or error as the pair's close, so
 * the server's own client-gone checks see on its end what the client did.
 * Connections beyond the limit wait in the listen backlog; out of
 * descriptors, accepting pauses for a moment (the message rate-limited).
 */
#ifndef SRV_FRONT_H
#define SRV_FRONT_H

#include <microhttpd.h>
#include <stdio.h>

#include "log.h"

typedef struct srv_front srv_front;

typedef struct srv_front_options {
  const char *bind;         /* IPv4 or IPv6 literal */
  unsigned port;            /* 0: the OS chooses */
  unsigned threads;         /* relay threads, at least 1 */
  unsigned max_connections; /* open connections before accept waits */
  double drain_time;        /* seconds a client has to read what the server
                            * wrote once the server closed its end */
  bool access_log;          /* log a line per refused request */
  srv_log *logger;          /* rate limit of repeated messages (borrowed) */
  FILE *log;                /* where lines go (borrowed) */
} srv_front_options;

/* Bind and listen (nothing is accepted before srv_front_start). NULL,
 * with a message in o->log, if the address is bad or in use or memory is
 * short. */
srv_front *srv_front_listen(const srv_front_options *o);

/* The port bound. */
unsigned srv_front_port(const srv_front *f);

/* Start the relay threads: accepted connections go to d, which must run
 * with MHD_USE_NO_LISTEN_SOCKET and internal threads. Returns 0, or -1
 * with a message. */
int srv_front_start(srv_front *f, struct MHD_Daemon *d);

/* Stop accepting at once: the listening socket leaves the LISTEN state
 * (connect is refused, connections not yet accepted are reset). Open
 * connections are relayed as before. Thread-safe. */
void srv_front_stop_listening(srv_front *f);

/* Requests refused by the front so far. Thread-safe. */
unsigned long srv_front_refused(const srv_front *f);

/* After libmicrohttpd stopped: give clients up to a second to receive
 * what was written to them, close every connection, join the threads and
 * free. Accepts NULL. */
void srv_front_destroy(srv_front *f);

#endif
