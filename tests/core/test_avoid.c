/* test_avoid.c - km_morph_create with intersections AVOID in the core: what
 * it reports, that the choice it keeps has frames that do not cross, that
 * it stops when asked to at any point of its search, and that ALLOW
 * reports nothing.
 *
 * Oracles: the glyphs of tests/fixtures/avoid/glyphs.json (DejaVu Sans 2
 * and 5: their aligned frames cross at the spine of the 2's stroke, as
 * the crossing count of the frames under ALLOW shows here), crossing
 * counts of frames (km_curve_self_intersections, checked against an
 * independent dense-polyline count in tests/api/test_api_avoid.c), and
 * the preview budget stated in core/src/morph_avoid.c (2 + 7 x 32).
 * The repairs (core/src/morph_repair.c), chosen through the core's
 * internal switch, are judged on pairs of tests/fixtures/avoid/repair.json
 * by a dense-polyline crossing count written here; the repair's motion is
 * tested in test_repair_motion.c.
 */
#include <cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../core/src/morph_repair.h"
#include "glyphs.h"
#include "km/kmorph.h"
#include "testmain.h"
#include "testutil.h"

/* Glyph id of fixture file path (absolute M, L, Q, Z path data) as a
 * curve. */
static void glyph_of(const char *path, const char *id, km_curve *out) {
  cJSON *root = tg_fixture(path);
  tg_glyph(root, id, out);
  cJSON_Delete(root);
}

static void glyph(const char *id, km_curve *out) {
  glyph_of(TG_AVOID_PATH, id, out);
}

typedef struct pair {
  km_curve a, b;
} pair;

static int pair_setup(void **state) {
  static pair p;
  glyph("dejavu-sans/2", &p.a);
  glyph("dejavu-sans/5", &p.b);
  *state = &p;
  return 0;
}

static int pair_teardown(void **state) {
  pair *p = *state;
  km_curve_free(&p->a);
  km_curve_free(&p->b);
  return 0;
}

static km_morph *make(const pair *p, km_intersections mode, const km_stop *stop,
                      km_status *st) {
  km_morph_options o;
  km_morph_options_default(&o);
  o.intersections = mode;
  o.stop = stop;
  km_morph_input A = {&p->a, NULL}, B = {&p->b, NULL};
  km_morph *m = NULL;
  *st = km_morph_create(&m, &A, &B, &o, NULL);
  return m;
}

/* Frames t = k/20, k = 1..19, that cross themselves. */
static int crossing_frames(const km_morph *m) {
  int n = 0;
  for (int k = 1; k < 20; k++) {
    km_curve f;
    km_frame_metrics mt;
    km_curve_init(&f);
    assert_status(km_morph_frame(m, k / 20.0, &f, &mt, NULL, NULL), KM_OK);
    n += mt.self_intersections > 0;
    km_curve_free(&f);
  }
  return n;
}

/* 2 -> 5: the aligned frames cross; AVOID searches, keeps another start
 * whose frames do not, within the budget, and says so. */
static void a_crossing_pair_is_searched_and_fixed(void **state) {
  const pair *p = *state;
  km_status st;
  km_morph *allow = make(p, KM_INTERSECTIONS_ALLOW, NULL, &st);
  assert_status(st, KM_OK);
  km_morph *avoid = make(p, KM_INTERSECTIONS_AVOID, NULL, &st);
  assert_status(st, KM_OK);
  km_morph_avoidance ra, rv;
  km_morph_avoided(allow, &ra);
  km_morph_avoided(avoid, &rv);
  assert_false(ra.searched || ra.changed || ra.previews > 0);
  assert_true(rv.searched && rv.changed);
  assert_true(rv.crossings_before > 0);
  assert_int_equal(rv.crossings_after, 0);
  assert_int_equal(rv.input_crossings[0], 0);
  assert_int_equal(rv.input_crossings[1], 0);
  assert_true(rv.previews >= 14 && rv.previews <= 2 + 7 * 32);
  int xa = crossing_frames(allow), xv = crossing_frames(avoid);
  print_message("frames t = k/20 crossing: %d allow, %d avoid; %zu previews\n",
                xa, xv, rv.previews);
  assert_true(xa >= 10);
  assert_int_equal(xv, 0);
  km_morph_free(allow);
  km_morph_free(avoid);
}

