/* route.c - the routing table of kmorphd (see route.h). */
#include "route.h"

#include <stdio.h>
#include <string.h>
#include <strings.h>

static const char *const ALLOW_GET = "GET, HEAD, OPTIONS";
static const char *const ALLOW_POST = "POST, OPTIONS";
static const char *const ALLOW_JOB = "GET, DELETE, OPTIONS";
static const char *const ALLOW_RESULT = "GET, OPTIONS";

static bool static_name_ok(const char *n) {
  size_t k = 0;
  if (n[0] == '\0' || n[0] == '.') return false;
  for (; n[k]; k++) {
    char c = n[k];
    if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
          (c >= '0' && c <= '9') || c == '.' || c == '_' || c == '-') ||
        k >= 100)
      return false;
  }
  return true;
}

srv_route srv__route_parse(srv_req *r, const char *url) {
  static const struct {
    const char *path;
    srv_route route;
  } FIXED[] = {{"/", SRV_R_INDEX},
               {"/healthz", SRV_R_HEALTHZ},
               {"/readyz", SRV_R_READYZ},
               {"/metrics", SRV_R_METRICS},
               {"/openapi.json", SRV_R_OPENAPI},
               {"/v1/signature", SRV_R_SIGNATURE},
               {"/v1/reconstruct", SRV_R_RECONSTRUCT},
               {"/v1/morph", SRV_R_MORPH},
               {"/v1/jobs", SRV_R_JOBS}};
  /* The absolute form (RFC 9112 3.2.2) names this origin's resource by
   * the path after the authority; an empty path is "/". */
  if (strncasecmp(url, "http://", 7) == 0 ||
      strncasecmp(url, "https://", 8) == 0) {
    const char *path = strchr(strstr(url, "//") + 2, '/');
    url = path != NULL ? path : "/";
  }
  for (size_t i = 0; i < sizeof FIXED / sizeof FIXED[0]; i++)
    if (strcmp(url, FIXED[i].path) == 0) return FIXED[i].route;
  const char *prefix = "/v1/jobs/";
  if (strncmp(url, prefix, strlen(prefix)) == 0) {
    const char *id = url + strlen(prefix);
    const char *slash = strchr(id, '/');
    size_t n = slash ? (size_t)(slash - id) : strlen(id);
    if (n == 0 || n > SRV_JOB_ID_LEN)
      return SRV_R_OTHER; /* cannot name a job: plain 404 */
    memcpy(r->job_id, id, n);
    r->job_id[n] = '\0';
    if (slash == NULL) return SRV_R_JOB;
    if (strcmp(slash, "/result") == 0) return SRV_R_JOB_RESULT;
    return SRV_R_OTHER;
  }
  const char *problems = "/problems/";
  if (strncmp(url, problems, strlen(problems)) == 0) {
    const char *name = url + strlen(problems);
    if (!static_name_ok(name)) return SRV_R_OTHER;
    snprintf(r->static_name, sizeof r->static_name, "%s", name);
    return SRV_R_PROBLEM;
  }
  if (url[0] == '/' && strchr(url + 1, '/') == NULL &&
      static_name_ok(url + 1)) {
    snprintf(r->static_name, sizeof r->static_name, "%s", url + 1);
    return SRV_R_STATIC;
  }
  return SRV_R_OTHER;
}

const char *srv__route_allowed_methods(srv_route route) {
  switch (route) {
  case SRV_R_SIGNATURE:
  case SRV_R_RECONSTRUCT:
  case SRV_R_MORPH:
  case SRV_R_JOBS: return ALLOW_POST;
  case SRV_R_JOB: return ALLOW_JOB;
  case SRV_R_JOB_RESULT: return ALLOW_RESULT;
  default: return ALLOW_GET;
  }
}

bool srv__route_method_allowed(srv_route route, const char *method) {
  switch (route) {
  case SRV_R_SIGNATURE:
  case SRV_R_RECONSTRUCT:
  case SRV_R_MORPH:
  case SRV_R_JOBS: return strcmp(method, "POST") == 0;
  case SRV_R_JOB:
    return strcmp(method, "GET") == 0 || strcmp(method, "DELETE") == 0;
  case SRV_R_JOB_RESULT: return strcmp(method, "GET") == 0;
  default: return strcmp(method, "GET") == 0 || strcmp(method, "HEAD") == 0;
  }
}

bool srv__route_is_compute(srv_route route) {
  return route == SRV_R_SIGNATURE || route == SRV_R_RECONSTRUCT ||
         route == SRV_R_MORPH || route == SRV_R_JOBS;
}

bool srv__route_is_probe(srv_route route) {
  return route == SRV_R_HEALTHZ || route == SRV_R_READYZ ||
         route == SRV_R_METRICS;
}
