/* test_svg_write.c - curves out as SVG path data: exact cubics for
 * polynomial curves of degree <= 3, bounded approximations for rational and
 * higher-degree curves, fixed piece counts for animation, and the
 * parse -> export -> parse round trip.
 *
 * Oracles: the curve exported (distance between traces, sampled densely and
 * refined), circles (radius and equal central angles for pieces uniform in
 * arc length), and counts of commands and numbers in the text.
 */
#include <ctype.h>
#include <stdbool.h>
#include <string.h>

#include "svg_testutil.h"
#include "testmain.h"

/* Command letters of d in order, and the count of numbers. */
static void structure(const char *d, char *cmds, size_t cap, size_t *nums) {
  size_t k = 0;
  *nums = 0;
  for (const char *p = d; *p;) {
    if (isalpha((unsigned char)*p) && *p != 'e' && *p != 'E') {
      if (k + 1 < cap) cmds[k++] = *p;
      p++;
    } else if (isdigit((unsigned char)*p) || *p == '.' || *p == '-' ||
               *p == '+') {
      char *end;
      strtod(p, &end);
      assert_true(end > p);
      (*nums)++;
      p = end;
    } else {
      p++;
    }
  }
  cmds[k] = '\0';
}

static void export_parse(const km_curve *c, double tol, km_curve *back,
                         double *bound) {
  char *d = api_svg_path_d(c, tol, bound);
  assert_non_null(d);
  st_parse(d, back);
  free(d);
}

/* A polynomial cubic exports exactly: parsed back it is the same curve at
 * the same parameters up to the printing budget. */
static void polynomial_cubic_exports_exactly(void **state) {
  (void)state;
  km_curve c, back;
  st_parse("M0 0C1 2 3 2 4 0S7-2 8 0L9 3Q11 5 12 3Z", &c);
  double bound = -1;
  export_parse(&c, 1e-6, &back, &bound);
  assert_le(bound, 1e-6);
  assert_true(bound >= 0);
  assert_true(back.closed);
  st_same_at_params(&c, &back, bound, "cubic export");
  km_curve_free(&back);
  /* with tol <= 0 every number is printed to round-trip exactly */
  export_parse(&c, 0, &back, &bound);
  st_same_at_params(&c, &back, 1e-13, "exact export");
  km_curve_free(&back);
  km_curve_free(&c);
}

/* Output is cubic Beziers only: "M" then "C" with 3 points a piece, "Z"
 * for closed curves; degree 1 and 2 pieces are raised, one cubic each. */
static void output_is_one_moveto_and_cubics(void **state) {
  (void)state;
  km_curve c;
  char cmds[16];
  size_t nums;
  st_parse("M0 0L10 0Q15 5 10 10L0 10z", &c);
  char *d = api_svg_path_d(&c, 1e-3, NULL);
  assert_non_null(d);
  structure(d, cmds, sizeof cmds, &nums);
  assert_string_equal(cmds, "MCZ");
  assert_int_equal(nums, 2 + 6 * 4);
  free(d);
  km_curve_free(&c);
}

/* A circle from two arcs is rational: the cubic path is within the
 * tolerance of it (points at distance r), the bound covers the true
 * error, and a tighter tolerance gives a tighter path. */
static void rational_circle_exports_within_the_stated_bound(void **state) {
  (void)state;
  km_curve c;
  st_parse("M20,100 A80,80 0 1,1 180,100 A80,80 0 1,1 20,100 Z", &c);
  const double tols[] = {1.0, 1e-2, 1e-4, 1e-7};
  for (int k = 0; k < 4; k++) {
    km_curve back;
    double bound = -1;
    export_parse(&c, tols[k], &back, &bound);
    assert_le(bound, tols[k]);
    assert_true(back.closed);
    assert_null(back.w);
    double t0, t1, worst = 0;
    km_curve_domain(&back, &t0, &t1);
    for (int i = 0; i <= 4000; i++) {
      double p[2];
      st_pos(&back, t0 + (t1 - t0) * i / 4000.0, p);
      double e = fabs(hypot(p[0] - 100, p[1] - 100) - 80);
      if (e > worst) worst = e;
    }
    assert_le(worst, bound);
    km_curve_free(&back);
  }
  km_curve_free(&c);
}

/* A degree-5 polynomial curve (no exact cubic form) is approximated within
 * the bound, which is within the tolerance. */
