/* json_read.c - typed readers of a parsed request: numbers, integers,
 * booleans and names of members, arrays of numbers and of points (packed
 * or not), and the request-wide "tolerance" and "include" members. Every
 * number is checked for type and finiteness, every count against the
 * limits, every failure reported with the JSON pointer of the bad value.
 *
 * Counts above configured limits are 422 /problems/limit-exceeded, not 413:
 * 413 is about the size of the body, which the transport and
 * api__parse_body already bound; a count limit is a property of the
 * request's content, checked like any other field and named by a pointer.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "internal.h"
#include "km/alloc.h"

const char *api__type_name(const cJSON *v) {
  if (v == NULL) return "nothing";
  if (cJSON_IsNull(v)) return "null";
  if (cJSON_IsBool(v)) return "a boolean";
  if (cJSON_IsNumber(v)) return "a number";
  if (cJSON_IsString(v)) return "a string";
  if (cJSON_IsArray(v)) return "an array";
  return "an object";
}

/* ---------------------------------------------------------------- scalars */

bool api__num(api_ctx *ctx, const cJSON *v, const char *ptr, double *out) {
  if (!cJSON_IsNumber(v))
    return api__invalid(ctx, ptr, "must be a number, not %s",
                        api__type_name(v));
  /* cJSON turns 1e999 into inf; the contract has no infinities. */
  if (!isfinite(v->valuedouble))
    return api__invalid(ctx, ptr, "must be a finite number");
  *out = v->valuedouble;
  return true;
}

const cJSON *api__require(api_ctx *ctx, const cJSON *obj, const char *base,
                          const char *key) {
  const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
  if (v == NULL) {
    char p[API_POINTER_MAX];
    api__ptr_key(p, base, key);
    api__invalid(ctx, p, "is required");
  }
  return v;
}

bool api__member_num(api_ctx *ctx, const cJSON *obj, const char *base,
                     const char *key, bool required, double *out,
                     bool *present) {
  const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
  char p[API_POINTER_MAX];
  if (present != NULL) *present = v != NULL;
  if (v == NULL)
    return required ? api__require(ctx, obj, base, key) != NULL : true;
  api__ptr_key(p, base, key);
  return api__num(ctx, v, p, out);
}

bool api__member_int(api_ctx *ctx, const cJSON *obj, const char *base,
                     const char *key, bool required, long lo, long hi,
                     long *out, bool *present) {
  const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
  char p[API_POINTER_MAX];
  double d = 0.0; /* set by api__num; -O3 cannot see it */
  if (present != NULL) *present = v != NULL;
  if (v == NULL)
    return required ? api__require(ctx, obj, base, key) != NULL : true;
  api__ptr_key(p, base, key);
  if (!api__num(ctx, v, p, &d)) return false;
  if (d != floor(d)) return api__invalid(ctx, p, "must be an integer");
  if (d < (double)lo || d > (double)hi)
    return api__invalid(ctx, p, "must be between %ld and %ld", lo, hi);
  *out = (long)d;
  return true;
}

bool api__member_bool(api_ctx *ctx, const cJSON *obj, const char *base,
                      const char *key, bool required, bool *out,
                      bool *present) {
  const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
  char p[API_POINTER_MAX];
  if (present != NULL) *present = v != NULL;
  if (v == NULL)
    return required ? api__require(ctx, obj, base, key) != NULL : true;
  api__ptr_key(p, base, key);
  if (!cJSON_IsBool(v))
    return api__invalid(ctx, p, "must be a boolean, not %s", api__type_name(v));
  *out = cJSON_IsTrue(v);
  return true;
}

