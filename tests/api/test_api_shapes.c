/* test_api_shapes.c - compound shapes in the contract: an SVG path of
 * several subpaths and the JSON "shape" type read as one shape, the morph
 * of two shapes answered contour by contour, their signatures, and every
 * bad contour named by its pointer (or, inside SVG path data, its
 * subpath's offset).
 *
 * Oracles: circles (length 2 pi r, every point at distance r from the
 * centre, curvature 1/r), the contour counts of the fixture glyphs
 * (tests/fixtures/compound, counts stated in pairs.json), the character
 * offsets of the subpaths in the request text, and the contract's bound on
 * the answer's size.
 */
#include <math.h>
#include <stdlib.h>

#include "api_testutil.h"
#include "testmain.h"

#define MORPH API_ROUTE_MORPH
#define SIGNATURE API_ROUTE_SIGNATURE

/* Circles about the origin as SVG arcs: radius 2 counter-clockwise (in
 * y-up terms, positive area), radius 1 the other way round. */
#define OUTER_D "M 0 -2 A 2 2 0 1 1 0 2 A 2 2 0 1 1 0 -2 Z"
#define INNER_D "M 0 -1 A 1 1 0 1 0 0 1 A 1 1 0 1 0 0 -1 Z"
#define RING_D OUTER_D " " INNER_D
#define RING "{\"type\":\"svg\",\"d\":\"" RING_D "\"}"
#define SQ(x) SQ_##x
#define SQ_0 SQUARE_AT(0, 1)
#define SQ_3 SQUARE_AT(3, 4)
#define SQ_6 SQUARE_AT(6, 7)
#define RING_SHAPE                                                             \
  "{\"type\":\"shape\",\"fill_rule\":\"nonzero\",\"contours\":["               \
  "{\"type\":\"svg\",\"d\":\"" OUTER_D "\"},"                                  \
  "{\"type\":\"svg\",\"d\":\"" INNER_D "\"}]}"
/* The unit square with its lower left corner at (x0, 0); x1 = x0 + 1. */
#define SQUARE_AT(x0, x1)                                                      \
  "{\"type\":\"bspline\",\"degree\":1,\"knots\":[0,0,1,2,3,4,4],"              \
  "\"control_points\":[[" #x0 ",0],[" #x1 ",0],[" #x1 ",1],[" #x0 ",1],[" #x0  \
  ",0]],\"closed\":true}"

static const double PI = 3.14159265358979323846;

/* The largest | |p| - r | over 64 points of each knot span of c. */
static double radius_error(const cJSON *c, double r) {
  at_curve a;
  double worst = 0;
  at_curve_from_json(c, &a);
  for (size_t i = (size_t)a.degree; i < a.n; i++) {
    double t0 = a.knots[i], t1 = a.knots[i + 1];
    for (int k = 0; k <= 64 && t1 > t0; k++) {
      double p[2];
      at_curve_point(&a, t0 + (t1 - t0) * k / 64.0, p);
      worst = fmax(worst, fabs(hypot(p[0], p[1]) - r));
    }
  }
  at_curve_free(&a);
  return worst;
}

static const cJSON *member(const cJSON *o, const char *key) {
  const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
  if (v == NULL) print_error("no member \"%s\"\n", key);
  assert_non_null(v);
  return v;
}

static void ring_to_ring_keeps_both_contours(void **state) {
  (void)state;
  cJSON *j = at_expect_json(MORPH, "{\"from\":" RING ",\"to\":" RING
                                   ",\"frames\":3,\"tolerance\":1e-6}");
  const cJSON *frames = member(j, "frames"), *f;
  const cJSON *used = member(j, "contour_matches_used");
  assert_null(cJSON_GetObjectItemCaseSensitive(j, "matches_used"));
  /* the outer circle with the outer, the hole with the hole */
  assert_int_equal(cJSON_GetArraySize(used), 2);
  for (int k = 0; k < 2; k++) {
    const cJSON *pr = cJSON_GetArrayItem(used, k);
    assert_int_equal(cJSON_GetArraySize(pr), 2);
    assert_int_equal(cJSON_GetArrayItem(pr, 0)->valueint, k);
    assert_int_equal(cJSON_GetArrayItem(pr, 1)->valueint, k);
  }
  assert_int_equal(cJSON_GetArraySize(frames), 3);
  cJSON_ArrayForEach(f, frames) {
    const cJSON *cs = member(f, "contours"), *m = member(f, "metrics");
    assert_null(cJSON_GetObjectItemCaseSensitive(f, "curve"));
    assert_int_equal(cJSON_GetArraySize(cs), 2);
    double t = member(f, "t")->valuedouble;
    for (int k = 0; k < 2; k++) {
      const cJSON *c = cJSON_GetArrayItem(cs, k);
      double r = k == 0 ? 2.0 : 1.0;
      assert_true(cJSON_IsObject(c));
      assert_true(cJSON_IsTrue(member(c, "closed")));
      assert_true(fabs(member(c, "length")->valuedouble - 2 * PI * r) < 1e-5);
      /* the ends are the inputs: circles of radius 2 and 1 */
      if (t == 0 || t == 1) assert_true(radius_error(c, r) < 1e-5);
    }
    assert_int_equal(cJSON_GetArraySize(member(m, "contours")), 2);
    assert_int_equal(member(m, "mutual_intersections")->valueint, 0);
    assert_true(cJSON_IsTrue(member(m, "nesting_ok")));
  }
  cJSON_Delete(j);
}

