/* fuzz_api_morph.c - libFuzzer target: POST /v1/morph bodies through
 * api_handle, as the daemon receives them (see ../fuzz_api.h).
 */
#define FUZZ_ROUTE API_ROUTE_MORPH
/* Also drive the job path (prepare, frames, result) the daemon uses. */
#define FUZZ_JOB_PATH 1
#include "../fuzz_api.h"
