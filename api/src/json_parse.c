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
 * and the api__elems_* walk of json_in.c, never through cJSON's own array
 * functions, which see a packed array as empty.
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
#include <ctype.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
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
#define SORT_ON_STACK 16

typedef struct member {
  const char *key;
  size_t index;
} member;

/* Heap bytes one malloc(n) takes under glibc: n and an 8-byte header,
 * rounded up to 16, at least 32. */
static size_t heap_bytes(size_t n) {
  size_t c = (n + 8 + 15) & ~(size_t)15;
  return c < 32 ? 32 : c;
}

static size_t pack_bytes(size_t count, size_t width) {
  return sizeof(api_pack) + count * (width > 0 ? width : 1) * sizeof(double);
}

/* ------------------------------------------------------- packed arrays */

size_t api__array_len(const cJSON *a) {
  if (!cJSON_IsArray(a))
    return 0;
  if ((a->type & API_PACKED) != 0)
    return ((const api_pack *)(const void *)a->valuestring)->count;
  return (size_t)cJSON_GetArraySize(a);
}

const double *api__array_packed(const cJSON *a, size_t *width) {
  const api_pack *pk;
  if (!cJSON_IsArray(a) || (a->type & API_PACKED) == 0)
    return NULL;
  pk = (const api_pack *)(const void *)a->valuestring;
  if (width != NULL)
    *width = pk->width;
  return pk->v;
}

static const unsigned char *skip_ws(const unsigned char *p,
                                    const unsigned char *end) {
  while (p < end && (*p == ' ' || *p == '\t' || *p == '\n' || *p == '\r'))
    p++;
  return p;
}

static bool number_char(unsigned char c) {
  return c != '\0' && strchr("+-0123456789.eE", c) != NULL;
}

/* Whether the array at p (text the scanner accepted, at its '[') is
 * stored packed, and its shape. Empty arrays and empty rows stay items. */
static bool pack_shape(const unsigned char *p, const unsigned char *end,
                       size_t *count, size_t *width) {
  size_t n = 0, w = 0;
  bool rows;
  p = skip_ws(p + 1, end);
  rows = p < end && *p == '[';
  for (;;) {
    size_t k = 0;
    if (rows) {
      if (p >= end || *p != '[')
        return false;
      p = skip_ws(p + 1, end);
    }
    do {
      if (p < end && *p == ',')
        p = skip_ws(p + 1, end);
      if (p >= end || !(*p == '-' || isdigit(*p)))
        return false;
      while (p < end && number_char(*p))
        p++;
      p = skip_ws(p, end);
      k++;
    } while (rows && p < end && *p == ',');
    if (rows) {
      if (k > API_PACK_WIDTH_MAX || (n > 0 && k != w))
        return false;
      w = k;
      p = skip_ws(p + 1, end); /* the row's ']' */
    }
    n++;
    if (p < end && *p == ',') {
      p = skip_ws(p + 1, end);
      continue;
    }
    break; /* ']' */
  }
  *count = n;
  *width = rows ? w : 0;
  return true;
}

/* --------------------------------------------------- strict JSON scanner */

typedef struct scan {
  const unsigned char *p, *end, *start;
  size_t depth, max_depth;
  const char *error; /* static message, NULL while fine */
  bool too_deep;
  size_t max_array;  /* no array in a valid request is longer */
  bool too_long;
  size_t cost;       /* heap bytes of the tree built so far */
  size_t transient;  /* the largest buffer held only while building */
} scan;

static bool scan_fail(scan *s, const char *msg) {
  if (s->error == NULL)
    s->error = msg;
  return false;
}

static void scan_ws(scan *s) { s->p = skip_ws(s->p, s->end); }

static bool scan_lit(scan *s, const char *lit) {
  size_t n = strlen(lit);
  if ((size_t)(s->end - s->p) < n || memcmp(s->p, lit, n) != 0)
    return scan_fail(s, "invalid literal");
  s->p += n;
  return true;
}

static bool scan_digits(scan *s) {
  if (s->p >= s->end || !isdigit(*s->p))
    return scan_fail(s, "digit expected");
  while (s->p < s->end && isdigit(*s->p))
    s->p++;
  return true;
}

