/* svg_parse.c - SVG 1.1 path data (the `d` attribute) into one exact curve.
 *
 * DESIGN. A hand-written scanner over the SVG 1.1 path grammar (section
 * 8.3.9): commands M L H V C S Q T A Z in both cases, implicit repetition
 * of a command's argument set, implicit lineto after a moveto, numbers in
 * every form the grammar allows ("1e-3", ".5.5" = 0.5 0.5, "-1-2"), arc
 * flags written without separators ("a1 1 0 00 1 1") and comma-wsp where
 * the grammar allows it. Geometry goes straight into a km_path builder,
 * which keeps every piece exact. api_svg_parse_path accepts one subpath:
 * a moveto or a drawing command after the path was drawn and closed is an
 * error, except trailing movetos that draw nothing. api_svg_parse_subpaths
 * runs the same scanner and finishes a curve at every further moveto (or
 * drawing after a Z), so its first subpath is what the other would give. Every error carries the character
 * offset and what the grammar expected there.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "km/alloc.h"
#include "km/path.h"
#include "svg.h"

typedef struct parser {
  const char *s;
  size_t len, pos;
  size_t err_off;
  char *msg;
  size_t msgcap;
  /* Several subpaths allowed (api_svg_parse_subpaths): the finished ones,
   * the offset of each one's moveto, and the bound on their count. */
  bool multi;
  km_curve *subs;
  size_t *sub_offs;
  size_t nsub, capsub, maxsub;
  size_t cur_off; /* offset of the current subpath's moveto */
  double tol;
} parser;

static bool is_wsp(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f';
}
static bool is_digit(char c) {
  return c >= '0' && c <= '9';
}

static km_status fail(parser *ps, size_t off, km_status st, const char *fmt,
                      ...) __attribute__((format(printf, 4, 5)));
static km_status fail(parser *ps, size_t off, km_status st, const char *fmt,
                      ...) {
  ps->err_off = off;
  if (ps->msg && ps->msgcap) {
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(ps->msg, ps->msgcap, fmt, ap);
    va_end(ap);
  }
  return st;
}

static void skip_wsp(parser *ps) {
  while (ps->pos < ps->len && is_wsp(ps->s[ps->pos])) ps->pos++;
}

/* comma-wsp?: wsp* ','? wsp* */
static void skip_comma_wsp(parser *ps) {
  skip_wsp(ps);
  if (ps->pos < ps->len && ps->s[ps->pos] == ',') {
    ps->pos++;
    skip_wsp(ps);
  }
}

/* Does a number start here? */
static bool number_ahead(const parser *ps) {
  if (ps->pos >= ps->len) return false;
  char c = ps->s[ps->pos];
  return is_digit(c) || c == '.' || c == '-' || c == '+';
}

/* Describe the character at pos for messages. */
static const char *found(const parser *ps, char buf[16]) {
  if (ps->pos >= ps->len) return "end of path data";
  unsigned char c = (unsigned char)ps->s[ps->pos];
  if (c >= 0x21 && c < 0x7f)
    snprintf(buf, 16, "'%c'", c);
  else
    snprintf(buf, 16, "byte 0x%02x", c);
  return buf;
}

/* number: sign? (digit+ ('.' digit*)? | '.' digit+) exponent?
 * exponent: ('e'|'E') sign? digit+ (an 'e' without digits is not part of
 * the number, so it ends up as an unknown command). */
