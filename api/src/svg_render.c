/* svg_render.c - SVG documents of morph results: filmstrip, overlay,
 * animation and curvature plot.
 *
 * DESIGN. Every layout is written into one growing buffer as plain SVG 1.1
 * that librsvg and browsers both draw. Frames are drawn in their own
 * coordinates (the SVG user space the input paths came from) under a
 * translate-and-scale transform, one scale for all frames so that sizes
 * compare as in the paper's figures; the view box fits the union of all
 * frames. Curve paths are written with api_svg_path_d at a tolerance of a
 * twentieth of a pixel, so what is drawn is the curve to the eye. All text
 * that comes from options is escaped; colours that are not plain CSS colour
 * tokens are replaced by the defaults, so the document is well-formed
 * whatever it is given. The animation writes every frame with the same
 * number of cubic pieces (uniform in arc length) so SMIL can interpolate.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "km/fn.h"
#include "km/signature.h"
#include "svg.h"

#define DEF_FROM "#2166ac"
#define DEF_TO "#b2182b"
#define DEF_STROKE "#1a1a1a"
#define FONT "font-family=\"sans-serif\""

/* Pixel budget for printed document coordinates. */
#define PX_BUDGET 0.005

typedef struct bbox {
  double x0, y0, x1, y1;
  bool empty;
} bbox;

static void bbox_add(bbox *b, double x, double y) {
  if (!isfinite(x) || !isfinite(y)) return;
  if (b->empty) {
    b->x0 = b->x1 = x;
    b->y0 = b->y1 = y;
    b->empty = false;
    return;
  }
  if (x < b->x0) b->x0 = x;
  if (x > b->x1) b->x1 = x;
  if (y < b->y0) b->y0 = y;
  if (y > b->y1) b->y1 = y;
}

/* Bounding box of a curve's trace by sampling every knot span (the control
 * polygon would be safe but loose for NURBS and long legs). */
static void curve_bbox(const km_curve *c, bbox *b) {
  if (!c || c->n == 0) return;
  size_t spans = 0;
  for (size_t i = (size_t)c->degree; i < c->n; i++)
    if (c->knots[i + 1] > c->knots[i]) spans++;
  int per = spans ? (int)(4096 / spans) : 2;
  if (per < 2) per = 2;
  if (per > 64) per = 64;
  for (size_t i = (size_t)c->degree; i < c->n; i++) {
    double a = c->knots[i], e = c->knots[i + 1];
    if (!(e > a)) continue;
    for (int k = 0; k <= per; k++) {
      double pt[1][2];
      km_curve_eval(c, a + (e - a) * k / per, 0, pt);
      bbox_add(b, pt[0][0], pt[0][1]);
    }
  }
}

typedef struct rgb {
  double r, g, b;
} rgb;

static int hexval(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

/* "#rgb" or "#rrggbb". */
static bool parse_hex(const char *s, rgb *out) {
  if (!s || s[0] != '#') return false;
  size_t n = strlen(s + 1);
  int v[6];
  if (n != 3 && n != 6) return false;
  for (size_t i = 0; i < n; i++)
    if ((v[i] = hexval(s[1 + i])) < 0) return false;
  if (n == 3) {
    out->r = v[0] * 17;
    out->g = v[1] * 17;
    out->b = v[2] * 17;
  } else {
    out->r = v[0] * 16 + v[1];
    out->g = v[2] * 16 + v[3];
    out->b = v[4] * 16 + v[5];
  }
  return true;
}

/* A plain CSS colour token: a name, #hex, or rgb()/hsl() with numbers. */
static bool css_colour_ok(const char *s) {
  if (!s || !*s || strlen(s) > 64) return false;
  for (const char *p = s; *p; p++) {
    char c = *p;
    if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
          (c >= '0' && c <= '9') || strchr("#(),.% -", c)))
      return false;
  }
  return true;
}

static const char *colour_or(const char *s, const char *def) {
  return css_colour_ok(s) ? s : def;
}

static void ramp(const rgb *a, const rgb *b, double f, char out[8]) {
  if (!(f >= 0)) f = 0;
  if (f > 1) f = 1;
  int r = (int)lround(a->r + (b->r - a->r) * f);
  int g = (int)lround(a->g + (b->g - a->g) * f);
  int bl = (int)lround(a->b + (b->b - a->b) * f);
  snprintf(out, 8, "#%02x%02x%02x", r & 255, g & 255, bl & 255);
}

