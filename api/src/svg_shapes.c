/* svg_shapes.c - the SVG documents of a compound morph: a filmstrip of
 * cells, an overlay along the colour ramp, an animation and a curvature
 * plot; every frame's contours filled as one path under the shapes' fill
 * rule, so that holes show as holes.
 *
 * The layouts are those of single curves (svg_frames.c,
 * svg_curvature_plot.c) with a frame's contours in place of its curve; the
 * view box is that of the contours' control points, which contain each
 * B-spline (convex hull property, weights > 0). The animation keeps one
 * command structure across frames, as animate_d does: a fixed number of
 * pieces per slot, a collapsed contour drawn as that many pieces at its
 * point.
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

static const char *rule_name(km_fill_rule fill) {
  return fill == KM_FILL_EVENODD ? "evenodd" : "nonzero";
}

/* The attributes of a filled shape's path after its transform: fill
 * `colour` at `opacity` under `rule`, stroked in it; the d attribute
 * opened. */
static void fill_attrs(api_svg_doc *c, double s, const char *rule,
                       const char *colour, const char *opacity) {
  api__svg_buf_put(&c->b, " fill=\"");
  api__svg_buf_escaped(&c->b, colour);
  api__svg_buf_put(&c->b, "\" fill-opacity=\"");
  api__svg_buf_put(&c->b, opacity);
  api__svg_buf_put(&c->b, "\" fill-rule=\"");
  api__svg_buf_put(&c->b, rule);
  api__svg_buf_put(&c->b, "\" stroke=\"");
  api__svg_buf_escaped(&c->b, colour);
  api__svg_buf_put(&c->b, "\" stroke-width=\"");
  api__svg_buf_num(&c->b, c->sw / s, 1e-3 * c->sw / s, NULL);
  api__svg_buf_put(&c->b, "\" stroke-linejoin=\"round\" d=\"");
}

