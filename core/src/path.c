/* path.c - path builder: Bezier pieces and SVG elliptical arcs chained into
 * one exact B-spline or NURBS curve.
 *
 * DESIGN. Pieces are stored exactly as given (arcs as rational quadratics
 * in the standard form w = 1, cos(a/2), 1, which makes every piece's end
 * weights 1 so that pieces share their junction control point and weight
 * without rescaling). km_path_to_curve elevates every piece to the largest
 * degree present, in homogeneous coordinates when rational, and lays the
 * pieces out with interior knot multiplicity = degree at 1, 2, 3, ...
 * Nothing is approximated, so the curve traces exactly the path drawn.
 */
#include "km/path.h"

#include <math.h>
#include <string.h>

#include "internal.h"
#include "km/alloc.h"
#include "km/limits.h"

void km_path_init(km_path *p) {
  if (!p) return;
  memset(p, 0, sizeof *p);
}

void km_path_free(km_path *p) {
  if (!p) return;
  km__free(p->pieces);
  km_path_init(p);
}

void km_path_current(const km_path *p, double pt[2]) {
  pt[0] = p->cur[0];
  pt[1] = p->cur[1];
}

/* Coordinates must be finite and within the representable range; idx is
 * the argument index reported in err->index. */
static km_status check_coord(double v, long idx, km_error *err) {
  if (!isfinite(v))
    return km__fail(err, KM_ENONFINITE, KM_FIELD_CONTROL_POINTS, idx, NAN,
                    "coordinate is not finite");
  if (fabs(v) > KM_MAX_COORDINATE)
    return km__fail(err, KM_ERANGE, KM_FIELD_CONTROL_POINTS, idx, NAN,
                    "coordinate %g exceeds the limit %g", v, KM_MAX_COORDINATE);
  return KM_OK;
}

static km_status check_coords(const double *v, int n, km_error *err) {
  for (int i = 0; i < n; i++) {
    km_status st = check_coord(v[i], i, err);
    if (st) return st;
  }
  return KM_OK;
}

static km_status check_open(const km_path *p, km_error *err) {
  if (!p->started)
    return km__fail(err, KM_EINVAL, KM_FIELD_NONE, -1, NAN,
                    "path has no start point");
  if (p->closed)
    return km__fail(err, KM_EINVAL, KM_FIELD_NONE, -1, NAN,
                    "path is closed: one subpath only");
  return KM_OK;
}

/* Append a piece whose first control point is the current point. */
static km_status push(km_path *p, const km_path_piece *pc, km_error *err) {
  if (p->npieces == p->cap) {
    size_t cap = p->cap ? 2 * p->cap : 16;
    if (cap > KM_MAX_PIECES) cap = KM_MAX_PIECES;
    if (p->npieces >= cap)
      return km__fail(err, KM_ELIMIT, KM_FIELD_NONE, -1, NAN,
                      "path has more than %zu pieces", (size_t)KM_MAX_PIECES);
    km_path_piece *np = km__realloc(p->pieces, cap * sizeof *np);
    if (!np) return km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
    p->pieces = np;
    p->cap = cap;
  }
  p->pieces[p->npieces++] = *pc;
  p->cur[0] = pc->p[pc->degree][0];
  p->cur[1] = pc->p[pc->degree][1];
  return KM_OK;
}

static void piece_poly(km_path_piece *pc, int degree, const double *pts,
                       const double cur[2]) {
  memset(pc, 0, sizeof *pc);
  pc->degree = degree;
  pc->p[0][0] = cur[0];
  pc->p[0][1] = cur[1];
  for (int i = 1; i <= degree; i++) {
    pc->p[i][0] = pts[2 * (i - 1)];
    pc->p[i][1] = pts[2 * (i - 1) + 1];
  }
  for (int i = 0; i < 4; i++) pc->w[i] = 1.0;
}

km_status km_path_move_to(km_path *p, double x, double y, km_error *err) {
  if (p->started)
    return km__fail(err, KM_EINVAL, KM_FIELD_NONE, -1, NAN,
                    "path already has a start point: one subpath only");
  double v[2] = {x, y};
  km_status st = check_coords(v, 2, err);
  if (st) return st;
  p->started = true;
  p->start[0] = p->cur[0] = x;
  p->start[1] = p->cur[1] = y;
  return KM_OK;
}

static km_status poly_to(km_path *p, int degree, const double *v,
                         km_error *err) {
  km_status st = check_open(p, err);
  if (st) return st;
  st = check_coords(v, 2 * degree, err);
  if (st) return st;
  km_path_piece pc;
  piece_poly(&pc, degree, v, p->cur);
  return push(p, &pc, err);
}

km_status km_path_line_to(km_path *p, double x, double y, km_error *err) {
  double v[2] = {x, y};
  return poly_to(p, 1, v, err);
}

