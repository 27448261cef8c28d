/* static_endpoints.c - the index page, static files from the web root and
 * /metrics (see endpoints.h).
 */
#include "endpoints.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "process_metrics.h"
#include "reply.h"
#include "util.h"

/* ------------------------------------------------------------- files */

static const char *type_of(const char *name) {
  static const struct {
    const char *ext, *type;
  } T[] = {{".html", "text/html; charset=utf-8"},
           {".js", "text/javascript; charset=utf-8"},
           {".mjs", "text/javascript; charset=utf-8"},
           {".css", "text/css; charset=utf-8"},
           {".svg", "image/svg+xml"},
           {".json", "application/json"},
           {".png", "image/png"},
           {".ico", "image/x-icon"},
           {".txt", "text/plain; charset=utf-8"}};
  const char *dot = strrchr(name, '.');
  if (dot != NULL)
    for (size_t i = 0; i < sizeof T / sizeof T[0]; i++)
      if (strcmp(dot, T[i].ext) == 0) return T[i].type;
  return NULL;
}

static const char INDEX_HTML[] =
    "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
    "<title>kmorph</title></head><body>\n"
    "<h1>kmorph</h1>\n<p>Morphs planar curves by blending their curvature."
    "</p>\n<ul>\n"
    "<li>POST <code>/v1/signature</code> &mdash; curvature signature of a "
    "curve</li>\n"
    "<li>POST <code>/v1/reconstruct</code> &mdash; curve from a signature"
    "</li>\n"
    "<li>POST <code>/v1/morph</code> &mdash; a morph sequence, "
    "synchronously</li>\n"
    "<li>POST <code>/v1/jobs</code>, GET/DELETE <code>/v1/jobs/{id}</code>, "
    "GET <code>/v1/jobs/{id}/result</code> &mdash; asynchronous morphs</li>\n"
    "<li>GET <a href=\"/openapi.json\"><code>/openapi.json</code></a> "
    "&mdash; the contract</li>\n"
    "<li>GET <a href=\"/healthz\"><code>/healthz</code></a>, "
    "<a href=\"/readyz\"><code>/readyz</code></a>, "
    "<a href=\"/metrics\"><code>/metrics</code></a></li>\n"
    "</ul>\n</body></html>\n";

/* The page's files and the contract carry no version in their names, so
 * a cached copy is revalidated on every use: its entity tag makes that a
 * 304 without a body. */
#define STATIC_CACHE_CONTROL "no-cache"

/* Answer with a cache entry (its reference is taken over). */
static enum MHD_Result answer_static(srv_req *r, const srv_static *st) {
  if (!srv__accepts_type(r, st->type)) {
    srv_static_unref((void *)st);
    return srv__not_acceptable(r, st->type);
  }
  srv_body b = {.type = st->type,
                .data = st->body,
                .len = st->len,
                .gz = st->gz,
                .gz_len = st->gz_len,
                .etag = st->etag,
                .gz_etag = st->gz ? st->gz_etag : NULL,
                .cache_control = STATIC_CACHE_CONTROL,
                .release = srv_static_unref,
                .cls = (void *)st};
  return srv__answer_body(r, 200, &b);
}

enum MHD_Result srv__serve_file(srv_req *r, const char *name) {
  const char *type = type_of(name);
  char path[1024];
  const srv_static *st = NULL;
  if (type != NULL &&
      (size_t)snprintf(path, sizeof path, "%s/%s", r->srv->cfg.web_root, name) <
          sizeof path)
    st = srv_static_get(r->srv->statics, path, type, (size_t)16 << 20);
  if (st == NULL && r->route == SRV_R_INDEX)
    st = srv_static_get_const(r->srv->statics, ":index", type, INDEX_HTML,
                              sizeof INDEX_HTML - 1);
  if (st != NULL) return answer_static(r, st);
  return srv__problem(r, 404, "/problems/not-found", "Not found",
                      "no such resource", NULL, NULL);
}

enum MHD_Result srv__serve_openapi(srv_req *r) {
  const char *doc = api_openapi_json();
  const srv_static *st = srv_static_get_const(r->srv->statics, ":openapi",
                                              SRV_JSON_TYPE, doc, strlen(doc));
  if (st == NULL) {
    r->cut = "out of memory";
    return MHD_NO;
  }
  return answer_static(r, st);
}

/* ----------------------------------------------------------- metrics */

enum MHD_Result srv__serve_metrics(srv_req *r) {
  srv_server *s = r->srv;
  static const char *const names[5] = {"queued", "running", "done", "failed",
                                       "cancelled"};
  srv_gauges g;
  memset(&g, 0, sizeof g);
  g.queue_depth = srv_pool_depth(s->pool);
  g.queue_capacity = srv_pool_capacity(s->pool);
  g.workers_busy = srv_pool_busy(s->pool);
  g.workers = srv_pool_workers(s->pool);
  /* The daemon pointer comes from the connection: s->daemon is written by
   * the main thread after the I/O threads have started. */
  const union MHD_ConnectionInfo *ci =
      MHD_get_connection_info(r->conn, MHD_CONNECTION_INFO_DAEMON);
  const union MHD_DaemonInfo *info =
      ci ? MHD_get_daemon_info(ci->daemon, MHD_DAEMON_INFO_CURRENT_CONNECTIONS)
         : NULL;
  g.connections = info ? info->num_connections : 0;
  s->store->ops->counts(s->store, srv_now(), g.jobs);
  g.body_bytes = atomic_load(&s->body_bytes);
  g.result_bytes = s->store->ops->result_bytes(s->store);
  srv_watch_counts(s->watch, &g.late_requests, &g.late_sends);
  g.job_state_names = names;
  char extra[2048];
  if (s->rjobs != NULL) {
    srv_rjobs_metrics(s->rjobs, extra, sizeof extra);
    g.extra = extra;
  } else {
    g.frames_rendered = srv_jobs_frames_rendered(s->jobs);
  }
  size_t len = 0;
  char *text = srv_metrics_render(s->metrics, &g, &len);
  if (text == NULL) return MHD_NO;
  char proc[2048];
  size_t plen = srv_process_metrics(proc, sizeof proc);
  char *all = realloc(text, len + plen + 1);
  if (all == NULL) {
    free(text);
    return MHD_NO;
  }
  memcpy(all + len, proc, plen + 1);
  text = all;
  len += plen;
  return srv__answer(r, 200, "text/plain; version=0.0.4; charset=utf-8", text,
                     len, true);
}
