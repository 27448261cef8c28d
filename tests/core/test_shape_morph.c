/* test_shape_morph.c - compound morphs: a ring to a ring through rings,
 * O to C with the counter shrinking away, frames at 0 and 1, no pop
 * between consecutive frames, nesting and crossings checked on dense
 * polylines written here.
 *
 * Oracles: circles (the turning blend of two circles is the circle of
 * the blended length, so its radius is (1-t) r_a + t r_b), the linear
 * length law of a vanishing contour ((1-t) L), the inputs at t = 0 and 1.
 */
#include <limits.h>
#include <string.h>

#include "km/curve.h"
#include "km/path.h"
#include "km/shape.h"
#include "curvedist.h"
#include "testutil.h"
#include "testmain.h"

static void circle(km_curve *c, double cx, double cy, double r, int ccw) {
  double kn[12], cp[18], w[9];
  tu_circle_nurbs(cx, cy, r, ccw, kn, cp, w);
  km_curve_init(c);
  assert_status(km_curve_create(c, 2, 9, kn, cp, w, true, NULL), KM_OK);
}

static void shape_of(km_shape *s, km_curve *c, size_t n) {
  km_shape_init(s);
  assert_status(km_shape_create(s, c, n, KM_FILL_EVENODD, NULL, NULL), KM_OK);
  for (size_t i = 0; i < n; i++) km_curve_free(&c[i]);
}

/* radii of a curve's samples about a centre: min and max */
static void radii(const km_curve *c, const double g[2], double *lo,
                  double *hi) {
  size_t np;
  double *P = curve_points(c, per_span(c, 400), &np);
  *lo = INFINITY;
  *hi = 0;
  for (size_t i = 0; i < np; i++) {
    double r = hypot(P[2 * i] - g[0], P[2 * i + 1] - g[1]);
    *lo = fmin(*lo, r);
    *hi = fmax(*hi, r);
  }
  free(P);
}

/* winding number of q about the dense polyline P (crossing rule) */
static int winding(const double *P, size_t np, const double *q) {
  int w = 0;
  for (size_t i = 0; i + 1 < np; i++) {
    const double *a = P + 2 * i, *b = a + 2;
    double cr = (b[0] - a[0]) * (q[1] - a[1]) - (q[0] - a[0]) * (b[1] - a[1]);
    if (a[1] <= q[1] && b[1] > q[1] && cr > 0) w++;
    if (a[1] > q[1] && b[1] <= q[1] && cr < 0) w--;
  }
  return w;
}

/* every sample of the inner curve inside the outer (dense polylines) */
static bool inside(const km_curve *inner, const km_curve *outer) {
  size_t ni, no;
  double *I = curve_points(inner, per_span(inner, 300), &ni);
  double *O = curve_points(outer, per_span(outer, 1500), &no);
  bool ok = true;
  for (size_t i = 0; i < ni && ok; i++) ok = winding(O, no, I + 2 * i) != 0;
  free(I);
  free(O);
  return ok;
}

