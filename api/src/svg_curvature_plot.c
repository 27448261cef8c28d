/* svg_curvature_plot.c - the curvature plot layout: kappa against
 * normalised arc length s/L for every frame, along the colour ramp, with
 * corners as ticks, axes, and a legend of t values or a colour bar. A
 * compound morph gets one such panel per contour pair, stacked and
 * labelled with the pair.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "km/alloc.h"
#include "km/fn.h"
#include "km/signature.h"
#include "svg_doc.h"

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
  se->x = km__malloc(cap * sizeof *se->x);
  se->y = km__malloc(cap * sizeof *se->y);
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

/* The plot's geometry: the frames' samples, the range of kappa shown,
 * the margins and the plot area in px. */
typedef struct plot {
  double ox, oy, w, h; /* the panel's place in the document, px */
  const char *clip_id; /* of the panel's clip path */
  const char *label;   /* above the panel, or NULL */
  const char *missing; /* legend note for a frame without a trace */
  bool ramp;           /* draw the colour ramp when the legend is one */
  size_t share;        /* traces sharing the document's sample budget */
  series *se;          /* one per frame */
  double lo, hi, step; /* kappa shown and its tick step */
  bool clipped;        /* kappa beyond [lo, hi] is drawn at its edge */
  bool legend_list;    /* the t of every frame, else a colour ramp */
  double ml, mr, mt, mb;
  double pw, ph;
} plot;

static double px(const plot *p, double u) {
  return p->ml + u * p->pw;
}

static double py(const plot *p, double v) {
  return p->mt + (p->hi - v) / (p->hi - p->lo) * p->ph;
}

/* Every frame's samples of kappa, its signature computed here when the
 * frame brought none (or left out when that fails, save for want of
 * memory, which fails the document); *total counts them.
 * NULL when out of memory; a sampling that fails sets c->b.failed. */
static series *plot_series(api_svg_doc *c, size_t share, size_t *total) {
  series *se = km__calloc(c->n ? c->n : 1, sizeof *se);
  if (!se) return NULL;
  /* Samples per trace: smooth curves for a few traces, a bounded document
   * for many. */
  size_t budget = 400000 / share;
  if (budget > 1600) budget = 1600;
  if (budget < 100) budget = 100;
  *total = 0;
  for (size_t i = 0; i < c->n; i++) {
    km_signature_init(&se[i].own);
    se[i].sig = c->f[i].sig;
    if (!se[i].sig && c->f[i].curve) {
      km_status st = km_signature_compute(c->f[i].curve, 0, &se[i].own, NULL);
      if (st == KM_OK) {
        se[i].has_own = true;
        se[i].sig = &se[i].own;
      }
      /* a trace left out for want of memory would be a wrong answer */
      if (st == KM_ENOMEM) c->b.failed = true;
    }
    if (se[i].sig && !sample_kappa(&se[i], budget)) c->b.failed = true;
    *total += se[i].n;
  }
  return se;
}

static void series_free(series *se, size_t n) {
  for (size_t i = 0; i < n; i++) {
    km__free(se[i].x);
    km__free(se[i].y);
    if (se[i].has_own) km_signature_free(&se[i].own);
  }
  km__free(se);
}

/* The range shown: all of kappa and zero, unless a few samples near a
 * degenerate leg (kappa ~ 1/sqrt(s)) would flatten everything else;
 * then the central 98 % with a margin, clipped and said so. Rounded out
 * to whole tick steps. */
static void plot_range(api_svg_doc *c, plot *p, size_t total) {
  double lo = 0, hi = 0;
  double *all = km__malloc((total ? total : 1) * sizeof *all);
  if (!all) c->b.failed = true;
  if (all && total) {
    size_t m = 0;
    for (size_t i = 0; i < c->n; i++)
      for (size_t k = 0; k < p->se[i].n; k++)
        if (isfinite(p->se[i].y[k])) all[m++] = p->se[i].y[k];
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
        p->clipped = true;
      }
    }
  }
  km__free(all);
  if (!(hi > lo)) {
    hi = lo + 1;
  }
  p->step = nice_step(hi - lo);
  p->lo = floor(lo / p->step) * p->step;
  p->hi = ceil(hi / p->step) * p->step;
  if (!(p->hi > p->lo)) p->hi = p->lo + p->step;
}

