/* morph_place.h - where a frame goes (morph_place.c): anchor "fit"
 * (2-D Procrustes onto the linear blend of the inputs), "start" or
 * "centroid"; internal to the core. */
#ifndef KM_MORPH_PLACE_H
#define KM_MORPH_PLACE_H

#include <stddef.h>

#include "morph_internal.h"

/* The placement targets of planned frames, taken once per morph from
 * m->plan into m->place_ab, place_w_sum, place_qa and place_qb.
 * KM_ENOMEM (err). */
km_status km__place_plan_targets(km_morph *m, km_error *err);
/* Rigid motion (rotation about the origin by *rot, then translation T)
 * that places frame t, a curve f parametrised by arc length over [0, Lt].
 * KM_OK or KM_ENOMEM (*rot and T then unspecified). */
km_status km__place_frame(const km_morph *m, double t, const km_curve *f,
                          double Lt, double *rot, double T[2]);
/* The same for a planned frame given by its points F at the plan's nb
 * breaks (after km__place_plan_targets). */
void km__place_planned(const km_morph *m, double t, const double (*F)[2],
                       size_t nb, double *rot, double T[2]);

#endif
