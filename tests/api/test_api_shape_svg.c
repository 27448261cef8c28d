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
#include <unistd.h>

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

/* Twice the signed area of the closed polyline q of n points. */
static double area2(const double *q, size_t n) {
  double a = 0;
  for (size_t i = 0; i < n; i++) {
    const double *u = q + 2 * i, *v = q + 2 * ((i + 1) % n);
    a += u[0] * v[1] - v[0] * u[1];
  }
  return a;
}

/* The innermost other subpath of p that holds every point of subpath k's
 * polyline (its parent in the nesting), or -1 for none. */
static int parent_subpath(const path *p, size_t k) {
  size_t nk, nh;
  double *qk = subpath_polyline(p, k, &nk), best = INFINITY;
  int parent = -1;
  for (size_t h = 0; h < p->nsub; h++) {
    if (h == k) continue;
    double *qh = subpath_polyline(p, h, &nh);
    bool all = nh > 2;
    for (size_t i = 0; all && i < nk; i++)
      all = winding(qh, nh, qk + 2 * i) != 0;
    double a = fabs(area2(qh, nh));
    if (all && a < best) {
      best = a;
      parent = (int)h;
    }
    free(qh);
  }
  free(qk);
  return parent;
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
 * its parent's partner (O -> C: the C; the icons: the ring or the die
 * that held it at the other end) or, for a top-level contour, inside a
 * paired one (i -> l: the l), and the live frames next to that end close
 * in on that point. That is the placement of "allow"; under "avoid" a
 * top-level contour may vanish where its host's mapping puts it instead
 * (km_shape_morph_create), as the dot of i does: pulled into the l it
 * meets the stem growing into it. */
static void collapsed_contour_is_a_point_inside_its_host(void **state) {
  (void)state;
  const int nframes = 21;
  for (size_t c = 0; c < sizeof CASES / sizeof CASES[0]; c++) {
    char *body = pair_request(CASES[c].from, CASES[c].to,
                              ",\"frames\":21,\"include\":[\"animate_d\"],"
                              "\"intersections\":\"allow\"");
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
      /* inside its parent's partner: the slot whose contour holds it at
       * the end where it is live (found here on that end's value) */
      path pl;
      path_parse(cJSON_GetArrayItem(ad, nframes - 1 - end)->valuestring, &pl);
      int parent = parent_subpath(&pl, (size_t)slot);
      path_free(&pl);
      if (parent >= 0) {
        size_t n;
        double *q = subpath_polyline(&pe, (size_t)parent, &n);
        if (winding(q, n, x) == 0)
          print_error("%s -> %s: slot %d collapses to (%g, %g), outside its "
                      "parent's slot %d\n",
                      CASES[c].from, CASES[c].to, slot, x[0], x[1], parent);
        assert_int_not_equal(winding(q, n, x), 0);
        free(q);
      }
      /* a top-level one inside a contour of a paired slot of that frame */
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
      /* a frame 1/20 from the end: scaled by 1/20 about a point 1/20 of
       * the way back along its path, so within 2/20 of the size (its
       * travel and its own extent are each within the size) */
      double r = spread_about(&pn, (size_t)slot, x);
      if (!(r <= 2.0 / 20 * size && r > 0))
        print_error("%s -> %s: slot %d next to its end spreads %g about its "
                    "point, size %g\n",
                    CASES[c].from, CASES[c].to, slot, r, size);
      assert_true(r <= 2.0 / 20 * size && r > 0);
      path_free(&pe);
      path_free(&pn);
    }
    assert_true(vanish >= 0 || appear >= 0);
    cJSON_Delete(j);
    free(body);
  }
}

/* ---- SVG documents ---- */

static const char *const LAYOUTS[] = {"filmstrip", "overlay", "animate",
                                      "curvature_plot"};

/* Write text to a fresh file under build/, its name into name. */
static void write_temp(const char *text, char name[64]) {
  strcpy(name, "build/shapesvg-XXXXXX");
  int fd = mkstemp(name);
  assert_true(fd >= 0);
  FILE *f = fdopen(fd, "w");
  assert_non_null(f);
  assert_true(fputs(text, f) >= 0);
  assert_int_equal(fclose(f), 0);
}

/* Exit status of cmd, its first line of output in out. */
static int run(const char *cmd, char *out, size_t cap) {
  FILE *p = popen(cmd, "r");
  char sink[256];
  assert_non_null(p);
  out[0] = '\0';
  if (!fgets(out, (int)cap, p)) out[0] = '\0';
  while (fgets(sink, sizeof sink, p)) {
  }
  return pclose(p);
}

