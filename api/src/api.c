/* api.c - entry points of the contract layer: configuration, responses,
 * problem+json, request parsing and dispatch of one request to its route.
 *
 * DESIGN: a body is first checked by a small strict RFC 8259 scanner
 * (syntax, UTF-8, nesting depth), which gives the byte offset of a syntax
 * error for the problem detail and bounds the depth before any recursion
 * that builds a tree. The tree is then built here with cJSON's item
 * constructors rather than by cJSON_ParseWithLengthOpts: that function
 * writes a process-wide static (the record behind cJSON_GetErrorPtr) on
 * every call, success included, which is a data race when the daemon's
 * threads parse requests at once. Bodies need no NUL terminator.
 */
#include <ctype.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"

void api_config_default(api_config *cfg) {
  cfg->max_body_bytes = 8u * 1024u * 1024u;
  cfg->max_control_points = 100000;
  cfg->max_frames_sync = 1000;
  cfg->max_frames_job = 10000;
  cfg->max_samples = 100000;
  cfg->max_json_depth = 64;
  cfg->max_output_bytes = 64u * 1024u * 1024u;
}

void api_response_init(api_response *r) {
  r->status = 0;
  r->content_type = NULL;
  r->body = NULL;
  r->length = 0;
}

void api_response_free(api_response *r) {
  if (r == NULL)
    return;
  free(r->body);
  api_response_init(r);
}

/* ---------------------------------------------------------------- problems */

static const char *default_type(int status) {
  switch (status) {
  case 400: return API_P_MALFORMED;
  case 404: return API_P_NOT_FOUND;
  case 405: return "/problems/method-not-allowed";
  case 409: return "/problems/not-ready";
  case 413: return API_P_TOO_LARGE;
  case 415: return "/problems/unsupported-media-type";
  case 422: return API_P_INVALID_REQUEST;
  case 429: return "/problems/too-many-requests";
  case 503: return "/problems/unavailable";
  default: return status >= 500 ? API_P_INTERNAL : "/problems/bad-request";
  }
}

static const char *default_title(int status) {
  switch (status) {
  case 400: return "Malformed JSON";
  case 404: return "Not found";
  case 405: return "Method not allowed";
  case 409: return "Result not ready";
  case 413: return "Body too large";
  case 415: return "Unsupported media type";
  case 422: return "Invalid request";
  case 429: return "Too many requests";
  case 503: return "Service unavailable";
  default: return status >= 500 ? "Internal error" : "Bad request";
  }
}

/* A request id is echoed only if it is short printable ASCII: it comes from
 * a client header and must not smuggle bytes into the body or the logs. */
static bool sane_request_id(const char *id) {
  size_t n = 0;
  if (id == NULL || *id == '\0')
    return false;
  for (; id[n] != '\0'; n++)
    if (n >= 200 || id[n] < 0x21 || id[n] > 0x7e)
      return false;
  return true;
}

/* Last resort when cJSON cannot allocate: a fixed body, still valid JSON. */
static void problem_fallback(api_response *out, int status) {
  static const char fmt[] =
      "{\"type\":\"%s\",\"title\":\"%s\",\"status\":%d}";
  char buf[256];
  int n = snprintf(buf, sizeof buf, fmt, default_type(status),
                   default_title(status), status);
  out->status = status;
  out->content_type = API_CT_PROBLEM;
  out->body = NULL;
  out->length = 0;
  if (n > 0 && (size_t)n < sizeof buf) {
    out->body = malloc((size_t)n + 1);
    if (out->body != NULL) {
      memcpy(out->body, buf, (size_t)n + 1);
      out->length = (size_t)n;
    }
  }
}

