/* signature_in.c - a Signature object of a request (its length, start,
 * curvature function kappa(s), corners and closure) checked member by
 * member, each failure named by its JSON pointer, then built by the core.
 */
#include "internal.h"
#include "km/alloc.h"

/* The members of a Signature and of its parts. "turning" is what the
 * signature route answers (the total turning, derived from the rest): a
 * signature sent back as it came is accepted, its turning not read. */
static const char *const signature_members[] = {"length",  "start",   "kappa",
                                                "corners", "turning", "closed"};
static const char *const start_members[] = {"point", "angle"};
static const char *const kappa_members[] = {"degree", "knots", "coefficients"};
static const char *const corner_members[] = {"s", "turn"};

/* "start": {"point": [x, y], "angle": a}, each optional; absent members
 * leave start and *angle as they are. */
static bool read_start(api_ctx *ctx, const cJSON *v, const char *ptr,
                       double start[2], double *angle) {
  char p[API_POINTER_MAX], q[API_POINTER_MAX];
  const cJSON *js = cJSON_GetObjectItemCaseSensitive(v, "start"), *jpt;
  if (js == NULL) return true;
  api__ptr_key(p, ptr, "start");
  if (!cJSON_IsObject(js))
    return api__invalid(ctx, p, "must be an object, not %s",
                        api__type_name(js));
  if (!api__known_members(ctx, js, p, API_NAMES(start_members))) return false;
  jpt = cJSON_GetObjectItemCaseSensitive(js, "point");
  if (jpt != NULL) {
    api__ptr_key(q, p, "point");
    if (!api__point(ctx, jpt, q, start)) return false;
  }
  return api__member_num(ctx, js, p, "angle", false, angle, NULL);
}

/* The members of "kappa" as read; the arrays are the caller's to free. */
typedef struct kappa_text {
  long degree;
  double *knots, *coef;
  size_t nk, nc;
} kappa_text;

/* "kappa": {"degree", "coefficients", "knots"}, read and checked but not
 * built (its other members' errors come first). */
static bool read_kappa(api_ctx *ctx, const cJSON *v, const char *ptr,
                       kappa_text *kt) {
  char p[API_POINTER_MAX], q[API_POINTER_MAX];
  const cJSON *jkappa, *jc;
  if ((jkappa = api__require(ctx, v, ptr, "kappa")) == NULL) return false;
  api__ptr_key(p, ptr, "kappa");
  if (!cJSON_IsObject(jkappa))
    return api__invalid(ctx, p, "must be an object, not %s",
                        api__type_name(jkappa));
  if (!api__known_members(ctx, jkappa, p, API_NAMES(kappa_members)))
    return false;
  if (!api__member_int(ctx, jkappa, p, "degree", true, 0, KM_MAX_FN_DEGREE,
                       &kt->degree, NULL) ||
      (jc = api__require(ctx, jkappa, p, "coefficients")) == NULL)
    return false;
  api__ptr_key(q, p, "coefficients");
  if (!api__num_array(ctx, jc, q, ctx->cfg->max_control_points, &kt->coef,
                      &kt->nc))
    return false;
  if (kt->nc < (size_t)kt->degree + 1)
    return api__failf(ctx, 422, API_P_INVALID_SIGNATURE, "Invalid signature", q,
                      "a degree %ld function needs at least %ld "
                      "coefficients",
                      kt->degree, kt->degree + 1);
  return api__read_knots(ctx, jkappa, p, kt->nc, kt->degree, API_KIND_SIGNATURE,
                         &kt->knots, &kt->nk);
}

/* The optional "corners": [{"s", "turn"}, ...]. *corners (the caller
 * frees it) is set as soon as it is allocated. */
