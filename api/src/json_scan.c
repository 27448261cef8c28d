/* json_scan.c - the strict RFC 8259 scanner of request bodies: syntax,
 * UTF-8 (RFC 3629), nesting depth and array lengths checked in one pass,
 * the first error given with its byte offset, and the heap the tree of
 * the text will take priced allocation by allocation, as glibc rounds
 * them, before anything is allocated.
 */
#include <ctype.h>
#include <stdint.h>
#include <string.h>

#include "json_parse.h"

typedef struct scan {
  const unsigned char *p, *end, *start;
  size_t depth, max_depth;
  const char *error; /* static message, NULL while fine */
  bool too_deep;
  size_t max_array; /* no array in a valid request is longer */
  bool too_long;
  size_t cost;      /* heap bytes of the tree built so far */
  size_t transient; /* the largest buffer held only while building */
} scan;

static bool scan_fail(scan *s, const char *msg) {
  if (s->error == NULL) s->error = msg;
  return false;
}

static void scan_ws(scan *s) {
  s->p = api__skip_ws(s->p, s->end);
}

static bool scan_lit(scan *s, const char *lit) {
  size_t n = strlen(lit);
  if ((size_t)(s->end - s->p) < n || memcmp(s->p, lit, n) != 0)
    return scan_fail(s, "invalid literal");
  s->p += n;
  return true;
}

static bool scan_digits(scan *s) {
  if (s->p >= s->end || !isdigit(*s->p)) return scan_fail(s, "digit expected");
  while (s->p < s->end && isdigit(*s->p)) s->p++;
  return true;
}

static bool scan_number(scan *s) {
  const unsigned char *from = s->p;
  if (s->p < s->end && *s->p == '-') s->p++;
  if (s->p < s->end && *s->p == '0') {
    s->p++;
  } else if (!scan_digits(s)) {
    return false;
  }
  if (s->p < s->end && *s->p == '.') {
    s->p++;
    if (!scan_digits(s)) return false;
  }
  if (s->p < s->end && (*s->p == 'e' || *s->p == 'E')) {
    s->p++;
    if (s->p < s->end && (*s->p == '+' || *s->p == '-')) s->p++;
    if (!scan_digits(s)) return false;
  }
  /* the builder copies a long token to a buffer of its own for strtod */
  if ((size_t)(s->p - from) >= 64 &&
      api__heap_bytes((size_t)(s->p - from) + 1) > s->transient)
    s->transient = api__heap_bytes((size_t)(s->p - from) + 1);
  return true;
}

/* One UTF-8 sequence (RFC 3629: no overlongs, no surrogates, <= U+10FFFF). */
static bool scan_utf8(scan *s) {
  unsigned c = *s->p;
  size_t len;
  unsigned cp;
  if (c < 0x80) {
    s->p++;
    return true;
  }
  if (c >= 0xc2 && c <= 0xdf) {
    len = 2;
    cp = c & 0x1f;
  } else if (c >= 0xe0 && c <= 0xef) {
    len = 3;
    cp = c & 0x0f;
  } else if (c >= 0xf0 && c <= 0xf4) {
    len = 4;
    cp = c & 0x07;
  } else {
    return scan_fail(s, "invalid UTF-8");
  }
  if ((size_t)(s->end - s->p) < len) return scan_fail(s, "invalid UTF-8");
  for (size_t i = 1; i < len; i++) {
    if ((s->p[i] & 0xc0) != 0x80) return scan_fail(s, "invalid UTF-8");
    cp = (cp << 6) | (s->p[i] & 0x3fu);
  }
  if ((len == 3 && (cp < 0x800 || (cp >= 0xd800 && cp <= 0xdfff))) ||
      (len == 4 && (cp < 0x10000 || cp > 0x10ffff)))
    return scan_fail(s, "invalid UTF-8");
  s->p += len;
  return true;
}

static bool scan_hex4(scan *s, unsigned *cp) {
  *cp = 0;
  for (int i = 0; i < 4; i++, s->p++) {
    if (s->p >= s->end || !isxdigit(*s->p))
      return scan_fail(s, "invalid \\u escape");
    *cp = (*cp << 4) | (unsigned)api__hexval(*s->p);
  }
  return true;
}

static bool scan_escape(scan *s) {
  unsigned char c = *s->p;
  if (c == 'u') {
    unsigned cp;
    s->p++;
    if (!scan_hex4(s, &cp)) return false;
    /* Only whole characters: a high surrogate must be followed by a low
     * one, and NUL would cut the C string short. */
    if (cp == 0) return scan_fail(s, "\\u0000 is not accepted in strings");
    if (cp >= 0xdc00 && cp <= 0xdfff)
      return scan_fail(s, "lone low surrogate in \\u escape");
    if (cp >= 0xd800 && cp <= 0xdbff) {
      unsigned lo;
      if ((size_t)(s->end - s->p) < 2 || s->p[0] != '\\' || s->p[1] != 'u')
        return scan_fail(s, "lone high surrogate in \\u escape");
      s->p += 2;
      if (!scan_hex4(s, &lo)) return false;
      if (lo < 0xdc00 || lo > 0xdfff)
        return scan_fail(s, "lone high surrogate in \\u escape");
    }
    return true;
  }
  if (strchr("\"\\/bfnrt", c) == NULL || c == '\0')
    return scan_fail(s, "invalid escape");
  s->p++;
  return true;
}

/* A string token; adds the buffer the builder will decode it into (the
 * token's length: decoded text is never longer). */