void api_problem(api_response *out, int status, const char *type,
                 const char *title, const char *detail, const char *pointer,
                 const char *message, const char *request_id) {
  cJSON *root = cJSON_CreateObject();
  bool ok = root != NULL;
  if (type == NULL)
    type = default_type(status);
  if (title == NULL)
    title = default_title(status);
  ok = ok && cJSON_AddStringToObject(root, "type", type) != NULL;
  ok = ok && cJSON_AddStringToObject(root, "title", title) != NULL;
  ok = ok && cJSON_AddNumberToObject(root, "status", status) != NULL;
  if (ok && detail != NULL)
    ok = cJSON_AddStringToObject(root, "detail", detail) != NULL;
  if (ok && pointer != NULL) {
    cJSON *errs = cJSON_AddArrayToObject(root, "errors");
    cJSON *e = cJSON_CreateObject();
    ok = errs != NULL && e != NULL;
    if (ok)
      cJSON_AddItemToArray(errs, e);
    else
      cJSON_Delete(e);
    ok = ok && cJSON_AddStringToObject(e, "pointer", pointer) != NULL;
    ok = ok && cJSON_AddStringToObject(
                   e, "message",
                   message != NULL ? message
                                   : (detail != NULL ? detail : title)) != NULL;
  }
  if (ok && sane_request_id(request_id))
    ok = cJSON_AddStringToObject(root, "request_id", request_id) != NULL;
  char *text = ok ? cJSON_PrintUnformatted(root) : NULL;
  cJSON_Delete(root);
  if (text == NULL) {
    problem_fallback(out, status);
    return;
  }
  out->status = status;
  out->content_type = API_CT_PROBLEM;
  out->body = text;
  out->length = strlen(text);
}

/* ----------------------------------------------------------------- context */

void api__ctx_init(api_ctx *ctx, const api_config *cfg) {
  memset(ctx, 0, sizeof *ctx);
  ctx->cfg = cfg;
}

bool api__fail(api_ctx *ctx, int status, const char *type, const char *title,
               const char *pointer, const char *message) {
  if (ctx->status != 0)
    return false;
  ctx->status = status;
  ctx->type = type != NULL ? type : default_type(status);
  ctx->title = title != NULL ? title : default_title(status);
  snprintf(ctx->message, sizeof ctx->message, "%s",
           message != NULL ? message : ctx->title);
  if (pointer != NULL) {
    ctx->has_pointer = true;
    snprintf(ctx->pointer, sizeof ctx->pointer, "%s", pointer);
    if (pointer[0] != '\0')
      snprintf(ctx->detail, sizeof ctx->detail, "%s: %s", ctx->pointer,
               ctx->message);
    else
      snprintf(ctx->detail, sizeof ctx->detail, "%s", ctx->message);
  } else {
    snprintf(ctx->detail, sizeof ctx->detail, "%s", ctx->message);
  }
  return false;
}

bool api__failf(api_ctx *ctx, int status, const char *type,
                const char *title, const char *pointer, const char *fmt,
                ...) {
  char msg[API_TEXT_MAX];
  va_list ap;
  if (ctx->status != 0)
    return false;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  return api__fail(ctx, status, type, title, pointer, msg);
}

bool api__invalid(api_ctx *ctx, const char *pointer, const char *fmt, ...) {
  char msg[API_TEXT_MAX];
  va_list ap;
  if (ctx->status != 0)
    return false;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  return api__fail(ctx, 422, API_P_INVALID_REQUEST, "Invalid request",
                   pointer, msg);
}

bool api__oom(api_ctx *ctx) {
  return api__fail(ctx, 503, API_P_NO_MEMORY, "Out of memory", NULL,
                   "the service ran out of memory; retry later");
}

void api__ptr_key(char *buf, const char *base, const char *key) {
  snprintf(buf, API_POINTER_MAX, "%s/%s", base, key);
}

void api__ptr_idx(char *buf, const char *base, size_t index) {
  snprintf(buf, API_POINTER_MAX, "%s/%zu", base, index);
}

void api__ctx_problem(const api_ctx *ctx, api_response *out,
                      const char *request_id) {
  int status = ctx->status != 0 ? ctx->status : 500;
  api_problem(out, status, ctx->type, ctx->title,
              ctx->status != 0 ? ctx->detail : "unknown failure",
              ctx->has_pointer ? ctx->pointer : NULL, ctx->message,
              request_id);
}

