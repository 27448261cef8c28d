/* http_syntax.c - see http_syntax.h. */
#include "http_syntax.h"

#include <stdio.h>
#include <string.h>
#include <strings.h>

bool srv_http_tchar(unsigned char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
         (c >= '0' && c <= '9') ||
         (c != '\0' && strchr("!#$%&'*+-.^_`|~", c) != NULL);
}

bool srv_http_decimal(const char *v, size_t n, unsigned long long *out) {
  unsigned long long x = 0;
  if (n == 0 || n > 19) return false;
  for (size_t i = 0; i < n; i++) {
    if (v[i] < '0' || v[i] > '9') return false;
    x = x * 10 + (unsigned)(v[i] - '0');
  }
  *out = x;
  return true;
}

static bool is_ows(char c) {
  return c == ' ' || c == '\t';
}

unsigned srv_http_codings(const char *v, size_t n, char *other, size_t cap) {
  unsigned count = 0;
  size_t i = 0;
  if (cap > 0) other[0] = '\0';
  while (i < n) {
    while (i < n && (is_ows(v[i]) || v[i] == ',')) i++;
    size_t b = i;
    while (i < n && v[i] != ',') i++;
    size_t e = i;
    while (e > b && is_ows(v[e - 1])) e--;
    if (e == b) continue;
    count++;
    bool chunked = e - b == 7 && strncasecmp(v + b, "chunked", 7) == 0;
    if (!chunked && cap > 0 && other[0] == '\0')
      snprintf(other, cap, "%.*s", (int)(e - b), v + b);
  }
  return count;
}
