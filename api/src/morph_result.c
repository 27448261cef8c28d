/* morph_result.c - the answer of a prepared morph: every frame rendered,
 * then assembled as JSON (frames with their curves and metrics, the
 * matches used, the animation paths) or as an SVG document; a frame that
 * failed is reported by its place in the request.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

cJSON *api__metrics_json(api_ctx *ctx, const km_frame_metrics *m) {
  cJSON *o = cJSON_CreateObject();
  if (o == NULL) {
    api__oom(ctx);
    return NULL;
  }
  if (!api__add_num(ctx, o, "length", m->length) ||
      !api__add_num(ctx, o, "max_abs_kappa", m->max_abs_kappa) ||
      !api__add_num(ctx, o, "bending_energy", m->bending_energy) ||
      !api__add_num(ctx, o, "self_intersections",
                    (double)m->self_intersections) ||
      !api__add_num(ctx, o, "closure_gap", m->closure_gap)) {
    cJSON_Delete(o);
    return NULL;
  }
  return o;
}

/* "animate_d": every frame as a path with one common number of cubic
 * pieces, the most any frame needs at the tolerance, so that SMIL or CSS
 * can interpolate between them. */
static cJSON *animate_json(api_ctx *ctx, const api_morph_plan *pl) {
  size_t pieces = 1;
  cJSON *a;
  for (size_t i = 0; i < pl->nframes; i++) {
    char *d = api_svg_path_d(&pl->frames[i].curve, pl->tol, NULL);
    if (d == NULL) {
      api__oom(ctx);
      return NULL;
    }
    pieces = api__count_pieces(d) > pieces ? api__count_pieces(d) : pieces;
    km__free(d);
  }
  a = cJSON_CreateArray();
  if (a == NULL) {
    api__oom(ctx);
    return NULL;
  }
  for (size_t i = 0; i < pl->nframes; i++) {
    char *d = api_svg_path_d_fixed(&pl->frames[i].curve, pieces);
    cJSON *s = d != NULL ? cJSON_CreateString(d) : NULL;
    km__free(d);
    if (s == NULL) {
      cJSON_Delete(a);
      api__oom(ctx);
      return NULL;
    }
    cJSON_AddItemToArray(a, s);
  }
  return a;
}

/* One frame's object: its t, its curve, its metrics when asked for. */
static cJSON *frame_json(api_ctx *ctx, const api_morph_plan *pl,
                         const api_frame_slot *f) {
  cJSON *fo, *c;
  if (pl->shapes) return api__shape_frame_json(ctx, pl, f);
  if ((fo = cJSON_CreateObject()) == NULL) {
    api__oom(ctx);
    return NULL;
  }
  if (!api__add_num(ctx, fo, "t", f->t)) goto fail;
  if ((c = api__curve_json(ctx, &f->curve, pl->inc.svg_d, pl->tol)) == NULL)
    goto fail;
  if (!api__add_item(ctx, fo, "curve", c)) goto fail;
  if (pl->metrics) {
    if ((c = api__metrics_json(ctx, &f->metrics)) == NULL ||
        !api__add_item(ctx, fo, "metrics", c))
      goto fail;
  }
  return fo;
fail:
  cJSON_Delete(fo);
  return NULL;
}

/* "matches_used": the [r_from, r_to] pairs the morph matched; [] when
 * none. */
static cJSON *matches_used_json(api_ctx *ctx, const km_morph *morph) {
  size_t npairs = km_morph_matches_used(morph, NULL, 0);
  double *pairs = km__malloc((npairs > 0 ? 2 * npairs : 1) * sizeof *pairs);
  cJSON *mu = NULL;
  if (pairs == NULL) {
    api__oom(ctx);
    return NULL;
  }
  npairs = km_morph_matches_used(morph, pairs, npairs);
  if (npairs > 0)
    mu = api__num_array_json(ctx, pairs, npairs, 2);
  else if ((mu = cJSON_CreateArray()) == NULL)
    api__oom(ctx);
  km__free(pairs);
  return mu;
}

/* The answer's text, growing as each part is printed. */
typedef struct text_out {
  char *p;
  size_t len, cap;
} text_out;

