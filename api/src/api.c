/* api.c - entry points of the contract layer: configuration, responses,
 * problem+json, the per-request context and dispatch of one request to its
 * route. Request bodies are parsed in json_parse.c.
 */
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "internal.h"
#include "km/alloc.h"

/* ------------------------------------------------------------ allocation */

#if defined(KM_ALLOC_HOOKED)
#include <pthread.h>

/* cJSON keeps its allocator in one process-wide table (cJSON_InitHooks):
 * pointed at the km/alloc.h hook, the request and response trees fail and
 * are counted like every other allocation of the api. The table is
 * written once, before the first tree, under pthread_once, so threads that
 * enter the api together never race on it. */
static pthread_once_t cjson_hooks_once = PTHREAD_ONCE_INIT;

static void install_cjson_hooks(void) {
  cJSON_Hooks hooks = {km__malloc, km__free};
  cJSON_InitHooks(&hooks);
}

void api__init(void) {
  pthread_once(&cjson_hooks_once, install_cjson_hooks);
}
#endif

void api_config_default(api_config *cfg) {
  cfg->max_body_bytes = 8u * 1024u * 1024u;
  cfg->max_control_points = 100000;
  cfg->max_frames_sync = 1000;
  cfg->max_frames_job = 10000;
  cfg->max_samples = 100000;
  cfg->max_json_depth = 64;
  cfg->max_output_bytes = 64u * 1024u * 1024u;
  cfg->max_contours = KM_SHAPE_DEFAULT_MAX_CONTOURS;
}

void api_response_init(api_response *r) {
  r->status = 0;
  r->content_type = NULL;
  r->body = NULL;
  r->length = 0;
}

void api_response_free(api_response *r) {
  if (r == NULL) return;
  km__free(r->body);
  api_response_init(r);
}

/* ---------------------------------------------------------------- problems */

static const char *default_type(api_status status) {
  switch (status) {
  case 400: return API_P_MALFORMED;
  case 404: return API_P_NOT_FOUND;
  case 405: return "/problems/method-not-allowed";
  case 409: return "/problems/not-ready";
  case 413: return API_P_TOO_LARGE;
  case 415: return "/problems/unsupported-media-type";
  case 422: return API_P_INVALID_REQUEST;
  case 429: return "/problems/too-many-requests";
  case 503: return "/problems/unavailable";
  default: return status >= 500 ? API_P_INTERNAL : "/problems/bad-request";
  }
}

static const char *default_title(api_status status) {
  switch (status) {
  case 400: return "Malformed JSON";
  case 404: return "Not found";
  case 405: return "Method not allowed";
  case 409: return "Result not ready";
  case 413: return "Body too large";
  case 415: return "Unsupported media type";
  case 422: return "Invalid request";
  case 429: return "Too many requests";
  case 503: return "Service unavailable";
  default: return status >= 500 ? "Internal error" : "Bad request";
  }
}

/* A request id is echoed only if it is short printable ASCII: it comes from
 * a client header and must not smuggle bytes into the body or the logs. */
static bool sane_request_id(const char *id) {
  size_t n = 0;
  if (id == NULL || *id == '\0') return false;
  for (; id[n] != '\0'; n++)
    if (n >= 200 || id[n] < 0x21 || id[n] > 0x7e) return false;
  return true;
}

/* Last resort when cJSON cannot allocate: a fixed body, still valid JSON. */
static void problem_fallback(api_response *out, api_status status) {
  static const char fmt[] = "{\"type\":\"%s\",\"title\":\"%s\",\"status\":%d}";
  char buf[256];
  int n = snprintf(buf, sizeof buf, fmt, default_type(status),
                   default_title(status), status);
  out->status = status;
  out->content_type = API_CT_PROBLEM;
  out->body = NULL;
  out->length = 0;
  if (n > 0 && (size_t)n < sizeof buf) {
    out->body = km__malloc((size_t)n + 1);
    if (out->body != NULL) {
      memcpy(out->body, buf, (size_t)n + 1);
      out->length = (size_t)n;
    }
  }
}

void api_problem(api_response *out, api_status status, const char *type,
                 const char *title, const char *detail, const char *pointer,
                 const char *message, const char *request_id) {
  cJSON *root;
  bool ok;
  api__init();
  root = cJSON_CreateObject();
  ok = root != NULL;
  if (type == NULL) type = default_type(status);
  if (title == NULL) title = default_title(status);
  ok = ok && cJSON_AddStringToObject(root, "type", type) != NULL;
  ok = ok && cJSON_AddStringToObject(root, "title", title) != NULL;
  ok = ok && cJSON_AddNumberToObject(root, "status", status) != NULL;
  if (ok && detail != NULL)
    ok = cJSON_AddStringToObject(root, "detail", detail) != NULL;
  if (ok && pointer != NULL) {
    cJSON *errs = cJSON_AddArrayToObject(root, "errors");
    cJSON *e = cJSON_CreateObject();
    ok = errs != NULL && e != NULL;
    if (ok)
      cJSON_AddItemToArray(errs, e);
    else
      cJSON_Delete(e);
    ok = ok && cJSON_AddStringToObject(e, "pointer", pointer) != NULL;
    ok = ok && cJSON_AddStringToObject(
                   e, "message",
                   message != NULL ? message
                                   : (detail != NULL ? detail : title)) != NULL;
  }
  if (ok && sane_request_id(request_id)) {
    /* instance (RFC 9457 3.1.5): this occurrence, as the request id in a
     * URN, the id the daemon's log lines carry. */
    char instance[sizeof API_INSTANCE_PREFIX + 200];
    snprintf(instance, sizeof instance, "%s%s", API_INSTANCE_PREFIX,
             request_id);
    ok = cJSON_AddStringToObject(root, "request_id", request_id) != NULL &&
         cJSON_AddStringToObject(root, "instance", instance) != NULL;
  }
  char *text = ok ? cJSON_PrintUnformatted(root) : NULL;
  cJSON_Delete(root);
  if (text == NULL) {
    problem_fallback(out, status);
    return;
  }
  out->status = status;
  out->content_type = API_CT_PROBLEM;
  out->body = text;
  out->length = strlen(text);
}