/* The document parses as XML (libxml2's xmllint) and renders (librsvg) to
 * a PNG that is not empty. */
static void check_xml_and_render(const char *doc, const char *what) {
  char svg[64], png[64], cmd[256], line[256];
  write_temp(doc, svg);
  snprintf(cmd, sizeof cmd, "xmllint --noout %s 2>&1", svg);
  int st = run(cmd, line, sizeof line);
  if (st != 0) print_error("%s: xmllint: %s\n", what, line);
  assert_int_equal(st, 0);
  write_temp("", png);
  snprintf(cmd, sizeof cmd, "rsvg-convert -f png -o %s %s 2>&1", png, svg);
  st = run(cmd, line, sizeof line);
  if (st != 0) print_error("%s: rsvg-convert: %s\n", what, line);
  assert_int_equal(st, 0);
  FILE *f = fopen(png, "rb");
  assert_non_null(f);
  assert_int_equal(fseek(f, 0, SEEK_END), 0);
  assert_true(ftell(f) > 100);
  fclose(f);
  unlink(svg);
  unlink(png);
}

/* The SVG answer to body through the prepared plan, checked against the
 * size it was predicted to take before any frame (caller frees). */
static char *svg_answer(const char *body) {
  api_config cfg;
  api_request req;
  api_response err, res;
  api_morph_plan *plan = NULL;
  api_config_default(&cfg);
  memset(&req, 0, sizeof req);
  req.route = MORPH;
  req.body = body;
  req.length = strlen(body);
  int st = api_morph_prepare(&cfg, &req, 10, &plan, &err);
  if (st != API_STEP_DONE) print_error("prepare: %s\n", err.body);
  assert_int_equal(st, API_STEP_DONE);
  size_t bound = api_morph_predicted_bytes(plan);
  assert_int_equal(api_morph_result(plan, &res), 200);
  assert_string_equal(res.content_type, "image/svg+xml");
  if (bound < res.length)
    print_error("%zu bytes against a bound of %zu\n", res.length, bound);
  assert_true(bound >= res.length);
  char *doc = malloc(res.length + 1);
  assert_non_null(doc);
  memcpy(doc, res.body, res.length + 1);
  api_morph_plan_free(plan);
  api_response_free(&res);
  return doc;
}

static char *layout_request(const morph_case *mc, const char *layout,
                            int frames) {
  char extra[160];
  snprintf(extra, sizeof extra,
           ",\"frames\":%d,\"format\":\"svg\",\"svg\":{\"layout\":\"%s\"}",
           frames, layout);
  return pair_request(mc->from, mc->to, extra);
}

static size_t count(const char *s, const char *what) {
  size_t n = 0;
  for (const char *p = strstr(s, what); p != NULL; p = strstr(p + 1, what)) n++;
  return n;
}

/* Every layout of every case is XML that renders, within its bound. */
static void every_layout_parses_and_renders(void **state) {
  (void)state;
  for (size_t c = 0; c < sizeof CASES / sizeof CASES[0]; c++)
    for (size_t l = 0; l < 4; l++) {
      char *body = layout_request(&CASES[c], LAYOUTS[l], 5), what[128];
      char *doc = svg_answer(body);
      snprintf(what, sizeof what, "%s -> %s %s", CASES[c].from, CASES[c].to,
               LAYOUTS[l]);
      check_xml_and_render(doc, what);
      free(doc);
      free(body);
    }
}

/* The value of attribute `name` of the element at p (malloc'd). */
static char *attribute(const char *p, const char *name) {
  char key[64];
  snprintf(key, sizeof key, " %s=\"", name);
  const char *end = strchr(p, '>'), *a = strstr(p, key);
  if (a == NULL || a > end) return NULL;
  a += strlen(key);
  const char *z = strchr(a, '"');
  char *v = malloc((size_t)(z - a) + 1);
  assert_non_null(v);
  memcpy(v, a, (size_t)(z - a));
  v[z - a] = '\0';
  return v;
}

/* Filled paths of doc: each has fill-rule `rule`; their count. */
static size_t filled_paths(const char *doc, const char *rule) {
  size_t n = 0;
  for (const char *p = strstr(doc, "<path "); p != NULL;
       p = strstr(p + 1, "<path ")) {
    char *fill = attribute(p, "fill"), *fr = attribute(p, "fill-rule");
    if (fill != NULL && strcmp(fill, "none") != 0) {
      if (fr == NULL || strcmp(fr, rule) != 0)
        print_error("a filled path with fill-rule %s, not %s\n",
                    fr ? fr : "(none)", rule);
      assert_non_null(fr);
      assert_string_equal(fr, rule);
      n++;
    }
    free(fill);
    free(fr);
  }
  return n;
}

