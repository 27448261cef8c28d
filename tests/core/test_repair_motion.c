/* test_repair_motion.c - the crossing repair (core/src/morph_repair.c)
 * moves frames smoothly in t: it does not make the animation pop.
 *
 * For every pair of tests/fixtures/avoid/repair.json whose morph under
 * intersections AVOID repairs frames, the 41 frames are built twice from
 * the same morph: as answered (repaired), and with the morph's repair set
 * aside (the frames of the same choice without it). Measured here with
 * the test's own geometry (curves_distance: the Hausdorff distance of the
 * traces from dense samples, tests/support/curvedist.h):
 *   - frames 0 and 40 are not moved (they are the inputs);
 *   - the repair's offset e_k = |R_k - B_k| changes from frame to frame by
 *     at most the motion of the frames themselves, |e_(k+1) - e_k| <= the
 *     larger of the steps |B_(k+1) - B_k| beside it (a repair that came
 *     and went within a frame would move by its full size in one step);
 *   - no step of the repaired sequence is more than twice the larger of
 *     its neighbours unless the sequence without the repair took that step
 *     too (to within 10%): the repair adds no jump.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "../../core/src/morph_internal.h"
#include "curvedist.h"
#include "glyphs.h"
#include "km/kmorph.h"
#include "testmain.h"
#include "testutil.h"

#define FRAMES 41
#define SAMPLES 500 /* about, per frame */

/* The frames of m at t = k / 40, with or without its repair. */
static void frames_of(km_morph *m, bool repaired, km_curve f[FRAMES]) {
  km__repair *keep = m->repair;
  if (!repaired) m->repair = NULL;
  for (int k = 0; k < FRAMES; k++) {
    km_curve_init(&f[k]);
    assert_status(
        km_morph_frame(m, k / (double)(FRAMES - 1), &f[k], NULL, NULL, NULL),
        KM_OK);
  }
  m->repair = keep;
}

static void repaired_frames_move_smoothly(void **state) {
  (void)state;
  cJSON *root = tg_fixture(TG_REPAIR_PATH);
  const cJSON *p;
  int pairs = 0;
  double worst_offset = 0, worst_step = 0;
  cJSON_ArrayForEach(p, cJSON_GetObjectItemCaseSensitive(root, "pairs")) {
    const char *from = cJSON_GetObjectItemCaseSensitive(p, "from")->valuestring;
    const char *to = cJSON_GetObjectItemCaseSensitive(p, "to")->valuestring;
    km_curve a, b;
    tg_glyph(root, from, &a);
    tg_glyph(root, to, &b);
    km_morph_options o;
    km_morph_options_default(&o);
    o.intersections = KM_INTERSECTIONS_AVOID;
    km_morph_input A = {&a, NULL}, B = {&b, NULL};
    km_morph *m = NULL;
    assert_status(km_morph_create(&m, &A, &B, &o, NULL), KM_OK);
    if (m->repair == NULL) {
      km_morph_free(m);
      km_curve_free(&a);
      km_curve_free(&b);
      continue;
    }
    pairs++;
    km_curve R[FRAMES], U[FRAMES];
    frames_of(m, true, R);
    frames_of(m, false, U);
    double e[FRAMES], sr[FRAMES - 1], su[FRAMES - 1];
    for (int k = 0; k < FRAMES; k++) {
      e[k] = curves_distance(&R[k], &U[k], SAMPLES);
      if (k + 1 < FRAMES) {
        sr[k] = curves_distance(&R[k], &R[k + 1], SAMPLES);
        su[k] = curves_distance(&U[k], &U[k + 1], SAMPLES);
      }
    }
    assert_true(e[0] <= 1e-9 * (1 + su[0]));
    assert_true(e[FRAMES - 1] <= 1e-9 * (1 + su[FRAMES - 2]));
    for (int k = 0; k + 1 < FRAMES; k++) {
      double beside = fmax(k > 0 ? su[k - 1] : 0, su[k]);
      beside = fmax(beside, k + 1 < FRAMES - 1 ? su[k + 1] : 0);
      double change = fabs(e[k + 1] - e[k]);
      if (change > beside)
        print_error("%s -> %s: offset %.3g -> %.3g beside steps %.3g\n", from,
                    to, e[k], e[k + 1], beside);
      assert_true(change <= beside);
      worst_offset = fmax(worst_offset, change / beside);
      double near =
          fmax(k > 0 ? sr[k - 1] : 0, k + 1 < FRAMES - 1 ? sr[k + 1] : 0);
      bool inherited = sr[k] <= 1.1 * su[k];
      if (sr[k] > 2 * near && !inherited)
        print_error("%s -> %s: step %d of %.3g beside %.3g (%.3g without the "
                    "repair)\n",
                    from, to, k, sr[k], near, su[k]);
      assert_true(sr[k] <= 2 * near || inherited);
      if (!inherited) worst_step = fmax(worst_step, sr[k] / near);
    }
    for (int k = 0; k < FRAMES; k++) {
      km_curve_free(&R[k]);
      km_curve_free(&U[k]);
    }
    km_morph_free(m);
    km_curve_free(&a);
    km_curve_free(&b);
  }
  print_message("%d repaired pairs: offset change / step at most %.2f, "
                "step / larger neighbour (not inherited) at most %.2f\n",
                pairs, worst_offset, worst_step);
  assert_true(pairs >= 5);
  cJSON_Delete(root);
}

static const struct CMUnitTest tests[] = {
    cmocka_unit_test(repaired_frames_move_smoothly),
};

TM_SUITE("repair_motion", tests, NULL, NULL);
