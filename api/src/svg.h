/* svg.h - SVG path data in and out, and SVG documents for morph results
 * (internal to the api layer).
 *
 * Ownership: returned strings are malloc'd and freed by the caller.
 */
#ifndef KMAPI_SVG_H
#define KMAPI_SVG_H

#include <stdbool.h>
#include <stddef.h>

#include "km/curve.h"
#include "km/shape.h"
#include "km/signature.h"

/* Parse one SVG 1.1 path `d` (one subpath; every command, absolute and
 * relative) into a curve: lines, quadratics and cubics exactly, arcs as
 * rational pieces exactly, all raised to one common degree; `Z` makes it
 * closed; zero-length pieces are dropped. tol (> 0) is the distance
 * tolerance used where a repair needs one. On failure returns a status,
 * *err_offset = character offset of the problem and msg (NUL-terminated,
 * at most msgcap bytes) says what was expected.
 * Details: only `len` bytes are read (NUL bytes inside are errors). Pieces
 * within min(tol, 1e-9 x extent) of a point are dropped (rounding slivers,
 * e.g. a Z after relative moves that miss the start by 1e-16); tol <= 0
 * means 1e-9 x extent alone. A moveto after drawing is an error unless
 * nothing follows it. Statuses: KM_EINVAL (grammar), KM_ERANGE (a number
 * beyond double range or |coordinate| > KM_MAX_COORDINATE),
 * KM_EDEGENERATE (draws nothing), KM_ELIMIT, KM_ENOMEM. The offset is a
 * byte offset, which equals the character offset: the grammar is ASCII
 * and the first non-ASCII byte is itself the error. Numbers are read with
 * strtod: the C locale is assumed (kmorph never calls setlocale). */
km_status api_svg_parse_path(const char *d, size_t len, double tol,
                             km_curve *out, size_t *err_offset, char *msg,
                             size_t msgcap);

/* The same grammar with several subpaths: each subpath (from a moveto
 * that is followed by drawing) becomes one curve, as api_svg_parse_path
 * would make it alone. *out (n curves) and *offsets (the character
 * offset of each subpath's moveto) are malloc'd, written on KM_OK only,
 * freed by the caller (each curve with km_curve_free). More than
 * max_subpaths subpaths is KM_ELIMIT at the first one past it; a subpath
 * that draws nothing (zero length) is KM_EDEGENERATE at its moveto;
 * other statuses and *err_offset, msg as api_svg_parse_path. */
km_status api_svg_parse_subpaths(const char *d, size_t len, double tol,
                                 size_t max_subpaths, km_curve **out,
                                 size_t **offsets, size_t *n,
                                 size_t *err_offset, char *msg, size_t msgcap);

/* The curve as an SVG path of cubic Beziers ("M x y C ..." and "Z" if
 * closed), within tol of the curve (degree > 3 and rational curves are
 * approximated; *err_bound, if not NULL, receives the bound). NULL on
 * out-of-memory.
 * Polynomial curves of degree <= 3 are exact up to the printing of numbers
 * (each within tol/4). Others become cubic Hermite pieces, halved until a
 * rigorous bound (Bernstein coefficients of the error numerator over the
 * smallest weight) is within tol/2; the bound holds at equal parameter, so
 * it also bounds the distance between the traces. *err_bound adds the
 * printing error actually committed; it exceeds tol only when tol is below
 * rounding (~1e-15 of the coordinates) or the output reached its piece cap
 * (2,000,000). tol <= 0: numbers round-trip exactly and approximations aim
 * at 1e-9 of the largest coordinate. */
char *api_svg_path_d(const km_curve *c, double tol, double *err_bound);

/* Same, with a fixed number of cubic pieces (n_pieces >= 1), so that paths
 * of every frame share one command structure (for SMIL / CSS animation).
 * Piece ends are uniform in arc length and lie on the curve; each piece is
 * the cubic Hermite interpolant of its stretch (a shape approximation, no
 * bound stated); coordinates are printed to 1e-6 of the curve's extent. */
char *api_svg_path_d_fixed(const km_curve *c, size_t n_pieces);

typedef enum api_svg_layout {
  API_SVG_FILMSTRIP,
  API_SVG_OVERLAY,
  API_SVG_ANIMATE,
  API_SVG_CURVATURE_PLOT
} api_svg_layout;

typedef struct api_svg_options {
  api_svg_layout layout;
  double width, height;   /* document size in px; <= 0: automatic */
  double stroke_width;    /* <= 0: automatic */
  const char *stroke;     /* colour of single-colour layouts, or NULL */
  const char *from_color; /* colour ramp start (overlay, plot), or NULL */
  const char *to_color;   /* colour ramp end, or NULL */
  double duration;        /* seconds, animate layout; <= 0: 2 s */
} api_svg_options;

