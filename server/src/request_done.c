/* request_done.c - the end of a request: metrics, the access log line and
 * the record freed (see request.h).
 */
#include "request.h"

#include <stdlib.h>
#include <time.h>

#include "util.h"

/* Why the connection was closed without a complete answer, or NULL. */
static const char *closed_why(const srv_req *r,
                              enum MHD_RequestTerminationCode toe) {
  if (r->cut != NULL || toe == MHD_REQUEST_TERMINATED_COMPLETED_OK)
    return r->cut;
  return toe == MHD_REQUEST_TERMINATED_TIMEOUT_REACHED   ? "idle timeout"
         : toe == MHD_REQUEST_TERMINATED_DAEMON_SHUTDOWN ? "shutdown"
         : toe == MHD_REQUEST_TERMINATED_CLIENT_ABORT    ? "client closed"
                                                         : "connection error";
}

/* One access log line for r, which took dt seconds. */
static void log_access(srv_server *s, const srv_req *r, double dt,
                       const char *why) {
  char when[32];
  time_t now = time(NULL);
  struct tm tm;
  gmtime_r(&now, &tm);
  strftime(when, sizeof when, "%Y-%m-%dT%H:%M:%SZ", &tm);
  char method[sizeof r->method];
  srv_http_log_token(method, sizeof method, r->method);
  if (srv_log_json()) {
    /* The path and method are printable already; escaped all the same,
     * so a line is always one valid JSON object. */
    char path[2 * sizeof r->path], m[2 * sizeof method];
    srv_json_escape(path, sizeof path, r->path);
    srv_json_escape(m, sizeof m, method);
    char closed[160] = "";
    if (why != NULL) {
      char esc[120];
      srv_json_escape(esc, sizeof esc, why);
      snprintf(closed, sizeof closed, ",\"closed\":\"%s\"", esc);
    }
    fprintf(s->log,
            "{\"time\":\"%s\",\"event\":\"access\",\"method\":\"%s\","
            "\"path\":\"%s\",\"status\":%d,\"bytes\":%zu,"
            "\"duration_ms\":%.3f,\"request_id\":\"%s\"%s}\n",
            when, m, path, r->status, r->bytes, dt * 1e3, r->rid, closed);
    return;
  }
  fprintf(s->log,
          "%s access method=%s path=\"%s\" status=%d bytes=%zu "
          "duration_ms=%.3f request_id=%s%s%s%s\n",
          when, method, r->path, r->status, r->bytes, dt * 1e3, r->rid,
          why ? " closed=\"" : "", why ? why : "", why ? "\"" : "");
}

void srv__on_completed(void *cls, struct MHD_Connection *c, void **req_cls,
                       enum MHD_RequestTerminationCode toe) {
  srv_server *s = cls;
  srv_req *r = *req_cls;
  (void)c;
  if (r == NULL) return;
  *req_cls = NULL;
  if (!r->begun) { /* refused by libmicrohttpd before the handler ran */
    free(r);
    return;
  }
  /* A client that left while its request computed: MHD completes the
   * resumed connection without calling the handler again. */
  if (r->counted) atomic_fetch_sub(&s->suspended, 1);
  srv_watch_request_done(srv__req_conn(r), srv_now());
  double dt = srv_now() - r->t0;
  const char *why = closed_why(r, toe);
  srv_metrics_observe(s->metrics, r->route, r->method,
                      r->status ? r->status : 0, dt);
  if (s->cfg.access_log) log_access(s, r, dt, why);
  api_response_free(&r->resp);
  srv__body_release(r);
  free(r->accept);
  free(r);
  atomic_fetch_sub(&s->inflight, 1);
}