/* Margins: room for a legend of t values on the right when it lists
 * them, for a colour ramp below when it does not. */
static void plot_layout(const api_svg_doc *c, plot *p) {
  p->legend_list = c->n <= 12;
  p->ml = p->ox + 64;
  p->mr = p->legend_list ? 100 : 16;
  p->mt = p->oy + (p->label != NULL ? 30 : 16);
  p->mb = p->legend_list || !p->ramp ? 48 : 72;
  p->pw = fmax(p->ox + p->w - p->ml - p->mr, 10);
  p->ph = fmax(p->oy + p->h - p->mt - p->mb, 10);
}

/* The plot area's clip path, and the group of axes and labels opened. */
static void plot_clip_open(api_svg_doc *c, const plot *p) {
  api__svg_buf_put(&c->b, "<defs><clipPath id=\"");
  api__svg_buf_put(&c->b, p->clip_id);
  api__svg_buf_put(&c->b, "\"><rect x=\"");
  api__svg_px(c, p->ml);
  api__svg_buf_put(&c->b, "\" y=\"");
  api__svg_px(c, p->mt);
  api__svg_buf_put(&c->b, "\" width=\"");
  api__svg_px(c, p->pw);
  api__svg_buf_put(&c->b, "\" height=\"");
  api__svg_px(c, p->ph);
  api__svg_buf_put(&c->b, "\"/></clipPath></defs>\n<g " API_SVG_FONT
                          " font-size=\"11\" fill=\"#333333\">\n");
}

/* s/L ticks, grid lines and labels at 0, 0.25, ..., 1. */
static void plot_x_ticks(api_svg_doc *c, const plot *p) {
  for (int k = 0; k <= 4; k++) {
    double u = k / 4.0;
    api__svg_buf_put(&c->b, "<line x1=\"");
    api__svg_px(c, px(p, u));
    api__svg_buf_put(&c->b, "\" y1=\"");
    api__svg_px(c, p->mt);
    api__svg_buf_put(&c->b, "\" x2=\"");
    api__svg_px(c, px(p, u));
    api__svg_buf_put(&c->b, "\" y2=\"");
    api__svg_px(c, p->mt + p->ph + 4);
    api__svg_buf_put(&c->b, "\" stroke=\"#e0e0e0\"/>\n<text x=\"");
    api__svg_px(c, px(p, u));
    api__svg_buf_put(&c->b, "\" y=\"");
    api__svg_px(c, p->mt + p->ph + 16);
    api__svg_buf_printf(&c->b, "\" text-anchor=\"middle\">%g</text>\n", u);
  }
}

/* kappa ticks, grid lines (the zero line darker) and labels. */
static void plot_y_ticks(api_svg_doc *c, const plot *p) {
  size_t nt = (size_t)llround((p->hi - p->lo) / p->step);
  for (size_t k = 0; k <= nt && k <= 40; k++) {
    double v = p->lo + p->step * (double)k;
    if (fabs(v) < 1e-9 * p->step) v = 0;
    api__svg_buf_put(&c->b, "<line x1=\"");
    api__svg_px(c, p->ml - 4);
    api__svg_buf_put(&c->b, "\" y1=\"");
    api__svg_px(c, py(p, v));
    api__svg_buf_put(&c->b, "\" x2=\"");
    api__svg_px(c, p->ml + p->pw);
    api__svg_buf_put(&c->b, "\" y2=\"");
    api__svg_px(c, py(p, v));
    api__svg_buf_put(&c->b, v == 0 ? "\" stroke=\"#888888\"/>\n<text x=\""
                                   : "\" stroke=\"#e0e0e0\"/>\n<text x=\"");
    api__svg_px(c, p->ml - 6);
    api__svg_buf_put(&c->b, "\" y=\"");
    api__svg_px(c, py(p, v) + 4);
    api__svg_buf_printf(&c->b, "\" text-anchor=\"end\">%.4g</text>\n", v);
  }
}

/* The plot area's frame and the axis titles; the group of axes closed
 * and the clipped group of curves opened. */
