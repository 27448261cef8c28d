/* frame_share.c - the frames of a synchronous morph shared with idle
 * compute workers (see frame_share.h).
 */
#include "frame_share.h"

#include "util.h"

int srv_frame_share_init(srv_frame_share *fs) {
  fs->open = NULL;
  if (pthread_mutex_init(&fs->mu, NULL) != 0) return -1;
  if (pthread_cond_init(&fs->left, NULL) != 0) {
    pthread_mutex_destroy(&fs->mu);
    return -1;
  }
  return 0;
}

void srv_frame_share_destroy(srv_frame_share *fs) {
  pthread_cond_destroy(&fs->left);
  pthread_mutex_destroy(&fs->mu);
}

void srv_frame_share_open(srv_frame_share *fs, srv_shared_frames *sf,
                          api_morph_plan *plan, size_t count, double deadline,
                          const atomic_bool *abort) {
  sf->plan = plan;
  sf->count = count;
  sf->deadline = deadline;
  sf->abort = abort;
  atomic_init(&sf->next, 0);
  atomic_init(&sf->done, 0);
  atomic_init(&sf->halt, false);
  sf->helpers = 0;
  pthread_mutex_lock(&fs->mu);
  sf->link = fs->open;
  fs->open = sf;
  pthread_mutex_unlock(&fs->mu);
}

size_t srv_frame_share_take(srv_shared_frames *sf) {
  size_t i = atomic_fetch_add(&sf->next, 1);
  return i < sf->count ? i : sf->count;
}

void srv_frame_share_close(srv_frame_share *fs, srv_shared_frames *sf) {
  pthread_mutex_lock(&fs->mu);
  for (srv_shared_frames **p = &fs->open; *p != NULL; p = &(*p)->link)
    if (*p == sf) {
      *p = sf->link;
      break;
    }
  while (sf->helpers > 0) pthread_cond_wait(&fs->left, &fs->mu);
  pthread_mutex_unlock(&fs->mu);
}

/* A helper's stop condition: only what another thread may read. */
static bool helper_should_stop(void *ctx) {
  srv_shared_frames *sf = ctx;
  return atomic_load(&sf->halt) || atomic_load(sf->abort) ||
         srv_now() > sf->deadline;
}

bool srv_frame_share_help(srv_frame_share *fs) {
  srv_shared_frames *sf = NULL;
  pthread_mutex_lock(&fs->mu);
  for (srv_shared_frames *o = fs->open; o != NULL; o = o->link)
    if (!atomic_load(&o->halt) && atomic_load(&o->next) < o->count) {
      sf = o;
      sf->helpers++;
      break;
    }
  pthread_mutex_unlock(&fs->mu);
  if (sf == NULL) return false;
  size_t i = srv_frame_share_take(sf);
  if (i < sf->count &&
      api_morph_render_frame_until(sf->plan, i, helper_should_stop, sf) != 503)
    atomic_fetch_add(&sf->done, 1);
  pthread_mutex_lock(&fs->mu);
  if (--sf->helpers == 0) pthread_cond_broadcast(&fs->left);
  pthread_mutex_unlock(&fs->mu);
  return true;
}
