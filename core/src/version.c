/* version.c - the version of the library, from its generated header. */
#include "km/version.h"

const char *km_version(void) {
  return KM_VERSION_STRING;
}
