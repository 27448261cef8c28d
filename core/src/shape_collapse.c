/* shape_collapse.c - where an unpaired contour of a compound morph is a
 * point: what an animation draws in place of a contour absent from a
 * frame, so that every frame keeps one subpath per slot.
 */
#include <stddef.h>

#include "km/shape.h"
#include "shape_internal.h"

bool km_shape_morph_collapse_point(const km_shape_morph *m, size_t slot,
                                   double p[2]) {
  if (m == NULL || p == NULL || slot >= m->npairs ||
      m->kind[slot] == KM__PAIRED)
    return false;
  p[0] = m->point[2 * slot];
  p[1] = m->point[2 * slot + 1];
  return true;
}
