/* json_out.c - core types to JSON: curves and signatures as the contract
 * spells them, refusing to print a non-finite number.
 *
 * cJSON prints NaN and infinities as null, which would silently break the
 * contract ("numbers are JSON numbers"), so every number goes through
 * api__add_num / api__num_array_json, which check it first.
 *
 * Numbers are printed here, not by cJSON: cJSON 1.7.15 prints %1.15g when
 * that reads back within DBL_EPSILON *relative*, which loses the last bit
 * (0.1 + 0.2 comes out as 0.3). We print the shortest decimal that reads
 * back exactly (num_print.c) and hand cJSON the text as a raw item.
 */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "json_write.h"
#include "km/alloc.h"
#include "num_print.h"
#include "svg.h"

/* The precision api/openapi.yaml promises for a curve's `length`. */
#define LENGTH_REL_TOL 1e-12

cJSON *api__number(double v) {
  char buf[API_NUM_PRINT_MAX];
  api__num_print(buf, v);
  return cJSON_CreateRaw(buf);
}

/* [x, y] */
static cJSON *pair(const double *v) {
  cJSON *a = cJSON_CreateArray(), *x, *y;
  if (a == NULL) return NULL;
  x = api__number(v[0]);
  if (x != NULL) cJSON_AddItemToArray(a, x);
  y = api__number(v[1]);
  if (y != NULL) cJSON_AddItemToArray(a, y);
  if (x == NULL || y == NULL) {
    cJSON_Delete(a);
    return NULL;
  }
  return a;
}

static bool nonfinite(api_ctx *ctx, const char *what) {
  return api__failf(ctx, 422, API_P_NO_CONVERGE, "Computation did not converge",
                    NULL,
                    "the computation produced a non-finite %s; try another "
                    "tolerance or simpler input",
                    what);
}

bool api__add_item(api_ctx *ctx, cJSON *obj, const char *key, cJSON *item) {
  /* cJSON copies the key, and when that copy fails the item stays ours */
  if (cJSON_AddItemToObject(obj, key, item)) return true;
  cJSON_Delete(item);
  return api__oom(ctx);
}

bool api__add_num(api_ctx *ctx, cJSON *obj, const char *key, double v) {
  if (!isfinite(v)) return nonfinite(ctx, key);
  cJSON *n = api__number(v);
  if (n == NULL) return api__oom(ctx);
  return api__add_item(ctx, obj, key, n);
}

/* n values (stride 1) or n points (stride 2) as a JSON array. */
cJSON *api__num_array_json(api_ctx *ctx, const double *v, size_t n,
                           size_t stride) {
  cJSON *a = cJSON_CreateArray();
  if (a == NULL) {
    api__oom(ctx);
    return NULL;
  }
  for (size_t i = 0; i < n; i++) {
    cJSON *e;
    if (stride == 1) {
      if (!isfinite(v[i])) goto nonfinite_value;
      e = api__number(v[i]);
    } else {
      if (!isfinite(v[2 * i]) || !isfinite(v[2 * i + 1])) goto nonfinite_value;
      e = pair(&v[2 * i]);
    }
    if (e == NULL) {
      cJSON_Delete(a);
      api__oom(ctx);
      return NULL;
    }
    cJSON_AddItemToArray(a, e);
  }
  return a;
nonfinite_value:
  cJSON_Delete(a);
  nonfinite(ctx, "coordinate");
  return NULL;
}

static bool add_array(api_ctx *ctx, cJSON *obj, const char *key,
                      const double *v, size_t n, size_t stride) {
  cJSON *a = api__num_array_json(ctx, v, n, stride);
  if (a == NULL) return false;
  return api__add_item(ctx, obj, key, a);
}

