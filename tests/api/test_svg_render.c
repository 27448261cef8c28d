/* test_svg_render.c - SVG documents of morphs: every layout is well-formed
 * XML (xmllint), renders with a real renderer (rsvg-convert) to an image of
 * the declared size that is not blank, honours its options, survives
 * hostile option strings, and the animation keeps one command structure.
 *
 * Oracles: the external tools (libxml2's parser, librsvg), pixel counts of
 * the decoded PNG (a thicker stroke inks more pixels; a red stroke gives
 * red pixels), and geometry (a circle's constant curvature is a horizontal
 * line in the curvature plot; a polygon's corners are its tick marks).
 */
#include <ctype.h>
#include <stdbool.h>
#include <string.h>
#include <unistd.h>

#include "km/signature.h"
#include "svg_testutil.h"
#include "testmain.h"

/* PNG decoder (zlib + the five row filters) printing "width height dark
 * red" with dark = pixels whose darkest channel is below 200 and red =
 * clearly red pixels; the C test stays free of image libraries. */
static const char *PNG_PY =
    "import sys, zlib, struct\n"
    "data = open(sys.argv[1], 'rb').read()\n"
    "assert data[:8] == b'\\x89PNG\\r\\n\\x1a\\n'\n"
    "pos = 8; idat = b''\n"
    "while pos < len(data):\n"
    "    n, typ = struct.unpack('>I4s', data[pos:pos + 8])\n"
    "    body = data[pos + 8:pos + 8 + n]; pos += 12 + n\n"
    "    if typ == b'IHDR':\n"
    "        w, h, depth, ctype, _, _, inter = struct.unpack('>IIBBBBB', "
    "body)\n"
    "    elif typ == b'IDAT':\n"
    "        idat += body\n"
    "assert depth == 8 and inter == 0\n"
    "bpp = {6: 4, 2: 3, 4: 2, 0: 1}[ctype]\n"
    "raw = zlib.decompress(idat); stride = w * bpp\n"
    "prev = bytearray(stride); i = 0; dark = 0; red = 0; rowd = rowr = 0\n"
    "for y in range(h):\n"
    "    f = raw[i]; line = bytearray(raw[i + 1:i + 1 + stride]); i += 1 + "
    "stride\n"
    "    if f == 2:\n"
    "        line = bytearray(prev) if not any(line) else bytearray((u + v) & "
    "255 for u, v in zip(line, prev))\n"
    "    elif f in (1, 3, 4):\n"
    "        for x in range(stride):\n"
    "            a = line[x - bpp] if x >= bpp else 0\n"
    "            b = prev[x]; c = prev[x - bpp] if x >= bpp else 0\n"
    "            if f == 1: line[x] = (line[x] + a) & 255\n"
    "            elif f == 3: line[x] = (line[x] + (a + b) // 2) & 255\n"
    "            else:\n"
    "                p = a + b - c; pa = abs(p - a); pb = abs(p - b); pc = "
    "abs(p - c)\n"
    "                pr = a if pa <= pb and pa <= pc else (b if pb <= pc else "
    "c)\n"
    "                line[x] = (line[x] + pr) & 255\n"
    "    if y == 0 or line != prev:\n"
    "        chans = [line[k::bpp] for k in range(bpp)]\n"
    "        if bpp < 3: chans = [chans[0]] * 3 + chans[1:]\n"
    "        alpha = chans[3] if len(chans) > 3 else [255] * w\n"
    "        rowd = sum(1 for r, g, b, a in zip(chans[0], chans[1], chans[2], "
    "alpha) if a and min(r, g, b) < 200)\n"
    "        rowr = sum(1 for r, g, b, a in zip(chans[0], chans[1], chans[2], "
    "alpha) if a and r > 200 and g < 60 and b < 60)\n"
    "    dark += rowd; red += rowr\n"
    "    prev = line\n"
    "print(w, h, dark, red)\n";

typedef struct image {
  int w, h;
  long dark, red;
} image;

