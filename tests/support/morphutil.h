/* morphutil.h - running a morph in the morph tests: create or fail the
 * test, frames with their metrics and signature, integers in error
 * messages (static functions, like testutil.h, which must be included
 * first). */
#ifndef KM_TEST_MORPHUTIL_H
#define KM_TEST_MORPHUTIL_H

#include <stdlib.h>
#include <string.h>

#include "km/morph.h"

static km_morph *morph_new(const km_morph_input *a, const km_morph_input *b,
                           const km_morph_options *o) {
  km_morph *m = NULL;
  km_error err;
  km_status st = km_morph_create(&m, a, b, o, &err);
  if (st != KM_OK) print_error("km_morph_create: %s\n", err.message);
  assert_status(st, KM_OK);
  assert_non_null(m);
  return m;
}

typedef struct frame {
  km_curve c;
  km_frame_metrics mt;
  km_signature sig;
} frame;

static void frame_get(const km_morph *m, double t, frame *f) {
  km_error err;
  km_curve_init(&f->c);
  km_signature_init(&f->sig);
  memset(&f->mt, 0, sizeof f->mt);
  km_status st = km_morph_frame(m, t, &f->c, &f->mt, &f->sig, &err);
  if (st != KM_OK) print_error("km_morph_frame(t = %g): %s\n", t, err.message);
  assert_status(st, KM_OK);
}

static void frame_free(frame *f) {
  km_curve_free(&f->c);
  km_signature_free(&f->sig);
}

/* whether an integer stands in a message as a whole number (e.g. the
 * turning numbers in "from turns 1 times, to 2") */
static inline int message_has_integer(const char *msg, long want) {
  const char *p = msg;
  while (*p) {
    if ((*p >= '0' && *p <= '9') || (*p == '-' && p[1] >= '0' && p[1] <= '9')) {
      char *end;
      long v = strtol(p, &end, 10);
      if (v == want && *end != '.') return 1;
      p = end;
    } else {
      p++;
    }
  }
  return 0;
}

#endif
