/* route_reconstruct.c - POST /v1/reconstruct: a curvature signature in, a
 * B-spline curve within the tolerance of the exact curve out, with the
 * bound actually achieved.
 */
#include <math.h>

#include "internal.h"
#include "json_write.h"

/* The members of a reconstruct request besides its signature. */
typedef struct options {
  double tol; /* 0: none given */
  long degree;
  api_include inc;
  api_precision precision;
} options;

static const char *const reconstruct_members[] = {
    "signature", "tolerance", "degree", "include", "precision"};

static bool read_options(api_ctx *ctx, const cJSON *root, options *o) {
  o->tol = 0;
  o->degree = 3;
  if (!api__parse_tolerance(ctx, root, &o->tol) ||
      !api__member_int(ctx, root, "", "degree", false, -1000000, 1000000,
                       &o->degree, NULL) ||
      !api__parse_include(ctx, root, false, &o->inc) ||
      !api__parse_precision(ctx, root, &o->precision))
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
  /* on the tolerance's grids the printing may move the curve by a tenth
   * of the tolerance, knots included (json_write.h): the fit leaves it */
  double tol = o->tol > 0 ? o->tol : 1e-5 * sig->length;
  if (o->precision == API_PRECISION_TOLERANCE) tol *= 0.9;
  km_status st = km_reconstruct_until(
      sig, (int)o->degree, tol, ctx->cfg->max_control_points,
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

/* {"curve": ..., "error_bound": ...}, written straight into a buffer;
 * svg_d printed to the request's tolerance, else 1e-5 of the length. The
 * bound includes what printing on the tolerance's grid moved the curve. */
static bool answer_write(api_ctx *ctx, api_svg_buf *b, const options *o,
                         double length, const km_curve *curve, double bound) {
  double tol = o->tol > 0 ? o->tol : 1e-5 * length, moved = 0.0;
  api_grid grid = {false, 0, 0.0};
  if (o->precision == API_PRECISION_TOLERANCE) grid = api__tolerance_grid(tol);
  API_JSON_LIT(b, "{\"curve\":");
  if (!api__json_curve(ctx, b, curve, o->inc.svg_d, tol, &grid, NAN, &moved))
    return false;
  API_JSON_LIT(b, ",\"error_bound\":");
  if (!api__json_num(ctx, b, bound + moved, "error_bound")) return false;
  API_JSON_LIT(b, "}");
  return api__json_done(ctx, b);
}

api_status api__route_reconstruct(api_ctx *ctx, const api_request *req,
                                  api_response *out) {
  cJSON *root = api__parse_body(ctx, req->body, req->length);
  api_svg_buf b;
  bool written = false;
  const cJSON *js;
  options o;
  km_signature sig;
  km_curve curve;
  double bound = 0, length;

  km_signature_init(&sig);
  km_curve_init(&curve);
  api__svg_buf_init(&b);
  if (root == NULL ||
      !api__known_members(ctx, root, "", API_NAMES(reconstruct_members)) ||
      !read_options(ctx, root, &o) ||
      (js = api__require(ctx, root, "", "signature")) == NULL ||
      !api__parse_signature(ctx, js, "/signature", &sig) ||
      !reconstruct(ctx, req, &o, &sig, &curve, &bound))
    goto done;
  /* the request's tree freed before the answer is written: the two never
   * take memory at once */
  cJSON_Delete(root);
  root = NULL;
  length = sig.length;
  km_signature_free(&sig);
  written = answer_write(ctx, &b, &o, length, &curve, bound);
done:
  cJSON_Delete(root);
  km_signature_free(&sig);
  km_curve_free(&curve);
  if (!written) {
    api__svg_buf_free(&b);
    api__ctx_problem(ctx, out, req->request_id);
    return out->status;
  }
  out->status = 200;
  out->content_type = API_CT_JSON;
  out->length = b.len;
  out->body = api__svg_buf_take(&b);
  return 200;
}
