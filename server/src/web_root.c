/* web_root.c - the default web root: the installed page, else the source
 * tree's.
 *
 * DESIGN: the installed page is found relative to the executable
 * (/proc/self/exe), not at a path compiled in, so one build serves its
 * page wherever `make install` put it - /usr/local, /usr or a staging
 * DESTDIR - and the build tree's daemon, which has no share/ beside it,
 * keeps serving clients/web as before.
 */
#include "web_root.h"

#include <stdio.h>
#include <string.h>
#include <unistd.h>

#define SOURCE_TREE_WEB_ROOT "clients/web"
#define INSTALLED_WEB_ROOT "share/kmorph/web"

/* The folder above the executable's own (PREFIX for PREFIX/bin/kmorphd)
 * into out; 0, or -1 when it cannot be read or does not fit. */
static int install_prefix(char *out, size_t n) {
  ssize_t len = readlink("/proc/self/exe", out, n - 1);
  if (len <= 0 || (size_t)len >= n - 1) return -1;
  out[len] = '\0';
  for (int up = 0; up < 2; up++) {
    char *slash = strrchr(out, '/');
    if (slash == NULL) return -1;
    *slash = '\0';
  }
  return 0;
}

void srv_default_web_root(char *out, size_t n) {
  char prefix[512];
  char candidate[600];
  char index[640];
  if (install_prefix(prefix, sizeof prefix) == 0 &&
      (size_t)snprintf(candidate, sizeof candidate, "%s/%s", prefix,
                       INSTALLED_WEB_ROOT) < sizeof candidate &&
      strlen(candidate) < n &&
      (size_t)snprintf(index, sizeof index, "%s/index.html", candidate) <
          sizeof index &&
      access(index, R_OK) == 0) {
    snprintf(out, n, "%s", candidate);
    return;
  }
  snprintf(out, n, "%s", SOURCE_TREE_WEB_ROOT);
}
