/* morph_linear.h - frames of method "linear" (morph_linear.c), the
 * control-point baseline; internal to the core. */
#ifndef KM_MORPH_LINEAR_H
#define KM_MORPH_LINEAR_H

#include "morph_internal.h"

/* Frame t of the linear morph: the compatible inputs m->lin blended point
 * by point into *out (the caller frees it). metrics (optional) are
 * measured on the curve itself; sig_out (optional) receives its signature,
 * or an empty one where the frame is singular (a cusp). KM_ECANCELLED
 * (err, via km__stopped) when poll says stop; the statuses of
 * km_curve_copy. */
km_status km__linear_frame(const km_morph *m, double t, km_curve *out,
                           km_frame_metrics *metrics, km_signature *sig_out,
                           km__poll *poll, km_error *err);

#endif
