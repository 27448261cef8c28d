/* fuzz_curves.c - libFuzzer target that turns its bytes into structurally
 * valid but extreme curves (coordinates from 1e-15 to 1e15, offsets far
 * from the origin, near-cusps, degenerate legs, degree 1..9, up to 800
 * control points, rational weights over four decades) and runs the core
 * directly: km_signature_compute, km_reconstruct, km_morph_create and
 * km_morph_frame. Each step may refuse with a status; what it returns must
 * keep the contract of its header, checked here against mathematics:
 *   - the signature's length is the curve's arc length;
 *   - corners are sorted, inside [0, length], with |turn| < pi;
 *   - a closed curve turns by a whole multiple of 2 pi;
 *   - the reconstruction starts at the signature's start point and its end
 *     lies within the promised tolerances of the input curve's end;
 *   - a morph frame is finite and so are its metrics.
 * Build and run with `make fuzz` / `make test-fuzz`.
 *
 * Layout of the input (missing bytes read as 0): family, degree, count
 * (2 bytes), scale exponent, offset, flags, tolerance exponent, frame time,
 * then the shape bytes the family consumes.
 */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "km/curve.h"
#include "km/limits.h"
#include "km/morph.h"
#include "km/reconstruct.h"
#include "km/signature.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static const double PI = 3.14159265358979323846;

/* Control points of the many-knot family, and of curves that are also
 * morphed: both bound the time an input takes. Signature work is linear in
 * the spans: under ASan+UBSan this family measured 0.1 to 0.25 ms a
 * control point for curves near the origin and up to 0.6 ms for rational
 * ones far from it at their tightest tolerance (directions there are
 * rounding noise, and pieces stay short), so 800 points keep within half
 * the one-second budget; 10^5 points cannot meet it at all:
 * tests/hardening times that case on the release build. A morph frame adds
 * a closure solve. */
#define MAX_POINTS 800
#define MAX_MORPH_POINTS 400
#define MAX_SMALL_POINTS 300
/* The morph signs its moved copy again at a tenth of the tolerance, which
 * is most of an input's time; a curve's evaluation costs about (p + 1)^2
 * (de Casteljau) and twice that with weights. Curves morphed stay within
 * MAX_MORPH_POINTS cubics' worth: a rational curve of degree 9 at 1e6
 * with degenerate legs, 58 points, took 1.2 s fuzzed with the morph (its
 * signature 23 ms at -O3), about 0.25 s without it. */
#define MAX_MORPH_WORK (MAX_MORPH_POINTS * 16)
/* The many-knot family likewise, from MAX_POINTS cubics' worth up: a
 * rational curve of degree 7 at 1e9, 738 points, took 0.9 to 1.1 s
 * fuzzed, 1.4 ms a point against 0.1 to 0.25 for cubics (degree 7:
 * at most 350 points; 9: 224). */
#define MANY_KNOTS_WORK (MAX_POINTS * 56)
static size_t many_knots_points(int degree, bool rational) {
  size_t per = (size_t)(degree + 1) * (size_t)(degree + 1) * (rational ? 2 : 1);
  size_t n = MANY_KNOTS_WORK / per;
  return n < MAX_POINTS ? n : MAX_POINTS;
}

typedef struct reader {
  const uint8_t *p;
  size_t n, i;
} reader;

static unsigned u8(reader *r) {
  return r->i < r->n ? r->p[r->i++] : 0u;
}
static unsigned u16(reader *r) {
  unsigned lo = u8(r);
  return lo | (u8(r) << 8);
}
/* A number in [-1, 1] from two bytes. */
static double sym(reader *r) {
  return u16(r) / 32767.5 - 1.0;
}

static void fail(const char *why, double a, double b) {
  fprintf(stderr, "fuzz_curves: %s (%.17g vs %.17g)\n", why, a, b);
  abort();
}

