/* test_curve_ops.c - knot insertion, split, reverse, Bezier extraction,
 * degree elevation, compatibility, reparameterisation and transforms leave
 * the traced curve exactly as it was.
 *
 * Oracles: a rational quadratic circle (every point at distance R from the
 * centre), polynomials written exactly on a knot vector through their
 * blossoms (testutil.h), and the original curve itself evaluated at the
 * same (or the mapped) parameter.
 */
#include "testutil.h"

#include <string.h>

#include "km/curve.h"
#include "km/limits.h"
#include "testmain.h"

#define CX 1.0
#define CY -1.0
#define R 2.0

/* Full circle of radius R about (CX, CY): nine-point rational quadratic,
 * knots at quarters, weights 1, sqrt(2)/2 alternating. */
static void make_circle(km_curve *c) {
  const double s = sqrt(0.5);
  double knots[] = {0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1};
  double unit[] = {1, 0, 1, 1, 0, 1, -1, 1, -1, 0, -1, -1, 0, -1, 1, -1, 1, 0};
  double cp[18], w[9];
  for (int i = 0; i < 9; i++) {
    cp[2 * i] = CX + R * unit[2 * i];
    cp[2 * i + 1] = CY + R * unit[2 * i + 1];
    w[i] = (i % 2) ? s : 1.0;
  }
  km_error e;
  assert_status(km_curve_create(c, 2, 9, knots, cp, w, true, &e), KM_OK);
}

/* The result is a curve km_curve_create accepts as it stands. */
static void assert_valid(const km_curve *c) {
  km_curve v;
  km_error e;
  assert_status(km_curve_create(&v, c->degree, c->n, c->knots, c->cp, c->w,
                                c->closed, &e),
                KM_OK);
  km_curve_free(&v);
}

static void assert_on_circle(const km_curve *c, int samples) {
  assert_valid(c);
  double t0, t1;
  km_curve_domain(c, &t0, &t1);
  for (int i = 0; i <= samples; i++) {
    double t = t0 + (t1 - t0) * i / samples, p[1][2];
    km_curve_eval(c, t, 0, p);
    assert_rel(hypot(p[0][0] - CX, p[0][1] - CY), R, 1e-12);
  }
}

/* A cubic with a double knot: polynomial x(t) = 1 + 2t - t^2 + 0.5 t^3 and
 * y(t) = -t + 3 t^2 - t^3 on knots that break nothing. */
static const double PX[4] = {1, 2, -1, 0.5};
static const double PY[4] = {0, -1, 3, -1};

static void make_poly_cubic(km_curve *c) {
  double knots[] = {0, 0, 0, 0, 0.3, 0.55, 0.55, 0.8, 1, 1, 1, 1};
  size_t n = 8;
  double cp[16];
  tu_poly_to_bspline(PX, 3, 3, knots, n, cp, 2);
  tu_poly_to_bspline(PY, 3, 3, knots, n, cp + 1, 2);
  km_error e;
  assert_status(km_curve_create(c, 3, n, knots, cp, NULL, false, &e), KM_OK);
}

static void assert_is_poly(const km_curve *c, double t0, double t1) {
  assert_valid(c);
  double a, b;
  km_curve_domain(c, &a, &b);
  for (int i = 0; i <= 200; i++) {
    double u = a + (b - a) * i / 200.0;
    double t = t0 + (t1 - t0) * (u - a) / (b - a), p[1][2];
    km_curve_eval(c, u, 0, p);
    assert_close(p[0][0], tu_poly(PX, 3, t, 0), 1e-13);
    assert_close(p[0][1], tu_poly(PY, 3, t, 0), 1e-13);
  }
}

/* A general (non-polynomial-in-disguise) NURBS: random points and weights
 * on a knot vector with a double knot. */