static void ring_to_ring_through_rings(void **state) {
  (void)state;
  /* given: rings (2, 1) about the origin and (3, 0.5) about (4, 1) */
  km_curve a[2], b[2];
  circle(&a[0], 0, 0, 2, 1);
  circle(&a[1], 0, 0, 1, 0);
  circle(&b[0], 4, 1, 0.5, 0);
  circle(&b[1], 4, 1, 3, 1);
  km_shape sa, sb;
  shape_of(&sa, a, 2);
  shape_of(&sb, b, 2);
  km_shape_morph *m = NULL;
  km_error err;
  assert_status(km_shape_morph_create(&m, &sa, &sb, NULL, NULL, &err), KM_OK);
  km_shape_pair p[2];
  assert_int_equal(km_shape_morph_pairs(m, p, 2), 2);
  assert_int_equal(p[0].from, 0);
  assert_int_equal(p[0].to, 1);
  assert_int_equal(p[1].from, 1);
  assert_int_equal(p[1].to, 0);
  for (int k = 0; k <= 8; k++) {
    double t = k / 8.0;
    km_shape_frame f;
    km_shape_frame_init(&f);
    assert_status(km_shape_morph_frame_until(m, t, NULL, &f, &err), KM_OK);
    assert_true(f.present[0] && f.present[1]);
    /* then: both are circles of the blended radii, the hole inside */
    double ro = (1 - t) * 2 + t * 3, rh = (1 - t) * 1 + t * 0.5, g[2], lo, hi;
    curve_centroid(&f.contours[0], g);
    radii(&f.contours[0], g, &lo, &hi);
    assert_close(lo, ro, 1e-3 * ro);
    assert_close(hi, ro, 1e-3 * ro);
    curve_centroid(&f.contours[1], g);
    radii(&f.contours[1], g, &lo, &hi);
    assert_close(lo, rh, 1e-3 * ro);
    assert_close(hi, rh, 1e-3 * ro);
    assert_true(inside(&f.contours[1], &f.contours[0]));
    assert_true(f.nesting_ok);
    assert_int_equal(f.mutual_intersections, 0);
    km_shape_frame_free(&f);
  }
  km_shape_morph_free(m);
  km_shape_free(&sa);
  km_shape_free(&sb);
}

/* a C: outer arc of radius 2 and inner of radius 1 about the origin,
 * open on the right between -40 and 40 degrees, joined by lines */
static void c_outline(km_curve *c) {
  km_path p;
  km_path_init(&p);
  double a = 40 * M_PI / 180;
  assert_status(km_path_move_to(&p, 2 * cos(a), 2 * sin(a), NULL), KM_OK);
  assert_status(
      km_path_arc_to(&p, 2, 2, 0, true, true, 2 * cos(a), -2 * sin(a), NULL),
      KM_OK);
  assert_status(km_path_line_to(&p, cos(a), -sin(a), NULL), KM_OK);
  assert_status(km_path_arc_to(&p, 1, 1, 0, true, false, cos(a), sin(a), NULL),
                KM_OK);
  assert_status(km_path_close(&p, NULL), KM_OK);
  km_curve_init(c);
  assert_status(km_path_to_curve(&p, 0.0, c, NULL), KM_OK);
  km_path_free(&p);
}

static void o_to_c_counter_shrinks_away(void **state) {
  (void)state;
  km_curve o[2], c[1], keep[2];
  circle(&o[0], 0, 0, 2, 1);
  circle(&o[1], 0.2, 0, 1.1, 0);
  c_outline(&c[0]);
  assert_status(km_curve_copy(&keep[0], &o[0], NULL), KM_OK);
  assert_status(km_curve_copy(&keep[1], &c[0], NULL), KM_OK);
  km_shape so, sc;
  shape_of(&so, o, 2);
  shape_of(&sc, c, 1);
  km_shape_morph *m = NULL;
  km_error err;
  assert_status(km_shape_morph_create(&m, &so, &sc, NULL, NULL, &err), KM_OK);
  const double hole_len = 2 * M_PI * 1.1, size = 4.0;
  double last_len = hole_len;
  km_shape_frame prev;
  km_shape_frame_init(&prev);
  double worst_step = 0;
  for (int k = 0; k <= 40; k++) {
    double t = k / 40.0;
    km_shape_frame f;
    km_shape_frame_init(&f);
    assert_status(km_shape_morph_frame_until(m, t, NULL, &f, &err), KM_OK);
    assert_int_equal(f.ncontours, 2);
    assert_true(f.present[0]);
    if (k < 40) {
      /* the counter's length is at most (1 - t) L (less where the O leaves
       * it no room), never growing as the O opens; it stays inside the O */
      assert_true(f.present[1]);
      double len = km_curve_length(&f.contours[1]);
      assert_le(len, (1 - t) * hole_len + 1e-3 * hole_len);
      assert_le(len, last_len + 1e-5 * hole_len); /* within tolerance */
      last_len = len;
      assert_true(inside(&f.contours[1], &f.contours[0]));
      assert_true(f.nesting_ok);
      assert_int_equal(f.mutual_intersections, 0);
    } else {
      assert_false(f.present[1]);
      assert_null(f.contours[1].cp);
    }
    if (k == 0) assert_le(curves_distance(&f.contours[0], &keep[0], 800), 1e-3);
    if (k == 40)
      assert_le(curves_distance(&f.contours[0], &keep[1], 800), 1e-3);
    if (k > 0)
      for (size_t s = 0; s < 2; s++)
        if (f.present[s] && prev.present[s]) {
          double d = curves_distance(&f.contours[s], &prev.contours[s], 400);
          worst_step = fmax(worst_step, d);
        }
    km_shape_frame_free(&prev);
    prev = f;
  }
  /* no pop: consecutive frames of 41 within 0.1 of the size */
  assert_le(worst_step, 0.1 * size);
  km_shape_frame_free(&prev);
  km_shape_morph_free(m);
  km_shape_free(&so);
  km_shape_free(&sc);
  km_curve_free(&keep[0]);
  km_curve_free(&keep[1]);
}

