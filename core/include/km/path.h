/* path.h - a pure-geometry path builder: lines, quadratic and cubic Beziers
 * and elliptical arcs chained from a start point into one km_curve.
 *
 * DESIGN. The builder records Bezier pieces (degree 1..3, arcs as rational
 * quadratics of at most 90 degrees each) exactly as given; nothing is
 * approximated. km_path_to_curve raises every piece to the common degree
 * (rational if any arc), joins them with interior knots of multiplicity
 * `degree` at the piece indices 0, 1, 2, ... and marks the curve closed when
 * the path was closed. Arcs use the SVG endpoint parameterisation, converted
 * to centre form per SVG 1.1 implementation notes F.6.5, with out-of-range
 * radii scaled up per F.6.6 and a zero radius meaning a straight line.
 *
 * Ownership: a km_path owns one growing heap array of pieces.
 * km_path_init() gives an empty builder, km_path_free() accepts NULL and
 * empty builders. A builder is used by one thread at a time; the curve it
 * produces is an ordinary immutable km_curve. The builder p of each call
 * is in/out: a call that fails leaves it as it was (km_path_arc_to
 * excepted, below). The conventions of km/kmorph.h hold.
 */
#ifndef KM_PATH_H
#define KM_PATH_H

#include "km/export.h"

#include <stdbool.h>
#include <stddef.h>

#include "km/curve.h"
#include "km/status.h"

/* One recorded piece: a Bezier of degree 1..3 (p[0..degree]) with weights
 * (all 1 for polynomial pieces; arcs have w = 1, cos(a/2), 1). */
typedef struct km_path_piece {
  int degree;
  double p[4][2];
  double w[4];
  bool rational;
} km_path_piece;

typedef struct km_path {
  bool started;    /* a start point was set */
  bool closed;     /* km_path_close was called */
  double start[2]; /* start point of the path */
  double cur[2];   /* current point */
  size_t npieces, cap;
  km_path_piece *pieces;
} km_path;

/* Make *p an empty builder (no start point, no pieces). Allocates nothing. */
KM_API void km_path_init(km_path *p);

/* Free the pieces and leave *p empty; p may be NULL or empty. */
KM_API void km_path_free(km_path *p);

/* Set the start point (and current point). Allowed once, before any piece.
 * Returns KM_OK, KM_EINVAL if called again or after close; KM_ENONFINITE /
 * KM_ERANGE (|coordinate| > KM_MAX_COORDINATE) for bad coordinates
 * (KM_FIELD_CONTROL_POINTS, err->index 0 for x, 1 for y). */
KM_API km_status km_path_move_to(km_path *p, double x, double y, km_error *err);

/* Append a straight line / quadratic / cubic Bezier from the current point;
 * the last point becomes the current point. Returns KM_OK, KM_EINVAL if
 * the path has no start point or is closed; KM_ENONFINITE / KM_ERANGE for
 * coordinates (KM_FIELD_CONTROL_POINTS, err->index the coordinate
 * argument at fault, 0-based: x1 is 0, y1 is 1, ...); KM_ELIMIT beyond
 * KM_MAX_PIECES pieces; KM_ENOMEM. */
KM_API km_status km_path_line_to(km_path *p, double x, double y, km_error *err);
KM_API km_status km_path_quad_to(km_path *p, double x1, double y1, double x,
                                 double y, km_error *err);
KM_API km_status km_path_cubic_to(km_path *p, double x1, double y1, double x2,
                                  double y2, double x, double y, km_error *err);

/* Append an elliptical arc to (x, y) in SVG endpoint parameterisation:
 * radii rx, ry (signs ignored), x-axis rotation in degrees, the two flags.
 * Radii too small to reach the end point are scaled up (F.6.6); a zero
 * radius makes a straight line; an end point equal to the current point
 * adds nothing. The arc is recorded exactly as rational quadratic pieces of
 * at most 90 degrees. Statuses as km_path_line_to (KM_FIELD_CONTROL_POINTS),
 * with err->index as follows: KM_ENONFINITE names the argument (0 rx,
 * 1 ry, 2 x_rot_deg, 3 x, 4 y); KM_ERANGE gives 0 or 1, the x or y of rx
 * and ry, of the end point or of a computed control point (a very
 * eccentric ellipse), which the index does not tell apart. On KM_ELIMIT or
 * KM_ENOMEM the pieces of the arc recorded before the failure stay in p:
 * free the builder rather than go on. */
KM_API km_status km_path_arc_to(km_path *p, double rx, double ry,
                                double x_rot_deg, bool large_arc, bool sweep,
                                double x, double y, km_error *err);

/* Close the path: a straight line back to the start point when the current
 * point is elsewhere. Further pieces are refused. Returns KM_OK, KM_EINVAL
 * without a start point or when already closed, and km_path_line_to's
 * KM_ELIMIT / KM_ENOMEM for the closing line. */
KM_API km_status km_path_close(km_path *p, km_error *err);

/* Current point into pt (out): the end of the last piece, the start
 * point before any piece, (0, 0) before km_path_move_to. */
KM_API void km_path_current(const km_path *p, double pt[2]);

/* Build the curve. A piece whose control points all lie within eps (>= 0)
 * of the end of the previous kept piece is dropped (eps = 0: only pieces
 * that are a single point), and the next piece is attached to that end;
 * the shape moves by at most eps. A closed path ends exactly at its start.
 * Zero-length control legs are kept as given. eps < 0 or not finite is
 * taken as 0. Returns KM_OK, KM_EDEGENERATE (no start point, no pieces, or nothing
 * left; KM_FIELD_CONTROL_POINTS), KM_ENOMEM, or a km_curve_create status.
 * *out is owned by the caller (km_curve_free); p is not changed. */
KM_API km_status km_path_to_curve(const km_path *p, double eps, km_curve *out,
                                  km_error *err);

#endif
