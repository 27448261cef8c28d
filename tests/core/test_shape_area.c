/* test_shape_area.c - the area and centroid a shape measures for each
 * contour, against closed forms.
 *
 * Oracles: the shoelace formulas of a polygon (a degree-1 B-spline) and,
 * for a closed curve of cubic Bezier pieces, the Bezier area formula
 * (1/20 of a weighted sum of the control points' cross products) and
 * Green's centroid integrals done on each piece's power form, term by
 * term. Both shapes sit far from the origin beside their size, where the
 * integrals of x dy and y dx nearly cancel.
 */
#include <math.h>

#include "km/curve.h"
#include "km/shape.h"
#include "testutil.h"
#include "testmain.h"

/* Relative agreement promised: exact up to rounding. */
#define EXACT 1e-12

static void one_contour_shape(km_shape *s, const km_curve *c) {
  km_error err;
  km_shape_init(s);
  assert_status(km_shape_create(s, c, 1, KM_FILL_NONZERO, NULL, &err), KM_OK);
}

static void
polygon_area_and_centroid_are_the_shoelace_closed_forms(void **state) {
  (void)state;
  /* given an L-shaped hexagon (closed: the first point again) far from
   * the origin, as a degree-1 B-spline */
  static const double xy[7][2] = {{0, 0}, {4, 0}, {4, 1}, {1, 1},
                                  {1, 3}, {0, 3}, {0, 0}};
  const double ox = 1000.0, oy = -700.0;
  double cp[14], kn[9] = {0, 0, 1, 2, 3, 4, 5, 6, 6};
  for (int i = 0; i < 7; i++) {
    cp[2 * i] = ox + xy[i][0];
    cp[2 * i + 1] = oy + xy[i][1];
  }
  double a = 0, cx = 0, cy = 0;
  for (int i = 0; i < 6; i++) {
    double cr = xy[i][0] * xy[i + 1][1] - xy[i + 1][0] * xy[i][1];
    a += 0.5 * cr;
    cx += (xy[i][0] + xy[i + 1][0]) * cr;
    cy += (xy[i][1] + xy[i + 1][1]) * cr;
  }
  cx = ox + cx / (6 * a);
  cy = oy + cy / (6 * a);
  km_curve c;
  km_error err;
  km_curve_init(&c);
  assert_status(km_curve_create(&c, 1, 7, kn, cp, NULL, true, &err), KM_OK);
  /* when it becomes a shape */
  km_shape s;
  one_contour_shape(&s, &c);
  /* then its area is 6 and its centroid the polygon's */
  assert_close(a, 6.0, 1e-15);
  assert_close(s.area[0], a, EXACT * a);
  assert_close(s.centroid[0], cx, EXACT * 4);
  assert_close(s.centroid[1], cy, EXACT * 4);
  km_shape_free(&s);
  km_curve_free(&c);
}

/* Power form of a cubic Bezier coordinate: sum of c[k] u^k. */
static void power_form(double p0, double p1, double p2, double p3,
                       double c[4]) {
  c[0] = p0;
  c[1] = 3 * (p1 - p0);
  c[2] = 3 * (p0 - 2 * p1 + p2);
  c[3] = p3 - 3 * p2 + 3 * p1 - p0;
}

/* Integral over [0, 1] of a(u) b(u) c'(u) for power forms of degree 3
 * (b NULL: of a(u) c'(u)). */
static double integral(const double a[4], const double *b, const double c[4]) {
  double s = 0;
  for (int i = 0; i < 4; i++)
    for (int j = 0; j < 4; j++)
      for (int k = 1; k < 4; k++) {
        if (!b && j > 0) continue;
        int e = i + (b ? j : 0) + k - 1;
        s += a[i] * (b ? b[j] : 1.0) * k * c[k] / (e + 1);
      }
  return s;
}

static void cubic_area_and_centroid_are_the_bezier_closed_forms(void **state) {
  (void)state;
  /* given a closed curve of three cubic Bezier pieces (interior knots
   * triple) far from the origin */
  static const double xy[10][2] = {{0, 0}, {4, -1}, {7, 1}, {8, 3},  {9, 5},
                                   {6, 8}, {3, 7},  {0, 6}, {-2, 2}, {0, 0}};
  const double ox = 250.0, oy = -120.0;
  double cp[20], kn[14] = {0, 0, 0, 0, 1, 1, 1, 2, 2, 2, 3, 3, 3, 3};
  for (int i = 0; i < 10; i++) {
    cp[2 * i] = ox + xy[i][0];
    cp[2 * i + 1] = oy + xy[i][1];
  }
  /* area by the Bezier formula, centroid by Green on the power forms,
   * both about the curve's own frame and then moved */
  double a = 0, mx = 0, my = 0;
  for (int p = 0; p < 3; p++) {
    const double(*P)[2] = xy + 3 * p;
#define CR(i, j) (P[i][0] * P[j][1] - P[j][0] * P[i][1])
    a += (6 * CR(0, 1) + 3 * CR(0, 2) + CR(0, 3) + 3 * CR(1, 2) + 3 * CR(1, 3) +
          6 * CR(2, 3)) /
         20.0;
#undef CR
    double X[4], Y[4];
    power_form(P[0][0], P[1][0], P[2][0], P[3][0], X);
    power_form(P[0][1], P[1][1], P[2][1], P[3][1], Y);
    mx += 0.5 * integral(X, X, Y);
    my -= 0.5 * integral(Y, Y, X);
    /* the area once more by Green's x dy - y dx: the formula checked */
    assert_close(0.5 * (integral(X, NULL, Y) - integral(Y, NULL, X)),
                 (6 * (P[0][0] * P[1][1] - P[1][0] * P[0][1]) +
                  3 * (P[0][0] * P[2][1] - P[2][0] * P[0][1]) +
                  (P[0][0] * P[3][1] - P[3][0] * P[0][1]) +
                  3 * (P[1][0] * P[2][1] - P[2][0] * P[1][1]) +
                  3 * (P[1][0] * P[3][1] - P[3][0] * P[1][1]) +
                  6 * (P[2][0] * P[3][1] - P[3][0] * P[2][1])) /
                     20.0,
                 1e-12);
  }
  double cx = ox + mx / a, cy = oy + my / a;
  km_curve c;
  km_error err;
  km_curve_init(&c);
  assert_status(km_curve_create(&c, 3, 10, kn, cp, NULL, true, &err), KM_OK);
  /* when it becomes a shape */
  km_shape s;
  one_contour_shape(&s, &c);
  /* then its area and centroid are the closed forms' */
  assert_true(a > 0);
  assert_close(s.area[0], a, EXACT * a);
  assert_close(s.centroid[0], cx, EXACT * 10);
  assert_close(s.centroid[1], cy, EXACT * 10);
  km_shape_free(&s);
  km_curve_free(&c);
}

static const struct CMUnitTest tests[] = {
    cmocka_unit_test(polygon_area_and_centroid_are_the_shoelace_closed_forms),
    cmocka_unit_test(cubic_area_and_centroid_are_the_bezier_closed_forms),
};

TM_SUITE("shape_area", tests, NULL, NULL);