int api__respond_json(api_ctx *ctx, cJSON *root, int status,
                      api_response *out, const char *request_id) {
  char *text = root != NULL ? cJSON_PrintUnformatted(root) : NULL;
  cJSON_Delete(root);
  if (text == NULL) {
    api__oom(ctx);
    api__ctx_problem(ctx, out, request_id);
    return out->status;
  }
  out->status = status;
  out->content_type = API_CT_JSON;
  out->body = text;
  out->length = strlen(text);
  return status;
}

/* --------------------------------------------------- strict JSON scanner */

typedef struct scan {
  const unsigned char *p, *end, *start;
  size_t depth, max_depth;
  const char *error; /* static message, NULL while fine */
  bool too_deep;
  size_t max_array;  /* no array in a valid request is longer */
  bool too_long;
} scan;

static bool scan_fail(scan *s, const char *msg) {
  if (s->error == NULL)
    s->error = msg;
  return false;
}

static void scan_ws(scan *s) {
  while (s->p < s->end &&
         (*s->p == ' ' || *s->p == '\t' || *s->p == '\n' || *s->p == '\r'))
    s->p++;
}

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

static bool scan_string(scan *s) {
  s->p++; /* opening quote */
  while (s->p < s->end) {
    unsigned char c = *s->p;
    if (c == '"') {
      s->p++;
      return true;
    }
    if (c < 0x20)
      return scan_fail(s, "control character in string");
    if (c == '\\') {
      s->p++;
      if (s->p >= s->end)
        break;
      c = *s->p;
      if (c == 'u') {
        unsigned cp;
        s->p++;
        if (!scan_hex4(s, &cp))
          return false;
        /* Only whole characters: a high surrogate must be followed by a
         * low one, and NUL would cut the C string short. */
        if (cp == 0)
          return scan_fail(s, "\\u0000 is not accepted in strings");
        if (cp >= 0xdc00 && cp <= 0xdfff)
          return scan_fail(s, "lone low surrogate in \\u escape");
        if (cp >= 0xd800 && cp <= 0xdbff) {
          unsigned lo;
          if ((size_t)(s->end - s->p) < 2 || s->p[0] != '\\' ||
              s->p[1] != 'u')
            return scan_fail(s, "lone high surrogate in \\u escape");
          s->p += 2;
          if (!scan_hex4(s, &lo))
            return false;
          if (lo < 0xdc00 || lo > 0xdfff)
            return scan_fail(s, "lone high surrogate in \\u escape");
        }
        continue;
      }
      if (strchr("\"\\/bfnrt", c) == NULL || c == '\0')
        return scan_fail(s, "invalid escape");
      s->p++;
      continue;
    }
    if (!scan_utf8(s))
      return false;
  }
  return scan_fail(s, "unterminated string");
}

static bool scan_value(scan *s);

static bool scan_container(scan *s, unsigned char close, bool object) {
  if (++s->depth > s->max_depth) {
    s->too_deep = true;
    return scan_fail(s, "nesting too deep");
  }
  s->p++;
  scan_ws(s);
  if (s->p < s->end && *s->p == close) {
    s->p++;
    s->depth--;
    return true;
  }
  size_t count = 0;
  for (;;) {
    /* refuse an overlong array before any tree is built: a million-point
     * array costs hundreds of megabytes as cJSON items */
    if (!object && ++count > s->max_array) {
      s->too_long = true;
      return scan_fail(s, "array too long");
    }
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
    if (s->p < s->end && *s->p == ',') {
      s->p++;
      continue;
    }
    if (s->p < s->end && *s->p == close) {
      s->p++;
      s->depth--;
      return true;
    }
    return scan_fail(s, object ? "',' or '}' expected" : "',' or ']' expected");
  }
}

