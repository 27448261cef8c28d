/* bench_repair.c - the crossing repairs of "intersections": "avoid" on
 * the glyph pairs of tests/fixtures/avoid/repair.json, whose frames still
 * cross after avoid's free choices.
 *
 * Each pair is morphed (avoid) into 41 frames with metrics, with the
 * repair named on the command line and without any repair. Reported per
 * pair and summed: frames that cross (km_curve_self_intersections at the
 * morph's tolerance, via the frame metrics) with the repair and without,
 * frames the repair changed, and for those, against the same frame
 * without repair sampled at 512 equal steps of its parameter (arc length
 * for both): the largest move relative to the frame's length, and the
 * move elsewhere - the largest median move of a frame, and the largest
 * share of a frame that moved more than 0.001 of its length; and the
 * largest |kappa| of a changed frame over the inputs' (the frames 0 and
 * 1), which the blend keeps at 1 or below. Create time per morph is the
 * best of 3.
 *
 * Usage: bench_repair [displacement|curvature|both] (run from the
 * repository root; "both": curvature, and displacement for the events
 * curvature does not repair; without a name the core's default).
 */
#include <cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "../core/src/morph_repair.h"
#include "bench_glyphs.h"
#include "km/kmorph.h"

#define FRAMES 41
#define SAMPLES 512
#define FIXTURE "tests/fixtures/avoid/repair.json"

typedef struct pair_result {
  double create_s;
  int crossing, before, repaired;
  double move;   /* largest move / frame length */
  double median; /* largest median move / frame length */
  double share;  /* largest share of a frame moved > 0.001 length */
  double kappa;  /* largest |kappa| of a changed frame / the inputs' */
} pair_result;

static int cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

static void point(const km_curve *c, double r, double out[2]) {
  double u0, u1, d[1][2];
  km_curve_domain(c, &u0, &u1);
  km_curve_eval(c, u0 + r * (u1 - u0), 0, d);
  out[0] = d[0][0];
  out[1] = d[0][1];
}

/* The moves of frame f from g (the same frame unrepaired) into r. */
static void compare(const km_curve *f, const km_curve *g, double len,
                    pair_result *r) {
  double d[SAMPLES + 1];
  int far = 0;
  for (int i = 0; i <= SAMPLES; i++) {
    double a[2], b[2];
    point(f, i / (double)SAMPLES, a);
    point(g, i / (double)SAMPLES, b);
    d[i] = hypot(a[0] - b[0], a[1] - b[1]) / len;
    r->move = fmax(r->move, d[i]);
    far += d[i] > 1e-3;
  }
  qsort(d, SAMPLES + 1, sizeof *d, cmp_double);
  r->median = fmax(r->median, d[SAMPLES / 2]);
  r->share = fmax(r->share, far / (double)(SAMPLES + 1));
}

static int measure(const km_curve *a, const km_curve *b, km__repair_method how,
                   pair_result *r) {
  km_morph_options o;
  km_morph_options_default(&o);
  o.intersections = KM_INTERSECTIONS_AVOID;
  km_morph_input A = {a, NULL}, B = {b, NULL};
  km_error err;
  memset(r, 0, sizeof *r);
  r->create_s = INFINITY;
  km_morph *off = NULL;
  if (km__morph_create_repair(&off, &A, &B, &o, KM__REPAIR_OFF, &err))
    return -1;
  for (int rep = 0; rep < 3; rep++) {
    km_morph *m = NULL;
    double t0 = now();
    if (km__morph_create_repair(&m, &A, &B, &o, how, &err) != KM_OK) {
      km_morph_free(off);
      return -1;
    }
    r->create_s = fmin(r->create_s, now() - t0);
    if (rep) {
      km_morph_free(m);
      continue;
    }
    double bound = 0.0, kmax = 0.0;
    for (int i = 0; i < FRAMES; i++) {
      double t = i / (double)(FRAMES - 1);
      km_curve f, g;
      km_frame_metrics mt, mg;
      km_curve_init(&f);
      km_curve_init(&g);
      km_status st = km_morph_frame(m, t, &f, &mt, NULL, &err);
      if (!st) st = km_morph_frame(off, t, &g, &mg, NULL, &err);
      if (!st) {
        if (mt.self_intersections > 0) r->crossing++;
        if (mg.self_intersections > 0) r->before++;
        if (i == 0 || i == FRAMES - 1) bound = fmax(bound, mg.max_abs_kappa);
        if (km_morph_repaired(m, t) > 0) {
          kmax = fmax(kmax, mt.max_abs_kappa);
          r->repaired++;
          compare(&f, &g, mt.length, r);
        }
      }
      km_curve_free(&f);
      km_curve_free(&g);
      if (st) {
        km_morph_free(m);
        km_morph_free(off);
        return -1;
      }
    }
    r->kappa = bound > 0 ? kmax / bound : 0.0;
    km_morph_free(m);
  }
  km_morph_free(off);
  return 0;
}

