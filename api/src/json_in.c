/* json_in.c - validating readers from cJSON values to core types: every
 * number checked for type and finiteness, every count against the limits,
 * every failure reported with the JSON pointer of the bad value.
 *
 * Counts above configured limits are 422 /problems/limit-exceeded, not 413:
 * 413 is about the size of the body, which the transport and
 * api__parse_body already bound; a count limit is a property of the
 * request's content, checked like any other field and named by a pointer.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "svg.h"

static const char *type_name(const cJSON *v) {
  if (v == NULL)
    return "nothing";
  if (cJSON_IsNull(v))
    return "null";
  if (cJSON_IsBool(v))
    return "a boolean";
  if (cJSON_IsNumber(v))
    return "a number";
  if (cJSON_IsString(v))
    return "a string";
  if (cJSON_IsArray(v))
    return "an array";
  return "an object";
}

/* ---------------------------------------------------------------- scalars */

bool api__num(api_ctx *ctx, const cJSON *v, const char *ptr, double *out) {
  if (!cJSON_IsNumber(v))
    return api__invalid(ctx, ptr, "must be a number, not %s", type_name(v));
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
  if (present != NULL)
    *present = v != NULL;
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
  if (present != NULL)
    *present = v != NULL;
  if (v == NULL)
    return required ? api__require(ctx, obj, base, key) != NULL : true;
  api__ptr_key(p, base, key);
  if (!api__num(ctx, v, p, &d))
    return false;
  if (d != floor(d))
    return api__invalid(ctx, p, "must be an integer");
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
  if (present != NULL)
    *present = v != NULL;
  if (v == NULL)
    return required ? api__require(ctx, obj, base, key) != NULL : true;
  api__ptr_key(p, base, key);
  if (!cJSON_IsBool(v))
    return api__invalid(ctx, p, "must be a boolean, not %s", type_name(v));
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
  if (present != NULL)
    *present = v != NULL;
  if (v == NULL)
    return true;
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
    if (w < 0)
      break;
    used += (size_t)w;
  }
  return api__invalid(ctx, p, "must be one of %s", list);
}

/* ----------------------------------------------------------------- arrays */

static bool check_count(api_ctx *ctx, const cJSON *v, const char *ptr,
                        size_t max, size_t *n) {
  size_t size;
  if (!cJSON_IsArray(v))
    return api__invalid(ctx, ptr, "must be an array, not %s", type_name(v));
  size = api__array_len(v);
  if (size == 0)
    return api__invalid(ctx, ptr, "must not be empty");
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
  if (it->item != NULL)
    it->item = it->item->next;
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
  if (it->packed == NULL)
    return api__num(ctx, it->item, p, out);
  if (it->width > 0)
    return api__invalid(ctx, p, "must be a number, not an array");
  return packed_num(ctx, it, it->index, p, out);
}

bool api__elems_point(api_ctx *ctx, const api_elems *it, const char *ptr,
                      double out[2]) {
  char p[API_POINTER_MAX], q[API_POINTER_MAX];
  api__ptr_idx(p, ptr, it->index);
  if (it->packed == NULL)
    return api__point(ctx, it->item, p, out);
  if (it->width != 2)
    return api__invalid(ctx, p, "must be a point [x, y]");
  api__ptr_idx(q, p, 0);
  if (!packed_num(ctx, it, 2 * it->index, q, &out[0]))
    return false;
  api__ptr_idx(q, p, 1);
  return packed_num(ctx, it, 2 * it->index + 1, q, &out[1]);
}

bool api__num_array(api_ctx *ctx, const cJSON *v, const char *ptr,
                    size_t max, double **out, size_t *n) {
  size_t count;
  double *a;
  api_elems it;
  if (!check_count(ctx, v, ptr, max, &count))
    return false;
  a = malloc(count * sizeof *a);
  if (a == NULL)
    return api__oom(ctx);
  api__elems_start(&it, v);
  for (size_t i = 0; i < count; i++, api__elems_next(&it)) {
    if (!api__elems_num(ctx, &it, ptr, &a[i])) {
      free(a);
      return false;
    }
  }
  *out = a;
  *n = count;
  return true;
}

bool api__point(api_ctx *ctx, const cJSON *v, const char *ptr,
                double out[2]) {
  api_elems it;
  if (!cJSON_IsArray(v) || api__array_len(v) != 2)
    return api__invalid(ctx, ptr, "must be a point [x, y]");
  api__elems_start(&it, v);
  if (!api__elems_num(ctx, &it, ptr, &out[0]))
    return false;
  api__elems_next(&it);
  return api__elems_num(ctx, &it, ptr, &out[1]);
}

