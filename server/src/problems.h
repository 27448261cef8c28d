/* problems.h - the catalogue of problem types kmorphd answers with, so
 * that every `type` of a problem+json body resolves: GET /problems/{name}
 * describes one (JSON, or an HTML page for a client preferring
 * text/html), 404 for a name not in the catalogue.
 *
 * tests/server/test_conventions.py checks that every type the sources
 * name is here.
 */
#ifndef SRV_PROBLEMS_H
#define SRV_PROBLEMS_H

#include "server_internal.h"

/* The URI scheme of a problem's `instance`: the request id as a URN, so
 * an occurrence is found in the logs (request_id=...) whatever path it
 * came on. */
#define SRV_INSTANCE_PREFIX "urn:kmorph:request:"

/* GET /problems/{name} (name in r->static_name): the description, 404 for
 * an unknown name, 406 when Accept allows neither JSON nor HTML. */
enum MHD_Result srv__serve_problem(srv_req *r);

#endif
