/* framing.c - request framing read from the raw byte stream (see
 * framing.h). */
#include "framing.h"

#include "http_syntax.h"

#include <stdio.h>
#include <string.h>
#include <strings.h>

enum {
  FR_REQUEST_LINE, /* before a request (empty lines are skipped) */
  FR_FIELDS,       /* in a header block, held */
  FR_BODY,         /* counting a Content-Length body */
  FR_CHUNK_SIZE,   /* at a chunk-size line */
  FR_CHUNK_DATA,   /* counting a chunk's data */
  FR_CHUNK_END,    /* at the CRLF after a chunk's data */
  FR_TRAILERS,     /* in the trailer section after the last chunk, held */
  FR_REFUSED       /* nothing more is read */
};

void srv_framing_init(srv_framing *f) {
  memset(f, 0, sizeof *f);
  f->state = FR_REQUEST_LINE;
}

/* Refuse with status and a detail (fmt has one %s for the name shown);
 * the first fault found is the one told. */
static void refuse(srv_framing *f, int status, const char *fmt,
                   const char *name, size_t name_len) {
  if (f->status != 0) return;
  char shown[48];
  size_t k = 0;
  for (; k < name_len && k + 1 < sizeof shown; k++) {
    unsigned char c = (unsigned char)name[k];
    shown[k] = (c >= 0x20 && c < 0x7f && c != '"' && c != '\\') ? (char)c : '?';
  }
  shown[k] = '\0';
  f->status = status;
  f->refused_in = f->state;
  f->state = FR_REFUSED;
  snprintf(f->detail, sizeof f->detail, fmt, shown);
}

static bool is_ows(char c) {
  return c == ' ' || c == '\t';
}

static bool is_hex(char c) {
  return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f') ||
         (c >= 'A' && c <= 'F');
}

static unsigned hex_value(char c) {
  return c <= '9' ? (unsigned)(c - '0') : (unsigned)((c | 0x20) - 'a' + 10);
}

/* A complete line at b->pos: its content [*start, *start + *n) without
 * the line end, and *next, the offset after its LF. False if no LF yet. */
static bool next_line(const srv_framing_buf *b, size_t *n, size_t *next) {
  const char *p = b->data + b->pos;
  const char *lf = memchr(p, '\n', b->len - b->pos);
  if (lf == NULL) return false;
  size_t k = (size_t)(lf - p);
  *next = b->pos + k + 1;
  if (k > 0 && p[k - 1] == '\r') k--;
  *n = k;
  return true;
}

/* ------------------------------------------------------------ the head */

/* "method SP target SP HTTP/d.d". Other bytes of the method and target
 * are libmicrohttpd's and http_guard.c's to judge (the access log escapes
 * them); NUL and a lone CR change where libmicrohttpd ends the line. */
static void request_line(srv_framing *f, const char *p, size_t n) {
  for (size_t i = 0; i < n; i++)
    if (p[i] == '\0' || p[i] == '\r') {
      refuse(f, 400, "the request line has a NUL byte or a lone CR%s", "", 0);
      return;
    }
  const char *sp1 = memchr(p, ' ', n);
  const char *sp2 = NULL;
  for (size_t i = n; i > 0; i--)
    if (p[i - 1] == ' ') {
      sp2 = p + i - 1;
      break;
    }
  const char *v = sp2 ? sp2 + 1 : NULL;
  size_t vn = v ? (size_t)(p + n - v) : 0;
  if (sp1 == NULL || sp1 == p || sp2 == sp1 || vn != 8 ||
      memcmp(v, "HTTP/", 5) != 0 || v[5] < '0' || v[5] > '9' || v[6] != '.' ||
      v[7] < '0' || v[7] > '9') {
    refuse(f, 400,
           "the request line is not a method, a target and an HTTP "
           "version%s",
           "", 0);
    return;
  }
  f->http11 = memcmp(v, "HTTP/1.1", 8) == 0;
  f->fields = f->lengths = f->codings = 0;
  f->exact_chunked = true;
  f->length = 0;
  f->coding[0] = '\0';
  f->state = FR_FIELDS;
}

/* RFC 9112 6.3: 1*DIGIT. libmicrohttpd 0.9.75 keeps a value's trailing
 * whitespace and answers a value it cannot read with a broken 400 of its
 * own, so only digits pass. */
static void content_length(srv_framing *f, const char *v, size_t n) {
  unsigned long long x = 0;
  if (!srv_http_decimal(v, n, &x))
    refuse(f, 400,
           "the Content-Length header is not a decimal number (digits "
           "only, at most 19)%s",
           "", 0);
  else if (f->lengths > 0 && x != f->length)
    refuse(f, 400, "the Content-Length header appears with different values%s",
           "", 0);
  f->length = x;
  f->lengths++;
}

