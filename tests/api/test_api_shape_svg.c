/* test_api_shape_svg.c - what a compound morph draws: animate_d keeps one
 * command structure from the first frame to the last, also where a contour
 * vanishes or appears (it is then a point, inside the contour that takes
 * it in), and the SVG layouts of shapes.
 *
 * Oracles: path data parsed here (commands and their numbers counted, the
 * cubic pieces sampled densely and a winding number taken about the
 * polyline), the fixture pairs of tests/fixtures/compound (their contour
 * counts stated in pairs.json), and geometry: a contour scaled by (1 - t)
 * about a point that moves to its collapse point is, at t near 1, within
 * (1 - t) of the drawing's size of that point.
 */
#include <math.h>
#include <stdlib.h>

#include "api_testutil.h"
#include "testmain.h"

#define MORPH API_ROUTE_MORPH

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

/* The path data of a fixture ("dejavu-sans/O" from glyphs.json, "mdi/..."
 * from icons.json), malloc'd. */
static char *fixture_d(const char *id) {
  bool icon = strncmp(id, "mdi/", 4) == 0;
  char *text = read_file(icon ? "tests/fixtures/compound/icons.json"
                              : "tests/fixtures/compound/glyphs.json");
  char *d = NULL;
  cJSON *root = cJSON_Parse(text), *g;
  assert_non_null(root);
  cJSON_ArrayForEach(
      g, cJSON_GetObjectItemCaseSensitive(root, icon ? "icons" : "glyphs")) {
    const cJSON *gid = cJSON_GetObjectItemCaseSensitive(g, "id");
    if (strcmp(gid->valuestring, id) != 0) continue;
    const char *s = cJSON_GetObjectItemCaseSensitive(g, "d")->valuestring;
    d = malloc(strlen(s) + 1);
    assert_non_null(d);
    strcpy(d, s);
  }
  cJSON_Delete(root);
  free(text);
  if (d == NULL) print_error("no fixture %s\n", id);
  assert_non_null(d);
  return d;
}

/* A morph request between two fixtures with extra members (malloc'd). */
static char *pair_request(const char *from, const char *to, const char *extra) {
  char *a = fixture_d(from), *b = fixture_d(to);
  at_buf buf = {0};
  at_printf(&buf,
            "{\"from\":{\"type\":\"svg\",\"d\":\"%s\"},"
            "\"to\":{\"type\":\"svg\",\"d\":\"%s\"}%s}",
            a, b, extra);
  free(a);
  free(b);
  return buf.s;
}

/* The pair (from, to) is in pairs.json: the tests take pairs from there. */
static void assert_fixture_pair(const char *from, const char *to) {
  char *text = read_file("tests/fixtures/compound/pairs.json");
  cJSON *root = cJSON_Parse(text), *p;
  bool found = false;
  assert_non_null(root);
  cJSON_ArrayForEach(p, cJSON_GetObjectItemCaseSensitive(root, "pairs")) {
    const char *f = cJSON_GetObjectItemCaseSensitive(p, "from")->valuestring;
    const char *t = cJSON_GetObjectItemCaseSensitive(p, "to")->valuestring;
    found = found || (strcmp(f, from) == 0 && strcmp(t, to) == 0);
  }
  cJSON_Delete(root);
  free(text);
  if (!found) print_error("%s -> %s is not a fixture pair\n", from, to);
  assert_true(found);
}

/* ---- path data, parsed here ---- */

#define MAX_SUB 16

/* A path of absolute M, C and Z commands: its structure (each command
 * letter followed by how many numbers it took, e.g. "M2C300Z"), and per
 * subpath its points (the M point, then every cubic's three). */
typedef struct path {
  char structure[4096];
  size_t nsub;
  double *pts[MAX_SUB]; /* 2 per point */
  size_t npts[MAX_SUB];
} path;

static void path_parse(const char *d, path *p) {
  size_t len = 0, cap[MAX_SUB] = {0};
  char cmd = 0;
  size_t numbers = 0;
  memset(p, 0, sizeof *p);
  for (const char *s = d;; s++) {
    bool letter = *s != '\0' && strchr("MmCcZzLlHhVvQqSsTtAa", *s) != NULL;
    if (*s == '\0' || letter) {
      if (cmd != 0)
        len += (size_t)snprintf(p->structure + len, sizeof p->structure - len,
                                cmd == 'Z' ? "%c" : "%c%zu", cmd, numbers);
      assert_true(len < sizeof p->structure);
      if (*s == '\0') break;
      cmd = *s;
      numbers = 0;
      /* only what the fixed-piece writer emits */
      assert_non_null(strchr("MCZ", cmd));
      if (cmd == 'M') {
        assert_true(p->nsub < MAX_SUB);
        p->nsub++;
      }
      continue;
    }
    char *end;
    double v = strtod(s, &end);
    if (end == s) continue; /* separators */
    size_t k = p->nsub - 1, n = p->npts[k];
    assert_true(p->nsub > 0);
    if (2 * n + 2 > cap[k]) {
      cap[k] = cap[k] ? 2 * cap[k] : 64;
      p->pts[k] = realloc(p->pts[k], cap[k] * sizeof(double));
      assert_non_null(p->pts[k]);
    }
    /* numbers come in x, y order: a point is complete every second one */
    p->pts[k][2 * n + (numbers % 2)] = v;
    if (numbers % 2 == 1) p->npts[k]++;
    numbers++;
    s = end - 1;
  }
}

