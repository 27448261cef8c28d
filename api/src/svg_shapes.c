/* svg_shapes.c - the SVG document of a compound morph: a filmstrip of
 * cells, each frame's present contours as one filled path under the
 * shapes' fill rule, so that holes show as holes.
 *
 * The cells are laid out as the single-curve filmstrip lays them out
 * (svg_frames.c); the view box is that of the contours' control points,
 * which contain each B-spline (convex hull property, weights > 0).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "km/alloc.h"
#include "svg_doc.h"

/* Box of every present contour's control points, padded, never flat. */
static api_svg_bbox shapes_bbox(const api_svg_shape_frame *f, size_t n) {
  api_svg_bbox bb = {0, 0, 1, 1, true};
  for (size_t i = 0; i < n; i++) {
    const km_shape_frame *sf = f[i].shape;
    for (size_t k = 0; sf != NULL && k < sf->ncontours; k++) {
      const km_curve *c = &sf->contours[k];
      for (size_t j = 0; sf->present[k] && j < c->n; j++) {
        double x = c->cp[2 * j], y = c->cp[2 * j + 1];
        if (bb.empty) {
          bb = (api_svg_bbox){x, y, x, y, false};
          continue;
        }
        bb.x0 = fmin(bb.x0, x);
        bb.y0 = fmin(bb.y0, y);
        bb.x1 = fmax(bb.x1, x);
        bb.y1 = fmax(bb.y1, y);
      }
    }
  }
  double w = bb.x1 - bb.x0, h = bb.y1 - bb.y0, m = fmax(w, h);
  if (!(m > 0)) m = 1;
  /* a flat box gets some height so the scale stays finite */
  double px = 0.05 * m + (w < 1e-3 * m ? 0.5e-3 * m : 0);
  double py = 0.05 * m + (h < 1e-3 * m ? 0.5e-3 * m : 0);
  bb.x0 -= px;
  bb.x1 += px;
  bb.y0 -= py;
  bb.y1 += py;
  return bb;
}

/* One frame's present contours as one path, filled under `rule`. */
static void draw_shape(api_svg_doc *c, const km_shape_frame *sf, double ox,
                       double oy, double s, const api_svg_bbox *bb,
                       const char *rule) {
  api__svg_path_open(c, ox, oy, s, bb);
  api__svg_buf_put(&c->b, " fill=\"");
  api__svg_buf_escaped(&c->b, c->stroke);
  api__svg_buf_put(&c->b, "\" fill-opacity=\"0.35\" fill-rule=\"");
  api__svg_buf_put(&c->b, rule);
  api__svg_buf_put(&c->b, "\" stroke=\"");
  api__svg_buf_escaped(&c->b, c->stroke);
  api__svg_buf_put(&c->b, "\" stroke-width=\"");
  api__svg_buf_num(&c->b, c->sw / s, 1e-3 * c->sw / s, NULL);
  api__svg_buf_put(&c->b, "\" stroke-linejoin=\"round\" d=\"");
  for (size_t k = 0, drawn = 0; k < sf->ncontours; k++) {
    if (!sf->present[k]) continue;
    char *d = api_svg_path_d(&sf->contours[k], 0.05 / s, NULL);
    if (d == NULL) {
      c->b.failed = true;
      return;
    }
    if (drawn++ > 0) api__svg_buf_put(&c->b, " ");
    api__svg_buf_put(&c->b, d);
    km__free(d);
  }
  api__svg_buf_put(&c->b, "\"/>\n");
}

/* Cell i of a filmstrip of cols columns and cw x ch px cells. */
static void cell(api_svg_doc *c, const api_svg_shape_frame *f, size_t i,
                 size_t cols, double cw, double ch, const api_svg_bbox *bb) {
  const char *rule = f[i].fill == KM_FILL_EVENODD ? "evenodd" : "nonzero";
  const double label = 20.0;
  double x = cw * (double)(i % cols), y = ch * (double)(i / cols);
  api__svg_cell_frame(c, x, y, cw, ch);
  double ox = x + 4, oy = y + 4;
  double s =
      api__svg_fit(bb, fmax(cw - 8, 1), fmax(ch - label - 8, 1), &ox, &oy);
  if (f[i].shape != NULL) draw_shape(c, f[i].shape, ox, oy, s, bb, rule);
  api__svg_buf_put(&c->b, "<text x=\"");
  api__svg_px(c, x + 0.5 * cw);
  api__svg_buf_put(&c->b, "\" y=\"");
  api__svg_px(c, y + ch - 6);
  api__svg_buf_put(&c->b, "\" " API_SVG_FONT " font-size=\"12\" "
                          "text-anchor=\"middle\" fill=\"#333333\">");
  api__svg_t_label(c, f[i].t);
  api__svg_buf_put(&c->b, "</text>\n");
}

