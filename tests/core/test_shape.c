/* test_shape.c - the compound shape value: contours copied and oriented
 * per fill rule, the nesting tree, the limits and refusals of
 * km_shape_create.
 *
 * Oracles: circles (area pi r^2, centroid the centre), the nesting of
 * concentric circles and of rectangles built from lines (known by
 * construction), the winding numbers of points chosen inside and outside,
 * and the statuses the contract of km/shape.h promises.
 */
#include <string.h>

#include "km/curve.h"
#include "km/path.h"
#include "km/shape.h"
#include "testutil.h"
#include "testmain.h"

static void circle(km_curve *c, double cx, double cy, double r, int ccw) {
  double kn[12], cp[18], w[9];
  km_error err;
  tu_circle_nurbs(cx, cy, r, ccw, kn, cp, w);
  km_curve_init(c);
  assert_status(km_curve_create(c, 2, 9, kn, cp, w, true, &err), KM_OK);
}

/* axis-aligned rectangle from lines, counter-clockwise when ccw */
static void rect(km_curve *c, double x0, double y0, double x1, double y1,
                 int ccw) {
  km_path p;
  km_error err;
  km_path_init(&p);
  assert_status(km_path_move_to(&p, x0, y0, &err), KM_OK);
  if (ccw) {
    assert_status(km_path_line_to(&p, x1, y0, &err), KM_OK);
    assert_status(km_path_line_to(&p, x1, y1, &err), KM_OK);
    assert_status(km_path_line_to(&p, x0, y1, &err), KM_OK);
  } else {
    assert_status(km_path_line_to(&p, x0, y1, &err), KM_OK);
    assert_status(km_path_line_to(&p, x1, y1, &err), KM_OK);
    assert_status(km_path_line_to(&p, x1, y0, &err), KM_OK);
  }
  assert_status(km_path_close(&p, &err), KM_OK);
  km_curve_init(c);
  assert_status(km_path_to_curve(&p, 0.0, c, &err), KM_OK);
  km_path_free(&p);
}

static void free_curves(km_curve *c, size_t n) {
  for (size_t i = 0; i < n; i++) km_curve_free(&c[i]);
}

/* signed area of a curve by the shoelace formula on 4000 samples */
static double shoelace(const km_curve *c) {
  double t0, t1, a = 0.0, prev[1][2], cur[1][2];
  km_curve_domain(c, &t0, &t1);
  km_curve_eval(c, t0, 0, prev);
  for (int k = 1; k <= 4000; k++) {
    km_curve_eval(c, t0 + (t1 - t0) * k / 4000.0, 0, cur);
    a += prev[0][0] * cur[0][1] - cur[0][0] * prev[0][1];
    prev[0][0] = cur[0][0];
    prev[0][1] = cur[0][1];
  }
  return 0.5 * a;
}

static void ring_nests_the_hole_and_orients_by_role(void **state) {
  (void)state;
  /* given: an outer circle drawn clockwise, a hole drawn counter-clockwise */
  km_curve c[2];
  circle(&c[0], 1, 1, 2, 0);
  circle(&c[1], 1.5, 1, 1, 1);
  km_shape s;
  km_shape_init(&s);
  km_error err;
  assert_status(km_shape_create(&s, c, 2, KM_FILL_EVENODD, NULL, &err), KM_OK);
  assert_int_equal(s.parent[0], -1);
  assert_int_equal(s.parent[1], 0);
  assert_int_equal(s.depth[1], 1);
  assert_int_equal(s.role[0], KM_ROLE_OUTER);
  assert_int_equal(s.role[1], KM_ROLE_HOLE);
  assert_true(s.reversed[0] && s.reversed[1]);
  /* then: outer counter-clockwise, hole clockwise, areas pi r^2 */
  assert_true(shoelace(&s.contours[0]) > 0);
  assert_true(shoelace(&s.contours[1]) < 0);
  assert_rel(s.area[0], 4 * M_PI, 1e-12);
  assert_rel(s.area[1], M_PI, 1e-12);
  assert_close(s.centroid[2], 1.5, 1e-12);
  assert_close(s.centroid[3], 1.0, 1e-12);
  const double inside_hole[2] = {1.5, 1.2}, in_ring[2] = {-0.5, 1.0};
  assert_int_equal(km_shape_winding(&s, 1, inside_hole), -1);
  assert_int_equal(km_shape_winding(&s, 0, in_ring), 1);
  assert_int_equal(km_shape_winding(&s, 1, in_ring), 0);
  km_shape_free(&s);
  km_shape_free(&s); /* freeing twice is allowed: it was left empty */
  free_curves(c, 2);
}