static void make_random_nurbs(km_curve *c, int degree, uint64_t seed) {
  uint64_t st = seed;
  size_t n = (size_t)degree + 6;
  double knots[32], cp[64], w[32];
  size_t nk = n + (size_t)degree + 1;
  for (size_t i = 0; i < nk; i++) {
    if (i <= (size_t)degree)
      knots[i] = 0;
    else if (i >= n)
      knots[i] = 2;
    else
      knots[i] = knots[i - 1] + tu_uniform(&st, 0.1, 0.5);
  }
  double top = knots[n - 1] + 0.3;
  for (size_t i = (size_t)degree + 1; i < n; i++) knots[i] *= 2.0 / top;
  if (degree >= 2) knots[degree + 3] = knots[degree + 2]; /* a double knot */
  for (size_t i = 0; i < n; i++) {
    cp[2 * i] = tu_uniform(&st, -5, 5);
    cp[2 * i + 1] = tu_uniform(&st, -5, 5);
    w[i] = tu_uniform(&st, 0.3, 3);
  }
  km_error e;
  assert_status(km_curve_create(c, degree, n, knots, cp, w, false, &e), KM_OK);
}

/* Same point at the same parameter (domains equal) within tol. */
static void assert_same_trace(const km_curve *a, const km_curve *b,
                              double tol) {
  assert_valid(b);
  double a0, a1, b0, b1;
  km_curve_domain(a, &a0, &a1);
  km_curve_domain(b, &b0, &b1);
  for (int i = 0; i <= 400; i++) {
    double f = i / 400.0, p[1][2], q[1][2];
    km_curve_eval(a, a0 + (a1 - a0) * f, 0, p);
    km_curve_eval(b, b0 + (b1 - b0) * f, 0, q);
    assert_close(q[0][0], p[0][0], tol);
    assert_close(q[0][1], p[0][1], tol);
  }
}

static size_t mult_of(const km_curve *c, double t) {
  size_t s = 0;
  for (size_t i = 0; i < c->n + (size_t)c->degree + 1; i++)
    if (c->knots[i] == t) s++;
  return s;
}

static void insert_knot_keeps_circle_on_circle(void **state) {
  (void)state;
  km_curve c, a, b;
  make_circle(&c);
  km_error e;
  assert_status(km_curve_insert_knot(&a, &c, 0.1, 1, &e), KM_OK);
  assert_int_equal(a.n, c.n + 1);
  assert_status(km_curve_insert_knot(&b, &a, 0.6, 5, &e), KM_OK);
  /* multiplicity is capped at the degree */
  assert_int_equal(mult_of(&b, 0.6), 2);
  assert_on_circle(&b, 997);
  assert_same_trace(&c, &b, 1e-14);
  assert_true(b.closed);
  assert_true(b.cp[0] == b.cp[2 * (b.n - 1)] &&
              b.cp[1] == b.cp[2 * (b.n - 1) + 1]);
  km_curve_free(&c);
  km_curve_free(&a);
  km_curve_free(&b);
}

static void insert_knot_keeps_polynomial(void **state) {
  (void)state;
  km_curve c, a;
  make_poly_cubic(&c);
  assert_status(km_curve_insert_knot(&a, &c, 0.55, 3, NULL), KM_OK);
  assert_int_equal(mult_of(&a, 0.55), 3);
  assert_is_poly(&a, 0, 1);
  km_curve_free(&a);
  /* inserting an existing full-multiplicity knot or a domain end is a
   * no-op copy */
  assert_status(km_curve_insert_knot(&a, &c, 0.0, 2, NULL), KM_OK);
  assert_int_equal(a.n, c.n);
  km_curve_free(&a);
  km_curve_free(&c);
}

static void insert_knot_keeps_random_nurbs(void **state) {
  (void)state;
  for (int deg = 1; deg <= 5; deg++) {
    km_curve c, a;
    make_random_nurbs(&c, deg, 77 + (uint64_t)deg);
    assert_status(km_curve_insert_knot(&a, &c, 1.234, deg, NULL), KM_OK);
    assert_same_trace(&c, &a, 1e-12);
    km_curve_free(&a);
    km_curve_free(&c);
  }
}

static void insert_knot_rejects_bad_input_and_leaves_out_alone(void **state) {
  (void)state;
  km_curve c, out;
  make_poly_cubic(&c);
  memset(&out, 0x5a, sizeof out);
  km_curve before = out;
  km_error e;
  assert_status(km_curve_insert_knot(&out, &c, 1.5, 1, &e), KM_ERANGE);
  assert_int_equal(e.code, KM_ERANGE);
  assert_status(km_curve_insert_knot(&out, &c, NAN, 1, &e), KM_ENONFINITE);
  assert_status(km_curve_insert_knot(&out, &c, 0.5, -1, &e), KM_EINVAL);
  assert_int_equal(e.field, KM_FIELD_TIMES);
  assert_memory_equal(&out, &before, sizeof out);
  km_curve_free(&c);
}

