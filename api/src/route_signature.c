/* route_signature.c - POST /v1/signature: a curve in, its curvature
 * signature out, optionally with evenly spaced samples of kappa(s); a
 * shape in, one signature per contour (as given, not reoriented) with the
 * shape's fill rule and each contour's role.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "internal.h"
#include "km/alloc.h"

/* n samples [s, kappa(s)] at s = i L / (n - 1). */
static cJSON *samples_json(api_ctx *ctx, const km_signature *sig, size_t n) {
  double *v = km__malloc(2 * n * sizeof *v);
  cJSON *a;
  if (v == NULL) {
    api__oom(ctx);
    return NULL;
  }
  for (size_t i = 0; i < n; i++) {
    /* The last sample sits exactly at the end, not at a rounded sum. */
    double s =
        i + 1 == n ? sig->length : sig->length * (double)i / (double)(n - 1);
    v[2 * i] = s;
    v[2 * i + 1] = km_fn_value(&sig->kappa, s);
  }
  a = api__num_array_json(ctx, v, n, 2);
  km__free(v);
  return a;
}

/* The signature of the request's curve: the one it gave, else computed
 * into *sig under the request's stop. *use points at it. */
static bool signature_of(api_ctx *ctx, const api_request *req,
                         const api_input *in, double tol, km_signature *sig,
                         const km_signature **use) {
  km_stop stop_buf;
  km_error err;
  km_status st;
  if (in->is_signature) {
    *use = &in->sig;
    return true;
  }
  st = km_signature_compute_until(&in->curve, tol, api__km_stop(req, &stop_buf),
                                  sig, &err);
  if (st == KM_ECANCELLED) return api__stopped(ctx);
  if (st != KM_OK) return api__core_fail(ctx, st, &err, "/curve", in->kind);
  *use = sig;
  return true;
}

/* The answer's size from the signature's pieces, before it is printed: a
 * curve of many spans at a tight tolerance answers with many times its
 * own size. samples is 0 when none were asked for. */
static bool check_size(api_ctx *ctx, const km_signature *use, size_t samples) {
  size_t per_sample = 2 * API_JSON_NUM_BYTES + 4;
  size_t sig_bytes = api__signature_json_bytes(use);
  size_t sample_bytes = samples * per_sample;
  size_t predicted = sig_bytes + sample_bytes + 64;
  if (ctx->cfg->max_output_bytes == 0 ||
      predicted <= ctx->cfg->max_output_bytes)
    return true;
  return api__failf(ctx, 422, API_P_LIMIT, "Limit exceeded",
                    sample_bytes > sig_bytes ? "/samples" : "/tolerance",
                    "the answer would take up to %zu bytes (a signature of "
                    "%zu curvature coefficients%s); the limit is %zu bytes",
                    predicted, use->kappa.n,
                    sample_bytes > sig_bytes ? " and its samples" : "",
                    ctx->cfg->max_output_bytes);
}

/* {"signature": ..., "samples": ...} (samples only when > 0). */
static cJSON *answer_json(api_ctx *ctx, const km_signature *use,
                          size_t samples) {
  cJSON *res = cJSON_CreateObject(), *js;
  if (res == NULL) {
    api__oom(ctx);
    return NULL;
  }
  if ((js = api__signature_json(ctx, use)) == NULL ||
      !api__add_item(ctx, res, "signature", js))
    goto fail;
  if (samples > 0) {
    if ((js = samples_json(ctx, use, samples)) == NULL ||
        !api__add_item(ctx, res, "samples", js))
      goto fail;
  }
  return res;
fail:
  cJSON_Delete(res);
  return NULL;
}

/* ------------------------------------------------------------- shapes */

/* Every contour's signature into sigs[] (in->ncontours, initialised), its
 * failure naming the contour; the shape's roles into *shape. */
static bool shape_signatures(api_ctx *ctx, const api_request *req,
                             const api_input *in, double tol,
                             km_signature *sigs, km_shape *shape) {
  km_shape_limits lim = {api__max_contours(ctx->cfg),
                         ctx->cfg->max_control_points};
  km_stop stop_buf;
  const km_stop *stop = api__km_stop(req, &stop_buf);
  km_error err;
  km_status st;
  size_t i = 0;
  char p[API_POINTER_MAX], where[96], msg[API_TEXT_MAX];
  st =
      km_shape_create(shape, in->contours, in->ncontours, in->fill, &lim, &err);
  if (st == KM_OK)
    for (; i < in->ncontours && st == KM_OK; i++)
      st = km_signature_compute_until(&in->contours[i], tol, stop, &sigs[i],
                                      &err);
  else
    i = err.index >= 0 ? (size_t)err.index + 1 : 1;
  if (st == KM_OK) return true;
  if (st == KM_ECANCELLED) return api__stopped(ctx);
  if (st == KM_ENOMEM) return api__oom(ctx);
  i = i > 0 && i - 1 < in->ncontours ? i - 1 : 0;
  api__contour_ptr(p, in, "/curve", i);
  api__contour_where(where, sizeof where, in, i);
  err.field = KM_FIELD_NONE;
  api__core_fail(ctx, st, &err, p, API_KIND_CURVE);
  snprintf(msg, sizeof msg, "%s: ", where);
  strncat(msg, ctx->message, sizeof msg - strlen(msg) - 1);
  memcpy(ctx->message, msg, sizeof msg);
  memcpy(ctx->detail, msg, sizeof msg);
  return false;
}

