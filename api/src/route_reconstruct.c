/* route_reconstruct.c - POST /v1/reconstruct: a curvature signature in, a
 * B-spline curve within the tolerance of the exact curve out, with the
 * bound actually achieved.
 */
#include <math.h>

#include "internal.h"

api_status api__route_reconstruct(api_ctx *ctx, const api_request *req,
                                  api_response *out) {
  cJSON *root = api__parse_body(ctx, req->body, req->length);
  cJSON *res = NULL, *jc;
  const cJSON *js;
  km_signature sig;
  km_curve curve;
  double tol = 0, bound = 0;
  long degree = 3;
  bool has_degree = false;
  api_include inc;
  km_error err;
  km_status st;
  km_stop stop_buf;
  size_t predicted;

  km_signature_init(&sig);
  km_curve_init(&curve);
  if (root == NULL)
    goto fail;
  if (!api__parse_tolerance(ctx, root, &tol) ||
      !api__member_int(ctx, root, "", "degree", false, -1000000, 1000000,
                       &degree, &has_degree) ||
      !api__parse_include(ctx, root, false, &inc))
    goto fail;
  if (degree != 3 && degree != 5) {
    api__invalid(ctx, "/degree", "must be 3 or 5");
    goto fail;
  }
  if ((js = api__require(ctx, root, "", "signature")) == NULL ||
      !api__parse_signature(ctx, js, "/signature", &sig))
    goto fail;
  /* the answer's curve is held to the limit on curves, as inputs are */
  st = km_reconstruct_until(&sig, (int)degree, tol,
                            ctx->cfg->max_control_points,
                            api__km_stop(req, &stop_buf), &curve, &bound,
                            &err);
  if (st == KM_ECANCELLED) {
    api__stopped(ctx);
    goto fail;
  }
  if (st != KM_OK) {
    api__core_fail(ctx, st, &err, "/signature", API_KIND_SIGNATURE);
    goto fail;
  }
  /* the answer's size from its control points, before it is printed */
  predicted = api__curve_json_bytes(curve.n, curve.degree, curve.w != NULL,
                                    inc.svg_d) +
              64;
  if (ctx->cfg->max_output_bytes > 0 &&
      predicted > ctx->cfg->max_output_bytes) {
    api__failf(ctx, 422, API_P_LIMIT, "Limit exceeded", "/tolerance",
               "the answer would take up to %zu bytes (a curve of %zu "
               "control points); the limit is %zu bytes: loosen the "
               "tolerance",
               predicted, curve.n, ctx->cfg->max_output_bytes);
    goto fail;
  }
  res = cJSON_CreateObject();
  if (res == NULL) {
    api__oom(ctx);
    goto fail;
  }
  if ((jc = api__curve_json(ctx, &curve, inc.svg_d,
                            tol > 0 ? tol : 1e-5 * sig.length)) == NULL)
    goto fail;
  cJSON_AddItemToObject(res, "curve", jc);
  if (!api__add_num(ctx, res, "error_bound", bound))
    goto fail;
  cJSON_Delete(root);
  km_signature_free(&sig);
  km_curve_free(&curve);
  return api__respond_json(ctx, res, 200, out, req->request_id);
fail:
  cJSON_Delete(res);
  cJSON_Delete(root);
  km_signature_free(&sig);
  km_curve_free(&curve);
  api__ctx_problem(ctx, out, req->request_id);
  return out->status;
}