/* One frame's present contours as one path, filled under its rule. */
static void draw_shape(api_svg_doc *c, const api_svg_shape_frame *f, double ox,
                       double oy, double s, const api_svg_bbox *bb,
                       const char *colour, const char *opacity) {
  const km_shape_frame *sf = f->shape;
  api__svg_path_open(c, ox, oy, s, bb);
  fill_attrs(c, s, rule_name(f->fill), colour, opacity);
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

/* A text of 12 px centred at (x, y). */
static void centred_text(api_svg_doc *c, double x, double y, const char *s) {
  api__svg_buf_put(&c->b, "<text x=\"");
  api__svg_px(c, x);
  api__svg_buf_put(&c->b, "\" y=\"");
  api__svg_px(c, y);
  api__svg_buf_put(&c->b, "\" " API_SVG_FONT " font-size=\"12\" "
                          "text-anchor=\"middle\" fill=\"#333333\">");
  api__svg_buf_escaped(&c->b, s);
  api__svg_buf_put(&c->b, "</text>\n");
}

/* Cell i of a filmstrip of cols columns and cw x ch px cells. */
static void cell(api_svg_doc *c, const api_svg_shape_morph *m, size_t i,
                 size_t cols, double cw, double ch, const api_svg_bbox *bb) {
  const double label = 20.0;
  char t[40];
  double x = cw * (double)(i % cols), y = ch * (double)(i / cols);
  api__svg_cell_frame(c, x, y, cw, ch);
  double ox = x + 4, oy = y + 4;
  double s =
      api__svg_fit(bb, fmax(cw - 8, 1), fmax(ch - label - 8, 1), &ox, &oy);
  if (m->frames[i].shape != NULL)
    draw_shape(c, &m->frames[i], ox, oy, s, bb, c->stroke, "0.35");
  snprintf(t, sizeof t, "t = %.4g",
           isfinite(m->frames[i].t) ? m->frames[i].t : 0.0);
  centred_text(c, x + 0.5 * cw, y + ch - 6, t);
}

static void filmstrip(api_svg_doc *c, const api_svg_shape_morph *m,
                      const api_svg_options *o) {
  char title[96];
  api_svg_bbox bb = shapes_bbox(m->frames, c->n);
  double aspect = fmin(fmax((bb.y1 - bb.y0) / (bb.x1 - bb.x0), 0.25), 4);
  size_t cnt = c->n ? c->n : 1;
  size_t cols = (size_t)ceil(sqrt(1.6 * (double)cnt / aspect));
  cols = cols < 1 ? 1 : cols > cnt ? cnt : cols;
  size_t rows = (cnt + cols - 1) / cols;
  double cw = o->width > 0 ? o->width / (double)cols : 160.0;
  double ch = o->height > 0 ? o->height / (double)rows : cw * aspect + 20.0;
  c->W = ceil(cw * (double)cols);
  c->H = ceil(ch * (double)rows);
  snprintf(title, sizeof title, "kmorph filmstrip of %zu frames of shapes",
           c->n);
  api__svg_doc_open(c, title);
  for (size_t i = 0; i < c->n; i++) cell(c, m, i, cols, cw, ch, &bb);
}

/* One panel holding every frame's box with a band of `band` px below it,
 * as the single-curve overlay and animation have it: the document sized
 * and opened, the scale and offsets returned. */
static double open_panel(api_svg_doc *c, const api_svg_shape_morph *m,
                         const api_svg_options *o, double default_width,
                         double band, const char *kind, api_svg_bbox *bb,
                         double *ox, double *oy) {
  char title[96];
  *bb = shapes_bbox(m->frames, c->n);
  double aspect = (bb->y1 - bb->y0) / (bb->x1 - bb->x0);
  double w = o->width > 0 ? o->width : default_width;
  double h =
      o->height > 0 ? o->height : ceil(w * fmin(fmax(aspect, 0.25), 4) + band);
  c->W = w;
  c->H = h;
  snprintf(title, sizeof title, "kmorph %s of %zu frames of shapes", kind,
           c->n);
  api__svg_doc_open(c, title);
  *ox = 6;
  *oy = 6;
  return api__svg_fit(bb, fmax(w - 12, 1), fmax(h - band - 12, 1), ox, oy);
}

static void overlay(api_svg_doc *c, const api_svg_shape_morph *m,
                    const api_svg_options *o) {
  api_svg_bbox bb;
  double ox, oy;
  double s = open_panel(c, m, o, 480.0, 24.0, "overlay", &bb, &ox, &oy);
  for (size_t i = 0; i < c->n; i++) {
    char col[8];
    api__svg_frame_colour(c, i, col);
    if (m->frames[i].shape != NULL)
      draw_shape(c, &m->frames[i], ox, oy, s, &bb, col, "0.12");
  }
  api__svg_ramp_legend(c, 0, c->H - 8, c->W);
}

/* Pieces of each slot in the animation (pieces[nslots]): twice the most
 * knot spans its contour has in any frame, within [16, 400], and fewer
 * when the frames and slots are many, so that the document stays a few
 * megabytes. */
static void animate_pieces(const api_svg_shape_morph *m, size_t *pieces) {
  size_t share = 200000 / (m->n * (m->nslots ? m->nslots : 1));
  if (share < 8) share = 8;
  for (size_t k = 0; k < m->nslots; k++) {
    size_t most = 0;
    for (size_t i = 0; i < m->n; i++) {
      const km_shape_frame *sf = m->frames[i].shape;
      if (sf == NULL || k >= sf->ncontours || !sf->present[k]) continue;
      const km_curve *cv = &sf->contours[k];
      size_t spans = 0;
      for (size_t j = (size_t)cv->degree; j < cv->n; j++)
        if (cv->knots[j + 1] > cv->knots[j]) spans++;
      most = spans > most ? spans : most;
    }
    most *= 2;
    most = most < 16 ? 16 : most > 400 ? 400 : most;
    pieces[k] = most > share ? share : most;
  }
}

/* keyTimes of the drawn frames (ds[i] != NULL) at their t, when the times
 * increase, into b; *tfirst and *tlast get the first and last drawn t. */
static void key_times(const api_svg_shape_morph *m, char *const *ds,
                      size_t drawn, api_svg_buf *b, double *tfirst,
                      double *tlast) {
  bool increasing = drawn >= 2;
  double prev = -INFINITY;
  *tfirst = *tlast = NAN;
  for (size_t i = 0; i < m->n; i++) {
    if (ds[i] == NULL) continue;
    double t = m->frames[i].t;
    if (!isfinite(t) || !(t > prev)) increasing = false;
    if (isnan(*tfirst)) *tfirst = t;
    *tlast = t;
    prev = t;
  }
  if (!(increasing && *tlast > *tfirst)) return;
  api__svg_buf_put(b, " keyTimes=\"");
  for (size_t i = 0, k = 0; i < m->n; i++) {
    if (ds[i] == NULL) continue;
    double kt = (m->frames[i].t - *tfirst) / (*tlast - *tfirst);
    kt = k == 0 ? 0 : k + 1 == drawn ? 1 : kt;
    if (k++) api__svg_buf_put(b, ";");
    api__svg_buf_num(b, kt, 1e-6, NULL);
  }
  api__svg_buf_put(b, "\"");
}

/* The animated path's <animate> elements: "d" through every drawn frame
 * (SMIL needs two values: one frame is given twice), and the fill rule,
 * discretely, where the frames' rules differ. */
static void animate_elements(api_svg_doc *c, const api_svg_shape_morph *m,
                             char *const *ds, size_t drawn, const char *keys,
                             double dur, const char *first) {
  bool rules_differ = false;
  int rule = -1;
  api__svg_buf_put(&c->b, "<animate attributeName=\"d\" dur=\"");
  api__svg_buf_num(&c->b, dur, 1e-4, NULL);
  api__svg_buf_put(&c->b, "s\" repeatCount=\"indefinite\" calcMode=\"linear\"");
  api__svg_buf_put(&c->b, keys);
  api__svg_buf_put(&c->b, " values=\"");
  for (size_t i = 0, k = 0; i < m->n; i++) {
    if (ds[i] == NULL) continue;
    if (k++) api__svg_buf_put(&c->b, ";");
    api__svg_buf_put(&c->b, ds[i]);
    rules_differ =
        rules_differ || (rule >= 0 && rule != (int)m->frames[i].fill);
    rule = (int)m->frames[i].fill;
  }
  if (drawn == 1) {
    api__svg_buf_put(&c->b, ";");
    api__svg_buf_put(&c->b, first);
  }
  api__svg_buf_put(&c->b, "\"/>\n");
  if (!rules_differ) return;
  api__svg_buf_put(&c->b, "<animate attributeName=\"fill-rule\" dur=\"");
  api__svg_buf_num(&c->b, dur, 1e-4, NULL);
  api__svg_buf_put(&c->b,
                   "s\" repeatCount=\"indefinite\" calcMode=\"discrete\"");
  api__svg_buf_put(&c->b, keys);
  api__svg_buf_put(&c->b, " values=\"");
  for (size_t i = 0, k = 0; i < m->n; i++) {
    if (ds[i] == NULL) continue;
    if (k++) api__svg_buf_put(&c->b, ";");
    api__svg_buf_put(&c->b, rule_name(m->frames[i].fill));
  }
  api__svg_buf_put(&c->b, "\"/>\n");
}

/* The animated path, its first frame drawn until the animation starts,
 * and the t range below it. */
static void animate_path(api_svg_doc *c, const api_svg_shape_morph *m,
                         char *const *ds, size_t drawn,
                         const api_svg_options *o, const api_svg_bbox *bb,
                         double ox, double oy, double s) {
  const char *first = NULL;
  size_t i0 = 0;
  double dur = o->duration > 0 && isfinite(o->duration) ? o->duration : 2.0;
  double tfirst, tlast;
  char label[80];
  api_svg_buf keys;
  for (size_t i = 0; i < m->n && first == NULL; i++)
    if ((first = ds[i]) != NULL) i0 = i;
  api__svg_buf_init(&keys);
  key_times(m, ds, drawn, &keys, &tfirst, &tlast);
  char *k = api__svg_buf_take(&keys);
  if (k == NULL) {
    c->b.failed = true;
    return;
  }
  api__svg_path_open(c, ox, oy, s, bb);
  fill_attrs(c, s, rule_name(m->frames[i0].fill), c->stroke, "0.35");
  api__svg_buf_put(&c->b, first);
  api__svg_buf_put(&c->b, "\">\n");
  animate_elements(c, m, ds, drawn, k, dur, first);
  api__svg_buf_put(&c->b, "</path>\n");
  km__free(k);
  snprintf(label, sizeof label, "t = %.4g \xe2\x80\xa6 %.4g",
           isfinite(tfirst) ? tfirst : 0.0, isfinite(tlast) ? tlast : 0.0);
  centred_text(c, 0.5 * c->W, c->H - 6, label);
}

static void animate(api_svg_doc *c, const api_svg_shape_morph *m,
                    const api_svg_options *o) {
  api_svg_bbox bb;
  double ox, oy;
  double s = open_panel(c, m, o, 400.0, 20.0, "animation", &bb, &ox, &oy);
  size_t *pieces = km__malloc((m->nslots ? m->nslots : 1) * sizeof *pieces);
  char **ds = km__calloc(c->n, sizeof *ds);
  size_t drawn = 0;
  if (pieces == NULL || ds == NULL) {
    c->b.failed = true;
    goto done;
  }
  animate_pieces(m, pieces);
  for (size_t i = 0; i < c->n; i++) {
    const km_shape_frame *sf = m->frames[i].shape;
    if (sf == NULL || sf->ncontours != m->nslots) continue;
    if ((ds[i] = api_svg_shape_frame_d(sf, pieces, m->collapse)) == NULL) {
      c->b.failed = true;
      goto done;
    }
    drawn++;
  }
  if (drawn > 0) animate_path(c, m, ds, drawn, o, &bb, ox, oy, s);
done:
  for (size_t i = 0; ds != NULL && i < c->n; i++) km__free(ds[i]);
  km__free(ds);
  km__free(pieces);
}

/* "contours 1 → 0", "contour 1 → (vanishes)", "(appears) → contour 2" */
static void pair_label(const km_shape_pair *pr, size_t k, char *s, size_t n) {
  if (pr->from >= 0 && pr->to >= 0)
    snprintf(s, n, "pair %zu: contour %ld \xe2\x86\x92 contour %ld", k,
             pr->from, pr->to);
  else if (pr->from >= 0)
    snprintf(s, n, "pair %zu: contour %ld \xe2\x86\x92 (vanishes)", k,
             pr->from);
  else
    snprintf(s, n, "pair %zu: (appears) \xe2\x86\x92 contour %ld", k, pr->to);
}

/* One labelled panel per slot, stacked, each with the frames' traces of
 * that slot's contour (none where it is collapsed). */
static void curvature_plot(api_svg_doc *c, const api_svg_shape_morph *m,
                           const api_svg_options *o) {
  char title[96], label[96];
  size_t np = m->nslots ? m->nslots : 1;
  double ph = o->height > 0 ? o->height / (double)np : 300.0;
  api_svg_frame *pf = km__calloc(c->n, sizeof *pf);
  const api_svg_frame *all = c->f;
  c->W = o->width > 0 ? o->width : 640.0;
  c->H = o->height > 0 ? o->height : ph * (double)np;
  snprintf(title, sizeof title,
           "kmorph curvature plot of %zu frames of %zu contour pairs", c->n,
           m->nslots);
  api__svg_doc_open(c, title);
  if (pf == NULL) {
    c->b.failed = true;
    return;
  }
  for (size_t k = 0; k < m->nslots && !c->b.failed; k++) {
    for (size_t i = 0; i < c->n; i++) {
      const km_shape_frame *sf = m->frames[i].shape;
      pf[i].t = m->frames[i].t;
      pf[i].curve = sf != NULL && k < sf->ncontours && sf->present[k]
                        ? &sf->contours[k]
                        : NULL;
      pf[i].sig = NULL;
    }
    pair_label(&m->pairs[k], k, label, sizeof label);
    api__svg_buf_printf(&c->b, "<g id=\"km-pair-%zu\">\n<title>", k);
    api__svg_buf_escaped(&c->b, label);
    api__svg_buf_put(&c->b, "</title>\n");
    c->f = pf;
    api__svg_curvature_panel(c, ph * (double)k, ph, k, m->nslots, label);
    c->f = all;
    api__svg_buf_put(&c->b, "</g>\n");
  }
  km__free(pf);
}

char *api_svg_shape_document(const api_svg_shape_morph *m,
                             const api_svg_options *opt) {
  api_svg_options o;
  api_svg_doc c;
  api__svg_doc_init(&c, opt, &o);
  c.n = m != NULL && m->frames != NULL ? m->n : 0;
  /* the frames' t for the legends the layouts share with single curves */
  api_svg_frame *tf = km__calloc(c.n ? c.n : 1, sizeof *tf);
  if (tf == NULL) return NULL;
  for (size_t i = 0; i < c.n; i++) tf[i].t = m->frames[i].t;
  c.f = tf;
  if (c.n == 0) {
    c.W = o.width > 0 ? o.width : 200;
    c.H = o.height > 0 ? o.height : 40;
    api__svg_doc_open(&c, "kmorph: no frames");
    centred_text(&c, 0.5 * c.W, 24, "no frames");
  } else {
    switch (o.layout) {
    case API_SVG_OVERLAY: overlay(&c, m, &o); break;
    case API_SVG_ANIMATE: animate(&c, m, &o); break;
    case API_SVG_CURVATURE_PLOT: curvature_plot(&c, m, &o); break;
    case API_SVG_FILMSTRIP:
    default: filmstrip(&c, m, &o); break;
    }
  }
  api__svg_buf_put(&c.b, "</svg>\n");
  km__free(tf);
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