bool api__point_array(api_ctx *ctx, const cJSON *v, const char *ptr,
                      size_t max, double **out, size_t *n) {
  size_t count;
  double *a;
  api_elems it;
  if (!check_count(ctx, v, ptr, max, &count))
    return false;
  a = malloc(2 * count * sizeof *a);
  if (a == NULL)
    return api__oom(ctx);
  api__elems_start(&it, v);
  for (size_t i = 0; i < count; i++, api__elems_next(&it)) {
    if (!api__elems_point(ctx, &it, ptr, &a[2 * i])) {
      free(a);
      return false;
    }
  }
  *out = a;
  *n = count;
  return true;
}

/* ------------------------------------------------------ core error mapping */

static const char *field_name(km_field f, api_kind kind) {
  /* A fitted curve's control points are not in the request: name the
   * points or the curve object instead. */
  if (kind == API_KIND_POINTS && f != KM_FIELD_POINTS && f != KM_FIELD_CLOSED)
    return NULL;
  switch (f) {
  case KM_FIELD_DEGREE: return "degree";
  case KM_FIELD_KNOTS: return "knots";
  case KM_FIELD_CONTROL_POINTS: return "control_points";
  case KM_FIELD_WEIGHTS: return "weights";
  case KM_FIELD_CLOSED: return "closed";
  case KM_FIELD_LENGTH: return "length";
  case KM_FIELD_START: return "start/point";
  case KM_FIELD_ANGLE: return "start/angle";
  case KM_FIELD_KAPPA_KNOTS: return "kappa/knots";
  case KM_FIELD_KAPPA_COEFFICIENTS: return "kappa/coefficients";
  case KM_FIELD_KAPPA_DEGREE: return "kappa/degree";
  case KM_FIELD_CORNERS: return "corners";
  case KM_FIELD_POINTS: return kind == API_KIND_CURVE ? "control_points"
                                                       : "points";
  default: return NULL;
  }
}

bool api__core_fail(api_ctx *ctx, km_status st, const km_error *err,
                    const char *base, api_kind kind) {
  char p[API_POINTER_MAX];
  char msg[API_TEXT_MAX];
  const char *type, *title;
  int status = 422;
  km_field field = err != NULL ? err->field : KM_FIELD_NONE;
  const char *name;
  const char *text =
      err != NULL && err->message[0] != '\0' ? err->message
                                              : km_status_message(st);

  switch (st) {
  case KM_ENOMEM:
    return api__oom(ctx);
  case KM_ETURNING:
  case KM_EMIXED:
    type = API_P_NOT_MORPHABLE;
    title = "Curves cannot be morphed";
    break;
  case KM_EMATCH:
    type = API_P_INVALID_REQUEST;
    title = "Invalid request";
    break;
  case KM_ENOCONVERGE:
    type = API_P_NO_CONVERGE;
    title = "Computation did not converge";
    break;
  case KM_ELIMIT:
    type = API_P_LIMIT;
    title = "Limit exceeded";
    break;
  case KM_ECANCELLED:
    status = 503;
    type = "/problems/cancelled";
    title = "Cancelled";
    break;
  case KM_EINVAL:
  case KM_EDEGREE:
  case KM_EKNOTS:
  case KM_ECOUNT:
  case KM_ENONFINITE:
  case KM_ERANGE:
  case KM_EWEIGHT:
  case KM_ECLOSED:
  case KM_EDEGENERATE:
  case KM_ECUSP:
    if (kind == API_KIND_SIGNATURE) {
      type = API_P_INVALID_SIGNATURE;
      title = "Invalid signature";
    } else if (kind == API_KIND_REQUEST) {
      type = API_P_INVALID_REQUEST;
      title = "Invalid request";
    } else {
      type = API_P_INVALID_CURVE;
      title = "Invalid curve";
    }
    break;
  default:
    status = 500;
    type = API_P_INTERNAL;
    title = "Internal error";
    break;
  }

  /* Fields that live at the request level, whatever was being processed. */
  if (field == KM_FIELD_TOLERANCE) {
    snprintf(p, sizeof p, "/tolerance");
  } else if (field == KM_FIELD_MATCHES || field == KM_FIELD_TIMES) {
    const char *key = field == KM_FIELD_MATCHES ? "/matches" : "/times";
    if (err->index >= 0)
      snprintf(p, sizeof p, "%s/%ld", key, err->index);
    else
      snprintf(p, sizeof p, "%s", key);
  } else if (kind == API_KIND_SVG) {
    api__ptr_key(p, base, "d");
  } else if ((name = field_name(field, kind)) != NULL) {
    if (err->index >= 0 && field != KM_FIELD_DEGREE &&
        field != KM_FIELD_CLOSED && field != KM_FIELD_LENGTH &&
        field != KM_FIELD_ANGLE && field != KM_FIELD_KAPPA_DEGREE)
      snprintf(p, sizeof p, "%s/%s/%ld", base, name, err->index);
    else
      api__ptr_key(p, base, name);
  } else {
    snprintf(p, sizeof p, "%s", base);
  }

  /* The core's own message usually says where already; add the place
   * only to a bare default message. */
  if (err != NULL && err->message[0] == '\0' && isfinite(err->param) &&
      (st == KM_ECUSP || st == KM_EDEGENERATE || st == KM_ENOCONVERGE))
    snprintf(msg, sizeof msg, "%s (at %s %.17g)", text,
             kind == API_KIND_SIGNATURE ? "arc length" : "parameter",
             err->param);
  else
    snprintf(msg, sizeof msg, "%s", text);
  return api__fail(ctx, status, type, title, p, msg);
}