typedef struct ctx {
  api_svg_buf b;
  const api_svg_frame *f;
  size_t n;
  double W, H;   /* document size, px */
  double sw;     /* stroke width, px */
  const char *stroke;
  rgb from, to;
  const char *from_s, *to_s; /* colour strings as written */
} ctx;

static void num(ctx *c, double v) { api__svg_buf_num(&c->b, v, PX_BUDGET, NULL); }

static void frame_colour(const ctx *c, size_t i, char out[8]) {
  double f = c->n > 1 ? (double)i / (double)(c->n - 1) : 0.0;
  ramp(&c->from, &c->to, f, out);
}

static void t_label(ctx *c, double t) {
  char s[40];
  snprintf(s, sizeof s, "t = %.4g", isfinite(t) ? t : 0.0);
  api__svg_buf_escaped(&c->b, s);
}

static void doc_open(ctx *c, const char *title) {
  api__svg_buf_put(&c->b, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
                          "<svg xmlns=\"http://www.w3.org/2000/svg\" "
                          "version=\"1.1\" width=\"");
  num(c, c->W);
  api__svg_buf_put(&c->b, "\" height=\"");
  num(c, c->H);
  api__svg_buf_put(&c->b, "\" viewBox=\"0 0 ");
  num(c, c->W);
  api__svg_buf_put(&c->b, " ");
  num(c, c->H);
  api__svg_buf_put(&c->b, "\">\n<title>");
  api__svg_buf_escaped(&c->b, title);
  api__svg_buf_put(&c->b, "</title>\n<rect width=\"100%\" height=\"100%\" "
                          "fill=\"#ffffff\"/>\n");
}

/* A frame's curve under transform x -> ox + s (x - bx0), y likewise. */
static void draw_curve(ctx *c, const km_curve *cv, double ox, double oy,
                       double s, const bbox *bb, const char *colour) {
  char *d = api_svg_path_d(cv, 0.05 / s, NULL);
  if (!d) {
    c->b.failed = true;
    return;
  }
  api__svg_buf_put(&c->b, "<path transform=\"translate(");
  num(c, ox);
  api__svg_buf_put(&c->b, " ");
  num(c, oy);
  api__svg_buf_put(&c->b, ") scale(");
  api__svg_buf_num(&c->b, s, 1e-9 * s, NULL);
  api__svg_buf_put(&c->b, ") translate(");
  api__svg_buf_num(&c->b, -bb->x0, 1e-4 / s, NULL);
  api__svg_buf_put(&c->b, " ");
  api__svg_buf_num(&c->b, -bb->y0, 1e-4 / s, NULL);
  api__svg_buf_put(&c->b, ")\" fill=\"none\" stroke=\"");
  api__svg_buf_escaped(&c->b, colour);
  api__svg_buf_put(&c->b, "\" stroke-width=\"");
  api__svg_buf_num(&c->b, c->sw / s, 1e-3 * c->sw / s, NULL);
  api__svg_buf_put(&c->b, "\" stroke-linejoin=\"round\" "
                          "stroke-linecap=\"round\" d=\"");
  api__svg_buf_put(&c->b, d);
  api__svg_buf_put(&c->b, "\"/>\n");
  free(d);
}

/* Union box of all frames, padded, never empty or flat. */
static bbox frames_bbox(const ctx *c) {
  bbox bb = {0, 0, 0, 0, true};
  for (size_t i = 0; i < c->n; i++) curve_bbox(c->f[i].curve, &bb);
  if (bb.empty) bb = (bbox){0, 0, 1, 1, false};
  double w = bb.x1 - bb.x0, h = bb.y1 - bb.y0;
  double m = (w > h ? w : h);
  if (!(m > 0)) m = 1.0;
  /* A line has no height: give it some so the scale stays finite. */
  if (w < 1e-3 * m) {
    bb.x0 -= 0.5e-3 * m;
    bb.x1 += 0.5e-3 * m;
  }
  if (h < 1e-3 * m) {
    bb.y0 -= 0.5e-3 * m;
    bb.y1 += 0.5e-3 * m;
  }
  double pad = 0.05 * m;
  bb.x0 -= pad;
  bb.y0 -= pad;
  bb.x1 += pad;
  bb.y1 += pad;
  return bb;
}

/* Largest uniform scale fitting bb into w x h, and the offsets centring
 * it. */
static double fit(const bbox *bb, double w, double h, double *ox,
                  double *oy) {
  double bw = bb->x1 - bb->x0, bh = bb->y1 - bb->y0;
  double s = fmin(w / bw, h / bh);
  *ox += 0.5 * (w - s * bw);
  *oy += 0.5 * (h - s * bh);
  return s;
}

