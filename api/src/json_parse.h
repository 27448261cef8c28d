/* json_parse.h - the parts of the request parser its files share: the
 * scanner (json_scan.c) checks and prices the text, the builder
 * (json_tree.c) makes the tree of packed arrays from text the scanner
 * accepted, json_parse.c drives both within the budget. Internal to the
 * api layer; readers of the tree use internal.h's api__array_* and
 * api__elems_* only.
 */
#ifndef KMAPI_JSON_PARSE_H
#define KMAPI_JSON_PARSE_H

#include <stdbool.h>
#include <stddef.h>
#include <string.h>

#include "internal.h"

/* A type bit cJSON leaves unused (its own end at cJSON_StringIsConst). */
#define API_PACKED (1 << 12)

/* The buffer of a packed array: count elements of width numbers each
 * (width 0: each element is one number), row-major. */
typedef struct api_pack {
  size_t count, width;
  double v[];
} api_pack;

/* Names of an object sorted on a stack buffer up to this many. */
#define API_SORT_ON_STACK 16

/* One member name of an object, as sorted to find repeats. */
typedef struct api_member {
  const char *key;
  size_t index;
} api_member;

/* Heap bytes one malloc(n) takes under glibc: n and an 8-byte header,
 * rounded up to 16, at least 32. */
static inline size_t api__heap_bytes(size_t n) {
  size_t c = (n + 8 + 15) & ~(size_t)15;
  return c < 32 ? 32 : c;
}

static inline size_t api__pack_bytes(size_t count, size_t width) {
  return sizeof(api_pack) + count * (width > 0 ? width : 1) * sizeof(double);
}

static inline const unsigned char *api__skip_ws(const unsigned char *p,
                                                const unsigned char *end) {
  while (p < end && (*p == ' ' || *p == '\t' || *p == '\n' || *p == '\r')) p++;
  return p;
}

static inline bool api__number_char(unsigned char c) {
  return c != '\0' && strchr("+-0123456789.eE", c) != NULL;
}

/* Whether the array at p (text the scanner accepted, at its '[') is
 * stored packed, and its shape (*count elements of *width numbers, 0:
 * each a number). Empty arrays and empty rows stay items. json_tree.c. */
bool api__pack_shape(const unsigned char *p, const unsigned char *end,
                     size_t *count, size_t *width);

/* Scan length bytes of body (a UTF-8 byte order mark tolerated) as one
 * strict RFC 8259 value nested at most ctx->cfg->max_json_depth deep with
 * no array longer than max_array. True with *need, the heap bytes the
 * builder will take for it; false with the error (400 with the byte
 * offset, or 422 for an overlong array) in ctx. json_scan.c. */
bool api__json_scan(api_ctx *ctx, const char *body, size_t length,
                    size_t max_array, size_t *need);

/* The byte offset from start of member `index` of the accepted object
 * whose '{' is at open (end: the end of the text). json_scan.c. */
size_t api__json_member_offset(const unsigned char *start,
                               const unsigned char *end,
                               const unsigned char *open, size_t index);

/* The tree of length bytes of body, which api__json_scan accepted. NULL
 * with the error in ctx: 400 naming a member name repeated in one object
 * (its object's pointer and byte offset), else 503 out of memory. The
 * caller frees the tree with cJSON_Delete. json_tree.c. */
cJSON *api__json_build(api_ctx *ctx, const char *body, size_t length);

#endif
