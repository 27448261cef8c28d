/* json_tree.c - the tree of a request body, built from text the scanner
 * accepted: strings decoded, numbers read with strtod, arrays of numbers
 * (or of equal rows of numbers) stored packed, and a member name repeated
 * in one object refused. Also the readers of packed arrays.
 *
 * DESIGN: an array whose elements are all numbers, or all arrays of the
 * same count (up to API_PACK_WIDTH_MAX) of numbers, is one item holding a
 * buffer of doubles: API_PACKED in its type, the buffer in valuestring
 * (cJSON_Delete frees it), no children. Each object's names are sorted
 * once when it closes, so thousands of members cost n log n, and the
 * repeat that comes first in the text is named. The builder reads only
 * accepted text, so nothing here can be malformed.
 */
#include <ctype.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "json_parse.h"

/* ------------------------------------------------------- packed arrays */

size_t api__array_len(const cJSON *a) {
  if (!cJSON_IsArray(a)) return 0;
  if ((a->type & API_PACKED) != 0)
    return ((const api_pack *)(const void *)a->valuestring)->count;
  return (size_t)cJSON_GetArraySize(a);
}

const double *api__array_packed(const cJSON *a, size_t *width) {
  const api_pack *pk;
  if (!cJSON_IsArray(a) || (a->type & API_PACKED) == 0) return NULL;
  pk = (const api_pack *)(const void *)a->valuestring;
  if (width != NULL) *width = pk->width;
  return pk->v;
}

/* Whether the array at p is stored packed, and its shape. */
bool api__pack_shape(const unsigned char *p, const unsigned char *end,
                     size_t *count, size_t *width) {
  size_t n = 0, w = 0;
  bool rows;
  p = api__skip_ws(p + 1, end);
  rows = p < end && *p == '[';
  for (;;) {
    size_t k = 0;
    if (rows) {
      if (p >= end || *p != '[') return false;
      p = api__skip_ws(p + 1, end);
    }
    do {
      if (p < end && *p == ',') p = api__skip_ws(p + 1, end);
      if (p >= end || !(*p == '-' || isdigit(*p))) return false;
      while (p < end && api__number_char(*p)) p++;
      p = api__skip_ws(p, end);
      k++;
    } while (rows && p < end && *p == ',');
    if (rows) {
      if (k > API_PACK_WIDTH_MAX || (n > 0 && k != w)) return false;
      w = k;
      p = api__skip_ws(p + 1, end); /* the row's ']' */
    }
    n++;
    if (p < end && *p == ',') {
      p = api__skip_ws(p + 1, end);
      continue;
    }
    break; /* ']' */
  }
  *count = n;
  *width = rows ? w : 0;
  return true;
}

/* ------------------------------------------------- tree from valid text */

/* The path from the root to the value being built, for error pointers. */
typedef struct frame {
  const struct frame *up;
  const char *key; /* the member being built; NULL in an array */
  size_t index;    /* the element being built in an array */
} frame;

/* The builder reads text the scanner accepted, so nothing here can be
 * malformed; its failures are out-of-memory and a repeated member name
 * (dup_detail set). cJSON_Create* and cJSON_Add* only read cJSON's global
 * hooks. */
typedef struct build {
  const unsigned char *p, *end, *start;
  bool dup;
  char dup_detail[API_TEXT_MAX];
} build;

static void build_ws(build *b) {
  b->p = api__skip_ws(b->p, b->end);
}

static unsigned build_hex4(build *b) {
  unsigned cp = 0;
  for (int i = 0; i < 4; i++) cp = (cp << 4) | (unsigned)api__hexval(*b->p++);
  return cp;
}

static size_t put_utf8(unsigned char *o, unsigned cp) {
  if (cp < 0x80) {
    o[0] = (unsigned char)cp;
    return 1;
  }
  if (cp < 0x800) {
    o[0] = (unsigned char)(0xc0 | (cp >> 6));
    o[1] = (unsigned char)(0x80 | (cp & 0x3f));
    return 2;
  }
  if (cp < 0x10000) {
    o[0] = (unsigned char)(0xe0 | (cp >> 12));
    o[1] = (unsigned char)(0x80 | ((cp >> 6) & 0x3f));
    o[2] = (unsigned char)(0x80 | (cp & 0x3f));
    return 3;
  }
  o[0] = (unsigned char)(0xf0 | (cp >> 18));
  o[1] = (unsigned char)(0x80 | ((cp >> 12) & 0x3f));
  o[2] = (unsigned char)(0x80 | ((cp >> 6) & 0x3f));
  o[3] = (unsigned char)(0x80 | (cp & 0x3f));
  return 4;
}

/* A string token, decoded into a NUL-terminated buffer from cJSON's hooks
 * (a key or value of the tree: cJSON_Delete frees it). Decoded text is
 * never longer than the token (an escape of 6 or 12 bytes yields at most
 * 4). */
