/* morph_match.c - matches "auto": corresponding features of two inputs.
 *
 * DESIGN. Features (corners and curvature extrema, with the turning they
 * carry) are aligned by dynamic programming over both sequences, rewarding
 * pairs of like turning and penalising drift in r.
 */
#include <math.h>
#include <stddef.h>

#include "internal.h"
#include "morph_match.h"

typedef struct feature {
  double r;    /* position, fraction of length */
  double turn; /* turning carried (corner turn, or integral of kappa over the
                  extremum's neighbourhood) */
} feature;

static size_t find_features(const km__input *in, feature *f, size_t cap) {
  size_t n = 0;
  double L = in->sig.length;
  for (size_t i = 0; i < in->sig.ncorners && n < cap; i++) {
    if (in->sig.corners[i].s >= L * (1 - 1e-12)) continue;
    if (fabs(in->sig.corners[i].turn) > 0.2) {
      f[n].r = in->sig.corners[i].s / L;
      f[n].turn = in->sig.corners[i].turn;
      n++;
    }
  }
  /* curvature extrema: local maxima of |kappa| on a grid, with the turning
   * within a window around them */
  enum { G = 400 };
  double kv[G + 1];
  for (int j = 0; j <= G; j++) kv[j] = km__pp_eval(&in->kappa, L * j / G);
  double kmax = 0.0;
  for (int j = 0; j <= G; j++) kmax = fmax(kmax, fabs(kv[j]));
  for (int j = 1; j < G && n < cap; j++) {
    double v = fabs(kv[j]);
    if (v > fabs(kv[j - 1]) && v >= fabs(kv[j + 1]) && v > 0.3 * kmax &&
        v * L > 4.0) {
      int w = 10;
      double lo = L * fmax(0, j - w) / G, hi = L * fmin(G, j + w) / G;
      double turn = km__input_theta_at(in, hi) - km__input_theta_at(in, lo);
      if (fabs(turn) > 0.2) {
        f[n].r = (double)j / G;
        f[n].turn = turn;
        n++;
      }
    }
  }
  /* sort by r */
  for (size_t i = 1; i < n; i++)
    for (size_t j = i; j > 0 && f[j].r < f[j - 1].r; j--) {
      feature t = f[j];
      f[j] = f[j - 1];
      f[j - 1] = t;
    }
  return n;
}

/* Align feature sequences by dynamic programming (longest-path over pairs
 * with a score for like turning and a penalty for drift in r). */
size_t km__auto_matches(const km__input *a, const km__input *b, double *pairs,
                        size_t cap) {
  enum { F = 64 };
  feature fa[F], fb[F];
  size_t na = find_features(a, fa, F), nb = find_features(b, fb, F);
  if (na == 0 || nb == 0) return 0;
  double score[F + 1][F + 1];
  int move[F + 1][F + 1];
  for (size_t i = 0; i <= na; i++)
    for (size_t j = 0; j <= nb; j++) {
      if (i == 0 || j == 0) {
        score[i][j] = 0;
        move[i][j] = 0;
        continue;
      }
      double best = score[i - 1][j];
      int mv = 1;
      if (score[i][j - 1] > best) {
        best = score[i][j - 1];
        mv = 2;
      }
      const feature *x = &fa[i - 1], *y = &fb[j - 1];
      double like = (x->turn * y->turn > 0)
                        ? fmin(fabs(x->turn), fabs(y->turn)) /
                              fmax(fabs(x->turn), fabs(y->turn))
                        : -1.0;
      double gain = like - 4.0 * fabs(x->r - y->r);
      if (gain > 0 && score[i - 1][j - 1] + gain > best) {
        best = score[i - 1][j - 1] + gain;
        mv = 3;
      }
      score[i][j] = best;
      move[i][j] = mv;
    }
  /* backtrack */
  double tmp[2 * F];
  size_t n = 0;
  size_t i = na, j = nb;
  while (i > 0 && j > 0) {
    if (move[i][j] == 3) {
      tmp[2 * n] = fa[i - 1].r;
      tmp[2 * n + 1] = fb[j - 1].r;
      n++;
      i--;
      j--;
    } else if (move[i][j] == 1) {
      i--;
    } else {
      j--;
    }
  }
  /* reverse into pairs, keep strictly increasing pairs inside (0,1) */
  size_t m = 0;
  double pa = 0.0, pb = 0.0;
  for (size_t k = n; k-- > 0 && m < cap;) {
    double x = tmp[2 * k], y = tmp[2 * k + 1];
    if (x > pa + 1e-6 && y > pb + 1e-6 && x < 1 - 1e-6 && y < 1 - 1e-6) {
      pairs[2 * m] = x;
      pairs[2 * m + 1] = y;
      pa = x;
      pb = y;
      m++;
    }
  }
  return m;
}
