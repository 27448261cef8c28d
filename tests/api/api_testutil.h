/* api_testutil.h - helpers for the contract-layer tests: send a request
 * through api_handle, parse the answer, check problem+json bodies, write
 * curves as request JSON, and evaluate returned B-splines independently of
 * libkmorph (plain de Boor), so that oracles never come from the code under
 * test. Header-only: each test binary is one translation unit.
 */
#ifndef KM_API_TESTUTIL_H
#define KM_API_TESTUTIL_H

#include <stdio.h>
#include <string.h>

#include <cJSON.h>

#include "kmapi/api.h"
#include "testutil.h"

/* One request through api_handle with the default limits (cfg NULL) or
 * the given ones; the parsed body (NULL unless JSON) in *json. */
static inline int at_call_cfg(const api_config *cfg, api_route route,
                              const char *body, size_t len, api_response *res,
                              cJSON **json) {
  api_config def;
  api_request req;
  if (cfg == NULL) {
    api_config_default(&def);
    cfg = &def;
  }
  memset(&req, 0, sizeof req);
  req.route = route;
  req.body = body;
  req.length = len;
  req.request_id = "test-1";
  api_response_init(res);
  int st = api_handle(cfg, &req, res);
  assert_int_equal(st, res->status);
  assert_non_null(res->body);
  assert_int_equal(strlen(res->body), res->length);
  if (json != NULL) {
    *json = NULL;
    if (strstr(res->content_type, "json") != NULL) {
      *json = cJSON_ParseWithLength(res->body, res->length);
      if (*json == NULL) print_error("response is not JSON: %s\n", res->body);
      assert_non_null(*json);
    }
  }
  return st;
}

static inline int at_call(api_route route, const char *body, api_response *res,
                          cJSON **json) {
  return at_call_cfg(NULL, route, body, strlen(body), res, json);
}

/* The answer to body must be a problem with this status and, when pointer
 * is not NULL, errors[0].pointer equal to it. Returns the parsed problem
 * (caller deletes) for further checks. */
static inline cJSON *at_expect_problem_cfg(const api_config *cfg,
                                           api_route route, const char *body,
                                           int status, const char *pointer) {
  api_response res;
  cJSON *j = NULL;
  int st = at_call_cfg(cfg, route, body, strlen(body), &res, &j);
  if (st != status)
    print_error("status %d, expected %d; body: %s\n", st, status, res.body);
  assert_int_equal(st, status);
  assert_string_equal(res.content_type, "application/problem+json");
  assert_non_null(j);
  const cJSON *s = cJSON_GetObjectItemCaseSensitive(j, "status");
  const cJSON *type = cJSON_GetObjectItemCaseSensitive(j, "type");
  const cJSON *title = cJSON_GetObjectItemCaseSensitive(j, "title");
  assert_true(cJSON_IsNumber(s));
  assert_int_equal(s->valueint, status);
  assert_true(cJSON_IsString(type));
  assert_true(strncmp(type->valuestring, "/problems/", 10) == 0);
  assert_true(cJSON_IsString(title));
  if (pointer != NULL) {
    const cJSON *errs = cJSON_GetObjectItemCaseSensitive(j, "errors");
    assert_true(cJSON_IsArray(errs));
    const cJSON *e0 = cJSON_GetArrayItem(errs, 0);
    const cJSON *p = cJSON_GetObjectItemCaseSensitive(e0, "pointer");
    const cJSON *m = cJSON_GetObjectItemCaseSensitive(e0, "message");
    assert_true(cJSON_IsString(p));
    if (strcmp(p->valuestring, pointer) != 0)
      print_error("pointer \"%s\", expected \"%s\"; body: %s\n", p->valuestring,
                  pointer, res.body);
    assert_string_equal(p->valuestring, pointer);
    assert_true(cJSON_IsString(m) && m->valuestring[0] != '\0');
  }
  api_response_free(&res);
  return j;
}

static inline cJSON *at_expect_problem(api_route route, const char *body,
                                       int status, const char *pointer) {
  return at_expect_problem_cfg(NULL, route, body, status, pointer);
}

/* Same, discarding the body. */
static inline void at_problem(api_route route, const char *body, int status,
                              const char *pointer) {
  cJSON_Delete(at_expect_problem(route, body, status, pointer));
}

/* The answer to body must be 200 with a JSON body; returns it parsed
 * (caller deletes), printing the body when the status is not 200. */
static inline cJSON *at_expect_json(api_route route, const char *body) {
  api_response res;
  cJSON *j = NULL;
  int st = at_call(route, body, &res, &j);
  if (st != 200) print_error("status %d: %s\n", st, res.body);
  assert_int_equal(st, 200);
  assert_string_equal(res.content_type, "application/json");
  api_response_free(&res);
  return j;
}

/* Appending formatted text to a growing malloc'd buffer. */
typedef struct at_buf {
  char *s;
  size_t n, cap;
} at_buf;

