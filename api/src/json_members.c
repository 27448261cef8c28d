/* json_members.c - the members a request object may have: any other is a
 * 422 naming it by its JSON pointer, with the nearest known name as a
 * suggestion.
 *
 * DESIGN: a typo in an optional member ("blending" for "blend") used to be
 * dropped silently, so the request ran with the default and the client
 * never learnt why its answer was not what it asked for. Every object of
 * a request is therefore checked against the one list of names its reader
 * takes, before any of its members is read, so the typo is the error
 * reported (the first error wins) rather than whatever its absence caused.
 * Suggestions use the edit distance with transpositions (optimal string
 * alignment), case folded, and are made only when the name is close: one
 * edit apart (names of two letters or more), at most a third of the longer
 * name's letters apart, or a prefix of three letters or more either way.
 */
#include <ctype.h>
#include <string.h>

#include "internal.h"

/* Names longer than this are never close to a member's name (the longest
 * is 24 letters) and are not measured. */
#define NAME_MEASURED_MAX 40

static int fold(int c) {
  return tolower((unsigned char)c);
}

/* Optimal string alignment distance of a and b (case folded), or a large
 * number when either is longer than NAME_MEASURED_MAX. */
static size_t distance(const char *a, const char *b) {
  size_t na = strlen(a), nb = strlen(b);
  size_t d[NAME_MEASURED_MAX + 1][NAME_MEASURED_MAX + 1];
  if (na > NAME_MEASURED_MAX || nb > NAME_MEASURED_MAX) return (size_t)-1 / 2;
  for (size_t i = 0; i <= na; i++) d[i][0] = i;
  for (size_t j = 0; j <= nb; j++) d[0][j] = j;
  for (size_t i = 1; i <= na; i++) {
    for (size_t j = 1; j <= nb; j++) {
      size_t cost = fold(a[i - 1]) == fold(b[j - 1]) ? 0 : 1;
      size_t best = d[i - 1][j - 1] + cost;
      if (d[i - 1][j] + 1 < best) best = d[i - 1][j] + 1;
      if (d[i][j - 1] + 1 < best) best = d[i][j - 1] + 1;
      if (i > 1 && j > 1 && fold(a[i - 1]) == fold(b[j - 2]) &&
          fold(a[i - 2]) == fold(b[j - 1]) && d[i - 2][j - 2] + 1 < best)
        best = d[i - 2][j - 2] + 1;
      d[i][j] = best;
    }
  }
  return d[na][nb];
}

/* Whether the shorter of a and b, of at least 3 letters, begins the other
 * (case folded): "blending" and "blend", "tol" and "tolerance". */
static bool prefix_either_way(const char *a, const char *b) {
  size_t na = strlen(a), nb = strlen(b), n = na < nb ? na : nb;
  if (n < 3) return false;
  for (size_t i = 0; i < n; i++)
    if (fold(a[i]) != fold(b[i])) return false;
  return true;
}

const char *api__nearest_name(const char *key, const char *const *names,
                              size_t n) {
  const char *best = NULL;
  size_t best_d = (size_t)-1;
  for (size_t i = 0; i < n; i++) {
    size_t d = distance(key, names[i]);
    size_t longer =
        strlen(key) > strlen(names[i]) ? strlen(key) : strlen(names[i]);
    bool close = 3 * d <= longer || (d == 1 && longer >= 2) ||
                 prefix_either_way(key, names[i]);
    if (close && d < best_d) {
      best = names[i];
      best_d = d;
    }
  }
  return best;
}

/* key as one RFC 6901 reference token after base ("~" is "~0", "/" is
 * "~1"), cut at API_POINTER_MAX. */
static void pointer_to_member(char *buf, const char *base, const char *key) {
  size_t used = strlen(base);
  if (used > API_POINTER_MAX - 2) used = API_POINTER_MAX - 2;
  memcpy(buf, base, used);
  buf[used++] = '/';
  for (const char *k = key; *k != '\0'; k++) {
    const char *rep = *k == '~' ? "~0" : *k == '/' ? "~1" : NULL;
    size_t len = rep != NULL ? 2 : 1;
    if (used + len >= API_POINTER_MAX) break;
    if (rep != NULL)
      memcpy(buf + used, rep, 2);
    else
      buf[used] = *k;
    used += len;
  }
  buf[used] = '\0';
}

bool api__known_members(api_ctx *ctx, const cJSON *obj, const char *base,
                        const char *const *names, size_t n) {
  const cJSON *m;
  if (!cJSON_IsObject(obj)) return true;
  cJSON_ArrayForEach(m, obj) {
    const char *key = m->string != NULL ? m->string : "";
    const char *near;
    char p[API_POINTER_MAX];
    bool known = false;
    for (size_t i = 0; i < n && !known; i++) known = strcmp(key, names[i]) == 0;
    if (known) continue;
    pointer_to_member(p, base, key);
    near = api__nearest_name(key, names, n);
    if (near != NULL)
      return api__invalid(ctx, p, "unknown member; did you mean \"%s\"?", near);
    return api__invalid(ctx, p, "unknown member");
  }
  return true;
}
