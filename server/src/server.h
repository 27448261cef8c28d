/* server.h - the kmorphd HTTP server: routing, admission control, compute
 * hand-off, jobs, CORS, request ids, access log and graceful shutdown.
 *
 * All state lives in one srv_server; nothing is global.
 */
#ifndef SRV_SERVER_H
#define SRV_SERVER_H

#include <stdio.h>

#include "config.h"
#include "log.h"

typedef struct srv_server srv_server;

/* Create the server (pools, job store, metrics) from cfg (copied; workers
 * must be > 0 already). log (borrowed; it must outlive the server)
 * receives the access log and notices, libmicrohttpd's messages rate-
 * limited. NULL if memory or threads are short (a message is printed to
 * log). */
srv_server *srv_server_create(const srv_config *cfg, srv_log *log);

/* Bind and start serving. Returns 0, or -1 with a message in the log
 * (address in use, bad bind address). */
int srv_server_start(srv_server *s);

/* The port actually bound (useful with --port 0). */
unsigned srv_server_port(const srv_server *s);

/* Graceful stop: close the listening socket (new connections are refused
 * at once; open ones get /readyz 503 and Connection: close), answer
 * queued compute with 503, cancel jobs, and give running requests
 * cfg.shutdown_grace seconds to finish. When the grace runs out, every
 * computation still running is told to stop and answers 503, within a
 * further 2 s; then the HTTP daemon stops. Returns 0 when everything
 * stopped cleanly; -1 when computations outlived even that (the HTTP
 * daemon is then left running and the caller should exit the process at
 * once). Call from one thread, once. */
int srv_server_shutdown(srv_server *s);

/* Free everything (after srv_server_shutdown returned 0, or if never
 * started). Accepts NULL. */
void srv_server_destroy(srv_server *s);

#endif