static km_status parse_number(parser *ps, const char *what, double *out) {
  char fb[16];
  size_t start = ps->pos, i = ps->pos;
  const char *s = ps->s;
  if (i < ps->len && (s[i] == '+' || s[i] == '-')) i++;
  size_t int_start = i;
  while (i < ps->len && is_digit(s[i])) i++;
  size_t nint = i - int_start, nfrac = 0;
  if (i < ps->len && s[i] == '.') {
    size_t f0 = ++i;
    while (i < ps->len && is_digit(s[i])) i++;
    nfrac = i - f0;
    if (nint == 0 && nfrac == 0) i = f0 - 1;
  }
  if (nint == 0 && nfrac == 0) {
    return fail(ps, start, KM_EINVAL, "expected %s (a number), found %s", what,
                found(ps, fb));
  }
  if (i < ps->len && (s[i] == 'e' || s[i] == 'E')) {
    size_t j = i + 1;
    if (j < ps->len && (s[j] == '+' || s[j] == '-')) j++;
    if (j < ps->len && is_digit(s[j])) {
      while (j < ps->len && is_digit(s[j])) j++;
      i = j;
    }
  }
  size_t n = i - start;
  char small[64];
  char *buf = n < sizeof small ? small : km__malloc(n + 1);
  if (!buf) return fail(ps, start, KM_ENOMEM, "out of memory");
  memcpy(buf, s + start, n);
  buf[n] = '\0';
  double v = strtod(buf, NULL);
  if (buf != small) km__free(buf);
  if (!isfinite(v))
    return fail(ps, start, KM_ERANGE, "%s is too large for a double", what);
  ps->pos = i;
  *out = v;
  return KM_OK;
}

/* flag: '0' | '1', no separator needed after it. */
static km_status parse_flag(parser *ps, const char *what, bool *out) {
  char fb[16];
  if (ps->pos < ps->len && (ps->s[ps->pos] == '0' || ps->s[ps->pos] == '1')) {
    *out = ps->s[ps->pos] == '1';
    ps->pos++;
    return KM_OK;
  }
  return fail(ps, ps->pos, KM_EINVAL, "expected %s (0 or 1), found %s", what,
              found(ps, fb));
}

/* Read n numbers separated by comma-wsp?; names[i] says what each is. */
static km_status parse_args(parser *ps, int n, const char *const *names,
                            double *v) {
  for (int i = 0; i < n; i++) {
    if (i > 0) skip_comma_wsp(ps);
    km_status st = parse_number(ps, names[i], &v[i]);
    if (st) return st;
  }
  return KM_OK;
}

static const char *const N_XY[] = {"x", "y"};
static const char *const N_H[] = {"x"};
static const char *const N_V[] = {"y"};
static const char *const N_C[] = {"x1", "y1", "x2", "y2", "x", "y"};
static const char *const N_S[] = {"x2", "y2", "x", "y"};
static const char *const N_Q[] = {"x1", "y1", "x", "y"};

/* Map a builder failure onto the offset of the argument set. */
static km_status geom_fail(parser *ps, size_t off, km_status st,
                           const km_error *e) {
  return fail(ps, off, st, "%s", e->message);
}

static double extent_of(const km_path *p) {
  double e = 0.0;
  for (size_t i = 0; i < p->npieces; i++)
    for (int j = 0; j <= p->pieces[i].degree; j++) {
      double dx = fabs(p->pieces[i].p[j][0] - p->start[0]);
      double dy = fabs(p->pieces[i].p[j][1] - p->start[1]);
      if (dx > e) e = dx;
      if (dy > e) e = dy;
    }
  return e;
}

/* Where drawing stands: the path so far, the current point, the
 * subpath's start, the last control point and command (for S and T). */
typedef struct pen {
  km_path path;
  char prev;       /* previous command, for S and T reflection */
  bool drawn;      /* a drawing command (or Z) was seen */
  bool done;       /* Z seen: further drawing is a second subpath */
  double cx, cy;   /* current point */
  double sx, sy;   /* subpath start */
  double lcx, lcy; /* last control point (S, T) */
} pen;

static km_status finish_subpath(parser *ps, pen *pn);

/* The path data must start with a moveto. */
static km_status expect_moveto(parser *ps) {
  char fb[16];
  skip_wsp(ps);
  if (ps->pos >= ps->len)
    return fail(ps, ps->pos, KM_EINVAL, "%s",
                "expected a moveto (M or m): path data is empty");
  if (ps->s[ps->pos] != 'M' && ps->s[ps->pos] != 'm')
    return fail(ps, ps->pos, KM_EINVAL,
                "expected a moveto (M or m) at the start, found %s",
                found(ps, fb));
  return KM_OK;
}

