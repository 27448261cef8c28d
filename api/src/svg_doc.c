/* svg_doc.c - SVG documents of morph results: the document around a
 * layout (filmstrip, overlay, animation and curvature plot, in
 * svg_frames.c and svg_curvature_plot.c) and what the layouts draw with.
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
#include <string.h>

#include "internal.h"
#include "km/alloc.h"
#include "km/limits.h"
#include "svg_doc.h"

#define DEF_FROM "#2166ac"
#define DEF_TO "#b2182b"
#define DEF_STROKE "#1a1a1a"

static void bbox_add(api_svg_bbox *b, double x, double y) {
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

/* Deepest halving of a piece whose control polygon still leaves the box. */
#define BOX_DEPTH 10

/* Box of the control points of a Bezier piece (homogeneous x w, y w, w;
 * weights are positive, so the piece lies in their hull). */
static void hull_box(const double (*h)[3], int p, double box[4]) {
  box[0] = box[2] = h[0][0] / h[0][2];
  box[1] = box[3] = h[0][1] / h[0][2];
  for (int k = 1; k <= p; k++) {
    double x = h[k][0] / h[k][2], y = h[k][1] / h[k][2];
    box[0] = fmin(box[0], x);
    box[1] = fmin(box[1], y);
    box[2] = fmax(box[2], x);
    box[3] = fmax(box[3], y);
  }
}

/* Grow *b to hold a Bezier piece (homogeneous points h[0..p]). Its end
 * points are on the trace; where its control polygon's box leaves *b by
 * more than slack, the piece is halved (de Casteljau) and each half looked
 * at again, so the box is the trace's to within slack (or, past BOX_DEPTH
 * halvings, the polygon's, which holds the trace). */
static void piece_bbox(const double (*h)[3], int p, int depth, double slack,
                       api_svg_bbox *b) {
  bbox_add(b, h[0][0] / h[0][2], h[0][1] / h[0][2]);
  bbox_add(b, h[p][0] / h[p][2], h[p][1] / h[p][2]);
  double hb[4];
  hull_box(h, p, hb);
  if (hb[0] >= b->x0 - slack && hb[1] >= b->y0 - slack &&
      hb[2] <= b->x1 + slack && hb[3] <= b->y1 + slack)
    return;
  if (depth >= BOX_DEPTH || !(hb[2] - hb[0] + hb[3] - hb[1] > slack)) {
    bbox_add(b, hb[0], hb[1]);
    bbox_add(b, hb[2], hb[3]);
    return;
  }
  double l[KM_MAX_DEGREE + 1][3], r[KM_MAX_DEGREE + 1][3],
      q[KM_MAX_DEGREE + 1][3];
  memcpy(q, h, (size_t)(p + 1) * sizeof *q);
  for (int j = 0; j <= p; j++) {
    memcpy(l[j], q[0], sizeof q[0]);
    memcpy(r[p - j], q[p - j], sizeof q[0]);
    for (int k = 0; k < p - j; k++)
      for (int d = 0; d < 3; d++) q[k][d] = 0.5 * (q[k][d] + q[k + 1][d]);
  }
  piece_bbox((const double(*)[3])l, p, depth + 1, slack, b);
  piece_bbox((const double(*)[3])r, p, depth + 1, slack, b);
}

/* The blossom of span i of c (knots[i] <= knots[i+1]) at x[0 .. p), in
 * homogeneous coordinates: de Boor's scheme with x[r - 1] at level r. */
static void span_blossom(const km_curve *c, size_t i, const double *x,
                         double out[3]) {
  int p = c->degree;
  double d[KM_MAX_DEGREE + 1][3];
  for (int k = 0; k <= p; k++) {
    size_t j = i - (size_t)p + (size_t)k;
    double w = c->w ? c->w[j] : 1.0;
    d[k][0] = c->cp[2 * j] * w;
    d[k][1] = c->cp[2 * j + 1] * w;
    d[k][2] = w;
  }
  for (int r = 1; r <= p; r++)
    for (int k = p; k >= r; k--) {
      double lo = c->knots[i - (size_t)p + (size_t)k],
             hi = c->knots[i + 1 + (size_t)k - (size_t)r];
      double al = hi > lo ? (x[r - 1] - lo) / (hi - lo) : 0.0;
      for (int q = 0; q < 3; q++)
        d[k][q] = (1 - al) * d[k - 1][q] + al * d[k][q];
    }
  memcpy(out, d[p], sizeof d[p]);
}

