/* alloc.h - the one allocation hook of libkmorph and the contract layer.
 *
 * Every allocation of core/ and api/ goes through the four functions
 * below (in a hooked build cJSON's trees and printed texts too: the api
 * then installs them as cJSON's hooks), so that a test can fail the Nth
 * allocation and count what is still held (SQLite's fault simulation).
 *
 * DESIGN: a compile-time seam. A normal build inlines the four to libc's
 * malloc, calloc, realloc and free, so the compiler keeps everything it
 * knows of them (a new block aliases nothing: loops that store into one
 * need not reload their inputs, and sin and cos of one value stay one
 * sincos; cJSON keeps printing with realloc): out-of-line wrappers cost
 * 0.45% of the instructions of a CLI morph request. A build with
 * KM_ALLOC_HOOKED defined (the Makefile's hooked libraries, which the
 * out-of-memory tests link) makes them external functions instead:
 * core/src/alloc.c defines them as libc's, and a program that defines all
 * four itself is linked with its own, since the linker then never takes
 * alloc.o out of the archive. A run-time setter was not chosen: the core
 * has no globals, and its objects are shared by threads read-only.
 *
 * A replacement must define all four (one missing pulls alloc.o in and the
 * link fails on the others), be thread-safe if the program has threads,
 * and hand out memory that libc free() releases: api response bodies reach
 * callers that free them with free() (libmicrohttpd's
 * MHD_RESPMEM_MUST_FREE among them).
 *
 * Each behaves as the libc function of the same name; any of them may
 * fail (NULL) at any call, and every caller in core/ and api/ turns that
 * into KM_ENOMEM or an HTTP 503, leaking nothing.
 */
#ifndef KM_ALLOC_H
#define KM_ALLOC_H

#include <stddef.h>

#if defined(KM_ALLOC_HOOKED)

/* n bytes, uninitialised; NULL when out of memory. */
void *km__malloc(size_t n);
/* count * size zeroed bytes; NULL when out of memory or on overflow. */
void *km__calloc(size_t count, size_t size);
/* p (NULL or from these functions) resized to n bytes, its contents kept
 * up to the smaller size; NULL when out of memory, p then untouched and
 * still the caller's. */
void *km__realloc(void *p, size_t n);
/* Release p (NULL or from these functions); NULL is a no-op. */
void km__free(void *p);

#else

#include <stdlib.h>

static inline void *km__malloc(size_t n) {
  return malloc(n);
}
static inline void *km__calloc(size_t count, size_t size) {
  return calloc(count, size);
}
static inline void *km__realloc(void *p, size_t n) {
  return realloc(p, n);
}
static inline void km__free(void *p) {
  free(p);
}

#endif

#endif