static bool scan_value(scan *s) {
  scan_ws(s);
  if (s->p >= s->end)
    return scan_fail(s, "value expected");
  switch (*s->p) {
  case '{': return scan_container(s, '}', true);
  case '[': return scan_container(s, ']', false);
  case '"': return scan_string(s);
  case 't': return scan_lit(s, "true");
  case 'f': return scan_lit(s, "false");
  case 'n': return scan_lit(s, "null");
  default:
    if (*s->p == '-' || isdigit(*s->p))
      return scan_number(s);
    return scan_fail(s, "value expected");
  }
}

/* ------------------------------------------------- tree from valid text */

/* Builds the cJSON tree from text the scanner accepted, so nothing here
 * can be malformed; the only failure is out-of-memory (NULL). It exists
 * because cJSON_ParseWithLengthOpts resets cJSON's process-wide error
 * record on every call, success included: concurrent requests would race
 * on it. cJSON_Create* and cJSON_Add* only read cJSON's global hooks. */
typedef struct build {
  const unsigned char *p;
} build;

static void build_ws(build *b) {
  while (*b->p == ' ' || *b->p == '\t' || *b->p == '\n' || *b->p == '\r')
    b->p++;
}

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

/* A string token, decoded into a malloc'd NUL-terminated buffer. Decoded
 * text is never longer than the token (an escape of 6 or 12 bytes yields
 * at most 4). */
static char *build_string(build *b) {
  const unsigned char *q = ++b->p;
  size_t n = 0;
  unsigned char *o;
  while (*q != '"')
    q += *q == '\\' ? 2 : 1;
  o = malloc((size_t)(q - b->p) + 1);
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

static cJSON *build_number(build *b) {
  const unsigned char *start = b->p;
  char small[64], *text = small, *end;
  size_t n;
  double v;
  while (*b->p != '\0' && strchr("+-0123456789.eE", *b->p) != NULL)
    b->p++;
  n = (size_t)(b->p - start);
  if (n >= sizeof small && (text = malloc(n + 1)) == NULL)
    return NULL;
  memcpy(text, start, n);
  text[n] = '\0';
  v = strtod(text, &end);
  if (text != small)
    free(text);
  return cJSON_CreateNumber(v);
}

static cJSON *build_value(build *b);

static cJSON *build_container(build *b, bool object) {
  cJSON *c = object ? cJSON_CreateObject() : cJSON_CreateArray();
  if (c == NULL)
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
      if ((key = build_string(b)) == NULL)
        goto fail;
      build_ws(b);
      b->p++; /* ':' */
    }
    v = build_value(b);
    if (v == NULL) {
      free(key);
      goto fail;
    }
    if (object) {
      bool added = cJSON_AddItemToObject(c, key, v);
      free(key);
      if (!added) {
        cJSON_Delete(v);
        goto fail;
      }
    } else {
      cJSON_AddItemToArray(c, v);
    }
    build_ws(b);
    if (*b->p++ == ',')
      continue;
    return c; /* '}' or ']' */
  }
fail:
  cJSON_Delete(c);
  return NULL;
}

static cJSON *build_value(build *b) {
  build_ws(b);
  switch (*b->p) {
  case '{': return build_container(b, true);
  case '[': return build_container(b, false);
  case '"': {
    char *str = build_string(b);
    cJSON *v = str != NULL ? cJSON_CreateString(str) : NULL;
    free(str);
    return v;
  }
  case 't': b->p += 4; return cJSON_CreateTrue();
  case 'f': b->p += 5; return cJSON_CreateFalse();
  case 'n': b->p += 4; return cJSON_CreateNull();
  default: return build_number(b);
  }
}