static bool scan_number(scan *s) {
  const unsigned char *from = s->p;
  if (s->p < s->end && *s->p == '-')
    s->p++;
  if (s->p < s->end && *s->p == '0') {
    s->p++;
  } else if (!scan_digits(s)) {
    return false;
  }
  if (s->p < s->end && *s->p == '.') {
    s->p++;
    if (!scan_digits(s))
      return false;
  }
  if (s->p < s->end && (*s->p == 'e' || *s->p == 'E')) {
    s->p++;
    if (s->p < s->end && (*s->p == '+' || *s->p == '-'))
      s->p++;
    if (!scan_digits(s))
      return false;
  }
  /* the builder copies a long token to a buffer of its own for strtod */
  if ((size_t)(s->p - from) >= 64 &&
      heap_bytes((size_t)(s->p - from) + 1) > s->transient)
    s->transient = heap_bytes((size_t)(s->p - from) + 1);
  return true;
}

/* One UTF-8 sequence (RFC 3629: no overlongs, no surrogates, <= U+10FFFF). */
static bool scan_utf8(scan *s) {
  unsigned c = *s->p;
  size_t len;
  unsigned cp;
  if (c < 0x80) {
    s->p++;
    return true;
  }
  if (c >= 0xc2 && c <= 0xdf) {
    len = 2;
    cp = c & 0x1f;
  } else if (c >= 0xe0 && c <= 0xef) {
    len = 3;
    cp = c & 0x0f;
  } else if (c >= 0xf0 && c <= 0xf4) {
    len = 4;
    cp = c & 0x07;
  } else {
    return scan_fail(s, "invalid UTF-8");
  }
  if ((size_t)(s->end - s->p) < len)
    return scan_fail(s, "invalid UTF-8");
  for (size_t i = 1; i < len; i++) {
    if ((s->p[i] & 0xc0) != 0x80)
      return scan_fail(s, "invalid UTF-8");
    cp = (cp << 6) | (s->p[i] & 0x3fu);
  }
  if ((len == 3 && (cp < 0x800 || (cp >= 0xd800 && cp <= 0xdfff))) ||
      (len == 4 && (cp < 0x10000 || cp > 0x10ffff)))
    return scan_fail(s, "invalid UTF-8");
  s->p += len;
  return true;
}

static unsigned hexval(unsigned char c) {
  return isdigit(c) ? (unsigned)(c - '0') : (unsigned)(tolower(c) - 'a' + 10);
}

static bool scan_hex4(scan *s, unsigned *cp) {
  *cp = 0;
  for (int i = 0; i < 4; i++, s->p++) {
    if (s->p >= s->end || !isxdigit(*s->p))
      return scan_fail(s, "invalid \\u escape");
    *cp = (*cp << 4) | hexval(*s->p);
  }
  return true;
}

static bool scan_escape(scan *s) {
  unsigned char c = *s->p;
  if (c == 'u') {
    unsigned cp;
    s->p++;
    if (!scan_hex4(s, &cp))
      return false;
    /* Only whole characters: a high surrogate must be followed by a low
     * one, and NUL would cut the C string short. */
    if (cp == 0)
      return scan_fail(s, "\\u0000 is not accepted in strings");
    if (cp >= 0xdc00 && cp <= 0xdfff)
      return scan_fail(s, "lone low surrogate in \\u escape");
    if (cp >= 0xd800 && cp <= 0xdbff) {
      unsigned lo;
      if ((size_t)(s->end - s->p) < 2 || s->p[0] != '\\' || s->p[1] != 'u')
        return scan_fail(s, "lone high surrogate in \\u escape");
      s->p += 2;
      if (!scan_hex4(s, &lo))
        return false;
      if (lo < 0xdc00 || lo > 0xdfff)
        return scan_fail(s, "lone high surrogate in \\u escape");
    }
    return true;
  }
  if (strchr("\"\\/bfnrt", c) == NULL || c == '\0')
    return scan_fail(s, "invalid escape");
  s->p++;
  return true;
}