/* A stop asked for after n questions, for n across the whole search,
 * ends km_morph_create with KM_ECANCELLED and no morph (a leak shows
 * under the sanitizers), or it finishes with the same choice. */
static void the_search_stops_when_asked(void **state) {
  const pair *p = *state;
  km_status st;
  int stopped = 0, finished = 0;
  for (long n = 0; n < 4000 && finished == 0; n += n < 64 ? 1 : n / 8) {
    countdown c = {n, 0};
    km_stop stop = {countdown_stop, &c};
    km_morph *m = make(p, KM_INTERSECTIONS_AVOID, &stop, &st);
    if (st == KM_ECANCELLED) {
      assert_null(m);
      stopped++;
      continue;
    }
    assert_status(st, KM_OK);
    km_morph_avoidance r;
    km_morph_avoided(m, &r);
    assert_true(r.changed && r.crossings_after == 0);
    km_morph_free(m);
    finished++;
  }
  assert_true(stopped > 10);
  assert_int_equal(finished, 1);
}

/* ---- the curvature repair --------------------------------------------- */

/* Proper crossings of the chords of frame f sampled at n equal steps of
 * its parameter, chords that share a point left out: a count that does
 * not use the core's crossing search. */
static long dense_crossings(const km_curve *f, size_t n) {
  double(*p)[2] = malloc((n + 1) * sizeof *p), u0, u1;
  assert_non_null(p);
  km_curve_domain(f, &u0, &u1);
  for (size_t i = 0; i <= n; i++) {
    double d[1][2];
    km_curve_eval(f, u0 + (u1 - u0) * (double)i / (double)n, 0, d);
    p[i][0] = d[0][0];
    p[i][1] = d[0][1];
  }
  long x = 0;
  for (size_t i = 0; i < n; i++)
    for (size_t j = i + 2; j < n; j++) {
      if (i == 0 && j == n - 1) continue; /* they meet at the seam */
      double *a = p[i], *b = p[i + 1], *c = p[j], *d = p[j + 1];
      double d1 = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
      double d2 = (b[0] - a[0]) * (d[1] - a[1]) - (b[1] - a[1]) * (d[0] - a[0]);
      double d3 = (d[0] - c[0]) * (a[1] - c[1]) - (d[1] - c[1]) * (a[0] - c[0]);
      double d4 = (d[0] - c[0]) * (b[1] - c[1]) - (d[1] - c[1]) * (b[0] - c[0]);
      x += d1 * d2 < 0 && d3 * d4 < 0;
    }
  free(p);
  return x;
}

/* DejaVu Sans y -> 3 (tests/fixtures/avoid/repair.json): under AVOID
 * without repair two of the frames t = k/40 cross, by a dense-polyline
 * count independent of the core's. The curvature repair (bumps of
 * curvature before the closure) leaves fewer crossing frames (measured:
 * none), changes neither end frame, and every frame it changes is
 * closed: its end is its start. */
