/* svg_doc.h - the SVG document of a morph as its layouts share it: the
 * growing document with its size, stroke and colour ramp, and the pieces
 * every layout draws with (the view box of all frames, a frame's curve
 * under a transform, the t labels, the colour ramp legend). svg_doc.c
 * writes the document around a layout; svg_frames.c has the filmstrip,
 * overlay and animation layouts, svg_curvature_plot.c the plot. Internal
 * to the api layer.
 */
#ifndef KMAPI_SVG_DOC_H
#define KMAPI_SVG_DOC_H

#include <stdbool.h>
#include <stddef.h>

#include "svg.h"

#define API_SVG_FONT "font-family=\"sans-serif\""

/* Pixel budget for printed document coordinates. */
#define API_SVG_PX_BUDGET 0.005

typedef struct api_svg_bbox {
  double x0, y0, x1, y1;
  bool empty;
} api_svg_bbox;

typedef struct api_svg_rgb {
  double r, g, b;
} api_svg_rgb;

/* The document being written and what every layout draws with. */
typedef struct api_svg_doc {
  api_svg_buf b;
  const api_svg_frame *f;
  size_t n;
  double W, H; /* document size, px */
  double sw;   /* stroke width, px */
  const char *stroke;
  api_svg_rgb from, to;
  const char *from_s, *to_s; /* colour strings as written */
} api_svg_doc;

/* An empty document for options opt (NULL: defaults), which are copied
 * into *o with absurd sizes dropped: the stroke, its width and the colour
 * ramp taken from them or their defaults. c->f and c->n are left 0. */
void api__svg_doc_init(api_svg_doc *c, const api_svg_options *opt,
                       api_svg_options *o);
/* A document coordinate, printed within API_SVG_PX_BUDGET. */
void api__svg_px(api_svg_doc *c, double v);
/* Open a <path> element whose transform maps the frames' box bb, scaled by
 * s, to the offset (ox, oy) in pixels; the caller writes its attributes
 * (from a space) and closes it. */
/* The light frame of a filmstrip cell of cw x ch pixels at (x, y). */
void api__svg_cell_frame(api_svg_doc *c, double x, double y, double cw,
                         double ch);
void api__svg_path_open(api_svg_doc *c, double ox, double oy, double s,
                        const api_svg_bbox *bb);
/* Frame i's colour on the ramp from the first frame's to the last's. */
void api__svg_frame_colour(const api_svg_doc *c, size_t i, char out[8]);
/* "t = 0.5", escaped. */
void api__svg_t_label(api_svg_doc *c, double t);
/* The XML declaration, the <svg> element of c->W x c->H px, its title and
 * a white background. */
void api__svg_doc_open(api_svg_doc *c, const char *title);
/* Union box of all frames, padded, never empty or flat. */
api_svg_bbox api__svg_frames_bbox(const api_svg_doc *c);
/* Largest uniform scale fitting bb into w x h; *ox, *oy move by the
 * offsets that centre it. */
double api__svg_fit(const api_svg_bbox *bb, double w, double h, double *ox,
                    double *oy);
/* A frame's curve under transform x -> ox + s (x - bb->x0), y likewise. */
void api__svg_draw_curve(api_svg_doc *c, const km_curve *cv, double ox,
                         double oy, double s, const api_svg_bbox *bb,
                         const char *colour);
/* Horizontal colour bar from the first frame's colour to the last one's,
 * with their t values, across [x, x + w] at height y. */
void api__svg_ramp_legend(api_svg_doc *c, double x, double y, double w);

/* The layouts: each sets c->W and c->H, opens the document and draws the
 * frames (c->n >= 1); the caller closes it. */
void api__svg_filmstrip(api_svg_doc *c, const api_svg_options *o);
void api__svg_overlay(api_svg_doc *c, const api_svg_options *o);
void api__svg_animate(api_svg_doc *c, const api_svg_options *o);
void api__svg_curvature_plot(api_svg_doc *c, const api_svg_options *o);
/* Panel k of npanels of a compound morph's curvature plot: the frames
 * c->f (one contour's pair, NULL curves where it is collapsed) across the
 * document, from y down h px, under `label`; the colour ramp, when the
 * legend is one, under the last panel only. The caller opens the
 * document. */
void api__svg_curvature_panel(api_svg_doc *c, double y, double h, size_t k,
                              size_t npanels, const char *label);

#endif