bool api__member_enum(api_ctx *ctx, const cJSON *obj, const char *base,
                      const char *key, const char *const *names, size_t n,
                      int *out, bool *present) {
  const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
  char p[API_POINTER_MAX];
  char list[API_TEXT_MAX];
  size_t used = 0;
  if (present != NULL) *present = v != NULL;
  if (v == NULL) return true;
  api__ptr_key(p, base, key);
  if (cJSON_IsString(v)) {
    for (size_t i = 0; i < n; i++) {
      if (strcmp(v->valuestring, names[i]) == 0) {
        *out = (int)i;
        return true;
      }
    }
  }
  list[0] = '\0';
  for (size_t i = 0; i < n && used < sizeof list; i++) {
    int w = snprintf(list + used, sizeof list - used, "%s\"%s\"",
                     i == 0 ? "" : (i + 1 == n ? " or " : ", "), names[i]);
    if (w < 0) break;
    used += (size_t)w;
  }
  return api__invalid(ctx, p, "must be one of %s", list);
}

/* ----------------------------------------------------------------- arrays */

static bool check_count(api_ctx *ctx, const cJSON *v, const char *ptr,
                        size_t max, size_t *n) {
  size_t size;
  if (!cJSON_IsArray(v))
    return api__invalid(ctx, ptr, "must be an array, not %s",
                        api__type_name(v));
  size = api__array_len(v);
  if (size == 0) return api__invalid(ctx, ptr, "must not be empty");
  if (size > max)
    return api__failf(ctx, 422, API_P_LIMIT, "Limit exceeded", ptr,
                      "has %zu elements; the limit is %zu", size, max);
  *n = size;
  return true;
}

void api__elems_start(api_elems *it, const cJSON *a) {
  it->packed = api__array_packed(a, &it->width);
  it->item = it->packed == NULL && a != NULL ? a->child : NULL;
  it->index = 0;
}

void api__elems_next(api_elems *it) {
  if (it->item != NULL) it->item = it->item->next;
  it->index++;
}

/* Packed number k of the walk's array at pointer p, checked finite. */
static bool packed_num(api_ctx *ctx, const api_elems *it, size_t k,
                       const char *p, double *out) {
  /* strtod turns 1e999 into inf; the contract has no infinities. */
  if (!isfinite(it->packed[k]))
    return api__invalid(ctx, p, "must be a finite number");
  *out = it->packed[k];
  return true;
}

bool api__elems_num(api_ctx *ctx, const api_elems *it, const char *ptr,
                    double *out) {
  char p[API_POINTER_MAX];
  api__ptr_idx(p, ptr, it->index);
  if (it->packed == NULL) return api__num(ctx, it->item, p, out);
  if (it->width > 0)
    return api__invalid(ctx, p, "must be a number, not an array");
  return packed_num(ctx, it, it->index, p, out);
}

bool api__elems_point(api_ctx *ctx, const api_elems *it, const char *ptr,
                      double out[2]) {
  char p[API_POINTER_MAX], q[API_POINTER_MAX];
  api__ptr_idx(p, ptr, it->index);
  if (it->packed == NULL) return api__point(ctx, it->item, p, out);
  if (it->width != 2) return api__invalid(ctx, p, "must be a point [x, y]");
  api__ptr_idx(q, p, 0);
  if (!packed_num(ctx, it, 2 * it->index, q, &out[0])) return false;
  api__ptr_idx(q, p, 1);
  return packed_num(ctx, it, 2 * it->index + 1, q, &out[1]);
}

bool api__num_array(api_ctx *ctx, const cJSON *v, const char *ptr, size_t max,
                    double **out, size_t *n) {
  size_t count;
  double *a;
  api_elems it;
  if (!check_count(ctx, v, ptr, max, &count)) return false;
  a = km__malloc(count * sizeof *a);
  if (a == NULL) return api__oom(ctx);
  api__elems_start(&it, v);
  for (size_t i = 0; i < count; i++, api__elems_next(&it)) {
    if (!api__elems_num(ctx, &it, ptr, &a[i])) {
      km__free(a);
      return false;
    }
  }
  *out = a;
  *n = count;
  return true;
}

bool api__point(api_ctx *ctx, const cJSON *v, const char *ptr, double out[2]) {
  api_elems it;
  if (!cJSON_IsArray(v) || api__array_len(v) != 2)
    return api__invalid(ctx, ptr, "must be a point [x, y]");
  api__elems_start(&it, v);
  if (!api__elems_num(ctx, &it, ptr, &out[0])) return false;
  api__elems_next(&it);
  return api__elems_num(ctx, &it, ptr, &out[1]);
}

