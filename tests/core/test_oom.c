/* test_oom.c - every core entry point survives running out of memory at
 * each of its allocations in turn: the call returns KM_ENOMEM, leaves its
 * out-parameters as they were and gives back every block it took (the
 * hook counts them; the ASan build checks again), and once no allocation
 * fails it succeeds. SQLite's fault simulation (test/malloc*.test) is the
 * model: fail the 1st allocation, then the 2nd, ... until a run fails
 * none. Each test prints how many allocations its call makes.
 */
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>

#include "km/kmorph.h"
#include "testutil.h"
#include "testmain.h"
#include "oomhook.h"
#include "fixtures.h"

/* Runs per loop at most: more than any call here allocates. */
#define OOM_MAX_RUNS 20000

/* ---------------------------------------------------------------- inputs */

/* The inputs of the tests, built once per test before its loop. */
typedef struct shapes {
  km_curve circle;  /* closed NURBS circle of radius 1 */
  km_curve rect;    /* closed rounded rectangle: corners of radius 0.25 */
  km_curve arch;    /* open cubic arch */
  km_curve wave;    /* open cubic S */
  km_signature sig; /* of the circle */
  km_curve letter_u, letter_s; /* U_to_S: several starts to preview */
} shapes;

static void open_cubic(km_curve *c, const double cp[10]) {
  static const double knots[9] = {0, 0, 0, 0, 0.5, 1, 1, 1, 1};
  km_curve_init(c);
  assert_status(km_curve_create(c, 3, 5, knots, cp, NULL, false, NULL), KM_OK);
}

static int shapes_setup(void **state) {
  static shapes s;
  double kn[20], cp[34], w[17];
  static const double arch[10] = {0, 0, 0.2, 0.8, 0.5, 1.1, 0.8, 0.8, 1, 0};
  static const double wave[10] = {0, 0, 0.3, 0.5, 0.5, 0, 0.7, -0.5, 1, 0};
  tu_circle_nurbs(0, 0, 1, 1, kn, cp, w);
  km_curve_init(&s.circle);
  assert_status(km_curve_create(&s.circle, 2, 9, kn, cp, w, true, NULL), KM_OK);
  tu_rounded_rect(-1, -0.75, 2, 1.5, 0.25, kn, cp, w);
  km_curve_init(&s.rect);
  assert_status(km_curve_create(&s.rect, 2, 17, kn, cp, w, true, NULL), KM_OK);
  {
    /* U -> S: its best-aligned start's frames cross, so the morph plans
     * and previews further starts to pick one. */
    tf_bspline b;
    const char which[2] = {'a', 'b'};
    km_curve *dst[2] = {&s.letter_u, &s.letter_s};
    for (int k = 0; k < 2; k++) {
      assert_int_equal(tf_load_shape("U_to_S", which[k], &b), 0);
      km_curve_init(dst[k]);
      assert_status(km_curve_create(dst[k], b.degree, b.n, b.knots, b.cp, b.w,
                                    b.closed, NULL),
                    KM_OK);
      tf_bspline_free(&b);
    }
  }
  open_cubic(&s.arch, arch);
  open_cubic(&s.wave, wave);
  km_signature_init(&s.sig);
  assert_status(km_signature_compute(&s.circle, 1e-6, &s.sig, NULL), KM_OK);
  *state = &s;
  return 0;
}

static int shapes_teardown(void **state) {
  shapes *s = *state;
  km_curve_free(&s->circle);
  km_curve_free(&s->rect);
  km_curve_free(&s->arch);
  km_curve_free(&s->wave);
  km_curve_free(&s->letter_u);
  km_curve_free(&s->letter_s);
  km_signature_free(&s->sig);
  return 0;
}

/* What a core status means for the loop; why names any other. */
static oom_outcome outcome_of(km_status st, const char *what, char *why) {
  if (st == KM_OK) return OOM_RAN_OK;
  if (st == KM_ENOMEM) return OOM_RAN_NOMEM;
  snprintf(why, 160, "%s: %s", what, km_status_name(st));
  return OOM_RAN_OTHER;
}

/* ------------------------------------------------- signature, reconstruct */

typedef struct sig_case {
  const km_curve *curve;
} sig_case;

static oom_outcome run_signature(void *ctx, char *why) {
  const sig_case *c = ctx;
  km_signature sig;
  km_status st;
  km_signature_init(&sig);
  st = km_signature_compute(c->curve, 1e-6, &sig, NULL);
  if (st != KM_OK && sig.length != 0) {
    snprintf(why, 160, "a failed signature was written");
    return OOM_RAN_OTHER;
  }
  km_signature_free(&sig);
  return outcome_of(st, "km_signature_compute", why);
}