km_status km_path_quad_to(km_path *p, double x1, double y1, double x, double y,
                          km_error *err) {
  double v[4] = {x1, y1, x, y};
  return poly_to(p, 2, v, err);
}

km_status km_path_cubic_to(km_path *p, double x1, double y1, double x2,
                           double y2, double x, double y, km_error *err) {
  double v[6] = {x1, y1, x2, y2, x, y};
  return poly_to(p, 3, v, err);
}

/* Angle from u to v (SVG F.6.5.4), in (-pi, pi]. */
static double vec_angle(double ux, double uy, double vx, double vy) {
  return atan2(ux * vy - uy * vx, ux * vx + uy * vy);
}

/* An SVG arc in centre parameterisation (F.6.5): centre, radii (scaled
 * up where they cannot reach the end point), rotation, start angle and
 * sweep. */
typedef struct arc_centre {
  double cx, cy, rx, ry, cphi, sphi, theta1, dtheta;
} arc_centre;

/* The arc from (x1, y1) to (x, y) of positive radii rx, ry in centre form;
 * KM_ERANGE when it cannot be computed in double precision. */
static km_status arc_to_centre(double x1, double y1, double rx, double ry,
                               double x_rot_deg, bool large_arc, bool sweep,
                               double x, double y, arc_centre *ac,
                               km_error *err) {
  double phi = fmod(x_rot_deg, 360.0) * (KM_PI / 180.0);
  double cphi = cos(phi), sphi = sin(phi);
  /* F.6.5.1 */
  double dx2 = 0.5 * (x1 - x), dy2 = 0.5 * (y1 - y);
  double x1p = cphi * dx2 + sphi * dy2;
  double y1p = -sphi * dx2 + cphi * dy2;
  /* F.6.6.2: scale radii up until the ellipse reaches the end point. */
  double lx = x1p / rx, ly = y1p / ry;
  double lambda = lx * lx + ly * ly;
  bool scaled = lambda > 1.0;
  if (scaled) {
    double sl = sqrt(lambda);
    rx *= sl;
    ry *= sl;
  }
  if (!isfinite(rx) || !isfinite(ry) || !isfinite(lambda))
    return km__fail(err, KM_ERANGE, KM_FIELD_CONTROL_POINTS, 0, NAN,
                    "arc radii out of range");
  /* F.6.5.2: centre in the rotated frame. Scaled radii put the centre at
   * the chord's midpoint exactly: the radicand is then 0, and computing it
   * would leave rounding noise whose square root (~1e-8) moves the centre. */
  double rx2 = rx * rx, ry2 = ry * ry;
  double num = rx2 * ry2 - rx2 * y1p * y1p - ry2 * x1p * x1p;
  double den = rx2 * y1p * y1p + ry2 * x1p * x1p;
  double coef = (!scaled && num > 0.0 && den > 0.0) ? sqrt(num / den) : 0.0;
  if (large_arc == sweep) coef = -coef;
  double cxp = coef * rx * y1p / ry;
  double cyp = -coef * ry * x1p / rx;
  /* F.6.5.3 */
  double cx = cphi * cxp - sphi * cyp + 0.5 * (x1 + x);
  double cy = sphi * cxp + cphi * cyp + 0.5 * (y1 + y);
  /* F.6.5.5-6 */
  double ux = (x1p - cxp) / rx, uy = (y1p - cyp) / ry;
  double vx = (-x1p - cxp) / rx, vy = (-y1p - cyp) / ry;
  double theta1 = atan2(uy, ux);
  double dtheta = vec_angle(ux, uy, vx, vy);
  if (!sweep && dtheta > 0)
    dtheta -= 2.0 * KM_PI;
  else if (sweep && dtheta < 0)
    dtheta += 2.0 * KM_PI;
  if (!isfinite(cx) || !isfinite(cy) || !isfinite(dtheta))
    return km__fail(err, KM_ERANGE, KM_FIELD_CONTROL_POINTS, 0, NAN,
                    "arc cannot be computed");
  *ac = (arc_centre){cx, cy, rx, ry, cphi, sphi, theta1, dtheta};
  return KM_OK;
}

/* The arc as nseg rational quadratic pieces of at most 90 degrees each,
 * starting exactly at (x1, y1) and ending exactly at (x, y). */
