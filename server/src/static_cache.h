/* static_cache.h - the files kmorphd serves unchanged (the web page, the
 * contract) held with their entity tag and gzip form, made once.
 *
 * DESIGN: an entry is keyed by name and checked against the file's
 * size, mtime and inode on every request (one stat), so a redeployed
 * page is seen at once without a restart. Entries are reference-counted:
 * an answer being sent holds its entry, so replacing it (the file
 * changed) frees nothing under a slow reader. The cache holds at most
 * SRV_STATIC_ENTRIES entries and SRV_STATIC_BYTES bytes (body plus gzip
 * form); a file beyond that is served from disk each time, still with
 * its entity tag.
 *
 * Thread-safety: every function may run on any thread at once.
 */
#ifndef SRV_STATIC_CACHE_H
#define SRV_STATIC_CACHE_H

#include <stddef.h>

#define SRV_STATIC_ENTRIES 64
#define SRV_STATIC_BYTES ((size_t)64 << 20)

typedef struct srv_static_cache srv_static_cache;

/* One file's bytes, its strong entity tag and, if worth it, its gzip form
 * (gz NULL otherwise) with that form's tag. Immutable. */
typedef struct srv_static {
  const char *type; /* media type (static text) */
  const char *body; /* len bytes */
  size_t len;
  const char *gz; /* gz_len bytes, or NULL */
  size_t gz_len;
  char etag[24];    /* "\"<16 hex>\"" */
  char gz_etag[28]; /* "\"<16 hex>-gz\"" */
} srv_static;

/* An empty cache, or NULL if memory is short. */
srv_static_cache *srv_static_cache_create(void);
void srv_static_cache_destroy(srv_static_cache *c);

/* The file at path, served as type: from the cache if unchanged, else
 * read (at most max bytes), compressed and kept if it fits. NULL if it
 * cannot be read (missing, too large, memory short). The caller drops
 * the reference with srv_static_unref. */
const srv_static *srv_static_get(srv_static_cache *c, const char *path,
                                 const char *type, size_t max);

/* An entry made once for bytes that never change (the contract): data is
 * borrowed for the cache's life. NULL if memory is short. Same reference
 * rule. */
const srv_static *srv_static_get_const(srv_static_cache *c, const char *key,
                                       const char *type, const char *data,
                                       size_t len);

/* Drop a reference (the last frees an entry no longer cached). Accepts
 * NULL. Its signature fits libmicrohttpd's free callbacks. */
void srv_static_unref(void *entry);

#endif