/* ---- the compound fixtures ---- */

static char *read_file(const char *path) {
  FILE *fp = fopen(path, "rb");
  char *s;
  long n;
  assert_non_null(fp);
  fseek(fp, 0, SEEK_END);
  n = ftell(fp);
  fseek(fp, 0, SEEK_SET);
  s = malloc((size_t)n + 1);
  assert_non_null(s);
  assert_int_equal(fread(s, 1, (size_t)n, fp), (size_t)n);
  s[n] = '\0';
  fclose(fp);
  return s;
}

/* The path data of glyph id in glyphs.json, or of an icon (mdi/...) in
 * icons.json (malloc'd). */
static char *glyph_d(const char *id) {
  bool icon = strncmp(id, "mdi/", 4) == 0;
  char *text = read_file(icon ? "tests/fixtures/compound/icons.json"
                              : "tests/fixtures/compound/glyphs.json"),
       *d = NULL;
  cJSON *root = cJSON_Parse(text), *g;
  assert_non_null(root);
  cJSON_ArrayForEach(
      g, cJSON_GetObjectItemCaseSensitive(root, icon ? "icons" : "glyphs")) {
    if (strcmp(cJSON_GetObjectItemCaseSensitive(g, "id")->valuestring, id) ==
        0) {
      const char *s = cJSON_GetObjectItemCaseSensitive(g, "d")->valuestring;
      d = malloc(strlen(s) + 1);
      assert_non_null(d);
      strcpy(d, s);
    }
  }
  cJSON_Delete(root);
  free(text);
  if (d == NULL) print_error("no glyph %s\n", id);
  assert_non_null(d);
  return d;
}

/* A morph request between two glyphs with extra members. */
static char *glyph_request(const char *from, const char *to,
                           const char *extra) {
  char *a = glyph_d(from), *b = glyph_d(to);
  at_buf buf = {0};
  at_printf(&buf,
            "{\"from\":{\"type\":\"svg\",\"d\":\"%s\"},"
            "\"to\":{\"type\":\"svg\",\"d\":\"%s\"}%s}",
            a, b, extra);
  free(a);
  free(b);
  return buf.s;
}

static void o_to_c_loses_the_hole_at_the_end(void **state) {
  (void)state;
  char *body = glyph_request("dejavu-sans/O", "dejavu-sans/C", ",\"frames\":5");
  cJSON *j = at_expect_json(MORPH, body);
  const cJSON *used = member(j, "contour_matches_used");
  const cJSON *frames = member(j, "frames");
  int slots = cJSON_GetArraySize(used), hole = -1, paired = -1;
  /* O has two contours, C one: one pair and one contour without */
  assert_int_equal(slots, 2);
  for (int k = 0; k < slots; k++) {
    const cJSON *pr = cJSON_GetArrayItem(used, k);
    if (cJSON_IsNull(cJSON_GetArrayItem(pr, 1)))
      hole = k;
    else
      paired = k;
    assert_true(cJSON_IsNumber(cJSON_GetArrayItem(pr, 0)));
  }
  assert_true(hole >= 0 && paired >= 0);
  const cJSON *first = cJSON_GetArrayItem(frames, 0);
  const cJSON *last = cJSON_GetArrayItem(frames, 4);
  assert_true(member(last, "t")->valuedouble == 1.0);
  for (int k = 0; k < slots; k++)
    assert_true(
        cJSON_IsObject(cJSON_GetArrayItem(member(first, "contours"), k)));
  assert_true(cJSON_IsNull(cJSON_GetArrayItem(member(last, "contours"), hole)));
  assert_true(
      cJSON_IsObject(cJSON_GetArrayItem(member(last, "contours"), paired)));
  assert_true(cJSON_IsNull(
      cJSON_GetArrayItem(member(member(last, "metrics"), "contours"), hole)));
  cJSON_Delete(j);
  free(body);
}

/* The linear baseline pairs contours as the curvature morph does and
 * blends each pair's control points: two unit squares at x = 0 and
 * x = 6 to two at x = 0 and x = 3 give, halfway, one square where it
 * stood and one at x = 4.5, corner for corner. */
