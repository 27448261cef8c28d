/* morph_crossings.c - the "intersections" member of a morph's answer when
 * the request asked to avoid crossings: which frames still cross, and why.
 */
#include <math.h>
#include <string.h>

#include "km/alloc.h"
#include "morph_plan.h"

/* Crossings of frame slot f: self-crossings (every contour's, for a
 * compound frame) plus crossings between contours. From the metrics when
 * the frame has them, else counted on its curve at tol. */
static long frame_crossings(const api_morph_plan *pl, const api_frame_slot *f,
                            double tol) {
  if (pl->shapes) {
    long n = f->shape.mutual_intersections;
    for (size_t k = 0; k < f->shape.ncontours; k++)
      if (f->shape.present[k]) {
        long x = f->shape.metrics
                     ? f->shape.metrics[k].self_intersections
                     : km_curve_self_intersections(&f->shape.contours[k], tol);
        n += x > 0 ? x : 0;
      }
    return n;
  }
  if (pl->metrics) return f->metrics.self_intersections;
  if (f->crossings >= 0) return f->crossings;
  long x = km_curve_self_intersections(&f->curve, tol);
  return x > 0 ? x : 0;
}

double api__crossing_tolerance(const api_morph_plan *pl) {
  if (pl->tol > 0) return pl->tol;
  if (pl->shapes || pl->morph == NULL) return 1e-3;
  double len[2], turn[2];
  km_morph_inputs(pl->morph, len, turn);
  return 1e-5 * fmax(len[0], len[1]);
}

/* Why frames still cross, or NULL when none does. */
static const char *crossing_reason(const km_morph_avoidance *a, bool single,
                                   size_t crossing) {
  if (crossing == 0) return NULL;
  if (single && a->input_crossings[0] > 0 && a->input_crossings[1] > 0)
    return "both inputs cross themselves";
  if (single && a->input_crossings[0] > 0) return "from crosses itself";
  if (single && a->input_crossings[1] > 0) return "to crosses itself";
  if (!single) return "contours of the frames cross themselves or each other";
  if (a->repair_unrepaired > 0)
    return "strands cross that pass through each other between frames "
           "that do not cross: no repair separates them";
  if (a->repair_events > 0) return "the repair did not separate every crossing";
  if (a->repair_scan_crossing == 0)
    return "the frames cross between the scanned times (t = k/32)";
  return "no start point or choice of matches the morph is free to make "
         "avoids the crossing";
}

/* "repaired_frames" (the frames the repair moved, with the largest
 * displacement of each) and "repair" (what the scan found and did). */
static bool add_repair(api_ctx *ctx, cJSON *o, const api_morph_plan *pl,
                       const km_morph_avoidance *a) {
  cJSON *list = cJSON_CreateArray(), *r = cJSON_CreateObject();
  if (list == NULL || r == NULL) {
    cJSON_Delete(list);
    cJSON_Delete(r);
    return api__oom(ctx);
  }
  if (!api__add_item(ctx, o, "repaired_frames", list)) {
    cJSON_Delete(r);
    return false;
  }
  if (!api__add_item(ctx, o, "repair", r)) return false;
  bool ok = true;
  for (size_t i = 0; ok && i < pl->nframes; i++) {
    double moved = km_morph_repaired(pl->morph, pl->frames[i].t);
    if (!(moved > 0)) continue;
    cJSON *f = cJSON_CreateObject();
    if (f == NULL || !cJSON_AddItemToArray(list, f)) {
      cJSON_Delete(f);
      return api__oom(ctx);
    }
    ok = api__add_num(ctx, f, "frame", (double)i) &&
         api__add_num(ctx, f, "displacement", moved);
  }
  return ok &&
         api__add_num(ctx, r, "scan_crossing_frames",
                      (double)a->repair_scan_crossing) &&
         api__add_num(ctx, r, "events", (double)a->repair_events) &&
         api__add_num(ctx, r, "unrepaired", (double)a->repair_unrepaired) &&
         api__add_num(ctx, r, "checks_crossing",
                      (double)a->repair_checks_crossing);
}

cJSON *api__intersections_json(api_ctx *ctx, const api_morph_plan *pl) {
  km_morph_avoidance a;
  memset(&a, 0, sizeof a);
  if (!pl->shapes && pl->morph) km_morph_avoided(pl->morph, &a);
  double tol = api__crossing_tolerance(pl);
  cJSON *o = cJSON_CreateObject(), *frames = cJSON_CreateArray();
  if (o == NULL || frames == NULL) {
    cJSON_Delete(o);
    cJSON_Delete(frames);
    api__oom(ctx);
    return NULL;
  }
  size_t crossing = 0;
  bool ok = api__add_item(ctx, o, "crossing_frames", frames);
  for (size_t i = 0; ok && i < pl->nframes; i++)
    if (frame_crossings(pl, &pl->frames[i], tol) > 0) {
      cJSON *n = api__number((double)i);
      if (n == NULL) {
        ok = api__oom(ctx);
        break;
      }
      cJSON_AddItemToArray(frames, n);
      crossing++;
    }
  const char *why = crossing_reason(&a, !pl->shapes, crossing);
  ok = ok && api__add_item(ctx, o, "reason",
                           why ? cJSON_CreateString(why) : cJSON_CreateNull());
  ok = ok && api__add_item(ctx, o, "changed", cJSON_CreateBool(a.changed)) &&
       api__add_num(ctx, o, "previews", (double)a.previews) &&
       api__add_num(ctx, o, "preview_crossings_before",
                    (double)a.crossings_before) &&
       api__add_num(ctx, o, "preview_crossings_after",
                    (double)a.crossings_after);
  if (ok && !pl->shapes) ok = add_repair(ctx, o, pl, &a);
  if (ok) return o;
  cJSON_Delete(o);
  return NULL;
}