/* Fill pts (2n values, in about [-1, 1]^2) for one family. */
static size_t make_points(reader *r, unsigned family, int degree,
                          unsigned count, size_t max_points, double *pts) {
  size_t n = 0;
  switch (family % 6) {
  case 0: /* arbitrary points */
    n = (size_t)degree + 1 + count % 64;
    for (size_t i = 0; i < n; i++) {
      pts[2 * i] = sym(r);
      pts[2 * i + 1] = sym(r);
    }
    break;
  case 1: { /* regular polygon with a small jitter: smooth, convex */
    n = (size_t)degree + 1 + count % 200;
    if (n < 4) n = 4;
    double jit = pow(10.0, -(double)(u8(r) % 16));
    for (size_t i = 0; i < n; i++) {
      double a = 2 * PI * (double)i / (double)(n - 1);
      double rr = 1 + jit * sym(r);
      pts[2 * i] = rr * cos(a);
      pts[2 * i + 1] = rr * sin(a);
    }
    break;
  }
  case 2: { /* a hairpin: the polygon nearly reverses, by 10^-k */
    n = (size_t)degree + 1 + count % 16;
    if (n < 4) n = 4;
    double eps = pow(10.0, -(double)(u8(r) % 16));
    double del = pow(10.0, -(double)(u8(r) % 16));
    size_t k = 1 + u8(r) % (n - 2);
    for (size_t i = 0; i < n; i++) {
      double x = (double)i / (double)n, y = 0.1 * sym(r);
      if (i == k) {
        x = pts[2 * (i - 1)] + 0.5;
        y = pts[2 * (i - 1) + 1];
      } else if (i == k + 1) {
        x = pts[2 * (i - 1)] - 0.5 + del;
        y = pts[2 * (i - 1) + 1] + eps;
      }
      pts[2 * i] = x;
      pts[2 * i + 1] = y;
    }
    break;
  }
  case 3: { /* many knots: a gentle wave, up to max_points points */
    n = (size_t)degree + 1 + (size_t)count % (max_points - KM_MAX_DEGREE);
    double amp = pow(10.0, -(double)(u8(r) % 8));
    double freq = 1 + u8(r) % 64;
    for (size_t i = 0; i < n; i++) {
      double x = (double)i / (double)(n - 1);
      pts[2 * i] = 2 * x - 1;
      pts[2 * i + 1] = amp * sin(2 * PI * freq * x);
    }
    break;
  }
  case 4: { /* degenerate legs: points repeated up to degree + 1 times */
    size_t distinct = 2 + count % 24;
    for (size_t j = 0; j < distinct && n < MAX_SMALL_POINTS; j++) {
      double x = sym(r), y = sym(r);
      unsigned rep = 1 + u8(r) % (unsigned)(degree + 1);
      for (unsigned q = 0; q < rep && n < MAX_SMALL_POINTS; q++) {
        pts[2 * n] = x;
        pts[2 * n + 1] = y;
        n++;
      }
    }
    while (n < (size_t)degree + 1) {
      pts[2 * n] = pts[2 * n - 2] + 1;
      pts[2 * n + 1] = pts[2 * n - 1];
      n++;
    }
    break;
  }
  default: { /* collinear, or one repeated point (zero length) */
    n = (size_t)degree + 1 + count % 32;
    double dx = (count & 1) ? 0 : 1, dy = sym(r);
    for (size_t i = 0; i < n; i++) {
      double s = (family & 8) ? sym(r) : (double)i / (double)n;
      pts[2 * i] = s * dx;
      pts[2 * i + 1] = s * dy;
    }
    break;
  }
  }
  return n;
}

/* Clamped knots with interior increments 0, 1, 2 or 1e-9 (multiplicity
 * capped at degree), or uniform for long curves. */
static void make_knots(reader *r, int degree, size_t n, bool uniform,
                       double *knots) {
  size_t m = n + (size_t)degree + 1;
  double t = 0;
  int mult = 0;
  for (int i = 0; i <= degree; i++) knots[i] = 0;
  for (size_t i = (size_t)degree + 1; i < n; i++) {
    double inc = 1;
    if (!uniform) {
      unsigned b = u8(r) % 8;
      inc = b == 0 ? 0 : b == 1 ? 2 : b == 2 ? 1e-9 : 1;
    }
    if (inc == 0 && mult + 1 >= degree) inc = 1;
    mult = inc == 0 ? mult + 1 : 0;
    t += inc;
    knots[i] = t;
  }
  t += 1;
  for (size_t i = n; i < m; i++) knots[i] = t;
}