static void linear_shapes_blend_each_pair(void **state) {
  (void)state;
  cJSON *j = at_expect_json(
      MORPH,
      "{\"method\":\"linear\",\"frames\":3,"
      "\"from\":{\"type\":\"shape\",\"contours\":[" SQ(0) "," SQ(
          6) "]},"
             "\"to\":{\"type\":\"shape\",\"contours\":[" SQ(0) "," SQ(3) "]}}");
  const cJSON *used = member(j, "contour_matches_used");
  assert_int_equal(cJSON_GetArraySize(used), 2);
  const cJSON *mid =
      member(cJSON_GetArrayItem(member(j, "frames"), 1), "contours");
  int seen[2] = {0, 0};
  for (int k = 0; k < 2; k++) {
    const cJSON *pr = cJSON_GetArrayItem(used, k);
    int from = cJSON_GetArrayItem(pr, 0)->valueint;
    assert_int_equal(cJSON_GetArrayItem(pr, 1)->valueint, from);
    double x0 = from == 0 ? 0.0 : 4.5; /* halfway from 6 to 3 */
    const cJSON *cp = member(cJSON_GetArrayItem(mid, k), "control_points");
    const double want[5][2] = {
        {x0, 0}, {x0 + 1, 0}, {x0 + 1, 1}, {x0, 1}, {x0, 0}};
    assert_int_equal(cJSON_GetArraySize(cp), 5);
    for (int i = 0; i < 5; i++)
      for (int c = 0; c < 2; c++)
        assert_true(
            fabs(cJSON_GetArrayItem(cJSON_GetArrayItem(cp, i), c)->valuedouble -
                 want[i][c]) < 1e-12);
    seen[from]++;
  }
  assert_true(seen[0] == 1 && seen[1] == 1);
  cJSON_Delete(j);
}

static void json_shape_is_the_svg_shape(void **state) {
  (void)state;
  api_response a, b;
  at_call(MORPH, "{\"from\":" RING ",\"to\":" RING ",\"frames\":3}", &a, NULL);
  at_call(MORPH, "{\"from\":" RING_SHAPE ",\"to\":" RING_SHAPE ",\"frames\":3}",
          &b, NULL);
  assert_int_equal(a.status, 200);
  assert_int_equal(b.status, 200);
  assert_int_equal(a.length, b.length);
  assert_memory_equal(a.body, b.body, a.length);
  api_response_free(&a);
  api_response_free(&b);
}

static void a_circle_against_a_ring_is_a_shape_of_one(void **state) {
  (void)state;
  cJSON *j =
      at_expect_json(MORPH, "{\"from\":{\"type\":\"svg\",\"d\":\"" OUTER_D
                            "\"},\"to\":" RING ",\"frames\":2}");
  const cJSON *used = member(j, "contour_matches_used");
  assert_int_equal(cJSON_GetArraySize(used), 2);
  const cJSON *f0 = cJSON_GetArrayItem(member(j, "frames"), 0);
  const cJSON *cs = member(f0, "contours");
  /* at t = 0 only the circle is there; the hole grows from a point */
  int present = 0;
  for (int k = 0; k < 2; k++)
    present += cJSON_IsObject(cJSON_GetArrayItem(cs, k));
  assert_int_equal(present, 1);
  cJSON_Delete(j);
}

static void caller_pairs_are_used_and_checked(void **state) {
  (void)state;
  cJSON *j = at_expect_json(MORPH, "{\"from\":" RING ",\"to\":" RING
                                   ",\"frames\":2,\"contour_matches\":"
                                   "[[0,0],[1,1]]}");
  assert_int_equal(cJSON_GetArraySize(member(j, "contour_matches_used")), 2);
  cJSON_Delete(j);
  j = at_expect_json(MORPH, "{\"from\":" RING ",\"to\":" RING
                            ",\"frames\":2,\"contour_matches\":"
                            "[[0,0],[1,null],[null,1]]}");
  const cJSON *u = member(j, "contour_matches_used");
  assert_int_equal(cJSON_GetArraySize(u), 3);
  assert_true(cJSON_IsNull(cJSON_GetArrayItem(cJSON_GetArrayItem(u, 1), 1)));
  cJSON_Delete(j);
  /* a hole may not be paired with an outer contour */
  at_problem(MORPH,
             "{\"from\":" RING ",\"to\":" RING
             ",\"contour_matches\":[[0,1],[1,0]]}",
             422, "/contour_matches/0");
  at_problem(MORPH,
             "{\"from\":" RING ",\"to\":" RING
             ",\"contour_matches\":[[0,0],[1,null]]}",
             422, "/contour_matches");
  at_problem(MORPH,
             "{\"from\":" RING ",\"to\":" RING
             ",\"contour_matches\":[[0,0],[1,1.5]]}",
             422, "/contour_matches/1/1");
  at_problem(MORPH,
             "{\"from\":" RING ",\"to\":" RING
             ",\"contour_matches\":[[null,null]]}",
             422, "/contour_matches/0");
  at_problem(MORPH,
             "{\"from\":" RING ",\"to\":" RING ",\"contour_matches\":[]}", 422,
             "/contour_matches");
}