/* Write text to a fresh file under build/; the name goes into path. */
static void write_temp(const char *text, char path[64]) {
  strcpy(path, "build/svgtest-XXXXXX");
  int fd = mkstemp(path);
  assert_true(fd >= 0);
  FILE *f = fdopen(fd, "w");
  assert_non_null(f);
  assert_true(fputs(text, f) >= 0);
  assert_int_equal(fclose(f), 0);
}

/* Run a command, returning its exit status and the first line it prints. */
static int run(const char *cmd, char *out, size_t cap) {
  FILE *p = popen(cmd, "r");
  assert_non_null(p);
  if (out && cap) {
    out[0] = '\0';
    if (!fgets(out, (int)cap, p)) out[0] = '\0';
  }
  char sink[256];
  while (fgets(sink, sizeof sink, p)) {
  }
  int st = pclose(p);
  return st;
}

/* The document must parse as XML and render; returns the decoded image
 * (decoding, in Python, is the slow part: skipped unless asked for). */
static image check_document_opt(const char *doc, bool decode) {
  char svg[64], png[64], py[64], cmd[512], line[256];
  image im = {0, 0, 0, 0};
  write_temp(doc, svg);
  snprintf(cmd, sizeof cmd, "xmllint --noout %s 2>&1", svg);
  int st = run(cmd, line, sizeof line);
  if (st != 0) print_error("xmllint: %s\n", line);
  assert_int_equal(st, 0);
  write_temp("", png);
  snprintf(cmd, sizeof cmd, "rsvg-convert -f png -o %s %s 2>&1", png, svg);
  st = run(cmd, line, sizeof line);
  if (st != 0) print_error("rsvg-convert: %s\n", line);
  assert_int_equal(st, 0);
  if (!decode) {
    FILE *f = fopen(png, "rb");
    assert_non_null(f);
    assert_int_equal(fseek(f, 0, SEEK_END), 0);
    assert_true(ftell(f) > 100); /* a real PNG, not an empty file */
    fclose(f);
    unlink(svg);
    unlink(png);
    return im;
  }
  write_temp(PNG_PY, py);
  snprintf(cmd, sizeof cmd, "python3 %s %s 2>&1", py, png);
  st = run(cmd, line, sizeof line);
  if (st != 0) print_error("png decoder: %s\n", line);
  assert_int_equal(st, 0);
  assert_int_equal(
      sscanf(line, "%d %d %ld %ld", &im.w, &im.h, &im.dark, &im.red), 4);
  unlink(svg);
  unlink(png);
  unlink(py);
  return im;
}

static image check_document(const char *doc) {
  return check_document_opt(doc, true);
}

/* Value of attribute `name` of the root <svg> element. */
static double root_attr(const char *doc, const char *name) {
  const char *svg = strstr(doc, "<svg ");
  assert_non_null(svg);
  char key[32];
  snprintf(key, sizeof key, " %s=\"", name);
  const char *a = strstr(svg, key);
  assert_non_null(a);
  return strtod(a + strlen(key), NULL);
}

static void expect_size_and_ink(const char *doc, const image *im) {
  assert_int_equal(im->w, (int)ceil(root_attr(doc, "width")));
  assert_int_equal(im->h, (int)ceil(root_attr(doc, "height")));
  double frac = (double)im->dark / ((double)im->w * im->h);
  /* drawn, but not a page of ink */
  if (!(frac > 0.003 && frac < 0.5)) {
    print_error("dark fraction %g\n", frac);
    fail();
  }
}

/* Five shapes of the fixture as frames t = 0, 0.25, ..., 1. */
typedef struct frames {
  km_curve c[5];
  km_signature sig[5];
  api_svg_frame f[5];
  st_shapes s;
} frames;

static void load_frames(frames *fr, bool with_sig) {
  st_load_shapes(&fr->s);
  const char *ds[5] = {fr->s.d[0][0], fr->s.d[1][0], fr->s.d[0][1],
                       fr->s.d[5][1], fr->s.d[5][0]};
  for (int i = 0; i < 5; i++) {
    st_parse(ds[i], &fr->c[i]);
    km_signature_init(&fr->sig[i]);
    fr->f[i].t = i / 4.0;
    fr->f[i].curve = &fr->c[i];
    fr->f[i].sig = NULL;
    if (with_sig) {
      km_error e;
      km_status st = km_signature_compute(&fr->c[i], 1e-6, &fr->sig[i], &e);
      if (st) print_error("signature of frame %d: %s\n", i, e.message);
      assert_status(st, KM_OK);
      fr->f[i].sig = &fr->sig[i];
    }
  }
}