/* an axis-parallel rectangle as a closed degree-1 curve, counter-clockwise */
static void rect(km_curve *c, double x0, double y0, double x1, double y1) {
  double kn[7] = {0, 0, 1, 2, 3, 4, 4};
  double cp[10] = {x0, y0, x1, y0, x1, y1, x0, y1, x0, y0};
  km_curve_init(c);
  assert_status(km_curve_create(c, 1, 5, kn, cp, NULL, true, NULL), KM_OK);
}

/* Dense polyline of a curve and its centroid (vertex mean). */
static double *dense(const km_curve *c, size_t *np) {
  return curve_points(c, per_span(c, 600), np);
}

/* Any proper crossing between two curves' dense polylines. */
static bool cross(const km_curve *a, const km_curve *b) {
  size_t na, nb;
  double *A = dense(a, &na), *B = dense(b, &nb);
  bool hit = false;
  for (size_t i = 0; i + 1 < na && !hit; i++)
    for (size_t j = 0; j + 1 < nb && !hit; j++) {
      const double *p = A + 2 * i, *q = A + 2 * i + 2;
      const double *r = B + 2 * j, *s = B + 2 * j + 2;
      double d1 = (s[0] - r[0]) * (p[1] - r[1]) - (s[1] - r[1]) * (p[0] - r[0]);
      double d2 = (s[0] - r[0]) * (q[1] - r[1]) - (s[1] - r[1]) * (q[0] - r[0]);
      double d3 = (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]);
      double d4 = (q[0] - p[0]) * (s[1] - p[1]) - (q[1] - p[1]) * (s[0] - p[0]);
      hit = d1 * d2 < 0 && d3 * d4 < 0;
    }
  free(A);
  free(B);
  return hit;
}

/* i -> l: the stem [0, 1] x [0, 6] with a dot of radius 0.6 at (0.5, 7.5)
 * becomes the stem [0, 1] x [0, 9]. The dot has no partner: its length
 * falls as (1 - t) L (nothing to fit into: it is no hole), it ends at a
 * point inside the l's stem, and it is gone at t = 1. */
