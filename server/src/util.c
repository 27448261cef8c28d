/* util.c - clocks, random ids and JSON string escaping for the daemon. */
#include "util.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/random.h>
#include <time.h>

double srv_now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

void srv_random_hex(char *out, size_t nhex) {
  static const char digits[] = "0123456789abcdef";
  unsigned char buf[64];
  size_t need = (nhex + 1) / 2;
  if (need > sizeof buf) need = sizeof buf;
  size_t got = 0;
  while (got < need) {
    ssize_t n = getrandom(buf + got, need - got, 0);
    if (n < 0) {
      if (errno == EINTR) continue;
      /* No kernel randomness (very old kernel or seccomp): fall back to
       * the clock so ids stay unique per process, if guessable. */
      struct timespec ts;
      clock_gettime(CLOCK_REALTIME, &ts);
      unsigned long long x = (unsigned long long)ts.tv_nsec ^
                             ((unsigned long long)ts.tv_sec << 30);
      for (; got < need; got++) {
        x = x * 6364136223846793005ULL + 1442695040888963407ULL;
        buf[got] = (unsigned char)(x >> 56);
      }
      break;
    }
    got += (size_t)n;
  }
  size_t i;
  for (i = 0; i < nhex && i / 2 < need; i++)
    out[i] = digits[(i % 2 == 0) ? (buf[i / 2] >> 4) : (buf[i / 2] & 15)];
  out[i] = '\0';
}

size_t srv_json_escape(char *dst, size_t cap, const char *src) {
  size_t o = 0;
  if (cap == 0) return 0;
  for (const unsigned char *p = (const unsigned char *)src; *p; p++) {
    char esc[8];
    size_t n;
    if (*p == '"' || *p == '\\') {
      esc[0] = '\\';
      esc[1] = (char)*p;
      n = 2;
    } else if (*p < 0x20) {
      n = (size_t)snprintf(esc, sizeof esc, "\\u%04x", *p);
    } else {
      esc[0] = (char)*p;
      n = 1;
    }
    if (o + n >= cap) break;
    memcpy(dst + o, esc, n);
    o += n;
  }
  dst[o] = '\0';
  return o;
}

bool srv_request_id_ok(const char *s) {
  size_t n = 0;
  if (s == NULL) return false;
  for (; s[n]; n++) {
    char c = s[n];
    bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
              (c >= '0' && c <= '9') || c == '.' || c == '_' || c == ':' ||
              c == '-';
    if (!ok || n >= 64) return false;
  }
  return n > 0;
}

void srv_sleep(double seconds) {
  if (seconds <= 0) return;
  struct timespec ts;
  ts.tv_sec = (time_t)seconds;
  ts.tv_nsec = (long)((seconds - (double)ts.tv_sec) * 1e9);
  while (nanosleep(&ts, &ts) != 0 && errno == EINTR)
    ;
}