static void split_pieces_concatenate_to_the_whole(void **state) {
  (void)state;
  km_curve c, l, r;
  make_circle(&c);
  const double ts[] = {0.1, 0.25, 0.6180339887};
  for (int k = 0; k < 3; k++) {
    double t = ts[k];
    assert_status(km_curve_split(&c, t, &l, &r, NULL), KM_OK);
    double l0, l1, r0, r1;
    km_curve_domain(&l, &l0, &l1);
    km_curve_domain(&r, &r0, &r1);
    assert_true(l0 == 0 && l1 == t && r0 == t && r1 == 1);
    assert_false(l.closed || r.closed);
    /* the pieces meet exactly */
    assert_true(l.cp[2 * (l.n - 1)] == r.cp[0] &&
                l.cp[2 * (l.n - 1) + 1] == r.cp[1]);
    for (int i = 0; i <= 300; i++) {
      double u = i / 300.0, p[1][2], q[1][2];
      km_curve_eval(&c, u, 0, p);
      km_curve_eval(u <= t ? &l : &r, u, 0, q);
      assert_close(q[0][0], p[0][0], 1e-14);
      assert_close(q[0][1], p[0][1], 1e-14);
    }
    assert_on_circle(&l, 101);
    assert_on_circle(&r, 101);
    km_curve_free(&l);
    km_curve_free(&r);
  }
  assert_status(km_curve_split(&c, 0.0, &l, &r, NULL), KM_ERANGE);
  assert_status(km_curve_split(&c, 1.0, &l, &r, NULL), KM_ERANGE);
  km_curve_free(&c);
}

static void split_polynomial_pieces_stay_the_polynomial(void **state) {
  (void)state;
  km_curve c, l, r;
  make_poly_cubic(&c);
  assert_status(km_curve_split(&c, 0.55, &l, &r, NULL), KM_OK);
  assert_is_poly(&l, 0, 0.55);
  assert_is_poly(&r, 0.55, 1);
  km_curve_free(&l);
  km_curve_free(&r);
  km_curve_free(&c);
}

static void reverse_traces_the_same_points_backwards(void **state) {
  (void)state;
  km_curve c, r;
  make_random_nurbs(&c, 3, 5);
  assert_status(km_curve_reverse(&r, &c, NULL), KM_OK);
  double a, b, ra, rb;
  km_curve_domain(&c, &a, &b);
  km_curve_domain(&r, &ra, &rb);
  assert_true(ra == a && rb == b);
  for (int i = 0; i <= 300; i++) {
    double t = a + (b - a) * i / 300.0, p[2][2], q[2][2];
    km_curve_eval_side(&c, t, 1, 1, p);
    km_curve_eval_side(&r, a + b - t, -1, 1, q);
    assert_close(q[0][0], p[0][0], 1e-12);
    assert_close(q[0][1], p[0][1], 1e-12);
    /* the velocity flips */
    assert_close(q[1][0], -p[1][0], 1e-9);
    assert_close(q[1][1], -p[1][1], 1e-9);
  }
  km_curve_free(&r);
  km_curve_free(&c);
}

static void to_bezier_has_full_interior_multiplicity(void **state) {
  (void)state;
  km_curve c, bz;
  make_circle(&c);
  assert_status(km_curve_to_bezier(&bz, &c, NULL), KM_OK);
  /* the circle is already in Bezier form */
  assert_int_equal(bz.n, 9);
  km_curve_free(&bz);
  km_curve_free(&c);

  make_random_nurbs(&c, 4, 11);
  assert_status(km_curve_to_bezier(&bz, &c, NULL), KM_OK);
  size_t distinct = 0;
  for (size_t i = 5; i < c.n; i++)
    if (c.knots[i] != c.knots[i - 1]) distinct++;
  assert_int_equal(bz.n, 4 * (distinct + 1) + 1);
  for (size_t k = 1; k <= distinct; k++) {
    double u = bz.knots[4 * k + 1];
    assert_int_equal(mult_of(&bz, u), 4);
  }
  assert_same_trace(&c, &bz, 1e-12);
  km_curve_free(&bz);
  km_curve_free(&c);
}