/* ------------------------------------------------------------ curve input */

void api__input_init(api_input *in) {
  in->is_signature = false;
  in->kind = API_KIND_CURVE;
  km_curve_init(&in->curve);
  km_signature_init(&in->sig);
  in->length = 0;
}

void api__input_free(api_input *in) {
  if (in == NULL)
    return;
  km_curve_free(&in->curve);
  km_signature_free(&in->sig);
  api__input_init(in);
}

/* The knot checks the contract names explicitly are made here too, so the
 * pointer of the first bad knot or weight never depends on how the core
 * happens to order its own checks. */
/* The "knots" member of obj (at base): present, numbers, as many as
 * ncoef + degree + 1 (what names the counted member in the message), never
 * decreasing. On failure the problem names the knot at fault. */
static bool read_knots(api_ctx *ctx, const cJSON *obj, const char *base,
                       size_t ncoef, long degree, const char *what,
                       const char *type, const char *title, double **knots,
                       size_t *nk) {
  char p[API_POINTER_MAX];
  const cJSON *jk = api__require(ctx, obj, base, "knots");
  if (jk == NULL)
    return false;
  api__ptr_key(p, base, "knots");
  if (!api__num_array(ctx, jk, p, ctx->cfg->max_control_points + 64, knots,
                      nk))
    return false;
  if (*nk != ncoef + (size_t)degree + 1) {
    api__failf(ctx, 422, type, title, p,
               "must have len(%s) + degree + 1 = %zu knots, not %zu", what,
               ncoef + (size_t)degree + 1, *nk);
    return false;
  }
  for (size_t i = 1; i < *nk; i++) {
    if ((*knots)[i] < (*knots)[i - 1]) {
      char q[API_POINTER_MAX];
      api__ptr_idx(q, p, i);
      api__failf(ctx, 422, type, title, q,
                 "must be >= previous knot (knot vector decreases at index "
                 "%zu)",
                 i);
      return false;
    }
  }
  return true;
}