static void filmstrip(ctx *c, const api_svg_options *o) {
  bbox bb = frames_bbox(c);
  double aspect = (bb.y1 - bb.y0) / (bb.x1 - bb.x0);
  if (aspect < 0.25) aspect = 0.25;
  if (aspect > 4) aspect = 4;
  size_t n = c->n ? c->n : 1;
  size_t cols = (size_t)ceil(sqrt(1.6 * (double)n / aspect));
  if (cols < 1) cols = 1;
  if (cols > n) cols = n;
  size_t rows = (n + cols - 1) / cols;
  const double label = 20.0;
  double cw = 160.0, ch = cw * aspect + label;
  if (o->width > 0) cw = o->width / (double)cols;
  if (o->height > 0) ch = o->height / (double)rows;
  else if (o->width > 0) ch = cw * aspect + label;
  /* Automatic sizes are whole pixels: renderers round them up anyway. */
  c->W = o->width > 0 ? o->width : ceil(cw * (double)cols);
  c->H = o->height > 0 ? o->height : ceil(ch * (double)rows);
  char title[80];
  snprintf(title, sizeof title, "kmorph filmstrip of %zu frames", c->n);
  doc_open(c, title);
  const char *stroke = c->stroke;
  for (size_t i = 0; i < c->n; i++) {
    size_t r = i / cols, k = i % cols;
    double x = cw * (double)k, y = ch * (double)r;
    api__svg_buf_put(&c->b, "<rect x=\"");
    num(c, x + 0.5);
    api__svg_buf_put(&c->b, "\" y=\"");
    num(c, y + 0.5);
    api__svg_buf_put(&c->b, "\" width=\"");
    num(c, fmax(cw - 1, 0));
    api__svg_buf_put(&c->b, "\" height=\"");
    num(c, fmax(ch - 1, 0));
    api__svg_buf_put(&c->b,
                     "\" fill=\"none\" stroke=\"#d0d0d0\" "
                     "stroke-width=\"1\"/>\n");
    double ox = x + 4, oy = y + 4;
    double dw = fmax(cw - 8, 1), dh = fmax(ch - label - 8, 1);
    double s = fit(&bb, dw, dh, &ox, &oy);
    if (c->f[i].curve) draw_curve(c, c->f[i].curve, ox, oy, s, &bb, stroke);
    api__svg_buf_put(&c->b, "<text x=\"");
    num(c, x + 0.5 * cw);
    api__svg_buf_put(&c->b, "\" y=\"");
    num(c, y + ch - 6);
    api__svg_buf_put(&c->b, "\" " FONT " font-size=\"12\" "
                            "text-anchor=\"middle\" fill=\"#333333\">");
    t_label(c, c->f[i].t);
    api__svg_buf_put(&c->b, "</text>\n");
  }
}

/* Horizontal colour bar from the first frame's colour to the last one's,
 * with their t values, across [x, x + w] at height y. */
static void ramp_legend(ctx *c, double x, double y, double w) {
  if (c->n == 0) return;
  api__svg_buf_put(&c->b, "<defs><linearGradient id=\"km-ramp\" x1=\"0\" "
                          "y1=\"0\" x2=\"1\" y2=\"0\"><stop offset=\"0\" "
                          "stop-color=\"");
  char a[8], z[8];
  frame_colour(c, 0, a);
  frame_colour(c, c->n - 1, z);
  api__svg_buf_put(&c->b, a);
  api__svg_buf_put(&c->b, "\"/><stop offset=\"1\" stop-color=\"");
  api__svg_buf_put(&c->b, z);
  api__svg_buf_put(&c->b, "\"/></linearGradient></defs>\n<rect x=\"");
  num(c, x + 60);
  api__svg_buf_put(&c->b, "\" y=\"");
  num(c, y - 9);
  api__svg_buf_put(&c->b, "\" width=\"");
  num(c, fmax(w - 120, 1));
  api__svg_buf_put(&c->b, "\" height=\"8\" fill=\"url(#km-ramp)\"/>\n");
  api__svg_buf_put(&c->b, "<text x=\"");
  num(c, x + 55);
  api__svg_buf_put(&c->b, "\" y=\"");
  num(c, y);
  api__svg_buf_put(&c->b, "\" " FONT " font-size=\"11\" "
                          "text-anchor=\"end\" fill=\"#333333\">");
  t_label(c, c->f[0].t);
  api__svg_buf_put(&c->b, "</text>\n<text x=\"");
  num(c, x + w - 55);
  api__svg_buf_put(&c->b, "\" y=\"");
  num(c, y);
  api__svg_buf_put(&c->b, "\" " FONT " font-size=\"11\" fill=\"#333333\">");
  t_label(c, c->f[c->n - 1].t);
  api__svg_buf_put(&c->b, "</text>\n");
}