/* The bars of pause paired by position with those of equal pass through
 * each other halfway (4 of 41 frames cross, by the engine's count and by
 * the fixture test's own geometry); under "avoid" the automatic pairing
 * is swapped and no frame crosses. A pairing the caller gives is kept as
 * given, crossings and all. */
static void avoid_pairs_the_bars_of_pause_otherwise(void **state) {
  (void)state;
  char *body = glyph_request("mdi/pause", "mdi/equal", ",\"frames\":41");
  cJSON *j = at_expect_json(MORPH, body);
  free(body);
  const cJSON *u = member(j, "contour_matches_used");
  assert_int_equal(cJSON_GetArraySize(u), 2);
  for (int k = 0; k < 2; k++) {
    const cJSON *pr = cJSON_GetArrayItem(u, k);
    assert_int_equal(cJSON_GetArrayItem(pr, 0)->valueint, k);
    assert_int_equal(cJSON_GetArrayItem(pr, 1)->valueint, k);
  }
  assert_int_equal(
      cJSON_GetArraySize(member(member(j, "intersections"), "crossing_frames")),
      0);
  cJSON_Delete(j);
  body = glyph_request("mdi/pause", "mdi/equal",
                       ",\"frames\":41,\"contour_matches\":[[0,1],[1,0]]");
  j = at_expect_json(MORPH, body);
  free(body);
  u = member(j, "contour_matches_used");
  assert_int_equal(cJSON_GetArrayItem(cJSON_GetArrayItem(u, 0), 1)->valueint,
                   1);
  assert_true(cJSON_GetArraySize(
                  member(member(j, "intersections"), "crossing_frames")) > 0);
  cJSON_Delete(j);
}

/* ---- errors name the contour ---- */

static void bad_contours_are_named(void **state) {
  (void)state;
  /* an open contour, a zero-length one, a signature, a shape in a shape */
  at_problem(MORPH,
             "{\"to\":" RING ",\"from\":{\"type\":\"shape\",\"contours\":[" SQ(
                 0) "," SQ(3) ",{\"type\":\"svg\",\"d\":\"M 7 0 L 8 "
                              "0 L 8 1\"}]}}",
             422, "/from/contours/2");
  at_problem(MORPH,
             "{\"to\":" RING ",\"from\":{\"type\":\"shape\",\"contours\":[" SQ(
                 0) ",{\"type\":\"svg\",\"d\":\"M 5 5 L 5 5 Z\"}]}}",
             422, "/from/contours/1/d");
  at_problem(MORPH,
             "{\"to\":" RING
             ",\"from\":{\"type\":\"shape\",\"contours\":[" SQ(0) "," RING
                                                                  "]}}",
             422, "/from/contours/1");
  at_problem(MORPH,
             "{\"to\":" RING ",\"from\":{\"type\":\"shape\",\"contours\":[]}}",
             422, "/from/contours");
  at_problem(MORPH,
             "{\"to\":" RING ",\"from\":{\"type\":\"shape\",\"contours\":[" SQ(
                 0) "],\"fill_rule\":\"winding\"}}",
             422, "/from/fill_rule");
  /* the single-curve side of a compound morph must be closed */
  at_problem(MORPH,
             "{\"to\":" RING ",\"from\":{\"type\":\"svg\",\"d\":\"M0 0 L1 "
             "0\"}}",
             422, "/from");
}

/* The message of a problem must name the subpath's offset in d. */
static void subpath_offsets_are_given(void **state) {
  (void)state;
  const char *d = OUTER_D " M 5 5 L 6 5 L 6 6";
  size_t off = (size_t)(strchr(d + 1, 'M') - d);
  char body[512], want[64];
  snprintf(body, sizeof body,
           "{\"from\":{\"type\":\"svg\",\"d\":\"%s\"},"
           "\"to\":" RING "}",
           d);
  cJSON *j = at_expect_problem(MORPH, body, 422, "/from/d");
  snprintf(want, sizeof want, "offset %zu", off);
  const char *msg = member(j, "detail")->valuestring;
  if (strstr(msg, want) == NULL)
    print_error("\"%s\" not in \"%s\"\n", want, msg);
  assert_non_null(strstr(msg, want));
  assert_non_null(strstr(msg, "subpath 1"));
  cJSON_Delete(j);
  /* a subpath of zero length */
  d = OUTER_D " M 5 5 L 5 5 Z";
  off = (size_t)(strchr(d + 1, 'M') - d);
  snprintf(body, sizeof body,
           "{\"from\":{\"type\":\"svg\",\"d\":\"%s\"},"
           "\"to\":" RING "}",
           d);
  j = at_expect_problem(MORPH, body, 422, "/from/d");
  msg = member(j, "detail")->valuestring;
  assert_non_null(strstr(msg, want));
  cJSON_Delete(j);
}