static bool parse_bspline(api_ctx *ctx, const cJSON *v, const char *ptr,
                          km_curve *out) {
  char p[API_POINTER_MAX];
  long degree = 0;
  double *cp = NULL, *knots = NULL, *w = NULL;
  size_t n = 0, nk = 0, nw = 0;
  bool closed = false;
  bool ok = false, has_w = false;
  const cJSON *jcp, *jw;
  km_error err;
  km_status st;

  if (!api__member_int(ctx, v, ptr, "degree", true, KM_MIN_DEGREE,
                       KM_MAX_DEGREE, &degree, NULL))
    goto done;
  if ((jcp = api__require(ctx, v, ptr, "control_points")) == NULL)
    goto done;
  api__ptr_key(p, ptr, "control_points");
  if (!api__point_array(ctx, jcp, p, ctx->cfg->max_control_points, &cp, &n))
    goto done;
  if (n < (size_t)degree + 1) {
    api__failf(ctx, 422, API_P_INVALID_CURVE, "Invalid curve", p,
               "a degree %ld curve needs at least %ld control points, not "
               "%zu",
               degree, degree + 1, n);
    goto done;
  }
  if (!read_knots(ctx, v, ptr, n, degree, "control_points",
                  API_P_INVALID_CURVE, "Invalid curve", &knots, &nk))
    goto done;
  jw = cJSON_GetObjectItemCaseSensitive(v, "weights");
  if (jw != NULL && !cJSON_IsNull(jw)) {
    api__ptr_key(p, ptr, "weights");
    if (!api__num_array(ctx, jw, p, ctx->cfg->max_control_points, &w, &nw))
      goto done;
    if (nw != n) {
      api__failf(ctx, 422, API_P_INVALID_CURVE, "Invalid curve", p,
                 "must have one weight per control point (%zu), not %zu", n,
                 nw);
      goto done;
    }
    for (size_t i = 0; i < nw; i++) {
      if (!(w[i] > 0)) {
        char q[API_POINTER_MAX];
        api__ptr_idx(q, p, i);
        api__fail(ctx, 422, API_P_INVALID_CURVE, "Invalid curve", q,
                  "weights must be > 0");
        goto done;
      }
    }
    has_w = true;
  }
  if (!api__member_bool(ctx, v, ptr, "closed", false, &closed, NULL))
    goto done;
  if (closed) {
    /* Scale-relative, so that rounding in a client's output does not turn
     * a closed curve into an error; the core has the final word. */
    double span = 0;
    for (size_t i = 0; i < 2 * n; i++)
      span = fmax(span, fabs(cp[i]));
    if (hypot(cp[0] - cp[2 * n - 2], cp[1] - cp[2 * n - 1]) >
        1e-12 * fmax(span, 1.0)) {
      api__ptr_key(p, ptr, "closed");
      api__fail(ctx, 422, API_P_INVALID_CURVE, "Invalid curve", p,
                "a closed curve needs its first and last control points "
                "equal");
      goto done;
    }
  }
  st = km_curve_create(out, (int)degree, n, knots, cp, has_w ? w : NULL,
                       closed, &err);
  if (st != KM_OK) {
    api__core_fail(ctx, st, &err, ptr, API_KIND_CURVE);
    goto done;
  }
  ok = true;
done:
  free(cp);
  free(knots);
  free(w);
  return ok;
}

static bool parse_points(api_ctx *ctx, const cJSON *v, const char *ptr,
                         double tol, km_curve *out) {
  char p[API_POINTER_MAX];
  double *pts = NULL;
  size_t n = 0;
  bool closed = false, ok = false;
  const cJSON *jp;
  km_error err;
  km_status st;
  if ((jp = api__require(ctx, v, ptr, "points")) == NULL)
    return false;
  api__ptr_key(p, ptr, "points");
  if (!api__point_array(ctx, jp, p, ctx->cfg->max_control_points, &pts, &n))
    return false;
  if (n < 2) {
    api__invalid(ctx, p, "needs at least 2 points");
    goto done;
  }
  if (!api__member_bool(ctx, v, ptr, "closed", false, &closed, NULL))
    goto done;
  {
    /* fitted within half the tolerance (the request's, else the default
     * 1e-5 of the length) so the rest of the work keeps the other half */
    double len = 0.0;
    for (size_t i = 1; i < n; i++)
      len += hypot(pts[2 * i] - pts[2 * i - 2], pts[2 * i + 1] - pts[2 * i - 1]);
    double fit_tol = 0.5 * (tol > 0 ? tol : 1e-5 * len);
    st = km_curve_fit_points(out, pts, n, closed, fit_tol, &err);
  }
  if (st != KM_OK) {
    api__core_fail(ctx, st, &err, ptr, API_KIND_POINTS);
    goto done;
  }
  ok = true;
done:
  free(pts);
  return ok;
}