static char *build_string(build *b) {
  const unsigned char *q = ++b->p;
  size_t n = 0;
  unsigned char *o;
  while (*q != '"') q += *q == '\\' ? 2 : 1;
  o = cJSON_malloc((size_t)(q - b->p) + 1);
  if (o == NULL) return NULL;
  while (*b->p != '"') {
    unsigned char c = *b->p++;
    if (c != '\\') {
      o[n++] = c;
      continue;
    }
    c = *b->p++;
    switch (c) {
    case 'b': o[n++] = '\b'; break;
    case 'f': o[n++] = '\f'; break;
    case 'n': o[n++] = '\n'; break;
    case 'r': o[n++] = '\r'; break;
    case 't': o[n++] = '\t'; break;
    case 'u': {
      unsigned cp = build_hex4(b);
      if (cp >= 0xd800 && cp <= 0xdbff) {
        b->p += 2;
        cp = 0x10000 + ((cp - 0xd800) << 10) + (build_hex4(b) - 0xdc00);
      }
      n += put_utf8(o + n, cp);
      break;
    }
    default: o[n++] = c; break; /* " \ / */
    }
  }
  b->p++;
  o[n] = '\0';
  return (char *)o;
}

/* A number token as a double; false only when a long token's copy cannot
 * be allocated. */
static bool build_double(build *b, double *out) {
  const unsigned char *from = b->p;
  char small[64], *text = small;
  size_t n;
  while (b->p < b->end && api__number_char(*b->p)) b->p++;
  n = (size_t)(b->p - from);
  /* strtod needs a terminator, which the body need not have */
  if (n >= sizeof small && (text = cJSON_malloc(n + 1)) == NULL) return false;
  memcpy(text, from, n);
  text[n] = '\0';
  *out = strtod(text, NULL);
  if (text != small) cJSON_free(text);
  return true;
}

/* The array at b->p, of the shape pack_shape found, as one packed item. */
static cJSON *build_packed(build *b, size_t count, size_t width) {
  api_pack *pk = cJSON_malloc(api__pack_bytes(count, width));
  cJSON *c = pk != NULL ? cJSON_CreateArray() : NULL;
  size_t k = 0;
  if (c == NULL) goto fail;
  pk->count = count;
  pk->width = width;
  b->p++; /* '[' */
  for (size_t i = 0; i < count; i++) {
    build_ws(b);
    if (width > 0) b->p++; /* the row's '[' */
    for (size_t j = 0; j < (width > 0 ? width : 1); j++) {
      build_ws(b);
      if (!build_double(b, &pk->v[k++])) goto fail;
      build_ws(b);
      b->p++; /* ',' or the row's ']' */
    }
    if (width > 0) {
      build_ws(b);
      b->p++; /* ',' or the array's ']' */
    }
  }
  c->type |= API_PACKED;
  c->valuestring = (char *)pk;
  return c;
fail:
  cJSON_free(pk);
  cJSON_Delete(c);
  return NULL;
}

/* Append s to buf[*len..cap) as far as it fits. */
static void append(char *buf, size_t cap, size_t *len, const char *s) {
  while (*s != '\0' && *len + 1 < cap) buf[(*len)++] = *s++;
  buf[*len] = '\0';
}

/* The RFC 6901 pointer of the value f leads into (the root: ""). */
static void frame_pointer(const frame *f, char *buf, size_t cap, size_t *len) {
  char idx[24];
  if (f == NULL) return;
  frame_pointer(f->up, buf, cap, len);
  append(buf, cap, len, "/");
  if (f->key == NULL) {
    snprintf(idx, sizeof idx, "%zu", f->index);
    append(buf, cap, len, idx);
    return;
  }
  for (const char *k = f->key; *k != '\0'; k++)
    append(buf, cap, len,
           *k == '~'   ? "~0"
           : *k == '/' ? "~1"
                       : (char[]){*k, 0});
}

/* Cut s (of *len bytes) back to whole UTF-8 characters. */
static void trim_utf8(char *s, size_t len) {
  size_t i = len;
  while (i > 0 && ((unsigned char)s[i - 1] & 0xc0) == 0x80) i--;
  if (i > 0 && (unsigned char)s[i - 1] >= 0xc0) {
    size_t need = (unsigned char)s[i - 1] >= 0xf0   ? 4
                  : (unsigned char)s[i - 1] >= 0xe0 ? 3
                                                    : 2;
    if (len - (i - 1) < need) s[i - 1] = '\0';
  }
}

