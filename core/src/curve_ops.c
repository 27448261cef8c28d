/* curve_ops.c - exact knot-level operations on B-spline / NURBS curves:
 * knot insertion, split, reverse, Bezier extraction, degree elevation,
 * reparameterisation, rigid transforms and making two curves compatible.
 *
 * DESIGN. Everything that changes the basis works on homogeneous points
 * (hcurve.h, hcurve.c), which makes it exact for rational curves too.
 */
#include <math.h>
#include <string.h>

#include "hcurve.h"
#include "internal.h"
#include "kernels.h"
#include "km/alloc.h"
#include "km/curve.h"
#include "km/limits.h"

/* ---- public operations ----------------------------------------------- */

static km_status check_curve(const km_curve *c, km_error *err) {
  if (!c || !c->knots || !c->cp || c->degree < KM_MIN_DEGREE ||
      c->degree > KM_MAX_DEGREE || c->n < (size_t)c->degree + 1)
    return km__fail(err, KM_EINVAL, KM_FIELD_NONE, -1, NAN,
                    "not a valid curve");
  return KM_OK;
}

static size_t multiplicity(const km_curve *c, double t) {
  size_t s = 0;
  for (size_t i = 0; i < c->n + (size_t)c->degree + 1; i++)
    if (c->knots[i] == t) s++;
  return s;
}

/* Insert t r times, r already limited; result in *out. */
static km_status insert_times(km_curve *out, const km_curve *c, double t,
                              size_t r) {
  km__hcurve h, q;
  km__h_init(&h);
  km__h_init(&q);
  double *x = NULL;
  km_status st = km__h_from_curve(&h, c, 2);
  if (st) goto cleanup;
  x = km__malloc((r ? r : 1) * sizeof(double));
  if (!x) {
    st = KM_ENOMEM;
    goto cleanup;
  }
  for (size_t i = 0; i < r; i++) x[i] = t;
  st = km__h_refine(&q, &h, x, r);
  if (st) goto cleanup;
  st = km__h_to_curve(out, &q, c->closed);
cleanup:
  km__free(x);
  km__h_free(&h);
  km__h_free(&q);
  return st;
}

/* Insert t (within the domain) `times` times, capped so that no interior
 * multiplicity exceeds the degree; at a domain end nothing is inserted.
 * out: a new curve owned by the caller (km_curve_free), same trace and
 * parameterisation, closed flag kept. Returns KM_OK, KM_EINVAL (not a
 * curve; times < 0, field KM_FIELD_TIMES), KM_ENONFINITE (t), KM_ERANGE (t
 * outside the domain, err->param = t), KM_ENOMEM. Thread-safe. */
km_status km_curve_insert_knot(km_curve *out, const km_curve *c, double t,
                               int times, km_error *err) {
  km_status st = check_curve(c, err);
  if (st) return st;
  if (times < 0)
    return km__fail(err, KM_EINVAL, KM_FIELD_TIMES, -1, t,
                    "times must not be negative (got %d)", times);
  if (!isfinite(t))
    return km__fail(err, KM_ENONFINITE, KM_FIELD_NONE, -1, t,
                    "knot value is not finite");
  double t0, t1;
  km_curve_domain(c, &t0, &t1);
  if (t < t0 || t > t1)
    return km__fail(err, KM_ERANGE, KM_FIELD_NONE, -1, t,
                    "knot %g lies outside the domain [%g, %g]", t, t0, t1);
  size_t r = 0;
  if (t > t0 && t < t1) {
    size_t s = multiplicity(c, t);
    r = (size_t)c->degree > s ? (size_t)c->degree - s : 0;
    if ((size_t)times < r) r = (size_t)times;
  }
  st = insert_times(out, c, t, r);
  if (st) return km__fail(err, st, KM_FIELD_NONE, -1, t, NULL);
  return KM_OK;
}

/* Split at t strictly inside the domain into left on [t0, t] and right on
 * [t, t1], both open, meeting in one bit-identical point; each is owned by
 * the caller. Returns KM_OK, KM_EINVAL, KM_ERANGE / KM_ENONFINITE (t not
 * inside), KM_ENOMEM; on failure neither output is written. */
