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
 * the preview budget stated in core/src/morph_avoid.c (2 + 7 x 32). The
 * repair's motion is tested in test_repair_motion.c.
 */
#include <cJSON.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "glyphs.h"
#include "km/kmorph.h"
#include "testmain.h"
#include "testutil.h"

/* Glyph id of tests/fixtures/avoid/glyphs.json as a curve. */
static void glyph(const char *id, km_curve *out) {
  cJSON *root = tg_fixture(TG_AVOID_PATH);
  tg_glyph(root, id, out);
  cJSON_Delete(root);
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

static const struct CMUnitTest tests[] = {
    cmocka_unit_test(a_crossing_pair_is_searched_and_fixed),
    cmocka_unit_test(the_search_stops_when_asked),
};

TM_SUITE("avoid", tests, pair_setup, pair_teardown);