static double max_abs(const double *v, size_t n) {
  double m = 0;
  for (size_t i = 0; i < n; i++) {
    if (!isfinite(v[i])) fail("non-finite value in a result", v[i], (double)i);
    if (fabs(v[i]) > m) m = fabs(v[i]);
  }
  return m;
}

static void check_signature(const km_curve *c, const km_signature *sig) {
  double L = km_curve_length(c);
  if (!(sig->length > 0) || !isfinite(sig->length))
    fail("signature length not positive and finite", sig->length, L);
  /* Both lengths are integrals of a speed computed from the coordinates:
   * each span's carries up to 8 p ulps of the largest coordinate M of
   * rounding, times the ratio r of the extreme weights of a rational curve
   * (km__bspan_length), so two ways of measuring may differ by twice that
   * per span beyond the 1e-6 asked of them. */
  double M = 0, r = 1;
  size_t spans = 0;
  for (size_t i = 0; i < 2 * c->n; i++) M = fmax(M, fabs(c->cp[i]));
  if (c->w != NULL) {
    double lo = c->w[0], hi = c->w[0];
    for (size_t i = 1; i < c->n; i++) {
      lo = fmin(lo, c->w[i]);
      hi = fmax(hi, c->w[i]);
    }
    r = hi / lo;
  }
  for (size_t i = (size_t)c->degree; i < c->n; i++)
    spans += c->knots[i + 1] > c->knots[i];
  double rounding = 16 * DBL_EPSILON * c->degree * M * r * (double)spans;
  if (fabs(sig->length - L) > 1e-6 * L + rounding)
    fail("signature length is not the curve's arc length", sig->length, L);
  if (!isfinite(sig->turning) || !isfinite(sig->angle))
    fail("turning or start angle not finite", sig->turning, sig->angle);
  double prev = 0;
  for (size_t i = 0; i < sig->ncorners; i++) {
    const km_corner *k = &sig->corners[i];
    if (!(k->s >= prev) || k->s > sig->length * (1 + 1e-12))
      fail("corner out of order or outside [0, length]", k->s, prev);
    if (!(fabs(k->turn) < PI))
      fail("corner turn outside (-pi, pi)", k->turn, PI);
    prev = k->s;
  }
  if (sig->closed) {
    double w = sig->turning / (2 * PI);
    if (fabs(w - nearbyint(w)) > 1e-3)
      fail("closed curve turns by a fraction of 2 pi", sig->turning,
           2 * PI * nearbyint(w));
  }
}

static void check_reconstruction(const km_curve *c, const km_signature *sig,
                                 double sig_tol, const km_curve *rc,
                                 double bound, double scale) {
  double t0, t1, pc[1][2], pr[1][2], r0, r1;
  if (!(bound >= 0) || !isfinite(bound))
    fail("error bound negative or not finite", bound, 0);
  (void)max_abs(rc->cp, 2 * rc->n);
  /* Both ends are computed from numbers of magnitude up to scale (the
   * coordinates plus the length): a few dozen ulps of it is rounding. */
  double slack = 64 * DBL_EPSILON * scale;
  km_curve_domain(rc, &r0, &r1);
  km_curve_eval(rc, r0, 0, pr);
  if (hypot(pr[0][0] - sig->start[0], pr[0][1] - sig->start[1]) > bound + slack)
    fail("reconstruction does not start at the start point", pr[0][0],
         sig->start[0]);
  km_curve_domain(c, &t0, &t1);
  km_curve_eval(c, t1, 0, pc);
  km_curve_eval(rc, r1, 0, pr);
  double gap = hypot(pc[0][0] - pr[0][0], pc[0][1] - pr[0][1]);
  if (gap > 2 * sig_tol + bound + slack)
    fail("reconstructed end misses the curve's end beyond the tolerances", gap,
         2 * sig_tol + bound);
}

