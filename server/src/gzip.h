/* gzip.h - gzip content coding for kmorphd's answers (zlib): compressed
 * once for bodies kept (static files, the contract), streamed for bodies
 * computed (results of morphs and jobs, which can be megabytes).
 *
 * DESIGN: a streamed answer deflates its body a socket-buffer at a time
 * as libmicrohttpd asks for bytes, so it costs one zlib state (about
 * 256 KiB: a 32 KiB window, memLevel 8) and nothing proportional to the
 * body; the number of such streams at once is bounded by the caller
 * (SRV_GZIP_STREAMS), beyond which answers go uncompressed. Nothing is
 * kept compressed beside a job's result, so --result-memory is unchanged.
 *
 * Thread-safety: every function may run on any thread; a stream belongs
 * to the response that owns it.
 */
#ifndef SRV_GZIP_H
#define SRV_GZIP_H

#include <microhttpd.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stddef.h>

/* Bodies shorter than this are sent as they are: the gzip header and the
 * CPU are not worth it. */
#define SRV_GZIP_MIN 1024

/* Compressed streams being sent at once, at most (about 256 KiB each). */
#define SRV_GZIP_STREAMS 32

/* True for a media type worth compressing (text, JSON, SVG, JavaScript)
 * at len bytes (>= SRV_GZIP_MIN). ctype may carry parameters. */
bool srv_gzip_worth(const char *ctype, size_t len);

/* data[0..len-1] gzip-compressed at once: malloc'd (caller frees), its
 * length in *out_len. NULL if memory is short or it would not be smaller. */
char *srv_gzip_buffer(const void *data, size_t len, size_t *out_len);

/* A response streaming data[0..len-1] gzip-compressed (chunked: its
 * length is not known in advance). data stays borrowed until the
 * response is destroyed, which then calls release(cls) (release may be
 * NULL). *streams counts the streams alive: NULL (and nothing counted,
 * release not called) when SRV_GZIP_STREAMS are already sending or
 * memory is short: the caller sends data as it is. */
struct MHD_Response *srv_gzip_stream(const char *data, size_t len,
                                     void (*release)(void *), void *cls,
                                     atomic_size_t *streams);

#endif