static void overlay(ctx *c, const api_svg_options *o) {
  bbox bb = frames_bbox(c);
  double aspect = (bb.y1 - bb.y0) / (bb.x1 - bb.x0);
  const double legend = 24.0;
  double w = o->width > 0 ? o->width : 480.0;
  double h = o->height > 0
                 ? o->height
                 : ceil(w * fmin(fmax(aspect, 0.25), 4) + legend);
  c->W = w;
  c->H = h;
  char title[80];
  snprintf(title, sizeof title, "kmorph overlay of %zu frames", c->n);
  doc_open(c, title);
  double ox = 6, oy = 6;
  double s = fit(&bb, fmax(w - 12, 1), fmax(h - legend - 12, 1), &ox, &oy);
  for (size_t i = 0; i < c->n; i++) {
    char col[8];
    frame_colour(c, i, col);
    if (c->f[i].curve) draw_curve(c, c->f[i].curve, ox, oy, s, &bb, col);
  }
  ramp_legend(c, 0, h - 8, w);
}

/* Pieces for the animation: enough for the most detailed frame, bounded
 * so that a long morph stays a reasonable document. */
static size_t animate_pieces(const ctx *c) {
  size_t most = 0;
  for (size_t i = 0; i < c->n; i++) {
    const km_curve *cv = c->f[i].curve;
    if (!cv) continue;
    size_t spans = 0;
    for (size_t k = (size_t)cv->degree; k < cv->n; k++)
      if (cv->knots[k + 1] > cv->knots[k]) spans++;
    if (spans > most) most = spans;
  }
  most *= 2;
  if (most < 32) most = 32;
  if (most > 400) most = 400;
  /* Keep a long animation's document to a few megabytes. */
  size_t share = c->n ? 200000 / c->n : 400;
  if (share < 16) share = 16;
  if (most > share) most = share;
  return most;
}