static void elevate_polynomial_stays_the_polynomial(void **state) {
  (void)state;
  km_curve c, e;
  make_poly_cubic(&c);
  for (int t = 1; t <= 4; t++) {
    assert_status(km_curve_elevate(&e, &c, t, NULL), KM_OK);
    assert_int_equal(e.degree, 3 + t);
    /* each distinct knot's multiplicity grows by t */
    assert_int_equal(mult_of(&e, 0.3), 1 + (size_t)t);
    assert_int_equal(mult_of(&e, 0.55), 2 + (size_t)t);
    assert_int_equal(mult_of(&e, 0.0), 4 + (size_t)t);
    assert_int_equal(e.n, c.n + 4 * (size_t)t);
    assert_is_poly(&e, 0, 1);
    km_curve_free(&e);
  }
  km_curve_free(&c);
}

static void elevate_circle_stays_on_circle(void **state) {
  (void)state;
  km_curve c, e;
  make_circle(&c);
  for (int t = 1; t <= 3; t++) {
    assert_status(km_curve_elevate(&e, &c, t, NULL), KM_OK);
    assert_int_equal(e.degree, 2 + t);
    assert_non_null(e.w);
    for (size_t i = 0; i < e.n; i++) assert_true(e.w[i] > 0);
    assert_on_circle(&e, 1001);
    assert_same_trace(&c, &e, 1e-13);
    assert_true(e.closed);
    km_curve_free(&e);
  }
  km_curve_free(&c);
}

static void elevate_random_nurbs_keeps_trace(void **state) {
  (void)state;
  for (int deg = 1; deg <= 5; deg++) {
    km_curve c, e;
    make_random_nurbs(&c, deg, 300 + (uint64_t)deg);
    assert_status(km_curve_elevate(&e, &c, 2, NULL), KM_OK);
    assert_same_trace(&c, &e, 1e-11);
    km_curve_free(&e);
    km_curve_free(&c);
  }
}

static void elevate_refuses_degree_beyond_limit(void **state) {
  (void)state;
  km_curve c, e;
  make_poly_cubic(&c);
  km_error err;
  assert_status(km_curve_elevate(&e, &c, KM_MAX_DEGREE - 2, &err), KM_EDEGREE);
  assert_int_equal(err.field, KM_FIELD_TIMES);
  assert_status(km_curve_elevate(&e, &c, -1, &err), KM_EINVAL);
  assert_status(km_curve_elevate(&e, &c, KM_MAX_DEGREE - 3, &err), KM_OK);
  assert_int_equal(e.degree, KM_MAX_DEGREE);
  assert_is_poly(&e, 0, 1);
  km_curve_free(&e);
  km_curve_free(&c);
}

static void make_compatible_gives_same_degree_and_knots(void **state) {
  (void)state;
  km_curve a, b, oa, ob;
  make_poly_cubic(&a); /* degree 3, [0, 1], polynomial */
  make_circle(&b);     /* degree 2, [0, 1], rational */
  km_curve b2;
  assert_status(km_curve_reparam(&b2, &b, -3, 5, NULL), KM_OK);
  assert_status(km_curve_make_compatible(&a, &b2, &oa, &ob, NULL), KM_OK);
  assert_int_equal(oa.degree, 3);
  assert_int_equal(ob.degree, 3);
  assert_int_equal(oa.n, ob.n);
  assert_non_null(oa.w);
  assert_non_null(ob.w);
  for (size_t i = 0; i < oa.n; i++) assert_true(oa.w[i] == 1.0);
  assert_memory_equal(oa.knots, ob.knots, (oa.n + 4) * sizeof(double));
  assert_true(oa.knots[0] == 0.0 && oa.knots[oa.n + 3] == 1.0);
  assert_is_poly(&oa, 0, 1);
  assert_on_circle(&ob, 999);
  assert_same_trace(&b, &ob, 1e-13);
  assert_true(ob.closed);
  assert_false(oa.closed);
  km_curve_free(&a);
  km_curve_free(&b);
  km_curve_free(&b2);
  km_curve_free(&oa);
  km_curve_free(&ob);
}

