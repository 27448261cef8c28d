/* morph_plan.c - the prepared morph: the request read and planned once
 * (api_morph_prepare), its frames rendered on any thread, and the plan's
 * accessors. The answer is assembled in morph_result.c.
 *
 * The inputs' signatures are computed here (not inside km_morph_create) for
 * curvature morphs, so that a cusp or a degenerate curve is reported under
 * the input it belongs to ("/from" or "/to").
 */
#include <math.h>
#include <string.h>

#include "km/alloc.h"
#include "json_write.h"
#include "morph_plan.h"

void api_morph_plan_free(api_morph_plan *plan) {
  if (plan == NULL) return;
  km_morph_free(plan->morph);
  km_shape_morph_free(plan->smorph);
  km_shape_free(&plan->sfrom);
  km_shape_free(&plan->sto);
  km__free(plan->cmatches);
  for (size_t i = 0; plan->frames != NULL && i < plan->nframes; i++) {
    km_curve_free(&plan->frames[i].curve);
    km_signature_free(&plan->frames[i].sig);
    km_shape_frame_free(&plan->frames[i].shape);
    api__svg_buf_free(&plan->frames[i].text);
  }
  km__free(plan->frames);
  km__free(plan->matches);
  km__free(plan->request_id);
  api__input_free(&plan->from);
  api__input_free(&plan->to);
  km__free(plan);
}

/* ------------------------------------------------------ preparing a plan */

/* An empty plan with copies of cfg and of the request id (may be NULL) in
 * *out, written even on failure (out of memory) so the caller frees it. */
static bool plan_new(api_ctx *ctx, const api_config *cfg,
                     const char *request_id, api_morph_plan **out) {
  api_morph_plan *pl = km__calloc(1, sizeof *pl);
  *out = pl;
  if (pl == NULL) return api__oom(ctx);
  pl->cfg = *cfg;
  api__input_init(&pl->from);
  api__input_init(&pl->to);
  km_shape_init(&pl->sfrom);
  km_shape_init(&pl->sto);
  if (request_id != NULL) {
    size_t n = strlen(request_id);
    if ((pl->request_id = km__malloc(n + 1)) == NULL) return api__oom(ctx);
    memcpy(pl->request_id, request_id, n + 1);
  }
  return true;
}

/* The request's body parsed and read into pl; the tree is not kept. */
static bool plan_read(api_ctx *ctx, const api_request *req, size_t max_frames,
                      api_morph_plan *pl) {
  cJSON *root;
  bool ok;
  if (req->route != API_ROUTE_MORPH)
    return api__fail(ctx, 404, API_P_NOT_FOUND, "Not found", NULL,
                     "a morph plan needs a morph request");
  if ((root = api__parse_body(ctx, req->body, req->length)) == NULL)
    return false;
  ok = api__morph_read_request(ctx, root, req->accept, max_frames, pl);
  cJSON_Delete(root);
  return ok;
}

/* The signature of a curve input, so that its failures name the input. */
static bool input_signature(api_ctx *ctx, api_input *in, const char *ptr,
                            double tol, const km_stop *stop) {
  km_error err;
  km_status st;
  if (in->is_signature) return true;
  st = km_signature_compute_until(&in->curve, tol, stop, &in->sig, &err);
  if (st == KM_ECANCELLED) return api__stopped(ctx);
  if (st != KM_OK) return api__core_fail(ctx, st, &err, ptr, in->kind);
  return true;
}

static km_morph_input morph_input(const api_input *in) {
  km_morph_input mi;
  mi.curve = in->is_signature ? NULL : &in->curve;
  /* For curve inputs the signature is there only if computed above. */
  mi.sig = in->is_signature || in->sig.length > 0 ? &in->sig : NULL;
  return mi;
}

/* The core's plan of the morph from the inputs read into pl, under the
 * request's tolerance (else 1e-5 of the longer input). */
static bool plan_build(api_ctx *ctx, api_morph_plan *pl, const km_stop *stop) {
  km_morph_input fi, ti;
  km_error err;
  km_status st;
  if (pl->tol <= 0) pl->tol = 1e-5 * fmax(pl->from.length, pl->to.length);
  pl->opt.tolerance = pl->tol;
  /* frames are curves of the answer: held to the limit on curves */
  pl->opt.max_points = pl->cfg.max_control_points;
  if (pl->shapes) return api__shape_build(ctx, pl, stop);
  if (pl->opt.method == KM_METHOD_CURVATURE &&
      (!input_signature(ctx, &pl->from, "/from", pl->tol, stop) ||
       !input_signature(ctx, &pl->to, "/to", pl->tol, stop)))
    return false;
  fi = morph_input(&pl->from);
  ti = morph_input(&pl->to);
  /* the plan keeps no reference to the request's stop */
  pl->opt.stop = stop;
  st = km_morph_create(&pl->morph, &fi, &ti, &pl->opt, &err);
  pl->opt.stop = NULL;
  if (st == KM_ECANCELLED) return api__stopped(ctx);
  if (st != KM_OK) return api__core_fail(ctx, st, &err, "", API_KIND_REQUEST);
  return true;
}

