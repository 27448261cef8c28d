/* fuzz_svg_path.c - libFuzzer target for the SVG path-data parser and the
 * path writer: any byte string must either parse into a valid curve or be
 * refused with an offset inside the input; a parsed curve must export and
 * its export must parse again. Build and run with `make fuzz-svg`.
 */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "svg.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  km_curve c;
  km_curve_init(&c);
  size_t off = (size_t)-1;
  char msg[128];
  km_status st = api_svg_parse_path((const char *)data, size, 1e-9, &c, &off,
                                    msg, sizeof msg);
  if (st != KM_OK) {
    /* errors point into the input (or just past its end) */
    if (off > size || memchr(msg, '\0', sizeof msg) == NULL) abort();
    if (c.cp != NULL) abort();
    return 0;
  }
  if (c.n < 2 || c.degree < 1 || c.degree > 3 || !c.cp || !c.knots) abort();
  double scale = 0, lo[2] = {INFINITY, INFINITY},
         hi[2] = {-INFINITY, -INFINITY};
  for (size_t i = 0; i < 2 * c.n; i++) {
    if (!isfinite(c.cp[i])) abort();
    if (fabs(c.cp[i]) > scale) scale = fabs(c.cp[i]);
    if (c.cp[i] < lo[i % 2]) lo[i % 2] = c.cp[i];
    if (c.cp[i] > hi[i % 2]) hi[i % 2] = c.cp[i];
  }
  double extent = hypot(hi[0] - lo[0], hi[1] - lo[1]);
  double bound = -1;
  double tol = 1e-6 * (scale > 1 ? scale : 1);
  char *d = api_svg_path_d(&c, tol, &bound);
  if (!d) abort();
  if (!(bound >= 0)) abort();
  /* The export parses again when its numbers stay in range (Hermite
   * handles of extreme ellipses may leave it). */
  if (scale < 1e12 && bound <= tol) {
    km_curve back;
    km_curve_init(&back);
    km_status st2 =
        api_svg_parse_path(d, strlen(d), 1e-9, &back, &off, msg, sizeof msg);
    /* Only a curve so small that printing within tol collapses it to a
     * point may come back as nothing. */
    if (st2 != KM_OK && !(st2 == KM_EDEGENERATE && extent <= tol)) abort();
    km_curve_free(&back);
  }
  free(d);
  d = api_svg_path_d_fixed(&c, 7);
  if (!d) abort();
  free(d);
  km_curve_free(&c);
  return 0;
}