bool api__point_array(api_ctx *ctx, const cJSON *v, const char *ptr, size_t max,
                      double **out, size_t *n) {
  size_t count;
  double *a;
  api_elems it;
  if (!check_count(ctx, v, ptr, max, &count)) return false;
  a = km__malloc(2 * count * sizeof *a);
  if (a == NULL) return api__oom(ctx);
  api__elems_start(&it, v);
  for (size_t i = 0; i < count; i++, api__elems_next(&it)) {
    if (!api__elems_point(ctx, &it, ptr, &a[2 * i])) {
      km__free(a);
      return false;
    }
  }
  *out = a;
  *n = count;
  return true;
}

/* ------------------------------------------------------------- knots */

/* The knot checks the contract names explicitly are made here too, so the
 * pointer of the first bad knot never depends on how the core happens to
 * order its own checks. */
bool api__read_knots(api_ctx *ctx, const cJSON *obj, const char *base,
                     size_t ncoef, long degree, api_kind kind, double **knots,
                     size_t *nk) {
  char p[API_POINTER_MAX];
  const bool sig = kind == API_KIND_SIGNATURE;
  const char *what = sig ? "coefficients" : "control_points";
  const char *type = sig ? API_P_INVALID_SIGNATURE : API_P_INVALID_CURVE;
  const char *title = sig ? "Invalid signature" : "Invalid curve";
  const cJSON *jk = api__require(ctx, obj, base, "knots");
  if (jk == NULL) return false;
  api__ptr_key(p, base, "knots");
  if (!api__num_array(ctx, jk, p, ctx->cfg->max_control_points + 64, knots, nk))
    return false;
  if (*nk != ncoef + (size_t)degree + 1)
    return api__failf(ctx, 422, type, title, p,
                      "must have len(%s) + degree + 1 = %zu knots, not %zu",
                      what, ncoef + (size_t)degree + 1, *nk);
  for (size_t i = 1; i < *nk; i++) {
    if ((*knots)[i] < (*knots)[i - 1]) {
      char q[API_POINTER_MAX];
      api__ptr_idx(q, p, i);
      return api__failf(ctx, 422, type, title, q,
                        "must be >= previous knot (knot vector decreases "
                        "at index %zu)",
                        i);
    }
  }
  return true;
}

/* ------------------------------------------------ request-wide members */

bool api__parse_tolerance(api_ctx *ctx, const cJSON *root, double *tol) {
  bool present = false;
  double t = 0;
  if (!api__member_num(ctx, root, "", "tolerance", false, &t, &present))
    return false;
  if (present && !(t > 0))
    return api__invalid(ctx, "/tolerance", "must be > 0");
  *tol = present ? t : 0;
  return true;
}

bool api__parse_include(api_ctx *ctx, const cJSON *root, bool allow_animate,
                        api_include *inc) {
  const cJSON *v = cJSON_GetObjectItemCaseSensitive(root, "include");
  api_elems it;
  size_t n;
  char p[API_POINTER_MAX];
  inc->svg_d = false;
  inc->animate_d = false;
  if (v == NULL) return true;
  if (!cJSON_IsArray(v))
    return api__invalid(ctx, "/include", "must be an array of strings");
  n = api__array_len(v);
  api__elems_start(&it, v);
  /* a packed element (a number or an array) is no string: item NULL */
  for (size_t i = 0; i < n; i++, api__elems_next(&it)) {
    const cJSON *e = it.item;
    api__ptr_idx(p, "/include", i);
    if (cJSON_IsString(e) && strcmp(e->valuestring, "svg_d") == 0)
      inc->svg_d = true;
    else if (allow_animate && cJSON_IsString(e) &&
             strcmp(e->valuestring, "animate_d") == 0)
      inc->animate_d = true;
    else
      return api__invalid(ctx, p,
                          allow_animate ? "must be \"svg_d\" or \"animate_d\""
                                        : "must be \"svg_d\"");
  }
  return true;
}