static void plot_axis_labels(api_svg_doc *c, const plot *p) {
  api__svg_buf_put(&c->b, "<rect x=\"");
  api__svg_px(c, p->ml);
  api__svg_buf_put(&c->b, "\" y=\"");
  api__svg_px(c, p->mt);
  api__svg_buf_put(&c->b, "\" width=\"");
  api__svg_px(c, p->pw);
  api__svg_buf_put(&c->b, "\" height=\"");
  api__svg_px(c, p->ph);
  api__svg_buf_put(&c->b, "\" fill=\"none\" stroke=\"#333333\"/>\n<text x=\"");
  api__svg_px(c, p->ml + 0.5 * p->pw);
  api__svg_buf_put(&c->b, "\" y=\"");
  api__svg_px(c, p->mt + p->ph + 34);
  api__svg_buf_put(&c->b, "\" text-anchor=\"middle\" font-size=\"12\">"
                          "normalised arc length s/L</text>\n<text x=\"");
  api__svg_px(c, p->ox + 14);
  api__svg_buf_put(&c->b, "\" y=\"");
  api__svg_px(c, p->mt + 0.5 * p->ph);
  api__svg_buf_put(&c->b, "\" text-anchor=\"middle\" font-size=\"12\" "
                          "transform=\"rotate(-90 ");
  api__svg_px(c, p->ox + 14);
  api__svg_buf_put(&c->b, " ");
  api__svg_px(c, p->mt + 0.5 * p->ph);
  api__svg_buf_put(&c->b, p->clipped
                              ? ")\">curvature \xce\xba (clipped)</text>\n"
                              : ")\">curvature \xce\xba</text>\n");
  api__svg_buf_put(&c->b, "</g>\n<g clip-path=\"url(#");
  api__svg_buf_put(&c->b, p->clip_id);
  api__svg_buf_put(&c->b, ")\" fill=\"none\" stroke-linejoin=\"round\">\n");
}

/* Corners: tangent jumps as vertical ticks at their s/L from the zero
 * line, up for a left turn, length growing with |turn|. */
static void plot_corners(api_svg_doc *c, const plot *p, const km_signature *sg,
                         const char *col) {
  double y0 = py(p, fmin(fmax(0.0, p->lo), p->hi));
  for (size_t k = 0; k < sg->ncorners; k++) {
    double u = sg->corners[k].s / sg->length, turn = sg->corners[k].turn;
    if (!isfinite(u) || !isfinite(turn)) continue;
    double len = 6 + 30 * fabs(turn) / 3.141592653589793;
    api__svg_buf_put(&c->b, "<line stroke=\"");
    api__svg_buf_put(&c->b, col);
    api__svg_buf_put(&c->b, "\" stroke-width=\"");
    api__svg_px(c, c->sw);
    api__svg_buf_put(&c->b, "\" x1=\"");
    api__svg_px(c, px(p, u));
    api__svg_buf_put(&c->b, "\" y1=\"");
    api__svg_px(c, y0);
    api__svg_buf_put(&c->b, "\" x2=\"");
    api__svg_px(c, px(p, u));
    api__svg_buf_put(&c->b, "\" y2=\"");
    api__svg_px(c, y0 - (turn > 0 ? len : -len));
    api__svg_buf_printf(&c->b,
                        "\"><title>corner: turn %.6g rad at s/L = "
                        "%.6g</title></line>\n",
                        turn, u);
  }
}

/* Frame i's kappa as a path of its colour, and its corners. */
static void plot_curve(api_svg_doc *c, const plot *p, size_t i) {
  char col[8];
  api__svg_frame_colour(c, i, col);
  api__svg_buf_put(&c->b, "<path stroke=\"");
  api__svg_buf_put(&c->b, col);
  api__svg_buf_put(&c->b, "\" stroke-width=\"");
  api__svg_px(c, c->sw);
  api__svg_buf_put(&c->b, "\" d=\"M");
  for (size_t k = 0; k < p->se[i].n; k++) {
    /* Clipped samples are drawn at the edge, not at infinity. */
    double y = p->se[i].y[k];
    if (!isfinite(y)) y = 0;
    y = fmin(fmax(y, p->lo - 0.1 * (p->hi - p->lo)),
             p->hi + 0.1 * (p->hi - p->lo));
    if (k) api__svg_buf_put(&c->b, k == 1 ? "L" : " ");
    api__svg_px(c, px(p, p->se[i].x[k]));
    api__svg_buf_put(&c->b, ",");
    api__svg_px(c, py(p, y));
  }
  api__svg_buf_put(&c->b, "\"/>\n");
  plot_corners(c, p, p->se[i].sig, col);
}