static void signature_of_closed_curve_survives_oom(void **state) {
  shapes *s = *state;
  sig_case c = {&s->rect};
  oom_loop("signature closed", run_signature, &c, false, OOM_MAX_RUNS);
}

static void signature_of_open_curve_survives_oom(void **state) {
  shapes *s = *state;
  sig_case c = {&s->arch};
  oom_loop("signature open", run_signature, &c, false, OOM_MAX_RUNS);
}

static oom_outcome run_reconstruct(void *ctx, char *why) {
  const km_signature *sig = ctx;
  km_curve out;
  double bound = -1;
  km_status st;
  km_curve_init(&out);
  st = km_reconstruct(sig, 3, 1e-6, &out, &bound, NULL);
  km_curve_free(&out);
  return outcome_of(st, "km_reconstruct", why);
}

static void reconstruct_survives_oom(void **state) {
  shapes *s = *state;
  oom_loop("reconstruct", run_reconstruct, &s->sig, false, OOM_MAX_RUNS);
}

static oom_outcome run_path(void *ctx, char *why) {
  km_path p;
  km_curve out;
  km_status st;
  (void)ctx;
  km_path_init(&p);
  km_curve_init(&out);
  st = km_path_move_to(&p, 0, 0, NULL);
  if (st == KM_OK) st = km_path_line_to(&p, 1, 0, NULL);
  if (st == KM_OK)
    st = km_path_arc_to(&p, 0.5, 0.5, 0, false, true, 1, 1, NULL);
  if (st == KM_OK) st = km_path_cubic_to(&p, 0.5, 1.5, 0, 1.5, 0, 1, NULL);
  if (st == KM_OK) st = km_path_close(&p, NULL);
  if (st == KM_OK) st = km_path_to_curve(&p, 0, &out, NULL);
  km_curve_free(&out);
  km_path_free(&p);
  return outcome_of(st, "km_path", why);
}

static void path_to_curve_survives_oom(void **state) {
  (void)state;
  oom_loop("path", run_path, NULL, false, OOM_MAX_RUNS);
}

/* ------------------------------------------------------------------ morph */

typedef struct morph_case {
  const km_curve *from, *to;
  km_morph_method method;
  const double *matches;
  size_t nmatches;
  bool auto_matches;
  bool metrics; /* frames with their metrics and signature */
} morph_case;

/* Two frames and the queries of a prepared morph, as a client makes them. */
static km_status morph_frames(const km_morph *m, const morph_case *c) {
  km_curve f;
  km_signature sig;
  km_frame_metrics mt;
  size_t points = 0;
  km_status st;
  km_curve_init(&f);
  km_signature_init(&sig);
  st = km_morph_frame(m, 0.5, &f, c->metrics ? &mt : NULL,
                      c->metrics ? &sig : NULL, NULL);
  km_curve_free(&f);
  km_signature_free(&sig);
  if (st == KM_OK) st = km_morph_frame(m, 0.25, &f, NULL, NULL, NULL);
  km_curve_free(&f);
  if (st == KM_OK)
    st = km_morph_frame_points(
        m, 0.75, c->metrics ? KM_FRAME_WITH_METRICS : KM_FRAME_CURVE, NULL,
        &points, NULL);
  if (st == KM_OK) (void)km_morph_matches_used(m, NULL, 0);
  return st;
}

static oom_outcome run_morph_as(const morph_case *c, km_intersections mode,
                                char *why) {
  km_morph_input a = {c->from, NULL}, b = {c->to, NULL};
  km_morph_options o;
  km_morph *m = NULL;
  km_status st;
  km_morph_options_default(&o);
  o.method = c->method;
  o.matches = c->matches;
  o.nmatches = c->nmatches;
  o.auto_matches = c->auto_matches;
  o.intersections = mode;
  o.tolerance = 1e-4;
  st = km_morph_create(&m, &a, &b, &o, NULL);
  if (st != KM_OK && m != NULL) {
    snprintf(why, 160, "a failed km_morph_create wrote its morph");
    return OOM_RAN_OTHER;
  }
  if (st != KM_OK) return outcome_of(st, "km_morph_create", why);
  st = morph_frames(m, c);
  km_morph_free(m);
  return outcome_of(st, "km_morph_frame", why);
}