static void path_free(path *p) {
  for (size_t k = 0; k < p->nsub; k++) free(p->pts[k]);
}

/* Subpath k as a dense closed polyline: 32 samples of each cubic. */
static double *subpath_polyline(const path *p, size_t k, size_t *n) {
  size_t pieces = (p->npts[k] - 1) / 3;
  double *q = malloc((32 * pieces + 1) * 2 * sizeof *q);
  const double *a = p->pts[k];
  assert_non_null(q);
  *n = 0;
  for (size_t i = 0; i < pieces; i++) {
    const double *c = a + 6 * i;
    for (int j = 0; j < 32; j++) {
      double u = j / 32.0, v = 1 - u;
      double b[4] = {v * v * v, 3 * u * v * v, 3 * u * u * v, u * u * u};
      q[2 * *n] = b[0] * c[0] + b[1] * c[2] + b[2] * c[4] + b[3] * c[6];
      q[2 * *n + 1] = b[0] * c[1] + b[1] * c[3] + b[2] * c[5] + b[3] * c[7];
      (*n)++;
    }
  }
  return q;
}

/* Winding number of x about the closed polyline q of n points. */
static int winding(const double *q, size_t n, const double x[2]) {
  int w = 0;
  for (size_t i = 0; i < n; i++) {
    const double *a = q + 2 * i, *b = q + 2 * ((i + 1) % n);
    double cross =
        (b[0] - a[0]) * (x[1] - a[1]) - (x[0] - a[0]) * (b[1] - a[1]);
    if (a[1] <= x[1] && b[1] > x[1] && cross > 0) w++;
    if (a[1] > x[1] && b[1] <= x[1] && cross < 0) w--;
  }
  return w;
}

/* Largest distance of subpath k's points from x. */
static double spread_about(const path *p, size_t k, const double x[2]) {
  double r = 0;
  for (size_t i = 0; i < p->npts[k]; i++)
    r = fmax(r, hypot(p->pts[k][2 * i] - x[0], p->pts[k][2 * i + 1] - x[1]));
  return r;
}

/* Size of the whole drawing: the diagonal of all subpaths' points. */
static double drawing_size(const path *p) {
  double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
  for (size_t k = 0; k < p->nsub; k++)
    for (size_t i = 0; i < p->npts[k]; i++)
      for (int c = 0; c < 2; c++) {
        lo[c] = fmin(lo[c], p->pts[k][2 * i + c]);
        hi[c] = fmax(hi[c], p->pts[k][2 * i + c]);
      }
  return hypot(hi[0] - lo[0], hi[1] - lo[1]);
}

/* ---- animate_d ---- */

static const cJSON *member(const cJSON *o, const char *key) {
  const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
  if (v == NULL) print_error("no member \"%s\"\n", key);
  assert_non_null(v);
  return v;
}

/* Slot of the pair with a null on the to side (vanishing), or on the from
 * side (appearing); -1 if none. */
static int unpaired_slot(const cJSON *used, int side) {
  for (int k = 0; k < cJSON_GetArraySize(used); k++)
    if (cJSON_IsNull(cJSON_GetArrayItem(cJSON_GetArrayItem(used, k), side)))
      return k;
  return -1;
}

typedef struct morph_case {
  const char *from, *to;
  int slots;
} morph_case;

/* O -> C and i -> l (a hole and a dot vanish), a 4-contour icon losing a
 * ring, and a die whose pips appear. */
static const morph_case CASES[] = {
    {"dejavu-sans/O", "dejavu-sans/C", 2},
    {"dejavu-sans/i", "dejavu-sans/l", 2},
    {"mdi/circle-double", "mdi/target", 4},
    {"mdi/dice-3", "mdi/dice-5", 6},
};

/* Every value of animate_d has the first one's commands and numbers, one
 * subpath a slot (collapsed contours included). */