static void free_frames(frames *fr) {
  for (int i = 0; i < 5; i++) {
    km_curve_free(&fr->c[i]);
    km_signature_free(&fr->sig[i]);
  }
  st_free_shapes(&fr->s);
}

static char *render(const frames *fr, size_t n, api_svg_layout layout) {
  api_svg_options o;
  memset(&o, 0, sizeof o);
  o.layout = layout;
  char *doc = api_svg_morph_document(fr->f, n, &o);
  assert_non_null(doc);
  return doc;
}

static void every_layout_is_well_formed_and_renders(void **state) {
  (void)state;
  frames fr;
  load_frames(&fr, true);
  const api_svg_layout layouts[] = {API_SVG_FILMSTRIP, API_SVG_OVERLAY,
                                    API_SVG_ANIMATE, API_SVG_CURVATURE_PLOT};
  for (int k = 0; k < 4; k++) {
    char *doc = render(&fr, 5, layouts[k]);
    image im = check_document(doc);
    expect_size_and_ink(doc, &im);
    free(doc);
  }
  free_frames(&fr);
}

/* Without signatures the plot computes them; one frame alone works too. */
static void
curvature_plot_without_signatures_and_single_frames_render(void **state) {
  (void)state;
  frames fr;
  load_frames(&fr, false);
  char *doc = render(&fr, 5, API_SVG_CURVATURE_PLOT);
  assert_null(strstr(doc, "no signature"));
  image im = check_document(doc);
  expect_size_and_ink(doc, &im);
  free(doc);
  const api_svg_layout layouts[] = {API_SVG_FILMSTRIP, API_SVG_OVERLAY,
                                    API_SVG_ANIMATE, API_SVG_CURVATURE_PLOT};
  for (int k = 0; k < 4; k++) {
    doc = render(&fr, 1, layouts[k]);
    im = check_document(doc);
    expect_size_and_ink(doc, &im);
    free(doc);
  }
  free_frames(&fr);
}

static void size_stroke_and_colour_options_are_honoured(void **state) {
  (void)state;
  frames fr;
  load_frames(&fr, false);
  api_svg_options o;
  memset(&o, 0, sizeof o);
  o.layout = API_SVG_OVERLAY;
  o.width = 300;
  o.height = 200;
  o.stroke_width = 1;
  char *doc = api_svg_morph_document(fr.f, 5, &o);
  image thin = check_document(doc);
  assert_int_equal(thin.w, 300);
  assert_int_equal(thin.h, 200);
  free(doc);
  o.stroke_width = 4;
  doc = api_svg_morph_document(fr.f, 5, &o);
  image thick = check_document(doc);
  free(doc);
  /* four times the stroke inks well over twice the pixels */
  assert_true(thick.dark > 2 * thin.dark);
  /* a red ramp end and a red filmstrip stroke give red pixels; the
   * default colours give none */
  assert_int_equal(thin.red, 0);
  o.to_color = "#ff0000";
  o.from_color = "#f00";
  doc = api_svg_morph_document(fr.f, 5, &o);
  image red = check_document(doc);
  assert_true(red.red > thin.dark / 2);
  free(doc);
  memset(&o, 0, sizeof o);
  o.layout = API_SVG_FILMSTRIP;
  o.stroke = "red";
  o.width = 500;
  doc = api_svg_morph_document(fr.f, 5, &o);
  red = check_document(doc);
  assert_int_equal(red.w, 500);
  assert_true(red.red > 100);
  free(doc);
  free_frames(&fr);
}

