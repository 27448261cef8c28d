/* bench_glyphs.h - what the glyph benches share (bench_avoid.c,
 * bench_repair.c): a clock, reading a fixture, and a glyph of the
 * tests/fixtures/avoid files (absolute M, L, Q, Z path data) as a curve.
 * Included by one .c file each; everything is static.
 */
#ifndef KM_BENCH_GLYPHS_H
#define KM_BENCH_GLYPHS_H

#include <cJSON.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "../tests/support/glyph_path.h"
#include "km/kmorph.h"

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static char *read_file(const char *path) {
  FILE *f = fopen(path, "rb");
  if (!f) return NULL;
  fseek(f, 0, SEEK_END);
  long n = ftell(f);
  fseek(f, 0, SEEK_SET);
  char *s = malloc((size_t)n + 1);
  if (s && fread(s, 1, (size_t)n, f) != (size_t)n) {
    free(s);
    s = NULL;
  }
  if (s) s[n] = '\0';
  fclose(f);
  return s;
}

static const char *glyph_d(const cJSON *root, const char *id) {
  const cJSON *g;
  cJSON_ArrayForEach(g, cJSON_GetObjectItemCaseSensitive(root, "glyphs")) {
    if (!strcmp(cJSON_GetObjectItemCaseSensitive(g, "id")->valuestring, id))
      return cJSON_GetObjectItemCaseSensitive(g, "d")->valuestring;
  }
  return NULL;
}

#endif
