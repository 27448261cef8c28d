/* morph_plan.h - the prepared morph behind POST /v1/morph and jobs, shared
 * by the files that build and use it: morph_request.c reads the request
 * into it, morph_plan.c plans it and renders its frames, morph_size.c
 * bounds the size of its answer, morph_result.c assembles the answer.
 * Internal to the api layer.
 *
 * DESIGN: api_handle(API_ROUTE_MORPH) is prepare + result on one thread, so
 * the synchronous route and asynchronous jobs run exactly the same code.
 * Each frame has its own slot in the plan; rendering frame i writes slot i
 * only, which is what makes distinct frames safe to render concurrently.
 * Errors found while rendering stay in their slot until api_morph_result
 * reports the first one.
 */
#ifndef KMAPI_MORPH_PLAN_H
#define KMAPI_MORPH_PLAN_H

#include <stdbool.h>
#include <stddef.h>

#include "internal.h"
#include "json_write.h"
#include "svg.h"

/* Bytes of a colour option, its NUL included, at most. */
#define API_COLOUR_MAX 64

typedef enum api_frame_state {
  API_FRAME_PENDING, /* not rendered yet */
  API_FRAME_DONE,    /* curve (and metrics, signature) valid */
  API_FRAME_FAILED   /* st and err say why; stopped is KM_ECANCELLED */
} api_frame_state;

typedef struct api_frame_slot {
  double t;
  api_frame_state state;
  km_curve curve;
  km_frame_metrics metrics;
  km_signature sig;     /* only for curvature plots */
  km_shape_frame shape; /* compound morphs: the frame, in place of curve */
  km_status st;
  km_error err;
  /* measured while rendering, so that frames rendered on several threads
   * leave the answer only its printing: the curve's length (NAN: not
   * measured) and its crossings for "intersections" (-1: not counted) */
  double length;
  long crossings;
  /* the frame's object of the JSON answer, printed on the thread that
   * rendered it (api_morph_print_while_rendering); empty: printed with
   * the answer */
  api_svg_buf text;
} api_frame_slot;

struct api_morph_plan {
  api_config cfg;
  char *request_id;
  api_input from, to;
  km_morph *morph;
  km_morph_options opt;
  double *matches;
  bool times_given;
  size_t nframes;
  api_frame_slot *frames;
  bool metrics;
  api_precision precision;
  bool svg;
  bool want_sig;
  api_include inc;
  double tol;
  api_svg_options svgopt;
  char stroke[API_COLOUR_MAX], from_color[API_COLOUR_MAX],
      to_color[API_COLOUR_MAX];
  size_t predicted; /* upper bound on the result's bytes */
  bool print_early; /* frames print themselves when rendered */
  /* A compound morph (either input a shape): the shapes, their morph,
   * and the request's contour pairing (NULL: automatic). */
  bool shapes;
  km_shape sfrom, sto;
  km_shape_morph *smorph;
  km_shape_pair *cmatches;
  size_t ncmatches;
};

/* "method" names, indexed by km_morph_method. */
extern const char *const api__morph_method_names[2];

/* Read the morph request in root into pl (zeroed but for cfg): options,
 * frames or times (at most max_frames), the answer's format (an explicit
 * "format" wins over the accept header, which may be NULL) and both input
 * curves, cheap checks first so that a bad option fails before any curve
 * is fitted. Allocations stay in pl for api_morph_plan_free. False with
 * the error in ctx. */
bool api__morph_read_request(api_ctx *ctx, const cJSON *root,
                             const char *accept, size_t max_frames,
                             api_morph_plan *pl);

/* Bound the answer of a planned morph (pl->morph built): set
 * pl->predicted and refuse (422 limit-exceeded) an answer above
 * pl->cfg.max_output_bytes, naming /tolerance when even the fewest frames
 * would not fit, else the frames. Polls stop (may be NULL): 503 stopped.
 * False with the error in ctx. */
bool api__morph_check_size(api_ctx *ctx, api_morph_plan *pl,
                           const km_stop *stop);

/* A frame's metrics object (morph_result.c), as json_write.h writes. */
bool api__json_metrics(api_ctx *ctx, api_svg_buf *b, const km_frame_metrics *m);
/* The "intersections" object of an answer that asked to avoid crossings
 * (morph_crossings.c): frames rendered. NULL with the error in ctx. */
cJSON *api__intersections_json(api_ctx *ctx, const api_morph_plan *pl);
/* The tolerance a frame's crossings are counted at for "intersections":
 * the request's, else the core's default (1e-5 of the longer input). */
double api__crossing_tolerance(const api_morph_plan *pl);
/* Frame f's object of the JSON answer (its t, curve or contours, metrics)
 * into b, its control points on grid; false when it cannot be written
 * (recorded in ctx). */
bool api__frame_write(api_ctx *ctx, api_svg_buf *b, const api_morph_plan *pl,
                      const api_frame_slot *f, const api_grid *grid);
/* The grid a plan's control points are printed on (off when exact). */
api_grid api__plan_grid(const api_morph_plan *pl);
/* Cubic pieces of a path "M x y C ..." as api_svg_path_d writes it. */
size_t api__count_pieces(const char *d);

/* ---- compound morphs (morph_shape.c) ---- */

/* The optional "contour_matches": [[i | null, j | null], ...], at most
 * 2 x the contour limit pairs, into pl->cmatches (the contours' ranges are
 * checked once the shapes are built). False with the error in ctx. */
bool api__shape_read_matches(api_ctx *ctx, const cJSON *root,
                             api_morph_plan *pl);

/* After both inputs are read: a compound morph when either is a shape
 * (pl->shapes); refuses what a compound morph does not take (a signature
 * input, an open single curve, explicit arc-length "matches", an SVG
 * answer) and contour_matches without a shape. */
bool api__shape_check_request(api_ctx *ctx, api_morph_plan *pl);

/* Build both shapes and their morph under pl->opt (stop polled), every
 * failure naming the contour ("/from/contours/2", or for SVG "/from/d"
 * with the subpath's offset). */
bool api__shape_build(api_ctx *ctx, api_morph_plan *pl, const km_stop *stop);

/* Render frame slot f of a compound morph. */
void api__shape_render(api_morph_plan *pl, api_frame_slot *f,
                       const km_stop *stop);

/* Bound the answer of a compound morph (as api__morph_check_size). */
bool api__shape_check_size(api_ctx *ctx, api_morph_plan *pl,
                           const km_stop *stop);

/* The JSON answer's frame of a compound morph, written into b as
 * json_write.h writes: t, contours (null for an absent one), svg_d when
 * asked, metrics when asked; contours on grid as single frames' curves
 * (NULL: exact). False with the error in ctx. */
bool api__shape_frame_write(api_ctx *ctx, api_svg_buf *b,
                            const api_morph_plan *pl, const api_frame_slot *f,
                            const api_grid *grid);

/* "contour_matches_used": the pairs of the morph, into b. */
bool api__shape_pairs_write(api_ctx *ctx, api_svg_buf *b,
                            const api_morph_plan *pl);

/* "animate_d" of a compound morph, into b: every frame as one path of the
 * present contours, each slot with one common number of pieces. */
bool api__shape_animate_write(api_ctx *ctx, api_svg_buf *b,
                              const api_morph_plan *pl);

/* The SVG document of a compound morph's rendered frames in the request's
 * layout, each frame filled under the fill rule of the nearer end
 * (from's for t < 0.5), whose nesting it keeps. NULL when out of memory. */
char *api__shape_svg(const api_morph_plan *pl);

#endif