/* Option strings go into attributes: markup in them must not escape. */
static void hostile_option_strings_keep_the_document_well_formed(void **state) {
  (void)state;
  frames fr;
  load_frames(&fr, false);
  const char *evil[] = {"\"/><script>alert(1)</script><x a=\"",
                        "&amp;&",
                        "<",
                        "red\" onload=\"x",
                        "\x01\x02",
                        ""};
  for (size_t i = 0; i < sizeof evil / sizeof evil[0]; i++) {
    for (int layout = 0; layout < 4; layout++) {
      api_svg_options o;
      memset(&o, 0, sizeof o);
      o.layout = (api_svg_layout)layout;
      o.stroke = o.from_color = o.to_color = evil[i];
      char *doc = api_svg_morph_document(fr.f, 2, &o);
      assert_non_null(doc);
      assert_null(strstr(doc, "<script"));
      assert_null(strstr(doc, "onload"));
      check_document_opt(doc, false);
      free(doc);
    }
  }
  /* non-finite t and absurd sizes still give a sane document */
  fr.f[0].t = NAN;
  fr.f[1].t = INFINITY;
  api_svg_options o;
  memset(&o, 0, sizeof o);
  o.layout = API_SVG_FILMSTRIP;
  o.width = 1e300;
  o.height = NAN;
  o.stroke_width = INFINITY;
  char *doc = api_svg_morph_document(fr.f, 2, &o);
  assert_null(strstr(doc, "nan"));
  assert_null(strstr(doc, "inf"));
  image im = check_document(doc);
  expect_size_and_ink(doc, &im);
  free(doc);
  free_frames(&fr);
}

/* The d strings of the values list, split at ';'. */
static size_t split_values(const char *doc, char **out, size_t cap) {
  const char *v = strstr(doc, " values=\"");
  assert_non_null(v);
  v += strlen(" values=\"");
  const char *end = strchr(v, '"');
  assert_non_null(end);
  size_t n = 0;
  while (v < end) {
    const char *semi = memchr(v, ';', (size_t)(end - v));
    if (!semi) semi = end;
    assert_true(n < cap);
    out[n] = strndup(v, (size_t)(semi - v));
    n++;
    v = semi + (semi < end);
  }
  return n;
}

/* Command letters and the count of numbers of one d string. */
static void shape_of(const char *d, char *cmds, size_t cap, size_t *nums) {
  size_t k = 0;
  *nums = 0;
  for (const char *p = d; *p;) {
    if (isalpha((unsigned char)*p) && *p != 'e') {
      if (k + 1 < cap) cmds[k++] = *p;
      p++;
    } else if (isdigit((unsigned char)*p) || strchr(".-+", *p)) {
      char *e;
      strtod(p, &e);
      (*nums)++;
      p = e;
    } else {
      p++;
    }
  }
  cmds[k] = '\0';
}

static void animation_frames_share_one_command_structure(void **state) {
  (void)state;
  frames fr;
  load_frames(&fr, false);
  for (int mixed = 0; mixed < 2; mixed++) {
    /* an open spiral among closed shapes: then no frame gets Z */
    km_curve open;
    if (mixed) {
      st_parse(fr.s.d[3][0], &open);
      assert_false(open.closed);
      fr.f[2].curve = &open;
    }
    char *doc = render(&fr, 5, API_SVG_ANIMATE);
    char *vals[8] = {NULL};
    size_t n = split_values(doc, vals, 8);
    assert_int_equal(n, 5);
    char c0[32], ci[32];
    size_t n0, ni;
    shape_of(vals[0], c0, sizeof c0, &n0);
    assert_string_equal(c0, mixed ? "MC" : "MCZ");
    for (size_t i = 0; i < n; i++) {
      shape_of(vals[i], ci, sizeof ci, &ni);
      assert_string_equal(ci, c0);
      assert_int_equal(ni, n0);
      /* every value is a path the parser accepts */
      km_curve back;
      st_parse(vals[i], &back);
      km_curve_free(&back);
      free(vals[i]);
    }
    /* the static d is the first frame */
    assert_non_null(strstr(doc, "d=\"M"));
    /* key times at the frames' t */
    const char *kt = strstr(doc, "keyTimes=\"");
    assert_non_null(kt);
    double k[5];
    assert_int_equal(sscanf(kt, "keyTimes=\"%lf;%lf;%lf;%lf;%lf", &k[0], &k[1],
                            &k[2], &k[3], &k[4]),
                     5);
    for (int i = 0; i < 5; i++) assert_close(k[i], i / 4.0, 1e-6);
    image im = check_document(doc);
    expect_size_and_ink(doc, &im);
    free(doc);
    if (mixed) {
      km_curve_free(&open);
      fr.f[2].curve = &fr.c[2];
    }
  }
  free_frames(&fr);
}