/* RFC 9110 5.6.1 list elements. libmicrohttpd 0.9.75 reads a chunked
 * body only when the whole value is "chunked", so any other spelling of
 * the same list is refused below rather than read two ways. */
static void transfer_coding(srv_framing *f, const char *v, size_t n) {
  if (!(n == 7 && strncasecmp(v, "chunked", 7) == 0)) f->exact_chunked = false;
  char other[sizeof f->coding];
  f->codings += srv_http_codings(v, n, other, sizeof other);
  if (f->coding[0] == '\0') memcpy(f->coding, other, sizeof other);
}

/* One field line of a head or a trailer section (not the empty one). */
static void field_line(srv_framing *f, const char *p, size_t n, bool head) {
  if (++f->fields > SRV_FRAMING_FIELDS_MAX) {
    refuse(f, head ? 431 : 400,
           "the request has more than 100 header or trailer fields%s", "", 0);
    return;
  }
  if (is_ows(p[0])) {
    refuse(f, 400,
           "a header line begins with whitespace (a folded continuation "
           "line)%s",
           "", 0);
    return;
  }
  const char *colon = memchr(p, ':', n);
  if (colon == NULL) {
    refuse(f, 400, "the header line \"%s\" has no colon", p, n);
    return;
  }
  size_t name_len = (size_t)(colon - p);
  if (name_len == 0) {
    refuse(f, 400, "a header field has an empty field name%s", "", 0);
    return;
  }
  for (size_t i = 0; i < name_len; i++)
    if (!srv_http_tchar((unsigned char)p[i])) {
      refuse(f, 400,
             "the header field name \"%s\" is not a token (whitespace "
             "before the colon?)",
             p, name_len);
      return;
    }
  const char *v = colon + 1;
  size_t vn = n - name_len - 1;
  for (size_t i = 0; i < vn; i++) {
    unsigned char c = (unsigned char)v[i];
    if ((c < 0x20 && c != '\t') || c == 0x7f) {
      refuse(f, 400,
             "the %s header has a control character or a NUL byte in its "
             "value",
             p, name_len);
      return;
    }
  }
  while (vn > 0 && is_ows(v[0])) v++, vn--;
  size_t rn = sizeof SRV_FRAMING_REFUSED_FIELD - 1;
  if (name_len == rn && strncasecmp(p, SRV_FRAMING_REFUSED_FIELD, rn) == 0) {
    refuse(f, 400, "the %s field is reserved for the server", p, name_len);
    return;
  }
  if (!head) return;
  if (name_len == 14 && strncasecmp(p, "Content-Length", 14) == 0)
    content_length(f, v, vn);
  else if (name_len == 17 && strncasecmp(p, "Transfer-Encoding", 17) == 0)
    transfer_coding(f, v, vn);
}

/* The head's empty line: how its body is framed, or why it cannot be. */
static void head_done(srv_framing *f) {
  if (f->codings > 0 && f->lengths > 0)
    refuse(f, 400,
           "both Content-Length and Transfer-Encoding headers: the length "
           "of the body is ambiguous%s",
           "", 0);
  else if (f->codings > 0 && !f->http11)
    refuse(f, 400, "the Transfer-Encoding header in an HTTP/1.0 request%s", "",
           0);
  else if (f->coding[0] != '\0')
    refuse(f, 501,
           "the Transfer-Encoding header names %s; chunked is the only "
           "transfer coding this service implements",
           f->coding, strlen(f->coding));
  else if (f->codings > 1)
    refuse(f, 400,
           "the Transfer-Encoding header applies chunked more than once%s", "",
           0);
  else if (f->codings == 1 && !f->exact_chunked)
    refuse(f, 400,
           "the Transfer-Encoding header is not exactly \"chunked\" (no "
           "list, no trailing whitespace)%s",
           "", 0);
  if (f->status != 0) return;
  f->requests++;
  if (f->codings == 1) {
    f->state = FR_CHUNK_SIZE;
  } else if (f->length > 0) {
    f->remaining = f->length;
    f->state = FR_BODY;
  } else {
    f->state = FR_REQUEST_LINE;
  }
}

/* ------------------------------------------------------- chunked body */

/* 1*HEXDIG [ ";" extensions ] with no control bytes; the line passes on
 * as its digits and line end alone. */