int main(int argc, char **argv) {
  km__repair_method how = KM__REPAIR_DEFAULT;
  if (argc > 1 && strcmp(argv[1], "curvature") == 0)
    how = KM__REPAIR_CURVATURE;
  else if (argc > 1 && strcmp(argv[1], "displacement") == 0)
    how = KM__REPAIR_DISPLACEMENT;
  else if (argc > 1 && strcmp(argv[1], "both") == 0)
    how = KM__REPAIR_BOTH;
  else if (argc > 1) {
    fprintf(stderr, "usage: bench_repair [displacement|curvature|both]\n");
    return 2;
  }
  char *text = read_file(FIXTURE);
  cJSON *root = text ? cJSON_Parse(text) : NULL;
  free(text);
  if (!root) {
    fprintf(stderr, "cannot read %s\n", FIXTURE);
    return 1;
  }
  int pairs = 0, clean = 0, crossing = 0, before = 0, repaired = 0;
  double move = 0.0, median = 0.0, share = 0.0, kappa = 0.0, create = 0.0;
  const cJSON *p;
  printf("repair: %s\n", how == KM__REPAIR_CURVATURE ? "curvature"
                         : how == KM__REPAIR_BOTH    ? "both"
                                                     : "displacement");
  printf("%-28s %-28s cross before repaired  move/len  median  share  "
         "kappa  create ms\n",
         "from", "to");
  cJSON_ArrayForEach(p, cJSON_GetObjectItemCaseSensitive(root, "pairs")) {
    const char *from = cJSON_GetObjectItemCaseSensitive(p, "from")->valuestring;
    const char *to = cJSON_GetObjectItemCaseSensitive(p, "to")->valuestring;
    const char *da = glyph_d(root, from), *db = glyph_d(root, to);
    km_curve a, b;
    if (!da || !db || glyph_path_curve(da, &a) || glyph_path_curve(db, &b)) {
      fprintf(stderr, "%s -> %s: cannot build the glyphs\n", from, to);
      cJSON_Delete(root);
      return 1;
    }
    pair_result r;
    int bad = measure(&a, &b, how, &r);
    km_curve_free(&a);
    km_curve_free(&b);
    if (bad) {
      fprintf(stderr, "%s -> %s: the morph failed\n", from, to);
      cJSON_Delete(root);
      return 1;
    }
    printf("%-28s %-28s %5d %6d %8d  %8.4f  %6.4f  %5.2f  %5.2f  %9.1f\n", from,
           to, r.crossing, r.before, r.repaired, r.move, r.median, r.share,
           r.kappa, 1e3 * r.create_s);
    fflush(stdout);
    pairs++;
    clean += r.crossing == 0;
    crossing += r.crossing;
    before += r.before;
    repaired += r.repaired;
    move = fmax(move, r.move);
    median = fmax(median, r.median);
    share = fmax(share, r.share);
    kappa = fmax(kappa, r.kappa);
    create += r.create_s;
  }
  cJSON_Delete(root);
  printf("%d pairs, %d frames each: %d frames cross (%d without repair), "
         "%d repaired, %d pairs crossing-free, largest move %.4f of the "
         "frame length, largest median move %.4f, largest share moved "
         "%.2f, largest |kappa| of a changed frame %.2f of the inputs', "
         "create %.1f ms a morph (mean)\n",
         pairs, FRAMES, crossing, before, repaired, clean, move, median, share,
         kappa, 1e3 * create / pairs);
  return 0;
}
