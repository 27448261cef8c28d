/* bench_avoid.c - the cost of "intersections": "avoid" against "allow" on
 * the glyph pairs of tests/fixtures/avoid/glyphs.json and repair.json.
 *
 * Each pair is morphed into 41 frames both ways: km_morph_create plus 41
 * km_morph_frame calls, curve only (the planned frames of an SVG answer)
 * and with metrics (the JSON answer's default), best of runs repeated for
 * at least MIN_SECONDS. The per-frame time (creation amortised over the 41
 * frames) is summed over three groups of pairs: those whose previews do
 * not cross (avoid checks and keeps the frames: its whole cost is the
 * check), those it searched and kept with no frame to repair, and those
 * whose frames it repaired (mostly from repair.json: pairs that still
 * cross after the choice). Glyph outlines are TrueType (M, L, Q, Z), built
 * with km_path exactly.
 *
 * Usage: bench_avoid (run from the repository root).
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
#define GROUPS 3
#define MIN_SECONDS 0.1

/* One morph of FRAMES frames: its time in seconds, or a negative number. */
static double morph_once(const km_curve *a, const km_curve *b,
                         km_intersections mode, bool metrics,
                         km_morph_avoidance *rep) {
  km_morph_options o;
  km_morph_options_default(&o);
  o.intersections = mode;
  km_morph_input A = {a, NULL}, B = {b, NULL};
  km_morph *m = NULL;
  km_error err;
  double t0 = now();
  if (km_morph_create(&m, &A, &B, &o, &err) != KM_OK) return -1;
  for (int i = 0; i < FRAMES; i++) {
    km_curve f;
    km_frame_metrics mt;
    km_curve_init(&f);
    km_status st = km_morph_frame(m, i / (double)(FRAMES - 1), &f,
                                  metrics ? &mt : NULL, NULL, &err);
    km_curve_free(&f);
    if (st) {
      km_morph_free(m);
      return -1;
    }
  }
  double t = now() - t0;
  if (rep) km_morph_avoided(m, rep);
  km_morph_free(m);
  return t;
}

static double morph_best(const km_curve *a, const km_curve *b,
                         km_intersections mode, bool metrics,
                         km_morph_avoidance *rep) {
  double best = INFINITY, end = now() + MIN_SECONDS;
  for (int r = 0; r < 3 || now() < end; r++) {
    double t = morph_once(a, b, mode, metrics, r == 0 ? rep : NULL);
    if (t < 0) return -1;
    best = fmin(best, t);
  }
  return best;
}

/* [metrics][group][allow, avoid]: summed per-frame microseconds */
typedef struct tally {
  double sum[2][GROUPS][2];
  int count[GROUPS];
  long previews[GROUPS], events[GROUPS];
} tally;

/* Every pair of the fixture at path, into *tl; 0 or -1. */
static int bench_fixture(const char *path, tally *tl) {
  char *text = read_file(path);
  cJSON *root = text ? cJSON_Parse(text) : NULL;
  free(text);
  if (!root) {
    fprintf(stderr, "cannot read %s\n", path);
    return -1;
  }
  const cJSON *p;
  cJSON_ArrayForEach(p, cJSON_GetObjectItemCaseSensitive(root, "pairs")) {
    const char *from = cJSON_GetObjectItemCaseSensitive(p, "from")->valuestring;
    const char *to = cJSON_GetObjectItemCaseSensitive(p, "to")->valuestring;
    const char *da = glyph_d(root, from), *db = glyph_d(root, to);
    km_curve a, b;
    if (!da || !db || glyph_path_curve(da, &a) || glyph_path_curve(db, &b)) {
      fprintf(stderr, "%s -> %s: cannot build the glyphs\n", from, to);
      cJSON_Delete(root);
      return -1;
    }
    km_morph_avoidance rep;
    memset(&rep, 0, sizeof rep);
    double t[2][2];
    for (int metrics = 0; metrics < 2; metrics++) {
      t[metrics][0] = morph_best(&a, &b, KM_INTERSECTIONS_ALLOW, metrics, NULL);
      t[metrics][1] = morph_best(&a, &b, KM_INTERSECTIONS_AVOID, metrics, &rep);
    }
    km_curve_free(&a);
    km_curve_free(&b);
    if (t[0][0] < 0 || t[0][1] < 0 || t[1][0] < 0 || t[1][1] < 0) {
      fprintf(stderr, "%s -> %s: the morph failed\n", from, to);
      cJSON_Delete(root);
      return -1;
    }
    int g = rep.repair_events > 0 ? 2 : rep.searched ? 1 : 0;
    tl->count[g]++;
    tl->previews[g] += (long)rep.previews;
    tl->events[g] += rep.repair_events;
    for (int metrics = 0; metrics < 2; metrics++)
      for (int k = 0; k < 2; k++)
        tl->sum[metrics][g][k] += 1e6 * t[metrics][k] / FRAMES;
  }
  cJSON_Delete(root);
  return 0;
}

int main(void) {
  static const char *fixtures[] = {"tests/fixtures/avoid/glyphs.json",
                                   "tests/fixtures/avoid/repair.json"};
  static const char *group[GROUPS] = {"previews do not cross (kept)",
                                      "previews cross (searched)",
                                      "frames repaired"};
  printf("intersections avoid against allow, %d frames, per frame (creation "
         "amortised), mean over pairs:\n",
         FRAMES);
  for (size_t i = 0; i < sizeof fixtures / sizeof *fixtures; i++) {
    tally tl;
    memset(&tl, 0, sizeof tl);
    if (bench_fixture(fixtures[i], &tl)) return 1;
    printf("%s\n", fixtures[i]);
    for (int g = 0; g < GROUPS; g++) {
      if (tl.count[g] == 0) continue;
      double n = tl.count[g];
      printf("  %-30s %2d pairs, %5.1f previews, %4.1f repair events: curve "
             "%6.1f us allow, %6.1f us avoid (x%.2f); with metrics %6.1f us, "
             "%6.1f us (x%.2f)\n",
             group[g], tl.count[g], (double)tl.previews[g] / n,
             (double)tl.events[g] / n, tl.sum[0][g][0] / n, tl.sum[0][g][1] / n,
             tl.sum[0][g][1] / tl.sum[0][g][0], tl.sum[1][g][0] / n,
             tl.sum[1][g][1] / n, tl.sum[1][g][1] / tl.sum[1][g][0]);
    }
  }
  return 0;
}