km_status km_curve_split(const km_curve *c, double t, km_curve *left,
                         km_curve *right, km_error *err) {
  km_status st = check_curve(c, err);
  if (st) return st;
  double t0, t1;
  km_curve_domain(c, &t0, &t1);
  if (!(t > t0 && t < t1))
    return km__fail(err, isfinite(t) ? KM_ERANGE : KM_ENONFINITE, KM_FIELD_NONE,
                    -1, t, "split parameter %g is not inside (%g, %g)", t, t0,
                    t1);
  km_curve ins, l, r;
  km_curve_init(&ins);
  km_curve_init(&l);
  km_curve_init(&r);
  int p = c->degree;
  size_t s = multiplicity(c, t);
  st = insert_times(&ins, c, t, (size_t)p > s ? (size_t)p - s : 0);
  if (st) goto cleanup;
  size_t f = 0;
  while (ins.knots[f] != t) f++;
  size_t nl = f, nr = ins.n - f + 1;
  bool rat = ins.w != NULL;
  st = km__curve_alloc(&l, p, nl, rat);
  if (st) goto cleanup;
  st = km__curve_alloc(&r, p, nr, rat);
  if (st) goto cleanup;
  memcpy(l.knots, ins.knots, (f + (size_t)p) * sizeof(double));
  l.knots[f + (size_t)p] = t;
  memcpy(l.cp, ins.cp, 2 * nl * sizeof(double));
  r.knots[0] = t;
  memcpy(r.knots + 1, ins.knots + f,
         (ins.n + (size_t)p + 1 - f) * sizeof(double));
  memcpy(r.cp, ins.cp + 2 * (f - 1), 2 * nr * sizeof(double));
  if (rat) {
    memcpy(l.w, ins.w, nl * sizeof(double));
    memcpy(r.w, ins.w + (f - 1), nr * sizeof(double));
  }
  *left = l;
  *right = r;
  km_curve_init(&l);
  km_curve_init(&r);
cleanup:
  if (st) km__fail(err, st, KM_FIELD_NONE, -1, t, NULL);
  km_curve_free(&ins);
  km_curve_free(&l);
  km_curve_free(&r);
  return st;
}

/* Same trace backwards on the same domain: C_rev(a + b - t) = C(t).
 * Returns KM_OK, KM_EINVAL, KM_ENOMEM; out owned by the caller. */
km_status km_curve_reverse(km_curve *out, const km_curve *c, km_error *err) {
  km_status st = check_curve(c, err);
  if (st) return st;
  km_curve r;
  st = km__curve_alloc(&r, c->degree, c->n, c->w != NULL);
  if (st) return km__fail(err, st, KM_FIELD_NONE, -1, NAN, NULL);
  size_t n = c->n, nk = n + (size_t)c->degree + 1;
  double a = c->knots[0], b = c->knots[nk - 1];
  for (size_t i = 0; i < nk; i++) r.knots[i] = (a + b) - c->knots[nk - 1 - i];
  /* the clamped ends must stay exactly a and b */
  for (size_t i = 0; i <= (size_t)c->degree; i++) {
    r.knots[i] = a;
    r.knots[nk - 1 - i] = b;
  }
  for (size_t i = 0; i < n; i++) {
    r.cp[2 * i] = c->cp[2 * (n - 1 - i)];
    r.cp[2 * i + 1] = c->cp[2 * (n - 1 - i) + 1];
    if (c->w) r.w[i] = c->w[n - 1 - i];
  }
  r.closed = c->closed;
  *out = r;
  return KM_OK;
}

/* Bezier extraction: every interior knot raised to multiplicity degree.
 * Returns KM_OK, KM_EINVAL, KM_ENOMEM; out owned by the caller. */