static void i_to_l_dot_vanishes_into_the_stem(void **state) {
  (void)state;
  km_curve i[2], l[1];
  rect(&i[0], 0, 0, 1, 6);
  circle(&i[1], 0.5, 7.5, 0.6, 1);
  rect(&l[0], 0, 0, 1, 9);
  km_shape si, sl;
  shape_of(&si, i, 2);
  shape_of(&sl, l, 1);
  km_shape_morph *m = NULL;
  km_error err;
  assert_status(km_shape_morph_create(&m, &si, &sl, NULL, NULL, &err), KM_OK);
  km_shape_pair p[2];
  assert_int_equal(km_shape_morph_pairs(m, p, 2), 2);
  assert_int_equal(p[0].from, 0);
  assert_int_equal(p[0].to, 0);
  assert_int_equal(p[1].from, 1);
  assert_int_equal(p[1].to, -1);
  const double dot_len = 2 * M_PI * 0.6;
  km_shape_frame prev;
  km_shape_frame_init(&prev);
  double worst_step = 0;
  for (int k = 0; k <= 40; k++) {
    double t = k / 40.0;
    km_shape_frame f;
    km_shape_frame_init(&f);
    assert_status(km_shape_morph_frame_until(m, t, NULL, &f, &err), KM_OK);
    assert_true(f.present[0]);
    assert_int_equal(f.present[1], k < 40);
    if (k < 40)
      assert_close(km_curve_length(&f.contours[1]), (1 - t) * dot_len,
                   1e-3 * dot_len);
    if (k == 39) {
      /* its last frame lies within the stem of the frame */
      double g[2];
      size_t n;
      curve_centroid(&f.contours[1], g);
      double *S = dense(&f.contours[0], &n);
      assert_int_not_equal(winding(S, n, g), 0);
      free(S);
    }
    if (k > 0)
      for (size_t s = 0; s < 2; s++)
        if (f.present[s] && prev.present[s])
          worst_step =
              fmax(worst_step,
                   curves_distance(&f.contours[s], &prev.contours[s], 400));
    km_shape_frame_free(&prev);
    prev = f;
  }
  /* no pop: consecutive frames of 41 within 0.1 of the size (9) */
  assert_le(worst_step, 0.9);
  km_shape_frame_free(&prev);
  km_shape_morph_free(m);
  km_shape_free(&si);
  km_shape_free(&sl);
}

/* 8 -> 3, both counters closing: the outer [0, 4] x [0, 8] with holes of
 * radius 1.2 at (2, 2) and (2, 6) becomes the outer [0, 3] x [0, 8] with
 * none. Each counter shrinks (never growing) to nothing at t = 1 and stays
 * inside the outer and apart from the other on every frame. */
static void eight_to_three_both_counters_close(void **state) {
  (void)state;
  km_curve e[3], th[1];
  rect(&e[0], 0, 0, 4, 8);
  circle(&e[1], 2, 2, 1.2, 0);
  circle(&e[2], 2, 6, 1.2, 0);
  rect(&th[0], 0, 0, 3, 8);
  km_shape se, st;
  shape_of(&se, e, 3);
  shape_of(&st, th, 1);
  km_shape_morph *m = NULL;
  km_error err;
  assert_status(km_shape_morph_create(&m, &se, &st, NULL, NULL, &err), KM_OK);
  km_shape_pair p[3];
  assert_int_equal(km_shape_morph_pairs(m, p, 3), 3);
  const double hole_len = 2 * M_PI * 1.2;
  double last[3] = {0, hole_len, hole_len};
  km_shape_frame prev;
  km_shape_frame_init(&prev);
  double worst_step = 0;
  for (int k = 0; k <= 40; k++) {
    double t = k / 40.0;
    km_shape_frame f;
    km_shape_frame_init(&f);
    assert_status(km_shape_morph_frame_until(m, t, NULL, &f, &err), KM_OK);
    assert_true(f.present[0]);
    for (size_t s = 1; s < 3; s++) {
      assert_int_equal(p[s].to, -1);
      assert_int_equal(f.present[s], k < 40);
      if (k == 40) continue;
      double len = km_curve_length(&f.contours[s]);
      assert_le(len, (1 - t) * hole_len + 1e-3 * hole_len);
      assert_le(len, last[s] + 1e-5 * hole_len); /* within tolerance */
      last[s] = len;
      assert_true(inside(&f.contours[s], &f.contours[0]));
    }
    if (k < 40) {
      assert_false(cross(&f.contours[1], &f.contours[2]));
      assert_true(f.nesting_ok);
      assert_int_equal(f.mutual_intersections, 0);
    }
    if (k > 0)
      for (size_t s = 0; s < 3; s++)
        if (f.present[s] && prev.present[s])
          worst_step =
              fmax(worst_step,
                   curves_distance(&f.contours[s], &prev.contours[s], 400));
    km_shape_frame_free(&prev);
    prev = f;
  }
  assert_le(worst_step, 0.8);
  km_shape_frame_free(&prev);
  km_shape_morph_free(m);
  km_shape_free(&se);
  km_shape_free(&st);
}

