/* fixtures.c - cJSON loaders for tests/fixtures/analytic.json and shapes.json.
 *
 * Malformed fixtures make a loader fail (-1) rather than guess, so a broken
 * fixture shows up as a failing test, not as a silently weaker one.
 */
#include "fixtures.h"

#include <cJSON.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Whole file as a NUL-terminated malloc'd string, or NULL. */
static char *read_text(const char *path, size_t *len) {
  FILE *f = fopen(path, "rb");
  char *buf = NULL;
  long size;
  if (!f) return NULL;
  if (fseek(f, 0, SEEK_END) != 0 || (size = ftell(f)) < 0 ||
      fseek(f, 0, SEEK_SET) != 0)
    goto done;
  buf = malloc((size_t)size + 1);
  if (!buf) goto done;
  if (fread(buf, 1, (size_t)size, f) != (size_t)size) {
    free(buf);
    buf = NULL;
    goto done;
  }
  buf[size] = '\0';
  *len = (size_t)size;
done:
  fclose(f);
  return buf;
}

static cJSON *parse_file(const char *path) {
  size_t len = 0;
  char *text = read_text(path, &len);
  if (!text) return NULL;
  cJSON *root = cJSON_ParseWithLength(text, len);
  free(text);
  return root;
}

/* Copy a JSON array of numbers into a new array; the count must be `want`
 * unless want == 0 (then any non-empty count is taken). */
static double *numbers(const cJSON *arr, size_t want, size_t *count) {
  if (!cJSON_IsArray(arr)) return NULL;
  size_t n = (size_t)cJSON_GetArraySize(arr);
  if (n == 0 || (want && n != want)) return NULL;
  double *v = malloc(n * sizeof *v);
  if (!v) return NULL;
  size_t i = 0;
  const cJSON *it;
  cJSON_ArrayForEach(it, arr) {
    if (!cJSON_IsNumber(it)) {
      free(v);
      return NULL;
    }
    v[i++] = it->valuedouble;
  }
  if (count) *count = n;
  return v;
}

static const cJSON *get(const cJSON *o, const char *key) {
  return cJSON_GetObjectItemCaseSensitive(o, key);
}

void tf_analytic_free(tf_analytic *a) {
  if (!a) return;
  free(a->kappa_knots);
  free(a->kappa_coef);
  free(a->samples);
  memset(a, 0, sizeof *a);
}

int tf_load_analytic(const char *name, tf_analytic *out) {
  cJSON *root = parse_file(TF_ANALYTIC_PATH);
  int rc = -1;
  tf_analytic a;
  memset(&a, 0, sizeof a);
  if (!root) return -1;
  const cJSON *c;
  cJSON_ArrayForEach(c, get(root, "cases")) {
    const cJSON *nm = get(c, "name");
    if (!cJSON_IsString(nm) || strcmp(nm->valuestring, name) != 0) continue;
    const cJSON *sig = get(c, "signature");
    const cJSON *start = get(sig, "start");
    const cJSON *kappa = get(sig, "kappa");
    const cJSON *len = get(sig, "length"), *ang = get(start, "angle");
    const cJSON *deg = get(kappa, "degree"), *cl = get(sig, "closed");
    const cJSON *agr = get(c, "reference_agreement");
    double *pt = numbers(get(start, "point"), 2, NULL);
    if (!cJSON_IsNumber(len) || !cJSON_IsNumber(ang) || !cJSON_IsNumber(deg) ||
        !pt) {
      free(pt);
      break;
    }
    a.length = len->valuedouble;
    a.angle = ang->valuedouble;
    a.start[0] = pt[0];
    a.start[1] = pt[1];
    free(pt);
    a.kappa_degree = deg->valueint;
    a.closed = cJSON_IsTrue(cl);
    a.agreement = cJSON_IsNumber(agr) ? agr->valuedouble : 0.0;
    a.kappa_coef = numbers(get(kappa, "coefficients"), 0, &a.kappa_n);
    if (!a.kappa_coef) break;
    a.kappa_knots = numbers(get(kappa, "knots"),
                            a.kappa_n + (size_t)a.kappa_degree + 1, NULL);
    if (!a.kappa_knots) break;
    const cJSON *smp = get(c, "samples_s_x_y_theta");
    if (!cJSON_IsArray(smp)) break;
    a.nsamples = (size_t)cJSON_GetArraySize(smp);
    a.samples = malloc(4 * a.nsamples * sizeof *a.samples);
    if (!a.samples || a.nsamples == 0) break;
    size_t i = 0;
    const cJSON *row;
    int ok = 1;
    cJSON_ArrayForEach(row, smp) {
      double *v = numbers(row, 4, NULL);
      if (!v) {
        ok = 0;
        break;
      }
      memcpy(a.samples + 4 * i++, v, 4 * sizeof *v);
      free(v);
    }
    if (ok) rc = 0;
    break;
  }
  cJSON_Delete(root);
  if (rc == 0)
    *out = a;
  else
    tf_analytic_free(&a);
  return rc;
}

void tf_bspline_free(tf_bspline *b) {
  if (!b) return;
  free(b->knots);
  free(b->cp);
  free(b->w);
  memset(b, 0, sizeof *b);
}

int tf_load_shape(const char *pair, char which, tf_bspline *out) {
  cJSON *root = parse_file(TF_SHAPES_PATH);
  int rc = -1;
  tf_bspline b;
  memset(&b, 0, sizeof b);
  if (!root) return -1;
  const char key[2] = {which, '\0'};
  const cJSON *p;
  cJSON_ArrayForEach(p, get(root, "pairs")) {
    const cJSON *nm = get(p, "name");
    if (!cJSON_IsString(nm) || strcmp(nm->valuestring, pair) != 0) continue;
    const cJSON *cv = get(p, key);
    const cJSON *deg = get(cv, "degree"), *pts = get(cv, "control_points");
    if (!cJSON_IsNumber(deg) || !cJSON_IsArray(pts)) break;
    b.degree = deg->valueint;
    b.n = (size_t)cJSON_GetArraySize(pts);
    b.closed = cJSON_IsTrue(get(cv, "closed"));
    b.cp = malloc(2 * b.n * sizeof *b.cp);
    if (!b.cp || b.n == 0) break;
    size_t i = 0;
    const cJSON *row;
    int ok = 1;
    cJSON_ArrayForEach(row, pts) {
      double *v = numbers(row, 2, NULL);
      if (!v) {
        ok = 0;
        break;
      }
      b.cp[2 * i] = v[0];
      b.cp[2 * i + 1] = v[1];
      i++;
      free(v);
    }
    if (!ok) break;
    b.knots = numbers(get(cv, "knots"), b.n + (size_t)b.degree + 1, NULL);
    if (!b.knots) break;
    if (get(cv, "weights")) {
      b.w = numbers(get(cv, "weights"), b.n, NULL);
      if (!b.w) break;
    }
    rc = 0;
    break;
  }
  cJSON_Delete(root);
  if (rc == 0)
    *out = b;
  else
    tf_bspline_free(&b);
  return rc;
}
