/* http_guard.c - checks of a request's framing (see http_guard.h).
 *
 * DESIGN: every field line is visited once through
 * MHD_get_connection_values_n, which gives names and values with their
 * lengths. A NUL byte cannot be seen that way: libmicrohttpd 0.9.75 takes
 * lengths with strlen, so "X: a\0b" arrives as "a". Its read buffer keeps
 * the header block in place, though (request line, then each line with
 * its CR LF, the colon and the end of each value overwritten by NULs), so
 * for that version the bytes between the end of one value and the start
 * of the next name must be exactly the NULs of one line end; anything
 * else is a NUL inside the line or a folded continuation line (which
 * 0.9.75 also appends to the name, not the value).
 */
#include "http_guard.h"

#include "http_syntax.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/socket.h>

/* ---------------------------------------------------------------- target */

void srv_http_target_scan(srv_http_target *t, const char *uri) {
  memset(t, 0, sizeof *t);
  if (uri == NULL) return;
  t->raw = uri;
  t->len = strlen(uri);
  for (size_t i = 0; i < t->len; i++) {
    unsigned char c = (unsigned char)uri[i];
    if (c < 0x21 || c == 0x7f) t->control = true;
    if (c == '%' && uri[i + 1] == '0' && uri[i + 2] == '0')
      t->nul_escape = true;
  }
}

/* ----------------------------------------------------------------- fields */

void srv_http_log_token(char *out, size_t n, const char *s) {
  size_t k = 0;
  for (; s != NULL && s[k] != '\0' && k + 1 < n; k++)
    out[k] = srv_http_tchar((unsigned char)s[k]) ? s[k] : '?';
  out[k] = '\0';
}

typedef struct scan {
  srv_http_verdict *out;
  bool http11;
  const char *lo, *hi;   /* the header block in the read buffer, or NULL */
  const char *prev_end;  /* where the previous line's value ended */
  const char *prev_name; /* and its name, NULL for the request line */
  size_t prev_name_len;
  unsigned hosts, lengths, codings;
  unsigned long long length;
  bool other_coding;
  char coding[40]; /* the first coding other than chunked */
} scan;

/* Refuse with status and a detail; the first fault found is the one told. */
static void refuse(scan *s, int status, const char *fmt, const char *name,
                   size_t name_len) {
  if (s->out->status != 0) return;
  char shown[48];
  size_t k = 0;
  for (; k < name_len && k + 1 < sizeof shown; k++) {
    unsigned char c = (unsigned char)name[k];
    shown[k] = (c >= 0x20 && c < 0x7f && c != '"' && c != '\\') ? (char)c : '?';
  }
  shown[k] = '\0';
  s->out->status = status;
  snprintf(s->out->detail, sizeof s->out->detail, fmt, shown);
}

/* The bytes from a line's value end (its terminating NUL) to p are the
 * NULs of one line end (CR LF or LF), extra of them more allowed (the
 * empty line that ends the block). */
static bool line_end_ok(const char *end, const char *p, size_t extra) {
  if (p < end + 1 || (size_t)(p - end) > 2 + extra) return false;
  for (; end < p; end++)
    if (*end != '\0') return false;
  return true;
}

static bool in_block(const scan *s, const char *p) {
  return p >= s->lo && p < s->hi;
}

/* One transfer-coding list (RFC 9110 5.6.1: elements, OWS around commas). */
static void codings(scan *s, const char *v, size_t n) {
  char other[sizeof s->coding];
  s->codings += srv_http_codings(v, n, other, sizeof other);
  if (other[0] != '\0' && !s->other_coding) {
    s->other_coding = true;
    memcpy(s->coding, other, sizeof other);
  }
}

static void content_length(scan *s, const char *v, size_t n) {
  unsigned long long x = 0;
  if (!srv_http_decimal(v, n, &x))
    refuse(s, 400, "the Content-Length header is not a decimal number%s", "",
           0);
  else if (s->lengths > 0 && x != s->length)
    refuse(s, 400,
           "the Content-Length header appears with different values"
           "%s",
           "", 0);
  s->length = x;
  s->lengths++;
}

/* What lies after a value is not its line end: a NUL byte in the line, a
 * line libmicrohttpd did not list (an empty field name) or a folded
 * continuation. */
static void line_refused(scan *s) {
  if (s->prev_name == NULL)
    refuse(s, 400,
           "the line after the request line has a NUL byte, an "
           "empty field name or a folded continuation line%s",
           "", 0);
  else
    refuse(s, 400,
           "the %s header line, or the line after it, has a NUL "
           "byte, an empty field name or a folded continuation line",
           s->prev_name, s->prev_name_len);
}

