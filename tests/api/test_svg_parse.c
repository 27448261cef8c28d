/* test_svg_parse.c - the SVG 1.1 path-data parser: real icon and glyph
 * paths, every grammar corner, the shapes fixture, arcs, and errors with
 * their offsets.
 *
 * Oracles: each shorthand or relative path is compared with the same path
 * written out by hand in absolute, explicit commands (the reflections of S
 * and T, relative sums and implicit commands worked out on paper); the
 * fixture's exact B-splines; circles (radius and curvature 1/r).
 */
#include <stdbool.h>
#include <string.h>

#include "svg_testutil.h"
#include "testmain.h"

typedef struct pair {
  const char *what, *d, *abs;
} pair;

/* Real paths: icons (Material Design), glyph outlines as font tools export
 * them (TrueType quadratics with T), and the MDN path examples. */
static const pair REAL[] = {
    {"home icon", "M10 20v-6h4v6h5v-8h3L12 3 2 12h3v8z",
     "M10,20 V14 H14 V20 H19 V12 H22 L12,3 L2,12 H5 V20 Z"},
    {"heart icon",
     "M12 21.35l-1.45-1.32C5.4 15.36 2 12.28 2 8.5 2 5.42 4.42 3 7.5 3c1.74 "
     "0 3.41.81 4.5 2.09C13.09 3.81 14.76 3 16.5 3 19.58 3 22 5.42 22 8.5c0 "
     "3.78-3.4 6.86-8.55 11.54L12 21.35z",
     "M12,21.35 L10.55,20.03 C5.4,15.36 2,12.28 2,8.5 C2,5.42 4.42,3 7.5,3 "
     "C9.24,3 10.91,3.81 12,5.09 C13.09,3.81 14.76,3 16.5,3 C19.58,3 22,5.42 "
     "22,8.5 C22,12.28 18.6,15.36 13.45,20.04 L12,21.35 Z"},
    {"check icon", "M20 6 9 17l-5-5", "M20,6 L9,17 L4,12"},
    {"glyph o, absolute quadratics",
     "M300-10Q180-10 112 65T44 270Q44 400 112 475T300 550Q420 550 488 "
     "475T556 270Q556 140 488 65T300-10Z",
     "M300,-10 Q180,-10 112,65 Q44,140 44,270 Q44,400 112,475 Q180,550 "
     "300,550 Q420,550 488,475 Q556,400 556,270 Q556,140 488,65 Q420,-10 "
     "300,-10 Z"},
    {"glyph o, relative quadratics",
     "m 300,-10 q -120,0 -188,75 t -68,205 q 0,130 68,205 t 188,75 q 120,0 "
     "188,-75 t 68,-205 q 0,-130 -68,-205 t -188,-75 z",
     "M300,-10 Q180,-10 112,65 Q44,140 44,270 Q44,400 112,475 Q180,550 "
     "300,550 Q420,550 488,475 Q556,400 556,270 Q556,140 488,65 Q420,-10 "
     "300,-10 Z"},
    {"pie icon", "M12 2a10 10 0 1 0 10 10H12z",
     "M12,2 A10,10 0 1,0 22,12 L12,12 Z"},
    {"MDN smooth cubic", "M10 80 C 40 10, 65 10, 95 80 S 150 150, 180 80",
     "M10,80 C40,10 65,10 95,80 C125,150 150,150 180,80"},
    {"MDN smooth quadratic", "M10 80 Q 52.5 10, 95 80 T 180 80",
     "M10,80 Q52.5,10 95,80 Q137.5,150 180,80"},
    {"MDN arcs, relative",
     "m10 315 l100-100 a30 50 0 0 1 52.55-52.55 l10-10 a30 50-45 0 1 "
     "42.55-42.55 l99.9-99.9",
     "M 10 315 L 110 215 A 30 50 0 0 1 162.55 162.45 L 172.55 152.45 A 30 "
     "50 -45 0 1 215.1 109.9 L 315 10"},
};

