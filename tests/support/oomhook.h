/* oomhook.h - the allocation hook of the out-of-memory tests: it defines
 * km/alloc.h's four functions (so the test binary must link the hooked
 * libraries, KM_ALLOC_HOOKED), counts every allocation and the blocks
 * still held, and fails the allocations it is told to; and the loop after
 * SQLite's fault simulation that runs a call with its 1st, 2nd, ... Nth
 * allocation failing until a run fails none. Include it in one file of a
 * binary only (it defines external functions). Single-threaded.
 */
#ifndef KM_TEST_OOMHOOK_H
#define KM_TEST_OOMHOOK_H

#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>

#include "km/alloc.h"

#if !defined(KM_ALLOC_HOOKED)
#error "oomhook.h replaces the hook of a KM_ALLOC_HOOKED build only"
#endif

typedef struct oom_state {
  long count;   /* allocations asked for since oom_arm */
  long fail_at; /* the ordinal that fails; 0: none */
  bool persist; /* and every one after it */
  long failed;  /* allocations failed since oom_arm */
  long live;    /* blocks handed out and not yet freed, ever */
} oom_state;

static oom_state oom;

static void oom_arm(long fail_at, bool persist) {
  oom.count = 0;
  oom.failed = 0;
  oom.fail_at = fail_at;
  oom.persist = persist;
}

static void oom_disarm(void) {
  oom.fail_at = 0;
}

/* Whether the allocation being asked for is to fail. */
static bool oom_fails_now(void) {
  long k = ++oom.count;
  bool fail =
      oom.fail_at > 0 && (k == oom.fail_at || (oom.persist && k > oom.fail_at));
  if (fail) oom.failed++;
  return fail;
}

void *km__malloc(size_t n) {
  void *p = oom_fails_now() ? NULL : malloc(n);
  if (p != NULL) oom.live++;
  return p;
}

void *km__calloc(size_t count, size_t size) {
  void *p = oom_fails_now() ? NULL : calloc(count, size);
  if (p != NULL) oom.live++;
  return p;
}

void *km__realloc(void *p, size_t n) {
  void *q;
  if (oom_fails_now()) return NULL;
  q = realloc(p, n);
  if (q != NULL && p == NULL) oom.live++;
  return q;
}

void km__free(void *p) {
  if (p != NULL) oom.live--;
  free(p);
}

/* What one run of a call under test ended with. */
typedef enum oom_outcome {
  OOM_RAN_OK,    /* the call succeeded */
  OOM_RAN_NOMEM, /* it reported out of memory, as it must */
  OOM_RAN_OTHER  /* anything else: a bug when an allocation failed */
} oom_outcome;

/* One run of a call: make it, check what it gave, free all it returned.
 * why (out, 160 bytes) says what went wrong for OOM_RAN_OTHER. */
typedef oom_outcome (*oom_run)(void *ctx, char *why);

/* How a loop went: allocations of a run that failed none (so N + 1 is
 * where the call first succeeded), runs that ended in out-of-memory. */
typedef struct oom_report {
  long allocations;
  long nomem_runs;
} oom_report;

/* Run run(ctx) with allocation 1, 2, ... failing (and every later one
 * too when persist) until a run fails none; every run that had a failure
 * must end in OOM_RAN_NOMEM and every run must give back all it took.
 * Fails the test otherwise, naming the allocation. max bounds the runs. */
static oom_report oom_loop(const char *name, oom_run run, void *ctx,
                           bool persist, long max) {
  oom_report rep = {0, 0};
  char why[160];
  for (long n = 1; n <= max; n++) {
    long live = oom.live;
    oom_outcome got;
    why[0] = '\0';
    oom_arm(n, persist);
    got = run(ctx, why);
    oom_disarm();
    if (oom.live != live) {
      print_error("%s: allocation %ld failing leaks %ld block(s)\n", name, n,
                  oom.live - live);
      fail();
    }
    if (oom.failed == 0) {
      if (got != OOM_RAN_OK) {
        print_error("%s: fails without a failed allocation: %s\n", name, why);
        fail();
      }
      rep.allocations = oom.count;
      printf("%s: %ld allocations, each failed in turn%s\n", name,
             rep.allocations, persist ? " (and all after it)" : "");
      return rep;
    }
    if (got != OOM_RAN_NOMEM) {
      print_error("%s: allocation %ld of %ld failing gives %s: %s\n", name, n,
                  oom.count, got == OOM_RAN_OK ? "success" : "another failure",
                  why);
      fail();
    }
    rep.nomem_runs++;
  }
  print_error("%s: still failing allocations after %ld runs\n", name, max);
  fail();
  return rep;
}

#endif