static void contours_past_the_limit_are_refused(void **state) {
  (void)state;
  api_config cfg;
  api_config_default(&cfg);
  assert_int_equal(cfg.max_contours, 64);
  cfg.max_contours = 2;
  cJSON *j = at_expect_problem_cfg(
      &cfg, MORPH,
      "{\"to\":" RING ",\"from\":{\"type\":\"shape\",\"contours\":[" SQ(
          0) "," SQ(3) "," SQ(6) "]}}",
      422, "/from/contours/2");
  assert_string_equal(member(j, "type")->valuestring,
                      "/problems/limit-exceeded");
  cJSON_Delete(j);
  /* the third subpath, at its offset */
  const char *d = "M0 0 L1 0 L1 1 Z M3 0 L4 0 L4 1 Z M6 0 L7 0 L7 1 Z";
  char body[256], want[32];
  snprintf(body, sizeof body,
           "{\"to\":" RING ",\"from\":{\"type\":\"svg\",\"d\":\"%s\"}}", d);
  j = at_expect_problem_cfg(&cfg, MORPH, body, 422, "/from/d");
  snprintf(want, sizeof want, "offset %zu", (size_t)(strstr(d, "M6") - d));
  assert_non_null(strstr(member(j, "detail")->valuestring, want));
  cJSON_Delete(j);
}

static void what_shapes_do_not_take_is_named(void **state) {
  (void)state;
  at_problem(MORPH,
             "{\"from\":" RING ",\"to\":" RING ",\"matches\":[[0.5,0.5]]}", 422,
             "/matches");
  at_problem(MORPH,
             "{\"from\":" RING ",\"to\":{\"type\":\"signature\","
             "\"signature\":{\"length\":6.283185307179586,\"start\":{"
             "\"point\":[1,0],\"angle\":1.5707963267948966},\"kappa\":{"
             "\"degree\":0,\"knots\":[0,6.283185307179586],"
             "\"coefficients\":[1]}}}}",
             422, "/to");
  /* contour pairs without a shape */
  at_problem(
      MORPH,
      "{\"from\":" SQ(0) ",\"to\":" SQ(3) ",\"contour_matches\":[[0,0]]}", 422,
      "/contour_matches");
}

/* A figure eight of turning number 0 (its right lobe larger, so it
 * encloses area), centred at (10, 0) clear of the squares. */
#define EIGHT_D                                                                \
  "M 10 0 C 11 2, 13 2, 13 0 C 13 -2, 11 -2, 10 0 C 9 1, 8 1, 8 0 "            \
  "C 8 -1, 9 -1, 10 0 Z"
#define EIGHT_WIDE_D                                                           \
  "M 10 0 C 11 3, 14 3, 14 0 C 14 -3, 11 -3, 10 0 C 9 1, 8 1, 8 0 "            \
  "C 8 -1, 9 -1, 10 0 Z"
#define SQUARE4_D "M 0 0 L 4 0 L 4 4 L 0 4 Z"
#define SQUARE5_D "M 0 0 L 5 0 L 5 5 L 0 5 Z"

static void empty_subpaths_are_named(void **state) {
  (void)state;
  /* a subpath that draws nothing, in SVG path data and as a contour */
  const char *d = SQUARE4_D " M 5 5 Z";
  char body[512], want[32];
  snprintf(body, sizeof body,
           "{\"from\":{\"type\":\"svg\",\"d\":\"%s\"},\"to\":" RING "}", d);
  cJSON *j = at_expect_problem(MORPH, body, 422, "/from/d");
  snprintf(want, sizeof want, "offset %zu", (size_t)(strrchr(d, 'Z') - d));
  assert_non_null(strstr(member(j, "detail")->valuestring, want));
  cJSON_Delete(j);
  at_problem(MORPH,
             "{\"to\":" RING ",\"from\":{\"type\":\"shape\",\"contours\":[" SQ(
                 0) ",{\"type\":\"svg\",\"d\":\"M 5 5 Z\"}]}}",
             422, "/from/contours/1/d");
  at_problem(MORPH,
             "{\"from\":" RING ",\"to\":{\"type\":\"shape\",\"contours\":[" SQ(
                 0) ",{\"type\":\"points\",\"points\":[[5,5],[5,5],[5,5]],"
                    "\"closed\":true}]}}",
             422, "/to/contours/1/points");
}

/* Turning number 0 against contours that all turn once: no pairing
 * avoids the mismatch, and an unpaired contour would morph to a circle
 * (turning once) as well. */