/* Grammar corners, each against its explicit absolute form. */
static const pair GRAMMAR[] = {
    {"no separators", "M1,2L3,4", "M 1 2 L 3 4"},
    {"implicit lineto after M", "M1 2 3 4 5 6", "M1 2 L3 4 L5 6"},
    {"first m absolute, then relative lineto", "m1 2 3 4 5 6",
     "M1 2 L4 6 L9 12"},
    {"repeated L", "M0 0L1 1 2 0 3 1", "M0 0 L1 1 L2 0 L3 1"},
    {"repeated relative h and v", "M0 0h1 2v3-4", "M0 0 H1 H3 V3 V-1"},
    {"exponents and leading dots", "M.5.5L1e-3-2E+1", "M0.5 0.5 L0.001 -20"},
    {"numbers split by dots", "M1.5.5.5.5", "M1.5 0.5 L0.5 0.5"},
    {"numbers split by signs", "M-1-2-3-4", "M-1 -2 L-3 -4"},
    {"plus signs", "M+1+2L+.5-.5", "M1 2 L0.5 -0.5"},
    {"exponent forms", "M0 0 1e1 1E1 2.5e+1-1.0E-0", "M0 0 L10 10 L25 -1"},
    {"white space everywhere", " \t\r\nM\n1\t2\r\nL 3 , 4 \n", "M1 2 L3 4"},
    {"arc flags without separators", "M0 0a1 1 0 00 1 1",
     "M0 0 A1 1 0 0 0 1 1"},
    {"arc flags with commas", "M0 0a1,1,0,1,1,1,1", "M0 0 A1 1 0 1 1 1 1"},
    {"arc flags run into the coordinate", "M0 0A1 1 0 1110 10",
     "M0 0 A1 1 0 1 1 10 10"},
    {"repeated arcs", "M0 0A1 1 0 0 1 2 0 1 1 0 0 1 4 0",
     "M0 0 A1 1 0 0 1 2 0 A1 1 0 0 1 4 0"},
    {"repeated C", "M0 0C1 1 2 1 3 0 4 -1 5 -1 6 0",
     "M0 0 C1 1 2 1 3 0 C4 -1 5 -1 6 0"},
    {"repeated relative c", "M0 0c1 1 2 1 3 0 1-1 2-1 3 0",
     "M0 0 C1 1 2 1 3 0 C4 -1 5 -1 6 0"},
    {"S after L starts at the current point", "M0 0L1 0S2 1 3 0",
     "M0 0 L1 0 C1 0 2 1 3 0"},
    {"repeated S reflects each time", "M0 0C0 1 1 1 1 0S2-1 2 0 3 1 3 0",
     "M0 0 C0 1 1 1 1 0 C1 -1 2 -1 2 0 C2 1 3 1 3 0"},
    {"relative s", "M0 0c0 1 1 1 1 0s1-1 1 0",
     "M0 0 C0 1 1 1 1 0 C1 -1 2 -1 2 0"},
    {"T after L starts at the current point", "M0 0L1 0T3 1",
     "M0 0 L1 0 Q1 0 3 1"},
    {"repeated relative t", "M0 0q1 1 2 0t2 0 2 0",
     "M0 0 Q1 1 2 0 Q3 -1 4 0 Q5 1 6 0"},
    {"S after Q does not reflect", "M0 0Q1 1 2 0S3 1 4 0",
     "M0 0 Q1 1 2 0 C2 0 3 1 4 0"},
    {"T after C does not reflect", "M0 0C1 1 2 1 3 0T5 1",
     "M0 0 C1 1 2 1 3 0 Q3 0 5 1"},
    {"closepath twice", "M0 0L1 0L1 1ZZ", "M0 0 L1 0 L1 1 Z"},
    {"lowercase z", "M0 0L1 0L1 1z", "M0 0 L1 0 L1 1 Z"},
    {"trailing moveto after Z", "M0 0L1 0L1 1Z M5 5", "M0 0L1 0L1 1Z"},
    {"trailing relative moveto", "M0 0 L1 1 m 3 3", "M0 0 L1 1"},
    {"leading movetos move the start", "M9 9 M0 0 L1 1", "M0 0 L1 1"},
    {"zero radius arc is a line", "M0 0A0 5 0 0 1 4 3", "M0 0 L4 3"},
    {"arc to the current point adds nothing", "M0 0L4 3A5 5 0 0 1 4 3",
     "M0 0 L4 3"},
    {"zero-length line is dropped", "M0 0L0 0L4 3l0 0", "M0 0 L4 3"},
    {"negative radii count as positive", "M0 0A-1-1 0 0 1 2 0",
     "M0 0 A1 1 0 0 1 2 0"},
};

static void check_pairs(const pair *t, size_t n) {
  for (size_t i = 0; i < n; i++) {
    km_curve a, b;
    st_parse(t[i].d, &a);
    st_parse(t[i].abs, &b);
    if (a.degree != b.degree || a.n != b.n || (a.w == NULL) != (b.w == NULL) ||
        a.closed != b.closed) {
      print_error("%s: degree %d/%d, n %zu/%zu, rational %d/%d, closed %d/%d\n",
                  t[i].what, a.degree, b.degree, a.n, b.n, a.w != NULL,
                  b.w != NULL, a.closed, b.closed);
      fail();
    }
    st_same_at_params(&a, &b, 1e-12 * st_scale(&b), t[i].what);
    km_curve_free(&a);
    km_curve_free(&b);
  }
}

