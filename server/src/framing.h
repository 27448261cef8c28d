/* framing.h - where each request on a connection begins and ends, read
 * from the raw bytes a client sends (RFC 9112), before libmicrohttpd sees
 * them.
 *
 * DESIGN: a connection's input is a byte stream held in one buffer; the
 * parser walks it and says how much of it is framed correctly and may be
 * passed on (safe) and how far it has read (pos). A request's header block
 * and a chunked body's trailer section are held back until their empty
 * line arrived and every line passed; body bytes and chunk data pass as
 * soon as they are counted. A chunk-size line is passed on without its
 * extensions (they mean nothing here), so the next reader only ever sees a
 * few hexadecimal digits. What cannot be framed one way only (RFC 9112
 * 6.3, 7.1) ends the connection's parse with a status (400, 431, 501) and
 * a detail naming the header or line at fault; nothing from that request
 * on is ever passed on. A fault inside a chunked body comes after its
 * head was passed on: the request is then ended for the server with a
 * last chunk and a trailer field (SRV_FRAMING_REFUSED_FIELD) that carries
 * the detail, and the server answers the refusal in its turn.
 *
 * What is checked: the request line has three parts and no NUL or lone
 * CR (libmicrohttpd 0.9.75 ends a line at a lone CR); each field line is
 * a token name, a colon and a value without control bytes; not folded;
 * Content-Length is digits only, repeated only with the same value;
 * Transfer-Encoding is exactly "chunked" (another coding is 501), on
 * HTTP/1.1 only and never with Content-Length; each chunk-size line is at
 * most SRV_FRAMING_CHUNK_LINE_MAX bytes; chunk data ends with CRLF; the
 * head and the trailers fit SRV_FRAMING_HEAD_MAX bytes and
 * SRV_FRAMING_FIELDS_MAX lines. Host and the
 * target are left to http_guard.c, which sees them parsed.
 */
#ifndef SRV_FRAMING_H
#define SRV_FRAMING_H

#include <stdbool.h>
#include <stddef.h>

/* Bytes of a request's header block (request line to the empty line) or
 * of a trailer section, and field lines in one. libmicrohttpd keeps the
 * block and a record per field in 32 KiB of connection memory and closes
 * without an answer when a block of about 32,380 bytes does not fit (it
 * answers its own 431 to some 600 short fields); half of it leaves room
 * for the records (Apache also allows 100 fields by default). More is
 * answered 431 here. */
#define SRV_FRAMING_HEAD_MAX 16384
#define SRV_FRAMING_FIELDS_MAX 100
/* Bytes of a chunk-size line before its CRLF, extensions included.
 * libmicrohttpd 0.9.75 answers 500 to a line longer than its read buffer;
 * a size and a few short extensions take well under 100 bytes. Longer is
 * answered 400. */
#define SRV_FRAMING_CHUNK_LINE_MAX 4096

/* The trailer field that ends a chunked request refused inside its body;
 * its value is the detail. A client's own field of this name is refused. */
#define SRV_FRAMING_REFUSED_FIELD "X-Kmorph-Framing-Refused"

typedef struct srv_framing {
  int state;                    /* where in a request the parse is */
  bool http11;                  /* the current request says HTTP/1.1 */
  unsigned fields;              /* field lines in this head or trailer */
  unsigned lengths;             /* Content-Length lines in this head */
  unsigned codings;             /* transfer codings named in this head */
  bool exact_chunked;           /* each Transfer-Encoding was "chunked" */
  unsigned long long length;    /* the Content-Length value */
  unsigned long long remaining; /* body or chunk bytes still to count */
  char coding[40];              /* the first coding other than chunked */
  unsigned requests;            /* requests whose head passed */
  int status;                   /* 0, or the refusal's HTTP status */
  int refused_in;               /* the state the refusal came in */
  char detail[224];             /* why, naming the header or line */
} srv_framing;

/* A connection's input as the parser sees it: data[0, len) held, of which
 * [0, safe) may be passed on and [0, pos) has been read. */
typedef struct srv_framing_buf {
  char *data;
  size_t len;
  size_t pos;
  size_t safe;
} srv_framing_buf;

/* Start a connection's parse. */
void srv_framing_init(srv_framing *f);

/* Read what b holds from b->pos on, as far as it can be framed: advances
 * b->pos and b->safe, and may shorten b->len (a chunk-size line loses its
 * extensions, the bytes after it move down). Stops at a line that is not
 * complete yet. Once f->status is set (a refusal) it does nothing more;
 * b->safe then ends before the refused request. */
void srv_framing_scan(srv_framing *f, srv_framing_buf *b);

/* True between requests: no part of one is held or being counted. */
bool srv_framing_idle(const srv_framing *f);

/* After a refusal inside a chunked body: the bytes that end that body
 * for the server (a last chunk if need be, SRV_FRAMING_REFUSED_FIELD with
 * the detail, the empty line), written to out; returns their length, or
 * 0 if the refused request's head was held (nothing of it passed on). */
size_t srv_framing_ending(const srv_framing *f, char *out, size_t cap);

#endif
