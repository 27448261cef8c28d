/* morph_result.c - the answer of a prepared morph: every frame rendered,
 * then assembled as JSON (frames with their curves and metrics, the
 * matches used, the animation paths) or as an SVG document; a frame that
 * failed is reported by its place in the request.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "json_write.h"
#include "km/alloc.h"
#include "morph_plan.h"

/* Number of cubic pieces in an SVG path written as "M x y C ..." with the
 * C command not repeated: six numbers a piece after the two of the moveto. */
size_t api__count_pieces(const char *d) {
  size_t numbers = 0;
  while (*d != '\0') {
    char *end;
    if ((*d >= '0' && *d <= '9') || *d == '-' || *d == '+' || *d == '.') {
      strtod(d, &end);
      if (end == d) {
        d++;
        continue;
      }
      numbers++;
      d = end;
    } else {
      d++;
    }
  }
  return numbers > 2 ? (numbers - 2) / 6 : 1;
}

bool api__json_metrics(api_ctx *ctx, api_svg_buf *b,
                       const km_frame_metrics *m) {
  API_JSON_LIT(b, "{\"length\":");
  if (!api__json_num(ctx, b, m->length, "length")) return false;
  API_JSON_LIT(b, ",\"max_abs_kappa\":");
  if (!api__json_num(ctx, b, m->max_abs_kappa, "max_abs_kappa")) return false;
  API_JSON_LIT(b, ",\"bending_energy\":");
  if (!api__json_num(ctx, b, m->bending_energy, "bending_energy")) return false;
  API_JSON_LIT(b, ",\"self_intersections\":");
  if (!api__json_num(ctx, b, (double)m->self_intersections,
                     "self_intersections"))
    return false;
  API_JSON_LIT(b, ",\"closure_gap\":");
  if (!api__json_num(ctx, b, m->closure_gap, "closure_gap")) return false;
  API_JSON_LIT(b, "}");
  return true;
}

/* "animate_d": every frame as a path with one common number of cubic
 * pieces, the most any frame needs at the tolerance, so that SMIL or CSS
 * can interpolate between them. */
static bool animate_write(api_ctx *ctx, api_svg_buf *b,
                          const api_morph_plan *pl) {
  size_t pieces = 1;
  for (size_t i = 0; i < pl->nframes; i++) {
    char *d = api_svg_path_d(&pl->frames[i].curve, pl->tol, NULL);
    if (d == NULL) return api__oom(ctx);
    pieces = api__count_pieces(d) > pieces ? api__count_pieces(d) : pieces;
    km__free(d);
  }
  API_JSON_LIT(b, "[");
  for (size_t i = 0; i < pl->nframes; i++) {
    char *d = api_svg_path_d_fixed(&pl->frames[i].curve, pieces);
    if (d == NULL) return api__oom(ctx);
    if (i > 0) API_JSON_LIT(b, ",");
    api__json_string(b, d);
    km__free(d);
  }
  API_JSON_LIT(b, "]");
  return true;
}

api_grid api__plan_grid(const api_morph_plan *pl) {
  api_grid grid = {false, 0, 0.0};
  if (pl->precision == API_PRECISION_TOLERANCE)
    grid = api__tolerance_grid(pl->tol);
  return grid;
}

/* One frame's object: its t, its curve, its metrics when asked for. */
bool api__frame_write(api_ctx *ctx, api_svg_buf *b, const api_morph_plan *pl,
                      const api_frame_slot *f, const api_grid *grid) {
  if (pl->shapes) return api__shape_frame_write(ctx, b, pl, f, grid);
  API_JSON_LIT(b, "{\"t\":");
  if (!api__json_num(ctx, b, f->t, "t")) return false;
  API_JSON_LIT(b, ",\"curve\":");
  if (!api__json_curve(ctx, b, &f->curve, pl->inc.svg_d, pl->tol, grid,
                       f->length, NULL))
    return false;
  if (pl->metrics) {
    API_JSON_LIT(b, ",\"metrics\":");
    if (!api__json_metrics(ctx, b, &f->metrics)) return false;
  }
  API_JSON_LIT(b, "}");
  return true;
}

/* "matches_used": the [r_from, r_to] pairs the morph matched; [] when
 * none. */
static bool matches_used_write(api_ctx *ctx, api_svg_buf *b,
                               const km_morph *morph) {
  size_t npairs = km_morph_matches_used(morph, NULL, 0);
  double *pairs = km__malloc((npairs > 0 ? 2 * npairs : 1) * sizeof *pairs);
  bool ok;
  if (pairs == NULL) return api__oom(ctx);
  npairs = km_morph_matches_used(morph, pairs, npairs);
  ok = api__json_nums(ctx, b, pairs, npairs, 2);
  km__free(pairs);
  return ok;
}

/* The JSON answer written straight into one buffer, frame after frame;
 * only "intersections" (morph_crossings.c), once an answer, is still
 * built as a tree and printed into it. */