cJSON *api__signature_json(api_ctx *ctx, const km_signature *sig) {
  cJSON *o = cJSON_CreateObject();
  cJSON *start, *kappa, *corners;
  if (o == NULL) {
    api__oom(ctx);
    return NULL;
  }
  if (!api__add_num(ctx, o, "length", sig->length)) goto fail;
  start = cJSON_AddObjectToObject(o, "start");
  if (start == NULL) {
    api__oom(ctx);
    goto fail;
  }
  if (!isfinite(sig->start[0]) || !isfinite(sig->start[1])) {
    nonfinite(ctx, "start point");
    goto fail;
  }
  {
    cJSON *pt = pair(sig->start);
    if (pt == NULL) {
      api__oom(ctx);
      goto fail;
    }
    if (!api__add_item(ctx, start, "point", pt)) goto fail;
  }
  if (!api__add_num(ctx, start, "angle", sig->angle)) goto fail;
  kappa = cJSON_AddObjectToObject(o, "kappa");
  if (kappa == NULL) {
    api__oom(ctx);
    goto fail;
  }
  if (!api__add_num(ctx, kappa, "degree", sig->kappa.degree) ||
      !add_array(ctx, kappa, "knots", sig->kappa.knots,
                 sig->kappa.n + (size_t)sig->kappa.degree + 1, 1) ||
      !add_array(ctx, kappa, "coefficients", sig->kappa.coef, sig->kappa.n, 1))
    goto fail;
  corners = cJSON_AddArrayToObject(o, "corners");
  if (corners == NULL) {
    api__oom(ctx);
    goto fail;
  }
  for (size_t i = 0; i < sig->ncorners; i++) {
    cJSON *c = cJSON_CreateObject();
    if (c == NULL) {
      api__oom(ctx);
      goto fail;
    }
    cJSON_AddItemToArray(corners, c);
    if (!api__add_num(ctx, c, "s", sig->corners[i].s) ||
        !api__add_num(ctx, c, "turn", sig->corners[i].turn))
      goto fail;
  }
  if (!api__add_num(ctx, o, "turning", sig->turning)) goto fail;
  if (cJSON_AddBoolToObject(o, "closed", sig->closed) == NULL) {
    api__oom(ctx);
    goto fail;
  }
  return o;
fail:
  cJSON_Delete(o);
  return NULL;
}

/* ------------------------------------- straight into a growing buffer */

bool api__json_num(api_ctx *ctx, api_svg_buf *b, double v, const char *what) {
  if (!isfinite(v)) return nonfinite(ctx, what);
  char *at = api__svg_buf_room(b, API_NUM_PRINT_MAX);
  if (at != NULL) b->len += api__num_print(at, v);
  return true;
}

void api__json_string(api_svg_buf *b, const char *s) {
  static const char hex[] = "0123456789abcdef";
  const unsigned char *p = (const unsigned char *)s, *run = p;
  API_JSON_LIT(b, "\"");
  for (; *p != '\0'; p++) {
    char esc[6] = {'\\', 'u', '0', '0', 0, 0};
    size_t n = 2;
    if (*p >= 0x20 && *p != '"' && *p != '\\') continue;
    api__json_raw(b, (const char *)run, (size_t)(p - run));
    run = p + 1;
    switch (*p) {
    case '"': esc[1] = '"'; break;
    case '\\': esc[1] = '\\'; break;
    case '\b': esc[1] = 'b'; break;
    case '\f': esc[1] = 'f'; break;
    case '\n': esc[1] = 'n'; break;
    case '\r': esc[1] = 'r'; break;
    case '\t': esc[1] = 't'; break;
    default:
      esc[4] = hex[*p >> 4];
      esc[5] = hex[*p & 15];
      n = 6;
    }
    api__json_raw(b, esc, n);
  }
  api__json_raw(b, (const char *)run, (size_t)(p - run));
  API_JSON_LIT(b, "\"");
}

/* v[0 .. count) as [a,b,...] at p; a number with the same bits as the
 * one before it (every knot of a Hermite frame is double, the ends'
 * fourfold) is copied, not printed again. Returns the end, or NULL at
 * the first non-finite number. */