km_status km_curve_to_bezier(km_curve *out, const km_curve *c, km_error *err) {
  km__hcurve h, q;
  km__h_init(&h);
  km__h_init(&q);
  km_status st = check_curve(c, err);
  if (st) return st;
  st = km__h_from_curve(&h, c, 2);
  if (!st) st = km__h_to_bezier(&q, &h);
  if (!st) st = km__h_to_curve(out, &q, c->closed);
  if (st) km__fail(err, st, KM_FIELD_NONE, -1, NAN, NULL);
  km__h_free(&h);
  km__h_free(&q);
  return st;
}

/* Degree raised by times >= 0 (exact; homogeneous for NURBS); each
 * distinct knot's multiplicity grows by times. Returns KM_OK, KM_EINVAL
 * (times < 0, field KM_FIELD_TIMES), KM_EDEGREE (degree + times above
 * KM_MAX_DEGREE, field KM_FIELD_TIMES), KM_ENOMEM; out owned by the
 * caller. */
km_status km_curve_elevate(km_curve *out, const km_curve *c, int times,
                           km_error *err) {
  km__hcurve h, q;
  km__h_init(&h);
  km__h_init(&q);
  km_status st = check_curve(c, err);
  if (st) return st;
  if (times < 0)
    return km__fail(err, KM_EINVAL, KM_FIELD_TIMES, -1, NAN,
                    "times must not be negative (got %d)", times);
  if (times > KM_MAX_DEGREE - c->degree)
    return km__fail(err, KM_EDEGREE, KM_FIELD_TIMES, -1, NAN,
                    "degree %d raised %d times exceeds %d", c->degree, times,
                    KM_MAX_DEGREE);
  st = km__h_from_curve(&h, c, 2);
  if (!st) st = km__h_elevate(&q, &h, times);
  if (!st) st = km__h_to_curve(out, &q, c->closed);
  if (st) km__fail(err, st, KM_FIELD_NONE, -1, NAN, NULL);
  km__h_free(&h);
  km__h_free(&q);
  return st;
}

/* Map the knots of h linearly onto [t0, t1], ends exact, order kept. */
static void reparam_knots(double *U, size_t nk, int p, double t0, double t1) {
  double a = U[0], b = U[nk - 1], f = (t1 - t0) / (b - a);
  for (size_t i = 0; i < nk; i++) {
    double v = t0 + (U[i] - a) * f;
    if (v < t0) v = t0;
    if (v > t1) v = t1;
    if (i > 0 && v < U[i - 1]) v = U[i - 1];
    U[i] = v;
  }
  for (size_t i = 0; i <= (size_t)p; i++) {
    U[i] = t0;
    U[nk - 1 - i] = t1;
  }
}

/* Linear map of the domain onto [t0, t1]; the trace is unchanged. Returns
 * KM_OK, KM_EINVAL, KM_ENONFINITE, KM_ERANGE (t0 >= t1 or beyond
 * KM_MAX_COORDINATE), KM_ENOMEM; out owned by the caller. */
km_status km_curve_reparam(km_curve *out, const km_curve *c, double t0,
                           double t1, km_error *err) {
  km_status st = check_curve(c, err);
  if (st) return st;
  if (!isfinite(t0) || !isfinite(t1))
    return km__fail(err, KM_ENONFINITE, KM_FIELD_NONE, -1, NAN,
                    "domain ends must be finite");
  if (!(t0 < t1) || fabs(t0) > KM_MAX_COORDINATE ||
      fabs(t1) > KM_MAX_COORDINATE)
    return km__fail(err, KM_ERANGE, KM_FIELD_NONE, -1, NAN,
                    "domain [%g, %g] is empty or too large", t0, t1);
  km_curve r;
  st = km_curve_copy(&r, c, err);
  if (st) return st;
  reparam_knots(r.knots, r.n + (size_t)r.degree + 1, r.degree, t0, t1);
  *out = r;
  return KM_OK;
}

/* Rigid motion x' = R(rot) x + (tx, ty) of the control points (exact for
 * NURBS too: rational curves are affinely invariant). Returns KM_OK,
 * KM_EINVAL, KM_ENONFINITE, KM_ERANGE (a point beyond KM_MAX_COORDINATE,
 * err->index names it), KM_ENOMEM; out owned by the caller. */