static api_status result_json(api_ctx *ctx, api_morph_plan *pl,
                              api_response *out) {
  api_svg_buf b;
  api_grid grid = api__plan_grid(pl);
  api__svg_buf_init(&b);
  API_JSON_LIT(&b, "{\"method\":");
  api__json_string(&b, api__morph_method_names[pl->opt.method]);
  API_JSON_LIT(&b, ",\"frames\":[");
  for (size_t i = 0; i < pl->nframes; i++) {
    api_frame_slot *f = &pl->frames[i];
    if (i > 0) API_JSON_LIT(&b, ",");
    if (f->text.s != NULL) {
      /* printed when rendered: copied, and its memory given back at once */
      api__json_raw(&b, f->text.s, f->text.len);
      api__svg_buf_free(&f->text);
    } else if (!api__frame_write(ctx, &b, pl, f, &grid)) {
      goto fail;
    }
  }
  if (pl->shapes) {
    API_JSON_LIT(&b, "],\"contour_matches_used\":");
    if (!api__shape_pairs_write(ctx, &b, pl)) goto fail;
  } else {
    API_JSON_LIT(&b, "],\"matches_used\":");
    if (!matches_used_write(ctx, &b, pl->morph)) goto fail;
  }
  if (pl->opt.intersections == KM_INTERSECTIONS_AVOID) {
    API_JSON_LIT(&b, ",\"intersections\":");
    if (!api__json_tree(ctx, &b, api__intersections_json(ctx, pl))) goto fail;
  }
  if (pl->inc.animate_d) {
    API_JSON_LIT(&b, ",\"animate_d\":");
    if (pl->shapes ? !api__shape_animate_write(ctx, &b, pl)
                   : !animate_write(ctx, &b, pl))
      goto fail;
  }
  API_JSON_LIT(&b, "}");
  if (!api__json_done(ctx, &b)) goto fail;
  out->status = 200;
  out->content_type = API_CT_JSON;
  out->length = b.len;
  out->body = api__svg_buf_take(&b);
  return 200;
fail:
  api__svg_buf_free(&b);
  api__ctx_problem(ctx, out, pl->request_id);
  return out->status;
}

static api_status result_svg(api_ctx *ctx, api_morph_plan *pl,
                             api_response *out) {
  api_svg_frame *fr = pl->shapes ? NULL : km__malloc(pl->nframes * sizeof *fr);
  char *doc = pl->shapes ? api__shape_svg(pl) : NULL;
  if (fr != NULL) {
    for (size_t i = 0; i < pl->nframes; i++) {
      fr[i].t = pl->frames[i].t;
      fr[i].curve = &pl->frames[i].curve;
      fr[i].sig = pl->want_sig ? &pl->frames[i].sig : NULL;
    }
    doc = api_svg_morph_document(fr, pl->nframes, &pl->svgopt);
    km__free(fr);
  }
  if (doc == NULL) {
    api__oom(ctx);
    api__ctx_problem(ctx, out, pl->request_id);
    return out->status;
  }
  out->status = 200;
  out->content_type = API_CT_SVG;
  out->body = doc;
  out->length = strlen(doc);
  return 200;
}

/* The problem of frame i, which failed or was stopped: named by its entry
 * of "times", or by the request as a whole, with the frame and its t
 * ahead of the core's message. */
static void frame_problem(api_ctx *ctx, const api_morph_plan *plan, size_t i) {
  const api_frame_slot *f = &plan->frames[i];
  char base[API_POINTER_MAX], msg[API_TEXT_MAX];
  km_error e = f->err;
  if (f->st == KM_ECANCELLED) {
    api__stopped(ctx);
    return;
  }
  base[0] = '\0';
  if (plan->times_given) api__ptr_idx(base, "/times", i);
  e.field = KM_FIELD_NONE;
  api__core_fail(ctx, f->st, &e, base, API_KIND_REQUEST);
  snprintf(msg, sizeof msg, "frame %zu (t = %.17g): ", i, f->t);
  strncat(msg, ctx->message, sizeof msg - strlen(msg) - 1);
  memcpy(ctx->message, msg, sizeof msg);
  memcpy(ctx->detail, msg, sizeof msg);
}

api_status api_morph_result(api_morph_plan *plan, api_response *out) {
  api_ctx ctx;
  api_response_init(out);
  if (plan == NULL) {
    api_problem(out, 500, API_P_INTERNAL, "Internal error", "no morph plan",
                NULL, NULL, NULL);
    return out->status;
  }
  api__ctx_init(&ctx, &plan->cfg);
  for (size_t i = 0; i < plan->nframes; i++) {
    if (plan->frames[i].state == API_FRAME_PENDING)
      api_morph_render_frame(plan, i);
    if (plan->frames[i].state != API_FRAME_DONE) {
      frame_problem(&ctx, plan, i);
      api__ctx_problem(&ctx, out, plan->request_id);
      return out->status;
    }
  }
  return plan->svg ? result_svg(&ctx, plan, out) : result_json(&ctx, plan, out);
}