/* A string token; adds the buffer the builder will decode it into (the
 * token's length: decoded text is never longer). */
static bool scan_string(scan *s) {
  const unsigned char *from = ++s->p; /* after the opening quote */
  while (s->p < s->end) {
    unsigned char c = *s->p;
    if (c == '"') {
      s->cost += heap_bytes((size_t)(s->p - from) + 1);
      s->p++;
      return true;
    }
    if (c < 0x20)
      return scan_fail(s, "control character in string");
    if (c == '\\') {
      s->p++;
      if (s->p >= s->end)
        break;
      if (!scan_escape(s))
        return false;
      continue;
    }
    if (!scan_utf8(s))
      return false;
  }
  return scan_fail(s, "unterminated string");
}

static bool scan_value(scan *s);

/* One member or element and what follows it; *more while a ',' did. */
static bool scan_entry(scan *s, bool object, bool *more) {
  unsigned char close = object ? '}' : ']';
  if (object) {
    scan_ws(s);
    if (s->p >= s->end || *s->p != '"')
      return scan_fail(s, "object key (a string) expected");
    if (!scan_string(s))
      return false;
    scan_ws(s);
    if (s->p >= s->end || *s->p != ':')
      return scan_fail(s, "':' expected");
    s->p++;
  }
  if (!scan_value(s))
    return false;
  scan_ws(s);
  if (s->p < s->end && (*s->p == ',' || *s->p == close)) {
    *more = *s->p++ == ',';
    return true;
  }
  return scan_fail(s, object ? "',' or '}' expected" : "',' or ']' expected");
}

static bool scan_container(scan *s, unsigned char close, bool object) {
  const unsigned char *open = s->p;
  size_t cost0 = s->cost, count = 0, rows, width;
  bool more = true;
  if (++s->depth > s->max_depth) {
    s->too_deep = true;
    return scan_fail(s, "nesting too deep");
  }
  s->p++;
  scan_ws(s);
  if (s->p < s->end && *s->p == close) {
    s->p++;
    more = false;
  }
  while (more) {
    /* refuse an overlong array before any tree is built */
    if (!object && ++count > s->max_array) {
      s->too_long = true;
      return scan_fail(s, "array too long");
    }
    if (object)
      count++;
    if (!scan_entry(s, object, &more))
      return false;
  }
  s->depth--;
  if (!object && pack_shape(open, s->p, &rows, &width)) {
    /* the elements' own items are not built: one item and its buffer */
    s->cost = cost0 + heap_bytes(pack_bytes(rows, width));
  } else if (object && count > SORT_ON_STACK &&
             2 * heap_bytes(count * sizeof(member)) > s->transient) {
    /* the names sorted once: the array and qsort's copy of it */
    s->transient = 2 * heap_bytes(count * sizeof(member));
  }
  s->cost += heap_bytes(sizeof(cJSON));
  return true;
}