static bool text_put(text_out *t, const char *s, size_t n) {
  if (t->len + n + 1 > t->cap) {
    size_t cap = t->cap ? t->cap : 4096;
    while (cap < t->len + n + 1) cap += cap / 2;
    char *p = km__realloc(t->p, cap);
    if (p == NULL) return false;
    t->p = p;
    t->cap = cap;
  }
  memcpy(t->p + t->len, s, n);
  t->len += n;
  t->p[t->len] = '\0';
  return true;
}

/* Print item (consumed) after the text key (the separators included). */
static bool text_put_item(text_out *t, const char *key, cJSON *item) {
  char *s = item != NULL ? cJSON_PrintUnformatted(item) : NULL;
  cJSON_Delete(item);
  bool ok =
      s != NULL && text_put(t, key, strlen(key)) && text_put(t, s, strlen(s));
  km__free(s);
  return ok;
}

/* The JSON answer printed part by part, a frame's tree freed as soon as
 * it is printed: the same text as printing one tree of the whole answer,
 * which would hold some three times the text's size in nodes while it is
 * printed (80 bytes a number against some 20 printed). */
static api_status result_json(api_ctx *ctx, api_morph_plan *pl,
                              api_response *out) {
  text_out t = {NULL, 0, 0};
  cJSON *method = cJSON_CreateString(api__morph_method_names[pl->opt.method]);
  if (!text_put_item(&t, "{\"method\":", method) ||
      !text_put(&t, ",\"frames\":[", 11))
    goto oom;
  for (size_t i = 0; i < pl->nframes; i++) {
    cJSON *fo = frame_json(ctx, pl, &pl->frames[i]);
    if (fo == NULL) goto fail;
    if (!text_put_item(&t, i > 0 ? "," : "", fo)) goto oom;
  }
  cJSON *item = pl->shapes ? api__shape_pairs_json(ctx, pl)
                           : matches_used_json(ctx, pl->morph);
  if (item == NULL) goto fail;
  if (!text_put_item(&t,
                     pl->shapes ? "],\"contour_matches_used\":"
                                : "],\"matches_used\":",
                     item))
    goto oom;
  if (pl->opt.intersections == KM_INTERSECTIONS_AVOID &&
      !text_put_item(&t,
                     ",\"intersections\":", api__intersections_json(ctx, pl)))
    goto fail;
  if (pl->inc.animate_d) {
    if ((item = pl->shapes ? api__shape_animate_json(ctx, pl)
                           : animate_json(ctx, pl)) == NULL)
      goto fail;
    if (!text_put_item(&t, ",\"animate_d\":", item)) goto oom;
  }
  if (!text_put(&t, "}", 1)) goto oom;
  out->status = 200;
  out->content_type = API_CT_JSON;
  out->body = t.p;
  out->length = t.len;
  return 200;
oom:
  api__oom(ctx);
fail:
  km__free(t.p);
  api__ctx_problem(ctx, out, pl->request_id);
  return out->status;
}

/* The filmstrip of a compound morph: each frame filled under the fill
 * rule of the nearer end (from's for t < 0.5), whose nesting it keeps. */
static char *shape_svg(const api_morph_plan *pl) {
  api_svg_shape_frame *fr = km__malloc(pl->nframes * sizeof *fr);
  char *doc;
  if (fr == NULL) return NULL;
  for (size_t i = 0; i < pl->nframes; i++) {
    fr[i].t = pl->frames[i].t;
    fr[i].shape = &pl->frames[i].shape;
    fr[i].fill = fr[i].t < 0.5 ? pl->sfrom.fill : pl->sto.fill;
  }
  doc = api_svg_shape_document(fr, pl->nframes, &pl->svgopt);
  km__free(fr);
  return doc;
}

static api_status result_svg(api_ctx *ctx, api_morph_plan *pl,
                             api_response *out) {
  api_svg_frame *fr = pl->shapes ? NULL : km__malloc(pl->nframes * sizeof *fr);
  char *doc = pl->shapes ? shape_svg(pl) : NULL;
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