static void dup_fail(build *b, const char *key, const frame *up,
                     size_t offset) {
  char name[72], where[API_POINTER_MAX];
  size_t n = 0;
  snprintf(name, sizeof name, "%s", key);
  trim_utf8(name, strlen(name));
  where[0] = '\0';
  frame_pointer(up, where, sizeof where, &n);
  trim_utf8(where, n);
  b->dup = true;
  snprintf(b->dup_detail, sizeof b->dup_detail,
           "duplicate member \"%s\"%s at %s (byte %zu)", name,
           strlen(key) > sizeof name - 1 ? "..." : "",
           where[0] != '\0' ? where : "the top level", offset);
}

static int member_cmp(const void *pa, const void *pb) {
  const api_member *a = pa, *b = pb;
  int c = strcmp(a->key, b->key);
  if (c != 0) return c;
  return (a->index > b->index) - (a->index < b->index);
}

/* Whether the n >= 2 members of obj (whose text starts at open) have
 * distinct names; names the first repeat in the text otherwise. */
static bool unique_members(build *b, const cJSON *obj, size_t n,
                           const unsigned char *open, const frame *up) {
  api_member stack[API_SORT_ON_STACK], *m = stack;
  size_t i = 0, first = SIZE_MAX;
  const char *key = NULL;
  if (n > API_SORT_ON_STACK && (m = cJSON_malloc(n * sizeof *m)) == NULL)
    return false;
  for (const cJSON *e = obj->child; e != NULL; e = e->next, i++) {
    m[i].key = e->string;
    m[i].index = i;
  }
  qsort(m, n, sizeof *m, member_cmp);
  /* in a run of equal names the second is that name's first repeat */
  for (i = 1; i < n; i++) {
    if (m[i].index < first && strcmp(m[i].key, m[i - 1].key) == 0 &&
        (i < 2 || strcmp(m[i - 1].key, m[i - 2].key) != 0)) {
      first = m[i].index;
      key = m[i].key;
    }
  }
  if (key != NULL)
    dup_fail(b, key, up,
             api__json_member_offset(b->start, b->end, open, first));
  if (m != stack) cJSON_free(m);
  return key == NULL;
}

static cJSON *build_value(build *b, const frame *up);

static cJSON *build_container(build *b, bool object, const frame *up) {
  const unsigned char *open = b->p;
  frame me = {up, NULL, 0};
  size_t rows, width;
  cJSON *c;
  if (!object && api__pack_shape(open, b->end, &rows, &width))
    return build_packed(b, rows, width);
  if ((c = object ? cJSON_CreateObject() : cJSON_CreateArray()) == NULL)
    return NULL;
  b->p++;
  build_ws(b);
  if (*b->p == '}' || *b->p == ']') {
    b->p++;
    return c;
  }
  for (;;) {
    char *key = NULL;
    cJSON *v;
    if (object) {
      build_ws(b);
      if ((me.key = key = build_string(b)) == NULL) goto fail;
      build_ws(b);
      b->p++; /* ':' */
    }
    if ((v = build_value(b, &me)) == NULL) {
      cJSON_free(key);
      goto fail;
    }
    v->string = key; /* the item owns its name now */
    cJSON_AddItemToArray(c, v);
    me.index++;
    build_ws(b);
    if (*b->p++ == ',') continue;
    break; /* '}' or ']' */
  }
  if (object && me.index > 1 && !unique_members(b, c, me.index, open, up))
    goto fail;
  return c;
fail:
  cJSON_Delete(c);
  return NULL;
}

static cJSON *build_value(build *b, const frame *up) {
  build_ws(b);
  switch (*b->p) {
  case '{': return build_container(b, true, up);
  case '[': return build_container(b, false, up);
  case '"': {
    char *str = build_string(b);
    cJSON *v = str != NULL ? cJSON_CreateNull() : NULL;
    if (v == NULL) {
      cJSON_free(str);
      return NULL;
    }
    v->type = cJSON_String;
    v->valuestring = str; /* freed by cJSON_Delete */
    return v;
  }
  case 't': b->p += 4; return cJSON_CreateTrue();
  case 'f': b->p += 5; return cJSON_CreateFalse();
  case 'n': b->p += 4; return cJSON_CreateNull();
  default: {
    double v;
    return build_double(b, &v) ? cJSON_CreateNumber(v) : NULL;
  }
  }
}

cJSON *api__json_build(api_ctx *ctx, const char *body, size_t length) {
  build b;
  cJSON *root;
  memset(&b, 0, sizeof b);
  b.start = (const unsigned char *)(body != NULL ? body : "");
  b.end = b.start + length;
  b.p = b.start;
  if (length >= 3 && memcmp(b.p, "\xef\xbb\xbf", 3) == 0) b.p += 3;
  root = build_value(&b, NULL);
  if (root == NULL) {
    if (b.dup)
      api__fail(ctx, 400, API_P_MALFORMED, "Malformed JSON", NULL,
                b.dup_detail);
    else
      api__oom(ctx);
  }
  return root;
}
