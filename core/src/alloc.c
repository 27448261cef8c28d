/* alloc.c - the default allocation hook of a hooked build: libc's heap
 * (km/alloc.h). A normal build inlines the hook, and this file then
 * defines nothing.
 *
 * It must define the four hook functions and nothing else: a program
 * replaces the hook by defining the same four, which works only while no
 * other symbol would pull this member out of the archive.
 */
#include "km/alloc.h"

#if defined(KM_ALLOC_HOOKED)

#include <stdlib.h>

void *km__malloc(size_t n) {
  return malloc(n);
}

void *km__calloc(size_t count, size_t size) {
  return calloc(count, size);
}

void *km__realloc(void *p, size_t n) {
  return realloc(p, n);
}

void km__free(void *p) {
  free(p);
}

#endif