/* An array member key of res, or NULL (the error in ctx). */
static cJSON *add_array(api_ctx *ctx, cJSON *res, const char *key) {
  cJSON *a = cJSON_CreateArray();
  if (a == NULL) {
    api__oom(ctx);
    return NULL;
  }
  return api__add_item(ctx, res, key, a) ? a : NULL;
}

/* item appended to a; item consumed either way. */
static bool append(api_ctx *ctx, cJSON *a, cJSON *item) {
  if (item != NULL && cJSON_AddItemToArray(a, item)) return true;
  cJSON_Delete(item);
  return api__oom(ctx);
}

/* {"signatures": [...], "fill_rule", "roles": [...], "samples": [[...]]}
 * after the answer's size is checked against max_output_bytes. */
static cJSON *shape_answer(api_ctx *ctx, const km_signature *sigs,
                           const km_shape *shape, size_t samples) {
  size_t bytes = 256, n = shape->ncontours;
  cJSON *res, *js, *jr, *jm = NULL;
  for (size_t i = 0; i < n; i++)
    bytes += api__signature_json_bytes(&sigs[i]) + 16 +
             samples * (2 * API_JSON_NUM_BYTES + 4);
  if (ctx->cfg->max_output_bytes != 0 && bytes > ctx->cfg->max_output_bytes) {
    api__failf(ctx, 422, API_P_LIMIT, "Limit exceeded",
               samples > 0 ? "/samples" : "/tolerance",
               "the answer would take up to %zu bytes (%zu signatures); the "
               "limit is %zu bytes",
               bytes, n, ctx->cfg->max_output_bytes);
    return NULL;
  }
  if ((res = cJSON_CreateObject()) == NULL) {
    api__oom(ctx);
    return NULL;
  }
  if ((js = add_array(ctx, res, "signatures")) == NULL ||
      !api__add_item(ctx, res, "fill_rule",
                     cJSON_CreateString(shape->fill == KM_FILL_EVENODD
                                            ? "evenodd"
                                            : "nonzero")) ||
      (jr = add_array(ctx, res, "roles")) == NULL ||
      (samples > 0 && (jm = add_array(ctx, res, "samples")) == NULL))
    goto fail;
  for (size_t i = 0; i < n; i++) {
    if (!append(ctx, js, api__signature_json(ctx, &sigs[i])) ||
        !append(ctx, jr,
                cJSON_CreateString(shape->role[i] == KM_ROLE_HOLE ? "hole"
                                                                  : "outer")) ||
        (samples > 0 && !append(ctx, jm, samples_json(ctx, &sigs[i], samples))))
      goto fail;
  }
  return res;
fail:
  cJSON_Delete(res);
  return NULL;
}

/* The answer for a shape: NULL with the error in ctx. */
static cJSON *shape_route(api_ctx *ctx, const api_request *req,
                          const api_input *in, double tol, size_t samples) {
  km_signature *sigs = km__calloc(in->ncontours, sizeof *sigs);
  km_shape shape;
  cJSON *res = NULL;
  km_shape_init(&shape);
  if (sigs == NULL) {
    api__oom(ctx);
    return NULL;
  }
  for (size_t i = 0; i < in->ncontours; i++) km_signature_init(&sigs[i]);
  if (shape_signatures(ctx, req, in, tol, sigs, &shape))
    res = shape_answer(ctx, sigs, &shape, samples);
  for (size_t i = 0; i < in->ncontours; i++) km_signature_free(&sigs[i]);
  km__free(sigs);
  km_shape_free(&shape);
  return res;
}

static const char *const signature_members[] = {"curve", "tolerance",
                                                "samples"};

api_status api__route_signature(api_ctx *ctx, const api_request *req,
                                api_response *out) {
  cJSON *root = api__parse_body(ctx, req->body, req->length);
  cJSON *res = NULL;
  api_input in;
  km_signature sig;
  const km_signature *use = NULL;
  double tol = 0;
  long samples = 0;

  api__input_init(&in);
  km_signature_init(&sig);
  if (root == NULL ||
      !api__known_members(ctx, root, "", API_NAMES(signature_members)) ||
      !api__parse_tolerance(ctx, root, &tol) ||
      !api__member_int(ctx, root, "", "samples", false, 2,
                       (long)ctx->cfg->max_samples, &samples, NULL) ||
      !api__parse_curve(ctx, cJSON_GetObjectItemCaseSensitive(root, "curve"),
                        "/curve", tol, &in))
    goto done;
  if (in.is_shape) {
    res = shape_route(ctx, req, &in, tol, (size_t)samples);
    goto done;
  }
  if (!signature_of(ctx, req, &in, tol, &sig, &use) ||
      !check_size(ctx, use, (size_t)samples))
    goto done;
  res = answer_json(ctx, use, (size_t)samples);
done:
  /* freed before the answer is printed: the two never take memory at once */
  cJSON_Delete(root);
  api__input_free(&in);
  km_signature_free(&sig);
  if (res == NULL) {
    api__ctx_problem(ctx, out, req->request_id);
    return out->status;
  }
  return api__respond_json(ctx, res, 200, out, req->request_id);
}