/* Z: close the path (a second Z on a closed path draws nothing). */
static km_status close_path(parser *ps, pen *pn, size_t cmd_off) {
  km_error e;
  if (!pn->done) {
    if (!pn->drawn)
      return fail(ps, cmd_off, KM_EDEGENERATE, "%s",
                  "closepath before any drawing command: path draws "
                  "nothing");
    km_status st = km_path_close(&pn->path, &e);
    if (st) return geom_fail(ps, cmd_off, st, &e);
    pn->done = true;
  }
  pn->cx = pn->sx;
  pn->cy = pn->sy;
  pn->prev = 'Z';
  return KM_OK;
}

/* Between argument sets: comma-wsp, none after the last one. *more says
 * whether another set follows. */
static km_status next_set(parser *ps, bool *more) {
  char fb[16];
  skip_wsp(ps);
  *more = true;
  if (ps->pos < ps->len && ps->s[ps->pos] == ',') {
    ps->pos++;
    skip_wsp(ps);
    if (!number_ahead(ps))
      return fail(ps, ps->pos, KM_EINVAL,
                  "expected a number after ',', found %s", found(ps, fb));
  } else if (!number_ahead(ps)) {
    *more = false;
  }
  return KM_OK;
}

/* M's argument set at (ox, oy) + (x, y). */
static km_status move_to(parser *ps, pen *pn, double ox, double oy,
                         size_t cmd_off, size_t arg_off) {
  double v[2];
  km_error e;
  km_status st = parse_args(ps, 2, N_XY, v);
  if (st) return st;
  if (pn->drawn && ps->multi) {
    /* The subpath so far is finished; this moveto starts the next one,
     * relative to where the last one ended (its start, after a Z). */
    if ((st = finish_subpath(ps, pn)) != KM_OK) return st;
    ps->cur_off = cmd_off;
  } else if (pn->drawn) {
    /* Only a trailing moveto that draws nothing is tolerated. */
    skip_wsp(ps);
    if (ps->pos < ps->len)
      return fail(ps, cmd_off, KM_EINVAL, "%s",
                  "a second subpath (moveto after drawing): one "
                  "subpath per curve");
    pn->cx = ox + v[0];
    pn->cy = oy + v[1];
    return KM_OK;
  }
  pn->cx = pn->sx = ox + v[0];
  pn->cy = pn->sy = oy + v[1];
  /* Consecutive movetos before drawing just move the start. */
  km_path_free(&pn->path);
  km_path_init(&pn->path);
  st = km_path_move_to(&pn->path, pn->cx, pn->cy, &e);
  return st ? geom_fail(ps, arg_off, st, &e) : KM_OK;
}

/* L, H or V's argument set. */
static km_status line_to(parser *ps, pen *pn, char up, double ox, double oy) {
  double v[2];
  km_error e;
  km_status st;
  size_t arg_off = ps->pos;
  if (up == 'L') {
    if ((st = parse_args(ps, 2, N_XY, v))) return st;
    pn->cx = ox + v[0];
    pn->cy = oy + v[1];
  } else if (up == 'H') {
    if ((st = parse_args(ps, 1, N_H, v))) return st;
    pn->cx = ox + v[0];
  } else {
    if ((st = parse_args(ps, 1, N_V, v))) return st;
    pn->cy = oy + v[0];
  }
  st = km_path_line_to(&pn->path, pn->cx, pn->cy, &e);
  return st ? geom_fail(ps, arg_off, st, &e) : KM_OK;
}