/* ----------------------------------------------------------------- context */

void api__ctx_init(api_ctx *ctx, const api_config *cfg) {
  memset(ctx, 0, sizeof *ctx);
  ctx->cfg = cfg;
}

bool api__fail(api_ctx *ctx, api_status status, const char *type,
               const char *title, const char *pointer, const char *message) {
  if (ctx->status != 0) return false;
  ctx->status = status;
  ctx->type = type != NULL ? type : default_type(status);
  ctx->title = title != NULL ? title : default_title(status);
  snprintf(ctx->message, sizeof ctx->message, "%s",
           message != NULL ? message : ctx->title);
  if (pointer != NULL) {
    ctx->has_pointer = true;
    snprintf(ctx->pointer, sizeof ctx->pointer, "%s", pointer);
    if (pointer[0] != '\0')
      snprintf(ctx->detail, sizeof ctx->detail, "%s: %s", ctx->pointer,
               ctx->message);
    else
      snprintf(ctx->detail, sizeof ctx->detail, "%s", ctx->message);
  } else {
    snprintf(ctx->detail, sizeof ctx->detail, "%s", ctx->message);
  }
  return false;
}

bool api__failf(api_ctx *ctx, api_status status, const char *type,
                const char *title, const char *pointer, const char *fmt, ...) {
  char msg[API_TEXT_MAX];
  va_list ap;
  if (ctx->status != 0) return false;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  return api__fail(ctx, status, type, title, pointer, msg);
}

bool api__invalid(api_ctx *ctx, const char *pointer, const char *fmt, ...) {
  char msg[API_TEXT_MAX];
  va_list ap;
  if (ctx->status != 0) return false;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  return api__fail(ctx, 422, API_P_INVALID_REQUEST, "Invalid request", pointer,
                   msg);
}

bool api__oom(api_ctx *ctx) {
  return api__fail(ctx, 503, API_P_NO_MEMORY, "Out of memory", NULL,
                   "the service ran out of memory; retry later");
}

void api__ptr_key(char *buf, const char *base, const char *key) {
  snprintf(buf, API_POINTER_MAX, "%s/%s", base, key);
}

void api__ptr_idx(char *buf, const char *base, size_t index) {
  snprintf(buf, API_POINTER_MAX, "%s/%zu", base, index);
}

void api__ctx_problem(const api_ctx *ctx, api_response *out,
                      const char *request_id) {
  api_status status = ctx->status != 0 ? ctx->status : 500;
  api_problem(out, status, ctx->type, ctx->title,
              ctx->status != 0 ? ctx->detail : "unknown failure",
              ctx->has_pointer ? ctx->pointer : NULL, ctx->message, request_id);
}

api_status api__respond_json(api_ctx *ctx, cJSON *root, api_status status,
                             api_response *out, const char *request_id) {
  char *text = root != NULL ? cJSON_PrintUnformatted(root) : NULL;
  cJSON_Delete(root);
  if (text == NULL) {
    api__oom(ctx);
    api__ctx_problem(ctx, out, request_id);
    return out->status;
  }
  out->status = status;
  out->content_type = API_CT_JSON;
  out->body = text;
  out->length = strlen(text);
  return status;
}

/* ---------------------------------------------------------------- dispatch */

api_status api_handle(const api_config *cfg, const api_request *req,
                      api_response *out) {
  api_config defaults;
  api_ctx ctx;
  api__init();
  if (cfg == NULL) {
    api_config_default(&defaults);
    cfg = &defaults;
  }
  api_response_init(out);
  api__ctx_init(&ctx, cfg);
  switch (req->route) {
  case API_ROUTE_SIGNATURE: return api__route_signature(&ctx, req, out);
  case API_ROUTE_RECONSTRUCT: return api__route_reconstruct(&ctx, req, out);
  case API_ROUTE_MORPH: {
    api_morph_plan *plan = NULL;
    api_status st =
        api_morph_prepare(cfg, req, cfg->max_frames_sync, &plan, out);
    if (st != API_STEP_DONE) return st;
    /* frames under the request's stop; a stopped or failed one is
     * reported by api_morph_result */
    for (size_t i = 0; req->stop != NULL && i < api_morph_frame_count(plan);
         i++)
      if (api_morph_render_frame_until(plan, i, req->stop, req->stop_ctx) ==
          503)
        break;
    st = api_morph_result(plan, out);
    api_morph_plan_free(plan);
    return st;
  }
  default:
    api_problem(out, 404, API_P_NOT_FOUND, "Not found", "unknown route", NULL,
                NULL, req->request_id);
    return out->status;
  }
}