/* Bounding box of a curve's trace to within 1e-6 of its control box: each
 * knot span as a Bezier piece (its control points the blossom's values at
 * a^(p-j) b^j), the pieces' end points, and their control polygons halved
 * where they leave the box (sampling would cut corners off and costs
 * thousands of evaluations a frame). Nothing is allocated. */
static void curve_bbox(const km_curve *c, api_svg_bbox *b) {
  if (!c || c->n == 0 || c->degree < 1 || c->degree > KM_MAX_DEGREE) return;
  int p = c->degree;
  double cb[4] = {INFINITY, INFINITY, -INFINITY, -INFINITY};
  for (size_t j = 0; j < c->n; j++) {
    cb[0] = fmin(cb[0], c->cp[2 * j]);
    cb[1] = fmin(cb[1], c->cp[2 * j + 1]);
    cb[2] = fmax(cb[2], c->cp[2 * j]);
    cb[3] = fmax(cb[3], c->cp[2 * j + 1]);
  }
  double slack = 1e-6 * fmax(cb[2] - cb[0], cb[3] - cb[1]);
  /* the curve's ends first (clamped: its first and last control points) */
  bbox_add(b, c->cp[0], c->cp[1]);
  bbox_add(b, c->cp[2 * (c->n - 1)], c->cp[2 * (c->n - 1) + 1]);
  for (size_t i = (size_t)p; i < c->n; i++) {
    double lo = c->knots[i], hi = c->knots[i + 1];
    if (!(hi > lo)) continue;
    double h[KM_MAX_DEGREE + 1][3], x[KM_MAX_DEGREE];
    for (int j = 0; j <= p; j++) {
      for (int k = 0; k < p; k++) x[k] = k < p - j ? lo : hi;
      span_blossom(c, i, x, h[j]);
    }
    piece_bbox((const double(*)[3])h, p, 0, slack, b);
  }
}