static void nonzero_keeps_a_same_turning_inner_contour_filled(void **state) {
  (void)state;
  /* given two nested counter-clockwise circles: under nonzero the inner
   * region has winding 2 (filled), under evenodd it is a hole */
  km_curve c[2];
  circle(&c[0], 0, 0, 3, 1);
  circle(&c[1], 0, 0, 1, 1);
  km_shape nz, eo;
  km_shape_init(&nz);
  km_shape_init(&eo);
  assert_status(km_shape_create(&nz, c, 2, KM_FILL_NONZERO, NULL, NULL), KM_OK);
  assert_status(km_shape_create(&eo, c, 2, KM_FILL_EVENODD, NULL, NULL), KM_OK);
  assert_int_equal(nz.role[1], KM_ROLE_OUTER);
  assert_false(nz.reversed[1]);
  assert_int_equal(eo.role[1], KM_ROLE_HOLE);
  assert_true(eo.reversed[1]);
  assert_int_equal(nz.parent[1], 0);
  /* a clockwise inner circle under nonzero is a hole (winding 0) */
  km_curve_free(&c[1]);
  circle(&c[1], 0, 0, 1, 0);
  km_shape_free(&nz);
  assert_status(km_shape_create(&nz, c, 2, KM_FILL_NONZERO, NULL, NULL), KM_OK);
  assert_int_equal(nz.role[1], KM_ROLE_HOLE);
  assert_false(nz.reversed[1]);
  km_shape_free(&nz);
  km_shape_free(&eo);
  free_curves(c, 2);
}

static void nesting_tree_does_not_depend_on_contour_order(void **state) {
  (void)state;
  /* given: outer [0,10]^2, hole [1,9]^2, island [2,5]x[2,8], a second
   * island [6,8]x[2,8], and a separate square [12,14]^2 */
  km_curve base[5];
  rect(&base[0], 0, 0, 10, 10, 1);
  rect(&base[1], 1, 1, 9, 9, 0);
  rect(&base[2], 2, 2, 5, 8, 1);
  rect(&base[3], 6, 2, 8, 8, 0);
  circle(&base[4], 13, 13, 1, 1);
  const long want_parent[5] = {-1, 0, 1, 1, -1};
  const int want_depth[5] = {0, 1, 2, 2, 0};
  const size_t orders[3][5] = {
      {0, 1, 2, 3, 4}, {4, 3, 2, 1, 0}, {2, 0, 4, 3, 1}};
  for (int o = 0; o < 3; o++) {
    km_curve c[5];
    for (int i = 0; i < 5; i++) c[i] = base[orders[o][i]];
    km_shape s;
    km_shape_init(&s);
    assert_status(km_shape_create(&s, c, 5, KM_FILL_EVENODD, NULL, NULL),
                  KM_OK);
    for (int i = 0; i < 5; i++) {
      size_t b = orders[o][i];
      long p = s.parent[i];
      long want = want_parent[b];
      assert_int_equal(p < 0 ? -1 : (long)orders[o][p], want);
      assert_int_equal(s.depth[i], want_depth[b]);
      assert_int_equal(s.role[i],
                       want_depth[b] % 2 ? KM_ROLE_HOLE : KM_ROLE_OUTER);
      double sa = shoelace(&s.contours[i]);
      assert_true(want_depth[b] % 2 ? sa < 0 : sa > 0);
    }
    assert_close(s.box[0], 0, 1e-12);
    assert_close(s.box[3], 14, 1e-9);
    km_shape_free(&s);
  }
  free_curves(base, 5);
}

