/* poly_index.c - horizontal bands over a closed polyline's edges, so that
 * a winding number or the crossings with another polyline look at the
 * few edges near a height instead of all of them.
 *
 * DESIGN: a compound frame tests every point of a hole against its parent
 * (up to a dozen times while a contour is fitted inside it) and every
 * edge of one contour against every edge of another: O(n m) a test on
 * flattenings of thousands of points, 94% of a compound frame's time. The
 * bands make both answers identical to the plain loops' (the same edges
 * that can count are visited, with the same arithmetic), at about the
 * cost of the edges that cross a horizontal line. An edge is listed in
 * every band its height range [min y, max y] touches, and a height y is
 * looked up in band(y), where band is monotone in y even in floating
 * point, so an edge whose range holds y is always in y's band. Bands
 * are halved while the listing would exceed 8 entries an edge (long
 * vertical edges), which bounds memory by O(n).
 */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "km/alloc.h"
#include "shape_internal.h"

static size_t band_of(const km__poly_index *ix, double y) {
  double u = (y - ix->y0) * ix->inv_h;
  if (!(u >= 0.0)) return 0;
  if (u >= ix->nbands_f) return ix->nbands - 1;
  return (size_t)u;
}

static const double *vertex(const km__poly_index *ix, size_t i) {
  return ix->P + 2 * (i == ix->np ? 0 : i);
}

/* The smaller and larger of two numbers that are not NaN, as fmin and
 * fmax give them but inline (a zero's sign does not matter to band_of). */
static double lower(double a, double b) {
  return b < a ? b : a;
}
static double upper(double a, double b) {
  return b > a ? b : a;
}

/* Entries the listing takes with nbands bands (SIZE_MAX past limit), and
 * each edge's first and last band in range[2 i], range[2 i + 1]
 * (UINT32_MAX first for an edge with a NaN, which never counts). */
static size_t count_entries(km__poly_index *ix, size_t limit, uint32_t *range) {
  size_t total = 0;
  for (size_t i = 0; i < ix->np; i++) {
    const double *a = vertex(ix, i), *b = vertex(ix, i + 1);
    if (!(a[1] == a[1] && b[1] == b[1])) {
      range[2 * i] = UINT32_MAX;
      continue;
    }
    size_t lo = band_of(ix, lower(a[1], b[1]));
    size_t hi = band_of(ix, upper(a[1], b[1]));
    range[2 * i] = (uint32_t)lo;
    range[2 * i + 1] = (uint32_t)hi;
    total += hi - lo + 1;
    if (total > limit) return SIZE_MAX;
  }
  return total;
}

void km__poly_index_init(km__poly_index *ix) {
  memset(ix, 0, sizeof *ix);
}

void km__poly_index_free(km__poly_index *ix) {
  km__free(ix->start);
  km__free(ix->edge);
  km__free(ix->seen);
  km__poly_index_init(ix);
}

km_status km__poly_index_build(km__poly_index *ix, const double *P, size_t np) {
  km__poly_index_free(ix);
  ix->P = P;
  ix->np = np;
  double y0 = INFINITY, y1 = -INFINITY;
  for (size_t i = 0; i < np; i++) {
    double y = P[2 * i + 1]; /* a NaN is skipped, as fmin and fmax do */
    if (y < y0) y0 = y;
    if (y > y1) y1 = y;
  }
  ix->y0 = y0;
  ix->y1 = y1;
  ix->nbands = np / 4 > 1 ? np / 4 : 1;
  if (ix->nbands > ((size_t)1 << 16)) ix->nbands = (size_t)1 << 16;
  /* bands are at most 2^16: an edge's range fits in two uint32_t */
  uint32_t *range = km__malloc((np ? 2 * np : 2) * sizeof *range);
  if (!range) {
    km__poly_index_free(ix);
    return KM_ENOMEM;
  }
  size_t total;
  for (;;) {
    ix->nbands_f = (double)ix->nbands;
    ix->inv_h = y1 > y0 ? ix->nbands_f / (y1 - y0) : 0.0;
    total = count_entries(ix, 8 * np + ix->nbands, range);
    if (total != SIZE_MAX || ix->nbands == 1) break;
    ix->nbands /= 2;
  }
  if (total == SIZE_MAX) total = count_entries(ix, SIZE_MAX - 1, range);
  ix->start = km__calloc(ix->nbands + 1, sizeof *ix->start);
  ix->edge = km__malloc((total ? total : 1) * sizeof *ix->edge);
  ix->seen = km__calloc(np ? np : 1, sizeof *ix->seen);
  if (!ix->start || !ix->edge || !ix->seen) {
    km__free(range);
    km__poly_index_free(ix);
    return KM_ENOMEM;
  }
  /* counting sort of (band, edge): counts, offsets, then places */
  for (int pass = 0; pass < 2; pass++) {
    for (size_t i = 0; i < np; i++) {
      if (range[2 * i] == UINT32_MAX) continue;
      for (size_t k = range[2 * i]; k <= range[2 * i + 1]; k++)
        if (pass == 0)
          ix->start[k + 1]++;
        else
          ix->edge[ix->start[k]++] = (uint32_t)i;
    }
    if (pass == 0) {
      for (size_t k = 0; k < ix->nbands; k++) ix->start[k + 1] += ix->start[k];
    } else {
      /* each start moved to the next band's: shift back */
      memmove(ix->start + 1, ix->start, ix->nbands * sizeof *ix->start);
      ix->start[0] = 0;
    }
  }
  km__free(range);
  return KM_OK;
}

int km__poly_index_winding(const km__poly_index *ix, const double p[2]) {
  /* an edge counts only where min y <= p.y < max y */
  if (!(p[1] >= ix->y0 && p[1] < ix->y1)) return 0;
  size_t k = band_of(ix, p[1]);
  int w = 0;
  for (size_t e = ix->start[k]; e < ix->start[k + 1]; e++) {
    size_t i = ix->edge[e];
    const double *a = ix->P + 2 * i, *b = i + 1 == ix->np ? ix->P : a + 2;
    w += km__edge_winding(a, b, p);
  }
  return w;
}

long km__poly_index_crossings(const double *P, size_t np, km__poly_index *Q,
                              km__poll *poll) {
  long count = 0;
  size_t last = Q->np ? Q->np - 1 : 0; /* the closing edge: not an edge of
                                          the plain loop */
  for (size_t i = 0; i + 1 < np; i++) {
    const double *a = P + 2 * i, *b = a + 2;
    double y0 = fmin(a[1], b[1]), y1 = fmax(a[1], b[1]);
    long visited = 0;
    if (y1 >= Q->y0 && y0 <= Q->y1) {
      Q->stamp++;
      size_t lo = band_of(Q, y0), hi = band_of(Q, y1);
      for (size_t k = lo; k <= hi; k++)
        for (size_t e = Q->start[k]; e < Q->start[k + 1]; e++) {
          size_t j = Q->edge[e];
          if (j == last || Q->seen[j] == Q->stamp) continue;
          Q->seen[j] = Q->stamp;
          visited++;
          if (km__edge_crosses(a, b, Q->P + 2 * j, Q->P + 2 * j + 2)) count++;
        }
    }
    if (km__poll_stop(poll, visited / 64 + 1)) return -1;
  }
  return count;
}