static void quintic_exports_within_the_stated_bound(void **state) {
  (void)state;
  const double knots[] = {0, 0, 0, 0, 0, 0, 0.4, 1, 1, 1, 1, 1, 1};
  const double cp[] = {0, 0, 2, 5, 4, -1, 7, 6, 9, 0, 11, 4, 14, 2};
  km_curve c, back;
  km_curve_init(&c);
  assert_status(km_curve_create(&c, 5, 7, knots, cp, NULL, false, NULL), KM_OK);
  const double tols[] = {1e-1, 1e-3, 1e-6};
  for (int k = 0; k < 3; k++) {
    double bound = -1;
    export_parse(&c, tols[k], &back, &bound);
    assert_le(bound, tols[k]);
    assert_le(st_trace_distance(&c, &back), bound);
    km_curve_free(&back);
  }
  km_curve_free(&c);
}

/* parse -> export -> parse keeps the trace for every real path, glyph and
 * fixture shape, within the bound the export states. */
static void parse_export_parse_keeps_the_trace(void **state) {
  (void)state;
  static const char *more[] = {
      "M12 21.35l-1.45-1.32C5.4 15.36 2 12.28 2 8.5 2 5.42 4.42 3 7.5 3c1.74 "
      "0 3.41.81 4.5 2.09C13.09 3.81 14.76 3 16.5 3 19.58 3 22 5.42 22 8.5c0 "
      "3.78-3.4 6.86-8.55 11.54L12 21.35z",
      "M300-10Q180-10 112 65T44 270Q44 400 112 475T300 550Q420 550 488 "
      "475T556 270Q556 140 488 65T300-10Z",
      "m10 315 l100-100 a30 50 0 0 1 52.55-52.55 l10-10 a30 50-45 0 1 "
      "42.55-42.55 l99.9-99.9",
      "M12 2a10 10 0 1 0 10 10H12z",
      "M0 0A0.5 3 30 1 1 1e-3 1e-3",
  };
  st_shapes s;
  st_load_shapes(&s);
  const char *all[32];
  size_t n = 0;
  for (size_t i = 0; i < s.n; i++) {
    all[n++] = s.d[i][0];
    all[n++] = s.d[i][1];
  }
  for (size_t i = 0; i < sizeof more / sizeof more[0]; i++) all[n++] = more[i];
  for (size_t i = 0; i < n; i++) {
    km_curve c, back, again;
    st_parse(all[i], &c);
    double tol = 1e-4 * st_scale(&c), bound = -1;
    export_parse(&c, tol, &back, &bound);
    assert_le(bound, tol);
    assert_int_equal(back.closed, c.closed);
    double dist = st_trace_distance(&c, &back);
    if (!(dist <= bound)) {
      print_error("%s: traces %g apart, bound %g\n", all[i], dist, bound);
      fail();
    }
    if (!c.w) st_same_at_params(&c, &back, bound, all[i]);
    /* and once more: the exported path is a fixed point up to printing */
    double bound2;
    export_parse(&back, tol, &again, &bound2);
    st_same_at_params(&back, &again, bound2, all[i]);
    km_curve_free(&c);
    km_curve_free(&back);
    km_curve_free(&again);
  }
  st_free_shapes(&s);
}

/* Fixed piece counts: exactly n cubics whatever the curve, and on a circle
 * (uniform in arc length = uniform in angle) the piece ends are at equal
 * central angles 2 pi / n and on the circle. */
static void fixed_pieces_are_uniform_in_arc_length(void **state) {
  (void)state;
  km_curve c;
  st_parse("M20,100 A80,80 0 1,1 180,100 A80,80 0 1,1 20,100 Z", &c);
  const size_t counts[] = {1, 3, 12, 50};
  for (int k = 0; k < 4; k++) {
    size_t np = counts[k];
    char *d = api_svg_path_d_fixed(&c, np);
    assert_non_null(d);
    char cmds[8];
    size_t nums;
    structure(d, cmds, sizeof cmds, &nums);
    assert_string_equal(cmds, "MCZ");
    assert_int_equal(nums, 2 + 6 * np);
    /* piece ends: numbers 0,1 then every third point */
    double v[2 + 6 * 50];
    const char *p = strchr(d, 'M') + 1;
    for (size_t i = 0; i < nums; i++) {
      while (*p && !(isdigit((unsigned char)*p) || *p == '-' || *p == '.')) p++;
      char *end;
      v[i] = strtod(p, &end);
      p = end;
    }
    /* coordinates are printed to 1e-6 of the drawing's extent (180):
     * that much in position, over the radius in angle */
    const double pos_tol = 2e-6 * 180, ang_tol = pos_tol / 80;
    double a0 = atan2(v[1] - 100, v[0] - 100);
    for (size_t j = 1; j <= np; j++) {
      double x = v[2 + 6 * (j - 1) + 4], y = v[2 + 6 * (j - 1) + 5];
      assert_close(hypot(x - 100, y - 100), 80, pos_tol);
      double a = atan2(y - 100, x - 100);
      /* sweep 1 with y down: the angle grows */
      assert_close(tu_wrap(a - a0 - 2 * M_PI * (double)j / (double)np), 0,
                   ang_tol);
    }
    free(d);
  }
  km_curve_free(&c);
}