/* "#rgb" or "#rrggbb". */
static bool parse_hex(const char *s, api_svg_rgb *out) {
  if (!s || s[0] != '#') return false;
  size_t n = strlen(s + 1);
  int v[6];
  if (n != 3 && n != 6) return false;
  for (size_t i = 0; i < n; i++)
    if ((v[i] = api__hexval(s[1 + i])) < 0) return false;
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

static void ramp(const api_svg_rgb *a, const api_svg_rgb *b, double f,
                 char out[8]) {
  if (!(f >= 0)) f = 0;
  if (f > 1) f = 1;
  int r = (int)lround(a->r + (b->r - a->r) * f);
  int g = (int)lround(a->g + (b->g - a->g) * f);
  int bl = (int)lround(a->b + (b->b - a->b) * f);
  snprintf(out, 8, "#%02x%02x%02x", r & 255, g & 255, bl & 255);
}

void api__svg_px(api_svg_doc *c, double v) {
  api__svg_buf_num(&c->b, v, API_SVG_PX_BUDGET, NULL);
}

void api__svg_path_open(api_svg_doc *c, double ox, double oy, double s,
                        const api_svg_bbox *bb) {
  api__svg_buf_put(&c->b, "<path transform=\"translate(");
  api__svg_px(c, ox);
  api__svg_buf_put(&c->b, " ");
  api__svg_px(c, oy);
  api__svg_buf_put(&c->b, ") scale(");
  api__svg_buf_num(&c->b, s, 1e-9 * s, NULL);
  api__svg_buf_put(&c->b, ") translate(");
  api__svg_buf_num(&c->b, -bb->x0, 1e-4 / s, NULL);
  api__svg_buf_put(&c->b, " ");
  api__svg_buf_num(&c->b, -bb->y0, 1e-4 / s, NULL);
  api__svg_buf_put(&c->b, ")\"");
}

void api__svg_cell_frame(api_svg_doc *c, double x, double y, double cw,
                         double ch) {
  api__svg_buf_put(&c->b, "<rect x=\"");
  api__svg_px(c, x + 0.5);
  api__svg_buf_put(&c->b, "\" y=\"");
  api__svg_px(c, y + 0.5);
  api__svg_buf_put(&c->b, "\" width=\"");
  api__svg_px(c, fmax(cw - 1, 0));
  api__svg_buf_put(&c->b, "\" height=\"");
  api__svg_px(c, fmax(ch - 1, 0));
  api__svg_buf_put(&c->b, "\" fill=\"none\" stroke=\"#d0d0d0\" "
                          "stroke-width=\"1\"/>\n");
}

void api__svg_frame_colour(const api_svg_doc *c, size_t i, char out[8]) {
  double f = c->n > 1 ? (double)i / (double)(c->n - 1) : 0.0;
  ramp(&c->from, &c->to, f, out);
}

void api__svg_t_label(api_svg_doc *c, double t) {
  char s[40];
  snprintf(s, sizeof s, "t = %.4g", isfinite(t) ? t : 0.0);
  api__svg_buf_escaped(&c->b, s);
}

void api__svg_doc_open(api_svg_doc *c, const char *title) {
  api__svg_buf_put(&c->b, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
                          "<svg xmlns=\"http://www.w3.org/2000/svg\" "
                          "version=\"1.1\" width=\"");
  api__svg_px(c, c->W);
  api__svg_buf_put(&c->b, "\" height=\"");
  api__svg_px(c, c->H);
  api__svg_buf_put(&c->b, "\" viewBox=\"0 0 ");
  api__svg_px(c, c->W);
  api__svg_buf_put(&c->b, " ");
  api__svg_px(c, c->H);
  api__svg_buf_put(&c->b, "\">\n<title>");
  api__svg_buf_escaped(&c->b, title);
  api__svg_buf_put(&c->b, "</title>\n<rect width=\"100%\" height=\"100%\" "
                          "fill=\"#ffffff\"/>\n");
}

/* A frame's curve under transform x -> ox + s (x - bx0), y likewise. */
void api__svg_draw_curve(api_svg_doc *c, const km_curve *cv, double ox,
                         double oy, double s, const api_svg_bbox *bb,
                         const char *colour) {
  char *d = api_svg_path_d(cv, 0.05 / s, NULL);
  if (!d) {
    c->b.failed = true;
    return;
  }
  api__svg_path_open(c, ox, oy, s, bb);
  api__svg_buf_put(&c->b, " fill=\"none\" stroke=\"");
  api__svg_buf_escaped(&c->b, colour);
  api__svg_buf_put(&c->b, "\" stroke-width=\"");
  api__svg_buf_num(&c->b, c->sw / s, 1e-3 * c->sw / s, NULL);
  api__svg_buf_put(&c->b, "\" stroke-linejoin=\"round\" "
                          "stroke-linecap=\"round\" d=\"");
  api__svg_buf_put(&c->b, d);
  api__svg_buf_put(&c->b, "\"/>\n");
  km__free(d);
}

/* Union box of all frames, padded, never empty or flat. */
api_svg_bbox api__svg_frames_bbox(const api_svg_doc *c) {
  api_svg_bbox bb = {0, 0, 0, 0, true};
  for (size_t i = 0; i < c->n; i++) curve_bbox(c->f[i].curve, &bb);
  if (bb.empty) bb = (api_svg_bbox){0, 0, 1, 1, false};
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
double api__svg_fit(const api_svg_bbox *bb, double w, double h, double *ox,
                    double *oy) {
  double bw = bb->x1 - bb->x0, bh = bb->y1 - bb->y0;
  double s = fmin(w / bw, h / bh);
  *ox += 0.5 * (w - s * bw);
  *oy += 0.5 * (h - s * bh);
  return s;
}

/* Horizontal colour bar from the first frame's colour to the last one's,
 * with their t values, across [x, x + w] at height y. */
void api__svg_ramp_legend(api_svg_doc *c, double x, double y, double w) {
  if (c->n == 0) return;
  api__svg_buf_put(&c->b, "<defs><linearGradient id=\"km-ramp\" x1=\"0\" "
                          "y1=\"0\" x2=\"1\" y2=\"0\"><stop offset=\"0\" "
                          "stop-color=\"");
  char a[8], z[8];
  api__svg_frame_colour(c, 0, a);
  api__svg_frame_colour(c, c->n - 1, z);
  api__svg_buf_put(&c->b, a);
  api__svg_buf_put(&c->b, "\"/><stop offset=\"1\" stop-color=\"");
  api__svg_buf_put(&c->b, z);
  api__svg_buf_put(&c->b, "\"/></linearGradient></defs>\n<rect x=\"");
  api__svg_px(c, x + 60);
  api__svg_buf_put(&c->b, "\" y=\"");
  api__svg_px(c, y - 9);
  api__svg_buf_put(&c->b, "\" width=\"");
  api__svg_px(c, fmax(w - 120, 1));
  api__svg_buf_put(&c->b, "\" height=\"8\" fill=\"url(#km-ramp)\"/>\n");
  api__svg_buf_put(&c->b, "<text x=\"");
  api__svg_px(c, x + 55);
  api__svg_buf_put(&c->b, "\" y=\"");
  api__svg_px(c, y);
  api__svg_buf_put(&c->b, "\" " API_SVG_FONT " font-size=\"11\" "
                          "text-anchor=\"end\" fill=\"#333333\">");
  api__svg_t_label(c, c->f[0].t);
  api__svg_buf_put(&c->b, "</text>\n<text x=\"");
  api__svg_px(c, x + w - 55);
  api__svg_buf_put(&c->b, "\" y=\"");
  api__svg_px(c, y);
  api__svg_buf_put(&c->b,
                   "\" " API_SVG_FONT " font-size=\"11\" fill=\"#333333\">");
  api__svg_t_label(c, c->f[c->n - 1].t);
  api__svg_buf_put(&c->b, "</text>\n");
}

void api__svg_doc_init(api_svg_doc *c, const api_svg_options *opt,
                       api_svg_options *o) {
  if (opt)
    *o = *opt;
  else {
    memset(o, 0, sizeof *o);
    o->layout = API_SVG_FILMSTRIP;
  }
  /* Absurd sizes would make documents no renderer can allocate. */
  if (!(o->width <= 1e5)) o->width = 0;
  if (!(o->height <= 1e5)) o->height = 0;
  memset(c, 0, sizeof *c);
  api__svg_buf_init(&c->b);
  c->sw = o->stroke_width > 0 && o->stroke_width < 1e3 ? o->stroke_width : 1.5;
  c->stroke = colour_or(o->stroke, DEF_STROKE);
  c->from_s = colour_or(o->from_color, DEF_FROM);
  c->to_s = colour_or(o->to_color, DEF_TO);
  if (!parse_hex(c->from_s, &c->from)) parse_hex(DEF_FROM, &c->from);
  if (!parse_hex(c->to_s, &c->to)) parse_hex(DEF_TO, &c->to);
}

char *api_svg_morph_document(const api_svg_frame *frames, size_t n,
                             const api_svg_options *opt) {
  api_svg_options o;
  api_svg_doc c;
  api__svg_doc_init(&c, opt, &o);
  c.f = frames;
  c.n = frames ? n : 0;
  if (c.n == 0) {
    c.W = o.width > 0 ? o.width : 200;
    c.H = o.height > 0 ? o.height : 40;
    api__svg_doc_open(&c, "kmorph: no frames");
    api__svg_buf_put(&c.b, "<text x=\"10\" y=\"24\" " API_SVG_FONT
                           " font-size=\"12\">no frames</text>\n");
  } else {
    switch (o.layout) {
    case API_SVG_OVERLAY: api__svg_overlay(&c, &o); break;
    case API_SVG_ANIMATE: api__svg_animate(&c, &o); break;
    case API_SVG_CURVATURE_PLOT: api__svg_curvature_plot(&c, &o); break;
    case API_SVG_FILMSTRIP:
    default: api__svg_filmstrip(&c, &o); break;
    }
  }
  api__svg_buf_put(&c.b, "</svg>\n");
  return api__svg_buf_take(&c.b);
}
