/* request.h - libmicrohttpd's per-request callbacks: a request's record
 * from its raw target to its complete body (request.c) and to its end
 * (request_done.c), and the budget of request bodies held in memory.
 *
 * DESIGN: the handler is called first with the headers (framing, reserved
 * slots, route, method, content type and Content-Length are checked here
 * so bad requests are refused before any body is read), then with body
 * chunks (collected up to the limit, counted and discarded beyond it),
 * then once with no data: the request is complete and is answered on the
 * I/O thread or handed to a worker (compute.h); after a worker resumed
 * the connection, once more to queue the worker's answer. I/O threads
 * never compute.
 */
#ifndef SRV_REQUEST_H
#define SRV_REQUEST_H

#include "server_internal.h"

/* MHD_OPTION_URI_LOG_CALLBACK (cls is the srv_server): the request's
 * record starts here with its raw target; the value returned is the
 * handler's first *req_cls (NULL if memory is short: the handler then
 * makes the record itself). */
void *srv__on_uri(void *cls, const char *uri, struct MHD_Connection *c);

/* The access handler (MHD_AccessHandlerCallback; cls is the srv_server).
 * Consumes every body chunk it is given (*upload_size becomes 0).
 * Returns MHD_NO to close the connection without an answer (memory
 * short, a body trickled past the request time). */
enum MHD_Result srv__on_request(void *cls, struct MHD_Connection *c,
                                const char *url, const char *method,
                                const char *version, const char *upload,
                                size_t *upload_size, void **req_cls);

/* MHD_OPTION_NOTIFY_COMPLETED (cls is the srv_server; request_done.c):
 * the request ended, answered or not. Counts it in the metrics, writes
 * its access log line (with why it was closed, if it was) and frees its
 * record; *req_cls becomes NULL. Never called while a worker owns the
 * request (libmicrohttpd does not process suspended connections). */
void srv__on_completed(void *cls, struct MHD_Connection *c, void **req_cls,
                       enum MHD_RequestTerminationCode toe);

/* Free r's body and give its bytes back to the budget of bodies in
 * flight. Run by whoever owns r (the I/O thread, or the worker in
 * PH_WAIT); may be called again. */
void srv__body_release(srv_req *r);

#endif