/* C or S's argument set. */
static km_status cubic_to(parser *ps, pen *pn, char up, double ox, double oy) {
  double v[6], x1 = pn->cx, y1 = pn->cy;
  km_error e;
  km_status st;
  size_t arg_off = ps->pos;
  if (up == 'C') {
    if ((st = parse_args(ps, 6, N_C, v))) return st;
    x1 = ox + v[0];
    y1 = oy + v[1];
  } else {
    if ((st = parse_args(ps, 4, N_S, v + 2))) return st;
    /* First control point: reflection of the previous cubic's second
     * one, else the current point (SVG 1.1, 8.3.6). */
    if (pn->prev == 'C' || pn->prev == 'S') {
      x1 = 2 * pn->cx - pn->lcx;
      y1 = 2 * pn->cy - pn->lcy;
    }
  }
  pn->lcx = ox + v[2];
  pn->lcy = oy + v[3];
  pn->cx = ox + v[4];
  pn->cy = oy + v[5];
  st =
      km_path_cubic_to(&pn->path, x1, y1, pn->lcx, pn->lcy, pn->cx, pn->cy, &e);
  return st ? geom_fail(ps, arg_off, st, &e) : KM_OK;
}

/* Q or T's argument set. */
static km_status quad_to(parser *ps, pen *pn, char up, double ox, double oy) {
  double v[4];
  km_error e;
  km_status st;
  size_t arg_off = ps->pos;
  if (up == 'Q') {
    if ((st = parse_args(ps, 4, N_Q, v))) return st;
    pn->lcx = ox + v[0];
    pn->lcy = oy + v[1];
  } else {
    if ((st = parse_args(ps, 2, N_XY, v + 2))) return st;
    if (pn->prev == 'Q' || pn->prev == 'T') {
      pn->lcx = 2 * pn->cx - pn->lcx;
      pn->lcy = 2 * pn->cy - pn->lcy;
    } else {
      pn->lcx = pn->cx;
      pn->lcy = pn->cy;
    }
  }
  pn->cx = ox + v[2];
  pn->cy = oy + v[3];
  st = km_path_quad_to(&pn->path, pn->lcx, pn->lcy, pn->cx, pn->cy, &e);
  return st ? geom_fail(ps, arg_off, st, &e) : KM_OK;
}

/* A's argument set: rx ry rotation large-arc sweep x y. */
static km_status arc_to(parser *ps, pen *pn, double ox, double oy) {
  double v[5];
  bool large = false, sweep = false;
  km_error e;
  size_t arg_off = ps->pos;
  km_status st = parse_number(ps, "rx", &v[0]);
  if (!st) {
    skip_comma_wsp(ps);
    st = parse_number(ps, "ry", &v[1]);
  }
  if (!st) {
    skip_comma_wsp(ps);
    st = parse_number(ps, "x-axis-rotation", &v[2]);
  }
  if (!st) {
    skip_comma_wsp(ps);
    st = parse_flag(ps, "large-arc-flag", &large);
  }
  if (!st) {
    skip_comma_wsp(ps);
    st = parse_flag(ps, "sweep-flag", &sweep);
  }
  if (!st) {
    skip_comma_wsp(ps);
    st = parse_args(ps, 2, N_XY, v + 3);
  }
  if (st) return st;
  pn->cx = ox + v[3];
  pn->cy = oy + v[4];
  st = km_path_arc_to(&pn->path, v[0], v[1], v[2], large, sweep, pn->cx, pn->cy,
                      &e);
  return st ? geom_fail(ps, arg_off, st, &e) : KM_OK;
}

/* One argument set of command up (M after its first set is L), relative
 * when rel; offsets name the command and the set in errors. */