static void a_contour_no_pairing_can_morph_is_named(void **state) {
  (void)state;
  cJSON *j = at_expect_problem(
      MORPH,
      "{\"from\":{\"type\":\"svg\",\"d\":\"" SQUARE4_D " " EIGHT_D "\"},"
      "\"to\":{\"type\":\"svg\",\"d\":\"" SQUARE5_D " M 20 0 L 21 0 L 21 1 "
      "Z\"}}",
      422, "/from/d");
  assert_string_equal(member(j, "type")->valuestring,
                      "/problems/not-morphable");
  const char *msg = member(j, "detail")->valuestring;
  assert_non_null(strstr(msg, "subpath 1"));
  assert_non_null(strstr(msg, "offset 26"));
  assert_non_null(strstr(msg, "turn"));
  cJSON_Delete(j);
  /* the same with the other side having fewer contours */
  at_problem(MORPH,
             "{\"from\":{\"type\":\"shape\",\"contours\":[{\"type\":\"svg\","
             "\"d\":\"" SQUARE4_D "\"},{\"type\":\"svg\",\"d\":\"" EIGHT_D
             "\"}]},\"to\":{\"type\":\"svg\",\"d\":\"" SQUARE5_D "\"}}",
             422, "/from/contours/1");
}

/* metrics member `name` of contour k of frame i */
static double contour_metric(const cJSON *frames, int i, int k,
                             const char *name) {
  const cJSON *m = member(cJSON_GetArrayItem(frames, i), "metrics");
  return member(cJSON_GetArrayItem(member(m, "contours"), k), name)
      ->valuedouble;
}

static double frame_metric(const cJSON *frames, int i, const char *name) {
  const cJSON *m = member(cJSON_GetArrayItem(frames, i), "metrics");
  return member(m, name)->valuedouble;
}

/* A contour crossing itself (the figure eight: one crossing, at its
 * centre) and two contours crossing each other (squares overlapping at a
 * corner: their edges cross twice) are morphed, their crossings counted
 * at both ends. */
static void crossing_contours_morph_and_show_their_crossings(void **state) {
  (void)state;
  cJSON *j = at_expect_json(
      MORPH, "{\"from\":{\"type\":\"svg\",\"d\":\"" SQUARE4_D " " EIGHT_D
             "\"},\"to\":{\"type\":\"svg\",\"d\":\"" SQUARE5_D " " EIGHT_WIDE_D
             "\"},\"frames\":3,\"metrics\":true}");
  const cJSON *frames = member(j, "frames");
  for (int i = 0; i < 3; i += 2) {
    assert_int_equal(contour_metric(frames, i, 1, "self_intersections"), 1);
    assert_int_equal(contour_metric(frames, i, 0, "self_intersections"), 0);
    assert_int_equal(frame_metric(frames, i, "mutual_intersections"), 0);
  }
  cJSON_Delete(j);
  j = at_expect_json(MORPH, "{\"from\":{\"type\":\"svg\",\"d\":\"" SQUARE4_D
                            " M 2.3 1.7 L 6.3 1.7 L 6.3 5.7 L 2.3 5.7 Z\"},"
                            "\"to\":{\"type\":\"svg\",\"d\":\"" SQUARE5_D
                            " M 3.1 2.9 L 7.1 2.9 L 7.1 6.9 L 3.1 6.9 Z\"},"
                            "\"frames\":3,\"metrics\":true}");
  frames = member(j, "frames");
  for (int i = 0; i < 3; i += 2)
    assert_int_equal(frame_metric(frames, i, "mutual_intersections"), 2);
  cJSON_Delete(j);
}

/* ---- SVG documents ---- */

/* The paths of an SVG document: their count, and each one's subpaths
 * (moveto letters of its d) and fill-rule checked. */
static size_t check_paths(const char *doc, const char *rule,
                          const size_t *subpaths, size_t n) {
  size_t count = 0;
  char want[40];
  snprintf(want, sizeof want, "fill-rule=\"%s\"", rule);
  for (const char *p = strstr(doc, "<path "); p != NULL;
       p = strstr(p + 1, "<path ")) {
    const char *end = strstr(p, "/>"), *d = strstr(p, " d=\"");
    assert_non_null(end);
    assert_non_null(d);
    assert_true(d < end);
    const char *r = strstr(p, want);
    assert_true(r != NULL && r < end);
    size_t m = 0, z = 0;
    for (const char *q = d + 4; *q != '"'; q++) {
      m += *q == 'M';
      z += *q == 'Z';
    }
    assert_true(count < n);
    assert_int_equal(m, subpaths[count]);
    assert_int_equal(z, subpaths[count]);
    count++;
  }
  return count;
}

static void svg_filmstrip_fills_every_frame(void **state) {
  (void)state;
  api_response res;
  const size_t two[3] = {2, 2, 2};
  at_call(MORPH,
          "{\"from\":" RING ",\"to\":" RING ",\"frames\":3,"
          "\"format\":\"svg\"}",
          &res, NULL);
  assert_int_equal(res.status, 200);
  assert_string_equal(res.content_type, "image/svg+xml");
  assert_non_null(strstr(res.body, "</svg>"));
  /* one filled path a frame, one subpath a contour */
  assert_int_equal(check_paths(res.body, "nonzero", two, 3), 3);
  api_response_free(&res);
  at_call(MORPH,
          "{\"from\":{\"type\":\"shape\",\"fill_rule\":\"evenodd\","
          "\"contours\":[" SQ(0) "," SQ(
              3) "]},\"to\":{\"type\":"
                 "\"shape\",\"fill_rule\":\"evenodd\",\"contours\":[" SQ(
                     0) "," SQ(3) "]},\"frames\":2,\"format\":\"svg\"}",
          &res, NULL);
  assert_int_equal(res.status, 200);
  assert_int_equal(check_paths(res.body, "evenodd", two, 2), 2);
  api_response_free(&res);
}