static enum MHD_Result field(void *cls, enum MHD_ValueKind kind,
                             const char *name, size_t name_len,
                             const char *value, size_t value_len) {
  scan *s = cls;
  (void)kind;
  if (name_len == 0) {
    refuse(s, 400, "a header field has an empty name%s", "", 0);
    return MHD_NO;
  }
  for (size_t i = 0; i < name_len; i++)
    if (!srv_http_tchar((unsigned char)name[i])) {
      refuse(s, 400,
             "the header field name \"%s\" is not a token "
             "(whitespace before the colon?)",
             name, name_len);
      return MHD_NO;
    }
  for (size_t i = 0; value != NULL && i < value_len; i++) {
    unsigned char c = (unsigned char)value[i];
    if ((c < 0x20 && c != '\t') || c == 0x7f) {
      refuse(s, 400, "the %s header has a control character in its value", name,
             name_len);
      return MHD_NO;
    }
  }
  if (s->lo != NULL) {
    /* The name follows the previous line's end; its colon (now a NUL)
     * and optional whitespace lead to the value. */
    bool ok = in_block(s, name) && value != NULL && in_block(s, value) &&
              line_end_ok(s->prev_end, name, 0) && value > name + name_len;
    for (const char *p = name + name_len + 1; ok && p < value; p++)
      ok = *p == ' ' || *p == '\t';
    if (!ok) {
      line_refused(s);
      return MHD_NO;
    }
    s->prev_end = value + value_len;
    s->prev_name = name;
    s->prev_name_len = name_len;
  }
  if (name_len == 4 && strncasecmp(name, "Host", 4) == 0)
    s->hosts++;
  else if (name_len == 14 && strncasecmp(name, "Content-Length", 14) == 0)
    content_length(s, value, value_len);
  else if (name_len == 17 && strncasecmp(name, "Transfer-Encoding", 17) == 0)
    codings(s, value, value_len);
  return s->out->status == 0 ? MHD_YES : MHD_NO;
}

/* The request line in the read buffer: method NUL, spaces, the target,
 * NUL, version, then its line end. */
static bool request_line_ok(const scan *s, const char *method,
                            const srv_http_target *t, const char *version) {
  const char *m_end = method + strlen(method);
  if (t->raw == NULL || !in_block(s, t->raw) || !in_block(s, version) ||
      t->raw <= m_end || *m_end != '\0')
    return false;
  for (const char *p = m_end + 1; p < t->raw; p++)
    if (*p != ' ') return false;
  return version == t->raw + t->len + 1;
}

void srv_http_check(struct MHD_Connection *conn, const char *method,
                    const char *version, const srv_http_target *target,
                    srv_http_verdict *out) {
  memset(out, 0, sizeof *out);
  scan s;
  memset(&s, 0, sizeof s);
  s.out = out;
  s.http11 = version != NULL && strcmp(version, "HTTP/1.1") == 0;
  if (target != NULL && target->nul_escape)
    refuse(&s, 400, "the request target has %%00 (an encoded NUL byte)%s", "",
           0);
  else if (target != NULL && target->control)
    refuse(&s, 400, "the request target has a space or a control byte%s", "",
           0);
#if MHD_VERSION <= 0x00097500
  const union MHD_ConnectionInfo *ci =
      MHD_get_connection_info(conn, MHD_CONNECTION_INFO_REQUEST_HEADER_SIZE);
  if (ci != NULL && method != NULL && version != NULL && target != NULL &&
      target->raw != NULL) {
    s.lo = method;
    s.hi = method + ci->header_size;
    s.prev_end = version + strlen(version);
    if (!request_line_ok(&s, method, target, version))
      refuse(&s, 400, "the request line has a NUL byte%s", "", 0);
  }
#endif
  if (out->status != 0) return;
  MHD_get_connection_values_n(conn, MHD_HEADER_KIND, field, &s);
  if (out->status != 0) return;
  if (s.lo != NULL && !line_end_ok(s.prev_end, s.hi, 2))
    line_refused(&s);
  else if (s.hosts == 0 && s.http11)
    refuse(&s, 400, "the Host header is missing (HTTP/1.1 requires it)%s", "",
           0);
  else if (s.hosts > 1)
    refuse(&s, 400, "the Host header appears more than once%s", "", 0);
  else if (s.codings > 0 && s.lengths > 0)
    refuse(&s, 400,
           "both Content-Length and Transfer-Encoding headers: "
           "the length of the body is ambiguous%s",
           "", 0);
  else if (s.codings > 0 && !s.http11)
    refuse(&s, 400, "the Transfer-Encoding header in an HTTP/1.0 request%s", "",
           0);
  else if (s.other_coding)
    refuse(&s, 501,
           "the Transfer-Encoding header names %s; chunked is the "
           "only transfer coding this service implements",
           s.coding, strlen(s.coding));
  else if (s.codings > 1)
    refuse(&s, 400,
           "the Transfer-Encoding header applies chunked more than "
           "once%s",
           "", 0);
}

/* ------------------------------------------------------------------ probe */

bool srv_http_fin_probe(int fd, bool http11, bool *sent) {
  static const char CONTINUE[] = "HTTP/1.1 100 Continue\r\n\r\n";
  const size_t len = sizeof CONTINUE - 1;
  const int flags = MSG_DONTWAIT | MSG_NOSIGNAL;
  if (!http11) return false;
  if (!*sent) {
    ssize_t n = send(fd, CONTINUE, len, flags);
    if (n < 0) return errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR;
    *sent = true;
    if ((size_t)n < len) {
      /* 25 bytes into an idle socket's send buffer: a partial write means
       * the peer has long stopped reading; the rest must precede the final
       * answer, so a peer that cannot take it now counts as gone. */
      size_t rest = len - (size_t)n;
      n = send(fd, CONTINUE + (len - rest), rest, flags);
      if (n < 0 || (size_t)n < rest) return true;
    }
  }
  /* After a FIN, recv reports end of file even once a reset came (the
   * FIN is read first); a send fails from the reset on, and one of no
   * bytes sends nothing to a peer that is still there. */
  ssize_t n = send(fd, "", 0, flags);
  return n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR;
}
