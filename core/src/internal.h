/* internal.h - helpers shared inside libkmorph; not part of the API.
 *
 * Non-static internal symbols are prefixed km__ (public ones km_). This
 * header only gathers the ones by subject, so a file may include the one
 * it needs instead: stop_internal.h (a caller's stop), status_internal.h
 * (errors), kernels.h (small numeric kernels), bspline_internal.h (curves,
 * spans, lengths), pp_internal.h (piecewise polynomials) and
 * signature_internal.h (signatures and reconstruction).
 */
#ifndef KM_INTERNAL_H
#define KM_INTERNAL_H

#include <math.h>
#include <stdbool.h>
#include <stddef.h>

#include "bspline_internal.h"
#include "kernels.h"
#include "km/curve.h"
#include "km/fn.h"
#include "km/limits.h"
#include "km/status.h"
#include "km/stop.h"
#include "pp_internal.h"
#include "signature_internal.h"
#include "status_internal.h"
#include "stop_internal.h"

#endif