static km_status argument_set(parser *ps, pen *pn, char up, bool rel,
                              bool first, size_t cmd_off, size_t arg_off) {
  double ox = rel ? pn->cx : 0.0, oy = rel ? pn->cy : 0.0;
  km_status st = KM_OK;
  if (up != 'M' && pn->done && ps->multi) {
    /* Drawing after a Z without a moveto starts a subpath at the last
     * one's start (SVG 1.1, 8.3.3). */
    km_error e;
    if ((st = finish_subpath(ps, pn)) != KM_OK) return st;
    ps->cur_off = first ? cmd_off : arg_off;
    if ((st = km_path_move_to(&pn->path, pn->cx, pn->cy, &e)) != KM_OK)
      return geom_fail(ps, ps->cur_off, st, &e);
  }
  if ((up != 'M') && pn->done)
    return fail(ps, first ? cmd_off : arg_off, KM_EINVAL, "%s",
                "a second subpath: one subpath per curve (the path "
                "was closed)");
  switch (up) {
  case 'M': st = move_to(ps, pn, ox, oy, cmd_off, arg_off); break;
  case 'L':
  case 'H':
  case 'V': st = line_to(ps, pn, up, ox, oy); break;
  case 'C':
  case 'S': st = cubic_to(ps, pn, up, ox, oy); break;
  case 'Q':
  case 'T': st = quad_to(ps, pn, up, ox, oy); break;
  case 'A': st = arc_to(ps, pn, ox, oy); break;
  default: break;
  }
  if (st) return st;
  if (up != 'M') pn->drawn = true;
  /* Coordinates reached by relative sums must stay representable. */
  if (!isfinite(pn->cx) || !isfinite(pn->cy))
    return fail(ps, arg_off, KM_ERANGE, "%s",
                "coordinate is too large for a double");
  pn->prev = up;
  return KM_OK;
}

/* A command at cmd_off (its letter read) and all its argument sets; the
 * first is required, more repeat the command. */
static km_status command(parser *ps, pen *pn, char cmd, size_t cmd_off) {
  bool rel = cmd >= 'a', first = true, more = true;
  char up = (char)(rel ? cmd - 32 : cmd);
  if (up == 'Z') return close_path(ps, pn, cmd_off);
  for (;;) {
    size_t arg_off = ps->pos;
    if (!first) {
      km_status st = next_set(ps, &more);
      if (st) return st;
      if (!more) return KM_OK;
      arg_off = ps->pos;
      if (up == 'M') up = 'L'; /* implicit lineto */
    }
    km_status st = argument_set(ps, pn, up, rel, first, cmd_off, arg_off);
    if (st) return st;
    first = false;
  }
}

/* The path as one curve: pieces within min(tol, 1e-9 x extent) of a
 * point dropped. */
static km_status to_curve(parser *ps, const pen *pn, double tol,
                          km_curve *out) {
  double eps = 1e-9 * extent_of(&pn->path);
  km_curve c;
  km_error e;
  km_status st;
  if (tol > 0 && tol < eps) eps = tol;
  km_curve_init(&c);
  st = km_path_to_curve(&pn->path, eps, &c, &e);
  if (st) return fail(ps, 0, st, "%s", e.message);
  *out = c;
  return KM_OK;
}

/* The drawn subpath as a curve appended to ps->subs, its offset to
 * ps->sub_offs; the pen is left empty for the next one. A subpath past
 * ps->maxsub is KM_ELIMIT at its moveto; one that draws nothing is the
 * builder's failure at its moveto. */
static km_status finish_subpath(parser *ps, pen *pn) {
  km_curve c;
  km_status st;
  if (ps->nsub == ps->maxsub)
    return fail(ps, ps->cur_off, KM_ELIMIT,
                "subpath %zu is one past the limit of %zu subpaths", ps->nsub,
                ps->maxsub);
  if (ps->nsub == ps->capsub) {
    size_t cap = ps->capsub ? 2 * ps->capsub : 4;
    km_curve *c2 = km__realloc(ps->subs, cap * sizeof *c2);
    if (c2 == NULL)
      return fail(ps, ps->cur_off, KM_ENOMEM, "%s", "out of memory");
    ps->subs = c2;
    size_t *o2 = km__realloc(ps->sub_offs, cap * sizeof *o2);
    if (o2 == NULL)
      return fail(ps, ps->cur_off, KM_ENOMEM, "%s", "out of memory");
    ps->sub_offs = o2;
    ps->capsub = cap;
  }
  if ((st = to_curve(ps, pn, ps->tol, &c)) != KM_OK) {
    /* A path of one subpath fails as api_svg_parse_path would. */
    if (ps->nsub == 0 && ps->pos >= ps->len) return st;
    if (st == KM_EDEGENERATE)
      return fail(ps, ps->cur_off, st,
                  "subpath %zu has zero length (it draws nothing)", ps->nsub);
    ps->err_off = ps->cur_off;
    return st;
  }
  ps->subs[ps->nsub] = c;
  ps->sub_offs[ps->nsub++] = ps->cur_off;
  km_path_free(&pn->path);
  km_path_init(&pn->path);
  pn->drawn = pn->done = false;
  return KM_OK;
}

