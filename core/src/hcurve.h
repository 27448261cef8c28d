/* hcurve.h - homogeneous B-spline workspaces shared by the knot-level
 * curve operations (hcurve.c, curve_ops.c) and the self-intersection
 * counter (intersect.c); internal to libkmorph.
 *
 * A rational curve is exact under knot insertion, knot removal and degree
 * elevation only when those act on the homogeneous points (w x, w y, w), so
 * every such operation works on a km__hcurve: a clamped B-spline whose
 * control points have `dim` coordinates, 2 for polynomial curves and 3 for
 * rational ones. One heap block holds knots then points.
 */
#ifndef KM_HCURVE_H
#define KM_HCURVE_H

#include <stdbool.h>
#include <stddef.h>

#include "internal.h"

typedef struct km__hcurve {
  int degree;
  int dim;       /* 2: (x, y); 3: (w x, w y, w) */
  size_t n;      /* control points */
  double *knots; /* n + degree + 1 values, start of the block */
  double *pw;    /* n * dim values */
} km__hcurve;

void km__h_init(km__hcurve *h);
void km__h_free(km__hcurve *h);
/* Block for n points of the given degree and dimension; contents
 * uninitialised. KM_ENOMEM on failure. */
km_status km__h_alloc(km__hcurve *h, int degree, int dim, size_t n);
/* Homogeneous copy of c; dim 3 makes a polynomial curve rational with unit
 * weights, dim 2 is honoured only for polynomial curves. */
km_status km__h_from_curve(km__hcurve *h, const km_curve *c, int dim);
/* Back to a km_curve (rational iff dim == 3). A closed result gets its last
 * point copied from its first so the seam stays bit-exact. KM_EWEIGHT or
 * KM_ENONFINITE if the homogeneous data went bad. */
km_status km__h_to_curve(km_curve *out, const km__hcurve *h, bool closed);
/* Knot refinement (Boehm / Oslo, Piegl & Tiller A5.4): insert the sorted
 * values x[0..nx-1], each strictly inside the domain. */
km_status km__h_refine(km__hcurve *out, const km__hcurve *h, const double *x,
                       size_t nx);
/* Every interior knot raised to multiplicity degree. */
km_status km__h_to_bezier(km__hcurve *out, const km__hcurve *h);
/* Degree raised by `times` (exact). */
km_status km__h_elevate(km__hcurve *out, const km__hcurve *h, int times);
/* Remove, in place, one occurrence of the interior knot whose last
 * occurrence is at index r. Exact when the curve is C^(p-s+1) there (s the
 * multiplicity); otherwise the result is a nearby curve. */
void km__h_remove_knot(km__hcurve *h, size_t r);

/* Binomial coefficient as a double (small arguments). */
double km__binom(int n, int k);

#endif