km_status km__curve_transform_in_place(km_curve *c, double rot, double tx,
                                       double ty, km_error *err) {
  if (!isfinite(rot) || !isfinite(tx) || !isfinite(ty))
    return km__fail(err, KM_ENONFINITE, KM_FIELD_NONE, -1, NAN,
                    "rotation and translation must be finite");
  double cs = cos(rot), sn = sin(rot);
  for (size_t i = 0; i < c->n; i++) {
    double x = c->cp[2 * i], y = c->cp[2 * i + 1];
    double nx = cs * x - sn * y + tx, ny = sn * x + cs * y + ty;
    if (!(fabs(nx) <= KM_MAX_COORDINATE && fabs(ny) <= KM_MAX_COORDINATE))
      return km__fail(err, KM_ERANGE, KM_FIELD_CONTROL_POINTS, (long)i, NAN,
                      "transformed control point %zu exceeds %g", i,
                      KM_MAX_COORDINATE);
    c->cp[2 * i] = nx;
    c->cp[2 * i + 1] = ny;
  }
  if (c->closed) {
    c->cp[2 * (c->n - 1)] = c->cp[0];
    c->cp[2 * (c->n - 1) + 1] = c->cp[1];
  }
  return KM_OK;
}

km_status km_curve_transform(km_curve *out, const km_curve *c, double rot,
                             double tx, double ty, km_error *err) {
  km_status st = check_curve(c, err);
  if (st) return st;
  km_curve r;
  km_curve_init(&r); /* a failed copy writes nothing, and r is freed */
  st = km_curve_copy(&r, c, err);
  if (!st) st = km__curve_transform_in_place(&r, rot, tx, ty, err);
  if (st) {
    km_curve_free(&r);
    return st;
  }
  *out = r;
  return KM_OK;
}

/* Interior knots of h missing from `other` (as multiset), sorted, written
 * to x (capacity: other's knot count); returns the count. Values of h
 * within `snap` of a knot of other are first moved onto it so that both
 * vectors end up bit-identical. */
static size_t missing_knots(const km__hcurve *h, const km__hcurve *o,
                            double *x) {
  int p = h->degree;
  size_t cnt = 0, i = (size_t)p + 1, j = (size_t)p + 1;
  size_t ie = h->n, je = o->n; /* interior knots are [p+1, n) */
  while (j < je) {
    double v = o->knots[j];
    if (i < ie && h->knots[i] < v) {
      i++;
    } else if (i < ie && h->knots[i] == v) {
      i++;
      j++;
    } else {
      x[cnt++] = v;
      j++;
    }
  }
  return cnt;
}

static void snap_knots(km__hcurve *b, const km__hcurve *a, double snap) {
  size_t j = (size_t)a->degree + 1;
  for (size_t i = (size_t)b->degree + 1; i < b->n; i++) {
    double v = b->knots[i];
    while (j < a->n && a->knots[j] < v - snap) j++;
    if (j < a->n && fabs(a->knots[j] - v) <= snap) b->knots[i] = a->knots[j];
  }
}

/* Interior knots within snap of a domain end are that end: a span
 * narrower than rounding there (left by a seam moved onto a knot) is
 * dropped with its control points. The basis functions of the remaining
 * points depend only on the remaining knots, so the trace is unchanged up
 * to the sliver's width; the end points are kept exactly, so a closed
 * curve stays closed. In place; h->n shrinks. */
static void drop_end_slivers(km__hcurve *h, double snap) {
  size_t p = (size_t)h->degree, n = h->n, nk = n + p + 1, dim = (size_t)h->dim;
  double *U = h->knots, *P = h->pw, t0 = U[0], t1 = U[nk - 1];
  size_t head = 0, tail = 0;
  while (p + 1 + head < n && U[p + 1 + head] <= t0 + snap) head++;
  while (n - 1 - tail > p + head && U[n - 1 - tail] >= t1 - snap) tail++;
  if (head == 0 && tail == 0) return;
  /* the first point moves onto the start it replaces, the last likewise */
  memcpy(P + head * dim, P, dim * sizeof *P);
  memcpy(P + (n - 1 - tail) * dim, P + (n - 1) * dim, dim * sizeof *P);
  memmove(P, P + head * dim, (n - head - tail) * dim * sizeof *P);
  memmove(U, U + head, (nk - head - tail) * sizeof *U);
  h->n = n - head - tail;
  for (size_t i = 0; i <= p; i++) {
    U[i] = t0;
    U[h->n + p - i] = t1;
  }
}