km_status api_svg_parse_subpaths(const char *d, size_t len, double tol,
                                 size_t max_subpaths, km_curve **out,
                                 size_t **offsets, size_t *n,
                                 size_t *err_offset, char *msg, size_t msgcap) {
  parser ps = {.s = d ? d : "",
               .len = d ? len : 0,
               .msg = msg,
               .msgcap = msgcap,
               .multi = true};
  pen pn = {.prev = 0};
  km_status st;
  char fb[16];
  km_path_init(&pn.path);
  if (msg && msgcap) msg[0] = '\0';
  ps.maxsub = max_subpaths > 0 ? max_subpaths : 1;
  ps.tol = tol;

  if ((st = expect_moveto(&ps))) goto cleanup;
  ps.cur_off = ps.pos;
  while (ps.pos < ps.len) {
    size_t cmd_off = ps.pos;
    char c = ps.s[ps.pos];
    if (!strchr("MmZzLlHhVvCcSsQqTtAa", c) || c == '\0') {
      st = fail(&ps, ps.pos, KM_EINVAL,
                "expected a path command (M L H V C S Q T A Z), found %s",
                found(&ps, fb));
      goto cleanup;
    }
    ps.pos++;
    skip_wsp(&ps);
    if ((st = command(&ps, &pn, c, cmd_off))) goto cleanup;
  }
  if (pn.drawn && (st = finish_subpath(&ps, &pn)) != KM_OK) goto cleanup;
  if (ps.nsub == 0) {
    st = fail(&ps, 0, KM_EDEGENERATE, "%s", "the path draws nothing");
    goto cleanup;
  }
  *out = ps.subs;
  *offsets = ps.sub_offs;
  *n = ps.nsub;
  ps.subs = NULL;
  ps.sub_offs = NULL;
  ps.nsub = 0;

cleanup:
  if (st && err_offset) *err_offset = ps.err_off;
  for (size_t i = 0; i < ps.nsub; i++) km_curve_free(&ps.subs[i]);
  km__free(ps.subs);
  km__free(ps.sub_offs);
  km_path_free(&pn.path);
  return st;
}

km_status api_svg_parse_path(const char *d, size_t len, double tol,
                             km_curve *out, size_t *err_offset, char *msg,
                             size_t msgcap) {
  parser ps = {
      .s = d ? d : "", .len = d ? len : 0, .msg = msg, .msgcap = msgcap};
  pen pn = {.prev = 0};
  km_status st;
  char fb[16];
  km_path_init(&pn.path);
  if (msg && msgcap) msg[0] = '\0';

  if ((st = expect_moveto(&ps))) goto cleanup;
  while (ps.pos < ps.len) {
    size_t cmd_off = ps.pos;
    char c = ps.s[ps.pos];
    if (!strchr("MmZzLlHhVvCcSsQqTtAa", c) || c == '\0') {
      st = fail(&ps, ps.pos, KM_EINVAL,
                "expected a path command (M L H V C S Q T A Z), found %s",
                found(&ps, fb));
      goto cleanup;
    }
    ps.pos++;
    skip_wsp(&ps);
    if ((st = command(&ps, &pn, c, cmd_off))) goto cleanup;
  }
  st = to_curve(&ps, &pn, tol, out);

cleanup:
  if (st && err_offset) *err_offset = ps.err_off;
  km_path_free(&pn.path);
  return st;
}
