/* conneg.c - Accept, Accept-Encoding and entity tags (see conneg.h).
 *
 * DESIGN: a list header is walked element by element in place: each
 * element is a token (media range or coding) followed by ;-parameters,
 * of which only q matters here. Malformed q values count as 1, the
 * default, rather than excluding: a client's typo should not turn an
 * answer into a 406.
 */
#include "conneg.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

typedef struct element {
  const char *tok; /* the token, trimmed */
  size_t len;
  double q;
} element;

static bool is_space(char c) {
  return c == ' ' || c == '\t';
}

/* The q parameter among params[0..n-1] (";a=b;q=0.5"), 1 if absent. */
static double q_of(const char *p, const char *end) {
  while (p < end) {
    const char *semi = memchr(p, ';', (size_t)(end - p));
    if (semi == NULL) break;
    p = semi + 1;
    while (p < end && is_space(*p)) p++;
    if (end - p >= 2 && (p[0] == 'q' || p[0] == 'Q') && p[1] == '=') {
      char num[16];
      size_t k = 0;
      for (p += 2; p < end && k + 1 < sizeof num && *p != ';' && !is_space(*p);
           p++)
        num[k++] = *p;
      num[k] = '\0';
      char *e = NULL;
      double q = strtod(num, &e);
      if (e == num || *e != '\0' || !(q >= 0) || q > 1) return 1;
      return q;
    }
  }
  return 1;
}

/* The next element of list from *at; false at the end. */
static bool next_element(const char **at, element *el) {
  const char *p = *at;
  for (;;) {
    while (*p == ',' || is_space(*p)) p++;
    if (*p == '\0') return false;
    const char *end = p + strcspn(p, ",");
    const char *tok_end = p + strcspn(p, ";,");
    while (tok_end > p && is_space(tok_end[-1])) tok_end--;
    *at = end;
    if (tok_end == p) {
      p = end;
      continue;
    }
    el->tok = p;
    el->len = (size_t)(tok_end - p);
    el->q = q_of(p, end);
    return true;
  }
}

static bool blank(const char *s) {
  if (s == NULL) return true;
  while (is_space(*s)) s++;
  return *s == '\0';
}

double srv_accept_q(const char *accept, const char *type) {
  if (blank(accept)) return 1;
  const char *slash = strchr(type, '/');
  size_t major = slash ? (size_t)(slash - type) : strlen(type);
  size_t tlen = strlen(type);
  int best = 0;
  double q = 0;
  size_t seen = 0;
  element el;
  const char *at = accept;
  while (next_element(&at, &el)) {
    seen++;
    int level = 0;
    if (el.len == tlen && strncasecmp(el.tok, type, tlen) == 0)
      level = 3;
    else if (el.len == major + 2 && strncasecmp(el.tok, type, major) == 0 &&
             el.tok[major] == '/' && el.tok[major + 1] == '*')
      level = 2;
    else if (el.len == 3 && strncmp(el.tok, "*/*", 3) == 0)
      level = 1;
    if (level > best || (level == best && level > 0 && el.q > q)) {
      best = level;
      q = el.q;
    }
  }
  if (seen == 0) return 1; /* only commas and spaces: as if absent */
  return best > 0 ? q : 0;
}

int srv_accept_pick(const char *accept, const char *const *types, size_t n) {
  int pick = -1;
  double best = 0;
  for (size_t i = 0; i < n; i++) {
    double q = srv_accept_q(accept, types[i]);
    if (q > best) {
      best = q;
      pick = (int)i;
    }
  }
  return pick;
}

double srv_coding_q(const char *accept_encoding, const char *coding) {
  if (accept_encoding == NULL) return 0;
  bool gz = strcasecmp(coding, "gzip") == 0;
  double own = -1, star = -1;
  element el;
  const char *at = accept_encoding;
  while (next_element(&at, &el)) {
    bool named = (el.len == strlen(coding) &&
                  strncasecmp(el.tok, coding, el.len) == 0) ||
                 (gz && el.len == 6 && strncasecmp(el.tok, "x-gzip", 6) == 0);
    if (named && el.q > own) own = el.q;
    if (el.len == 1 && el.tok[0] == '*') star = el.q;
  }
  return own >= 0 ? own : star >= 0 ? star : 0;
}

bool srv_etag_match(const char *inm, const char *etag) {
  if (inm == NULL) return false;
  size_t elen = strlen(etag);
  const char *p = inm;
  while (*p) {
    while (*p == ',' || is_space(*p)) p++;
    if (*p == '*') return true;
    if (strncmp(p, "W/", 2) == 0) p += 2;
    const char *end = p + strcspn(p, ",");
    const char *t = end;
    while (t > p && is_space(t[-1])) t--;
    if ((size_t)(t - p) == elen && strncmp(p, etag, elen) == 0) return true;
    p = end;
  }
  return false;
}

void srv_etag_of(char *out, size_t cap, const void *data, size_t len,
                 const char *suffix) {
  const unsigned char *b = data;
  uint64_t h = 14695981039346656037ull;
  for (size_t i = 0; i < len; i++) {
    h ^= b[i];
    h *= 1099511628211ull;
  }
  snprintf(out, cap, "\"%016llx%s\"", (unsigned long long)h, suffix);
}
