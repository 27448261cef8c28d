/* morph_repair.h - which crossing repair intersections AVOID uses
 * (morph_repair.c): an internal switch for the benches and tests that
 * compare the repairs; the public km_morph_create uses the default.
 * Internal to the core. */
#ifndef KM_MORPH_REPAIR_H
#define KM_MORPH_REPAIR_H

#include "km/morph.h"
#include "km/status.h"

typedef enum km__repair_method {
  /* move the strands apart by a displacement smooth in t */
  KM__REPAIR_DISPLACEMENT = 0,
  /* add bumps of curvature over the strands before the closure */
  KM__REPAIR_CURVATURE = 1,
  /* no repair: the frames avoid's choices give */
  KM__REPAIR_OFF = 2,
  /* each event by curvature, by displacement where that is not kept */
  KM__REPAIR_BOTH = 3
} km__repair_method;

#define KM__REPAIR_DEFAULT KM__REPAIR_DISPLACEMENT

/* km_morph_create with the repair `repair` (used only under intersections
 * AVOID). Statuses and ownership as km_morph_create. */
km_status km__morph_create_repair(km_morph **out, const km_morph_input *from,
                                  const km_morph_input *to,
                                  const km_morph_options *opt,
                                  km__repair_method repair, km_error *err);

#endif
