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

/* Absolute M, L, Q and Z path data (one subpath) into *c. */
static int glyph_curve(const char *d, km_curve *c) {
  km_path p;
  km_path_init(&p);
  km_error err;
  km_status st = KM_OK;
  double v[4];
  while (*d && !st) {
    while (*d == ' ') d++;
    char op = *d;
    if (!op) break;
    d++;
    int n = op == 'M' || op == 'L' ? 2 : op == 'Q' ? 4 : 0;
    for (int i = 0; i < n; i++) v[i] = strtod(d, (char **)&d);
    if (op == 'M')
      st = km_path_move_to(&p, v[0], v[1], &err);
    else if (op == 'L')
      st = km_path_line_to(&p, v[0], v[1], &err);
    else if (op == 'Q')
      st = km_path_quad_to(&p, v[0], v[1], v[2], v[3], &err);
    else if (op == 'Z')
      st = km_path_close(&p, &err);
    else
      st = KM_EINVAL;
  }
  km_curve_init(c);
  if (!st) st = km_path_to_curve(&p, 0.0, c, &err);
  km_path_free(&p);
  return st == KM_OK ? 0 : -1;
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