char *api_svg_shape_document(const api_svg_shape_frame *frames, size_t n,
                             const api_svg_options *o) {
  api_svg_doc c;
  api_svg_options def;
  char title[96];
  if (o == NULL) {
    memset(&def, 0, sizeof def);
    o = &def;
  }
  memset(&c, 0, sizeof c);
  api__svg_buf_init(&c.b);
  c.n = frames != NULL ? n : 0;
  c.sw = o->stroke_width > 0 && o->stroke_width < 1e3 ? o->stroke_width : 1.5;
  c.stroke = o->stroke != NULL ? o->stroke : "#1a1a1a";
  api_svg_bbox bb = shapes_bbox(frames, c.n);
  double aspect = fmin(fmax((bb.y1 - bb.y0) / (bb.x1 - bb.x0), 0.25), 4);
  size_t cnt = c.n ? c.n : 1;
  size_t cols = (size_t)ceil(sqrt(1.6 * (double)cnt / aspect));
  cols = cols < 1 ? 1 : cols > cnt ? cnt : cols;
  size_t rows = (cnt + cols - 1) / cols;
  double cw = o->width > 0 && o->width <= 1e5 ? o->width / (double)cols : 160.0;
  double ch = o->height > 0 && o->height <= 1e5 ? o->height / (double)rows
                                                : cw * aspect + 20.0;
  c.W = ceil(cw * (double)cols);
  c.H = ceil(ch * (double)rows);
  snprintf(title, sizeof title, "kmorph filmstrip of %zu frames of shapes",
           c.n);
  api__svg_doc_open(&c, title);
  for (size_t i = 0; i < c.n; i++) cell(&c, frames, i, cols, cw, ch, &bb);
  api__svg_buf_put(&c.b, "</svg>\n");
  return api__svg_buf_take(&c.b);
}

char *api_svg_point_d(const double p[2], size_t n_pieces) {
  api_svg_buf b;
  double ext = fmax(fabs(p[0]), fabs(p[1]));
  /* the budget api_svg_path_d_fixed_z gives a curve of this extent */
  double budget = 1e-6 * (ext > 0 ? ext : 1.0);
  api__svg_buf_init(&b);
  if (n_pieces < 1) n_pieces = 1;
  api__svg_buf_put(&b, "M");
  for (size_t i = 0; i <= 3 * n_pieces; i++) {
    if (i > 0) api__svg_buf_put(&b, i == 1 ? "C" : " ");
    api__svg_buf_num(&b, p[0], budget, NULL);
    api__svg_buf_put(&b, ",");
    api__svg_buf_num(&b, p[1], budget, NULL);
  }
  api__svg_buf_put(&b, " Z");
  return api__svg_buf_take(&b);
}

char *api_svg_shape_frame_d(const km_shape_frame *sf, const size_t *pieces,
                            const double *collapse) {
  api_svg_buf b;
  api__svg_buf_init(&b);
  for (size_t k = 0; k < sf->ncontours && !b.failed; k++) {
    const double *p = collapse + 2 * k;
    char *d = NULL;
    if (sf->present[k])
      d = api_svg_path_d_fixed_z(&sf->contours[k], pieces[k], true);
    else if (isfinite(p[0]) && isfinite(p[1]))
      d = api_svg_point_d(p, pieces[k]);
    else
      continue;
    if (d == NULL) {
      b.failed = true;
      break;
    }
    if (b.len > 0) api__svg_buf_put(&b, " ");
    api__svg_buf_put(&b, d);
    km__free(d);
  }
  return api__svg_buf_take(&b);
}