static void make_compatible_of_two_random_nurbs(void **state) {
  (void)state;
  km_curve a, b, oa, ob;
  make_random_nurbs(&a, 2, 1);
  make_random_nurbs(&b, 4, 2);
  assert_status(km_curve_make_compatible(&a, &b, &oa, &ob, NULL), KM_OK);
  assert_int_equal(oa.degree, 4);
  assert_int_equal(oa.n, ob.n);
  assert_memory_equal(oa.knots, ob.knots, (oa.n + 5) * sizeof(double));
  assert_same_trace(&a, &oa, 1e-11);
  assert_same_trace(&b, &ob, 1e-11);
  km_curve_free(&a);
  km_curve_free(&b);
  km_curve_free(&oa);
  km_curve_free(&ob);
}

static void make_compatible_merges_knots_equal_up_to_rounding(void **state) {
  (void)state;
  /* A's knot 0.55 on [0.1, 0.7] and B's knot 0.75 on [0, 1] are the same
   * place once both live on [0, 1], although (0.55 - 0.1) / 0.6 rounds to
   * 0.7500000000000001 */
  double ka[] = {0.1, 0.1, 0.1, 0.1, 0.55, 0.7, 0.7, 0.7, 0.7};
  double kb[] = {0, 0, 0, 0, 0.75, 1, 1, 1, 1};
  double pa[] = {0, 0, 1, 2, 2, 3, 3, 1, 4, 0};
  double pb[] = {0, 5, 1, 6, 2, 6, 3, 5, 4, 4};
  km_curve a, b, oa, ob;
  assert_status(km_curve_create(&a, 3, 5, ka, pa, NULL, false, NULL), KM_OK);
  assert_status(km_curve_create(&b, 3, 5, kb, pb, NULL, false, NULL), KM_OK);
  assert_status(km_curve_make_compatible(&a, &b, &oa, &ob, NULL), KM_OK);
  /* one shared interior knot, not two a hair apart */
  assert_int_equal(oa.n, 5);
  assert_int_equal(ob.n, 5);
  assert_null(oa.w);
  assert_memory_equal(oa.knots, ob.knots, 9 * sizeof(double));
  assert_same_trace(&a, &oa, 1e-13);
  assert_same_trace(&b, &ob, 1e-13);
  km_curve_free(&a);
  km_curve_free(&b);
  km_curve_free(&oa);
  km_curve_free(&ob);
}

/* Curvature of c at t from its first two derivatives. */
static double curvature_at(const km_curve *c, double t) {
  double d[3][2];
  km_curve_eval(c, t, 2, d);
  double sp = hypot(d[1][0], d[1][1]);
  return (d[1][0] * d[2][1] - d[1][1] * d[2][0]) / (sp * sp * sp);
}

static void make_compatible_drops_slivers_at_the_ends(void **state) {
  (void)state;
  /* A closed curve whose seam was moved next to a knot carries spans a
   * few ulps wide at its ends (a circle's seam moved to within 2e-16 of
   * a knot, as a closed morph's start search leaves it); kept, they
   * become spans of nearly repeated control points whose second
   * derivative is rounding divided by (2e-16)^2, the curvature 1e16 where
   * the circle's is 1 / R. */
  km_curve c, c1, s, a, oa, ob;
  make_circle(&c);
  assert_status(km_curve_insert_knot(&c1, &c, 2e-16, 2, NULL), KM_OK);
  assert_status(km_curve_insert_knot(&s, &c1, 1 - 1.5e-16, 2, NULL), KM_OK);
  assert_int_equal(s.n, c.n + 4);
  make_poly_cubic(&a);
  assert_status(km_curve_make_compatible(&a, &s, &oa, &ob, NULL), KM_OK);
  assert_memory_equal(oa.knots, ob.knots, (oa.n + 4) * sizeof(double));
  /* no span narrower than the inputs' own (0.05 and 0.25 wide) */
  for (size_t i = 3; i < ob.n; i++) {
    double w = ob.knots[i + 1] - ob.knots[i];
    assert_true(w == 0.0 || w > 0.01);
  }
  assert_on_circle(&ob, 999);
  assert_true(ob.closed);
  assert_true(ob.cp[0] == ob.cp[2 * (ob.n - 1)] &&
              ob.cp[1] == ob.cp[2 * (ob.n - 1) + 1]);
  /* the circle's curvature everywhere, the ends and their sides too */
  for (int i = 0; i <= 1000; i++) {
    double t = i / 1000.0;
    assert_rel(curvature_at(&ob, t), 1.0 / R, 1e-9);
  }
  for (double t = 1e-17; t < 1e-12; t *= 10) {
    assert_rel(curvature_at(&ob, t), 1.0 / R, 1e-9);
    assert_rel(curvature_at(&ob, 1 - t), 1.0 / R, 1e-9);
  }
  assert_is_poly(&oa, 0, 1);
  km_curve_free(&c);
  km_curve_free(&c1);
  km_curve_free(&s);
  km_curve_free(&a);
  km_curve_free(&oa);
  km_curve_free(&ob);
}

