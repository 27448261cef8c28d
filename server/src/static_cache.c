/* static_cache.c - files served unchanged, with entity tags and gzip forms
 * made once (see static_cache.h).
 */
#include "static_cache.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "conneg.h"
#include "gzip.h"

typedef struct entry {
  srv_static pub; /* first: a srv_static * is an entry * */
  char key[600];
  dev_t dev;
  ino_t ino;
  off_t size;
  struct timespec mtime;
  bool owns_body; /* body is malloc'd (else borrowed for the cache's life) */
  size_t bytes;   /* body + gzip form held, if the body is owned */
  atomic_size_t refs;
} entry;

struct srv_static_cache {
  pthread_mutex_t mu;
  entry *e[SRV_STATIC_ENTRIES];
  size_t n;
  size_t bytes;
};

srv_static_cache *srv_static_cache_create(void) {
  srv_static_cache *c = calloc(1, sizeof *c);
  if (c != NULL) pthread_mutex_init(&c->mu, NULL);
  return c;
}

void srv_static_unref(void *p) {
  entry *e = p;
  if (e == NULL || atomic_fetch_sub(&e->refs, 1) != 1) return;
  if (e->owns_body) free((char *)e->pub.body);
  free((char *)e->pub.gz);
  free(e);
}

void srv_static_cache_destroy(srv_static_cache *c) {
  if (c == NULL) return;
  for (size_t i = 0; i < c->n; i++) srv_static_unref(c->e[i]);
  pthread_mutex_destroy(&c->mu);
  free(c);
}

/* A new entry over body (taken if owned), with refs 1, or NULL. */
static entry *make_entry(const char *key, const char *type, const char *body,
                         size_t len, bool owned) {
  entry *e = calloc(1, sizeof *e);
  if (e == NULL) {
    if (owned) free((char *)body);
    return NULL;
  }
  snprintf(e->key, sizeof e->key, "%s", key);
  e->pub.type = type;
  e->pub.body = body;
  e->pub.len = len;
  e->owns_body = owned;
  srv_etag_of(e->pub.etag, sizeof e->pub.etag, body, len, "");
  if (srv_gzip_worth(type, len)) {
    size_t gl = 0;
    char *gz = srv_gzip_buffer(body, len, &gl);
    if (gz != NULL) {
      e->pub.gz = gz;
      e->pub.gz_len = gl;
      srv_etag_of(e->pub.gz_etag, sizeof e->pub.gz_etag, body, len, "-gz");
    }
  }
  e->bytes = (owned ? len : 0) + e->pub.gz_len;
  atomic_init(&e->refs, 1);
  return e;
}

static bool same_file(const entry *e, const struct stat *st) {
  return e->dev == st->st_dev && e->ino == st->st_ino &&
         e->size == st->st_size && e->mtime.tv_sec == st->st_mtim.tv_sec &&
         e->mtime.tv_nsec == st->st_mtim.tv_nsec;
}

static size_t find(const srv_static_cache *c, const char *key) {
  for (size_t i = 0; i < c->n; i++)
    if (strcmp(c->e[i]->key, key) == 0) return i;
  return SIZE_MAX;
}

/* Keep e in the cache (replacing the entry of the same key) if it fits;
 * the cache's reference is a second one. Called with c->mu held. */
static void keep(srv_static_cache *c, entry *e) {
  size_t i = find(c, e->key);
  if (i != SIZE_MAX) {
    entry *old = c->e[i];
    c->bytes -= old->bytes;
    c->e[i] = c->e[--c->n];
    srv_static_unref(old);
  }
  if (c->n == SRV_STATIC_ENTRIES || c->bytes + e->bytes > SRV_STATIC_BYTES)
    return;
  atomic_fetch_add(&e->refs, 1);
  c->e[c->n++] = e;
  c->bytes += e->bytes;
}

static char *read_all(const char *path, size_t max, size_t *len) {
  FILE *f = fopen(path, "rb");
  if (f == NULL) return NULL;
  char *buf = malloc(max + 1);
  size_t n = buf ? fread(buf, 1, max + 1, f) : 0;
  fclose(f);
  if (buf == NULL || n > max) {
    free(buf);
    return NULL;
  }
  *len = n;
  return buf;
}

const srv_static *srv_static_get(srv_static_cache *c, const char *path,
                                 const char *type, size_t max) {
  struct stat st;
  if (stat(path, &st) != 0 || !S_ISREG(st.st_mode) ||
      (unsigned long long)st.st_size > max)
    return NULL;
  pthread_mutex_lock(&c->mu);
  size_t i = find(c, path);
  if (i != SIZE_MAX && same_file(c->e[i], &st)) {
    entry *e = c->e[i];
    atomic_fetch_add(&e->refs, 1);
    pthread_mutex_unlock(&c->mu);
    return &e->pub;
  }
  pthread_mutex_unlock(&c->mu);
  /* Read and compress outside the lock: another thread may do the same
   * for the same file at once; the last one kept wins, both are right. */
  size_t len = 0;
  char *body = read_all(path, max, &len);
  if (body == NULL) return NULL;
  entry *e = make_entry(path, type, body, len, true);
  if (e == NULL) return NULL;
  e->dev = st.st_dev;
  e->ino = st.st_ino;
  e->size = st.st_size;
  e->mtime = st.st_mtim;
  if ((off_t)len == st.st_size) { /* not changed while read */
    pthread_mutex_lock(&c->mu);
    keep(c, e);
    pthread_mutex_unlock(&c->mu);
  }
  return &e->pub;
}

const srv_static *srv_static_get_const(srv_static_cache *c, const char *key,
                                       const char *type, const char *data,
                                       size_t len) {
  pthread_mutex_lock(&c->mu);
  size_t i = find(c, key);
  entry *e = i != SIZE_MAX ? c->e[i] : NULL;
  if (e != NULL) {
    atomic_fetch_add(&e->refs, 1);
  } else if ((e = make_entry(key, type, data, len, false)) != NULL) {
    keep(c, e); /* the new entry's own reference goes to the caller */
  }
  pthread_mutex_unlock(&c->mu);
  return e ? &e->pub : NULL;
}