static void animate(ctx *c, const api_svg_options *o) {
  bbox bb = frames_bbox(c);
  double aspect = (bb.y1 - bb.y0) / (bb.x1 - bb.x0);
  const double label = 20.0;
  double w = o->width > 0 ? o->width : 400.0;
  double h = o->height > 0
                 ? o->height
                 : ceil(w * fmin(fmax(aspect, 0.25), 4) + label);
  c->W = w;
  c->H = h;
  char title[80];
  snprintf(title, sizeof title, "kmorph animation of %zu frames", c->n);
  doc_open(c, title);
  double ox = 6, oy = 6;
  double s = fit(&bb, fmax(w - 12, 1), fmax(h - label - 12, 1), &ox, &oy);
  size_t np = animate_pieces(c);
  /* One command structure for every frame, Z included or not for all. */
  bool all_closed = c->n > 0;
  size_t drawn = 0;
  for (size_t i = 0; i < c->n; i++)
    if (c->f[i].curve) {
      drawn++;
      if (!c->f[i].curve->closed) all_closed = false;
    }
  if (drawn == 0) return;
  char **ds = calloc(c->n, sizeof *ds);
  if (!ds) {
    c->b.failed = true;
    return;
  }
  const char *first = NULL;
  for (size_t i = 0; i < c->n; i++) {
    if (!c->f[i].curve) continue;
    ds[i] = api_svg_path_d_fixed_z(c->f[i].curve, np, all_closed);
    if (!ds[i]) c->b.failed = true;
    else if (!first) first = ds[i];
  }
  if (!c->b.failed) {
    double dur = o->duration > 0 && isfinite(o->duration) ? o->duration : 2.0;
    api__svg_buf_put(&c->b, "<path transform=\"translate(");
    num(c, ox);
    api__svg_buf_put(&c->b, " ");
    num(c, oy);
    api__svg_buf_put(&c->b, ") scale(");
    api__svg_buf_num(&c->b, s, 1e-9 * s, NULL);
    api__svg_buf_put(&c->b, ") translate(");
    api__svg_buf_num(&c->b, -bb.x0, 1e-4 / s, NULL);
    api__svg_buf_put(&c->b, " ");
    api__svg_buf_num(&c->b, -bb.y0, 1e-4 / s, NULL);
    api__svg_buf_put(&c->b, ")\" fill=\"none\" stroke=\"");
    api__svg_buf_escaped(&c->b, c->stroke);
    api__svg_buf_put(&c->b, "\" stroke-width=\"");
    api__svg_buf_num(&c->b, c->sw / s, 1e-3 * c->sw / s, NULL);
    api__svg_buf_put(&c->b, "\" stroke-linejoin=\"round\" d=\"");
    api__svg_buf_put(&c->b, first);
    api__svg_buf_put(&c->b, "\">\n<animate attributeName=\"d\" dur=\"");
    api__svg_buf_num(&c->b, dur, 1e-4, NULL);
    api__svg_buf_put(&c->b, "s\" repeatCount=\"indefinite\" "
                            "calcMode=\"linear\"");
    /* keyTimes place frames at their t when the times increase. */
    bool increasing = drawn >= 2;
    double tfirst = NAN, tlast = NAN, prev = -INFINITY;
    for (size_t i = 0; i < c->n; i++) {
      if (!ds[i]) continue;
      double t = c->f[i].t;
      if (!isfinite(t) || !(t > prev)) increasing = false;
      if (isnan(tfirst)) tfirst = t;
      tlast = t;
      prev = t;
    }
    if (increasing && tlast > tfirst) {
      api__svg_buf_put(&c->b, " keyTimes=\"");
      size_t k = 0;
      for (size_t i = 0; i < c->n; i++) {
        if (!ds[i]) continue;
        double kt = (c->f[i].t - tfirst) / (tlast - tfirst);
        if (k == 0) kt = 0;
        if (k + 1 == drawn) kt = 1;
        if (k) api__svg_buf_put(&c->b, ";");
        api__svg_buf_num(&c->b, kt, 1e-6, NULL);
        k++;
      }
      api__svg_buf_put(&c->b, "\"");
    }
    api__svg_buf_put(&c->b, " values=\"");
    size_t k = 0;
    for (size_t i = 0; i < c->n; i++) {
      if (!ds[i]) continue;
      if (k++) api__svg_buf_put(&c->b, ";");
      api__svg_buf_put(&c->b, ds[i]);
    }
    /* SMIL needs two values to animate; one frame holds still. */
    if (drawn == 1) {
      api__svg_buf_put(&c->b, ";");
      api__svg_buf_put(&c->b, first);
    }
    api__svg_buf_put(&c->b, "\"/>\n</path>\n<text x=\"");
    num(c, 0.5 * w);
    api__svg_buf_put(&c->b, "\" y=\"");
    num(c, h - 6);
    api__svg_buf_put(&c->b, "\" " FONT " font-size=\"12\" "
                            "text-anchor=\"middle\" fill=\"#333333\">");
    char s2[80];
    snprintf(s2, sizeof s2, "t = %.4g \xe2\x80\xa6 %.4g",
             isfinite(tfirst) ? tfirst : 0.0, isfinite(tlast) ? tlast : 0.0);
    api__svg_buf_escaped(&c->b, s2);
    api__svg_buf_put(&c->b, "</text>\n");
  }
  for (size_t i = 0; i < c->n; i++) free(ds[i]);
  free(ds);
}

/* ---- curvature plot ---------------------------------------------------- */

typedef struct series {
  double *x, *y; /* s/L and kappa */
  size_t n;
  const km_signature *sig;
  km_signature own; /* computed here when the frame brought none */
  bool has_own;
} series;

static int cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

/* Samples of kappa over every knot span of the function, with one-sided
 * values at both ends of each span so jumps stay jumps. */
static bool sample_kappa(series *se, size_t budget) {
  const km_fn *f = &se->sig->kappa;
  double L = se->sig->length;
  if (!(L > 0) || f->n == 0) return true;
  size_t spans = 0;
  for (size_t i = (size_t)f->degree; i < f->n; i++)
    if (f->knots[i + 1] > f->knots[i]) spans++;
  size_t per = spans ? budget / spans : 2;
  if (per < 2) per = 2;
  size_t cap = spans * (per + 1) + 2;
  if (spans > 4000) cap = 4002;
  se->x = malloc(cap * sizeof *se->x);
  se->y = malloc(cap * sizeof *se->y);
  if (!se->x || !se->y) return false;
  size_t m = 0;
  if (spans > 4000) {
    double a, b;
    km_fn_domain(f, &a, &b);
    for (size_t k = 0; k <= 4000; k++) {
      double s = a + (b - a) * (double)k / 4000.0;
      se->x[m] = s / L;
      se->y[m++] = km_fn_value(f, s);
    }
  } else {
    for (size_t i = (size_t)f->degree; i < f->n; i++) {
      double a = f->knots[i], b = f->knots[i + 1];
      if (!(b > a)) continue;
      for (size_t k = 0; k <= per; k++) {
        double s = a + (b - a) * (double)k / (double)per;
        /* The left limit at the span's end. */
        if (k == per) s = b - 1e-9 * (b - a);
        se->x[m] = s / L;
        se->y[m++] = km_fn_value(f, s);
      }
    }
  }
  se->n = m;
  return true;
}

