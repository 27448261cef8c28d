/* util.h - small helpers of the daemon: clocks, random ids, JSON strings.
 *
 * Everything here is thread-safe and allocation-free.
 */
#ifndef SRV_UTIL_H
#define SRV_UTIL_H

#include <stdbool.h>
#include <stddef.h>

/* Seconds on the monotonic clock (for durations and deadlines). */
double srv_now(void);

/* Fill out[0..nhex-1] with random lowercase hex digits and NUL-terminate
 * (out must hold nhex + 1 bytes). Uses the kernel's random source, so ids
 * are not guessable from each other. */
void srv_random_hex(char *out, size_t nhex);

/* Copy src into dst as the inside of a JSON string (quotes not added),
 * escaping what JSON requires. Truncates to fit cap (always
 * NUL-terminated, never splits an escape). Returns bytes written. */
size_t srv_json_escape(char *dst, size_t cap, const char *src);

/* True if s is a sane client-supplied request id: 1..64 characters from
 * [A-Za-z0-9._:-]. Anything else is replaced by a generated id so that
 * logs and headers never carry control characters or unbounded text. */
bool srv_request_id_ok(const char *s);

/* Sleep for the given number of seconds (fractions allowed). */
void srv_sleep(double seconds);

#endif