static inline void at_printf(at_buf *b, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
static inline void at_printf(at_buf *b, const char *fmt, ...) {
  va_list ap;
  for (;;) {
    size_t room = b->cap - b->n;
    va_start(ap, fmt);
    int w = vsnprintf(b->s != NULL ? b->s + b->n : NULL,
                      b->s != NULL ? room : 0, fmt, ap);
    va_end(ap);
    assert_true(w >= 0);
    if (b->s != NULL && (size_t)w < room) {
      b->n += (size_t)w;
      return;
    }
    b->cap = 2 * (b->cap + (size_t)w + 64);
    b->s = realloc(b->s, b->cap);
    assert_non_null(b->s);
  }
}

/* A bspline Curve object as JSON text. */
static inline void at_bspline_json(at_buf *b, int degree, size_t n,
                                   const double *knots, const double *cp,
                                   const double *w, int closed) {
  at_printf(b, "{\"type\":\"bspline\",\"degree\":%d,\"knots\":[", degree);
  for (size_t i = 0; i < n + (size_t)degree + 1; i++)
    at_printf(b, "%s%.17g", i ? "," : "", knots[i]);
  at_printf(b, "],\"control_points\":[");
  for (size_t i = 0; i < n; i++)
    at_printf(b, "%s[%.17g,%.17g]", i ? "," : "", cp[2 * i], cp[2 * i + 1]);
  at_printf(b, "]");
  if (w != NULL) {
    at_printf(b, ",\"weights\":[");
    for (size_t i = 0; i < n; i++) at_printf(b, "%s%.17g", i ? "," : "", w[i]);
    at_printf(b, "]");
  }
  at_printf(b, ",\"closed\":%s}", closed ? "true" : "false");
}

/* The NURBS circle of radius r as a Curve object. */
static inline void at_circle_json(at_buf *b, double cx, double cy, double r,
                                  int ccw) {
  double knots[12], cp[18], w[9];
  tu_circle_nurbs(cx, cy, r, ccw, knots, cp, w);
  at_bspline_json(b, 2, 9, knots, cp, w, 1);
}

/* Numbers out of a JSON array (of numbers); malloc'd. */
static inline double *at_numbers(const cJSON *a, size_t *n) {
  assert_true(cJSON_IsArray(a));
  *n = (size_t)cJSON_GetArraySize(a);
  double *v = malloc((*n > 0 ? *n : 1) * sizeof *v);
  assert_non_null(v);
  size_t i = 0;
  const cJSON *e;
  cJSON_ArrayForEach(e, a) {
    assert_true(cJSON_IsNumber(e));
    v[i++] = e->valuedouble;
  }
  return v;
}

/* A polynomial output curve read back from JSON (weights must be absent). */
typedef struct at_curve {
  int degree;
  size_t n;
  double *knots, *cp;
  int closed;
  double length;
} at_curve;

static inline void at_curve_from_json(const cJSON *c, at_curve *out) {
  size_t nk, i = 0;
  const cJSON *e;
  const cJSON *deg = cJSON_GetObjectItemCaseSensitive(c, "degree");
  const cJSON *pts = cJSON_GetObjectItemCaseSensitive(c, "control_points");
  assert_true(cJSON_IsNumber(deg));
  /* de Boor below is for polynomial curves only. */
  assert_null(cJSON_GetObjectItemCaseSensitive(c, "weights"));
  out->degree = deg->valueint;
  out->knots = at_numbers(cJSON_GetObjectItemCaseSensitive(c, "knots"), &nk);
  assert_true(cJSON_IsArray(pts));
  out->n = (size_t)cJSON_GetArraySize(pts);
  assert_int_equal(nk, out->n + (size_t)out->degree + 1);
  out->cp = malloc(2 * out->n * sizeof *out->cp);
  assert_non_null(out->cp);
  cJSON_ArrayForEach(e, pts) {
    assert_true(cJSON_IsArray(e) && cJSON_GetArraySize(e) == 2);
    out->cp[2 * i] = cJSON_GetArrayItem(e, 0)->valuedouble;
    out->cp[2 * i + 1] = cJSON_GetArrayItem(e, 1)->valuedouble;
    i++;
  }
  out->closed = cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(c, "closed"));
  const cJSON *len = cJSON_GetObjectItemCaseSensitive(c, "length");
  assert_true(cJSON_IsNumber(len));
  out->length = len->valuedouble;
}

static inline void at_curve_free(at_curve *c) {
  free(c->knots);
  free(c->cp);
}

/* Point of a polynomial B-spline at t by de Boor's algorithm. */
static inline void at_curve_point(const at_curve *c, double t, double p[2]) {
  int k = c->degree;
  const double *u = c->knots;
  size_t span = (size_t)k;
  double d[2 * 16];
  while (span + 1 < c->n && t >= u[span + 1]) span++;
  for (int j = 0; j <= k; j++) {
    d[2 * j] = c->cp[2 * (span - (size_t)k + (size_t)j)];
    d[2 * j + 1] = c->cp[2 * (span - (size_t)k + (size_t)j) + 1];
  }
  for (int r = 1; r <= k; r++) {
    for (int j = k; j >= r; j--) {
      size_t i = span - (size_t)k + (size_t)j;
      double den = u[i + (size_t)k + 1 - (size_t)r] - u[i];
      double a = den > 0 ? (t - u[i]) / den : 0;
      d[2 * j] = (1 - a) * d[2 * (j - 1)] + a * d[2 * j];
      d[2 * j + 1] = (1 - a) * d[2 * (j - 1) + 1] + a * d[2 * j + 1];
    }
  }
  p[0] = d[2 * k];
  p[1] = d[2 * k + 1];
}

#endif