static bool scan_value(scan *s) {
  scan_ws(s);
  if (s->p >= s->end)
    return scan_fail(s, "value expected");
  switch (*s->p) {
  case '{': return scan_container(s, '}', true);
  case '[': return scan_container(s, ']', false);
  case '"': s->cost += heap_bytes(sizeof(cJSON)); return scan_string(s);
  case 't': s->cost += heap_bytes(sizeof(cJSON)); return scan_lit(s, "true");
  case 'f': s->cost += heap_bytes(sizeof(cJSON)); return scan_lit(s, "false");
  case 'n': s->cost += heap_bytes(sizeof(cJSON)); return scan_lit(s, "null");
  default:
    s->cost += heap_bytes(sizeof(cJSON));
    if (*s->p == '-' || isdigit(*s->p))
      return scan_number(s);
    return scan_fail(s, "value expected");
  }
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

static void build_ws(build *b) { b->p = skip_ws(b->p, b->end); }

static unsigned build_hex4(build *b) {
  unsigned cp = 0;
  for (int i = 0; i < 4; i++)
    cp = (cp << 4) | hexval(*b->p++);
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
  while (*q != '"')
    q += *q == '\\' ? 2 : 1;
  o = cJSON_malloc((size_t)(q - b->p) + 1);
  if (o == NULL)
    return NULL;
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
  while (b->p < b->end && number_char(*b->p))
    b->p++;
  n = (size_t)(b->p - from);
  /* strtod needs a terminator, which the body need not have */
  if (n >= sizeof small && (text = cJSON_malloc(n + 1)) == NULL)
    return false;
  memcpy(text, from, n);
  text[n] = '\0';
  *out = strtod(text, NULL);
  if (text != small)
    cJSON_free(text);
  return true;
}

/* The array at b->p, of the shape pack_shape found, as one packed item. */
static cJSON *build_packed(build *b, size_t count, size_t width) {
  api_pack *pk = cJSON_malloc(pack_bytes(count, width));
  cJSON *c = pk != NULL ? cJSON_CreateArray() : NULL;
  size_t k = 0;
  if (c == NULL)
    goto fail;
  pk->count = count;
  pk->width = width;
  b->p++; /* '[' */
  for (size_t i = 0; i < count; i++) {
    build_ws(b);
    if (width > 0)
      b->p++; /* the row's '[' */
    for (size_t j = 0; j < (width > 0 ? width : 1); j++) {
      build_ws(b);
      if (!build_double(b, &pk->v[k++]))
        goto fail;
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
  while (*s != '\0' && *len + 1 < cap)
    buf[(*len)++] = *s++;
  buf[*len] = '\0';
}

/* The RFC 6901 pointer of the value f leads into (the root: ""). */
static void frame_pointer(const frame *f, char *buf, size_t cap,
                          size_t *len) {
  char idx[24];
  if (f == NULL)
    return;
  frame_pointer(f->up, buf, cap, len);
  append(buf, cap, len, "/");
  if (f->key == NULL) {
    snprintf(idx, sizeof idx, "%zu", f->index);
    append(buf, cap, len, idx);
    return;
  }
  for (const char *k = f->key; *k != '\0'; k++)
    append(buf, cap, len, *k == '~' ? "~0" : *k == '/' ? "~1"
                                                       : (char[]){*k, 0});
}

/* Cut s (of *len bytes) back to whole UTF-8 characters. */
static void trim_utf8(char *s, size_t len) {
  size_t i = len;
  while (i > 0 && ((unsigned char)s[i - 1] & 0xc0) == 0x80)
    i--;
  if (i > 0 && (unsigned char)s[i - 1] >= 0xc0) {
    size_t need = (unsigned char)s[i - 1] >= 0xf0   ? 4
                  : (unsigned char)s[i - 1] >= 0xe0 ? 3
                                                    : 2;
    if (len - (i - 1) < need)
      s[i - 1] = '\0';
  }
}

/* The byte offset of member `index` of the object at open: found again by
 * walking the accepted text, which only a refused body pays for. */
static size_t member_offset(const build *b, const unsigned char *open,
                            size_t index) {
  scan s;
  bool more = true;
  memset(&s, 0, sizeof s);
  s.p = open + 1;
  s.end = b->end;
  s.max_depth = SIZE_MAX;
  s.max_array = SIZE_MAX;
  for (size_t i = 0; i < index && more; i++)
    scan_entry(&s, true, &more);
  scan_ws(&s);
  return (size_t)(s.p - b->start);
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
  const member *a = pa, *b = pb;
  int c = strcmp(a->key, b->key);
  if (c != 0)
    return c;
  return (a->index > b->index) - (a->index < b->index);
}

/* Whether the n >= 2 members of obj (whose text starts at open) have
 * distinct names; names the first repeat in the text otherwise. */
static bool unique_members(build *b, const cJSON *obj, size_t n,
                           const unsigned char *open, const frame *up) {
  member stack[SORT_ON_STACK], *m = stack;
  size_t i = 0, first = SIZE_MAX;
  const char *key = NULL;
  if (n > SORT_ON_STACK && (m = cJSON_malloc(n * sizeof *m)) == NULL)
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
    dup_fail(b, key, up, member_offset(b, open, first));
  if (m != stack)
    cJSON_free(m);
  return key == NULL;
}

static cJSON *build_value(build *b, const frame *up);

static cJSON *build_container(build *b, bool object, const frame *up) {
  const unsigned char *open = b->p;
  frame me = {up, NULL, 0};
  size_t rows, width;
  cJSON *c;
  if (!object && pack_shape(open, b->end, &rows, &width))
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
      if ((me.key = key = build_string(b)) == NULL)
        goto fail;
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
    if (*b->p++ == ',')
      continue;
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

/* ------------------------------------------------------------- the body */

/* The longest array any field may hold: control points, knots (points +
 * degree + 1), weights, samples, times. */
static size_t longest_array(const api_config *cfg) {
  size_t m = cfg->max_control_points + 32;
  if (cfg->max_samples > m)
    m = cfg->max_samples;
  if (cfg->max_frames_job > m)
    m = cfg->max_frames_job;
  return m;
}

/* Scan the body into s; false with the error recorded in ctx. */
static bool scan_body(api_ctx *ctx, scan *s, const char *body,
                      size_t length) {
  memset(s, 0, sizeof *s);
  s->start = s->p = (const unsigned char *)(body != NULL ? body : "");
  s->end = s->p + length;
  s->max_depth = ctx->cfg->max_json_depth;
  s->max_array = longest_array(ctx->cfg);
  /* A UTF-8 byte order mark is tolerated, as cJSON does. */
  if (length >= 3 && memcmp(s->p, "\xef\xbb\xbf", 3) == 0)
    s->p += 3;
  if (scan_value(s)) {
    scan_ws(s);
    if (s->p != s->end)
      scan_fail(s, "unexpected data after the JSON value");
  }
  if (s->error == NULL)
    return true;
  if (s->too_long)
    return api__failf(ctx, 422, API_P_LIMIT, "Limit exceeded", NULL,
                      "an array holds more than %zu elements (at byte %zu)",
                      s->max_array, (size_t)(s->p - s->start));
  if (s->too_deep)
    return api__failf(ctx, 400, API_P_MALFORMED, "Malformed JSON", NULL,
                      "JSON nested deeper than %zu levels (at byte %zu)",
                      s->max_depth, (size_t)(s->p - s->start));
  return api__failf(ctx, 400, API_P_MALFORMED, "Malformed JSON", NULL,
                    "%s at byte %zu", s->error, (size_t)(s->p - s->start));
}

size_t api__tree_budget(size_t length) {
  return API_TREE_FACTOR * length + API_TREE_SLACK;
}

cJSON *api__parse_body(api_ctx *ctx, const char *body, size_t length) {
  scan s;
  build b;
  cJSON *root;
  size_t need;
  if (length > ctx->cfg->max_body_bytes) {
    api__failf(ctx, 413, API_P_TOO_LARGE, "Body too large", NULL,
               "the body has %zu bytes; the limit is %zu", length,
               ctx->cfg->max_body_bytes);
    return NULL;
  }
  if (body == NULL)
    length = 0;
  if (!scan_body(ctx, &s, body, length))
    return NULL;
  need = s.cost + s.transient;
  if (need > api__tree_budget(length)) {
    api__failf(ctx, 413, API_P_TOO_LARGE, "Body too large", NULL,
               "the body's %zu bytes would take %zu bytes to parse, more "
               "than %d times their size: short strings, objects and "
               "numbers outside arrays of numbers cost up to 40 times their "
               "text",
               length, need, API_TREE_FACTOR);
    return NULL;
  }
  memset(&b, 0, sizeof b);
  b.start = s.start;
  b.end = s.end;
  b.p = s.start;
  if (length >= 3 && memcmp(b.p, "\xef\xbb\xbf", 3) == 0)
    b.p += 3;
  root = build_value(&b, NULL);
  if (root == NULL) {
    if (b.dup)
      api__fail(ctx, 400, API_P_MALFORMED, "Malformed JSON", NULL,
                b.dup_detail);
    else
      api__oom(ctx);
    return NULL;
  }
  if (!cJSON_IsObject(root)) {
    cJSON_Delete(root);
    api__invalid(ctx, "", "the request body must be a JSON object");
    return NULL;
  }
  return root;
}