static void shape_refuses_bad_contours_naming_them(void **state) {
  (void)state;
  km_curve c[4];
  circle(&c[0], 0, 0, 3, 1);
  circle(&c[1], 0, 0, 1, 1);
  circle(&c[2], 5, 0, 1, 1);
  /* an open contour (an arc's control points, closed false) */
  double kn[12], cp[18], w[9];
  tu_circle_nurbs(0, 0, 1, 1, kn, cp, w);
  const double okn[6] = {0, 0, 0, 1, 1, 1};
  km_curve_init(&c[3]);
  assert_status(km_curve_create(&c[3], 2, 3, okn, cp, w, false, NULL), KM_OK);
  km_shape s;
  km_shape_init(&s);
  km_error err;
  assert_status(km_shape_create(&s, c, 4, KM_FILL_NONZERO, NULL, &err),
                KM_ECLOSED);
  assert_int_equal(err.index, 3);
  assert_int_equal(err.field, KM_FIELD_CLOSED);
  /* more contours than the limit */
  km_shape_limits lim = {2, 0};
  assert_status(km_shape_create(&s, c, 3, KM_FILL_NONZERO, &lim, &err),
                KM_ELIMIT);
  assert_int_equal(err.index, 2);
  /* control points of all contours above the bound: 9 + 9 > 12 */
  km_shape_limits pts = {0, 12};
  assert_status(km_shape_create(&s, c, 3, KM_FILL_NONZERO, &pts, &err),
                KM_ELIMIT);
  assert_int_equal(err.index, 1);
  assert_int_equal(err.field, KM_FIELD_CONTROL_POINTS);
  /* zero length: a closed curve whose control points all coincide */
  const double pkn[8] = {0, 0, 0, 0.3, 0.6, 1, 1, 1};
  const double pcp[10] = {2, 2, 2, 2, 2, 2, 2, 2, 2, 2};
  km_curve dot;
  km_curve_init(&dot);
  assert_status(km_curve_create(&dot, 2, 5, pkn, pcp, NULL, true, NULL), KM_OK);
  km_curve_free(&c[1]);
  c[1] = dot;
  assert_status(km_shape_create(&s, c, 3, KM_FILL_NONZERO, NULL, &err),
                KM_EDEGENERATE);
  assert_int_equal(err.index, 1);
  /* a flat closed contour (there and back) encloses no area */
  const double fkn[5] = {0, 0, 1, 2, 2};
  const double fcp[6] = {0, 0, 1, 0, 0, 0};
  km_curve flat;
  km_curve_init(&flat);
  assert_status(km_curve_create(&flat, 1, 3, fkn, fcp, NULL, true, NULL),
                KM_OK);
  assert_status(km_shape_create(&s, &flat, 1, KM_FILL_NONZERO, NULL, &err),
                KM_EDEGENERATE);
  assert_int_equal(err.index, 0);
  assert_status(km_shape_create(&s, c, 0, KM_FILL_NONZERO, NULL, &err),
                KM_ECOUNT);
  assert_status(km_shape_create(&s, c, 1, (km_fill_rule)7, NULL, &err),
                KM_EINVAL);
  assert_null(s.contours);
  km_curve_free(&flat);
  free_curves(c, 4);
}

static void copy_is_deep(void **state) {
  (void)state;
  km_curve c[2];
  circle(&c[0], 0, 0, 3, 1);
  circle(&c[1], 0.5, 0, 1, 0);
  km_shape s, d;
  km_shape_init(&s);
  km_shape_init(&d);
  assert_status(km_shape_create(&s, c, 2, KM_FILL_EVENODD, NULL, NULL), KM_OK);
  assert_status(km_shape_copy(&d, &s, NULL), KM_OK);
  assert_true(d.contours[1].cp != s.contours[1].cp);
  assert_int_equal(d.parent[1], 0);
  assert_memory_equal(d.flat, s.flat, 2 * s.flat_off[2] * sizeof(double));
  km_shape_free(&s);
  const double p[2] = {0.5, 0.5};
  assert_int_equal(km_shape_winding(&d, 1, p), -1);
  km_shape_free(&d);
  free_curves(c, 2);
}

/* ---- pairing ------------------------------------------------------------ */

static void make_shape(km_shape *s, km_curve *c, size_t n) {
  km_shape_init(s);
  assert_status(km_shape_create(s, c, n, KM_FILL_EVENODD, NULL, NULL), KM_OK);
}

