/* route_reconstruct.c - POST /v1/reconstruct: a curvature signature in, a
 * B-spline curve within the tolerance of the exact curve out, with the
 * bound actually achieved.
 */
#include <math.h>

#include "internal.h"

/* The members of a reconstruct request besides its signature. */
typedef struct options {
  double tol; /* 0: none given */
  long degree;
  api_include inc;
} options;

static bool read_options(api_ctx *ctx, const cJSON *root, options *o) {
  o->tol = 0;
  o->degree = 3;
  if (!api__parse_tolerance(ctx, root, &o->tol) ||
      !api__member_int(ctx, root, "", "degree", false, -1000000, 1000000,
                       &o->degree, NULL) ||
      !api__parse_include(ctx, root, false, &o->inc))
    return false;
  if (o->degree != 3 && o->degree != 5)
    return api__invalid(ctx, "/degree", "must be 3 or 5");
  return true;
}

/* The curve of sig into *curve, within the tolerance, with the bound
 * achieved; the answer's size checked from its control points before it
 * is printed. */
static bool reconstruct(api_ctx *ctx, const api_request *req, const options *o,
                        const km_signature *sig, km_curve *curve,
                        double *bound) {
  km_error err;
  km_stop stop_buf;
  size_t predicted;
  /* the answer's curve is held to the limit on curves, as inputs are */
  km_status st = km_reconstruct_until(
      sig, (int)o->degree, o->tol, ctx->cfg->max_control_points,
      api__km_stop(req, &stop_buf), curve, bound, &err);
  if (st == KM_ECANCELLED) return api__stopped(ctx);
  if (st != KM_OK)
    return api__core_fail(ctx, st, &err, "/signature", API_KIND_SIGNATURE);
  predicted = api__curve_json_bytes(curve->n, curve->degree, curve->w != NULL,
                                    o->inc.svg_d) +
              64;
  if (ctx->cfg->max_output_bytes == 0 ||
      predicted <= ctx->cfg->max_output_bytes)
    return true;
  return api__failf(ctx, 422, API_P_LIMIT, "Limit exceeded", "/tolerance",
                    "the answer would take up to %zu bytes (a curve of %zu "
                    "control points); the limit is %zu bytes: loosen the "
                    "tolerance",
                    predicted, curve->n, ctx->cfg->max_output_bytes);
}

/* {"curve": ..., "error_bound": ...}; svg_d printed to the request's
 * tolerance, else 1e-5 of the length. */
static cJSON *answer_json(api_ctx *ctx, const options *o, double length,
                          const km_curve *curve, double bound) {
  cJSON *res = cJSON_CreateObject(), *jc;
  if (res == NULL) {
    api__oom(ctx);
    return NULL;
  }
  if ((jc = api__curve_json(ctx, curve, o->inc.svg_d,
                            o->tol > 0 ? o->tol : 1e-5 * length)) == NULL)
    goto fail;
  if (!api__add_item(ctx, res, "curve", jc) ||
      !api__add_num(ctx, res, "error_bound", bound))
    goto fail;
  return res;
fail:
  cJSON_Delete(res);
  return NULL;
}

api_status api__route_reconstruct(api_ctx *ctx, const api_request *req,
                                  api_response *out) {
  cJSON *root = api__parse_body(ctx, req->body, req->length);
  cJSON *res = NULL;
  const cJSON *js;
  options o;
  km_signature sig;
  km_curve curve;
  double bound = 0;

  km_signature_init(&sig);
  km_curve_init(&curve);
  if (root == NULL || !read_options(ctx, root, &o) ||
      (js = api__require(ctx, root, "", "signature")) == NULL ||
      !api__parse_signature(ctx, js, "/signature", &sig) ||
      !reconstruct(ctx, req, &o, &sig, &curve, &bound))
    goto done;
  res = answer_json(ctx, &o, sig.length, &curve, bound);
done:
  /* freed before the answer is printed: the two never take memory at once */
  cJSON_Delete(root);
  km_signature_free(&sig);
  km_curve_free(&curve);
  if (res == NULL) {
    api__ctx_problem(ctx, out, req->request_id);
    return out->status;
  }
  return api__respond_json(ctx, res, 200, out, req->request_id);
}