static void real_icon_and_glyph_paths_equal_their_absolute_forms(void **state) {
  (void)state;
  check_pairs(REAL, sizeof REAL / sizeof REAL[0]);
}

static void every_grammar_corner_equals_its_explicit_form(void **state) {
  (void)state;
  check_pairs(GRAMMAR, sizeof GRAMMAR / sizeof GRAMMAR[0]);
}

/* Shape facts of the real paths that the comparison above cannot see. */
static void real_paths_have_the_expected_pieces(void **state) {
  (void)state;
  km_curve c;
  /* home: 10 straight sides and the closing one */
  st_parse(REAL[0].d, &c);
  assert_int_equal(c.degree, 1);
  assert_int_equal(c.n, 12);
  assert_true(c.closed);
  km_curve_free(&c);
  /* heart: lines raised to cubics, 8 pieces, closed without a Z line
   * (its last L returns to the start) */
  st_parse(REAL[1].d, &c);
  assert_int_equal(c.degree, 3);
  assert_int_equal(c.n, 3 * 8 + 1);
  assert_true(c.closed);
  km_curve_free(&c);
  /* glyph o: 8 quadratics with T joins, tangent-continuous everywhere */
  st_parse(REAL[3].d, &c);
  assert_int_equal(c.degree, 2);
  assert_int_equal(c.n, 17);
  for (int k = 1; k < 8; k++) {
    double l[2][2], r[2][2];
    km_curve_eval_side(&c, k, -1, 1, l);
    km_curve_eval_side(&c, k, 1, 1, r);
    double cr = l[1][0] * r[1][1] - l[1][1] * r[1][0];
    assert_close(cr / (hypot(l[1][0], l[1][1]) * hypot(r[1][0], r[1][1])), 0.0,
                 1e-12);
  }
  km_curve_free(&c);
  /* pie: 270-degree arc in 3 pieces and two lines, rational */
  st_parse(REAL[5].d, &c);
  assert_non_null(c.w);
  assert_int_equal(c.degree, 2);
  assert_int_equal(c.n, 2 * 5 + 1);
  for (int i = 0; i <= 300; i++) {
    double p[2];
    st_pos(&c, 3.0 * i / 300, p);
    assert_rel(hypot(p[0] - 12, p[1] - 12), 10.0, 1e-12);
  }
  km_curve_free(&c);
}

/* The 12 paths of shapes.json against the exact B-splines given with them:
 * polynomial paths at equal parameters, arcs (which the fixture gives as
 * cubics within about 3e-4 of the radius) as traces; both split arcs into
 * the same quarter-or-less pieces, so the piece counts and junctions agree. */
static void shapes_fixture_paths_match_their_bsplines(void **state) {
  (void)state;
  st_shapes s;
  st_load_shapes(&s);
  for (size_t i = 0; i < s.n; i++)
    for (int w = 0; w < 2; w++) {
      const char *d = s.d[i][w];
      tf_bspline fx;
      assert_int_equal(tf_load_shape(s.name[i], w ? 'b' : 'a', &fx), 0);
      km_curve want, got;
      km_curve_init(&want);
      assert_status(km_curve_create(&want, fx.degree, fx.n, fx.knots, fx.cp,
                                    fx.w, fx.closed, NULL),
                    KM_OK);
      st_parse(d, &got);
      assert_int_equal(got.closed, want.closed);
      size_t pieces_got = (got.n - 1) / (size_t)got.degree;
      size_t pieces_want = (want.n - 1) / (size_t)want.degree;
      assert_int_equal(pieces_got, pieces_want);
      for (size_t k = 0; k <= pieces_got; k++) {
        double p[2], q[2];
        st_pos(&got, (double)k, p);
        st_pos(&want, (double)k, q);
        assert_close(hypot(p[0] - q[0], p[1] - q[1]), 0.0, 1e-9);
      }
      bool arcs = strchr(d, 'A') || strchr(d, 'a');
      if (!arcs) {
        assert_null(got.w);
        st_same_at_params(&got, &want, 1e-9, s.name[i]);
      } else {
        /* radii in the fixture are at most 90 */
        double dist = st_trace_distance(&got, &want);
        assert_le(dist, 3.5e-4 * 90);
      }
      km_curve_free(&want);
      km_curve_free(&got);
      tf_bspline_free(&fx);
    }
  st_free_shapes(&s);
}