static void animate_d_keeps_one_structure(void **state) {
  (void)state;
  for (size_t c = 0; c < sizeof CASES / sizeof CASES[0]; c++) {
    assert_fixture_pair(CASES[c].from, CASES[c].to);
    char *body = pair_request(CASES[c].from, CASES[c].to,
                              ",\"frames\":9,\"include\":[\"animate_d\"]");
    cJSON *j = at_expect_json(MORPH, body);
    const cJSON *ad = member(j, "animate_d"), *v;
    int slots = cJSON_GetArraySize(member(j, "contour_matches_used"));
    path first, p;
    assert_int_equal(slots, CASES[c].slots);
    assert_int_equal(cJSON_GetArraySize(ad), 9);
    path_parse(cJSON_GetArrayItem(ad, 0)->valuestring, &first);
    cJSON_ArrayForEach(v, ad) {
      path_parse(v->valuestring, &p);
      if (p.nsub != (size_t)slots || strcmp(p.structure, first.structure) != 0)
        print_error("%s -> %s: value has %zu subpaths (%d slots), "
                    "structure %s, first %s\n",
                    CASES[c].from, CASES[c].to, p.nsub, slots, p.structure,
                    first.structure);
      assert_int_equal(p.nsub, (size_t)slots);
      assert_string_equal(p.structure, first.structure);
      path_free(&p);
    }
    path_free(&first);
    cJSON_Delete(j);
    free(body);
  }
}

/* At the end where a contour is absent its subpath is one point, inside
 * the contour it collapses into (O -> C: the C; i -> l: the l; the icon:
 * one of the rings left), and the live frames next to that end close in
 * on that point. */
static void collapsed_contour_is_a_point_inside_its_host(void **state) {
  (void)state;
  const int nframes = 41;
  for (size_t c = 0; c < sizeof CASES / sizeof CASES[0]; c++) {
    char *body = pair_request(CASES[c].from, CASES[c].to,
                              ",\"frames\":41,\"include\":[\"animate_d\"]");
    cJSON *j = at_expect_json(MORPH, body);
    const cJSON *ad = member(j, "animate_d");
    const cJSON *used = member(j, "contour_matches_used");
    int vanish = unpaired_slot(used, 1), appear = unpaired_slot(used, 0);
    for (int side = 0; side < 2; side++) {
      int slot = side == 0 ? vanish : appear;
      if (slot < 0) continue;
      /* the end where it is absent, and the frame next to it */
      int end = side == 0 ? nframes - 1 : 0, next = side == 0 ? end - 1 : 1;
      path pe, pn;
      path_parse(cJSON_GetArrayItem(ad, end)->valuestring, &pe);
      path_parse(cJSON_GetArrayItem(ad, next)->valuestring, &pn);
      assert_int_equal(pe.nsub, (size_t)cJSON_GetArraySize(used));
      const double *x = pe.pts[slot];
      double size = drawing_size(&pe);
      /* one point: every number of the subpath the same */
      assert_true(spread_about(&pe, (size_t)slot, x) <= 1e-9 * size);
      /* inside a contour of a paired slot of that frame */
      bool inside = false;
      for (size_t k = 0; k < pe.nsub; k++) {
        const cJSON *pr = cJSON_GetArrayItem(used, (int)k);
        if (cJSON_IsNull(cJSON_GetArrayItem(pr, 0)) ||
            cJSON_IsNull(cJSON_GetArrayItem(pr, 1)))
          continue;
        size_t n;
        double *q = subpath_polyline(&pe, k, &n);
        inside = inside || winding(q, n, x) != 0;
        free(q);
      }
      if (!inside)
        print_error("%s -> %s: slot %d collapses to (%g, %g), inside no "
                    "paired contour\n",
                    CASES[c].from, CASES[c].to, slot, x[0], x[1]);
      assert_true(inside);
      /* a frame 1/40 from the end: scaled by 1/40 about a point 1/40 of
       * the way back along its path, so within 2/40 of the size (its
       * travel and its own extent are each within the size) */
      double r = spread_about(&pn, (size_t)slot, x);
      if (!(r <= 2.0 / 40 * size && r > 0))
        print_error("%s -> %s: slot %d next to its end spreads %g about its "
                    "point, size %g\n",
                    CASES[c].from, CASES[c].to, slot, r, size);
      assert_true(r <= 2.0 / 40 * size && r > 0);
      path_free(&pe);
      path_free(&pn);
    }
    assert_true(vanish >= 0 || appear >= 0);
    cJSON_Delete(j);
    free(body);
  }
}

static const struct CMUnitTest tests[] = {
    cmocka_unit_test(animate_d_keeps_one_structure),
    cmocka_unit_test(collapsed_contour_is_a_point_inside_its_host),
};

TM_SUITE("api_shape_svg", tests, NULL, NULL);