/* Two unit squares side by side against one; evenodd on both sides. */
#define SQUARE_AT(x0, x1)                                                      \
  "{\"type\":\"bspline\",\"degree\":1,\"knots\":[0,0,1,2,3,4,4],"              \
  "\"control_points\":[[" #x0 ",0],[" #x1 ",0],[" #x1 ",1],[" #x0 ",1],[" #x0  \
  ",0]],\"closed\":true}"
#define SHAPE(rule, ...)                                                       \
  "{\"type\":\"shape\",\"fill_rule\":\"" rule "\",\"contours\":[" __VA_ARGS__  \
  "]}"

/* The filmstrip, the overlay and the animation fill every shape under its
 * fill rule: one filled path a frame, one for the animation; and where the
 * two ends' rules differ the animation switches its rule at t = 0.5. */
static void fills_carry_the_fill_rule(void **state) {
  (void)state;
  static const size_t want[3] = {3, 3, 1};
  for (size_t l = 0; l < 3; l++) {
    char body[2048];
    snprintf(
        body, sizeof body,
        "{\"from\":" SHAPE(
            "evenodd",
            SQUARE_AT(0, 1) "," SQUARE_AT(
                3, 4)) ",\"to\":" SHAPE("evenodd",
                                        SQUARE_AT(0, 1)) ",\"frames\":3,"
                                                         "\"format\":\"svg\","
                                                         "\"svg\":{"
                                                         "\"layout\":\"%s\"}}",
        LAYOUTS[l]);
    char *doc = svg_answer(body);
    assert_int_equal(filled_paths(doc, "evenodd"), want[l]);
    assert_int_equal(count(doc, "fill-rule=\"nonzero\""), 0);
    free(doc);
    char *gl = layout_request(&CASES[0], LAYOUTS[l], 3);
    doc = svg_answer(gl);
    assert_int_equal(filled_paths(doc, "nonzero"), want[l]);
    free(doc);
    free(gl);
  }
  /* evenodd to nonzero: the rule of the nearer end, switched at 0.5 */
  char *doc = svg_answer("{\"from\":" SHAPE(
      "evenodd",
      SQUARE_AT(0, 1) "," SQUARE_AT(
          3, 4)) ",\"to\":" SHAPE("nonzero",
                                  SQUARE_AT(0, 1) "," SQUARE_AT(
                                      3, 4)) ",\"frames\":3,\"format\":\"svg\","
                                             "\"svg\":{\"layout\":"
                                             "\"animate\"}}");
  const char *a = strstr(doc, "<animate attributeName=\"fill-rule\"");
  assert_non_null(a);
  char *values = attribute(a, "values"), *mode = attribute(a, "calcMode");
  assert_string_equal(values, "evenodd;nonzero;nonzero");
  assert_string_equal(mode, "discrete");
  free(values);
  free(mode);
  free(doc);
}

/* The animation's values split at ';' into paths (malloc'd, *n of them). */
static char **split_values(const char *v, size_t *n) {
  size_t cap = count(v, ";") + 1, len;
  char **out = malloc(cap * sizeof *out);
  assert_non_null(out);
  *n = 0;
  for (const char *p = v;; p += len + 1) {
    const char *z = strchr(p, ';');
    len = z != NULL ? (size_t)(z - p) : strlen(p);
    out[*n] = malloc(len + 1);
    assert_non_null(out[*n]);
    memcpy(out[*n], p, len);
    out[(*n)++][len] = '\0';
    if (z == NULL) break;
  }
  return out;
}

/* The animate layout: one <animate> of "d" with a value a frame and as
 * many key times, every value of the first one's commands and numbers,
 * one subpath a slot, the collapsed slot one point inside a paired
 * contour (under "allow": see collapsed_contour_is_a_point_inside_its_host
 * for "avoid"). */