static char *put_values(char *p, const double *v, size_t count) {
  const char *last = NULL;
  size_t last_len = 0;
  *p++ = '[';
  for (size_t i = 0; i < count; i++) {
    if (!isfinite(v[i])) return NULL;
    *p = ',';
    p += i > 0 ? 1 : 0;
    if (i > 0 && memcmp(&v[i], &v[i - 1], sizeof *v) == 0) {
      /* by way of a buffer: the number before is the last thing
       * written, so the two places overlap; a fixed-size copy costs
       * less than an exact one and a number has at most 24 bytes */
      char copy[API_NUM_PRINT_MAX];
      memcpy(copy, last, 24);
      memcpy(p, copy, 24);
    } else {
      last_len = api__num_print(p, v[i]);
    }
    last = p;
    p += last_len;
  }
  *p++ = ']';
  return p;
}

/* n points (x, y) at v as [[x,y],...] at p. Returns the end, or NULL at
 * the first non-finite coordinate. */
static char *put_points(char *p, const double *v, size_t n) {
  *p++ = '[';
  for (size_t i = 0; i < n; i++) {
    if (!isfinite(v[2 * i]) || !isfinite(v[2 * i + 1])) return NULL;
    *p = ',';
    p += i > 0 ? 1 : 0;
    *p++ = '[';
    p += api__num_print(p, v[2 * i]);
    *p++ = ',';
    p += api__num_print(p, v[2 * i + 1]);
    *p++ = ']';
  }
  *p++ = ']';
  return p;
}

bool api__json_nums(api_ctx *ctx, api_svg_buf *b, const double *v, size_t n,
                    size_t stride) {
  size_t count = n * stride;
  if (count > SIZE_MAX / (2 * API_NUM_PRINT_MAX)) return api__oom(ctx);
  /* the whole array's room at once: a number (printed into room for
   * API_NUM_PRINT_MAX bytes), its comma and brackets */
  char *at = api__svg_buf_room(b, 2 + count * (API_NUM_PRINT_MAX + 2));
  if (at == NULL) return true;
  char *end = stride == 2 ? put_points(at, v, n) : put_values(at, v, count);
  if (end == NULL) {
    *at = '\0';
    return nonfinite(ctx, "coordinate");
  }
  *end = '\0';
  b->len += (size_t)(end - at);
  return true;
}

bool api__parse_precision(api_ctx *ctx, const cJSON *root, api_precision *out) {
  static const char *const names[] = {"exact", "tolerance"};
  int which = API_PRECISION_EXACT;
  if (!api__member_enum(ctx, root, "", "precision", names, 2, &which, NULL))
    return false;
  *out = (api_precision)which;
  return true;
}

api_grid api__tolerance_grid(double tol) {
  api_grid g = {true, api__grid_decimals(0.1 * tol), 0.1 * tol};
  return g;
}

/* ---- knots on a grid ---------------------------------------------------
 *
 * A curve printed with rounded knots u2 and rounded control points cp2 is
 * compared span by span with the exact one: each span (u_j < u_(j+1)) of
 * either is a Bezier curve of degree p over the same local parameter, its
 * points the blossoms at p - k copies of u_j and k of u_(j+1). Bernstein
 * weights are non-negative and sum to one, so no point of a span moves by
 * more than the largest distance between corresponding Bezier points. For
 * cubic frames (double knots at smooth joins) that is the implied joint's
 * movement along b_left -> b_right with the control points' own rounding;
 * triple and end knots count only through the ratios of their neighbours.
 * Kept only while the knots keep their multiplicities (no span collapses,
 * none appears) and the whole movement fits in the grid's share. */

#define KNOT_GRID_DECADES 6 /* tried past the first candidate */

/* The reciprocals of de Boor's denominators on span j of degree p with
 * knots u, level r (1..p) and local index i (r..p) at inv[r * (p + 1) +
 * i]: shared by the span's Bezier points. */
