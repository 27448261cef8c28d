/* redis_conn.h - connections to the Redis server that holds shared jobs
 * (kmorphd --jobs redis://HOST:PORT/DB).
 *
 * DESIGN: a hiredis context is not thread-safe, so each caller borrows
 * one from a mutex-guarded pool for the span of its commands and gives it
 * back, marked broken if a command failed (it is then freed, not
 * reused). Every context has a connect timeout and a command timeout, so
 * no thread waits on Redis for longer than those. When Redis cannot be
 * reached, new connections are tried again with an exponential backoff
 * (0.1 s doubling to 2 s) and srv_redis_acquire returns NULL at once in
 * between: callers answer 503 rather than queue up behind a dead server.
 *
 * Thread-safety: every function may be called from any thread.
 */
#ifndef SRV_REDIS_CONN_H
#define SRV_REDIS_CONN_H

#include <hiredis/hiredis.h>
#include <stdbool.h>
#include <stddef.h>

typedef struct srv_redis srv_redis;

/* Parse url ("redis://HOST[:PORT][/DB]", PORT 6379 and DB 0 by default)
 * and make an empty pool; nothing is connected yet. NULL with the reason
 * in err (errlen bytes) if the URL is malformed or memory is short. */
srv_redis *srv_redis_create(const char *url, char *err, size_t errlen);

/* Borrow a connected context (connecting one if none is idle), or NULL
 * while Redis is unreachable (within the backoff, or the attempt now
 * failed). Give it back with srv_redis_release. */
redisContext *srv_redis_acquire(srv_redis *r);

/* Give c back; broken (a command on it failed or its reply was not
 * understood) frees it and marks Redis down until a new connection
 * succeeds. c may be NULL. */
void srv_redis_release(srv_redis *r, redisContext *c, bool broken);

/* True if the last connection attempt or command succeeded. */
bool srv_redis_up(const srv_redis *r);

/* PING on a borrowed context: true if Redis answered (for /readyz). */
bool srv_redis_ping(srv_redis *r);

/* "HOST:PORT/DB" for logs (static storage of r). */
const char *srv_redis_name(const srv_redis *r);

/* Free idle contexts and the pool; borrowed ones must be back. Accepts
 * NULL. */
void srv_redis_destroy(srv_redis *r);

#endif
