/* fuzz_api_signature.c - libFuzzer target: POST /v1/signature bodies through
 * api_handle, as the daemon receives them (see ../fuzz_api.h).
 */
#define FUZZ_ROUTE API_ROUTE_SIGNATURE
#include "../fuzz_api.h"