static void the_curvature_repair_separates_a_pinch(void **state) {
  (void)state;
  const char *fx = "tests/fixtures/avoid/repair.json";
  km_curve a, b;
  glyph_of(fx, "dejavu-sans/y", &a);
  glyph_of(fx, "dejavu-sans/3", &b);
  km_morph_options o;
  km_morph_options_default(&o);
  o.intersections = KM_INTERSECTIONS_AVOID;
  km_morph_input A = {&a, NULL}, B = {&b, NULL};
  km_morph *off = NULL, *kap = NULL;
  assert_status(km__morph_create_repair(&off, &A, &B, &o, KM__REPAIR_OFF, NULL),
                KM_OK);
  assert_status(
      km__morph_create_repair(&kap, &A, &B, &o, KM__REPAIR_CURVATURE, NULL),
      KM_OK);
  int before = 0, after = 0, changed = 0;
  for (int k = 0; k <= 40; k++) {
    double t = k / 40.0;
    km_curve f, g;
    km_curve_init(&f);
    km_curve_init(&g);
    assert_status(km_morph_frame(off, t, &g, NULL, NULL, NULL), KM_OK);
    assert_status(km_morph_frame(kap, t, &f, NULL, NULL, NULL), KM_OK);
    before += dense_crossings(&g, 1500) > 0;
    after += dense_crossings(&f, 1500) > 0;
    if (k == 0 || k == 40) {
      /* the inputs: the same curve with and without the repair */
      assert_true(km_morph_repaired(kap, t) == 0.0);
      assert_int_equal(f.n, g.n);
      for (size_t i = 0; i < 2 * f.n; i++) assert_true(f.cp[i] == g.cp[i]);
    }
    if (km_morph_repaired(kap, t) > 0) {
      changed++;
      assert_true(f.closed);
      assert_true(f.cp[0] == f.cp[2 * (f.n - 1)] &&
                  f.cp[1] == f.cp[2 * (f.n - 1) + 1]);
    }
    km_curve_free(&f);
    km_curve_free(&g);
  }
  print_message("curvature repair, y -> 3: %d crossing frames without, %d "
                "with, %d changed\n",
                before, after, changed);
  assert_true(before > 0);
  assert_true(changed > 0);
  assert_true(after < before);
  km_morph_free(off);
  km_morph_free(kap);
  km_curve_free(&a);
  km_curve_free(&b);
}

/* Crossing frames of 41 (t = k/40) of the pair under repair how, by the
 * dense count; the morph is returned through *out. */
static int dense_crossing_frames(const km_curve *a, const km_curve *b,
                                 km__repair_method how, km_morph **out) {
  km_morph_options o;
  km_morph_options_default(&o);
  o.intersections = KM_INTERSECTIONS_AVOID;
  km_morph_input A = {a, NULL}, B = {b, NULL};
  assert_status(km__morph_create_repair(out, &A, &B, &o, how, NULL), KM_OK);
  int n = 0;
  for (int k = 0; k <= 40; k++) {
    km_curve f;
    km_curve_init(&f);
    assert_status(km_morph_frame(*out, k / 40.0, &f, NULL, NULL, NULL), KM_OK);
    n += dense_crossings(&f, 1500) > 0;
    if (km_morph_repaired(*out, k / 40.0) > 0) {
      assert_true(k > 0 && k < 40);
      assert_true(f.closed);
    }
    km_curve_free(&f);
  }
  return n;
}

/* DejaVu Sans m -> Liberation Serif 3: the displacement's fit is not kept
 * (a frame still crosses, by the dense count), the curvature separates
 * the pinch; trying the curvature first and the displacement where it
 * fails leaves fewer crossing frames than the displacement alone
 * (measured: 1 -> 0), never more than without repair. */
static void curvature_first_repairs_what_displacement_cannot(void **state) {
  (void)state;
  const char *fx = "tests/fixtures/avoid/repair.json";
  km_curve a, b;
  glyph_of(fx, "dejavu-sans/m", &a);
  glyph_of(fx, "liberation-serif/3", &b);
  km_morph *off, *disp, *both;
  int n_off = dense_crossing_frames(&a, &b, KM__REPAIR_OFF, &off);
  int n_disp = dense_crossing_frames(&a, &b, KM__REPAIR_DISPLACEMENT, &disp);
  int n_both = dense_crossing_frames(&a, &b, KM__REPAIR_BOTH, &both);
  print_message("m -> 3: %d crossing frames without repair, %d displacement, "
                "%d curvature first\n",
                n_off, n_disp, n_both);
  assert_true(n_disp > 0);
  assert_true(n_both < n_disp);
  assert_true(n_both <= n_off);
  km_morph_free(off);
  km_morph_free(disp);
  km_morph_free(both);
  km_curve_free(&a);
  km_curve_free(&b);
}

static const struct CMUnitTest tests[] = {
    cmocka_unit_test(a_crossing_pair_is_searched_and_fixed),
    cmocka_unit_test(the_search_stops_when_asked),
    cmocka_unit_test(the_curvature_repair_separates_a_pinch),
    cmocka_unit_test(curvature_first_repairs_what_displacement_cannot),
};

TM_SUITE("avoid", tests, pair_setup, pair_teardown);