/* A full circle written as two A commands: curvature 1/r from the rational
 * derivatives, every point at distance r from the centre. */
static void
circle_from_two_arc_commands_has_curvature_one_over_r(void **state) {
  (void)state;
  const char *ds[] = {"M20,100 A80,80 0 1,1 180,100 A80,80 0 1,1 20,100 Z",
                      "M20 100a80 80 0 1 0 160 0a80 80 0 1 0-160 0z"};
  for (int k = 0; k < 2; k++) {
    km_curve c;
    st_parse(ds[k], &c);
    assert_true(c.closed);
    double t0, t1;
    km_curve_domain(&c, &t0, &t1);
    for (int i = 0; i <= 2000; i++) {
      double t = t0 + (t1 - t0) * i / 2000.0, p[2];
      st_pos(&c, t, p);
      assert_rel(hypot(p[0] - 100, p[1] - 100), 80.0, 1e-12);
      double kap = fabs(st_curvature(&c, t));
      assert_close(kap, 1.0 / 80.0, 1e-9);
    }
    assert_rel(km_curve_length(&c), 2 * M_PI * 80, 1e-12);
    km_curve_free(&c);
  }
}

/* F.6.6 through the parser: radius 1 for a chord of 10 becomes 5. */
static void arc_with_too_small_radii_is_scaled_up(void **state) {
  (void)state;
  km_curve c;
  st_parse("M0 0A1 1 0 0 0 10 0", &c);
  double t0, t1, p[2];
  km_curve_domain(&c, &t0, &t1);
  for (int i = 0; i <= 100; i++) {
    st_pos(&c, t0 + (t1 - t0) * i / 100.0, p);
    assert_close(hypot(p[0] - 5, p[1]), 5.0, 1e-13);
  }
  /* sweep 0: the negative-angle way round, through (5, 5) */
  st_pos(&c, 0.5 * (t0 + t1), p);
  assert_close(p[1], 5.0, 1e-13);
  km_curve_free(&c);
}

typedef struct bad {
  const char *d;
  size_t len;         /* 0: strlen(d) */
  const char *marker; /* expected offset = where this occurs; NULL = end */
  km_status status;
  const char *says; /* part of the message */
} bad;

static const bad BAD[] = {
    {"", 0, NULL, KM_EINVAL, "moveto"},
    {"   ", 0, NULL, KM_EINVAL, "moveto"},
    {"L1 2", 0, "L", KM_EINVAL, "moveto"},
    {"M", 0, NULL, KM_EINVAL, "expected x"},
    {"M 1", 0, NULL, KM_EINVAL, "expected y"},
    {"M1 2L3 x", 0, "x", KM_EINVAL, "expected y"},
    {"M1 2 K3 4", 0, "K", KM_EINVAL, "path command"},
    {"M1 2L3 4,", 0, NULL, KM_EINVAL, "after ','"},
    {"M1 2,L3 4", 0, "L", KM_EINVAL, "after ','"},
    {"M,1 2", 0, ",", KM_EINVAL, "expected x"},
    {"M0 0L1 1 M2 2L3 3", 0, "M2", KM_EINVAL, "second subpath"},
    {"M0 0L1 1 M2 2 3 3", 0, "M2", KM_EINVAL, "second subpath"},
    {"M0 0L1 1Z L2 2", 0, "L2", KM_EINVAL, "second subpath"},
    {"M0 0L1 1Z 2 2", 0, "2 2", KM_EINVAL, "path command"},
    {"M0 0A1 1 0 2 0 1 1", 0, "2 0 1", KM_EINVAL, "large-arc-flag"},
    {"M0 0A1 1 0 0,x 1 1", 0, "x", KM_EINVAL, "sweep-flag"},
    {"M0 0A1 1 0 0 0", 0, NULL, KM_EINVAL, "expected x"},
    {"M0 0L1e400 0", 0, "1e400", KM_ERANGE, "too large"},
    {"M0 0L1 2e", 0, "e", KM_EINVAL, "path command"},
    {"M0 0L1 1e+", 0, "e+", KM_EINVAL, "path command"},
    {"M0 0 L 1 . 5", 0, ". 5", KM_EINVAL, "expected y"},
    {"M0 0 L- 1 2", 0, "- 1", KM_EINVAL, "expected x"},
    {"M0 0 L1 1\0L2 2", 14, "", KM_EINVAL, "0x00"},
    {"M0 0 L1 1 \xc3\xa9", 0, "\xc3", KM_EINVAL, "0xc3"},
    {"M0 0 C1 1 2 2", 0, NULL, KM_EINVAL, "expected x"},
    {"M0 0 Q1 1", 0, NULL, KM_EINVAL, "expected x"},
    {"M0 0 S1 1 2", 0, NULL, KM_EINVAL, "expected y"},
    {"M0 0L1e15 0 2e15 0", 0, "2e15", KM_ERANGE, "exceeds"},
    {"M0 0 Z", 0, "Z", KM_EDEGENERATE, "draws nothing"},
    {"M0 0 L0 0", 0, "M", KM_EDEGENERATE, "zero length"},
    {"M0 0 0x10 0", 0, "x10", KM_EINVAL, "expected y"},
    {"M0 0 Linf 0", 0, "inf", KM_EINVAL, "expected x"},
};