static bool parse_svg(api_ctx *ctx, const cJSON *v, const char *ptr,
                      double tol, km_curve *out) {
  char p[API_POINTER_MAX];
  char msg[API_TEXT_MAX];
  const cJSON *jd;
  size_t off = 0;
  km_status st;
  if ((jd = api__require(ctx, v, ptr, "d")) == NULL)
    return false;
  api__ptr_key(p, ptr, "d");
  if (!cJSON_IsString(jd))
    return api__invalid(ctx, p, "must be a string, not %s", type_name(jd));
  msg[0] = '\0';
  /* Without a request tolerance nothing is known of the drawing's scale
   * yet; a tiny absolute tolerance only lets exact repairs happen. */
  st = api_svg_parse_path(jd->valuestring, strlen(jd->valuestring),
                          tol > 0 ? tol : 1e-9, out, &off, msg, sizeof msg);
  if (st == KM_ENOMEM)
    return api__oom(ctx);
  if (st != KM_OK)
    return api__failf(ctx, 422, API_P_INVALID_CURVE, "Invalid curve", p,
                      "invalid path data at offset %zu: %s", off,
                      msg[0] != '\0' ? msg : km_status_message(st));
  if (out->n > ctx->cfg->max_control_points) {
    size_t n = out->n;
    km_curve_free(out);
    return api__failf(ctx, 422, API_P_LIMIT, "Limit exceeded", p,
                      "the path makes %zu control points; the limit is %zu",
                      n, ctx->cfg->max_control_points);
  }
  return true;
}

bool api__parse_signature(api_ctx *ctx, const cJSON *v, const char *ptr,
                          km_signature *out) {
  char p[API_POINTER_MAX], q[API_POINTER_MAX];
  double length = 0, start[2] = {0, 0}, angle = 0;
  long degree = 0;
  double *knots = NULL, *coef = NULL;
  size_t nk = 0, nc = 0, ncorners = 0;
  km_corner *corners = NULL;
  bool closed = false, ok = false;
  const cJSON *js, *jkappa, *jc, *jcorners;
  km_fn kappa;
  km_error err;
  km_status st;

  km_fn_init(&kappa);
  if (!cJSON_IsObject(v))
    return api__invalid(ctx, ptr, "must be an object, not %s", type_name(v));
  if (!api__member_num(ctx, v, ptr, "length", true, &length, NULL))
    goto done;
  if (!(length > 0)) {
    api__ptr_key(p, ptr, "length");
    api__fail(ctx, 422, API_P_INVALID_SIGNATURE, "Invalid signature", p,
              "must be > 0");
    goto done;
  }
  js = cJSON_GetObjectItemCaseSensitive(v, "start");
  if (js != NULL) {
    api__ptr_key(p, ptr, "start");
    if (!cJSON_IsObject(js)) {
      api__invalid(ctx, p, "must be an object, not %s", type_name(js));
      goto done;
    }
    const cJSON *jpt = cJSON_GetObjectItemCaseSensitive(js, "point");
    if (jpt != NULL) {
      api__ptr_key(q, p, "point");
      if (!api__point(ctx, jpt, q, start))
        goto done;
    }
    if (!api__member_num(ctx, js, p, "angle", false, &angle, NULL))
      goto done;
  }
  if ((jkappa = api__require(ctx, v, ptr, "kappa")) == NULL)
    goto done;
  api__ptr_key(p, ptr, "kappa");
  if (!cJSON_IsObject(jkappa)) {
    api__invalid(ctx, p, "must be an object, not %s", type_name(jkappa));
    goto done;
  }
  if (!api__member_int(ctx, jkappa, p, "degree", true, 0, KM_MAX_FN_DEGREE,
                       &degree, NULL))
    goto done;
  if ((jc = api__require(ctx, jkappa, p, "coefficients")) == NULL)
    goto done;
  api__ptr_key(q, p, "coefficients");
  if (!api__num_array(ctx, jc, q, ctx->cfg->max_control_points, &coef, &nc))
    goto done;
  if (nc < (size_t)degree + 1) {
    api__failf(ctx, 422, API_P_INVALID_SIGNATURE, "Invalid signature", q,
               "a degree %ld function needs at least %ld coefficients", degree,
               degree + 1);
    goto done;
  }
  if (!read_knots(ctx, jkappa, p, nc, degree, "coefficients",
                  API_P_INVALID_SIGNATURE, "Invalid signature", &knots, &nk))
    goto done;
  jcorners = cJSON_GetObjectItemCaseSensitive(v, "corners");
  if (jcorners != NULL && !cJSON_IsNull(jcorners)) {
    api_elems it;
    api__ptr_key(p, ptr, "corners");
    if (!cJSON_IsArray(jcorners)) {
      api__invalid(ctx, p, "must be an array, not %s", type_name(jcorners));
      goto done;
    }
    ncorners = api__array_len(jcorners);
    if (ncorners > ctx->cfg->max_control_points) {
      api__failf(ctx, 422, API_P_LIMIT, "Limit exceeded", p,
                 "has %zu elements; the limit is %zu", ncorners,
                 ctx->cfg->max_control_points);
      goto done;
    }
    corners = malloc((ncorners > 0 ? ncorners : 1) * sizeof *corners);
    if (corners == NULL) {
      api__oom(ctx);
      goto done;
    }
    /* a packed element (a number or an array) is no object: item NULL */
    api__elems_start(&it, jcorners);
    for (size_t i = 0; i < ncorners; i++, api__elems_next(&it)) {
      const cJSON *e = it.item;
      api__ptr_idx(q, p, i);
      if (!cJSON_IsObject(e)) {
        api__invalid(ctx, q, "must be an object {\"s\", \"turn\"}");
        goto done;
      }
      if (!api__member_num(ctx, e, q, "s", true, &corners[i].s, NULL) ||
          !api__member_num(ctx, e, q, "turn", true, &corners[i].turn, NULL))
        goto done;
    }
  }
  if (!api__member_bool(ctx, v, ptr, "closed", false, &closed, NULL))
    goto done;
  st = km_fn_create(&kappa, (int)degree, nc, knots, coef, &err);
  if (st != KM_OK) {
    /* km_fn_create speaks of its own knots/coefficients: name them under
     * kappa. */
    if (err.field == KM_FIELD_KNOTS)
      err.field = KM_FIELD_KAPPA_KNOTS;
    else if (err.field == KM_FIELD_DEGREE)
      err.field = KM_FIELD_KAPPA_DEGREE;
    else if (err.field == KM_FIELD_NONE || err.field == KM_FIELD_CONTROL_POINTS)
      err.field = KM_FIELD_KAPPA_COEFFICIENTS;
    api__core_fail(ctx, st, &err, ptr, API_KIND_SIGNATURE);
    goto done;
  }
  st = km_signature_create(out, length, start, angle, &kappa, corners,
                           ncorners, closed, &err);
  if (st != KM_OK) {
    api__core_fail(ctx, st, &err, ptr, API_KIND_SIGNATURE);
    goto done;
  }
  ok = true;
done:
  km_fn_free(&kappa);
  free(knots);
  free(coef);
  free(corners);
  return ok;
}