static double nice_step(double range) {
  if (!(range > 0)) return 1.0;
  double raw = range / 5.0;
  double p = pow(10.0, floor(log10(raw)));
  double m = raw / p;
  return (m < 1.5 ? 1 : m < 3.5 ? 2 : m < 7.5 ? 5 : 10) * p;
}

static void curvature_plot(ctx *c, const api_svg_options *o) {
  c->W = o->width > 0 ? o->width : 640.0;
  c->H = o->height > 0 ? o->height : 400.0;
  char title[80];
  snprintf(title, sizeof title, "kmorph curvature plot of %zu frames", c->n);
  doc_open(c, title);
  series *se = calloc(c->n ? c->n : 1, sizeof *se);
  double *all = NULL;
  if (!se) {
    c->b.failed = true;
    return;
  }
  size_t total = 0;
  /* Samples per frame: smooth curves for a few frames, a bounded document
   * for many. */
  size_t budget = 400000 / c->n;
  if (budget > 1600) budget = 1600;
  if (budget < 100) budget = 100;
  for (size_t i = 0; i < c->n; i++) {
    km_signature_init(&se[i].own);
    se[i].sig = c->f[i].sig;
    if (!se[i].sig && c->f[i].curve) {
      /* A frame without its signature: compute it, or leave it out. */
      if (km_signature_compute(c->f[i].curve, 0, &se[i].own, NULL) == KM_OK) {
        se[i].has_own = true;
        se[i].sig = &se[i].own;
      }
    }
    if (se[i].sig && !sample_kappa(&se[i], budget)) c->b.failed = true;
    total += se[i].n;
  }
  /* The range shown: all of kappa and zero, unless a few samples near a
   * degenerate leg (kappa ~ 1/sqrt(s)) would flatten everything else;
   * then the central 98 % with a margin, clipped and said so. */
  double lo = 0, hi = 0;
  bool clipped = false;
  all = malloc((total ? total : 1) * sizeof *all);
  if (!all) c->b.failed = true;
  if (all && total) {
    size_t m = 0;
    for (size_t i = 0; i < c->n; i++)
      for (size_t k = 0; k < se[i].n; k++)
        if (isfinite(se[i].y[k])) all[m++] = se[i].y[k];
    if (m) {
      qsort(all, m, sizeof *all, cmp_double);
      double mn = all[0], mx = all[m - 1];
      double p1 = all[m / 100], p99 = all[m - 1 - m / 100];
      lo = fmin(mn, 0);
      hi = fmax(mx, 0);
      if (p99 > p1 && (mx - mn) > 4 * (p99 - p1)) {
        double mg = 0.25 * (p99 - p1);
        lo = fmin(fmax(mn, p1 - mg), 0);
        hi = fmax(fmin(mx, p99 + mg), 0);
        clipped = true;
      }
    }
  }
  if (!(hi > lo)) {
    hi = lo + 1;
  }
  double step = nice_step(hi - lo);
  lo = floor(lo / step) * step;
  hi = ceil(hi / step) * step;
  if (!(hi > lo)) hi = lo + step;

  bool legend_list = c->n <= 12;
  double ml = 64, mr = legend_list ? 100 : 16, mt = 16, mb = legend_list ? 48 : 72;
  double pw = fmax(c->W - ml - mr, 10), ph = fmax(c->H - mt - mb, 10);
#define PX(u) (ml + (u)*pw)
#define PY(v) (mt + (hi - (v)) / (hi - lo) * ph)
  /* Axes frame, ticks and grid. */
  api__svg_buf_put(&c->b, "<defs><clipPath id=\"km-plot\"><rect x=\"");
  num(c, ml);
  api__svg_buf_put(&c->b, "\" y=\"");
  num(c, mt);
  api__svg_buf_put(&c->b, "\" width=\"");
  num(c, pw);
  api__svg_buf_put(&c->b, "\" height=\"");
  num(c, ph);
  api__svg_buf_put(&c->b, "\"/></clipPath></defs>\n<g " FONT
                          " font-size=\"11\" fill=\"#333333\">\n");
  for (int k = 0; k <= 4; k++) {
    double u = k / 4.0;
    api__svg_buf_put(&c->b, "<line x1=\"");
    num(c, PX(u));
    api__svg_buf_put(&c->b, "\" y1=\"");
    num(c, mt);
    api__svg_buf_put(&c->b, "\" x2=\"");
    num(c, PX(u));
    api__svg_buf_put(&c->b, "\" y2=\"");
    num(c, mt + ph + 4);
    api__svg_buf_put(&c->b, "\" stroke=\"#e0e0e0\"/>\n<text x=\"");
    num(c, PX(u));
    api__svg_buf_put(&c->b, "\" y=\"");
    num(c, mt + ph + 16);
    api__svg_buf_printf(&c->b, "\" text-anchor=\"middle\">%g</text>\n", u);
  }
  size_t nt = (size_t)llround((hi - lo) / step);
  for (size_t k = 0; k <= nt && k <= 40; k++) {
    double v = lo + step * (double)k;
    if (fabs(v) < 1e-9 * step) v = 0;
    api__svg_buf_put(&c->b, "<line x1=\"");
    num(c, ml - 4);
    api__svg_buf_put(&c->b, "\" y1=\"");
    num(c, PY(v));
    api__svg_buf_put(&c->b, "\" x2=\"");
    num(c, ml + pw);
    api__svg_buf_put(&c->b, "\" y2=\"");
    num(c, PY(v));
    api__svg_buf_put(&c->b, v == 0 ? "\" stroke=\"#888888\"/>\n<text x=\""
                                   : "\" stroke=\"#e0e0e0\"/>\n<text x=\"");
    num(c, ml - 6);
    api__svg_buf_put(&c->b, "\" y=\"");
    num(c, PY(v) + 4);
    api__svg_buf_printf(&c->b, "\" text-anchor=\"end\">%.4g</text>\n", v);
  }
  api__svg_buf_put(&c->b, "<rect x=\"");
  num(c, ml);
  api__svg_buf_put(&c->b, "\" y=\"");
  num(c, mt);
  api__svg_buf_put(&c->b, "\" width=\"");
  num(c, pw);
  api__svg_buf_put(&c->b, "\" height=\"");
  num(c, ph);
  api__svg_buf_put(&c->b, "\" fill=\"none\" stroke=\"#333333\"/>\n<text x=\"");
  num(c, ml + 0.5 * pw);
  api__svg_buf_put(&c->b, "\" y=\"");
  num(c, mt + ph + 34);
  api__svg_buf_put(&c->b, "\" text-anchor=\"middle\" font-size=\"12\">"
                          "normalised arc length s/L</text>\n<text x=\"14\" "
                          "y=\"");
  num(c, mt + 0.5 * ph);
  api__svg_buf_put(&c->b, "\" text-anchor=\"middle\" font-size=\"12\" "
                          "transform=\"rotate(-90 14 ");
  num(c, mt + 0.5 * ph);
  api__svg_buf_put(&c->b, clipped ? ")\">curvature \xce\xba (clipped)</text>\n"
                                  : ")\">curvature \xce\xba</text>\n");
  api__svg_buf_put(&c->b, "</g>\n<g clip-path=\"url(#km-plot)\" fill=\"none\" "
                          "stroke-linejoin=\"round\">\n");
  for (size_t i = 0; i < c->n; i++) {
    if (!se[i].n) continue;
    char col[8];
    frame_colour(c, i, col);
    api__svg_buf_put(&c->b, "<path stroke=\"");
    api__svg_buf_put(&c->b, col);
    api__svg_buf_put(&c->b, "\" stroke-width=\"");
    num(c, c->sw);
    api__svg_buf_put(&c->b, "\" d=\"M");
    for (size_t k = 0; k < se[i].n; k++) {
      /* Clipped samples are drawn at the edge, not at infinity. */
      double y = se[i].y[k];
      if (!isfinite(y)) y = 0;
      y = fmin(fmax(y, lo - 0.1 * (hi - lo)), hi + 0.1 * (hi - lo));
      if (k) api__svg_buf_put(&c->b, k == 1 ? "L" : " ");
      num(c, PX(se[i].x[k]));
      api__svg_buf_put(&c->b, ",");
      num(c, PY(y));
    }
    api__svg_buf_put(&c->b, "\"/>\n");
    /* Corners: tangent jumps as vertical ticks at their s/L from the zero
     * line, up for a left turn, length growing with |turn|. */
    const km_signature *sg = se[i].sig;
    double y0 = PY(fmin(fmax(0.0, lo), hi));
    for (size_t k = 0; k < sg->ncorners; k++) {
      double u = sg->corners[k].s / sg->length, turn = sg->corners[k].turn;
      if (!isfinite(u) || !isfinite(turn)) continue;
      double len = 6 + 30 * fabs(turn) / 3.141592653589793;
      api__svg_buf_put(&c->b, "<line stroke=\"");
      api__svg_buf_put(&c->b, col);
      api__svg_buf_put(&c->b, "\" stroke-width=\"");
      num(c, c->sw);
      api__svg_buf_put(&c->b, "\" x1=\"");
      num(c, PX(u));
      api__svg_buf_put(&c->b, "\" y1=\"");
      num(c, y0);
      api__svg_buf_put(&c->b, "\" x2=\"");
      num(c, PX(u));
      api__svg_buf_put(&c->b, "\" y2=\"");
      num(c, y0 - (turn > 0 ? len : -len));
      api__svg_buf_printf(&c->b, "\"><title>corner: turn %.6g rad at s/L = "
                                 "%.6g</title></line>\n",
                          turn, u);
    }
  }
  api__svg_buf_put(&c->b, "</g>\n");
  /* Legend: the t of every frame, or a colour ramp for many frames. */
  if (legend_list) {
    for (size_t i = 0; i < c->n; i++) {
      char col[8];
      frame_colour(c, i, col);
      double y = mt + 8 + 16 * (double)i;
      api__svg_buf_put(&c->b, "<line x1=\"");
      num(c, c->W - mr + 10);
      api__svg_buf_put(&c->b, "\" y1=\"");
      num(c, y);
      api__svg_buf_put(&c->b, "\" x2=\"");
      num(c, c->W - mr + 30);
      api__svg_buf_put(&c->b, "\" y2=\"");
      num(c, y);
      api__svg_buf_put(&c->b, "\" stroke-width=\"3\" stroke=\"");
      api__svg_buf_put(&c->b, col);
      api__svg_buf_put(&c->b, "\"/>\n<text x=\"");
      num(c, c->W - mr + 34);
      api__svg_buf_put(&c->b, "\" y=\"");
      num(c, y + 4);
      api__svg_buf_put(&c->b, "\" " FONT " font-size=\"11\" fill=\"#333333\">");
      t_label(c, c->f[i].t);
      if (!se[i].n) api__svg_buf_put(&c->b, " (no signature)");
      api__svg_buf_put(&c->b, "</text>\n");
    }
  } else {
    ramp_legend(c, ml, c->H - 10, pw);
  }
#undef PX
#undef PY
  for (size_t i = 0; i < c->n; i++) {
    free(se[i].x);
    free(se[i].y);
    if (se[i].has_own) km_signature_free(&se[i].own);
  }
  free(se);
  free(all);
}

