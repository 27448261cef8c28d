/* morph_kappa.h - the curvature of a planned morph's frames, tabled once
 * per morph (morph_kappa.c), so that a frame's metrics cost a pass over
 * the table instead of a blend of the inputs' pieces. Internal to the
 * core. */
#ifndef KM_MORPH_KAPPA_H
#define KM_MORPH_KAPPA_H

#include "km/status.h"
#include "pp_internal.h"

typedef struct km__kappa_table km__kappa_table;

/* The table of the turning blend without matches of two inputs whose
 * curvatures are ka and kb (each over its own arc length) into *out (NULL
 * on failure). KM_ENOMEM. */
km_status km__kappa_table_build(const km_pp *ka, const km_pp *kb,
                                km__kappa_table **out);
void km__kappa_table_free(km__kappa_table *k);

/* Metrics of frame t of inputs of lengths La and Lb: its curvature is the
 * blend plus, when c is not NULL, the lsq closure's psi' of coefficients c
 * (KM__CLOSURE_INTERVALS - 3 of them, as km__closure_kappa adds them).
 * *max_abs: the largest |kappa|, to rel relative (attained, at most rel
 * below the largest); *energy: the integral of kappa^2 over the frame's
 * arc length. KM_ENOMEM. */
km_status km__kappa_table_metrics(const km__kappa_table *k, double t, double La,
                                  double Lb, const double *c, double rel,
                                  double *max_abs, double *energy);

#endif
