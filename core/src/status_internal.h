/* status_internal.h - recording errors and formatting their messages without stdio
 * (status.c); internal.
 */
#ifndef KM_STATUS_INTERNAL_H
#define KM_STATUS_INTERNAL_H

#include <stddef.h>

#include "km/status.h"

/* Record an error: code, field, element index, parameter and a message
 * formatted by km__format (a small printf subset: %s %d %ld %zu %g; no
 * locale, no stdio). Returns code so callers can `return km__fail(...)`. */
km_status km__fail(km_error *err, km_status code, km_field field, long index,
                   double param, const char *fmt, ...);

/* printf-like formatting into buf (always NUL-terminated): %s %d %ld %zu
 * and %g (six significant digits). */
void km__format(char *buf, size_t cap, const char *fmt, ...);

#endif