static void reparam_maps_domain_linearly(void **state) {
  (void)state;
  km_curve c, r;
  make_poly_cubic(&c);
  assert_status(km_curve_reparam(&r, &c, 10, 14, NULL), KM_OK);
  double a, b;
  km_curve_domain(&r, &a, &b);
  assert_true(a == 10 && b == 14);
  assert_is_poly(&r, 0, 1);
  assert_status(km_curve_reparam(&r, &c, 1, 1, NULL), KM_ERANGE);
  km_curve_free(&r);
  km_curve_free(&c);
}

static void transform_moves_circle_rigidly(void **state) {
  (void)state;
  km_curve c, t;
  make_circle(&c);
  double rot = 0.7, tx = 3, ty = -2;
  assert_status(km_curve_transform(&t, &c, rot, tx, ty, NULL), KM_OK);
  /* the centre maps to R(c) + t and the radius is kept */
  double ncx = cos(rot) * CX - sin(rot) * CY + tx;
  double ncy = sin(rot) * CX + cos(rot) * CY + ty;
  for (int i = 0; i <= 400; i++) {
    double u = i / 400.0, p[1][2], q[1][2];
    km_curve_eval(&t, u, 0, p);
    km_curve_eval(&c, u, 0, q);
    assert_rel(hypot(p[0][0] - ncx, p[0][1] - ncy), R, 1e-12);
    /* and each point is the image of the original point */
    assert_close(p[0][0], cos(rot) * q[0][0] - sin(rot) * q[0][1] + tx, 1e-13);
    assert_close(p[0][1], sin(rot) * q[0][0] + cos(rot) * q[0][1] + ty, 1e-13);
  }
  km_curve_free(&t);
  km_curve_free(&c);
}

static const struct CMUnitTest tests[] = {
    cmocka_unit_test(insert_knot_keeps_circle_on_circle),
    cmocka_unit_test(insert_knot_keeps_polynomial),
    cmocka_unit_test(insert_knot_keeps_random_nurbs),
    cmocka_unit_test(insert_knot_rejects_bad_input_and_leaves_out_alone),
    cmocka_unit_test(split_pieces_concatenate_to_the_whole),
    cmocka_unit_test(split_polynomial_pieces_stay_the_polynomial),
    cmocka_unit_test(reverse_traces_the_same_points_backwards),
    cmocka_unit_test(to_bezier_has_full_interior_multiplicity),
    cmocka_unit_test(elevate_polynomial_stays_the_polynomial),
    cmocka_unit_test(elevate_circle_stays_on_circle),
    cmocka_unit_test(elevate_random_nurbs_keeps_trace),
    cmocka_unit_test(elevate_refuses_degree_beyond_limit),
    cmocka_unit_test(make_compatible_gives_same_degree_and_knots),
    cmocka_unit_test(make_compatible_of_two_random_nurbs),
    cmocka_unit_test(make_compatible_merges_knots_equal_up_to_rounding),
    cmocka_unit_test(make_compatible_drops_slivers_at_the_ends),
    cmocka_unit_test(reparam_maps_domain_linearly),
    cmocka_unit_test(transform_moves_circle_rigidly),
};

TM_SUITE("curve_ops", tests, NULL, NULL);
