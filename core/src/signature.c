/* signature.c - the curvature signature value: creation from kappa and
 * corners, copy, free, and what it answers (theta, max |kappa|, bending
 * energy). Computing one from a curve is signature_walk.c and
 * signature_theta.c.
 */
#include <math.h>
#include <string.h>

#include "internal.h"
#include "km/alloc.h"
#include "km/limits.h"
#include "km/signature.h"

void km_signature_init(km_signature *sig) {
  if (!sig) return;
  memset(sig, 0, sizeof *sig);
  km_fn_init(&sig->kappa);
}

void km_signature_free(km_signature *sig) {
  if (!sig) return;
  km_fn_free(&sig->kappa);
  km__free(sig->corners);
  km_signature_init(sig);
}

km_status km_signature_copy(km_signature *out, const km_signature *sig,
                            km_error *err) {
  return km_signature_create(out, sig->length, sig->start, sig->angle,
                             &sig->kappa, sig->corners, sig->ncorners,
                             sig->closed, err);
}

/* ---- the checks of km_signature_create, in the order their errors are
 * reported: length, start, angle, kappa's domain, corners, turning. */
static km_status check_placement(double length, const double start[2],
                                 double angle, km_error *err) {
  if (!isfinite(length))
    return km__fail(err, KM_ENONFINITE, KM_FIELD_LENGTH, -1, NAN,
                    "length is not finite");
  if (!(length > 0) || length > KM_MAX_COORDINATE)
    return km__fail(err, KM_ERANGE, KM_FIELD_LENGTH, -1, NAN,
                    "length must be positive and at most %g",
                    KM_MAX_COORDINATE);
  for (int k = 0; k < 2; k++) {
    if (!isfinite(start[k]))
      return km__fail(err, KM_ENONFINITE, KM_FIELD_START, k, NAN,
                      "start point is not finite");
    if (fabs(start[k]) > KM_MAX_COORDINATE)
      return km__fail(err, KM_ERANGE, KM_FIELD_START, k, NAN,
                      "start point exceeds %g in magnitude", KM_MAX_COORDINATE);
  }
  if (!isfinite(angle) || fabs(angle) > 1e6)
    return km__fail(err, KM_ERANGE, KM_FIELD_ANGLE, -1, NAN,
                    "start angle must be finite and at most 1e6 radians");
  return KM_OK;
}

static km_status check_corners(const km_corner *corners, size_t ncorners,
                               double length, km_error *err) {
  for (size_t i = 0; i < ncorners; i++) {
    if (!isfinite(corners[i].s) || !isfinite(corners[i].turn))
      return km__fail(err, KM_ENONFINITE, KM_FIELD_CORNERS, (long)i, NAN,
                      "corner %zu is not finite", i);
    if (corners[i].s < 0 || corners[i].s > length * (1 + 1e-12))
      return km__fail(err, KM_ERANGE, KM_FIELD_CORNERS, (long)i, NAN,
                      "corner %zu lies outside [0, length]", i);
    if (!(fabs(corners[i].turn) < KM_PI))
      return km__fail(err, KM_ERANGE, KM_FIELD_CORNERS, (long)i, NAN,
                      "corner %zu turns by %g, outside (-pi, pi)", i,
                      corners[i].turn);
    if (i > 0 && corners[i].s < corners[i - 1].s)
      return km__fail(err, KM_EINVAL, KM_FIELD_CORNERS, (long)i, NAN,
                      "corners must be sorted by s (corner %zu)", i);
  }
  return KM_OK;
}

/* A bound on the integral of |kappa| plus |turn| at the corners, held to
 * the turns a signature may trace. */
static km_status check_turning(const km_fn *kappa, const km_corner *corners,
                               size_t ncorners, km_error *err) {
  double abs_turning = 0.0;
  int p = kappa->degree;
  for (size_t i = 0; i < kappa->n; i++)
    abs_turning += fabs(kappa->coef[i]) *
                   (kappa->knots[i + (size_t)p + 1] - kappa->knots[i]) /
                   (p + 1);
  for (size_t i = 0; i < ncorners; i++) abs_turning += fabs(corners[i].turn);
  double max_turns = KM_MAX_SIGNATURE_TURNS + 0.25 * (double)kappa->n;
  if (!(abs_turning <= 2 * KM_PI * max_turns))
    return km__fail(err, KM_ELIMIT, KM_FIELD_KAPPA_COEFFICIENTS, -1, NAN,
                    "the curve would turn up to %g times (|kappa| "
                    "integrates to %g rad); at most %g turns are traced",
                    abs_turning / (2 * KM_PI), abs_turning, max_turns);
  return KM_OK;
}

km_status km_signature_create(km_signature *out, double length,
                              const double start[2], double angle,
                              const km_fn *kappa, const km_corner *corners,
                              size_t ncorners, bool closed, km_error *err) {
  km_status st = check_placement(length, start, angle, err);
  if (st) return st;
  double a, b;
  km_fn_domain(kappa, &a, &b);
  if (fabs(a) > 1e-9 * length || fabs(b - length) > 1e-9 * length)
    return km__fail(err, KM_EKNOTS, KM_FIELD_KAPPA_KNOTS, -1, NAN,
                    "kappa must be defined on [0, length] = [0, %g], not "
                    "[%g, %g]",
                    length, a, b);
  st = check_corners(corners, ncorners, length, err);
  if (!st) st = check_turning(kappa, corners, ncorners, err);
  if (st) return st;
  km_signature r;
  km_signature_init(&r);
  st = km_fn_copy(&r.kappa, kappa, err);
  if (st) goto cleanup;
  /* snap the domain to [0, length] exactly */
  size_t nk = r.kappa.n + (size_t)r.kappa.degree + 1;
  for (size_t i = 0; i < nk; i++) {
    if (r.kappa.knots[i] < 0 || i <= (size_t)r.kappa.degree)
      r.kappa.knots[i] = 0.0;
    if (r.kappa.knots[i] > length || i >= r.kappa.n) r.kappa.knots[i] = length;
  }
  if (ncorners) {
    r.corners = km__malloc(ncorners * sizeof *r.corners);
    if (!r.corners) {
      st = km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
      goto cleanup;
    }
    memcpy(r.corners, corners, ncorners * sizeof *r.corners);
    for (size_t i = 0; i < ncorners; i++)
      if (r.corners[i].s > length) r.corners[i].s = length;
  }
  r.ncorners = ncorners;
  r.length = length;
  r.start[0] = start[0];
  r.start[1] = start[1];
  r.angle = angle;
  r.closed = closed;
  double turning = km_fn_integral(&r.kappa);
  for (size_t i = 0; i < ncorners; i++) turning += corners[i].turn;
  r.turning = turning;
  *out = r;
  km_signature_init(&r);
cleanup:
  km_signature_free(&r);
  return st;
}

double km_signature_theta(const km_signature *sig, double s) {
  /* integral of kappa over [0, s] by the antiderivative on the fly */
  km_fn F;
  double th = sig->angle;
  if (km_fn_antiderivative(&F, &sig->kappa, 0.0, NULL) == KM_OK) {
    th += km_fn_value(&F, s);
    km_fn_free(&F);
  }
  for (size_t i = 0; i < sig->ncorners; i++)
    if (sig->corners[i].s <= s) th += sig->corners[i].turn;
  return th;
}

double km_signature_max_abs_kappa(const km_signature *sig) {
  return km_fn_max_abs(&sig->kappa);
}

double km_signature_bending_energy(const km_signature *sig) {
  return km_fn_integral_sq(&sig->kappa);
}