/* Legend: the t of every frame, or a colour ramp for many frames. */
static void plot_legend(api_svg_doc *c, const plot *p) {
  if (p->legend_list) {
    for (size_t i = 0; i < c->n; i++) {
      char col[8];
      api__svg_frame_colour(c, i, col);
      double y = p->mt + 8 + 16 * (double)i;
      api__svg_buf_put(&c->b, "<line x1=\"");
      api__svg_px(c, p->ox + p->w - p->mr + 10);
      api__svg_buf_put(&c->b, "\" y1=\"");
      api__svg_px(c, y);
      api__svg_buf_put(&c->b, "\" x2=\"");
      api__svg_px(c, p->ox + p->w - p->mr + 30);
      api__svg_buf_put(&c->b, "\" y2=\"");
      api__svg_px(c, y);
      api__svg_buf_put(&c->b, "\" stroke-width=\"3\" stroke=\"");
      api__svg_buf_put(&c->b, col);
      api__svg_buf_put(&c->b, "\"/>\n<text x=\"");
      api__svg_px(c, p->ox + p->w - p->mr + 34);
      api__svg_buf_put(&c->b, "\" y=\"");
      api__svg_px(c, y + 4);
      api__svg_buf_put(&c->b, "\" " API_SVG_FONT
                              " font-size=\"11\" fill=\"#333333\">");
      api__svg_t_label(c, c->f[i].t);
      if (!p->se[i].n) api__svg_buf_put(&c->b, p->missing);
      api__svg_buf_put(&c->b, "</text>\n");
    }
  } else if (p->ramp) {
    api__svg_ramp_legend(c, p->ml, p->oy + p->h - 10, p->pw);
  }
}

/* The panel p (its place, ids and label set) of the frames c->f. */
static void plot_panel(api_svg_doc *c, plot *p) {
  size_t total = 0;
  if ((p->se = plot_series(c, p->share, &total)) == NULL) {
    c->b.failed = true;
    return;
  }
  plot_range(c, p, total);
  plot_layout(c, p);
  if (p->label != NULL) {
    api__svg_buf_put(&c->b, "<text x=\"");
    api__svg_px(c, p->ml);
    api__svg_buf_put(&c->b, "\" y=\"");
    api__svg_px(c, p->oy + 20);
    api__svg_buf_put(&c->b, "\" " API_SVG_FONT " font-size=\"13\" "
                            "fill=\"#333333\">");
    api__svg_buf_escaped(&c->b, p->label);
    api__svg_buf_put(&c->b, "</text>\n");
  }
  plot_clip_open(c, p);
  plot_x_ticks(c, p);
  plot_y_ticks(c, p);
  plot_axis_labels(c, p);
  for (size_t i = 0; i < c->n; i++)
    if (p->se[i].n) plot_curve(c, p, i);
  api__svg_buf_put(&c->b, "</g>\n");
  plot_legend(c, p);
  series_free(p->se, c->n);
  p->se = NULL;
}

void api__svg_curvature_plot(api_svg_doc *c, const api_svg_options *o) {
  plot p;
  c->W = o->width > 0 ? o->width : 640.0;
  c->H = o->height > 0 ? o->height : 400.0;
  char title[80];
  snprintf(title, sizeof title, "kmorph curvature plot of %zu frames", c->n);
  api__svg_doc_open(c, title);
  memset(&p, 0, sizeof p);
  p.w = c->W;
  p.h = c->H;
  p.clip_id = "km-plot";
  p.missing = " (no signature)";
  p.ramp = true;
  p.share = c->n;
  plot_panel(c, &p);
}

void api__svg_curvature_panel(api_svg_doc *c, double y, double h, size_t k,
                              size_t npanels, const char *label) {
  plot p;
  char id[40];
  memset(&p, 0, sizeof p);
  snprintf(id, sizeof id, "km-plot-%zu", k);
  p.oy = y;
  p.w = c->W;
  p.h = h;
  p.clip_id = id;
  p.label = label;
  p.missing = " (point)";
  p.ramp = k + 1 == npanels;
  p.share = c->n * (npanels ? npanels : 1);
  plot_panel(c, &p);
}
