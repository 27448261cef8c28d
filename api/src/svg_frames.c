/* svg_frames.c - the layouts that draw the frames' curves: a filmstrip of
 * cells, an overlay of every frame in one box along the colour ramp, and
 * an animation whose frames share one command structure (uniform in arc
 * length) so that SMIL can interpolate between them.
 */
#include <math.h>
#include <stdio.h>

#include "km/alloc.h"
#include "svg_doc.h"

void api__svg_filmstrip(api_svg_doc *c, const api_svg_options *o) {
  api_svg_bbox bb = api__svg_frames_bbox(c);
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
  if (o->height > 0)
    ch = o->height / (double)rows;
  else if (o->width > 0)
    ch = cw * aspect + label;
  /* Automatic sizes are whole pixels: renderers round them up anyway. */
  c->W = o->width > 0 ? o->width : ceil(cw * (double)cols);
  c->H = o->height > 0 ? o->height : ceil(ch * (double)rows);
  char title[80];
  snprintf(title, sizeof title, "kmorph filmstrip of %zu frames", c->n);
  api__svg_doc_open(c, title);
  const char *stroke = c->stroke;
  for (size_t i = 0; i < c->n; i++) {
    size_t r = i / cols, k = i % cols;
    double x = cw * (double)k, y = ch * (double)r;
    api__svg_cell_frame(c, x, y, cw, ch);
    double ox = x + 4, oy = y + 4;
    double dw = fmax(cw - 8, 1), dh = fmax(ch - label - 8, 1);
    double s = api__svg_fit(&bb, dw, dh, &ox, &oy);
    if (c->f[i].curve)
      api__svg_draw_curve(c, c->f[i].curve, ox, oy, s, &bb, stroke);
    api__svg_buf_put(&c->b, "<text x=\"");
    api__svg_px(c, x + 0.5 * cw);
    api__svg_buf_put(&c->b, "\" y=\"");
    api__svg_px(c, y + ch - 6);
    api__svg_buf_put(&c->b, "\" " API_SVG_FONT " font-size=\"12\" "
                            "text-anchor=\"middle\" fill=\"#333333\">");
    api__svg_t_label(c, c->f[i].t);
    api__svg_buf_put(&c->b, "</text>\n");
  }
}

/* One panel holding every frame's box, with a band of `band` pixels below
 * it: the document sized (the asked size, else default_width wide and as
 * tall as the frames' aspect wants, within 1:4 and 4:1) and opened, and
 * the scale and offset that fit the frames into the panel. */
static double open_panel(api_svg_doc *c, const api_svg_options *o,
                         double default_width, double band, const char *kind,
                         api_svg_bbox *bb, double *ox, double *oy) {
  *bb = api__svg_frames_bbox(c);
  double aspect = (bb->y1 - bb->y0) / (bb->x1 - bb->x0);
  double w = o->width > 0 ? o->width : default_width;
  double h =
      o->height > 0 ? o->height : ceil(w * fmin(fmax(aspect, 0.25), 4) + band);
  c->W = w;
  c->H = h;
  char title[80];
  snprintf(title, sizeof title, "kmorph %s of %zu frames", kind, c->n);
  api__svg_doc_open(c, title);
  *ox = 6;
  *oy = 6;
  return api__svg_fit(bb, fmax(w - 12, 1), fmax(h - band - 12, 1), ox, oy);
}

void api__svg_overlay(api_svg_doc *c, const api_svg_options *o) {
  api_svg_bbox bb;
  double ox, oy;
  double s = open_panel(c, o, 480.0, 24.0, "overlay", &bb, &ox, &oy);
  double w = c->W, h = c->H;
  for (size_t i = 0; i < c->n; i++) {
    char col[8];
    api__svg_frame_colour(c, i, col);
    if (c->f[i].curve)
      api__svg_draw_curve(c, c->f[i].curve, ox, oy, s, &bb, col);
  }
  api__svg_ramp_legend(c, 0, h - 8, w);
}

/* Pieces for the animation: enough for the most detailed frame, bounded
 * so that a long morph stays a reasonable document. */