static km_status arc_pieces(const arc_centre *ac, double x1, double y1,
                            double x, double y, km_path_piece pcs[5],
                            int *nseg_out, km_error *err) {
  /* the small allowance keeps an exact quarter from becoming two pieces
   * through rounding */
  int nseg = (int)ceil(fabs(ac->dtheta) / (0.5 * KM_PI) - 1e-9);
  if (nseg < 1) nseg = 1;
  double delta = ac->dtheta / nseg;
  double wmid = cos(0.5 * delta);
  for (int k = 0; k < nseg; k++) {
    double a0 = ac->theta1 + k * delta, a1 = ac->theta1 + (k + 1) * delta;
    double am = 0.5 * (a0 + a1);
    double uv[3][2] = {{cos(a0), sin(a0)},
                       {cos(am) / wmid, sin(am) / wmid},
                       {cos(a1), sin(a1)}};
    km_path_piece *pc = &pcs[k];
    memset(pc, 0, sizeof *pc);
    pc->degree = 2;
    pc->rational = true;
    pc->w[0] = 1.0;
    pc->w[1] = wmid;
    pc->w[2] = 1.0;
    pc->w[3] = 1.0;
    for (int j = 0; j < 3; j++) {
      double ex = ac->rx * uv[j][0], ey = ac->ry * uv[j][1];
      pc->p[j][0] = ac->cx + ac->cphi * ex - ac->sphi * ey;
      pc->p[j][1] = ac->cy + ac->sphi * ex + ac->cphi * ey;
    }
    /* Exact junctions: the path's points, not their recomputation. */
    if (k == 0) {
      pc->p[0][0] = x1;
      pc->p[0][1] = y1;
    } else {
      pc->p[0][0] = pcs[k - 1].p[2][0];
      pc->p[0][1] = pcs[k - 1].p[2][1];
    }
    if (k == nseg - 1) {
      pc->p[2][0] = x;
      pc->p[2][1] = y;
    }
    for (int j = 0; j < 3; j++) {
      km_status st = check_coords(pc->p[j], 2, err);
      if (st) return st;
    }
  }
  *nseg_out = nseg;
  return KM_OK;
}

km_status km_path_arc_to(km_path *p, double rx, double ry, double x_rot_deg,
                         bool large_arc, bool sweep, double x, double y,
                         km_error *err) {
  km_status st = check_open(p, err);
  if (st) return st;
  double args[5] = {rx, ry, x_rot_deg, x, y};
  for (int i = 0; i < 5; i++)
    if (!isfinite(args[i]))
      return km__fail(err, KM_ENONFINITE, KM_FIELD_CONTROL_POINTS, i, NAN,
                      "arc argument is not finite");
  for (int i = 0; i < 2; i++) {
    st = check_coord(args[i], i, err);
    if (st) return st;
  }
  double v[2] = {x, y};
  st = check_coords(v, 2, err);
  if (st) return st;

  double x1 = p->cur[0], y1 = p->cur[1];
  /* F.6.2: identical end points omit the arc; zero radius is a line. */
  if (x1 == x && y1 == y) return KM_OK;
  rx = fabs(rx);
  ry = fabs(ry);
  if (rx == 0.0 || ry == 0.0) return km_path_line_to(p, x, y, err);
  arc_centre ac = {0, 0, 0, 0, 0, 0, 0, 0};
  st = arc_to_centre(x1, y1, rx, ry, x_rot_deg, large_arc, sweep, x, y, &ac,
                     err);
  if (st) return st;
  km_path_piece pcs[5];
  int nseg = 0;
  st = arc_pieces(&ac, x1, y1, x, y, pcs, &nseg, err);
  if (st) return st;
  for (int k = 0; k < nseg; k++) {
    st = push(p, &pcs[k], err);
    if (st) return st;
  }
  return KM_OK;
}

km_status km_path_close(km_path *p, km_error *err) {
  km_status st = check_open(p, err);
  if (st) return st;
  if (p->cur[0] != p->start[0] || p->cur[1] != p->start[1]) {
    st = km_path_line_to(p, p->start[0], p->start[1], err);
    if (st) return st;
  }
  p->closed = true;
  return KM_OK;
}

/* Elevate a (possibly rational) Bezier piece in homogeneous coordinates
 * from its degree to `deg`: out[i] = (w x, w y, w). */
static void elevate_h(const km_path_piece *pc, int deg, double out[][3]) {
  double h[10][3];
  int d = pc->degree;
  for (int i = 0; i <= d; i++) {
    h[i][0] = pc->w[i] * pc->p[i][0];
    h[i][1] = pc->w[i] * pc->p[i][1];
    h[i][2] = pc->w[i];
  }
  while (d < deg) {
    double g[10][3];
    for (int k = 0; k < 3; k++) {
      g[0][k] = h[0][k];
      g[d + 1][k] = h[d][k];
    }
    for (int i = 1; i <= d; i++) {
      double a = (double)i / (d + 1);
      for (int k = 0; k < 3; k++)
        g[i][k] = a * h[i - 1][k] + (1.0 - a) * h[i][k];
    }
    d++;
    memcpy(h, g, sizeof h);
  }
  for (int i = 0; i <= deg; i++)
    for (int k = 0; k < 3; k++) out[i][k] = h[i][k];
}

