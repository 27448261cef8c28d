/* fuzz_api_reconstruct.c - libFuzzer target: POST /v1/reconstruct bodies through
 * api_handle, as the daemon receives them (see ../fuzz_api.h).
 */
#define FUZZ_ROUTE API_ROUTE_RECONSTRUCT
#include "../fuzz_api.h"
