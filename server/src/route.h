/* route.h - what a request target names, and which methods it allows.
 *
 * Thread-safety: every function works on its arguments only.
 */
#ifndef SRV_ROUTE_H
#define SRV_ROUTE_H

#include <stdbool.h>

#include "server_internal.h"

/* The route url names (origin form, or absolute form whose authority is
 * skipped). For /v1/jobs/{id}[/result] fills r->job_id; for a single
 * safe file name under "/", or a name under /problems/, fills
 * r->static_name. SRV_R_OTHER (a plain
 * 404) for everything else, including job ids longer than
 * SRV_JOB_ID_LEN. */
srv_route srv__route_parse(srv_req *r, const char *url);

/* The Allow header of route (static text). */
const char *srv__route_allowed_methods(srv_route route);

/* True if method may be used on route (OPTIONS is handled apart). */
bool srv__route_method_allowed(srv_route route, const char *method);

/* True if route's answer is computed by a worker from the body. */
bool srv__route_is_compute(srv_route route);

/* True for the probes a load balancer or an operator sends: they are
 * answered from a reserved slot when every ordinary one is taken. */
bool srv__route_is_probe(srv_route route);

#endif