static void animation_values_share_one_structure(void **state) {
  (void)state;
  for (size_t c = 0; c < sizeof CASES / sizeof CASES[0]; c++) {
    char *body = pair_request(CASES[c].from, CASES[c].to,
                              ",\"frames\":9,\"format\":\"svg\",\"svg\":"
                              "{\"layout\":\"animate\"},"
                              "\"intersections\":\"allow\"");
    char *doc = svg_answer(body);
    assert_int_equal(count(doc, "<animate attributeName=\"d\""), 1);
    const char *a = strstr(doc, "<animate attributeName=\"d\"");
    char *values = attribute(a, "values"), *keys = attribute(a, "keyTimes");
    size_t n, nk;
    char **vs = split_values(values, &n), **ks = split_values(keys, &nk);
    assert_int_equal(n, 9);
    assert_int_equal(nk, 9);
    path first, p;
    path_parse(vs[0], &first);
    assert_int_equal(first.nsub, (size_t)CASES[c].slots);
    for (size_t i = 0; i < n; i++) {
      path_parse(vs[i], &p);
      if (strcmp(p.structure, first.structure) != 0)
        print_error("%s -> %s: value %zu is %s, the first %s\n", CASES[c].from,
                    CASES[c].to, i, p.structure, first.structure);
      assert_int_equal(p.nsub, first.nsub);
      assert_string_equal(p.structure, first.structure);
      /* a collapsed slot at the ends: one point inside another subpath */
      for (size_t k = 0; (i == 0 || i + 1 == n) && k < p.nsub; k++) {
        if (spread_about(&p, k, p.pts[k]) > 1e-9 * drawing_size(&p)) continue;
        bool inside = false;
        for (size_t h = 0; h < p.nsub; h++) {
          size_t np;
          if (h == k || spread_about(&p, h, p.pts[h]) == 0) continue;
          double *q = subpath_polyline(&p, h, &np);
          inside = inside || winding(q, np, p.pts[k]) != 0;
          free(q);
        }
        assert_true(inside);
      }
      path_free(&p);
      free(vs[i]);
      free(ks[i]);
    }
    path_free(&first);
    free(vs);
    free(ks);
    free(values);
    free(keys);
    free(doc);
    free(body);
  }
}

/* The curvature plot: one labelled panel per contour pair, each with one
 * trace per frame where the pair's contour is present (as the JSON answer
 * to the same morph says), none where it is a point. */
static void curvature_plot_has_a_panel_per_pair(void **state) {
  (void)state;
  for (size_t c = 0; c < sizeof CASES / sizeof CASES[0]; c++) {
    char *body = layout_request(&CASES[c], "curvature_plot", 5);
    char *jbody = pair_request(CASES[c].from, CASES[c].to, ",\"frames\":5");
    char *doc = svg_answer(body);
    cJSON *j = at_expect_json(MORPH, jbody);
    const cJSON *frames = member(j, "frames");
    int slots = CASES[c].slots;
    assert_int_equal(count(doc, "<g id=\"km-pair-"), (size_t)slots);
    for (int k = 0; k < slots; k++) {
      char id[40], label[40];
      snprintf(id, sizeof id, "<g id=\"km-pair-%d\">", k);
      snprintf(label, sizeof label, ">pair %d: contour", k);
      const char *g = strstr(doc, id), *end;
      assert_non_null(g);
      /* the panel runs to the next one or the document's end */
      end = strstr(g + 1, "<g id=\"km-pair-");
      if (end == NULL) end = strstr(g, "</svg>");
      assert_non_null(end);
      /* the panel's label names the pair */
      const char *lab = strstr(g, label);
      char alt[40];
      snprintf(alt, sizeof alt, ">pair %d: (appears)", k);
      const char *lab2 = strstr(g, alt);
      assert_true((lab != NULL && lab < end) || (lab2 != NULL && lab2 < end));
      size_t traces = 0, present = 0;
      for (const char *p = strstr(g, "<path "); p != NULL && p < end;
           p = strstr(p + 1, "<path "))
        traces++;
      const cJSON *f;
      cJSON_ArrayForEach(f, frames) {
        present += cJSON_IsObject(cJSON_GetArrayItem(member(f, "contours"), k));
      }
      if (traces != present)
        print_error("%s -> %s: panel %d has %zu traces, %zu frames with its "
                    "contour\n",
                    CASES[c].from, CASES[c].to, k, traces, present);
      assert_int_equal(traces, present);
    }
    cJSON_Delete(j);
    free(doc);
    free(jbody);
    free(body);
  }
}

static const struct CMUnitTest tests[] = {
    cmocka_unit_test(animate_d_keeps_one_structure),
    cmocka_unit_test(collapsed_contour_is_a_point_inside_its_host),
    cmocka_unit_test(every_layout_parses_and_renders),
    cmocka_unit_test(fills_carry_the_fill_rule),
    cmocka_unit_test(animation_values_share_one_structure),
    cmocka_unit_test(curvature_plot_has_a_panel_per_pair),
};

TM_SUITE("api_shape_svg", tests, NULL, NULL);
