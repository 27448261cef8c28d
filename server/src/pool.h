/* pool.h - fixed pool of compute workers over a bounded queue.
 *
 * DESIGN: request handlers never block on compute. An I/O thread first
 * reserves a queue slot (srv_pool_reserve; refused at once when the queue
 * is full, which the caller turns into 503 + Retry-After), then suspends
 * its connection and submits the task into the slot. Workers run queued
 * tasks first; when the queue is empty they ask the background source
 * (frames of asynchronous jobs) for one unit of work, so frames of one job
 * spread over all workers while interactive requests keep priority.
 */
#ifndef SRV_POOL_H
#define SRV_POOL_H

#include <stdbool.h>
#include <stddef.h>

typedef struct srv_pool srv_pool;

/* A queued task. cancelled is true when the pool is stopping and the task
 * must only answer (e.g. 503) and release its resources, not compute. */
typedef void (*srv_task_fn)(void *arg, bool cancelled);

/* Background work: do one unit and return true, or return false when there
 * is none. Called by workers with no lock held; must be thread-safe. */
typedef bool (*srv_idle_fn)(void *ctx);

/* Start `workers` threads (>= 1) over a queue of `capacity` (>= 1) slots.
 * idle may be NULL. Returns NULL if memory or threads are short. */
srv_pool *srv_pool_create(size_t workers, size_t capacity, srv_idle_fn idle,
                          void *idle_ctx);

/* Reserve one queue slot. False when the queue is full or the pool is
 * stopping: the caller answers "overloaded" without suspending anything.
 * A reservation must be followed by exactly one srv_pool_submit or
 * srv_pool_unreserve. */
bool srv_pool_reserve(srv_pool *p);
void srv_pool_unreserve(srv_pool *p);

/* Put a task into a reserved slot; never fails. */
void srv_pool_submit(srv_pool *p, srv_task_fn fn, void *arg);

/* Make idle workers ask the background source again every `seconds`
 * even without a kick (a source fed from outside the process, such as a
 * shared job stream); 0, the default, waits for a kick. */
void srv_pool_set_poll(srv_pool *p, double seconds);

/* From inside the background source (on a worker): run one queued task
 * now, if there is one, so that a unit of background work longer than a
 * frame (a batch of a shared job) does not hold interactive requests
 * back. True if a task ran. */
bool srv_pool_run_queued(srv_pool *p);

/* Tell idle workers that background work may have appeared. */
void srv_pool_kick(srv_pool *p);

/* Gauges for /metrics: tasks waiting (reserved slots included), workers
 * running a task or a background unit, total workers, capacity. */
size_t srv_pool_depth(srv_pool *p);
size_t srv_pool_busy(srv_pool *p);
size_t srv_pool_workers(const srv_pool *p);
size_t srv_pool_capacity(const srv_pool *p);

/* Stop admitting work; tasks still queued run with cancelled = true; the
 * background source is no longer polled. Does not wait. */
void srv_pool_stop(srv_pool *p);

/* Stop (if not yet), wait for every worker to finish and free the pool.
 * Accepts NULL. */
void srv_pool_destroy(srv_pool *p);

#endif
