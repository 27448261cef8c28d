/* compute.h - handing a request to a compute worker, and what the worker
 * does with it.
 *
 * DESIGN: the I/O thread reserves a slot in the compute queue (none
 * free: 503 at once), suspends the connection, then submits; the worker
 * validates and computes through the api layer with a stop condition
 * (time limit, client gone, shutdown grace over), leaves the answer in
 * r->resp, gives the body's memory back and resumes the connection, and
 * the handler, called again, queues the answer (request.c). Suspending
 * first means the resume always comes after it.
 */
#ifndef SRV_COMPUTE_H
#define SRV_COMPUTE_H

#include "server_internal.h"

/* Hand a complete compute request (POST /v1/signature, /v1/reconstruct,
 * /v1/morph, /v1/jobs) to a worker. Answers at once instead while the
 * server drains (503), when the job limit is reached (429, POST /v1/jobs)
 * or when no compute slot is free (503). On the hand-off r is PH_WAIT,
 * counted in srv->suspended and owned by the worker until it resumes the
 * connection with r PH_READY. Runs on the request's I/O thread. */
enum MHD_Result srv__hand_off(srv_req *r);

#endif