static void span_inverses(const double *u, int p, size_t j, double *inv) {
  size_t base = j - (size_t)p;
  for (int r = 1; r <= p; r++)
    for (int i = r; i <= p; i++)
      inv[r * (p + 1) + i] =
          1.0 / (u[base + (size_t)(i + p + 1 - r)] - u[base + (size_t)i]);
}

/* The k-th Bezier point of span j of the non-rational B-spline of degree
 * p with knots u and control points cp, by de Boor's algorithm on the
 * blossom's arguments (k copies of u_(j+1), then u_j); inv from
 * span_inverses. */
static void bezier_point(const double *u, const double *cp, int p, size_t j,
                         int k, const double *inv, double out[2]) {
  double d[2 * (KM_MAX_DEGREE + 1)];
  size_t base = j - (size_t)p;
  memcpy(d, cp + 2 * base, 2 * (size_t)(p + 1) * sizeof *d);
  for (int r = 1; r <= p; r++) {
    double a = r <= k ? u[j + 1] : u[j];
    for (int i = p; i >= r; i--) {
      double al = (a - u[base + (size_t)i]) * inv[r * (p + 1) + i];
      d[2 * i] = (1 - al) * d[2 * (i - 1)] + al * d[2 * i];
      d[2 * i + 1] = (1 - al) * d[2 * (i - 1) + 1] + al * d[2 * i + 1];
    }
  }
  out[0] = d[2 * p];
  out[1] = d[2 * p + 1];
}

/* The largest distance between the spans' Bezier points of c and of the
 * curve with knots u2 and control points cp2 (the same spans); stops once
 * past limit. cp_moved: the largest distance between c's control points
 * and cp2's, which is what a cubic span between knots of multiplicity two
 * or more moves at its inner Bezier points (they are control points). */
static double bezier_gap(const km_curve *c, const double *u2, const double *cp2,
                         double cp_moved, double limit) {
  int p = c->degree;
  const double *u = c->knots;
  double gap2 = cp_moved * cp_moved, limit2 = limit * limit;
  double ie[(KM_MAX_DEGREE + 1) * (KM_MAX_DEGREE + 1)];
  double ir[(KM_MAX_DEGREE + 1) * (KM_MAX_DEGREE + 1)];
  for (size_t j = (size_t)p; j < c->n; j++) {
    if (!(c->knots[j] < c->knots[j + 1])) continue;
    /* inner Bezier points of such a span: counted in cp_moved */
    bool hermite = p == 3 && u[j - 1] == u[j] && u[j + 1] == u[j + 2];
    if (hermite) {
      /* its ends by de Boor's algorithm worked out: with u_(j-1) = u_j the
       * start is P_(j-3) + a (P_(j-2) - P_(j-3)), a = (u_j - u_(j-2)) /
       * (u_(j+1) - u_(j-2)), and with u_(j+1) = u_(j+2) the end is
       * P_(j-1) + b (P_j - P_(j-1)), b = (u_(j+1) - u_j) / (u_(j+3) -
       * u_j): the joints' ratios (and the ends, where a = 0 or b = 1) */
      const double *P = c->cp + 2 * (j - 3), *Q = cp2 + 2 * (j - 3);
      double a = (u[j] - u[j - 2]) / (u[j + 1] - u[j - 2]),
             a2 = (u2[j] - u2[j - 2]) / (u2[j + 1] - u2[j - 2]),
             b = (u[j + 1] - u[j]) / (u[j + 3] - u[j]),
             b2 = (u2[j + 1] - u2[j]) / (u2[j + 3] - u2[j]);
      double d0[2], d3[2];
      for (int x = 0; x < 2; x++) {
        d0[x] =
            (Q[x] + a2 * (Q[2 + x] - Q[x])) - (P[x] + a * (P[2 + x] - P[x]));
        d3[x] = (Q[4 + x] + b2 * (Q[6 + x] - Q[4 + x])) -
                (P[4 + x] + b * (P[6 + x] - P[4 + x]));
      }
      gap2 = fmax(gap2, fmax(d0[0] * d0[0] + d0[1] * d0[1],
                             d3[0] * d3[0] + d3[1] * d3[1]));
      if (gap2 > limit2) break;
      continue;
    }
    span_inverses(c->knots, p, j, ie);
    span_inverses(u2, p, j, ir);
    for (int k = 0; k <= p; k++) {
      double e[2], r[2];
      bezier_point(c->knots, c->cp, p, j, k, ie, e);
      bezier_point(u2, cp2, p, j, k, ir, r);
      double dx = r[0] - e[0], dy = r[1] - e[1];
      gap2 = fmax(gap2, dx * dx + dy * dy);
    }
    if (gap2 > limit2) break;
  }
  return sqrt(gap2);
}

