/* svg_parse.c - SVG 1.1 path data (the `d` attribute) into one exact curve.
 *
 * DESIGN. A hand-written scanner over the SVG 1.1 path grammar (section
 * 8.3.9): commands M L H V C S Q T A Z in both cases, implicit repetition
 * of a command's argument set, implicit lineto after a moveto, numbers in
 * every form the grammar allows ("1e-3", ".5.5" = 0.5 0.5, "-1-2"), arc
 * flags written without separators ("a1 1 0 00 1 1") and comma-wsp where
 * the grammar allows it. Geometry goes straight into a km_path builder,
 * which keeps every piece exact. Only one subpath is accepted: a moveto or
 * a drawing command after the path was drawn and closed is an error, except
 * trailing movetos that draw nothing. Every error carries the character
 * offset and what the grammar expected there.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "km/path.h"
#include "svg.h"

typedef struct parser {
  const char *s;
  size_t len, pos;
  size_t err_off;
  char *msg;
  size_t msgcap;
} parser;

static bool is_wsp(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f';
}
static bool is_digit(char c) { return c >= '0' && c <= '9'; }

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
  if (c >= 0x21 && c < 0x7f) snprintf(buf, 16, "'%c'", c);
  else snprintf(buf, 16, "byte 0x%02x", c);
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
    return fail(ps, start, KM_EINVAL, "expected %s (a number), found %s",
                what, found(ps, fb));
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
  char *buf = n < sizeof small ? small : malloc(n + 1);
  if (!buf) return fail(ps, start, KM_ENOMEM, "out of memory");
  memcpy(buf, s + start, n);
  buf[n] = '\0';
  double v = strtod(buf, NULL);
  if (buf != small) free(buf);
  if (!isfinite(v))
    return fail(ps, start, KM_ERANGE, "%s is too large for a double",
                what);
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
  return fail(ps, ps->pos, KM_EINVAL, "expected %s (0 or 1), found %s",
              what, found(ps, fb));
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

km_status api_svg_parse_path(const char *d, size_t len, double tol,
                             km_curve *out, size_t *err_offset, char *msg,
                             size_t msgcap) {
  parser ps = {d ? d : "", d ? len : 0, 0, 0, msg, msgcap};
  km_path path;
  km_path_init(&path);
  km_error e;
  km_status st = KM_OK;
  char fb[16];
  char cmd = 0;          /* current command letter */
  char prev = 0;         /* previous command, for S and T reflection */
  bool drawn = false;    /* a drawing command (or Z) was seen */
  bool done = false;     /* Z seen: further drawing is a second subpath */
  double cx = 0, cy = 0; /* current point */
  double sx = 0, sy = 0; /* subpath start */
  double lcx = 0, lcy = 0; /* last control point (S, T) */
  if (msg && msgcap) msg[0] = '\0';

  skip_wsp(&ps);
  if (ps.pos >= ps.len) {
    st = fail(&ps, ps.pos, KM_EINVAL, "%s",
              "expected a moveto (M or m): path data is empty");
    goto cleanup;
  }
  if (ps.s[ps.pos] != 'M' && ps.s[ps.pos] != 'm') {
    st = fail(&ps, ps.pos, KM_EINVAL,
              "expected a moveto (M or m) at the start, found %s",
              found(&ps, fb));
    goto cleanup;
  }
  while (ps.pos < ps.len) {
    size_t cmd_off = ps.pos;
    char c = ps.s[ps.pos];
    if (!strchr("MmZzLlHhVvCcSsQqTtAa", c) || c == '\0') {
      st = fail(&ps, ps.pos, KM_EINVAL,
                "expected a path command (M L H V C S Q T A Z), found %s",
                found(&ps, fb));
      goto cleanup;
    }
    cmd = c;
    ps.pos++;
    skip_wsp(&ps);
    bool rel = cmd >= 'a';
    char up = (char)(rel ? cmd - 32 : cmd);

    if (up == 'Z') {
      /* A second Z on an already closed path draws nothing. */
      if (!done) {
        if (!drawn) {
          st = fail(&ps, cmd_off, KM_EDEGENERATE, "%s",
                    "closepath before any drawing command: path draws "
                    "nothing");
          goto cleanup;
        }
        st = km_path_close(&path, &e);
        if (st) {
          st = geom_fail(&ps, cmd_off, st, &e);
          goto cleanup;
        }
        done = true;
      }
      cx = sx;
      cy = sy;
      prev = 'Z';
      continue;
    }

    /* Argument sets; the first is required, more repeat the command. */
    bool first = true;
    for (;;) {
      size_t arg_off = ps.pos;
      if (!first) {
        /* comma-wsp between argument sets, none after the last one. */
        skip_wsp(&ps);
        if (ps.pos < ps.len && ps.s[ps.pos] == ',') {
          ps.pos++;
          skip_wsp(&ps);
          if (!number_ahead(&ps)) {
            st = fail(&ps, ps.pos, KM_EINVAL,
                      "expected a number after ',', found %s",
                      found(&ps, fb));
            goto cleanup;
          }
        } else if (!number_ahead(&ps)) {
          break;
        }
        arg_off = ps.pos;
      }
      double v[7];
      double ox = rel ? cx : 0.0, oy = rel ? cy : 0.0;
      if (up == 'M' && !first) up = 'L'; /* implicit lineto */
      if ((up != 'M') && done) {
        st = fail(&ps, first ? cmd_off : arg_off, KM_EINVAL, "%s",
                  "a second subpath: one subpath per curve (the path "
                  "was closed)");
        goto cleanup;
      }
      switch (up) {
      case 'M':
        st = parse_args(&ps, 2, N_XY, v);
        if (st) goto cleanup;
        if (drawn) {
          /* Only a trailing moveto that draws nothing is tolerated. */
          skip_wsp(&ps);
          size_t save = ps.pos;
          if (ps.pos < ps.len) {
            st = fail(&ps, cmd_off, KM_EINVAL, "%s",
                      "a second subpath (moveto after drawing): one "
                      "subpath per curve");
            goto cleanup;
          }
          ps.pos = save;
          cx = ox + v[0];
          cy = oy + v[1];
          break;
        }
        cx = sx = ox + v[0];
        cy = sy = oy + v[1];
        /* Consecutive movetos before drawing just move the start. */
        km_path_free(&path);
        km_path_init(&path);
        st = km_path_move_to(&path, cx, cy, &e);
        if (st) {
          st = geom_fail(&ps, arg_off, st, &e);
          goto cleanup;
        }
        break;
      case 'L':
        st = parse_args(&ps, 2, N_XY, v);
        if (!st) {
          cx = ox + v[0];
          cy = oy + v[1];
          st = km_path_line_to(&path, cx, cy, &e);
          if (st) st = geom_fail(&ps, arg_off, st, &e);
        }
        break;
      case 'H':
        st = parse_args(&ps, 1, N_H, v);
        if (!st) {
          cx = ox + v[0];
          st = km_path_line_to(&path, cx, cy, &e);
          if (st) st = geom_fail(&ps, arg_off, st, &e);
        }
        break;
      case 'V':
        st = parse_args(&ps, 1, N_V, v);
        if (!st) {
          cy = oy + v[0];
          st = km_path_line_to(&path, cx, cy, &e);
          if (st) st = geom_fail(&ps, arg_off, st, &e);
        }
        break;
      case 'C':
        st = parse_args(&ps, 6, N_C, v);
        if (!st) {
          double x1 = ox + v[0], y1 = oy + v[1];
          lcx = ox + v[2];
          lcy = oy + v[3];
          cx = ox + v[4];
          cy = oy + v[5];
          st = km_path_cubic_to(&path, x1, y1, lcx, lcy, cx, cy, &e);
          if (st) st = geom_fail(&ps, arg_off, st, &e);
        }
        break;
      case 'S':
        st = parse_args(&ps, 4, N_S, v);
        if (!st) {
          /* First control point: reflection of the previous cubic's
           * second one, else the current point (SVG 1.1, 8.3.6). */
          double x1 = cx, y1 = cy;
          if (prev == 'C' || prev == 'S') {
            x1 = 2 * cx - lcx;
            y1 = 2 * cy - lcy;
          }
          lcx = ox + v[0];
          lcy = oy + v[1];
          cx = ox + v[2];
          cy = oy + v[3];
          st = km_path_cubic_to(&path, x1, y1, lcx, lcy, cx, cy, &e);
          if (st) st = geom_fail(&ps, arg_off, st, &e);
        }
        break;
      case 'Q':
        st = parse_args(&ps, 4, N_Q, v);
        if (!st) {
          lcx = ox + v[0];
          lcy = oy + v[1];
          cx = ox + v[2];
          cy = oy + v[3];
          st = km_path_quad_to(&path, lcx, lcy, cx, cy, &e);
          if (st) st = geom_fail(&ps, arg_off, st, &e);
        }
        break;
      case 'T':
        st = parse_args(&ps, 2, N_XY, v);
        if (!st) {
          if (prev == 'Q' || prev == 'T') {
            lcx = 2 * cx - lcx;
            lcy = 2 * cy - lcy;
          } else {
            lcx = cx;
            lcy = cy;
          }
          cx = ox + v[0];
          cy = oy + v[1];
          st = km_path_quad_to(&path, lcx, lcy, cx, cy, &e);
          if (st) st = geom_fail(&ps, arg_off, st, &e);
        }
        break;
      case 'A': {
        bool large = false, sweep = false;
        st = parse_number(&ps, "rx", &v[0]);
        if (!st) {
          skip_comma_wsp(&ps);
          st = parse_number(&ps, "ry", &v[1]);
        }
        if (!st) {
          skip_comma_wsp(&ps);
          st = parse_number(&ps, "x-axis-rotation", &v[2]);
        }
        if (!st) {
          skip_comma_wsp(&ps);
          st = parse_flag(&ps, "large-arc-flag", &large);
        }
        if (!st) {
          skip_comma_wsp(&ps);
          st = parse_flag(&ps, "sweep-flag", &sweep);
        }
        if (!st) {
          skip_comma_wsp(&ps);
          st = parse_args(&ps, 2, N_XY, v + 3);
        }
        if (!st) {
          cx = ox + v[3];
          cy = oy + v[4];
          st = km_path_arc_to(&path, v[0], v[1], v[2], large, sweep, cx, cy,
                              &e);
          if (st) st = geom_fail(&ps, arg_off, st, &e);
        }
        break;
      }
      default:
        break;
      }
      if (st) goto cleanup;
      if (up != 'M') drawn = true;
      /* Coordinates reached by relative sums must stay representable. */
      if (!isfinite(cx) || !isfinite(cy)) {
        st = fail(&ps, arg_off, KM_ERANGE, "%s",
                  "coordinate is too large for a double");
        goto cleanup;
      }
      prev = up;
      first = false;
    }
  }

  {
    double eps = 1e-9 * extent_of(&path);
    if (tol > 0 && tol < eps) eps = tol;
    km_curve c;
    km_curve_init(&c);
    st = km_path_to_curve(&path, eps, &c, &e);
    if (st) {
      st = fail(&ps, 0, st, "%s", e.message);
      goto cleanup;
    }
    *out = c;
  }

cleanup:
  if (st && err_offset) *err_offset = ps.err_off;
  km_path_free(&path);
  return st;
}
