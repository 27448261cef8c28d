/* http_syntax.h - the small grammar pieces of RFC 9110 / 9112 that both
 * readers of a request's head share: the front parser over raw bytes
 * (framing.c) and the check of what libmicrohttpd parsed (http_guard.c).
 * One definition, so that the two can never disagree on what a token, a
 * Content-Length or a transfer-coding list is.
 */
#ifndef SRV_HTTP_SYNTAX_H
#define SRV_HTTP_SYNTAX_H

#include <stdbool.h>
#include <stddef.h>

/* RFC 9110 5.6.2 tchar. */
bool srv_http_tchar(unsigned char c);

/* RFC 9112 6.3 Content-Length: 1*DIGIT, here at most 19 digits so that
 * the value fits. True and *out set when v[0..n) is one. */
bool srv_http_decimal(const char *v, size_t n, unsigned long long *out);

/* The elements of a transfer-coding list (RFC 9110 5.6.1: empty elements
 * and whitespace around commas skipped): returns how many there are, and
 * copies the first that is not "chunked" (any case) into other[cap], or
 * leaves other[0] = '\0' when all are. */
unsigned srv_http_codings(const char *v, size_t n, char *other, size_t cap);

#endif