/* The knots of c on the coarsest decimal grid (tried from an estimate,
 * one decade finer at a time) on which the curve with them and the
 * rounded control points cp2 stays within share of c: u2 receives them,
 * *decimals the grid, *gap the movement (rounding of the computation
 * included). false (exact knots): rational curves, and no grid within
 * KNOT_GRID_DECADES of the estimate. */
static bool knot_grid(const km_curve *c, const double *cp2, double cp_moved,
                      double share, double *u2, int *decimals, double *gap) {
  int p = c->degree;
  size_t nk = c->n + (size_t)p + 1;
  double min_gap = INFINITY, speed = 0.0, scale = 0.0;
  if (c->w != NULL || p < 1 || p > KM_MAX_DEGREE || c->n <= (size_t)p)
    return false;
  for (size_t i = 0; i + 1 < nk; i++) {
    double h = c->knots[i + 1] - c->knots[i];
    if (h > 0 && h < min_gap) min_gap = h;
  }
  for (size_t i = 0; i < c->n; i++) {
    scale = fmax(scale, fmax(fabs(c->cp[2 * i]), fabs(c->cp[2 * i + 1])));
    if (i + 1 == c->n) break;
    double h = c->knots[i + (size_t)p + 1] - c->knots[i + 1];
    double dx = c->cp[2 * i + 2] - c->cp[2 * i],
           dy = c->cp[2 * i + 3] - c->cp[2 * i + 1];
    if (h > 0) speed = fmax(speed, p * hypot(dx, dy) / h);
  }
  /* what computing the Bezier points may get wrong, both curves */
  double slack = 64 * (p + 1) * DBL_EPSILON * scale;
  double budget = share - cp_moved - slack;
  if (!(budget > 0) || !isfinite(min_gap)) return false;
  /* knots moved by half a step each move a double knot's ratio lambda by
   * at most a step over the two spans, and its joint along b_left ->
   * b_right, a third of the spans times the speed at most: a step of
   * three budgets over the speed fits; one more budget tried as well */
  double step = speed > 0 ? fmin(min_gap, 4 * budget / speed) : min_gap;
  int d0 = api__grid_decimals(step);
  for (int d = d0; d < d0 + KNOT_GRID_DECADES; d++) {
    bool same = true;
    for (size_t i = 0; i < nk && same; i++) {
      u2[i] = api__num_grid_value(c->knots[i], d);
      if (i > 0)
        same = (u2[i] == u2[i - 1]) == (c->knots[i] == c->knots[i - 1]) &&
               u2[i] >= u2[i - 1];
    }
    if (!same) continue;
    double g = bezier_gap(c, u2, cp2, cp_moved, share);
    if (g + slack <= share) {
      *decimals = d;
      *gap = g + slack;
      return true;
    }
  }
  return false;
}

