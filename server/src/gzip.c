/* gzip.c - gzip content coding with zlib (see gzip.h). */
#include "gzip.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <zlib.h>

/* zlib's windowBits for a gzip wrapper (15 + 16) and its memLevel. */
enum { GZ_WBITS = 31, GZ_MEMLEVEL = 8, GZ_LEVEL = 6 };

/* Input handed to deflate per step: bounds the work of one reader call. */
#define GZ_SLICE ((size_t)64 << 10)

bool srv_gzip_worth(const char *ctype, size_t len) {
  if (ctype == NULL || len < SRV_GZIP_MIN) return false;
  size_t n = strcspn(ctype, ";");
  while (n > 0 && ctype[n - 1] == ' ') n--;
  if (n >= 5 && strncasecmp(ctype, "text/", 5) == 0) return true;
  if (n >= 5 && strncasecmp(ctype + n - 5, "+json", 5) == 0) return true;
  if (n >= 4 && strncasecmp(ctype + n - 4, "+xml", 4) == 0) return true;
  static const char *const T[] = {"application/json", "application/javascript",
                                  "image/x-icon"};
  for (size_t i = 0; i < sizeof T / sizeof T[0]; i++)
    if (n == strlen(T[i]) && strncasecmp(ctype, T[i], n) == 0) return true;
  return false;
}

char *srv_gzip_buffer(const void *data, size_t len, size_t *out_len) {
  z_stream z;
  memset(&z, 0, sizeof z);
  if (len > ((size_t)1 << 30)) return NULL; /* uInt counts; files are small */
  if (deflateInit2(&z, GZ_LEVEL, Z_DEFLATED, GZ_WBITS, GZ_MEMLEVEL,
                   Z_DEFAULT_STRATEGY) != Z_OK)
    return NULL;
  size_t cap = deflateBound(&z, (uLong)len);
  char *out = malloc(cap);
  int rc = Z_STREAM_ERROR;
  if (out != NULL) {
    z.next_in = (Bytef *)(uintptr_t)data;
    z.avail_in = (uInt)len;
    z.next_out = (Bytef *)out;
    z.avail_out = (uInt)cap;
    rc = deflate(&z, Z_FINISH);
  }
  size_t n = z.total_out;
  deflateEnd(&z);
  if (rc != Z_STREAM_END || n >= len) {
    free(out);
    return NULL;
  }
  *out_len = n;
  return out;
}

typedef struct gz_stream {
  z_stream z;
  const char *data;
  size_t len, fed; /* bytes of data handed to deflate so far */
  bool done;       /* Z_STREAM_END seen */
  void (*release)(void *);
  void *cls;
  atomic_size_t *streams;
} gz_stream;

static ssize_t gz_read(void *cls, uint64_t pos, char *buf, size_t max) {
  gz_stream *g = cls;
  (void)pos;
  if (g->done) return MHD_CONTENT_READER_END_OF_STREAM;
  g->z.next_out = (Bytef *)buf;
  g->z.avail_out = (uInt)max;
  /* Deflate until some output is ready: a reader returning 0 would be
   * asked again at once. */
  while (g->z.avail_out == max && !g->done) {
    if (g->z.avail_in == 0 && g->fed < g->len) {
      size_t n = g->len - g->fed < GZ_SLICE ? g->len - g->fed : GZ_SLICE;
      g->z.next_in = (Bytef *)(uintptr_t)(g->data + g->fed);
      g->z.avail_in = (uInt)n;
      g->fed += n;
    }
    int flush = g->fed == g->len ? Z_FINISH : Z_NO_FLUSH;
    int rc = deflate(&g->z, flush);
    if (rc == Z_STREAM_END)
      g->done = true;
    else if (rc != Z_OK && rc != Z_BUF_ERROR)
      return MHD_CONTENT_READER_END_WITH_ERROR;
  }
  size_t out = max - g->z.avail_out;
  if (out == 0) return MHD_CONTENT_READER_END_OF_STREAM;
  return (ssize_t)out;
}

static void gz_free(void *cls) {
  gz_stream *g = cls;
  deflateEnd(&g->z);
  if (g->release != NULL) g->release(g->cls);
  atomic_fetch_sub(g->streams, 1);
  free(g);
}

struct MHD_Response *srv_gzip_stream(const char *data, size_t len,
                                     void (*release)(void *), void *cls,
                                     atomic_size_t *streams) {
  if (atomic_fetch_add(streams, 1) >= SRV_GZIP_STREAMS) {
    atomic_fetch_sub(streams, 1);
    return NULL;
  }
  gz_stream *g = calloc(1, sizeof *g);
  if (g == NULL || deflateInit2(&g->z, GZ_LEVEL, Z_DEFLATED, GZ_WBITS,
                                GZ_MEMLEVEL, Z_DEFAULT_STRATEGY) != Z_OK) {
    free(g);
    atomic_fetch_sub(streams, 1);
    return NULL;
  }
  g->data = data;
  g->len = len;
  g->release = release;
  g->cls = cls;
  g->streams = streams;
  struct MHD_Response *resp = MHD_create_response_from_callback(
      MHD_SIZE_UNKNOWN, 32 * 1024, gz_read, g, gz_free);
  if (resp == NULL) {
    g->release = NULL; /* the caller keeps data and sends it plain */
    gz_free(g);
    return NULL;
  }
  MHD_add_response_header(resp, MHD_HTTP_HEADER_CONTENT_ENCODING, "gzip");
  return resp;
}
