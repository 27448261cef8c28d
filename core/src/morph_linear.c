/* morph_linear.c - frames of method "linear": the inputs made compatible
 * and their control points blended, the baseline the curvature morph is
 * compared with.
 */
#include <math.h>

#include "internal.h"
#include "km/signature.h"
#include "morph_linear.h"

static double curve_kappa(const km_curve *c, double t, double *speed) {
  double d[3][2];
  km_curve_eval(c, t, 2, d);
  double sp = hypot(d[1][0], d[1][1]);
  *speed = sp;
  return (d[1][0] * d[2][1] - d[1][1] * d[2][0]) / (sp * sp * sp);
}

/* Metrics of a curve measured directly (linear frames may have cusps, so
 * no signature is assumed): dense Gauss-Legendre per span. */
static km_status curve_metrics(const km_curve *c, double tol, km__poll *poll,
                               km_frame_metrics *mt) {
  double L = 0.0, kmax = 0.0, bend = 0.0;
  for (size_t i = (size_t)c->degree; i < c->n; i++) {
    double a = c->knots[i], b = c->knots[i + 1];
    if (!(b > a)) continue;
    for (int sub = 0; sub < 8; sub++) {
      double sa = a + (b - a) * sub / 8, sb = a + (b - a) * (sub + 1) / 8;
      double mid = 0.5 * (sa + sb), hw = 0.5 * (sb - sa);
      for (int k = 0; k < 16; k++) {
        double sp, kap = curve_kappa(c, mid + hw * km__gl16_x[k], &sp);
        double w = hw * km__gl16_w[k] * sp;
        L += w;
        if (isfinite(kap)) {
          bend += w * kap * kap;
          kmax = fmax(kmax, fabs(kap));
        }
      }
    }
  }
  mt->length = km_curve_length(c);
  (void)L;
  mt->max_abs_kappa = kmax;
  mt->bending_energy = bend;
  mt->self_intersections = km__self_intersections(c, tol, poll);
  mt->closure_gap = 0.0;
  /* -1 for a valid curve: stopped (the caller reports it) or no memory */
  return mt->self_intersections < 0 && !(poll && poll->stopped) ? KM_ENOMEM
                                                                : KM_OK;
}

km_status km__linear_frame(const km_morph *m, double t, km_curve *out,
                           km_frame_metrics *metrics, km_signature *sig_out,
                           km__poll *poll, km_error *err) {
  const km_curve *a = &m->lin[0], *b = &m->lin[1];
  km_curve f;
  km_status st = km_curve_copy(&f, a, err);
  if (st) return st;
  for (size_t i = 0; i < 2 * f.n; i++)
    f.cp[i] = (1 - t) * a->cp[i] + t * b->cp[i];
  if (f.w)
    for (size_t i = 0; i < f.n; i++) f.w[i] = (1 - t) * a->w[i] + t * b->w[i];
  f.closed = a->closed && b->closed;
  st = metrics ? curve_metrics(&f, m->tol, poll, metrics) : KM_OK;
  if (!st && sig_out) {
    km_signature_init(sig_out);
    /* a linear frame may be singular (cusp): then no signature, but out of
     * memory is no answer about the frame */
    st = km__signature_compute(&f, m->tol, 1e-5, poll, sig_out, NULL);
    if (st != KM_OK) km_signature_init(sig_out);
    if (st != KM_ENOMEM) st = KM_OK;
  }
  if (poll && poll->stopped) {
    km_curve_free(&f);
    km_signature_free(sig_out);
    return km__stopped(err);
  }
  if (st) {
    km_curve_free(&f);
    km_signature_free(sig_out);
    return km__fail(err, st, KM_FIELD_NONE, -1, NAN, NULL);
  }
  *out = f;
  return KM_OK;
}
