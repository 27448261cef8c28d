/* pool.c - compute workers over a bounded FIFO of tasks (see pool.h). */
#include "pool.h"

#include <pthread.h>
#include <stdlib.h>
#include <time.h>

typedef struct task {
  srv_task_fn fn;
  void *arg;
} task;

struct srv_pool {
  pthread_mutex_t mu;
  pthread_cond_t cv;
  task *ring;
  size_t capacity;
  size_t head, count; /* submitted tasks in the ring */
  size_t reserved;    /* slots promised but not yet submitted */
  size_t busy;
  unsigned long kicks; /* bumped by srv_pool_kick: no lost wake-ups */
  bool stopping;
  srv_idle_fn idle;
  void *idle_ctx;
  double poll; /* seconds between asks of idle when not kicked; 0: never */
  pthread_t *threads;
  size_t nthreads;
};

static void *worker_main(void *arg) {
  srv_pool *p = arg;
  pthread_mutex_lock(&p->mu);
  for (;;) {
    if (p->count > 0) {
      task t = p->ring[p->head];
      p->head = (p->head + 1) % p->capacity;
      p->count--;
      p->busy++;
      bool cancelled = p->stopping;
      pthread_mutex_unlock(&p->mu);
      t.fn(t.arg, cancelled);
      pthread_mutex_lock(&p->mu);
      p->busy--;
      pthread_cond_broadcast(&p->cv); /* someone may wait for idleness */
      continue;
    }
    if (p->stopping && p->reserved == 0) break;
    if (!p->stopping && p->idle != NULL) {
      unsigned long seen = p->kicks;
      p->busy++;
      pthread_mutex_unlock(&p->mu);
      bool did = p->idle(p->idle_ctx);
      pthread_mutex_lock(&p->mu);
      p->busy--;
      if (did || p->kicks != seen || p->count > 0) continue;
    }
    if (p->poll > 0 && !p->stopping) {
      struct timespec ts;
      clock_gettime(CLOCK_REALTIME, &ts);
      long ns = ts.tv_nsec + (long)(p->poll * 1e9);
      ts.tv_sec += ns / 1000000000L;
      ts.tv_nsec = ns % 1000000000L;
      pthread_cond_timedwait(&p->cv, &p->mu, &ts);
    } else {
      pthread_cond_wait(&p->cv, &p->mu);
    }
  }
  pthread_mutex_unlock(&p->mu);
  return NULL;
}

srv_pool *srv_pool_create(size_t workers, size_t capacity, srv_idle_fn idle,
                          void *idle_ctx) {
  if (workers == 0 || capacity == 0) return NULL;
  srv_pool *p = calloc(1, sizeof *p);
  if (p == NULL) return NULL;
  p->ring = calloc(capacity, sizeof *p->ring);
  p->threads = calloc(workers, sizeof *p->threads);
  if (p->ring == NULL || p->threads == NULL) goto fail;
  p->capacity = capacity;
  p->idle = idle;
  p->idle_ctx = idle_ctx;
  pthread_mutex_init(&p->mu, NULL);
  pthread_cond_init(&p->cv, NULL);
  for (size_t i = 0; i < workers; i++) {
    if (pthread_create(&p->threads[i], NULL, worker_main, p) != 0) break;
    p->nthreads++;
  }
  if (p->nthreads == workers) return p;
  srv_pool_destroy(p);
  return NULL;
fail:
  free(p->ring);
  free(p->threads);
  free(p);
  return NULL;
}

bool srv_pool_reserve(srv_pool *p) {
  bool ok;
  pthread_mutex_lock(&p->mu);
  ok = !p->stopping && p->count + p->reserved < p->capacity;
  if (ok) p->reserved++;
  pthread_mutex_unlock(&p->mu);
  return ok;
}

void srv_pool_unreserve(srv_pool *p) {
  pthread_mutex_lock(&p->mu);
  p->reserved--;
  pthread_cond_broadcast(&p->cv);
  pthread_mutex_unlock(&p->mu);
}

void srv_pool_submit(srv_pool *p, srv_task_fn fn, void *arg) {
  pthread_mutex_lock(&p->mu);
  p->reserved--;
  p->ring[(p->head + p->count) % p->capacity] = (task){fn, arg};
  p->count++;
  pthread_cond_broadcast(&p->cv);
  pthread_mutex_unlock(&p->mu);
}

bool srv_pool_run_queued(srv_pool *p) {
  pthread_mutex_lock(&p->mu);
  if (p->count == 0) {
    pthread_mutex_unlock(&p->mu);
    return false;
  }
  /* The calling worker is already counted busy (it runs the source). */
  task t = p->ring[p->head];
  p->head = (p->head + 1) % p->capacity;
  p->count--;
  bool cancelled = p->stopping;
  pthread_mutex_unlock(&p->mu);
  t.fn(t.arg, cancelled);
  pthread_mutex_lock(&p->mu);
  pthread_cond_broadcast(&p->cv);
  pthread_mutex_unlock(&p->mu);
  return true;
}

void srv_pool_set_poll(srv_pool *p, double seconds) {
  pthread_mutex_lock(&p->mu);
  p->poll = seconds;
  pthread_cond_broadcast(&p->cv);
  pthread_mutex_unlock(&p->mu);
}

void srv_pool_kick(srv_pool *p) {
  pthread_mutex_lock(&p->mu);
  p->kicks++;
  pthread_cond_broadcast(&p->cv);
  pthread_mutex_unlock(&p->mu);
}

size_t srv_pool_depth(srv_pool *p) {
  pthread_mutex_lock(&p->mu);
  size_t n = p->count + p->reserved;
  pthread_mutex_unlock(&p->mu);
  return n;
}

size_t srv_pool_busy(srv_pool *p) {
  pthread_mutex_lock(&p->mu);
  size_t n = p->busy;
  pthread_mutex_unlock(&p->mu);
  return n;
}

size_t srv_pool_workers(const srv_pool *p) {
  return p->nthreads;
}
size_t srv_pool_capacity(const srv_pool *p) {
  return p->capacity;
}

void srv_pool_stop(srv_pool *p) {
  pthread_mutex_lock(&p->mu);
  p->stopping = true;
  pthread_cond_broadcast(&p->cv);
  pthread_mutex_unlock(&p->mu);
}

void srv_pool_destroy(srv_pool *p) {
  if (p == NULL) return;
  srv_pool_stop(p);
  for (size_t i = 0; i < p->nthreads; i++) pthread_join(p->threads[i], NULL);
  pthread_mutex_destroy(&p->mu);
  pthread_cond_destroy(&p->cv);
  free(p->ring);
  free(p->threads);
  free(p);
}