static bool within(const double a[2], const double b[2], double eps) {
  return fabs(a[0] - b[0]) <= eps && fabs(a[1] - b[1]) <= eps &&
         hypot(a[0] - b[0], a[1] - b[1]) <= eps;
}

/* The path's pieces without those that are points (within eps of the end
 * so far), each starting exactly where the last kept one ends; a closed
 * path's last piece ends exactly at the first's start. Returns the number
 * kept. */
static size_t drawn_pieces(const km_path *p, double eps, km_path_piece *kept) {
  size_t m = 0;
  double end[2] = {p->start[0], p->start[1]};
  for (size_t i = 0; i < p->npieces; i++) {
    const km_path_piece *pc = &p->pieces[i];
    bool point = true;
    for (int j = 0; j <= pc->degree && point; j++)
      point = eps > 0.0 ? within(pc->p[j], end, eps)
                        : (pc->p[j][0] == end[0] && pc->p[j][1] == end[1]);
    if (point) continue;
    kept[m] = *pc;
    kept[m].p[0][0] = end[0];
    kept[m].p[0][1] = end[1];
    end[0] = pc->p[pc->degree][0];
    end[1] = pc->p[pc->degree][1];
    m++;
  }
  /* A closed path ends where it starts; a dropped closing piece left at
   * most eps between them. */
  if (p->closed && m > 0) {
    kept[m - 1].p[kept[m - 1].degree][0] = kept[0].p[0][0];
    kept[m - 1].p[kept[m - 1].degree][1] = kept[0].p[0][1];
  }
  return m;
}

/* Knots (piece i over [i, i + 1], interior knots of multiplicity deg),
 * control points and weights (w NULL without) of the m pieces elevated to
 * degree deg. */
static void pieces_to_bspline(const km_path_piece *kept, size_t m, int deg,
                              double *knots, double *cp, double *w) {
  size_t k = 0;
  for (int j = 0; j <= deg; j++) knots[k++] = 0.0;
  for (size_t i = 1; i < m; i++)
    for (int j = 0; j < deg; j++) knots[k++] = (double)i;
  for (int j = 0; j <= deg; j++) knots[k++] = (double)m;
  for (size_t i = 0; i < m; i++) {
    double h[10][3];
    elevate_h(&kept[i], deg, h);
    for (int j = (i == 0 ? 0 : 1); j <= deg; j++) {
      size_t idx = i * (size_t)deg + (size_t)j;
      /* Polynomial pieces keep weight 1 exactly, also inside a NURBS. */
      double wj = kept[i].rational ? h[j][2] : 1.0;
      /* Ends of every piece have weight 1 exactly: copy them verbatim so
       * junctions are bit-for-bit the path's points. */
      if (j == 0 || j == deg) {
        cp[2 * idx] = kept[i].p[kept[i].degree * (j == deg)][0];
        cp[2 * idx + 1] = kept[i].p[kept[i].degree * (j == deg)][1];
      } else {
        cp[2 * idx] = h[j][0] / wj;
        cp[2 * idx + 1] = h[j][1] / wj;
      }
      if (w) w[idx] = wj;
    }
  }
}

km_status km_path_to_curve(const km_path *p, double eps, km_curve *out,
                           km_error *err) {
  km_status st = KM_OK;
  double *knots = NULL, *cp = NULL, *w = NULL;
  km_path_piece *kept = NULL;
  if (!(eps >= 0.0) || !isfinite(eps)) eps = 0.0;
  if (!p->started || p->npieces == 0)
    return km__fail(err, KM_EDEGENERATE, KM_FIELD_CONTROL_POINTS, -1, NAN,
                    "path draws nothing");
  kept = km__malloc(p->npieces * sizeof *kept);
  if (!kept) return km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
  size_t m = drawn_pieces(p, eps, kept);
  if (m == 0) {
    st = km__fail(err, KM_EDEGENERATE, KM_FIELD_CONTROL_POINTS, -1, NAN,
                  "path has zero length");
    goto cleanup;
  }
  int deg = 1;
  bool rational = false;
  for (size_t i = 0; i < m; i++) {
    if (kept[i].degree > deg) deg = kept[i].degree;
    if (kept[i].rational) rational = true;
  }
  size_t n = m * (size_t)deg + 1;
  size_t nk = n + (size_t)deg + 1;
  knots = km__malloc(nk * sizeof *knots);
  cp = km__malloc(2 * n * sizeof *cp);
  if (rational) w = km__malloc(n * sizeof *w);
  if (!knots || !cp || (rational && !w)) {
    st = km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
    goto cleanup;
  }
  pieces_to_bspline(kept, m, deg, knots, cp, w);
  st = km_curve_create(out, deg, n, knots, cp, w, p->closed, err);
cleanup:
  km__free(kept);
  km__free(knots);
  km__free(cp);
  km__free(w);
  return st;
}