static size_t animate_pieces(const api_svg_doc *c) {
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

/* Every frame's path of np pieces (NULL for a frame without a curve), Z
 * written for all frames or for none, so that they share one command
 * structure; *drawn counts them. NULL when no frame has a curve, or out
 * of memory (then c->b.failed); the caller frees each path and the
 * array. */
static char **animate_paths(api_svg_doc *c, size_t np, size_t *drawn) {
  bool all_closed = c->n > 0;
  char **ds;
  *drawn = 0;
  for (size_t i = 0; i < c->n; i++)
    if (c->f[i].curve) {
      (*drawn)++;
      if (!c->f[i].curve->closed) all_closed = false;
    }
  if (*drawn == 0) return NULL;
  ds = km__calloc(c->n, sizeof *ds);
  if (!ds) {
    c->b.failed = true;
    return NULL;
  }
  for (size_t i = 0; i < c->n; i++) {
    if (!c->f[i].curve) continue;
    ds[i] = api_svg_path_d_fixed_z(c->f[i].curve, np, all_closed);
    if (!ds[i]) c->b.failed = true;
  }
  return ds;
}

/* The animated <path>, drawn as the first frame under the layout's
 * transform until its <animate> starts, which this opens for its dur. */
static void animate_open(api_svg_doc *c, const api_svg_bbox *bb, double ox,
                         double oy, double s, const char *first, double dur) {
  api__svg_path_open(c, ox, oy, s, bb);
  api__svg_buf_put(&c->b, " fill=\"none\" stroke=\"");
  api__svg_buf_escaped(&c->b, c->stroke);
  api__svg_buf_put(&c->b, "\" stroke-width=\"");
  api__svg_buf_num(&c->b, c->sw / s, 1e-3 * c->sw / s, NULL);
  api__svg_buf_put(&c->b, "\" stroke-linejoin=\"round\" d=\"");
  api__svg_buf_put(&c->b, first);
  api__svg_buf_put(&c->b, "\">\n<animate attributeName=\"d\" dur=\"");
  api__svg_buf_num(&c->b, dur, 1e-4, NULL);
  api__svg_buf_put(&c->b, "s\" repeatCount=\"indefinite\" "
                          "calcMode=\"linear\"");
}

/* keyTimes place frames at their t when the times increase; *tfirst and
 * *tlast receive the first and last drawn frames' t. */
static void animate_key_times(api_svg_doc *c, char *const *ds, size_t drawn,
                              double *tfirst, double *tlast) {
  bool increasing = drawn >= 2;
  double prev = -INFINITY;
  *tfirst = NAN;
  *tlast = NAN;
  for (size_t i = 0; i < c->n; i++) {
    if (!ds[i]) continue;
    double t = c->f[i].t;
    if (!isfinite(t) || !(t > prev)) increasing = false;
    if (isnan(*tfirst)) *tfirst = t;
    *tlast = t;
    prev = t;
  }
  if (!(increasing && *tlast > *tfirst)) return;
  api__svg_buf_put(&c->b, " keyTimes=\"");
  size_t k = 0;
  for (size_t i = 0; i < c->n; i++) {
    if (!ds[i]) continue;
    double kt = (c->f[i].t - *tfirst) / (*tlast - *tfirst);
    if (k == 0) kt = 0;
    if (k + 1 == drawn) kt = 1;
    if (k) api__svg_buf_put(&c->b, ";");
    api__svg_buf_num(&c->b, kt, 1e-6, NULL);
    k++;
  }
  api__svg_buf_put(&c->b, "\"");
}

/* The frames' paths as the animation's values; the <animate> and the
 * <path> closed. */
static void animate_values(api_svg_doc *c, char *const *ds, size_t drawn,
                           const char *first) {
  size_t k = 0;
  api__svg_buf_put(&c->b, " values=\"");
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
  api__svg_buf_put(&c->b, "\"/>\n</path>\n");
}

/* "t = first ... last" under the animation, of a w x h document. */
static void animate_label(api_svg_doc *c, double w, double h, double tfirst,
                          double tlast) {
  char s[80];
  api__svg_buf_put(&c->b, "<text x=\"");
  api__svg_px(c, 0.5 * w);
  api__svg_buf_put(&c->b, "\" y=\"");
  api__svg_px(c, h - 6);
  api__svg_buf_put(&c->b, "\" " API_SVG_FONT " font-size=\"12\" "
                          "text-anchor=\"middle\" fill=\"#333333\">");
  snprintf(s, sizeof s, "t = %.4g \xe2\x80\xa6 %.4g",
           isfinite(tfirst) ? tfirst : 0.0, isfinite(tlast) ? tlast : 0.0);
  api__svg_buf_escaped(&c->b, s);
  api__svg_buf_put(&c->b, "</text>\n");
}

void api__svg_animate(api_svg_doc *c, const api_svg_options *o) {
  api_svg_bbox bb;
  double ox, oy;
  double s = open_panel(c, o, 400.0, 20.0, "animation", &bb, &ox, &oy);
  double w = c->W, h = c->H;
  size_t drawn = 0;
  char **ds = animate_paths(c, animate_pieces(c), &drawn);
  if (!ds) return;
  if (!c->b.failed) {
    const char *first = NULL;
    double dur = o->duration > 0 && isfinite(o->duration) ? o->duration : 2.0;
    double tfirst, tlast;
    for (size_t i = 0; i < c->n && !first; i++) first = ds[i];
    animate_open(c, &bb, ox, oy, s, first, dur);
    animate_key_times(c, ds, drawn, &tfirst, &tlast);
    animate_values(c, ds, drawn, first);
    animate_label(c, w, h, tfirst, tlast);
  }
  for (size_t i = 0; i < c->n; i++) km__free(ds[i]);
  km__free(ds);
}