typedef struct api_svg_frame {
  double t;
  const km_curve *curve;
  const km_signature *sig; /* for curvature plots; may be NULL */
} api_svg_frame;

/* A complete, well-formed SVG document of a morph. NULL on out-of-memory. */
char *api_svg_morph_document(const api_svg_frame *frames, size_t n,
                             const api_svg_options *opt);

/* A frame of a compound morph for its document. */
typedef struct api_svg_shape_frame {
  double t;
  const km_shape_frame *shape;
  km_fill_rule fill; /* the rule its path is filled under */
} api_svg_shape_frame;

/* A compound morph as its document draws it: n frames of nslots slots,
 * what each slot pairs, and where a collapsed slot is a point. */
typedef struct api_svg_shape_morph {
  const api_svg_shape_frame *frames;
  size_t n;
  size_t nslots;
  const km_shape_pair *pairs; /* nslots: the contours each slot morphs */
  const double *collapse;     /* 2 per slot: a collapsed contour's point,
                                 NaN for a paired slot */
} api_svg_shape_morph;

/* A complete, well-formed SVG document of a compound morph in opt's
 * layout (NULL: a filmstrip with defaults). Shapes are filled under each
 * frame's fill rule and stroked: the filmstrip one filled path a frame
 * (opt->stroke at 35% opacity), the overlay every frame's path along the
 * colour ramp (12% opacity), the animation one path whose <animate> of
 * "d" has one value a frame, all of one command structure (a collapsed
 * contour drawn at its point, see api_svg_shape_frame_d; the fill rule
 * switched discretely where it changes), and the curvature plot one
 * labelled panel per slot with a trace per frame where its contour is
 * present. NULL on out-of-memory. */
char *api_svg_shape_document(const api_svg_shape_morph *m,
                             const api_svg_options *opt);

/* As api_svg_path_d_fixed, with the closing "Z" written when with_z is true
 * whatever c->closed says: frames of one animation must agree on it. */
char *api_svg_path_d_fixed_z(const km_curve *c, size_t n_pieces, bool with_z);

/* A closed path of n_pieces (>= 1) cubic pieces all at the point p, with
 * the commands api_svg_path_d_fixed_z writes for a closed curve: what an
 * animation draws for a contour collapsed to p, so that interpolating it
 * with the contour's live frames grows or shrinks it from p. */
char *api_svg_point_d(const double p[2], size_t n_pieces);

/* One frame of a compound animation: every slot of sf with pieces[k]
 * pieces and its Z, a slot collapsed to a point written by
 * api_svg_point_d at (collapse[2k], collapse[2k + 1]) (a slot without a
 * collapse point, NaN, is left out), the subpaths joined by spaces. Frames
 * of one morph so written share one command structure. NULL on
 * out-of-memory. */
char *api_svg_shape_frame_d(const km_shape_frame *sf, const size_t *pieces,
                            const double *collapse);

/* ---- internal helpers shared by the SVG writers ---- */

/* A growing NUL-terminated string; after an allocation failure every
 * append is a no-op and api__svg_buf_take returns NULL. */
typedef struct api_svg_buf {
  char *s;
  size_t len, cap;
  bool failed;
} api_svg_buf;

void api__svg_buf_init(api_svg_buf *b);
void api__svg_buf_free(api_svg_buf *b);
void api__svg_buf_put(api_svg_buf *b, const char *str);
/* n bytes of str (no NUL among them needed). */
void api__svg_buf_put_n(api_svg_buf *b, const char *str, size_t n);
/* Room for n more bytes and a NUL at the end of the string: where to
 * write them (the writer then adds what it wrote to len and keeps the
 * NUL), or NULL after a failure. */
char *api__svg_buf_room(api_svg_buf *b, size_t n);
void api__svg_buf_printf(api_svg_buf *b, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
/* Text with the XML special characters escaped (&<>"'); bytes below 0x20
 * other than tab/newline become spaces so the document stays well-formed. */
void api__svg_buf_escaped(api_svg_buf *b, const char *text);
/* The shortest decimal form of x that reads back within budget (>= 0; 0
 * means exact round-trip); *err (may be NULL) is raised to the error
 * actually committed. Non-finite x is written as 0. C locale assumed. */
void api__svg_buf_num(api_svg_buf *b, double x, double budget, double *err);
/* The string (caller frees), or NULL after a failure; b is emptied. */
char *api__svg_buf_take(api_svg_buf *b);

#endif
