/* core_problem.c - core failures as problems: a km_status and its
 * km_error mapped to an HTTP status, a problem type and title, the JSON
 * pointer of the request member at fault and a message.
 */
#include <math.h>
#include <stdio.h>

#include "internal.h"

static const char *field_name(km_field f, api_kind kind) {
  /* A fitted curve's control points are not in the request: name the
   * points or the curve object instead. */
  if (kind == API_KIND_POINTS && f != KM_FIELD_POINTS && f != KM_FIELD_CLOSED)
    return NULL;
  switch (f) {
  case KM_FIELD_DEGREE: return "degree";
  case KM_FIELD_KNOTS: return "knots";
  case KM_FIELD_CONTROL_POINTS: return "control_points";
  case KM_FIELD_WEIGHTS: return "weights";
  case KM_FIELD_CLOSED: return "closed";
  case KM_FIELD_LENGTH: return "length";
  case KM_FIELD_START: return "start/point";
  case KM_FIELD_ANGLE: return "start/angle";
  case KM_FIELD_KAPPA_KNOTS: return "kappa/knots";
  case KM_FIELD_KAPPA_COEFFICIENTS: return "kappa/coefficients";
  case KM_FIELD_KAPPA_DEGREE: return "kappa/degree";
  case KM_FIELD_CORNERS: return "corners";
  case KM_FIELD_POINTS:
    return kind == API_KIND_CURVE ? "control_points" : "points";
  default: return NULL;
  }
}

typedef struct problem_kind {
  api_status status;
  const char *type, *title;
} problem_kind;

/* The status, type and title of core failure st (not KM_ENOMEM), met
 * while working on something of the given kind. */
static problem_kind problem_of(km_status st, api_kind kind) {
  switch (st) {
  case KM_ETURNING:
  case KM_EMIXED:
    return (problem_kind){422, API_P_NOT_MORPHABLE, "Curves cannot be morphed"};
  case KM_EMATCH:
    return (problem_kind){422, API_P_INVALID_REQUEST, "Invalid request"};
  case KM_ENOCONVERGE:
    return (problem_kind){422, API_P_NO_CONVERGE,
                          "Computation did not converge"};
  case KM_ELIMIT: return (problem_kind){422, API_P_LIMIT, "Limit exceeded"};
  case KM_ECANCELLED:
    return (problem_kind){503, "/problems/cancelled", "Cancelled"};
  case KM_EINVAL:
  case KM_EDEGREE:
  case KM_EKNOTS:
  case KM_ECOUNT:
  case KM_ENONFINITE:
  case KM_ERANGE:
  case KM_EWEIGHT:
  case KM_ECLOSED:
  case KM_EDEGENERATE:
  case KM_ECUSP:
    if (kind == API_KIND_SIGNATURE)
      return (problem_kind){422, API_P_INVALID_SIGNATURE, "Invalid signature"};
    if (kind == API_KIND_REQUEST)
      return (problem_kind){422, API_P_INVALID_REQUEST, "Invalid request"};
    return (problem_kind){422, API_P_INVALID_CURVE, "Invalid curve"};
  default: return (problem_kind){500, API_P_INTERNAL, "Internal error"};
  }
}

/* The pointer of the member at fault into p (API_POINTER_MAX bytes):
 * fields that live at the request level whatever was being processed,
 * else the field's name under base, with the element's index where the
 * field is an array. */
static void fault_pointer(char *p, const km_error *err, const char *base,
                          api_kind kind) {
  km_field field = err != NULL ? err->field : KM_FIELD_NONE;
  const char *name;
  if (field == KM_FIELD_TOLERANCE) {
    snprintf(p, API_POINTER_MAX, "/tolerance");
  } else if (field == KM_FIELD_MATCHES || field == KM_FIELD_TIMES) {
    const char *key = field == KM_FIELD_MATCHES ? "/matches" : "/times";
    if (err->index >= 0)
      snprintf(p, API_POINTER_MAX, "%s/%ld", key, err->index);
    else
      snprintf(p, API_POINTER_MAX, "%s", key);
  } else if (kind == API_KIND_SVG) {
    api__ptr_key(p, base, "d");
  } else if ((name = field_name(field, kind)) != NULL) {
    if (err->index >= 0 && field != KM_FIELD_DEGREE &&
        field != KM_FIELD_CLOSED && field != KM_FIELD_LENGTH &&
        field != KM_FIELD_ANGLE && field != KM_FIELD_KAPPA_DEGREE)
      snprintf(p, API_POINTER_MAX, "%s/%s/%ld", base, name, err->index);
    else
      api__ptr_key(p, base, name);
  } else {
    snprintf(p, API_POINTER_MAX, "%s", base);
  }
}

/* The message into msg (API_TEXT_MAX bytes). The core's own message
 * usually says where already; the place is added only to a bare default
 * message. */
static void fault_message(char *msg, km_status st, const km_error *err,
                          api_kind kind) {
  const char *text = err != NULL && err->message[0] != '\0'
                         ? err->message
                         : km_status_message(st);
  if (err != NULL && err->message[0] == '\0' && isfinite(err->param) &&
      (st == KM_ECUSP || st == KM_EDEGENERATE || st == KM_ENOCONVERGE))
    snprintf(msg, API_TEXT_MAX, "%s (at %s %.17g)", text,
             kind == API_KIND_SIGNATURE ? "arc length" : "parameter",
             err->param);
  else
    snprintf(msg, API_TEXT_MAX, "%s", text);
}

bool api__core_fail(api_ctx *ctx, km_status st, const km_error *err,
                    const char *base, api_kind kind) {
  char p[API_POINTER_MAX], msg[API_TEXT_MAX];
  problem_kind pk;
  if (st == KM_ENOMEM) return api__oom(ctx);
  pk = problem_of(st, kind);
  fault_pointer(p, err, base, kind);
  fault_message(msg, st, err, kind);
  return api__fail(ctx, pk.status, pk.type, pk.title, p, msg);
}