/* n values on the grid 10^-decimals as [v,...]. */
static void json_values_grid(api_svg_buf *b, const double *v, size_t n,
                             int decimals) {
  char *at = api__svg_buf_room(b, 2 + n * (API_NUM_PRINT_MAX + 1));
  if (at == NULL) return;
  char *p = at;
  *p++ = '[';
  for (size_t i = 0; i < n; i++) {
    double got;
    if (i > 0) *p++ = ',';
    p += api__num_print_grid(p, v[i], decimals, &got);
  }
  *p++ = ']';
  *p = '\0';
  b->len += (size_t)(p - at);
}

/* n points on grid g as [[x,y],...]; rounded receives the points as they
 * read back, *moved the largest distance one moved. */
static bool json_points_grid(api_ctx *ctx, api_svg_buf *b, const double *v,
                             size_t n, const api_grid *g, double *rounded,
                             double *moved) {
  if (n > SIZE_MAX / (4 * API_NUM_PRINT_MAX)) return api__oom(ctx);
  char *at = api__svg_buf_room(b, 2 + n * 2 * (API_NUM_PRINT_MAX + 2));
  if (at == NULL) return true;
  char *p = at;
  *p++ = '[';
  for (size_t i = 0; i < n; i++) {
    if (!isfinite(v[2 * i]) || !isfinite(v[2 * i + 1])) {
      *at = '\0';
      return nonfinite(ctx, "coordinate");
    }
    if (i > 0) *p++ = ',';
    *p++ = '[';
    p += api__num_print_grid(p, v[2 * i], g->decimals, &rounded[2 * i]);
    *p++ = ',';
    p += api__num_print_grid(p, v[2 * i + 1], g->decimals, &rounded[2 * i + 1]);
    *p++ = ']';
    double d =
        hypot(rounded[2 * i] - v[2 * i], rounded[2 * i + 1] - v[2 * i + 1]);
    if (d > *moved) *moved = d;
  }
  *p++ = ']';
  *p = '\0';
  b->len += (size_t)(p - at);
  return true;
}

double api__curve_length(const km_curve *c) {
  return km_curve_length_within(c, LENGTH_REL_TOL);
}

