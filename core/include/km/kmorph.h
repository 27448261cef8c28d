/* kmorph.h - umbrella header of libkmorph, and the conventions every
 * public header of the core follows.
 *
 * Each public function's comment says what it does, its parameters (in,
 * out, or in/out), every status it returns and what err->field / index /
 * param then name, who owns what it returns, and its units and
 * tolerances. What this comment says holds for all of them unless a
 * function's own comment says otherwise.
 *
 * PARAMETER ORDER. Inputs first, the object a function is named after
 * leading (km_morph_frame(m, t, ...), km_curve_split(c, t, &left,
 * &right, ...), km_signature_compute(c, tol, &sig, ...)), then the
 * out-parameters, then the optional `km_error *err` last. One exception
 * by design: a constructor - a function that builds an object of its
 * own type from its parts or from another of its kind - takes that object
 * first, as memcpy takes its destination: km_curve_create(out, ...),
 * km_curve_copy(out, c, err), km_fn_blend(out, ...),
 * km_signature_create(out, ...), km_morph_create(&out, ...). Two
 * functions take no km_error, since nothing but memory can fail in them
 * and no field is at fault: km_signature_point and
 * km_curve_self_intersections_until (their comments say so).
 *
 * STATUS AND ERRORS (km/status.h). A fallible function returns KM_OK (0)
 * or a negative km_status. `err` may be NULL; when it is not and the call
 * fails, it receives the code, the input field and element at fault and a
 * message. Read err only after a failure. KM_ENOMEM may come from any
 * function that allocates, which is every fallible one; it is listed all
 * the same.
 *
 * OWNERSHIP. Inputs are borrowed (const) for the call only and
 * deep-copied when kept. An out-parameter is written only on success, and
 * nothing is leaked on failure. Objects a call returns are the caller's,
 * freed by their km_x_free (which accepts NULL and empty objects); an
 * out-parameter of object type is taken as empty: whatever it held is not
 * freed, so pass an init'ed or freed object. Memory comes from the hook of
 * km/alloc.h (libc's malloc and free unless the program replaces it).
 *
 * VALIDITY. Fallible functions check what they are given and return a
 * status; the ones that return a value (a length, a count, a point) or
 * nothing take valid objects only: one built by a function here, never
 * NULL nor an empty (init'ed) object, which they do not check.
 *
 * THREADS. The core has no globals, no locks and no I/O. Objects are
 * never changed after construction, so any number of threads may read one
 * object at once (km_morph_frame on a shared km_morph is the common
 * case). An object being written (an out-parameter, a km_path being
 * built) belongs to the calling thread for the call.
 *
 * UNITS. Coordinates, lengths, arc lengths s and tolerances are in the
 * curve's own coordinate units; a tolerance is a distance, and a
 * tolerance <= 0 (or NaN) asks for a default, usually 1e-5 of the length
 * in question (each function names its own). Curve parameters t are in the units of the curve's knots.
 * Angles are radians, counter-clockwise (the one exception:
 * km_path_arc_to's x-axis rotation is in degrees, as in SVG). Curvature
 * is 1 / length unit. Hard bounds on all of these are in km/limits.h.
 */
#ifndef KM_KMORPH_H
#define KM_KMORPH_H
#include "km/curve.h"
#include "km/fn.h"
#include "km/limits.h"
#include "km/morph.h"
#include "km/path.h"
#include "km/reconstruct.h"
#include "km/signature.h"
#include "km/status.h"
#include "km/stop.h"
#include "km/version.h"
#endif
