/* static_endpoints.c - the index page, static files from the web root and
 * /metrics (see endpoints.h).
 */
#include "endpoints.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "reply.h"
#include "util.h"

/* ------------------------------------------------------------- files */

static char *read_file(const char *path, size_t max, size_t *len) {
  FILE *f = fopen(path, "rb");
  if (f == NULL) return NULL;
  char *buf = malloc(max + 1);
  size_t n = buf ? fread(buf, 1, max + 1, f) : 0;
  fclose(f);
  if (buf == NULL || n > max) {
    free(buf);
    return NULL;
  }
  buf[n] = '\0';
  *len = n;
  return buf;
}

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

enum MHD_Result srv__serve_file(srv_req *r, const char *name) {
  const char *type = type_of(name);
  char path[1024];
  size_t len = 0;
  char *body = NULL;
  if (type != NULL &&
      (size_t)snprintf(path, sizeof path, "%s/%s", r->srv->cfg.web_root, name) <
          sizeof path)
    body = read_file(path, (size_t)16 << 20, &len);
  if (body != NULL) return srv__answer(r, 200, type, body, len, true);
  if (r->route == SRV_R_INDEX)
    return srv__answer(r, 200, "text/html; charset=utf-8", (char *)INDEX_HTML,
                       sizeof INDEX_HTML - 1, false);
  return srv__problem(r, 404, "/problems/not-found", "Not found",
                      "no such resource", NULL, NULL);
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
  return srv__answer(r, 200, "text/plain; version=0.0.4; charset=utf-8", text,
                     len, true);
}
