/* route_signature.c - POST /v1/signature: a curve in, its curvature
 * signature out, optionally with evenly spaced samples of kappa(s).
 */
#include <math.h>

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
    double s = i + 1 == n ? sig->length
                          : sig->length * (double)i / (double)(n - 1);
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
  st = km_signature_compute_until(&in->curve, tol,
                                  api__km_stop(req, &stop_buf), sig, &err);
  if (st == KM_ECANCELLED)
    return api__stopped(ctx);
  if (st != KM_OK)
    return api__core_fail(ctx, st, &err, "/curve", in->kind);
  *use = sig;
  return true;
}

/* The answer's size from the signature's pieces, before it is printed: a
 * curve of many spans at a tight tolerance answers with many times its
 * own size. samples is 0 when none were asked for. */
static bool check_size(api_ctx *ctx, const km_signature *use,
                       size_t samples) {
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
      !api__parse_tolerance(ctx, root, &tol) ||
      !api__member_int(ctx, root, "", "samples", false, 2,
                       (long)ctx->cfg->max_samples, &samples, NULL) ||
      !api__parse_curve(ctx, cJSON_GetObjectItemCaseSensitive(root, "curve"),
                        "/curve", tol, &in) ||
      !signature_of(ctx, req, &in, tol, &sig, &use) ||
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