static void get_pairs(const km_shape *a, const km_shape *b, km_shape_pair **p,
                      size_t *n) {
  km_error err;
  assert_status(km_shape_pair_auto(a, b, NULL, NULL, p, n, &err), KM_OK);
}

/* the partner in b of contour i of a; -1 vanishing, -2 in no pair */
static long partner_of(const km_shape_pair *p, size_t n, long i) {
  for (size_t k = 0; k < n; k++)
    if (p[k].from == i) return p[k].to;
  return -2;
}

static void ring_pairs_outer_with_outer_and_hole_with_hole(void **state) {
  (void)state;
  /* given: a ring, and a wider ring listed hole first, each circle of the
   * second drawn from another start point (rotated about its centre) */
  km_curve a[2], b[2], tmp;
  circle(&a[0], 0, 0, 2, 1);
  circle(&a[1], 0, 0, 1, 0);
  circle(&tmp, 5, 1, 1.5, 1);
  km_curve_init(&b[0]);
  assert_status(km_curve_transform(&b[0], &tmp, 2.0,
                                   5 - 5 * cos(2.0) + sin(2.0),
                                   1 - 5 * sin(2.0) - cos(2.0), NULL),
                KM_OK);
  km_curve_free(&tmp);
  circle(&b[1], 5, 1, 3, 1);
  km_shape sa, sb;
  make_shape(&sa, a, 2);
  make_shape(&sb, b, 2);
  km_shape_pair *p = NULL;
  size_t n = 0;
  get_pairs(&sa, &sb, &p, &n);
  /* then: outer 0 with outer 1, hole 1 with hole 0, nothing unpaired */
  assert_int_equal(n, 2);
  assert_int_equal(partner_of(p, n, 0), 1);
  assert_int_equal(partner_of(p, n, 1), 0);
  assert_status(km_shape_pair_check(&sa, &sb, p, n, NULL), KM_OK);
  km_shape_pairs_free(p);
  km_shape_free(&sa);
  km_shape_free(&sb);
  free_curves(a, 2);
  free_curves(b, 2);
}

/* an outline with a large hole on the left and a small one on the right */
static void two_holes(km_curve *c, const size_t *order, double dx) {
  km_curve k[3];
  rect(&k[0], dx, 0, dx + 12, 6, 1);
  circle(&k[1], dx + 3.5, 3, 2, 0);
  circle(&k[2], dx + 9, 3, 1.2, 0);
  for (int i = 0; i < 3; i++) c[i] = k[order[i]];
}

static void pairing_does_not_depend_on_order_or_start(void **state) {
  (void)state;
  const size_t id[3] = {0, 1, 2}, perm[3] = {2, 0, 1};
  km_curve a[3], b[3];
  two_holes(a, id, 0);
  two_holes(b, perm, 30); /* b[0] small hole, b[1] outline, b[2] big hole */
  km_shape sa, sb;
  make_shape(&sa, a, 3);
  make_shape(&sb, b, 3);
  km_shape_pair *p = NULL;
  size_t n = 0;
  get_pairs(&sa, &sb, &p, &n);
  assert_int_equal(n, 3);
  assert_int_equal(partner_of(p, n, 0), 1);
  assert_int_equal(partner_of(p, n, 1), 2);
  assert_int_equal(partner_of(p, n, 2), 0);
  km_shape_pairs_free(p);
  /* the other way round gives the inverse pairing */
  get_pairs(&sb, &sa, &p, &n);
  assert_int_equal(partner_of(p, n, 1), 0);
  assert_int_equal(partner_of(p, n, 2), 1);
  assert_int_equal(partner_of(p, n, 0), 2);
  km_shape_pairs_free(p);
  km_shape_free(&sa);
  km_shape_free(&sb);
  free_curves(a, 3);
  free_curves(b, 3);
}