static void run_morph(reader *r, const km_curve *c, const km_signature *sig,
                      unsigned flags, double tol) {
  km_curve moved, to;
  km_curve_init(&moved);
  km_curve_init(&to);
  km_morph *m = NULL;
  double rot = PI * sym(r), dx = sym(r), dy = sym(r);
  if (km_curve_transform(&moved, c, rot, dx, dy, NULL) != KM_OK) goto done;
  /* The reversed copy has the opposite turning of a closed curve: the
   * morph must refuse it or re-orient it, never break. */
  if (flags & 0x80) {
    if (km_curve_reverse(&to, &moved, NULL) != KM_OK) goto done;
  } else {
    to = moved;
    km_curve_init(&moved);
  }
  km_morph_options o;
  km_morph_options_default(&o);
  unsigned b = u8(r);
  o.method = (b & 1) ? KM_METHOD_LINEAR : KM_METHOD_CURVATURE;
  o.blend = (b & 2) ? KM_BLEND_PAPER : KM_BLEND_TURNING;
  o.closure = (km_closure)((b >> 2) % 6);
  o.anchor = (km_anchor)((b >> 5) % 3);
  o.orient = (flags & 0x40) ? KM_ORIENT_KEEP : KM_ORIENT_AUTO;
  o.degree = (flags & 0x20) ? 5 : 3;
  o.tolerance = tol;
  o.auto_matches = (u8(r) & 1) != 0;
  km_morph_input from = {c, sig}, dest = {&to, NULL};
  km_error err;
  if (km_morph_create(&m, &from, &dest, &o, &err) != KM_OK) goto done;
  double t = u8(r) / 255.0;
  km_curve f;
  km_curve_init(&f);
  km_frame_metrics fm;
  if (km_morph_frame(m, t, &f, &fm, NULL, &err) == KM_OK) {
    (void)max_abs(f.cp, 2 * f.n);
    double mv[4] = {fm.length, fm.max_abs_kappa, fm.bending_energy,
                    fm.closure_gap};
    (void)max_abs(mv, 4);
    if (!(fm.length > 0) || fm.self_intersections < 0)
      fail("frame metrics out of range", fm.length,
           (double)fm.self_intersections);
  }
  km_curve_free(&f);
done:
  km_morph_free(m);
  km_curve_free(&moved);
  km_curve_free(&to);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  reader rd = {data, size, 0};
  reader *r = &rd;
  unsigned family = u8(r);
  int degree = 1 + (int)(u8(r) % KM_MAX_DEGREE);
  unsigned count = u16(r);
  double scale = pow(10.0, (double)((int)(u8(r) % 31) - 15));
  unsigned ob = u8(r);
  double offset = (ob & 1) ? pow(10.0, (double)((ob >> 1) % 16)) : 0;
  unsigned flags = u8(r);
  unsigned tb = u8(r);

  double *pts = malloc(sizeof(double) * 2 * (MAX_POINTS + 16));
  double *knots = malloc(sizeof(double) * (MAX_POINTS + 16 + KM_MAX_DEGREE));
  double *w = malloc(sizeof(double) * (MAX_POINTS + 16));
  km_curve c;
  km_signature sig;
  km_curve rc;
  km_curve_init(&c);
  km_signature_init(&sig);
  km_curve_init(&rc);
  if (pts == NULL || knots == NULL || w == NULL) goto done;

  size_t n = make_points(r, family, degree, count,
                         many_knots_points(degree, (flags & 2) != 0), pts);
  bool closed = (flags & 1) && n > (size_t)degree + 1;
  for (size_t i = 0; i < 2 * n; i++) pts[i] = pts[i] * scale + offset;
  if (closed) {
    pts[2 * (n - 1)] = pts[0];
    pts[2 * (n - 1) + 1] = pts[1];
  }
  make_knots(r, degree, n, family % 6 == 3, knots);
  bool rational = (flags & 2) != 0;
  if (rational)
    for (size_t i = 0; i < n; i++)
      w[i] = pow(10.0, ((double)(u8(r) % 9) - 4) / 2);
  if (km_curve_create(&c, degree, n, knots, pts, rational ? w : NULL, closed,
                      NULL) != KM_OK)
    goto done;

  bool verbose = getenv("FUZZ_CURVES_VERBOSE") != NULL;
  if (verbose) {
    fprintf(stderr,
            "family %u degree %d n %zu closed %d rational %d "
            "scale %g offset %g flags 0x%02x\n",
            family % 6, degree, n, (int)closed, (int)rational, scale, offset,
            flags);
    /* the same curve as a POST /v1/signature body, to reproduce it */
    fprintf(stderr,
            "{\"curve\":{\"type\":\"bspline\",\"degree\":%d,"
            "\"closed\":%s,\"knots\":[",
            degree, closed ? "true" : "false");
    for (size_t i = 0; i < n + (size_t)degree + 1; i++)
      fprintf(stderr, "%s%.17g", i ? "," : "", knots[i]);
    fprintf(stderr, "],\"control_points\":[");
    for (size_t i = 0; i < n; i++)
      fprintf(stderr, "%s[%.17g,%.17g]", i ? "," : "", pts[2 * i],
              pts[2 * i + 1]);
    fprintf(stderr, "]");
    if (rational) {
      fprintf(stderr, ",\"weights\":[");
      for (size_t i = 0; i < n; i++)
        fprintf(stderr, "%s%.17g", i ? "," : "", w[i]);
      fprintf(stderr, "]");
    }
    fprintf(stderr, "},\"tolerance\":%.17g}\n",
            (flags & 4) ? 0 : scale * pow(10.0, -(double)(tb % 14)));
  }
  /* tolerance: the default (0), or 10^-k of the scale */
  double tol = (flags & 4) ? 0 : scale * pow(10.0, -(double)(tb % 14));
  km_error err;
  clock_t c0 = clock();
  km_status sst = km_signature_compute(&c, tol, &sig, &err);
  if (verbose)
    fprintf(stderr,
            "tol %g signature %s in %.3f s, length %.17g, %zu "
            "kappa knots\n",
            tol, km_status_name(sst), (double)(clock() - c0) / CLOCKS_PER_SEC,
            sig.length, sst == KM_OK ? sig.kappa.n : (size_t)0);
  if (sst != KM_OK) goto done;
  check_signature(&c, &sig);

  /* The tolerance the signature promises: the asked one raised to its
   * floors, a part in 1e13 of the length and the rounding of the curve
   * itself (limits.h). */
  double L = sig.length;
  double sig_tol = tol <= 0 ? 1e-5 * L : tol;
  sig_tol = fmax(sig_tol, KM_MIN_RELATIVE_TOLERANCE * L);
  sig_tol = fmax(sig_tol, KM_MIN_TOLERANCE_ULPS * DBL_EPSILON * degree *
                              max_abs(c.cp, 2 * c.n));
  double bound = -1;
  int rdeg = (flags & 8) ? 5 : 3;
  c0 = clock();
  km_status rst = km_reconstruct(&sig, rdeg, tol, &rc, &bound, &err);
  if (verbose)
    fprintf(stderr, "reconstruct (degree %d) %s in %.3f s, %zu points\n", rdeg,
            km_status_name(rst), (double)(clock() - c0) / CLOCKS_PER_SEC,
            rst == KM_OK ? rc.n : (size_t)0);
  if (rst == KM_OK)
    check_reconstruction(&c, &sig, sig_tol, &rc, bound,
                         max_abs(c.cp, 2 * c.n) + L);

  /* and its planned pieces, with the nodes of every pass and the crossings
   * counted on its preview frames, grow as (L / tol)^(1/4) (cubic Hermite
   * pieces err by h^4 max|theta'''| / 384): counted from 1e-8 of the
   * scale, where the bound above was measured (a rational cubic of 44
   * points at 1e-13 took 1.5-2.2 s with its morph, 6,615 signature
   * pieces), and of the length for the tolerance the morph keeps (raised
   * to its floors), whichever is finer: a closed quartic with degenerate
   * legs jumping across its box is 6 to 10 times longer than the box's
   * half-width, and at 1e-13 of its length took 2.2 s with its morph (24
   * points). */
  double fine = fmax(tol > 0 ? pow(1e-8 * scale / tol, 0.25) : 1.0,
                     pow(1e-8 * L / sig_tol, 0.25));
  double morph_work = (double)n * (degree + 1) * (degree + 1) *
                      (rational ? 2 : 1) * fmax(fine, 1.0);
  if (morph_work <= MAX_MORPH_WORK && (flags & 0x10)) {
    c0 = clock();
    run_morph(r, &c, &sig, flags, tol);
    if (verbose)
      fprintf(stderr, "morph in %.3f s\n",
              (double)(clock() - c0) / CLOCKS_PER_SEC);
  }

done:
  km_curve_free(&rc);
  km_signature_free(&sig);
  km_curve_free(&c);
  free(pts);
  free(knots);
  free(w);
  return 0;
}
