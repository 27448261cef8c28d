/* frame_share.h - the frames of a synchronous morph shared with idle
 * compute workers.
 *
 * DESIGN: a synchronous POST /v1/morph belongs to the worker that took it,
 * which renders its frames one after another and answers. While other
 * workers have nothing to do, they help: the owner opens its morph here,
 * every idle worker's background call (the pool's idle source) takes one
 * frame of an open morph at a time, and the owner takes frames from the
 * same counter. Before assembling the answer the owner closes the morph,
 * which waits for frames still being rendered by helpers. Frames are
 * distinct, which the plan allows at once, and the answer is assembled
 * in frame order, so it is the same bytes however the frames were shared.
 *   Helpers poll only what is safe from another thread: the owner's halt
 * (set when the client left or the time ran out, as the owner sees it),
 * the shutdown's abort and the deadline. Interactive requests keep their
 * priority: a helper renders one frame a call and then the pool looks at
 * its queue again.
 */
#ifndef SRV_FRAME_SHARE_H
#define SRV_FRAME_SHARE_H

#include <pthread.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stddef.h>

#include "kmapi/api.h"

/* One morph's frames while they are rendered. */
typedef struct srv_shared_frames {
  api_morph_plan *plan;
  size_t count;
  double deadline;                /* srv_now() past it: helpers stop */
  const atomic_bool *abort;       /* the server's abort_compute */
  atomic_size_t next;             /* the next frame to take */
  atomic_size_t done;             /* frames rendered and not stopped */
  atomic_bool halt;               /* the owner stopped: take no more */
  size_t helpers;                 /* rendering now (under the registry lock) */
  struct srv_shared_frames *link; /* open morphs (under the registry lock) */
} srv_shared_frames;

typedef struct srv_frame_share {
  pthread_mutex_t mu;
  pthread_cond_t left; /* a helper finished a frame */
  srv_shared_frames *open;
} srv_frame_share;

/* Initialise / release the registry (no morph may be open). 0 or -1. */
int srv_frame_share_init(srv_frame_share *fs);
void srv_frame_share_destroy(srv_frame_share *fs);

/* Open plan's count frames for helpers (sf: the owner's, initialised
 * here, open until srv_frame_share_close). */
void srv_frame_share_open(srv_frame_share *fs, srv_shared_frames *sf,
                          api_morph_plan *plan, size_t count, double deadline,
                          const atomic_bool *abort);
/* The next frame for the owner to render, or count when none is left. */
size_t srv_frame_share_take(srv_shared_frames *sf);
/* Close sf to helpers and wait until none is rendering its frames. */
void srv_frame_share_close(srv_frame_share *fs, srv_shared_frames *sf);

/* The pool's idle source: render one frame of an open morph. False when
 * no open morph has a frame left. */
bool srv_frame_share_help(srv_frame_share *fs);

#endif