static void o_to_c_leaves_the_counter_unpaired(void **state) {
  (void)state;
  km_curve o[2], c[1];
  circle(&o[0], 0, 0, 2, 1);
  circle(&o[1], 0, 0, 1.2, 0);
  rect(&c[0], -2, -2, 2, 2, 1);
  km_shape so, sc;
  make_shape(&so, o, 2);
  make_shape(&sc, c, 1);
  km_shape_pair *p = NULL;
  size_t n = 0;
  get_pairs(&so, &sc, &p, &n);
  assert_int_equal(n, 2);
  assert_int_equal(p[0].from, 0);
  assert_int_equal(p[0].to, 0);
  assert_int_equal(p[1].from, 1);
  assert_int_equal(p[1].to, -1);
  km_shape_pairs_free(p);
  /* and the counter appears going back */
  get_pairs(&sc, &so, &p, &n);
  assert_int_equal(n, 2);
  assert_int_equal(p[1].from, -1);
  assert_int_equal(p[1].to, 1);
  km_shape_pairs_free(p);
  km_shape_free(&so);
  km_shape_free(&sc);
  free_curves(o, 2);
  free_curves(c, 1);
}

static void caller_pairing_is_checked(void **state) {
  (void)state;
  const size_t id[3] = {0, 1, 2};
  km_curve a[3], b[3];
  two_holes(a, id, 0);
  two_holes(b, id, 0);
  km_shape sa, sb;
  make_shape(&sa, a, 3);
  make_shape(&sb, b, 3);
  km_error err;
  /* holes crossed over: allowed (same parent pair, same role) */
  const km_shape_pair ok[3] = {{0, 0}, {1, 2}, {2, 1}};
  assert_status(km_shape_pair_check(&sa, &sb, ok, 3, &err), KM_OK);
  /* one hole vanishing, the other appearing */
  const km_shape_pair vanish[4] = {{0, 0}, {1, 1}, {2, -1}, {-1, 2}};
  assert_status(km_shape_pair_check(&sa, &sb, vanish, 4, &err), KM_OK);
  const km_shape_pair role[3] = {{0, 0}, {1, -1}, {2, 1}};
  const km_shape_pair outer_hole[4] = {{0, 1}, {1, 0}, {2, 2}, {-1, -1}};
  assert_status(km_shape_pair_check(&sa, &sb, role, 3, &err), KM_EMATCH);
  assert_int_equal(err.index, 3); /* b's contour 2 is in no pair */
  assert_int_equal(err.field, KM_FIELD_MATCHES);
  assert_status(km_shape_pair_check(&sa, &sb, outer_hole, 4, &err), KM_EMATCH);
  assert_int_equal(err.index, 0);
  const km_shape_pair twice[3] = {{0, 0}, {1, 1}, {1, 2}};
  assert_status(km_shape_pair_check(&sa, &sb, twice, 3, &err), KM_EMATCH);
  assert_int_equal(err.index, 2);
  const km_shape_pair range[3] = {{0, 0}, {1, 1}, {2, 3}};
  assert_status(km_shape_pair_check(&sa, &sb, range, 3, &err), KM_EMATCH);
  assert_int_equal(err.index, 2);
  /* a hole paired under a vanishing parent: its parent is not paired */
  const km_shape_pair orphan[4] = {{0, -1}, {-1, 0}, {1, 1}, {2, 2}};
  assert_status(km_shape_pair_check(&sa, &sb, orphan, 4, &err), KM_EMATCH);
  assert_int_equal(err.index, 2);
  km_shape_free(&sa);
  km_shape_free(&sb);
  free_curves(a, 3);
  free_curves(b, 3);
}

static const struct CMUnitTest tests[] = {
    cmocka_unit_test(ring_nests_the_hole_and_orients_by_role),
    cmocka_unit_test(nonzero_keeps_a_same_turning_inner_contour_filled),
    cmocka_unit_test(nesting_tree_does_not_depend_on_contour_order),
    cmocka_unit_test(shape_refuses_bad_contours_naming_them),
    cmocka_unit_test(copy_is_deep),
    cmocka_unit_test(ring_pairs_outer_with_outer_and_hole_with_hole),
    cmocka_unit_test(pairing_does_not_depend_on_order_or_start),
    cmocka_unit_test(o_to_c_leaves_the_counter_unpaired),
    cmocka_unit_test(caller_pairing_is_checked),
};

TM_SUITE("shape", tests, NULL, NULL);