bool api__parse_curve(api_ctx *ctx, const cJSON *v, const char *ptr,
                      double tol, api_input *out) {
  static const char *const types[] = {"bspline", "points", "signature",
                                      "svg"};
  int type = -1;
  bool present = false;
  char p[API_POINTER_MAX];
  if (v == NULL)
    return api__invalid(ctx, ptr, "is required");
  if (!cJSON_IsObject(v))
    return api__invalid(ctx, ptr, "must be a curve object, not %s",
                        type_name(v));
  if (!api__member_enum(ctx, v, ptr, "type", types, 4, &type, &present))
    return false;
  if (!present) {
    api__ptr_key(p, ptr, "type");
    return api__invalid(ctx, p,
                        "is required: \"bspline\", \"points\", \"signature\" "
                        "or \"svg\"");
  }
  switch (type) {
  case 0:
    if (!parse_bspline(ctx, v, ptr, &out->curve))
      return false;
    out->kind = API_KIND_CURVE;
    break;
  case 1:
    if (!parse_points(ctx, v, ptr, tol, &out->curve))
      return false;
    out->kind = API_KIND_POINTS;
    break;
  case 2: {
    const cJSON *js = api__require(ctx, v, ptr, "signature");
    if (js == NULL)
      return false;
    api__ptr_key(p, ptr, "signature");
    if (!api__parse_signature(ctx, js, p, &out->sig))
      return false;
    out->is_signature = true;
    out->kind = API_KIND_SIGNATURE;
    out->length = out->sig.length;
    return true;
  }
  default:
    if (!parse_svg(ctx, v, ptr, tol, &out->curve))
      return false;
    out->kind = API_KIND_SVG;
    break;
  }
  out->is_signature = false;
  out->length = km_curve_length(&out->curve);
  if (!isfinite(out->length) || !(out->length > 0))
    return api__fail(ctx, 422, API_P_INVALID_CURVE, "Invalid curve", ptr,
                     "the curve has zero length");
  return true;
}

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
  if (v == NULL)
    return true;
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
      return api__invalid(ctx, p, allow_animate
                                      ? "must be \"svg_d\" or \"animate_d\""
                                      : "must be \"svg_d\"");
  }
  return true;
}