static void frame_refuses_t_outside(void **state) {
  (void)state;
  km_curve a[1], b[1];
  circle(&a[0], 0, 0, 1, 1);
  circle(&b[0], 0, 0, 2, 1);
  km_shape sa, sb;
  shape_of(&sa, a, 1);
  shape_of(&sb, b, 1);
  km_shape_morph *m = NULL;
  km_error err;
  assert_status(km_shape_morph_create(&m, &sa, &sb, NULL, NULL, &err), KM_OK);
  km_shape_frame f;
  km_shape_frame_init(&f);
  assert_status(km_shape_morph_frame_until(m, 1.5, NULL, &f, &err), KM_ERANGE);
  assert_int_equal(err.field, KM_FIELD_TIMES);
  assert_status(km_shape_morph_frame_until(m, NAN, NULL, &f, &err), KM_ERANGE);
  assert_null(f.contours);
  km_shape_morph_free(m);
  km_shape_free(&sa);
  km_shape_free(&sb);
}

/* The i -> l shapes of the test above. */
static void i_and_l(km_shape *si, km_shape *sl) {
  km_curve i[2], l[1];
  rect(&i[0], 0, 0, 1, 6);
  circle(&i[1], 0.5, 7.5, 0.6, 1);
  rect(&l[0], 0, 0, 1, 9);
  shape_of(si, i, 2);
  shape_of(sl, l, 1);
}

static km_shape_morph *morph_under(const km_shape *a, const km_shape *b,
                                   km_intersections x) {
  km_shape_morph_options o;
  km_shape_morph_options_default(&o);
  o.morph.intersections = x;
  km_shape_morph *m = NULL;
  assert_status(km_shape_morph_create(&m, a, b, &o, NULL, NULL), KM_OK);
  return m;
}

/* Frames of 41 with a mutual crossing or a nesting failure. */
static int failing_frames(const km_shape_morph *m) {
  int bad = 0;
  for (int k = 0; k <= 40; k++) {
    km_shape_frame f;
    km_shape_frame_init(&f);
    assert_status(km_shape_morph_frame_until(m, k / 40.0, NULL, &f, NULL),
                  KM_OK);
    bad += f.mutual_intersections > 0 || !f.nesting_ok;
    km_shape_frame_free(&f);
  }
  return bad;
}

/* Largest distance between the control points of two frames' curves. */
static double frames_apart(const km_shape_frame *a, const km_shape_frame *b) {
  double d = 0;
  assert_int_equal(a->ncontours, b->ncontours);
  for (size_t k = 0; k < a->ncontours; k++) {
    assert_int_equal(a->present[k], b->present[k]);
    if (!a->present[k]) continue;
    assert_int_equal(a->contours[k].n, b->contours[k].n);
    for (size_t i = 0; i < 2 * a->contours[k].n; i++)
      d = fmax(d, fabs(a->contours[k].cp[i] - b->contours[k].cp[i]));
  }
  return d;
}

/* A morph whose frames keep holes inside and contours apart (ring to ring
 * through rings) gets the same frames under avoid as under allow; one
 * whose dot crosses the stem (i -> l) fails on no more frames under
 * avoid, and its frames 0 and 1 are still the inputs (allow's ends). */
