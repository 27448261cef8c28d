/* route_signature.c - POST /v1/signature: a curve in, its curvature
 * signature out, optionally with evenly spaced samples of kappa(s).
 */
#include <math.h>
#include <stdlib.h>

#include "internal.h"

/* n samples [s, kappa(s)] at s = i L / (n - 1). */
static cJSON *samples_json(api_ctx *ctx, const km_signature *sig, size_t n) {
  double *v = malloc(2 * n * sizeof *v);
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
  free(v);
  return a;
}

api_status api__route_signature(api_ctx *ctx, const api_request *req,
                                api_response *out) {
  cJSON *root = api__parse_body(ctx, req->body, req->length);
  cJSON *res = NULL, *js;
  api_input in;
  km_signature sig;
  const km_signature *use;
  double tol = 0;
  long samples = 0;
  bool has_samples = false;
  km_error err;
  km_status st;

  api__input_init(&in);
  km_signature_init(&sig);
  if (root == NULL)
    goto fail;
  if (!api__parse_tolerance(ctx, root, &tol) ||
      !api__member_int(ctx, root, "", "samples", false, 2,
                       (long)ctx->cfg->max_samples, &samples, &has_samples))
    goto fail;
  if (!api__parse_curve(ctx, cJSON_GetObjectItemCaseSensitive(root, "curve"),
                        "/curve", tol, &in))
    goto fail;
  if (in.is_signature) {
    use = &in.sig;
  } else {
    km_stop stop_buf;
    st = km_signature_compute_until(&in.curve, tol,
                                    api__km_stop(req, &stop_buf), &sig, &err);
    if (st == KM_ECANCELLED) {
      api__stopped(ctx);
      goto fail;
    }
    if (st != KM_OK) {
      api__core_fail(ctx, st, &err, "/curve", in.kind);
      goto fail;
    }
    use = &sig;
  }
  {
    /* the answer's size from the signature's pieces, before it is
     * printed: a curve of many spans at a tight tolerance answers with
     * many times its own size */
    size_t per_sample = 2 * 25 + 4;
    size_t sig_bytes = api__signature_json_bytes(use);
    size_t sample_bytes = has_samples ? (size_t)samples * per_sample : 0;
    size_t predicted = sig_bytes + sample_bytes + 64;
    if (ctx->cfg->max_output_bytes > 0 &&
        predicted > ctx->cfg->max_output_bytes) {
      api__failf(ctx, 422, API_P_LIMIT, "Limit exceeded",
                 sample_bytes > sig_bytes ? "/samples" : "/tolerance",
                 "the answer would take up to %zu bytes (a signature of "
                 "%zu curvature coefficients%s); the limit is %zu bytes",
                 predicted, use->kappa.n,
                 sample_bytes > sig_bytes ? " and its samples" : "",
                 ctx->cfg->max_output_bytes);
      goto fail;
    }
  }
  res = cJSON_CreateObject();
  if (res == NULL) {
    api__oom(ctx);
    goto fail;
  }
  if ((js = api__signature_json(ctx, use)) == NULL)
    goto fail;
  cJSON_AddItemToObject(res, "signature", js);
  if (has_samples) {
    if ((js = samples_json(ctx, use, (size_t)samples)) == NULL)
      goto fail;
    cJSON_AddItemToObject(res, "samples", js);
  }
  cJSON_Delete(root);
  api__input_free(&in);
  km_signature_free(&sig);
  return api__respond_json(ctx, res, 200, out, req->request_id);
fail:
  cJSON_Delete(res);
  cJSON_Delete(root);
  api__input_free(&in);
  km_signature_free(&sig);
  api__ctx_problem(ctx, out, req->request_id);
  return out->status;
}
