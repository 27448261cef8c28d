/* json_parse.c - request bodies from bytes to a cJSON tree, within a memory
 * budget proportional to the body, with numeric arrays stored packed.
 *
 * DESIGN: a strict RFC 8259 scanner (syntax, UTF-8, nesting depth, array
 * lengths) runs first and gives the byte offset of a syntax error. It also
 * prices the tree the builder will make, allocation by allocation as glibc
 * rounds them, so a body whose tree would take more than API_TREE_FACTOR
 * times its size is refused with 413 before anything is allocated. A cJSON
 * item is 80 bytes of heap, which made `[0,0],` cost 35 times its text;
 * so an array whose elements are all numbers, or all arrays of the same
 * count (up to API_PACK_WIDTH_MAX) of numbers, such as control points
 * [[x, y], ...], is one item holding a buffer of doubles: API_PACKED in its
 * type, the buffer in valuestring (cJSON_Delete frees it), no children.
 * Readers reach elements only through api__array_len, api__array_packed
 * and the api__elems_* walk of json_read.c, never through cJSON's own array
 * functions, which see a packed array as empty. The scanner is
 * json_scan.c, the builder json_tree.c; this file drives them.
 *
 * The tree is built with cJSON's item constructors, not by
 * cJSON_ParseWithLengthOpts: that function writes a process-wide static
 * (the record behind cJSON_GetErrorPtr) on every call, success included, a
 * data race when the daemon's threads parse requests at once. Every
 * allocation goes through cJSON's hooks, so a test can count them.
 *
 * An object that repeats a member name is refused (400): RFC 8259 leaves
 * the meaning of duplicates open, and a silent "first wins" lets two
 * readers of one request see different values. Each object's names are
 * sorted once when it closes, so thousands of members cost n log n, and
 * the repeat that comes first in the text is named with its object's
 * pointer and byte offset. Bodies need no NUL terminator.
 */
#include <stdlib.h>

#include "json_parse.h"

/* The longest array any field may hold: control points, knots (points +
 * degree + 1), weights, samples, times. */
static size_t longest_array(const api_config *cfg) {
  size_t m = cfg->max_control_points + 32;
  if (cfg->max_samples > m) m = cfg->max_samples;
  if (cfg->max_frames_job > m) m = cfg->max_frames_job;
  return m;
}

size_t api__tree_budget(size_t length) {
  return API_TREE_FACTOR * length + API_TREE_SLACK;
}

cJSON *api__parse_body(api_ctx *ctx, const char *body, size_t length) {
  cJSON *root;
  size_t need = 0;
  if (length > ctx->cfg->max_body_bytes) {
    api__failf(ctx, 413, API_P_TOO_LARGE, "Body too large", NULL,
               "the body has %zu bytes; the limit is %zu", length,
               ctx->cfg->max_body_bytes);
    return NULL;
  }
  if (body == NULL) length = 0;
  if (!api__json_scan(ctx, body, length, longest_array(ctx->cfg), &need))
    return NULL;
  if (need > api__tree_budget(length)) {
    api__failf(ctx, 413, API_P_TOO_LARGE, "Body too large", NULL,
               "the body's %zu bytes would take %zu bytes to parse, more "
               "than %d times their size: short strings, objects and "
               "numbers outside arrays of numbers cost up to 40 times their "
               "text",
               length, need, API_TREE_FACTOR);
    return NULL;
  }
  if ((root = api__json_build(ctx, body, length)) == NULL) return NULL;
  if (!cJSON_IsObject(root)) {
    cJSON_Delete(root);
    api__invalid(ctx, "", "the request body must be a JSON object");
    return NULL;
  }
  return root;
}
