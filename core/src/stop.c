/* stop.c - the core's side of km/stop.h: one call's poll of its caller's
 * stop condition (the counting itself is inline in internal.h). */
#include <math.h>

#include "internal.h"

void km__poll_init(km__poll *p, const km_stop *stop) {
  p->stop = stop;
  /* the first question comes after the first interval's work, so that
   * calls shorter than an interval never ask */
  p->left = KM_STOP_POLL_UNITS;
  p->stopped = false;
  p->asked = 0;
}

km_status km__stopped(km_error *err) {
  return km__fail(err, KM_ECANCELLED, KM_FIELD_NONE, -1, NAN,
                  "the computation was stopped before it finished");
}
