/* alloc.h - the one allocation hook of libkmorph and the contract layer.
 *
 * Every allocation of core/ and api/ (cJSON's trees and printed texts
 * included: the api installs these as cJSON's hooks) goes through the four
 * functions below, so that a test can fail the Nth allocation and count
 * what is still held (SQLite's fault simulation).
 *
 * DESIGN: the hook is replaced at link time, not set at run time. The
 * core has no globals, and its objects are shared by threads read-only; a
 * settable function pointer would be a mutable global read by every
 * thread on every allocation. Instead core/src/alloc.c defines the four
 * functions, and nothing else, as libc's; a program that defines all four
 * itself is linked with its own, since the linker then never takes
 * alloc.o out of libkmorph.a. A replacement must define all four (one
 * missing pulls alloc.o in and the link fails on the others twice), be
 * thread-safe if the program has threads, and hand out memory that libc
 * free() releases: api response bodies reach callers that free them with
 * free() (libmicrohttpd's MHD_RESPMEM_MUST_FREE among them).
 *
 * Each behaves as the libc function of the same name, with one addition:
 * any of them may fail (NULL) at any call, and every caller in core/ and
 * api/ turns that into KM_ENOMEM or an HTTP 503, leaking nothing.
 */
#ifndef KM_ALLOC_H
#define KM_ALLOC_H

#include <stddef.h>

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

#endif
