/* stop_internal.h - a call's poll of its caller's km_stop (stop.c); internal.
 */
#ifndef KM_STOP_INTERNAL_H
#define KM_STOP_INTERNAL_H

#include <stdbool.h>

#include "km/status.h"
#include "km/stop.h"

/* ---- stopping (km/stop.h) ------------------------------------------------
 * One call's poll of its caller's km_stop: loops count their work in units
 * and the callback is asked once every KM_STOP_POLL_UNITS of them. Once it
 * said stop every later check says so without asking again, so nested
 * loops unwind one after the other. A NULL km__poll never stops, so
 * helpers shared with callers that cannot stop take NULL. */
typedef struct km__poll {
  const km_stop *stop;
  long left;    /* units until the next question */
  bool stopped; /* the answer was yes */
  long asked;   /* questions asked (for tests and figures) */
} km__poll;

void km__poll_init(km__poll *p, const km_stop *stop);
/* Count units of work; true when the computation must end now. */
static inline bool km__poll_stop(km__poll *p, long units) {
  if (!p) return false;
  if (p->stopped) return true;
  if (!p->stop || !p->stop->requested) return false;
  p->left -= units;
  if (p->left > 0) return false;
  p->left = KM_STOP_POLL_UNITS;
  p->asked++;
  p->stopped = p->stop->requested(p->stop->ctx);
  return p->stopped;
}
/* The status of a stopped call, with its message in err. */
km_status km__stopped(km_error *err);

#endif
