/* http_guard.h - checks of a request's framing before kmorphd acts on it.
 *
 * libmicrohttpd 0.9.75 frames a request by the first Content-Length or
 * Transfer-Encoding it finds and keeps the rest as plain headers, so a
 * request with two lengths, a length and a coding, or a length written
 * "Content-Length : 5" is framed one way here and another way by any
 * proxy in front: the body can carry a second, hidden request (request
 * smuggling). These checks look at every field line on the first call of
 * the access handler, before the body is read, and say whether the
 * request must be refused (RFC 9112 sections 3.2, 5.1, 6.1, 6.3). They
 * read what libmicrohttpd gives and never the socket; no geometry.
 *
 * Thread-safety: every function works on its arguments only.
 */
#ifndef SRV_HTTP_GUARD_H
#define SRV_HTTP_GUARD_H

#include <microhttpd.h>
#include <stdbool.h>
#include <stddef.h>

/* The raw request target as the URI log callback sees it: before
 * libmicrohttpd splits off the query and percent-decodes it in place,
 * which turns "%00" into a NUL that ends the path early. */
typedef struct srv_http_target {
  const char *raw; /* libmicrohttpd's pointer into its read buffer */
  size_t len;      /* strlen(raw) when it was seen */
  bool nul_escape; /* "%00" somewhere in it */
  bool control;    /* a byte below 0x21 or 0x7f: never valid in a target */
} srv_http_target;

/* Record what the URI log callback was given (uri may be NULL: a request
 * line without a target). Fills *t entirely. */
void srv_http_target_scan(srv_http_target *t, const char *uri);

/* Why a request is refused: status 400 (malformed framing) or 501 (a
 * transfer coding kmorphd does not implement), 0 if it is acceptable. */
typedef struct srv_http_verdict {
  int status;
  char detail[240]; /* names the header (or the request target) at fault */
} srv_http_verdict;

/* Check the request on conn, on the first call of the access handler.
 * method and version are the handler's arguments (libmicrohttpd's
 * pointers into its read buffer); target is what srv_http_target_scan
 * recorded for this request, or NULL if nothing was. Refuses:
 *   - "%00", a control byte or a space in the request target, or a NUL
 *     byte in the request line;
 *   - a field name that is empty or not a token (whitespace before the
 *     colon), a control byte other than HTAB in a field value, and, with
 *     libmicrohttpd up to 0.9.75 whose read buffer layout is known, a NUL
 *     byte inside a field line or an obsolete line folding;
 *   - an HTTP/1.1 request without Host, any request with more than one;
 *   - a Content-Length that is not 1*DIGIT or whose lines disagree
 *     (identical repeated values are accepted, RFC 9112 6.3);
 *   - Transfer-Encoding together with Content-Length, in an HTTP/1.0
 *     request, or whose last coding is not chunked (400); any coding other
 *     than chunked (501).
 * Fills *out (status 0 when nothing is wrong). Never fails. */
void srv_http_check(struct MHD_Connection *conn, const char *method,
                    const char *version, const srv_http_target *target,
                    srv_http_verdict *out);

/* Copy s into out (size n > 0, always terminated) for a log line: bytes
 * that are not token characters (RFC 9110 5.6.2) become '?', so a client
 * cannot add fields, quotes or terminal escapes to the line. */
void srv_http_log_token(char *out, size_t n, const char *s);

/* A suspended connection's peer has sent FIN, or has left: probe it. An
 * HTTP/1.1 peer that only half-closed still reads, and the answer will
 * reach it; one that closed its socket answers data with a reset. The
 * probe is an interim "100 Continue" (RFC 9110 15.2: clients must parse
 * unexpected 1xx answers; http.client, curl and browsers skip it), sent at
 * most once (*sent records it). HTTP/1.0 peers cannot be sent a 1xx, so
 * a FIN alone never counts as gone for them. Returns true if the peer is
 * gone (the probe failed or was answered by a reset), false if the answer
 * may still be delivered. fd is the connection's socket; the caller owns
 * the connection (suspended, so libmicrohttpd does not write to it). */
bool srv_http_fin_probe(int fd, bool http11, bool *sent);

#endif