/* Offsets are where the problem is: computed from the marker's position in
 * the string, not copied from the parser. */
static void bad_path_data_is_refused_with_the_offset(void **state) {
  (void)state;
  for (size_t i = 0; i < sizeof BAD / sizeof BAD[0]; i++) {
    const bad *b = &BAD[i];
    size_t len = b->len ? b->len : strlen(b->d);
    size_t want;
    if (!b->marker)
      want = len;
    else if (!*b->marker)
      want = strlen(b->d); /* at the embedded NUL */
    else {
      /* the last occurrence, so "M2" is not found in "M0" */
      const char *at = NULL, *p = b->d;
      while ((p = strstr(p, b->marker)) != NULL) at = p++;
      assert_non_null(at);
      want = (size_t)(at - b->d);
    }
    km_curve c;
    km_curve_init(&c);
    size_t off = 12345;
    char msg[256] = "";
    km_status st =
        api_svg_parse_path(b->d, len, 1e-9, &c, &off, msg, sizeof msg);
    if (st != b->status || off != want || !strstr(msg, b->says)) {
      print_error("\"%s\": status %d offset %zu \"%s\"; expected status %d "
                  "offset %zu and a message saying \"%s\"\n",
                  b->d, st, off, msg, b->status, want, b->says);
      fail();
    }
    /* a failure leaves the output untouched */
    assert_null(c.cp);
  }
}

/* The message always fits and is terminated, even in a tiny buffer; a NULL
 * message buffer is allowed. */
static void error_messages_are_bounded(void **state) {
  (void)state;
  char msg[8];
  memset(msg, 'x', sizeof msg);
  km_curve c;
  km_curve_init(&c);
  size_t off;
  assert_status(api_svg_parse_path("M1 2 K", 6, 1, &c, &off, msg, sizeof msg),
                KM_EINVAL);
  assert_int_equal(strlen(msg), sizeof msg - 1);
  assert_status(api_svg_parse_path("M1 2 K", 6, 1, &c, &off, NULL, 0),
                KM_EINVAL);
  assert_int_equal(off, 5);
  /* len bounds the input: the rest of the string is not read */
  assert_status(api_svg_parse_path("M1 2 L3 4 K", 9, 1, &c, &off, NULL, 0),
                KM_OK);
  km_curve_free(&c);
}

/* Relative sums that come back to the start within rounding close the
 * path without a sliver of a closing line. */
static void closing_after_relative_round_trip_adds_no_sliver(void **state) {
  (void)state;
  km_curve c;
  st_parse("M0.1 0.2l0.7 0.1l-0.3 0.6l-0.4-0.7z", &c);
  /* 0.1 + 0.7 - 0.3 - 0.4 is not 0.1 in binary: a gap of ~1e-16 */
  assert_int_equal(c.n, 4);
  assert_true(c.closed);
  assert_true(c.cp[0] == c.cp[6] && c.cp[1] == c.cp[7]);
  km_curve_free(&c);
}

static const struct CMUnitTest tests[] = {
    cmocka_unit_test(real_icon_and_glyph_paths_equal_their_absolute_forms),
    cmocka_unit_test(every_grammar_corner_equals_its_explicit_form),
    cmocka_unit_test(real_paths_have_the_expected_pieces),
    cmocka_unit_test(shapes_fixture_paths_match_their_bsplines),
    cmocka_unit_test(circle_from_two_arc_commands_has_curvature_one_over_r),
    cmocka_unit_test(arc_with_too_small_radii_is_scaled_up),
    cmocka_unit_test(bad_path_data_is_refused_with_the_offset),
    cmocka_unit_test(error_messages_are_bounded),
    cmocka_unit_test(closing_after_relative_round_trip_adds_no_sliver),
};

TM_SUITE("svg_parse", tests, NULL, NULL);