static oom_outcome run_morph(void *ctx, char *why) {
  return run_morph_as(ctx, KM_INTERSECTIONS_ALLOW, why);
}

static oom_outcome run_morph_avoid(void *ctx, char *why) {
  return run_morph_as(ctx, KM_INTERSECTIONS_AVOID, why);
}

static void morph_curvature_closed_survives_oom(void **state) {
  shapes *s = *state;
  morph_case c = {&s->circle, &s->rect, KM_METHOD_CURVATURE, NULL, 0,
                  false,      false};
  oom_loop("morph curvature closed", run_morph, &c, false, OOM_MAX_RUNS);
}

/* A failed allocation while previewing the starts must fail the morph:
 * it made another start win and answered a different morph. */
static void morph_start_preview_survives_oom(void **state) {
  shapes *s = *state;
  morph_case c = {&s->letter_u, &s->letter_s, KM_METHOD_CURVATURE, NULL, 0,
                  false,        false};
  oom_loop("morph start preview", run_morph, &c, false, OOM_MAX_RUNS);
}

/* A failed allocation while avoiding crossings (previews of other starts)
 * fails the morph in the same way. */
static void morph_avoid_survives_oom(void **state) {
  shapes *s = *state;
  morph_case c = {&s->letter_u, &s->letter_s, KM_METHOD_CURVATURE, NULL, 0,
                  false,        false};
  oom_loop("morph avoid", run_morph_avoid, &c, false, OOM_MAX_RUNS);
}

static void morph_curvature_closed_metrics_survives_oom(void **state) {
  shapes *s = *state;
  morph_case c = {&s->circle, &s->rect, KM_METHOD_CURVATURE, NULL, 0,
                  false,      true};
  oom_loop("morph curvature closed metrics", run_morph, &c, false,
           OOM_MAX_RUNS);
}

static void morph_curvature_open_survives_oom(void **state) {
  shapes *s = *state;
  morph_case c = {&s->arch, &s->wave, KM_METHOD_CURVATURE, NULL, 0,
                  false,    true};
  oom_loop("morph curvature open", run_morph, &c, false, OOM_MAX_RUNS);
}

static void morph_linear_closed_survives_oom(void **state) {
  shapes *s = *state;
  morph_case c = {&s->circle, &s->rect, KM_METHOD_LINEAR, NULL, 0, false, true};
  oom_loop("morph linear closed", run_morph, &c, false, OOM_MAX_RUNS);
}

static void morph_linear_open_survives_oom(void **state) {
  shapes *s = *state;
  morph_case c = {&s->arch, &s->wave, KM_METHOD_LINEAR, NULL, 0, false, false};
  oom_loop("morph linear open", run_morph, &c, false, OOM_MAX_RUNS);
}

static void morph_with_matches_survives_oom(void **state) {
  shapes *s = *state;
  static const double pairs[4] = {0.3, 0.4, 0.6, 0.7};
  morph_case c = {&s->arch, &s->wave, KM_METHOD_CURVATURE, pairs, 2,
                  false,    true};
  oom_loop("morph matches", run_morph, &c, false, OOM_MAX_RUNS);
}

static void morph_with_auto_matches_survives_oom(void **state) {
  shapes *s = *state;
  morph_case c = {&s->circle, &s->rect, KM_METHOD_CURVATURE, NULL, 0,
                  true,       true};
  oom_loop("morph auto matches", run_morph, &c, false, OOM_MAX_RUNS);
}

static const struct CMUnitTest tests[] = {
    cmocka_unit_test(signature_of_closed_curve_survives_oom),
    cmocka_unit_test(signature_of_open_curve_survives_oom),
    cmocka_unit_test(reconstruct_survives_oom),
    cmocka_unit_test(path_to_curve_survives_oom),
    cmocka_unit_test(morph_curvature_closed_survives_oom),
    cmocka_unit_test(morph_curvature_closed_metrics_survives_oom),
    cmocka_unit_test(morph_start_preview_survives_oom),
    cmocka_unit_test(morph_avoid_survives_oom),
    cmocka_unit_test(morph_curvature_open_survives_oom),
    cmocka_unit_test(morph_linear_closed_survives_oom),
    cmocka_unit_test(morph_linear_open_survives_oom),
    cmocka_unit_test(morph_with_matches_survives_oom),
    cmocka_unit_test(morph_with_auto_matches_survives_oom),
};

TM_SUITE("oom", tests, shapes_setup, shapes_teardown);
