/* glyphs.h - the glyph outlines of tests/fixtures/avoid (glyphs.json,
 * repair.json: absolute M, L, Q, Z path data of one subpath, TrueType
 * quadratics) as exact km_curve values, for the core tests of crossing
 * avoidance and repair (a header of static functions, like testutil.h).
 */
#ifndef KM_TEST_GLYPHS_H
#define KM_TEST_GLYPHS_H

#include <cJSON.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "glyph_path.h"
#include "km/kmorph.h"
#include "testutil.h"

#define TG_AVOID_PATH "tests/fixtures/avoid/glyphs.json"
#define TG_REPAIR_PATH "tests/fixtures/avoid/repair.json"

/* A fixture file, parsed; fails the test if it cannot be read. */
static inline cJSON *tg_fixture(const char *path) {
  FILE *fp = fopen(path, "rb");
  assert_non_null(fp);
  fseek(fp, 0, SEEK_END);
  long n = ftell(fp);
  fseek(fp, 0, SEEK_SET);
  char *s = malloc((size_t)n + 1);
  assert_non_null(s);
  assert_int_equal(fread(s, 1, (size_t)n, fp), (size_t)n);
  s[n] = '\0';
  fclose(fp);
  cJSON *root = cJSON_Parse(s);
  free(s);
  assert_non_null(root);
  return root;
}

/* Glyph id of a parsed fixture as a curve, built with km_path exactly. */
static inline void tg_glyph(const cJSON *root, const char *id, km_curve *out) {
  const char *d = NULL;
  const cJSON *g;
  cJSON_ArrayForEach(g, cJSON_GetObjectItemCaseSensitive(root, "glyphs")) {
    if (!strcmp(cJSON_GetObjectItemCaseSensitive(g, "id")->valuestring, id))
      d = cJSON_GetObjectItemCaseSensitive(g, "d")->valuestring;
  }
  assert_non_null(d);
  assert_int_equal(glyph_path_curve(d, out), 0);
}

#endif