static bool read_corners(api_ctx *ctx, const cJSON *v, const char *ptr,
                         km_corner **corners, size_t *ncorners) {
  char p[API_POINTER_MAX], q[API_POINTER_MAX];
  const cJSON *jcorners = cJSON_GetObjectItemCaseSensitive(v, "corners");
  api_elems it;
  size_t n;
  if (jcorners == NULL || cJSON_IsNull(jcorners)) return true;
  api__ptr_key(p, ptr, "corners");
  if (!cJSON_IsArray(jcorners))
    return api__invalid(ctx, p, "must be an array, not %s",
                        api__type_name(jcorners));
  n = api__array_len(jcorners);
  if (n > ctx->cfg->max_control_points)
    return api__failf(ctx, 422, API_P_LIMIT, "Limit exceeded", p,
                      "has %zu elements; the limit is %zu", n,
                      ctx->cfg->max_control_points);
  if ((*corners = km__malloc((n > 0 ? n : 1) * sizeof **corners)) == NULL)
    return api__oom(ctx);
  *ncorners = n;
  /* a packed element (a number or an array) is no object: item NULL */
  api__elems_start(&it, jcorners);
  for (size_t i = 0; i < n; i++, api__elems_next(&it)) {
    const cJSON *e = it.item;
    api__ptr_idx(q, p, i);
    if (!cJSON_IsObject(e))
      return api__invalid(ctx, q, "must be an object {\"s\", \"turn\"}");
    if (!api__known_members(ctx, e, q, API_NAMES(corner_members))) return false;
    if (!api__member_num(ctx, e, q, "s", true, &(*corners)[i].s, NULL) ||
        !api__member_num(ctx, e, q, "turn", true, &(*corners)[i].turn, NULL))
      return false;
  }
  return true;
}

/* kappa built by the core, its failures named under ptr/kappa. */
static bool build_kappa(api_ctx *ctx, const kappa_text *kt, const char *ptr,
                        km_fn *kappa) {
  km_error err;
  km_status st =
      km_fn_create(kappa, (int)kt->degree, kt->nc, kt->knots, kt->coef, &err);
  if (st == KM_OK) return true;
  /* km_fn_create speaks of its own knots/coefficients: name them under
   * kappa. */
  if (err.field == KM_FIELD_KNOTS)
    err.field = KM_FIELD_KAPPA_KNOTS;
  else if (err.field == KM_FIELD_DEGREE)
    err.field = KM_FIELD_KAPPA_DEGREE;
  else if (err.field == KM_FIELD_NONE || err.field == KM_FIELD_CONTROL_POINTS)
    err.field = KM_FIELD_KAPPA_COEFFICIENTS;
  return api__core_fail(ctx, st, &err, ptr, API_KIND_SIGNATURE);
}

bool api__parse_signature(api_ctx *ctx, const cJSON *v, const char *ptr,
                          km_signature *out) {
  char p[API_POINTER_MAX];
  double length = 0, start[2] = {0, 0}, angle = 0;
  kappa_text kt = {0, NULL, NULL, 0, 0};
  km_corner *corners = NULL;
  size_t ncorners = 0;
  bool closed = false, ok = false;
  km_fn kappa;
  km_error err;
  km_status st;

  km_fn_init(&kappa);
  if (!cJSON_IsObject(v))
    return api__invalid(ctx, ptr, "must be an object, not %s",
                        api__type_name(v));
  if (!api__known_members(ctx, v, ptr, API_NAMES(signature_members)) ||
      !api__member_num(ctx, v, ptr, "length", true, &length, NULL))
    goto done;
  if (!(length > 0)) {
    api__ptr_key(p, ptr, "length");
    api__fail(ctx, 422, API_P_INVALID_SIGNATURE, "Invalid signature", p,
              "must be > 0");
    goto done;
  }
  if (!read_start(ctx, v, ptr, start, &angle) ||
      !read_kappa(ctx, v, ptr, &kt) ||
      !read_corners(ctx, v, ptr, &corners, &ncorners) ||
      !api__member_bool(ctx, v, ptr, "closed", false, &closed, NULL) ||
      !build_kappa(ctx, &kt, ptr, &kappa))
    goto done;
  st = km_signature_create(out, length, start, angle, &kappa, corners, ncorners,
                           closed, &err);
  if (st != KM_OK) {
    api__core_fail(ctx, st, &err, ptr, API_KIND_SIGNATURE);
    goto done;
  }
  ok = true;
done:
  km_fn_free(&kappa);
  km__free(kt.knots);
  km__free(kt.coef);
  km__free(corners);
  return ok;
}
