/* stop.h - a caller's request that a long computation end early.
 *
 * The core has no clock and no threads, so it cannot know about deadlines
 * or disconnected clients; instead its long loops ask the caller. Every
 * entry point whose work grows with its input (a signature, a
 * reconstruction, preparing a morph, a frame, counting self-crossings)
 * has a form taking a `const km_stop *`: NULL, or a NULL `requested`,
 * never stops. The core polls `requested(ctx)` after bounded amounts of
 * work (KM_STOP_POLL_UNITS units of work, a unit being about one curve or
 * polynomial evaluation: some 0.02 to 0.1 ms at -O3 between polls); once
 * it answers true the entry point frees what it built and returns
 * KM_ECANCELLED, with nothing written to its out-parameters. After a true
 * answer it is not asked again within that call.
 *
 * Thread-safety: the core only calls `requested`, from the thread that
 * called the entry point; a callback that reads a flag another thread
 * sets must read it atomically (an atomic_bool, a relaxed load suffices).
 * The same km_stop may be shared by calls on many threads if its callback
 * is itself thread-safe.
 */
#ifndef KM_STOP_H
#define KM_STOP_H

#include <stdbool.h>

typedef struct km_stop {
  bool (*requested)(void *ctx); /* true: stop now; NULL: never */
  void *ctx;                    /* passed to requested, borrowed */
} km_stop;

/* Units of work between two polls (see above). */
#define KM_STOP_POLL_UNITS 2048

#endif
