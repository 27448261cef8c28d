/* status.c - status names and messages, and the core's tiny formatter.
 *
 * The core may not use stdio or the locale, so messages are formatted by a
 * small local routine that knows exactly the conversions it needs.
 */
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"

const char *km_status_name(km_status s) {
  switch (s) {
#define KM__STATUS_NAME(name, value, msg)                                      \
  case KM_##name: return "KM_" #name;
    KM_STATUS_MAP(KM__STATUS_NAME)
#undef KM__STATUS_NAME
  }
  return "KM_UNKNOWN";
}

const char *km_status_message(km_status s) {
  switch (s) {
#define KM__STATUS_MSG(name, value, msg)                                       \
  case KM_##name: return msg;
    KM_STATUS_MAP(KM__STATUS_MSG)
#undef KM__STATUS_MSG
  }
  return "unknown status";
}

typedef struct sink {
  char *buf;
  size_t cap, len;
} sink;

static void put_char(sink *s, char ch) {
  if (s->len + 1 < s->cap) s->buf[s->len] = ch;
  s->len++;
}

static void put_str(sink *s, const char *str) {
  if (!str) str = "(null)";
  while (*str) put_char(s, *str++);
}

static void put_uint(sink *s, unsigned long long v) {
  char tmp[24];
  int n = 0;
  do {
    tmp[n++] = (char)('0' + v % 10);
    v /= 10;
  } while (v && n < 24);
  while (n) put_char(s, tmp[--n]);
}

static void put_int(sink *s, long long v) {
  if (v < 0) {
    put_char(s, '-');
    put_uint(s, (unsigned long long)(-(v + 1)) + 1);
  } else {
    put_uint(s, (unsigned long long)v);
  }
}

/* Six significant digits, plain or scientific like %g. */
static void put_double(sink *s, double v) {
  if (isnan(v)) {
    put_str(s, "nan");
    return;
  }
  if (v < 0 || (v == 0 && signbit(v))) {
    put_char(s, '-');
    v = -v;
  }
  if (isinf(v)) {
    put_str(s, "inf");
    return;
  }
  if (v == 0) {
    put_char(s, '0');
    return;
  }
  int e = (int)floor(log10(v));
  double m = v / pow(10.0, e);
  long long digits = llround(m * 1e5);
  if (digits >= 1000000) {
    digits /= 10;
    e++;
  }
  char d[7];
  for (int i = 5; i >= 0; i--) {
    d[i] = (char)('0' + digits % 10);
    digits /= 10;
  }
  int last = 5;
  while (last > 0 && d[last] == '0') last--;
  if (e >= -4 && e < 6) {
    if (e >= 0) {
      for (int i = 0; i <= e; i++) put_char(s, i <= 5 ? d[i] : '0');
      if (last > e) {
        put_char(s, '.');
        for (int i = e + 1; i <= last; i++) put_char(s, d[i]);
      }
    } else {
      put_str(s, "0.");
      for (int i = 0; i < -e - 1; i++) put_char(s, '0');
      for (int i = 0; i <= last; i++) put_char(s, d[i]);
    }
  } else {
    put_char(s, d[0]);
    if (last > 0) {
      put_char(s, '.');
      for (int i = 1; i <= last; i++) put_char(s, d[i]);
    }
    put_char(s, 'e');
    put_int(s, e);
  }
}

static void vformat(char *buf, size_t cap, const char *fmt, va_list ap) {
  sink s = {buf, cap, 0};
  for (const char *p = fmt; *p; p++) {
    if (*p != '%') {
      put_char(&s, *p);
      continue;
    }
    p++;
    if (*p == 's') {
      put_str(&s, va_arg(ap, const char *));
    } else if (*p == 'd') {
      put_int(&s, va_arg(ap, int));
    } else if (*p == 'l' && p[1] == 'd') {
      p++;
      put_int(&s, va_arg(ap, long));
    } else if (*p == 'z' && p[1] == 'u') {
      p++;
      put_uint(&s, va_arg(ap, size_t));
    } else if (*p == 'g') {
      put_double(&s, va_arg(ap, double));
    } else if (*p == '%') {
      put_char(&s, '%');
    } else if (*p == '\0') {
      break;
    }
  }
  if (cap) buf[s.len < cap ? s.len : cap - 1] = '\0';
}

void km__format(char *buf, size_t cap, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  vformat(buf, cap, fmt, ap);
  va_end(ap);
}

km_status km__fail(km_error *err, km_status code, km_field field, long index,
                   double param, const char *fmt, ...) {
  if (err) {
    err->code = code;
    err->field = field;
    err->index = index;
    err->param = param;
    if (fmt) {
      va_list ap;
      va_start(ap, fmt);
      vformat(err->message, sizeof err->message, fmt, ap);
      va_end(ap);
    } else {
      size_t n = strlen(km_status_message(code));
      if (n >= sizeof err->message) n = sizeof err->message - 1;
      memcpy(err->message, km_status_message(code), n);
      err->message[n] = '\0';
    }
  }
  return code;
}

double km__wrap_angle(double a) {
  double w = fmod(a + KM_PI, 2.0 * KM_PI);
  if (w <= 0) w += 2.0 * KM_PI;
  return w - KM_PI;
}

const double km__gl8_x[8] = {0.96028985649753629,  0.79666647741362684,
                             0.52553240991632899,  0.18343464249564981,
                             -0.18343464249564981, -0.52553240991632899,
                             -0.79666647741362684, -0.96028985649753629};
const double km__gl8_w[8] = {0.10122853629037618, 0.22238103445337445,
                             0.31370664587788738, 0.36268378337836199,
                             0.36268378337836199, 0.31370664587788738,
                             0.22238103445337445, 0.10122853629037618};
const double km__gl16_x[16] = {
    0.98940093499164994,  0.9445750230732326,   0.86563120238783176,
    0.755404408355003,    0.61787624440264377,  0.45801677765722737,
    0.28160355077925892,  0.095012509837637441, -0.095012509837637441,
    -0.28160355077925892, -0.45801677765722737, -0.61787624440264377,
    -0.755404408355003,   -0.86563120238783176, -0.9445750230732326,
    -0.98940093499164994};
const double km__gl16_w[16] = {
    0.027152459411754058, 0.062253523938647776, 0.095158511682492897,
    0.12462897125553395,  0.14959598881657682,  0.16915651939500256,
    0.18260341504492361,  0.18945061045506847,  0.18945061045506847,
    0.18260341504492361,  0.16915651939500256,  0.14959598881657682,
    0.12462897125553395,  0.095158511682492897, 0.062253523938647776,
    0.027152459411754058};
