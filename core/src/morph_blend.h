/* morph_blend.h - a frame's curvature blended from the two inputs'
 * (morph_blend.c), and the correspondence it follows; internal to the
 * core. */
#ifndef KM_MORPH_BLEND_H
#define KM_MORPH_BLEND_H

#include "morph_internal.h"

/* The blended signature of frame t in [0, 1] (before closure), at the
 * origin with the blended start angle, into *out (the caller frees it).
 * With matches and 0 < t < 1 the correspondence is the smooth one where
 * it stays monotone, else piecewise linear. KM_ENOMEM (err), KM_ENOCONVERGE
 * (an interpolation that is singular; no message) and the statuses of
 * km_signature_create. */
km_status km__blend_signature(const km_morph *m, double t, km_signature *out,
                              km_error *err);
/* Frame arc length s of frame t -> the normalised arc lengths *ra, *rb on
 * the inputs that correspond to it (piecewise-linear correspondence). */
void km__corresponding(const km_morph *m, double t, double s, double *ra,
                       double *rb);

#endif