/* The O of the fixtures loses its hole on the way to the C: the last
 * frame's path has one subpath; the bound holds for documents too. */
static void svg_of_o_to_c_within_its_bound(void **state) {
  (void)state;
  char *body = glyph_request("dejavu-sans/O", "dejavu-sans/C",
                             ",\"frames\":3,\"format\":\"svg\"");
  const size_t sub[3] = {2, 2, 1};
  api_config cfg;
  api_request req;
  api_response err, res;
  api_morph_plan *plan = NULL;
  api_config_default(&cfg);
  memset(&req, 0, sizeof req);
  req.route = MORPH;
  req.body = body;
  req.length = strlen(body);
  assert_int_equal(api_morph_prepare(&cfg, &req, 10, &plan, &err),
                   API_STEP_DONE);
  assert_int_equal(api_morph_result(plan, &res), 200);
  assert_int_equal(check_paths(res.body, "nonzero", sub, 3), 3);
  assert_true(api_morph_predicted_bytes(plan) >= res.length);
  api_morph_plan_free(plan);
  api_response_free(&res);
  free(body);
}

/* ---- the prepared plan, its stop and its size ---- */

static bool stop_now(void *ctx) {
  (void)ctx;
  return true;
}

static void prepared_shapes_give_the_same_answer(void **state) {
  (void)state;
  char *body = glyph_request("dejavu-sans/B", "dejavu-sans/R",
                             ",\"frames\":4,\"include\":[\"svg_d\","
                             "\"animate_d\"]");
  api_config cfg;
  api_request req;
  api_response direct, err, res;
  api_morph_plan *plan = NULL;
  api_config_default(&cfg);
  memset(&req, 0, sizeof req);
  req.route = MORPH;
  req.body = body;
  req.length = strlen(body);
  assert_int_equal(api_handle(&cfg, &req, &direct), 200);
  assert_int_equal(api_morph_prepare(&cfg, &req, 10, &plan, &err),
                   API_STEP_DONE);
  assert_int_equal(api_morph_frame_count(plan), 4);
  for (size_t i = 4; i-- > 0;)
    assert_int_equal(api_morph_render_frame_until(plan, i, NULL, NULL),
                     API_STEP_DONE);
  assert_int_equal(api_morph_result(plan, &res), 200);
  assert_int_equal(res.length, direct.length);
  assert_memory_equal(res.body, direct.body, res.length);
  /* the bound given before any frame is rendered holds */
  assert_true(api_morph_predicted_bytes(plan) >= res.length);
  api_morph_plan_free(plan);
  api_response_free(&res);
  api_response_free(&direct);
  /* a stop asked for before the work is answered as stopped */
  req.stop = stop_now;
  plan = NULL;
  assert_int_equal(api_morph_prepare(&cfg, &req, 10, &plan, &err), 503);
  assert_null(plan);
  assert_non_null(strstr(err.body, "/problems/stopped"));
  api_response_free(&err);
  free(body);
}

/* Every fixture pair's answer stays within the bound predicted for it,
 * and a limit below the bound is refused before any frame. */
static void answers_stay_within_their_bound(void **state) {
  (void)state;
  static const char *const pairs[][2] = {{"dejavu-sans/O", "dejavu-sans/C"},
                                         {"dejavu-sans/i", "dejavu-sans/l"},
                                         {"dejavu-sans/8", "dejavu-sans/3"},
                                         {"dejavu-sans/e", "dejavu-sans/c"}};
  for (size_t k = 0; k < sizeof pairs / sizeof pairs[0]; k++) {
    char *body = glyph_request(pairs[k][0], pairs[k][1],
                               ",\"frames\":7,\"include\":[\"svg_d\"]");
    api_config cfg;
    api_request req;
    api_response err, res;
    api_morph_plan *plan = NULL;
    api_config_default(&cfg);
    memset(&req, 0, sizeof req);
    req.route = MORPH;
    req.body = body;
    req.length = strlen(body);
    assert_int_equal(api_morph_prepare(&cfg, &req, 10, &plan, &err),
                     API_STEP_DONE);
    size_t bound = api_morph_predicted_bytes(plan);
    assert_int_equal(api_morph_result(plan, &res), 200);
    if (bound < res.length)
      print_error("%s -> %s: %zu bytes, bound %zu\n", pairs[k][0], pairs[k][1],
                  res.length, bound);
    assert_true(bound >= res.length);
    api_morph_plan_free(plan);
    api_response_free(&res);
    cfg.max_output_bytes = bound - 1;
    assert_int_equal(api_morph_prepare(&cfg, &req, 10, &plan, &err), 422);
    assert_non_null(strstr(err.body, "/problems/limit-exceeded"));
    api_response_free(&err);
    free(body);
  }
}