cJSON *api__parse_body(api_ctx *ctx, const char *body, size_t length) {
  scan s;
  cJSON *root;
  if (length > ctx->cfg->max_body_bytes) {
    api__failf(ctx, 413, API_P_TOO_LARGE, "Body too large", NULL,
               "the body has %zu bytes; the limit is %zu", length,
               ctx->cfg->max_body_bytes);
    return NULL;
  }
  if (body == NULL)
    length = 0;
  s.start = s.p = (const unsigned char *)(body != NULL ? body : "");
  s.end = s.p + length;
  s.depth = 0;
  s.max_depth = ctx->cfg->max_json_depth;
  s.error = NULL;
  s.too_deep = false;
  s.too_long = false;
  {
    /* the longest array any field may hold: control points, knots
     * (points + degree + 1), weights, samples, times */
    size_t m = ctx->cfg->max_control_points + 32;
    if (ctx->cfg->max_samples > m) m = ctx->cfg->max_samples;
    if (ctx->cfg->max_frames_job > m) m = ctx->cfg->max_frames_job;
    s.max_array = m;
  }
  /* A UTF-8 byte order mark is tolerated, as cJSON does. */
  if (length >= 3 && memcmp(s.p, "\xef\xbb\xbf", 3) == 0)
    s.p += 3;
  if (scan_value(&s)) {
    scan_ws(&s);
    if (s.p != s.end)
      scan_fail(&s, "unexpected data after the JSON value");
  }
  if (s.error != NULL) {
    if (s.too_long)
      api__failf(ctx, 422, API_P_LIMIT, "Limit exceeded", NULL,
                 "an array holds more than %zu elements (at byte %zu)",
                 s.max_array, (size_t)(s.p - s.start));
    else if (s.too_deep)
      api__failf(ctx, 400, API_P_MALFORMED, "Malformed JSON", NULL,
                 "JSON nested deeper than %zu levels (at byte %zu)",
                 s.max_depth, (size_t)(s.p - s.start));
    else
      api__failf(ctx, 400, API_P_MALFORMED, "Malformed JSON", NULL,
                 "%s at byte %zu", s.error, (size_t)(s.p - s.start));
    return NULL;
  }
  {
    /* The builder reads up to the end of the one value, which the scanner
     * proved lies within `length`; a NUL-terminated copy keeps its
     * look-ahead (number tokens) inside the buffer. */
    char *copy = malloc(length + 1);
    build b;
    if (copy == NULL) {
      api__oom(ctx);
      return NULL;
    }
    memcpy(copy, s.start, length);
    copy[length] = '\0';
    b.p = (const unsigned char *)copy;
    if (length >= 3 && memcmp(copy, "\xef\xbb\xbf", 3) == 0)
      b.p += 3;
    root = build_value(&b);
    free(copy);
  }
  if (root == NULL) {
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

/* ---------------------------------------------------------------- dispatch */

int api_handle(const api_config *cfg, const api_request *req,
               api_response *out) {
  api_config defaults;
  api_ctx ctx;
  if (cfg == NULL) {
    api_config_default(&defaults);
    cfg = &defaults;
  }
  api_response_init(out);
  api__ctx_init(&ctx, cfg);
  switch (req->route) {
  case API_ROUTE_SIGNATURE:
    return api__route_signature(&ctx, req, out);
  case API_ROUTE_RECONSTRUCT:
    return api__route_reconstruct(&ctx, req, out);
  case API_ROUTE_MORPH: {
    api_morph_plan *plan = NULL;
    int st = api_morph_prepare(cfg, req, cfg->max_frames_sync, &plan, out);
    if (st != 0)
      return st;
    /* frames under the request's stop; a stopped or failed one is
     * reported by api_morph_result */
    for (size_t i = 0; req->stop != NULL && i < api_morph_frame_count(plan);
         i++)
      if (api_morph_render_frame_until(plan, i, req->stop, req->stop_ctx) ==
          503)
        break;
    st = api_morph_result(plan, out);
    api_morph_plan_free(plan);
    return st;
  }
  default:
    api_problem(out, 404, API_P_NOT_FOUND, "Not found", "unknown route",
                NULL, NULL, req->request_id);
    return out->status;
  }
}