/* Both curves on [0, 1], of the larger degree, with one merged knot vector
 * (multiplicity the larger of the two; knots closer than 1e-13 are taken
 * as one, and as the domain's end within 1e-13 of it) and both rational if either is (unit weights for a polynomial
 * one). Traces unchanged, closed flags kept. Returns KM_OK, KM_EINVAL,
 * KM_ENOMEM; on failure neither output is written; outputs owned by the
 * caller. Thread-safe. */
km_status km_curve_make_compatible(const km_curve *a, const km_curve *b,
                                   km_curve *out_a, km_curve *out_b,
                                   km_error *err) {
  km_status st = check_curve(a, err);
  if (!st) st = check_curve(b, err);
  if (st) return st;
  km__hcurve ha, hb, ea, eb, ra, rb;
  km__h_init(&ha);
  km__h_init(&hb);
  km__h_init(&ea);
  km__h_init(&eb);
  km__h_init(&ra);
  km__h_init(&rb);
  km_curve ca, cb;
  km_curve_init(&ca);
  km_curve_init(&cb);
  double *x = NULL;
  int dim = (a->w || b->w) ? 3 : 2;
  int q = a->degree > b->degree ? a->degree : b->degree;
  st = km__h_from_curve(&ha, a, dim);
  if (st) goto cleanup;
  st = km__h_from_curve(&hb, b, dim);
  if (st) goto cleanup;
  reparam_knots(ha.knots, ha.n + (size_t)ha.degree + 1, ha.degree, 0.0, 1.0);
  reparam_knots(hb.knots, hb.n + (size_t)hb.degree + 1, hb.degree, 0.0, 1.0);
  drop_end_slivers(&ha, 1e-13);
  drop_end_slivers(&hb, 1e-13);
  st = km__h_elevate(&ea, &ha, q - a->degree);
  if (st) goto cleanup;
  st = km__h_elevate(&eb, &hb, q - b->degree);
  if (st) goto cleanup;
  /* knots a hair apart (rounding in the reparameterisation) are the same
   * knot: moving one by 1e-13 of the domain changes the curve by less than
   * rounding elsewhere does, while keeping both would add a sliver span */
  snap_knots(&eb, &ea, 1e-13);
  x = km__malloc((ea.n + eb.n + 2) * sizeof(double));
  if (!x) {
    st = KM_ENOMEM;
    goto cleanup;
  }
  size_t nxa = missing_knots(&ea, &eb, x);
  st = km__h_refine(&ra, &ea, x, nxa);
  if (st) goto cleanup;
  size_t nxb = missing_knots(&eb, &ea, x);
  st = km__h_refine(&rb, &eb, x, nxb);
  if (st) goto cleanup;
  if (ra.n != rb.n) {
    st = KM_EKNOTS;
    goto cleanup;
  }
  /* identical by construction; copy so rounding cannot tell them apart */
  memcpy(rb.knots, ra.knots, (ra.n + (size_t)q + 1) * sizeof(double));
  st = km__h_to_curve(&ca, &ra, a->closed);
  if (st) goto cleanup;
  st = km__h_to_curve(&cb, &rb, b->closed);
  if (st) goto cleanup;
  *out_a = ca;
  *out_b = cb;
  km_curve_init(&ca);
  km_curve_init(&cb);
cleanup:
  if (st) km__fail(err, st, KM_FIELD_NONE, -1, NAN, NULL);
  km__free(x);
  km__h_free(&ha);
  km__h_free(&hb);
  km__h_free(&ea);
  km__h_free(&eb);
  km__h_free(&ra);
  km__h_free(&rb);
  km_curve_free(&ca);
  km_curve_free(&cb);
  return st;
}
