/* fixtures.h - loading the shared test fixtures (analytic.json, shapes.json).
 *
 * analytic.json holds curvature signatures whose curves are known exactly
 * (the unit circle, Cornu spirals) with reference samples [s, x, y, theta];
 * shapes.json holds shape pairs as exact B-splines. The loaders return plain
 * arrays, not libkmorph objects, so they link into every test binary
 * whatever parts of the library exist. Paths are relative to the repository
 * root, where the tests run.
 */
#ifndef KM_TEST_FIXTURES_H
#define KM_TEST_FIXTURES_H

#include <stdbool.h>
#include <stddef.h>

#define TF_ANALYTIC_PATH "tests/fixtures/analytic.json"
#define TF_SHAPES_PATH "tests/fixtures/shapes.json"

/* One case of analytic.json. Arrays are malloc'd; free with
 * tf_analytic_free. */
typedef struct tf_analytic {
  double length;
  double start[2];
  double angle;
  int kappa_degree;
  size_t kappa_n;      /* number of coefficients */
  double *kappa_knots; /* kappa_n + kappa_degree + 1 */
  double *kappa_coef;  /* kappa_n */
  bool closed;
  size_t nsamples;
  double *samples;  /* 4 per sample: s, x, y, theta */
  double agreement; /* stated accuracy of the samples */
} tf_analytic;

/* One curve (a or b) of a shapes.json pair. Arrays malloc'd; w may be
 * NULL; free with tf_bspline_free. */
typedef struct tf_bspline {
  int degree;
  size_t n;      /* control points */
  double *knots; /* n + degree + 1 */
  double *cp;    /* 2n */
  double *w;     /* n or NULL */
  bool closed;
} tf_bspline;

/* Load the analytic case called `name`; returns 0 on success, -1 if the
 * file is missing or malformed or has no such case. */
int tf_load_analytic(const char *name, tf_analytic *out);
void tf_analytic_free(tf_analytic *a);

/* Load curve `which` ('a' or 'b') of the shape pair `pair`; 0 or -1. */
int tf_load_shape(const char *pair, char which, tf_bspline *out);
void tf_bspline_free(tf_bspline *b);

#endif
