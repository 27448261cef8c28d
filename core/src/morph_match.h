/* morph_match.h - matches "auto" (morph_match.c): the correspondence of
 * two inputs' features, found once per morph; internal to the core. */
#ifndef KM_MORPH_MATCH_H
#define KM_MORPH_MATCH_H

#include <stddef.h>

#include "morph_internal.h"

/* Match pairs (r_a, r_b) of features (corners and curvature extrema with
 * the turning they carry) of a and b, aligned by dynamic programming:
 * pairs of like turning gain, drift in r costs. Writes at most cap pairs
 * to pairs (2 values each), strictly increasing on both inputs and inside
 * (0, 1), and returns how many (0 when either input has no feature). */
size_t km__auto_matches(const km__input *a, const km__input *b, double *pairs,
                        size_t cap);

#endif