bool api__json_curve(api_ctx *ctx, api_svg_buf *b, const km_curve *c,
                     bool svg_d, double tol, const api_grid *grid,
                     double known_length, double *moved) {
  double length, largest = 0.0, knot_gap = 0.0;
  km_curve printed = *c;
  double *rounded = NULL, *u2 = NULL;
  size_t nk = c->n + (size_t)c->degree + 1;
  int knot_decimals = 0;
  bool ok = false, knots_on_grid = false;
  if (grid != NULL && grid->on) {
    if ((rounded = km__malloc((c->n > 0 ? 2 * c->n : 1) * sizeof *rounded +
                              nk * sizeof *u2)) == NULL)
      return api__oom(ctx);
    u2 = rounded + (c->n > 0 ? 2 * c->n : 1);
    /* the control points as they will read back, to choose the knots'
     * grid with; printed (and rounded again, alike) below */
    bool finite = true;
    for (size_t i = 0; i < 2 * c->n; i++) {
      finite = finite && isfinite(c->cp[i]);
      rounded[i] = api__num_grid_value(c->cp[i], grid->decimals);
    }
    for (size_t i = 0; i < c->n; i++) {
      double dx = rounded[2 * i] - c->cp[2 * i],
             dy = rounded[2 * i + 1] - c->cp[2 * i + 1];
      largest = fmax(largest, dx * dx + dy * dy);
    }
    largest = sqrt(largest);
    bool knots_finite = true;
    for (size_t i = 0; i < nk; i++)
      knots_finite = knots_finite && isfinite(c->knots[i]);
    if (finite && knots_finite)
      knots_on_grid = knot_grid(c, rounded, largest, grid->share, u2,
                                &knot_decimals, &knot_gap);
    largest = 0.0;
  }
  API_JSON_LIT(b, "{\"degree\":");
  if (!api__json_num(ctx, b, c->degree, "degree")) goto done;
  API_JSON_LIT(b, ",\"knots\":");
  if (knots_on_grid) {
    json_values_grid(b, c->knots, nk, knot_decimals);
    printed.knots = u2;
  } else if (!api__json_nums(ctx, b, c->knots, nk, 1)) {
    goto done;
  }
  API_JSON_LIT(b, ",\"control_points\":");
  if (rounded != NULL) {
    if (!json_points_grid(ctx, b, c->cp, c->n, grid, rounded, &largest))
      goto done;
    printed.cp = rounded;
    /* the whole movement, knots' included, when they are rounded */
    if (knots_on_grid) largest = fmax(largest, knot_gap);
  } else if (!api__json_nums(ctx, b, c->cp, c->n, 2)) {
    goto done;
  }
  if (c->w != NULL) {
    API_JSON_LIT(b, ",\"weights\":");
    if (!api__json_nums(ctx, b, c->w, c->n, 1)) goto done;
  }
  if (c->closed)
    API_JSON_LIT(b, ",\"closed\":true,\"length\":");
  else
    API_JSON_LIT(b, ",\"closed\":false,\"length\":");
  /* the length of the curve as printed, which the contract promises:
   * the curve's own when printed exactly and already measured */
  length =
      printed.cp == c->cp && printed.knots == c->knots && !isnan(known_length)
          ? known_length
          : km_curve_length_within(&printed, LENGTH_REL_TOL);
  if (!api__json_num(ctx, b, length, "length")) goto done;
  if (svg_d) {
    /* Default tolerance as everywhere: 1e-5 of the curve's length. */
    char *d = api_svg_path_d(c, tol > 0 ? tol : 1e-5 * length, NULL);
    if (d == NULL) {
      api__oom(ctx);
      goto done;
    }
    API_JSON_LIT(b, ",\"svg_d\":");
    api__json_string(b, d);
    km__free(d);
  }
  API_JSON_LIT(b, "}");
  if (moved != NULL) *moved = largest;
  ok = true;
done:
  km__free(rounded);
  return ok;
}

bool api__json_tree(api_ctx *ctx, api_svg_buf *b, cJSON *item) {
  if (item == NULL) return false;
  char *s = cJSON_PrintUnformatted(item);
  cJSON_Delete(item);
  if (s == NULL) return api__oom(ctx);
  api__svg_buf_put(b, s);
  km__free(s);
  return true;
}

bool api__json_done(api_ctx *ctx, const api_svg_buf *b) {
  return b->failed ? api__oom(ctx) : true;
}

/* ------------------------------------------------- bounds on the bytes */

/* Numbers of cubic pieces' points a curve of n control points puts in a
 * path. Curvature frames are Hermite splines: a cubic's knots are double
 * (a span per two control points, three Bezier points a span), a
 * quintic's at least triple, each span drawn as up to four cubics (halved
 * until within the tolerance). Other curves (linear frames) have a span
 * per control point. */
size_t api__path_numbers(size_t n, int degree, bool hermite) {
  if (hermite) return (degree <= 3 ? 3 : 8) * n + 2;
  return (degree <= 3 ? 6 : 24) * n + 2;
}

size_t api__curve_json_bytes(size_t n, int degree, bool rational, bool svg_d) {
  size_t knots = n + (size_t)degree + 1;
  size_t b =
      128 + API_JSON_NUM_BYTES * (knots + 2 * n + (rational ? n : 0)) + 3 * n;
  if (svg_d) b += 16 + API_SVG_NUM_BYTES * api__path_numbers(n, degree, false);
  return b;
}

size_t api__signature_json_bytes(const km_signature *sig) {
  size_t knots = sig->kappa.n + (size_t)sig->kappa.degree + 1;
  return 256 + (API_JSON_NUM_BYTES + 1) * (knots + sig->kappa.n) +
         (2 * API_JSON_NUM_BYTES + 16) * sig->ncorners;
}