static void chunk_size_line(srv_framing *f, srv_framing_buf *b, size_t n,
                            size_t next) {
  const char *p = b->data + b->pos;
  size_t digits = 0;
  unsigned long long size = 0;
  while (digits < n && is_hex(p[digits])) {
    size = size * 16 + hex_value(p[digits]);
    digits++;
  }
  bool ok = digits > 0 && digits <= 16 && (digits == n || p[digits] == ';');
  for (size_t i = digits; ok && i < n; i++) {
    unsigned char c = (unsigned char)p[i];
    ok = (c >= 0x20 || c == '\t') && c != 0x7f;
  }
  if (!ok) {
    refuse(f, 400,
           "a chunk-size line is not a hexadecimal size (at most 16 digits) "
           "with optional ;extensions%s",
           "", 0);
    return;
  }
  size_t cut = n - digits; /* the extensions */
  if (cut > 0) {
    memmove(b->data + b->pos + digits, b->data + b->pos + n,
            b->len - b->pos - n);
    b->len -= cut;
    next -= cut;
  }
  b->pos = b->safe = next;
  if (size == 0) {
    f->fields = 0;
    f->state = FR_TRAILERS;
  } else {
    f->remaining = size;
    f->state = FR_CHUNK_DATA;
  }
}

/* ----------------------------------------------------------- the walk */

/* One step; false when it needs more bytes (or the parse is over). */
static bool step(srv_framing *f, srv_framing_buf *b) {
  size_t avail = b->len - b->pos;
  size_t n = 0, next = 0;
  switch (f->state) {
  case FR_BODY:
  case FR_CHUNK_DATA: {
    if (avail == 0) return false;
    size_t k = f->remaining < avail ? (size_t)f->remaining : avail;
    b->pos = b->safe = b->pos + k;
    f->remaining -= k;
    if (f->remaining == 0)
      f->state = f->state == FR_BODY ? FR_REQUEST_LINE : FR_CHUNK_END;
    return true;
  }
  case FR_CHUNK_END:
    if (avail == 0) return false;
    if (b->data[b->pos] == '\n') {
      n = 1;
    } else if (b->data[b->pos] == '\r') {
      if (avail < 2) return false;
      n = b->data[b->pos + 1] == '\n' ? 2 : 0;
    }
    if (n == 0) {
      refuse(f, 400,
             "a chunk's data is not followed by CRLF (more data than its "
             "size says)%s",
             "", 0);
      return false;
    }
    b->pos = b->safe = b->pos + n;
    f->state = FR_CHUNK_SIZE;
    return true;
  case FR_CHUNK_SIZE:
    if (!next_line(b, &n, &next)) {
      if (avail > SRV_FRAMING_CHUNK_LINE_MAX + 1)
        refuse(f, 400,
               "a chunk-size line is longer than 4096 bytes (its "
               "extensions)%s",
               "", 0);
      return false;
    }
    if (n > SRV_FRAMING_CHUNK_LINE_MAX) {
      refuse(f, 400,
             "a chunk-size line is longer than 4096 bytes (its extensions)%s",
             "", 0);
      return false;
    }
    chunk_size_line(f, b, n, next);
    return f->status == 0;
  case FR_REQUEST_LINE:
  case FR_FIELDS:
  case FR_TRAILERS: {
    bool got = next_line(b, &n, &next);
    /* A head is held from b->safe on: its size so far, or the line's. */
    size_t held = (got ? next : b->len) - b->safe;
    if (held > SRV_FRAMING_HEAD_MAX) {
      if (f->state == FR_TRAILERS)
        refuse(f, 400, "the trailer section is longer than 16384 bytes%s", "",
               0);
      else
        refuse(f, 431, "the request header is longer than 16384 bytes%s", "",
               0);
      return false;
    }
    if (!got) return false;
    const char *p = b->data + b->pos;
    b->pos = next;
    if (f->state == FR_REQUEST_LINE) {
      if (n == 0)
        b->safe = next; /* an empty line before a request is skipped */
      else
        request_line(f, p, n);
    } else if (n > 0) {
      field_line(f, p, n, f->state == FR_FIELDS);
    } else if (f->state == FR_FIELDS) {
      head_done(f);
      if (f->status == 0) b->safe = next;
    } else {
      b->safe = next;
      f->state = FR_REQUEST_LINE;
    }
    return f->status == 0;
  }
  default: return false;
  }
}

void srv_framing_scan(srv_framing *f, srv_framing_buf *b) {
  while (f->status == 0 && step(f, b)) {
  }
}

size_t srv_framing_ending(const srv_framing *f, char *out, size_t cap) {
  const char *lead = f->refused_in == FR_CHUNK_SIZE  ? "0\r\n"
                     : f->refused_in == FR_CHUNK_END ? "\r\n0\r\n"
                     : f->refused_in == FR_TRAILERS  ? ""
                                                     : NULL;
  if (f->status == 0 || lead == NULL) return 0;
  int n = snprintf(out, cap, "%s" SRV_FRAMING_REFUSED_FIELD ": %s\r\n\r\n",
                   lead, f->detail);
  return n > 0 && (size_t)n < cap ? (size_t)n : 0;
}

bool srv_framing_idle(const srv_framing *f) {
  return f->state == FR_REQUEST_LINE && f->status == 0;
}
