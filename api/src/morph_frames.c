/* morph_frames.c - a prepared morph's frames one at a time as text, and
 * its answer assembled from such texts: for daemons that share the
 * frames of one job between processes.
 *
 * DESIGN: both functions run the very code of api_morph_result on a view
 * of the plan (the same struct with another frame range), so a frame's
 * text is byte for byte what the whole answer holds for it and the answer
 * assembled from texts equals the one api_morph_result writes. A frame's
 * text is private to this pair of functions: a line saying whether the
 * frame crosses (and why, as the answer's "intersections" would say),
 * then its object of "frames". The members that depend on every frame
 * ("crossing_frames", "reason") are written from those lines; answers
 * that need every frame's geometry at once (SVG, "animate_d") are not
 * assembled from texts: api_morph_frames_apart says which.
 */
#include <stdio.h>
#include <string.h>

#include "json_write.h"
#include "km/alloc.h"
#include "kmapi/api.h"
#include "morph_plan.h"

bool api_morph_frames_apart(const api_morph_plan *plan) {
  return plan != NULL && !plan->svg && !plan->inc.animate_d;
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

/* The "intersections" member's crossing list and reason in the answer's
 * tail: where "crossing_frames":[ ends (just after '[') and the reason's
 * value [*rs, *re); false when the answer has no such member. */
static bool crossings_span(const char *tail, const char **list, const char **rs,
                           const char **re) {
  static const char key[] = "\"intersections\":{\"crossing_frames\":[";
  const char *a = strstr(tail, key);
  if (a == NULL) return false;
  *list = a + sizeof key - 1;
  const char *r = strstr(*list, "],\"reason\":");
  const char *e = r ? strstr(r, ",\"changed\":") : NULL;
  if (r == NULL || e == NULL) return false;
  *rs = r + 11;
  *re = e;
  return true;
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
  /* The first line: "1" and the reason if the frame crosses, else "0". */
  const char *list, *rs, *re;
  bool crosses = false;
  size_t head = 2;
  if (crossings_span(whole.body + close, &list, &rs, &re) && *list != ']') {
    crosses = true;
    head = 2 + (size_t)(re - rs);
  }
  size_t len = head + (close - open);
  char *body = km__malloc(len + 1);
  if (body == NULL) {
    api_response_free(&whole);
    api_problem(out, 503, NULL, NULL, "out of memory", NULL, NULL, NULL);
    return 503;
  }
  body[0] = crosses ? '1' : '0';
  if (crosses) memcpy(body + 1, rs, (size_t)(re - rs));
  body[head - 1] = '\n';
  memcpy(body + head, whole.body + open, close - open);
  body[len] = '\0';
  out->status = 200;
  out->content_type = whole.content_type;
  out->body = body;
  out->length = len;
  api_response_free(&whole);
  return 200;
}

/* Append n bytes of s to buf at *at (room was counted). */
static void put(char *buf, size_t *at, const char *s, size_t n) {
  memcpy(buf + *at, s, n);
  *at += n;
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
  /* Room: the empty answer, the frames, their indexes, one reason. */
  size_t total = frame.length + 1;
  const char *reason = NULL;
  size_t reason_len = 0;
  for (size_t i = 0; i < plan->nframes; i++) {
    const char *nl = memchr(texts[i], '\n', lengths[i]);
    if (nl == NULL) {
      api_response_free(&frame);
      return 500;
    }
    total += lengths[i] + 24;
    if (texts[i][0] == '1' && reason == NULL) {
      reason = texts[i] + 1;
      reason_len = (size_t)(nl - reason);
      total += reason_len;
    }
  }
  char *body = km__malloc(total);
  if (body == NULL) {
    api_response_free(&frame);
    api_problem(out, 503, NULL, NULL, "out of memory", NULL, NULL, NULL);
    return 503;
  }
  size_t n = 0;
  put(body, &n, frame.body, open);
  for (size_t i = 0; i < plan->nframes; i++) {
    const char *nl = memchr(texts[i], '\n', lengths[i]);
    size_t skip = (size_t)(nl - texts[i]) + 1;
    if (i > 0) put(body, &n, ",", 1);
    put(body, &n, texts[i] + skip, lengths[i] - skip);
  }
  const char *tail = frame.body + close, *end = frame.body + frame.length;
  const char *list, *rs, *re;
  if (crossings_span(tail, &list, &rs, &re)) {
    put(body, &n, tail, (size_t)(list - tail));
    bool first = true;
    for (size_t i = 0; i < plan->nframes; i++)
      if (texts[i][0] == '1') {
        char num[24];
        int k = snprintf(num, sizeof num, first ? "%zu" : ",%zu", i);
        put(body, &n, num, (size_t)k);
        first = false;
      }
    put(body, &n, "],\"reason\":", 11);
    if (reason != NULL)
      put(body, &n, reason, reason_len);
    else
      put(body, &n, rs, (size_t)(re - rs));
    tail = re;
  }
  put(body, &n, tail, (size_t)(end - tail));
  body[n] = '\0';
  out->status = 200;
  out->content_type = frame.content_type;
  out->body = body;
  out->length = n;
  api_response_free(&frame);
  return 200;
}