static void filmstrip_labels_every_frame_with_its_t(void **state) {
  (void)state;
  frames fr;
  load_frames(&fr, false);
  char *doc = render(&fr, 5, API_SVG_FILMSTRIP);
  const char *labels[] = {">t = 0<", ">t = 0.25<", ">t = 0.5<", ">t = 0.75<",
                          ">t = 1<"};
  for (int i = 0; i < 5; i++) assert_non_null(strstr(doc, labels[i]));
  size_t paths = 0;
  for (const char *p = doc; (p = strstr(p, "<path")); p++) paths++;
  assert_int_equal(paths, 5);
  free(doc);
  free_frames(&fr);
}

/* Pixel coordinates (x, y) of the polyline of frame i in the plot. */
static size_t plot_points(const char *doc, const char *colour, double *xy,
                          size_t cap) {
  char key[64];
  snprintf(key, sizeof key, "<path stroke=\"%s\"", colour);
  const char *p = strstr(doc, key);
  assert_non_null(p);
  p = strstr(p, " d=\"M");
  assert_non_null(p);
  p += 5;
  size_t n = 0;
  while (*p && *p != '"') {
    if (*p == 'L' || *p == ' ' || *p == ',') {
      p++;
      continue;
    }
    char *e;
    double v = strtod(p, &e);
    assert_true(e > p);
    assert_true(n < cap);
    xy[n++] = v;
    p = e;
  }
  return n / 2;
}

static void curvature_plot_shows_kappa_and_corners(void **state) {
  (void)state;
  frames fr;
  load_frames(&fr, true);
  char *doc = render(&fr, 5, API_SVG_CURVATURE_PLOT);
  /* default ramp: first frame #2166ac (the circle), third (the star) is
   * the middle colour */
  static double xy[2 * 20000];
  size_t n = plot_points(doc, "#2166ac", xy, 2 * 20000);
  assert_true(n > 10);
  double ymin = INFINITY, ymax = -INFINITY;
  for (size_t i = 0; i < n; i++) {
    ymin = fmin(ymin, xy[2 * i + 1]);
    ymax = fmax(ymax, xy[2 * i + 1]);
  }
  /* constant curvature 1/80 of the circle: a horizontal line */
  assert_close(ymax - ymin, 0, 0.02);
  /* x spans the normalised arc length [0, 1] */
  assert_true(xy[0] < xy[2 * (n - 1)]);
  /* one tick per corner: square 4 (the seam included), star 10, circle
   * none, heart 2, crescent 2 */
  size_t ticks = 0;
  for (const char *p = doc; (p = strstr(p, "<title>corner")); p++) ticks++;
  size_t want = 0;
  for (int i = 0; i < 5; i++) want += fr.sig[i].ncorners;
  assert_int_equal(ticks, want);
  assert_int_equal(fr.sig[0].ncorners, 0);
  assert_int_equal(fr.sig[1].ncorners, 4);
  assert_int_equal(fr.sig[2].ncorners, 10);
  free(doc);
  free_frames(&fr);
}

