/* morph_frames.c - a prepared morph's frames one at a time as JSON text,
 * and its answer assembled from such texts: for daemons that share the
 * frames of one job between processes.
 *
 * DESIGN: both functions run the very code of api_morph_result on a view
 * of the plan (the same struct with another frame range), so a frame's
 * text is byte for byte what the whole answer holds for it: the answer
 * assembled from texts equals the one api_morph_result writes. Answers
 * that need every frame's geometry at once (SVG, "animate_d", crossing
 * avoidance) are not assembled from texts: api_morph_frames_apart says
 * which.
 */
#include <string.h>

#include "json_write.h"
#include "km/alloc.h"
#include "kmapi/api.h"
#include "morph_plan.h"

bool api_morph_frames_apart(const api_morph_plan *plan) {
  return plan != NULL && !plan->svg && !plan->inc.animate_d &&
         plan->opt.intersections != KM_INTERSECTIONS_AVOID;
}

/* The answer of plan restricted to frames [first, first + n): a view
 * shares the plan's slots, so nothing is copied or rendered again. */
static api_status answer_of_range(const api_morph_plan *plan, size_t first,
                                  size_t n, api_response *out) {
  api_morph_plan view = *plan;
  view.frames = plan->frames + first;
  view.nframes = n;
  return api_morph_result(&view, out);
}

/* Where the frames array of a JSON answer starts (just after its '[')
 * and where it ends (its ']'); false if the text is not such an answer. */
static bool frames_span(const char *text, size_t len, size_t *open,
                        size_t *close) {
  static const char key[] = "\"frames\":[";
  const char *a = strstr(text, key);
  if (a == NULL) return false;
  *open = (size_t)(a - text) + sizeof key - 1;
  /* The members after the frames are number arrays and objects of
   * numbers: the last "]," followed by a member name ends the frames. */
  static const char *const next[] = {"],\"contour_matches_used\":",
                                     "],\"matches_used\":"};
  for (size_t k = 0; k < 2; k++) {
    size_t m = strlen(next[k]);
    for (size_t i = len >= m ? len - m + 1 : 0; i-- > *open;)
      if (memcmp(text + i, next[k], m) == 0) {
        *close = i;
        return true;
      }
  }
  return false;
}

api_status api_morph_frame_text(api_morph_plan *plan, size_t i,
                                api_response *out) {
  api_response_init(out);
  if (plan == NULL || i >= plan->nframes || !api_morph_frames_apart(plan))
    return 404;
  api_status st = api_morph_render_frame(plan, i);
  if (st != API_STEP_DONE) return st;
  if (plan->frames[i].state != API_FRAME_DONE) return 422;
  api_response whole;
  st = answer_of_range(plan, i, 1, &whole);
  if (st != 200) {
    *out = whole;
    return st;
  }
  size_t open, close;
  if (!frames_span(whole.body, whole.length, &open, &close)) {
    api_response_free(&whole);
    return 500;
  }
  memmove(whole.body, whole.body + open, close - open);
  whole.length = close - open;
  whole.body[whole.length] = '\0';
  *out = whole;
  return 200;
}

api_status api_morph_result_from_texts(api_morph_plan *plan,
                                       const char *const *texts,
                                       const size_t *lengths,
                                       api_response *out) {
  api_response_init(out);
  if (plan == NULL || !api_morph_frames_apart(plan)) return 404;
  api_response frame;
  api_status st = answer_of_range(plan, 0, 0, &frame);
  if (st != 200) {
    *out = frame;
    return st;
  }
  size_t open, close;
  if (!frames_span(frame.body, frame.length, &open, &close)) {
    api_response_free(&frame);
    return 500;
  }
  size_t total = frame.length + 1;
  for (size_t i = 0; i < plan->nframes; i++) total += lengths[i] + 1;
  char *body = km__malloc(total);
  if (body == NULL) {
    api_response_free(&frame);
    api_problem(out, 503, NULL, NULL, "out of memory", NULL, NULL, NULL);
    return 503;
  }
  size_t n = 0;
  memcpy(body, frame.body, open);
  n = open;
  for (size_t i = 0; i < plan->nframes; i++) {
    if (i > 0) body[n++] = ',';
    memcpy(body + n, texts[i], lengths[i]);
    n += lengths[i];
  }
  memcpy(body + n, frame.body + close, frame.length - close);
  n += frame.length - close;
  body[n] = '\0';
  out->status = 200;
  out->content_type = frame.content_type;
  out->body = body;
  out->length = n;
  api_response_free(&frame);
  return 200;
}