static bool scan_string(scan *s) {
  const unsigned char *from = ++s->p; /* after the opening quote */
  while (s->p < s->end) {
    unsigned char c = *s->p;
    if (c == '"') {
      s->cost += api__heap_bytes((size_t)(s->p - from) + 1);
      s->p++;
      return true;
    }
    if (c < 0x20) return scan_fail(s, "control character in string");
    if (c == '\\') {
      s->p++;
      if (s->p >= s->end) break;
      if (!scan_escape(s)) return false;
      continue;
    }
    if (!scan_utf8(s)) return false;
  }
  return scan_fail(s, "unterminated string");
}

static bool scan_value(scan *s);

/* One member or element and what follows it; *more while a ',' did. */
static bool scan_entry(scan *s, bool object, bool *more) {
  unsigned char close = object ? '}' : ']';
  if (object) {
    scan_ws(s);
    if (s->p >= s->end || *s->p != '"')
      return scan_fail(s, "object key (a string) expected");
    if (!scan_string(s)) return false;
    scan_ws(s);
    if (s->p >= s->end || *s->p != ':') return scan_fail(s, "':' expected");
    s->p++;
  }
  if (!scan_value(s)) return false;
  scan_ws(s);
  if (s->p < s->end && (*s->p == ',' || *s->p == close)) {
    *more = *s->p++ == ',';
    return true;
  }
  return scan_fail(s, object ? "',' or '}' expected" : "',' or ']' expected");
}

static bool scan_container(scan *s, unsigned char close, bool object) {
  const unsigned char *open = s->p;
  size_t cost0 = s->cost, count = 0, rows, width;
  bool more = true;
  if (++s->depth > s->max_depth) {
    s->too_deep = true;
    return scan_fail(s, "nesting too deep");
  }
  s->p++;
  scan_ws(s);
  if (s->p < s->end && *s->p == close) {
    s->p++;
    more = false;
  }
  while (more) {
    /* refuse an overlong array before any tree is built */
    if (!object && ++count > s->max_array) {
      s->too_long = true;
      return scan_fail(s, "array too long");
    }
    if (object) count++;
    if (!scan_entry(s, object, &more)) return false;
  }
  s->depth--;
  if (!object && api__pack_shape(open, s->p, &rows, &width)) {
    /* the elements' own items are not built: one item and its buffer */
    s->cost = cost0 + api__heap_bytes(api__pack_bytes(rows, width));
  } else if (object && count > API_SORT_ON_STACK &&
             2 * api__heap_bytes(count * sizeof(api_member)) > s->transient) {
    /* the names sorted once: the array and qsort's copy of it */
    s->transient = 2 * api__heap_bytes(count * sizeof(api_member));
  }
  s->cost += api__heap_bytes(sizeof(cJSON));
  return true;
}

static bool scan_value(scan *s) {
  scan_ws(s);
  if (s->p >= s->end) return scan_fail(s, "value expected");
  switch (*s->p) {
  case '{': return scan_container(s, '}', true);
  case '[': return scan_container(s, ']', false);
  default: break;
  }
  /* any other value is one item (scan_string prices a string's text) */
  s->cost += api__heap_bytes(sizeof(cJSON));
  switch (*s->p) {
  case '"': return scan_string(s);
  case 't': return scan_lit(s, "true");
  case 'f': return scan_lit(s, "false");
  case 'n': return scan_lit(s, "null");
  default:
    if (*s->p == '-' || isdigit(*s->p)) return scan_number(s);
    return scan_fail(s, "value expected");
  }
}

size_t api__json_member_offset(const unsigned char *start,
                               const unsigned char *end,
                               const unsigned char *open, size_t index) {
  scan s;
  bool more = true;
  memset(&s, 0, sizeof s);
  s.p = open + 1;
  s.end = end;
  s.max_depth = SIZE_MAX;
  s.max_array = SIZE_MAX;
  for (size_t i = 0; i < index && more; i++) scan_entry(&s, true, &more);
  scan_ws(&s);
  return (size_t)(s.p - start);
}

bool api__json_scan(api_ctx *ctx, const char *body, size_t length,
                    size_t max_array, size_t *need) {
  scan sc, *s = &sc;
  memset(s, 0, sizeof *s);
  s->start = s->p = (const unsigned char *)(body != NULL ? body : "");
  s->end = s->p + length;
  s->max_depth = ctx->cfg->max_json_depth;
  s->max_array = max_array;
  /* A UTF-8 byte order mark is tolerated, as cJSON does. */
  if (length >= 3 && memcmp(s->p, "\xef\xbb\xbf", 3) == 0) s->p += 3;
  if (scan_value(s)) {
    scan_ws(s);
    if (s->p != s->end) scan_fail(s, "unexpected data after the JSON value");
  }
  *need = s->cost + s->transient;
  if (s->error == NULL) return true;
  if (s->too_long)
    return api__failf(ctx, 422, API_P_LIMIT, "Limit exceeded", NULL,
                      "an array holds more than %zu elements (at byte %zu)",
                      s->max_array, (size_t)(s->p - s->start));
  if (s->too_deep)
    return api__failf(ctx, 400, API_P_MALFORMED, "Malformed JSON", NULL,
                      "JSON nested deeper than %zu levels (at byte %zu)",
                      s->max_depth, (size_t)(s->p - s->start));
  return api__failf(ctx, 400, API_P_MALFORMED, "Malformed JSON", NULL,
                    "%s at byte %zu", s->error, (size_t)(s->p - s->start));
}
