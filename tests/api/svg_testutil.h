/* svg_testutil.h - helpers for the SVG tests: parsing that must succeed,
 * comparison of two curves at equal parameters and as traces (two-sided
 * distance), and the path strings of tests/fixtures/shapes.json.
 * Header-only: each test binary is one translation unit.
 */
#ifndef KM_SVG_TESTUTIL_H
#define KM_SVG_TESTUTIL_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cJSON.h>

#include "fixtures.h"
#include "km/curve.h"
#include "../../api/src/svg.h"
#include "testutil.h"

/* Parse d (which must be valid) into c. */
static inline void st_parse(const char *d, km_curve *c) {
  size_t off = 0;
  char msg[256];
  km_curve_init(c);
  km_status st =
      api_svg_parse_path(d, strlen(d), 1e-9, c, &off, msg, sizeof msg);
  if (st != KM_OK)
    print_error("parsing \"%s\" failed at offset %zu: %s\n", d, off, msg);
  assert_status(st, KM_OK);
}

static inline void st_pos(const km_curve *c, double t, double p[2]) {
  double v[1][2];
  km_curve_eval(c, t, 0, v);
  p[0] = v[0][0];
  p[1] = v[0][1];
}

/* Largest |coordinate| of the control points, at least 1. */
static inline double st_scale(const km_curve *c) {
  double m = 1.0;
  for (size_t i = 0; i < 2 * c->n; i++)
    if (fabs(c->cp[i]) > m) m = fabs(c->cp[i]);
  return m;
}

/* Same domain and the same point at every sampled parameter (per = samples
 * per unit of parameter), within tol. */
static inline void st_same_at_params(const km_curve *a, const km_curve *b,
                                     double tol, const char *what) {
  double a0, a1, b0, b1;
  km_curve_domain(a, &a0, &a1);
  km_curve_domain(b, &b0, &b1);
  assert_close(a0, b0, 0);
  assert_close(a1, b1, 0);
  int n = (int)ceil((a1 - a0) * 40) + 1;
  for (int i = 0; i <= n; i++) {
    double t = a0 + (a1 - a0) * i / n, p[2], q[2];
    st_pos(a, t, p);
    st_pos(b, t, q);
    if (!(hypot(p[0] - q[0], p[1] - q[1]) <= tol)) {
      print_error("%s: at t = %g (%.17g, %.17g) vs (%.17g, %.17g)\n", what, t,
                  p[0], p[1], q[0], q[1]);
      fail();
    }
  }
}

/* Dense samples of a curve's trace, for nearest-point searches. */
typedef struct st_samples {
  const km_curve *c;
  double t0, t1;
  int n;
  double *xy; /* 2 (n + 1) */
} st_samples;

static inline void st_sample(const km_curve *c, st_samples *s) {
  s->c = c;
  km_curve_domain(c, &s->t0, &s->t1);
  s->n = (int)ceil((s->t1 - s->t0) * 256) + 1;
  if (s->n > 20000) s->n = 20000;
  s->xy = malloc(2 * ((size_t)s->n + 1) * sizeof *s->xy);
  assert_non_null(s->xy);
  for (int i = 0; i <= s->n; i++)
    st_pos(c, s->t0 + (s->t1 - s->t0) * i / s->n, s->xy + 2 * i);
}

/* Distance from p to the trace: the nearest sample, then a golden-section
 * search between its neighbours. */
static inline double st_dist_s(const st_samples *s, const double p[2]) {
  double best = INFINITY;
  int bi = 0;
  for (int i = 0; i <= s->n; i++) {
    double d = hypot(s->xy[2 * i] - p[0], s->xy[2 * i + 1] - p[1]);
    if (d < best) {
      best = d;
      bi = i;
    }
  }
  double lo = s->t0 + (s->t1 - s->t0) * (bi > 0 ? bi - 1 : 0) / s->n;
  double hi = s->t0 + (s->t1 - s->t0) * (bi < s->n ? bi + 1 : s->n) / s->n;
  const double g = 0.5 * (sqrt(5.0) - 1.0);
  for (int it = 0; it < 80; it++) {
    double m1 = hi - g * (hi - lo), m2 = lo + g * (hi - lo), q1[2], q2[2];
    st_pos(s->c, m1, q1);
    st_pos(s->c, m2, q2);
    double d1 = hypot(q1[0] - p[0], q1[1] - p[1]);
    double d2 = hypot(q2[0] - p[0], q2[1] - p[1]);
    if (d1 < best) best = d1;
    if (d2 < best) best = d2;
    if (d1 < d2)
      hi = m2;
    else
      lo = m1;
  }
  return best;
}

/* Two-sided distance between traces, sampled: the largest distance from a
 * sample of one curve to the other curve. */
static inline double st_trace_distance(const km_curve *a, const km_curve *b) {
  double worst = 0.0;
  for (int side = 0; side < 2; side++) {
    const km_curve *x = side ? b : a, *y = side ? a : b;
    st_samples ys;
    st_sample(y, &ys);
    double t0, t1;
    km_curve_domain(x, &t0, &t1);
    int n = (int)ceil((t1 - t0) * 24) + 1;
    if (n > 600) n = 600;
    for (int i = 0; i <= n; i++) {
      double p[2];
      st_pos(x, t0 + (t1 - t0) * i / n, p);
      double d = st_dist_s(&ys, p);
      if (d > worst) worst = d;
    }
    free(ys.xy);
  }
  return worst;
}

/* The a_d / b_d strings of shapes.json and the pair names. */
typedef struct st_shapes {
  cJSON *root;
  size_t n;
  const char *name[16];
  const char *d[16][2];
} st_shapes;

static inline void st_load_shapes(st_shapes *s) {
  memset(s, 0, sizeof *s);
  FILE *f = fopen(TF_SHAPES_PATH, "rb");
  assert_non_null(f);
  fseek(f, 0, SEEK_END);
  long len = ftell(f);
  fseek(f, 0, SEEK_SET);
  char *text = malloc((size_t)len + 1);
  assert_non_null(text);
  assert_int_equal(fread(text, 1, (size_t)len, f), (size_t)len);
  fclose(f);
  text[len] = '\0';
  s->root = cJSON_Parse(text);
  free(text);
  assert_non_null(s->root);
  const cJSON *pairs = cJSON_GetObjectItemCaseSensitive(s->root, "pairs");
  const cJSON *p;
  cJSON_ArrayForEach(p, pairs) {
    assert_true(s->n < 16);
    s->name[s->n] = cJSON_GetObjectItemCaseSensitive(p, "name")->valuestring;
    s->d[s->n][0] = cJSON_GetObjectItemCaseSensitive(p, "a_d")->valuestring;
    s->d[s->n][1] = cJSON_GetObjectItemCaseSensitive(p, "b_d")->valuestring;
    assert_non_null(s->d[s->n][0]);
    assert_non_null(s->d[s->n][1]);
    s->n++;
  }
  assert_int_equal(s->n, 6);
}

static inline void st_free_shapes(st_shapes *s) {
  cJSON_Delete(s->root);
}

/* Signed curvature (x'y'' - x''y') / |C'|^3 from the curve's own rational
 * derivatives. */
static inline double st_curvature(const km_curve *c, double t) {
  double d[3][2];
  km_curve_eval(c, t, 2, d);
  return (d[1][0] * d[2][1] - d[1][1] * d[2][0]) /
         pow(hypot(d[1][0], d[1][1]), 3);
}

#endif
