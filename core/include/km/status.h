/* status.h - status codes and the inline error record of libkmorph.
 *
 * Every fallible core function returns a km_status (0 = KM_OK, negative =
 * failure) and, when given a non-NULL km_error, fills it with the code, the
 * input field and element at fault, and a fixed-size message. The record
 * lives in the caller's memory: no heap (out-of-memory stays reportable), no
 * global (thread-safe). It is written by a call that fails and is to be
 * read only then; on success its contents are unspecified. Each function's
 * comment lists the statuses it returns and what field, index and param
 * then name.
 */
#ifndef KM_STATUS_H
#define KM_STATUS_H

#include "km/export.h"

#include <stddef.h>

/* X(name, value, default message) */
#define KM_STATUS_MAP(X)                                                       \
  X(OK, 0, "success")                                                          \
  X(EINVAL, -1, "invalid argument")                                            \
  X(ENOMEM, -2, "out of memory")                                               \
  X(EDEGREE, -3, "degree out of range")                                        \
  X(EKNOTS, -4, "invalid knot vector")                                         \
  X(ECOUNT, -5, "wrong number of elements")                                    \
  X(ENONFINITE, -6, "value is not finite")                                     \
  X(ERANGE, -7, "value out of range")                                          \
  X(EWEIGHT, -8, "weights must be positive")                                   \
  X(ECLOSED, -9, "closed curve does not close")                                \
  X(EDEGENERATE, -10, "curve has zero length")                                 \
  X(ECUSP, -11, "curve is not regular: the tangent reverses (cusp)")           \
  X(ENOCONVERGE, -12, "numerical method did not converge")                     \
  X(ETURNING, -13, "closed curves have different turning numbers")             \
  X(EMIXED, -14, "cannot morph an open curve into a closed one")               \
  X(ELIMIT, -15, "result would exceed a limit")                                \
  X(ECANCELLED, -16, "cancelled")                                              \
  X(EMATCH, -17, "invalid correspondence")

typedef enum km_status {
#define KM__STATUS_ENUM(name, value, msg) KM_##name = value,
  KM_STATUS_MAP(KM__STATUS_ENUM)
#undef KM__STATUS_ENUM
} km_status;

/* Which part of an input an error is about, so that upper layers can build
 * a JSON pointer without parsing messages. */
typedef enum km_field {
  KM_FIELD_NONE = 0,
  KM_FIELD_DEGREE,
  KM_FIELD_KNOTS,
  KM_FIELD_CONTROL_POINTS,
  KM_FIELD_WEIGHTS,
  KM_FIELD_CLOSED,
  KM_FIELD_LENGTH,
  KM_FIELD_START,
  KM_FIELD_ANGLE,
  KM_FIELD_KAPPA_KNOTS,
  KM_FIELD_KAPPA_COEFFICIENTS,
  KM_FIELD_KAPPA_DEGREE,
  KM_FIELD_CORNERS,
  KM_FIELD_TOLERANCE,
  KM_FIELD_POINTS,
  KM_FIELD_MATCHES,
  KM_FIELD_TIMES
} km_field;

#define KM_ERROR_MESSAGE_MAX 200

typedef struct km_error {
  km_status code;
  km_field field; /* input field at fault, KM_FIELD_NONE if none */
  long index;     /* element index within that field, -1 if none */
  double param;   /* curve parameter (or arc length) where it happened, NAN
                      if none */
  char message[KM_ERROR_MESSAGE_MAX];
} km_error;

/* Name of a status ("KM_ECUSP") and its default message (the table above):
 * static strings, never NULL, safe from any thread. A value not in the
 * table gives "KM_UNKNOWN" and "unknown status". */
KM_API const char *km_status_name(km_status s);
KM_API const char *km_status_message(km_status s);

#endif