static void avoid_keeps_clean_morphs_and_ends(void **state) {
  (void)state;
  km_curve a[2], b[2];
  circle(&a[0], 0, 0, 4, 1);
  circle(&a[1], 1, 0, 1, 0);
  circle(&b[0], 0, 0, 3, 1);
  circle(&b[1], -0.5, 0.5, 1.5, 0);
  km_shape sa, sb, si, sl;
  shape_of(&sa, a, 2);
  shape_of(&sb, b, 2);
  i_and_l(&si, &sl);
  km_shape_morph *ma = morph_under(&sa, &sb, KM_INTERSECTIONS_ALLOW);
  km_shape_morph *mv = morph_under(&sa, &sb, KM_INTERSECTIONS_AVOID);
  km_shape_morph *ia = morph_under(&si, &sl, KM_INTERSECTIONS_ALLOW);
  km_shape_morph *iv = morph_under(&si, &sl, KM_INTERSECTIONS_AVOID);
  assert_int_equal(failing_frames(ma), 0);
  for (int k = 0; k <= 10; k++) {
    km_shape_frame f, g;
    km_shape_frame_init(&f);
    km_shape_frame_init(&g);
    assert_status(km_shape_morph_frame_until(ma, k / 10.0, NULL, &f, NULL),
                  KM_OK);
    assert_status(km_shape_morph_frame_until(mv, k / 10.0, NULL, &g, NULL),
                  KM_OK);
    assert_true(frames_apart(&f, &g) == 0.0);
    km_shape_frame_free(&f);
    km_shape_frame_free(&g);
  }
  assert_true(failing_frames(iv) <= failing_frames(ia));
  for (int e = 0; e <= 1; e++) {
    km_shape_frame f, g;
    km_shape_frame_init(&f);
    km_shape_frame_init(&g);
    assert_status(km_shape_morph_frame_until(ia, e, NULL, &f, NULL), KM_OK);
    assert_status(km_shape_morph_frame_until(iv, e, NULL, &g, NULL), KM_OK);
    assert_le(frames_apart(&f, &g), 1e-9);
    km_shape_frame_free(&f);
    km_shape_frame_free(&g);
  }
  km_shape_morph_free(ma);
  km_shape_morph_free(mv);
  km_shape_morph_free(ia);
  km_shape_morph_free(iv);
  km_shape_free(&sa);
  km_shape_free(&sb);
  km_shape_free(&si);
  km_shape_free(&sl);
}

/* A stop counting its questions, saying yes from the n-th on. */
typedef struct asker {
  long asked, yes_at;
} asker;

static bool ask(void *ctx) {
  asker *a = ctx;
  return ++a->asked >= a->yes_at;
}

/* The previews and the search of avoid poll the caller's stop: a morph
 * asks more questions under avoid than under allow, and a stop at any
 * of them ends the morph with KM_ECANCELLED and nothing returned. */
static void avoid_polls_the_stop(void **state) {
  (void)state;
  km_shape si, sl;
  i_and_l(&si, &sl);
  km_shape_morph_options o;
  km_shape_morph_options_default(&o);
  long asked[2];
  for (int x = 0; x < 2; x++) {
    asker a = {0, LONG_MAX};
    km_stop stop = {ask, &a};
    o.morph.intersections = x ? KM_INTERSECTIONS_AVOID : KM_INTERSECTIONS_ALLOW;
    km_shape_morph *m = NULL;
    assert_status(km_shape_morph_create(&m, &si, &sl, &o, &stop, NULL), KM_OK);
    km_shape_morph_free(m);
    asked[x] = a.asked;
  }
  assert_true(asked[1] > asked[0]);
  for (long n = asked[0] + 1; n <= asked[1];
       n += 1 + (asked[1] - asked[0]) / 4) {
    asker a = {0, n};
    km_stop stop = {ask, &a};
    km_shape_morph *m = NULL;
    km_error err;
    assert_status(km_shape_morph_create(&m, &si, &sl, &o, &stop, &err),
                  KM_ECANCELLED);
    assert_null(m);
    assert_int_equal(a.asked, n);
  }
  km_shape_free(&si);
  km_shape_free(&sl);
}

static const struct CMUnitTest tests[] = {
    cmocka_unit_test(ring_to_ring_through_rings),
    cmocka_unit_test(o_to_c_counter_shrinks_away),
    cmocka_unit_test(i_to_l_dot_vanishes_into_the_stem),
    cmocka_unit_test(eight_to_three_both_counters_close),
    cmocka_unit_test(frame_refuses_t_outside),
    cmocka_unit_test(avoid_keeps_clean_morphs_and_ends),
    cmocka_unit_test(avoid_polls_the_stop),
};

TM_SUITE("shape_morph", tests, NULL, NULL);
