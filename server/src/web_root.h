/* web_root.h - where the daemon finds its web page when not told. */
#ifndef SRV_WEB_ROOT_H
#define SRV_WEB_ROOT_H

#include <stddef.h>

/* srv_default_web_root - the folder of the web page to serve when neither
 * --web-root nor KMORPH_WEB_ROOT names one, written to out (n bytes, NUL
 * terminated, truncated paths never chosen): share/kmorph/web beside the
 * bin or sbin folder of the running executable when it holds index.html
 * (an installed daemon, under any PREFIX and DESTDIR), else clients/web
 * relative to the working directory (the source tree). */
void srv_default_web_root(char *out, size_t n);

#endif
