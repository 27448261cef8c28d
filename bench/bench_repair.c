/* bench_repair.c - the crossing repair of "intersections": "avoid" on the
 * glyph pairs of tests/fixtures/avoid/repair.json, whose frames still
 * cross after avoid's free choices.
 *
 * Each pair is morphed (avoid) into 41 frames with metrics. Reported per
 * pair and summed: frames that cross (km_curve_self_intersections at the
 * morph's tolerance, via the frame metrics), frames the repair moved, the
 * largest displacement relative to the frame's length, and the create
 * time (best of 3).
 *
 * Usage: bench_repair (run from the repository root).
 */
#include <cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "km/kmorph.h"
#include "bench_glyphs.h"

#define FRAMES 41
#define FIXTURE "tests/fixtures/avoid/repair.json"

typedef struct pair_result {
  double create_s;
  int crossing, repaired;
  double move; /* largest displacement / frame length */
} pair_result;

static int measure(const km_curve *a, const km_curve *b, pair_result *r) {
  km_morph_options o;
  km_morph_options_default(&o);
  o.intersections = KM_INTERSECTIONS_AVOID;
  km_morph_input A = {a, NULL}, B = {b, NULL};
  km_error err;
  memset(r, 0, sizeof *r);
  r->create_s = INFINITY;
  for (int rep = 0; rep < 3; rep++) {
    km_morph *m = NULL;
    double t0 = now();
    if (km_morph_create(&m, &A, &B, &o, &err) != KM_OK) return -1;
    r->create_s = fmin(r->create_s, now() - t0);
    if (rep) {
      km_morph_free(m);
      continue;
    }
    for (int i = 0; i < FRAMES; i++) {
      double t = i / (double)(FRAMES - 1);
      km_curve f;
      km_frame_metrics mt;
      km_curve_init(&f);
      km_status st = km_morph_frame(m, t, &f, &mt, NULL, &err);
      km_curve_free(&f);
      if (st) {
        km_morph_free(m);
        return -1;
      }
      double d = km_morph_repaired(m, t);
      if (mt.self_intersections > 0) r->crossing++;
      if (d > 0) {
        r->repaired++;
        r->move = fmax(r->move, d / mt.length);
      }
    }
    km_morph_free(m);
  }
  return 0;
}

int main(void) {
  char *text = read_file(FIXTURE);
  cJSON *root = text ? cJSON_Parse(text) : NULL;
  free(text);
  if (!root) {
    fprintf(stderr, "cannot read %s\n", FIXTURE);
    return 1;
  }
  int pairs = 0, clean = 0, crossing = 0, repaired = 0;
  double move = 0.0, create = 0.0;
  const cJSON *p;
  printf("%-28s %-28s cross repaired  move/len  create ms\n", "from", "to");
  cJSON_ArrayForEach(p, cJSON_GetObjectItemCaseSensitive(root, "pairs")) {
    const char *from = cJSON_GetObjectItemCaseSensitive(p, "from")->valuestring;
    const char *to = cJSON_GetObjectItemCaseSensitive(p, "to")->valuestring;
    const char *da = glyph_d(root, from), *db = glyph_d(root, to);
    km_curve a, b;
    if (!da || !db || glyph_curve(da, &a) || glyph_curve(db, &b)) {
      fprintf(stderr, "%s -> %s: cannot build the glyphs\n", from, to);
      cJSON_Delete(root);
      return 1;
    }
    pair_result r;
    int bad = measure(&a, &b, &r);
    km_curve_free(&a);
    km_curve_free(&b);
    if (bad) {
      fprintf(stderr, "%s -> %s: the morph failed\n", from, to);
      cJSON_Delete(root);
      return 1;
    }
    printf("%-28s %-28s %5d %8d  %8.4f  %9.1f\n", from, to, r.crossing,
           r.repaired, r.move, 1e3 * r.create_s);
    pairs++;
    clean += r.crossing == 0;
    crossing += r.crossing;
    repaired += r.repaired;
    move = fmax(move, r.move);
    create += r.create_s;
  }
  cJSON_Delete(root);
  printf("%d pairs, %d frames each: %d frames cross, %d repaired, %d pairs "
         "crossing-free, largest displacement %.4f of the frame length, "
         "create %.1f ms a morph (mean)\n",
         pairs, FRAMES, crossing, repaired, clean, move, 1e3 * create / pairs);
  return 0;
}