/* ---- signatures ---- */

static void a_ring_has_one_signature_per_contour(void **state) {
  (void)state;
  cJSON *j = at_expect_json(SIGNATURE, "{\"curve\":" RING ",\"samples\":5}");
  const cJSON *sigs = member(j, "signatures"), *roles = member(j, "roles");
  const cJSON *samples = member(j, "samples");
  assert_string_equal(member(j, "fill_rule")->valuestring, "nonzero");
  assert_int_equal(cJSON_GetArraySize(sigs), 2);
  assert_string_equal(cJSON_GetArrayItem(roles, 0)->valuestring, "outer");
  assert_string_equal(cJSON_GetArrayItem(roles, 1)->valuestring, "hole");
  for (int k = 0; k < 2; k++) {
    double r = k == 0 ? 2.0 : 1.0;
    /* the contours as given: the inner circle turns clockwise */
    double kappa = k == 0 ? 0.5 : -1.0;
    const cJSON *s = cJSON_GetArrayItem(sigs, k), *p;
    assert_true(fabs(member(s, "length")->valuedouble - 2 * PI * r) < 1e-9);
    cJSON_ArrayForEach(p, cJSON_GetArrayItem(samples, k))
        assert_true(fabs(cJSON_GetArrayItem(p, 1)->valuedouble - kappa) < 1e-6);
  }
  cJSON_Delete(j);
  at_problem(SIGNATURE,
             "{\"curve\":{\"type\":\"shape\",\"contours\":[" SQ(
                 0) ",{\"type\":\"points\",\"points\":[[0,0],[1,0],[1,1]]}]}}",
             422, "/curve/contours/1");
}

/* ---- one contour stays what it was ---- */

/* A single subpath answers with a "curve" a frame and "matches_used", no
 * member of compound morphs, and the same text as the same path followed
 * by a moveto that draws nothing. */
static void one_subpath_answers_as_one_curve(void **state) {
  (void)state;
  api_response a, b;
  cJSON *j = at_expect_json(
      MORPH, "{\"from\":{\"type\":\"svg\",\"d\":\"" OUTER_D "\"},"
             "\"to\":" SQ(0) ",\"frames\":2}");
  const cJSON *f = cJSON_GetArrayItem(member(j, "frames"), 0);
  assert_true(cJSON_IsObject(member(f, "curve")));
  assert_null(cJSON_GetObjectItemCaseSensitive(f, "contours"));
  assert_true(cJSON_IsArray(member(j, "matches_used")));
  assert_null(cJSON_GetObjectItemCaseSensitive(j, "contour_matches_used"));
  cJSON_Delete(j);
  at_call(MORPH,
          "{\"from\":{\"type\":\"svg\",\"d\":\"" OUTER_D
          "\"},\"to\":" SQ(0) ",\"frames\":2}",
          &a, NULL);
  at_call(MORPH,
          "{\"from\":{\"type\":\"svg\",\"d\":\"" OUTER_D " M 9 9\"},"
          "\"to\":" SQ(0) ",\"frames\":2}",
          &b, NULL);
  assert_int_equal(a.length, b.length);
  assert_memory_equal(a.body, b.body, a.length);
  api_response_free(&a);
  api_response_free(&b);
}

static const struct CMUnitTest tests[] = {
    cmocka_unit_test(ring_to_ring_keeps_both_contours),
    cmocka_unit_test(o_to_c_loses_the_hole_at_the_end),
    cmocka_unit_test(json_shape_is_the_svg_shape),
    cmocka_unit_test(linear_shapes_blend_each_pair),
    cmocka_unit_test(a_circle_against_a_ring_is_a_shape_of_one),
    cmocka_unit_test(caller_pairs_are_used_and_checked),
    cmocka_unit_test(avoid_pairs_the_bars_of_pause_otherwise),
    cmocka_unit_test(bad_contours_are_named),
    cmocka_unit_test(subpath_offsets_are_given),
    cmocka_unit_test(contours_past_the_limit_are_refused),
    cmocka_unit_test(empty_subpaths_are_named),
    cmocka_unit_test(a_contour_no_pairing_can_morph_is_named),
    cmocka_unit_test(crossing_contours_morph_and_show_their_crossings),
    cmocka_unit_test(what_shapes_do_not_take_is_named),
    cmocka_unit_test(svg_filmstrip_fills_every_frame),
    cmocka_unit_test(svg_of_o_to_c_within_its_bound),
    cmocka_unit_test(prepared_shapes_give_the_same_answer),
    cmocka_unit_test(answers_stay_within_their_bound),
    cmocka_unit_test(a_ring_has_one_signature_per_contour),
    cmocka_unit_test(one_subpath_answers_as_one_curve),
};

TM_SUITE("api_shapes", tests, NULL, NULL);