api_status api_morph_prepare(const api_config *cfg, const api_request *req,
                             size_t max_frames, api_morph_plan **plan,
                             api_response *error) {
  api_config defaults;
  api_ctx ctx;
  api_morph_plan *pl = NULL;
  km_stop stop_buf;
  const km_stop *stop = api__km_stop(req, &stop_buf);

  api__init();
  if (cfg == NULL) {
    api_config_default(&defaults);
    cfg = &defaults;
  }
  api_response_init(error);
  api__ctx_init(&ctx, cfg);
  if (!plan_new(&ctx, cfg, req->request_id, &pl) ||
      !plan_read(&ctx, req, max_frames, pl) || !plan_build(&ctx, pl, stop) ||
      !(pl->shapes ? api__shape_check_size(&ctx, pl, stop)
                   : api__morph_check_size(&ctx, pl, stop)))
    goto fail;
  *plan = pl;
  return API_STEP_DONE;
fail:
  api__ctx_problem(&ctx, error, req->request_id);
  api_morph_plan_free(pl);
  return error->status;
}

/* ------------------------------------------------------------- accessors */

size_t api_morph_frame_count(const api_morph_plan *plan) {
  return plan != NULL ? plan->nframes : 0;
}

const char *api_morph_frames_pointer(const api_morph_plan *plan) {
  return plan != NULL && plan->times_given ? "/times" : "/frames";
}

size_t api_morph_predicted_bytes(const api_morph_plan *plan) {
  return plan != NULL ? plan->predicted : 0;
}

/* ------------------------------------------------------ rendering frames */

bool api_morph_print_while_rendering(api_morph_plan *plan, size_t limit) {
  if (plan == NULL || plan->svg || plan->inc.animate_d ||
      plan->predicted > limit)
    return false;
  plan->print_early = true;
  return true;
}

/* Frame f's object of the answer into its slot, when the plan prints
 * frames as they are rendered; left empty when it cannot be written (the
 * answer then writes it and reports why). */
static void print_early(api_morph_plan *plan, api_frame_slot *f) {
  if (!plan->print_early) return;
  api_ctx ctx;
  api__ctx_init(&ctx, &plan->cfg);
  api_grid grid = api__plan_grid(plan);
  /* room for the frame's share of the predicted answer at once */
  api__svg_buf_room(&f->text, plan->predicted / (plan->nframes + 1));
  if (!api__frame_write(&ctx, &f->text, plan, f, &grid) || f->text.failed)
    api__svg_buf_free(&f->text);
}

api_status api_morph_render_frame(api_morph_plan *plan, size_t i) {
  return api_morph_render_frame_until(plan, i, NULL, NULL);
}

api_status api_morph_render_frame_until(api_morph_plan *plan, size_t i,
                                        api_stop_fn stop, void *ctx) {
  api_frame_slot *f;
  km_stop ks = {stop, ctx};
  if (plan == NULL || i >= plan->nframes) return 404;
  f = &plan->frames[i];
  if (f->state == API_FRAME_DONE) return API_STEP_DONE;
  api__svg_buf_free(&f->text);
  if (plan->shapes) {
    api__shape_render(plan, f, stop != NULL ? &ks : NULL);
    if (f->state == API_FRAME_DONE) {
      print_early(plan, f);
      return API_STEP_DONE;
    }
    return f->st == KM_ENOMEM || f->st == KM_ECANCELLED ? 503 : 422;
  }
  km_curve_free(&f->curve);
  km_signature_free(&f->sig);
  memset(&f->err, 0, sizeof f->err);
  f->length = NAN;
  f->crossings = -1;
  f->st = km_morph_frame_until(plan->morph, f->t, stop != NULL ? &ks : NULL,
                               &f->curve, plan->metrics ? &f->metrics : NULL,
                               plan->want_sig ? &f->sig : NULL, &f->err);
  if (f->st != KM_OK) {
    f->state = API_FRAME_FAILED;
    return f->st == KM_ENOMEM || f->st == KM_ECANCELLED ? 503 : 422;
  }
  /* what the JSON answer measures of the frame; a count stopped or out
   * of memory is left to the answer */
  if (!plan->svg) {
    if (plan->precision != API_PRECISION_TOLERANCE)
      f->length = api__curve_length(&f->curve);
    if (plan->opt.intersections == KM_INTERSECTIONS_AVOID && !plan->metrics) {
      long n = -1;
      if (km_curve_self_intersections_until(
              &f->curve, api__crossing_tolerance(plan),
              stop != NULL ? &ks : NULL, &n) == KM_OK)
        f->crossings = n;
    }
  }
  f->state = API_FRAME_DONE;
  print_early(plan, f);
  return API_STEP_DONE;
}