static void no_frames_still_give_a_document(void **state) {
  (void)state;
  for (int layout = 0; layout < 4; layout++) {
    api_svg_options o;
    memset(&o, 0, sizeof o);
    o.layout = (api_svg_layout)layout;
    char *doc = api_svg_morph_document(NULL, 0, &o);
    assert_non_null(doc);
    check_document_opt(doc, false);
    free(doc);
  }
  /* frames whose curve is missing are skipped, not dereferenced */
  api_svg_frame f[2] = {{0, NULL, NULL}, {1, NULL, NULL}};
  for (int layout = 0; layout < 4; layout++) {
    api_svg_options o;
    memset(&o, 0, sizeof o);
    o.layout = (api_svg_layout)layout;
    char *doc = api_svg_morph_document(f, 2, &o);
    assert_non_null(doc);
    check_document_opt(doc, false);
    free(doc);
  }
  char *doc = api_svg_morph_document(NULL, 3, NULL);
  assert_non_null(doc);
  check_document_opt(doc, false);
  free(doc);
}

/* The number after `key` in the first <path ...> of a document. */
static double path_number(const char *doc, const char *key) {
  const char *p = strstr(doc, "<path ");
  assert_non_null(p);
  const char *a = strstr(p, key);
  assert_non_null(a);
  return strtod(a + strlen(key), NULL);
}

/* A frame is laid out by the box of its trace, not of its control points
 * nor of samples: the cubic with control points (0, 0), (0, 10), (1, 3),
 * (1, 0) has x = 3 t^2 - 2 t^3 (0 .. 1) and y = 30 t - 51 t^2 + 21 t^3,
 * highest where y' = 30 - 102 t + 63 t^2 = 0, t = (102 - sqrt 2844) / 126,
 * between samples; its overlay must be laid out exactly as that of the
 * rectangle [0, 1] x [0, y max], whose corners are control points. */
static void the_layout_box_is_the_trace_box(void **state) {
  (void)state;
  double t = (102 - sqrt(2844.0)) / 126,
         ymax = 30 * t - 51 * t * t + 21 * t * t * t;
  const double kb[] = {0, 0, 0, 0, 1, 1, 1, 1};
  const double cb[] = {0, 0, 0, 10, 1, 3, 1, 0};
  const double kr[] = {0, 0, 1, 2, 3, 4, 4};
  const double cr[] = {0, 0, 1, 0, 1, ymax, 0, ymax, 0, 0};
  km_curve c[2];
  km_error err;
  km_curve_init(&c[0]);
  km_curve_init(&c[1]);
  assert_status(km_curve_create(&c[0], 3, 4, kb, cb, NULL, false, &err), KM_OK);
  assert_status(km_curve_create(&c[1], 1, 5, kr, cr, NULL, true, &err), KM_OK);
  double scale[2], shift[2];
  for (int k = 0; k < 2; k++) {
    api_svg_frame f = {0, &c[k], NULL};
    api_svg_options o;
    memset(&o, 0, sizeof o);
    o.layout = API_SVG_OVERLAY;
    char *doc = api_svg_morph_document(&f, 1, &o);
    assert_non_null(doc);
    scale[k] = path_number(doc, "scale(");
    shift[k] = path_number(doc, ") translate(");
    free(doc);
    km_curve_free(&c[k]);
  }
  /* the box is the trace's to 1e-6 of the control box (10 high): 2e-6 of
   * the frame's 5.7; sampling at t = k / 64 misses the top by 5e-4 (9e-5
   * of it), the control box overshoots by 4.8 */
  assert_true(fabs(scale[0] - scale[1]) <= 4e-6 * scale[1]);
  assert_true(fabs(shift[0] - shift[1]) <= 4e-6 * (1 + fabs(shift[1])));
}

static const struct CMUnitTest tests[] = {
    cmocka_unit_test(every_layout_is_well_formed_and_renders),
    cmocka_unit_test(the_layout_box_is_the_trace_box),
    cmocka_unit_test(
        curvature_plot_without_signatures_and_single_frames_render),
    cmocka_unit_test(size_stroke_and_colour_options_are_honoured),
    cmocka_unit_test(hostile_option_strings_keep_the_document_well_formed),
    cmocka_unit_test(animation_frames_share_one_command_structure),
    cmocka_unit_test(filmstrip_labels_every_frame_with_its_t),
    cmocka_unit_test(curvature_plot_shows_kappa_and_corners),
    cmocka_unit_test(no_frames_still_give_a_document),
};

TM_SUITE("svg_render", tests, NULL, NULL);
