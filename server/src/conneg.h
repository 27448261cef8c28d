/* conneg.h - content negotiation: the Accept and Accept-Encoding headers
 * (RFC 9110 12.5) and entity tags (If-None-Match, 13.1.2).
 *
 * Everything here works on the strings given: thread-safe,
 * allocation-free. A header absent (NULL) or empty accepts anything for
 * Accept, and nothing but identity for Accept-Encoding (a client that
 * does not say it can decompress is never sent gzip).
 */
#ifndef SRV_CONNEG_H
#define SRV_CONNEG_H

#include <stdbool.h>
#include <stddef.h>

/* The quality the Accept header gives the media type `type` ("a/b", no
 * parameters): the q of the most specific range matching it (a/b, then
 * a/ *, then * / *; parameters other than q ignored), 0 if none matches,
 * 1 for an absent or empty header (or one of commas only). q=0
 * excludes. */
double srv_accept_q(const char *accept, const char *type);

/* Index of the type in types[0..n-1] the Accept header likes best (q >
 * 0; the earlier wins ties), or -1 when it accepts none of them (406). */
int srv_accept_pick(const char *accept, const char *const *types, size_t n);

/* The quality Accept-Encoding gives the coding ("gzip"; x-gzip is the
 * same): its own entry's q, else that of "*", else 0. */
double srv_coding_q(const char *accept_encoding, const char *coding);

/* True when the If-None-Match list names etag (quoted, e.g. "\"ab12\"")
 * by the weak comparison RFC 9110 13.1.2 prescribes, or is "*". */
bool srv_etag_match(const char *if_none_match, const char *etag);

/* A strong entity tag for len bytes at data: 16 hex digits of their
 * 64-bit FNV-1a hash, quoted, then suffix (e.g. "-gz" for the gzip
 * variant; may be ""). out holds at least 20 + strlen(suffix) bytes. */
void srv_etag_of(char *out, size_t cap, const void *data, size_t len,
                 const char *suffix);

#endif
