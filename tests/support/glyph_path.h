/* glyph_path.h - a glyph outline of the fixtures (absolute M, L, Q and Z
 * path data of one subpath: TrueType quadratics, as in
 * tests/fixtures/avoid) as an exact km_curve. Shared by the tests
 * (glyphs.h) and the glyph benches (bench/bench_glyphs.h); a header of
 * static functions, with no test framework in it.
 */
#ifndef KM_TEST_GLYPH_PATH_H
#define KM_TEST_GLYPH_PATH_H

#include <stdlib.h>

#include "km/kmorph.h"

/* The path data d into *c (initialised here); 0, or -1 when d is not
 * such path data or a step of km_path refuses it. */
static inline int glyph_path_curve(const char *d, km_curve *c) {
  km_path p;
  km_path_init(&p);
  km_status st = KM_OK;
  double v[4];
  while (*d && !st) {
    while (*d == ' ') d++;
    char op = *d;
    if (!op) break;
    d++;
    int n = op == 'M' || op == 'L' ? 2 : op == 'Q' ? 4 : 0;
    for (int i = 0; i < n; i++) v[i] = strtod(d, (char **)&d);
    st = op == 'M'   ? km_path_move_to(&p, v[0], v[1], NULL)
         : op == 'L' ? km_path_line_to(&p, v[0], v[1], NULL)
         : op == 'Q' ? km_path_quad_to(&p, v[0], v[1], v[2], v[3], NULL)
         : op == 'Z' ? km_path_close(&p, NULL)
                     : KM_EINVAL;
  }
  km_curve_init(c);
  if (!st) st = km_path_to_curve(&p, 0.0, c, NULL);
  km_path_free(&p);
  return st == KM_OK ? 0 : -1;
}

#endif
