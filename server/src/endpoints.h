/* endpoints.h - the answers kmorphd makes on the I/O thread from what it
 * holds, without a worker: the index page and static files
 * (static_endpoints.c), /metrics (static_endpoints.c), a job's state and
 * its result (job_endpoints.c).
 *
 * Each is called once for a complete request on its route with an
 * allowed method, queues its answer (reply.h) and returns libmicrohttpd's
 * verdict (MHD_NO: memory short, the connection is closed).
 */
#ifndef SRV_ENDPOINTS_H
#define SRV_ENDPOINTS_H

#include "server_internal.h"

/* GET / and GET /<name>: the file name (borrowed) under cfg.web_root if
 * its type is known and it is at most 16 MiB; for / a built-in index
 * page when the web root has none; else 404. */
enum MHD_Result srv__serve_file(srv_req *r, const char *name);

/* GET /openapi.json: the contract, with its entity tag and gzip form made
 * once. */
enum MHD_Result srv__serve_openapi(srv_req *r);

/* GET /metrics: the Prometheus text of the metrics and of the gauges read
 * now (queue, workers, connections, jobs, memory held, late clients). */
enum MHD_Result srv__serve_metrics(srv_req *r);

/* GET /v1/jobs/{id}: the job's state (200), 404 if it was never known or
 * was deleted, 410 if it is no longer kept. DELETE: cancel a live job or
 * forget a final one (204), 404 if unknown. */
enum MHD_Result srv__serve_job(srv_req *r);

/* GET /v1/jobs/{id}/result: the result of a done job, sent from the
 * store's copy; 409 while it is not done or when it failed or was
 * cancelled; 404 or 410 as for srv__serve_job. */
enum MHD_Result srv__serve_result(srv_req *r);

/* The 503 problem (into *out; the caller frees) of a job route while the
 * shared job store (--jobs, Redis) cannot be reached; rid may be NULL. */
void srv__store_unavailable(api_response *out, const char *rid);
/* The same problem as the answer to r. */
enum MHD_Result srv__answer_store_down(srv_req *r);

#endif