/* Frames of different shapes written with one piece count share one
 * command structure, and an open curve gets no Z unless asked. */
static void fixed_pieces_give_one_structure_for_different_shapes(void **state) {
  (void)state;
  st_shapes s;
  st_load_shapes(&s);
  char first[64] = "";
  size_t first_n = 0;
  for (size_t i = 0; i < s.n; i++) {
    km_curve c;
    st_parse(s.d[i][0], &c);
    char *d = api_svg_path_d_fixed_z(&c, 24, true);
    char cmds[64];
    size_t nums;
    structure(d, cmds, sizeof cmds, &nums);
    if (i == 0) {
      strcpy(first, cmds);
      first_n = nums;
    }
    assert_string_equal(cmds, first);
    assert_int_equal(nums, first_n);
    free(d);
    d = api_svg_path_d_fixed(&c, 24);
    assert_int_equal(strchr(d, 'Z') != NULL, c.closed);
    free(d);
    km_curve_free(&c);
  }
  st_free_shapes(&s);
}

/* Numbers are compact: integers print as integers, no exponent for
 * ordinary sizes, and the printing error respects the budget. */
static void numbers_are_compact_and_within_budget(void **state) {
  (void)state;
  const double xs[] = {0,    20,      -100, 0.5,      123.456789,
                       1e-7, -3.25e9, 1e15, 7.0 / 3.0};
  const double budgets[] = {0, 1e-3, 0.25};
  for (int b = 0; b < 3; b++)
    for (size_t i = 0; i < sizeof xs / sizeof xs[0]; i++) {
      api_svg_buf buf;
      api__svg_buf_init(&buf);
      double err = 0;
      api__svg_buf_num(&buf, xs[i], budgets[b], &err);
      char *s = api__svg_buf_take(&buf);
      assert_non_null(s);
      double back = strtod(s, NULL);
      assert_le(fabs(back - xs[i]), budgets[b]);
      assert_close(err, fabs(back - xs[i]), 0);
      if (budgets[b] == 0) assert_true(back == xs[i]);
      free(s);
    }
  api_svg_buf buf;
  api__svg_buf_init(&buf);
  api__svg_buf_num(&buf, 20, 1e-6, NULL);
  api__svg_buf_put(&buf, " ");
  api__svg_buf_num(&buf, -100, 1e-6, NULL);
  api__svg_buf_put(&buf, " ");
  api__svg_buf_num(&buf, 0.1 + 0.2, 1e-9, NULL);
  api__svg_buf_put(&buf, " ");
  api__svg_buf_num(&buf, NAN, 1e-9, NULL);
  char *s = api__svg_buf_take(&buf);
  assert_string_equal(s, "20 -100 0.3 0");
  free(s);
}

static const struct CMUnitTest tests[] = {
    cmocka_unit_test(polynomial_cubic_exports_exactly),
    cmocka_unit_test(output_is_one_moveto_and_cubics),
    cmocka_unit_test(rational_circle_exports_within_the_stated_bound),
    cmocka_unit_test(quintic_exports_within_the_stated_bound),
    cmocka_unit_test(parse_export_parse_keeps_the_trace),
    cmocka_unit_test(fixed_pieces_are_uniform_in_arc_length),
    cmocka_unit_test(fixed_pieces_give_one_structure_for_different_shapes),
    cmocka_unit_test(numbers_are_compact_and_within_budget),
};

TM_SUITE("svg_write", tests, NULL, NULL);