char *api_svg_morph_document(const api_svg_frame *frames, size_t n,
                             const api_svg_options *opt) {
  api_svg_options o;
  if (opt) o = *opt;
  else {
    memset(&o, 0, sizeof o);
    o.layout = API_SVG_FILMSTRIP;
  }
  /* Absurd sizes would make documents no renderer can allocate. */
  if (!(o.width <= 1e5)) o.width = 0;
  if (!(o.height <= 1e5)) o.height = 0;
  ctx c;
  memset(&c, 0, sizeof c);
  api__svg_buf_init(&c.b);
  c.f = frames;
  c.n = frames ? n : 0;
  c.sw = o.stroke_width > 0 && o.stroke_width < 1e3 ? o.stroke_width : 1.5;
  c.stroke = colour_or(o.stroke, DEF_STROKE);
  c.from_s = colour_or(o.from_color, DEF_FROM);
  c.to_s = colour_or(o.to_color, DEF_TO);
  if (!parse_hex(c.from_s, &c.from)) parse_hex(DEF_FROM, &c.from);
  if (!parse_hex(c.to_s, &c.to)) parse_hex(DEF_TO, &c.to);
  if (c.n == 0) {
    c.W = o.width > 0 ? o.width : 200;
    c.H = o.height > 0 ? o.height : 40;
    doc_open(&c, "kmorph: no frames");
    api__svg_buf_put(&c.b, "<text x=\"10\" y=\"24\" " FONT
                           " font-size=\"12\">no frames</text>\n");
  } else {
    switch (o.layout) {
    case API_SVG_OVERLAY: overlay(&c, &o); break;
    case API_SVG_ANIMATE: animate(&c, &o); break;
    case API_SVG_CURVATURE_PLOT: curvature_plot(&c, &o); break;
    case API_SVG_FILMSTRIP:
    default: filmstrip(&c, &o); break;
    }
  }
  api__svg_buf_put(&c.b, "</svg>\n");
  return api__svg_buf_take(&c.b);
}
