/* morph_plan.c - curvature frames planned once per morph.
 *
 * DESIGN. Without matches, a frame of the turning blend is
 *     theta_t(r) = theta0(t) + (1 - t) Ta(r) + t Tb(r),   r in [0, 1],
 *     C_t(r)     = integral from 0 to r of L_t e^(i theta_t),
 * with Ta, Tb the inputs' tangent angles less their start angles over the
 * normalised arc length r, and L_t = (1 - t) La + t Lb. Everything a frame
 * needs that does not depend on t is computed here once per morph:
 *   - The inputs' theta pieces merged where one polynomial of degree 7
 *     stays within a tenth of the tolerance over L of them (km__pp_merge:
 *     a bound from Bernstein coefficients), so that breaks at knots where
 *     nothing happens cost no nodes.
 *   - The output pieces: cubic Hermite pieces in r. The derivatives of
 *     theta_t are convex combinations of the inputs', so the larger of the
 *     two inputs' bounds holds for every t (and L_t <= max(La, Lb)); the
 *     pieces are sized with the remainder bound of reconstruct.c
 *     (h^4 / 384 * B_3, plus jump terms where a piece spans a breakpoint of
 *     either input's curvature), so every frame meets the tolerance.
 *   - Gauss-Legendre nodes on every piece with Ta, Tb and the closure basis
 *     evaluated there. Each chunk gets the lowest rule order whose error
 *     bound, K_n h^(2n+1) max|f^(2n)| with |d^m e^(i theta)| <= B_m(|theta'|,
 *     ..., |theta^(m)|) (complete Bell polynomial), meets its share of the
 *     tolerance: smooth inputs need two or three nodes a piece, not eight.
 * A frame is then a pass of sin/cos over the nodes, a pass turning them by
 * the closure's first change, a bounded first-order finish (close_frame)
 * and the Hermite control points: no piecewise-polynomial blending, no
 * planning, no allocation but the output. The closure is the one of morph.c (close_lsq): interior uniform
 * cubic B-splines psi added to theta, minimum-norm steps in the metric
 * integral psi'^2 (the Gram matrix of their derivatives is Toeplitz with
 * entries 2/3, -1/8, -1/5, -1/120), so the seam stays G2.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "km/limits.h"
#include "morph_plan.h"

#define NB KM__CLOSURE_INTERVALS
#define NF (KM__CLOSURE_INTERVALS - 3)
#define MAX_RULE 8      /* highest Gauss-Legendre order used */
/* Gap (over the frame's length) at which the lsq closure stops: a tenth of
 * its promise, 1e-9 of the length (a hundredth cost U_to_S's 60-frame
 * morph 21 more passes over the nodes, 228 instead of 207) */
#define CLOSED_GAP 1e-10
#define NDER (2 * MAX_RULE)
/* Closure corrections kept at t = k / WARM_POINTS, from which frames start
 * theirs (WARM_POINTS + 1 of them, zero at both ends) */
#define WARM_POINTS 6
#define MERGE_DEGREE 7   /* of theta on merged input pieces */
#define MERGE_SHARE 0.1  /* of the tolerance, for merging them */

typedef struct gnode {
  double w;      /* weight in r */
  double ta, tb; /* Ta(r), Tb(r) at the node */
  int bi;        /* first closure basis function that may be nonzero */
  double bv[4];  /* basis values bi .. bi+3 (0 where outside 0..NF-1) */
} gnode;

struct km__frame_plan {
  double La, Lb, tol;
  bool closed;
  size_t np;            /* output pieces */
  double *x;            /* np + 1 breaks in r */
  unsigned char *corner; /* np + 1: theta jumps there (C0 junction) */
  double *ta_l, *ta_r;  /* Ta left / right of each break */
  double *tb_l, *tb_r;
  size_t *first;        /* nodes of piece k: first[k] .. first[k+1] - 1 */
  double wb[NF];        /* sum over the nodes of w B_i: integral of B_i */
  gnode *at_break;      /* the closure basis at every break (bi, bv) */
  gnode *node;
  size_t nn;
  double chol[NF * NF]; /* Cholesky factor of the closure metric */
  double c_at[WARM_POINTS + 1][NF]; /* closure corrections at t = k / WARM_POINTS */
  size_t *corner_at;    /* breaks (1 .. np - 1) that are corners */
  size_t ncorners;
  bool by_corners;      /* closed frames close by their corners */
};

/* ---- small numerics ---------------------------------------------------- */

/* Gauss-Legendre rules of order 1..MAX_RULE on [-1, 1], by Newton on the
 * Legendre recurrence. */
typedef struct gl_rules {
  double x[MAX_RULE + 1][MAX_RULE], w[MAX_RULE + 1][MAX_RULE];
  double K[MAX_RULE + 1]; /* error constant (n!)^4 / ((2n+1) ((2n)!)^3) */
} gl_rules;

static void gl_make(gl_rules *g) {
  for (int n = 1; n <= MAX_RULE; n++) {
    for (int i = 0; i < n; i++) {
      double z = cos(KM_PI * (i + 0.75) / (n + 0.5)), dp = 1.0;
      for (int it = 0; it < 100; it++) {
        double p0 = 1.0, p1 = z;
        for (int k = 2; k <= n; k++) {
          double p2 = ((2 * k - 1) * z * p1 - (k - 1) * p0) / k;
          p0 = p1;
          p1 = p2;
        }
        if (n == 1) p0 = 1.0;
        dp = n * (z * p1 - p0) / (z * z - 1);
        double dz = p1 / dp;
        z -= dz;
        if (fabs(dz) < 1e-16) break;
      }
      g->x[n][i] = z;
      g->w[n][i] = 2.0 / ((1 - z * z) * dp * dp);
    }
    double f = 1.0, f2 = 1.0;
    for (int k = 2; k <= n; k++) f *= k;
    for (int k = 2; k <= 2 * n; k++) f2 *= k;
    g->K[n] = f * f * f * f / ((2 * n + 1) * f2 * f2 * f2);
  }
}

/* Complete Bell polynomial B_m(x[1], ..., x[m]) for m = 0..mmax. */
static void bell(const double *x, int mmax, double *B) {
  B[0] = 1.0;
  for (int m = 0; m < mmax; m++) {
    double s = 0.0, binom = 1.0;
    for (int i = 0; i <= m; i++) {
      s += binom * B[m - i] * x[i + 1];
      binom = binom * (m - i) / (i + 1);
    }
    B[m + 1] = s;
  }
}

double km__bspline3_d(double u) {
  if (u <= 0 || u >= 4) return 0.0;
  if (u < 1) return u * u / 2.0;
  if (u < 2) return (-9 * u * u + 24 * u - 12) / 6.0;
  if (u < 3) return (9 * u * u - 48 * u + 60) / 6.0;
  double v = 4 - u;
  return -v * v / 2.0;
}

double km__bspline3(double u) {
  if (u <= 0 || u >= 4) return 0.0;
  if (u < 1) return u * u * u / 6.0;
  if (u < 2) return (-3 * u * u * u + 12 * u * u - 12 * u + 4) / 6.0;
  if (u < 3) return (3 * u * u * u - 24 * u * u + 60 * u - 44) / 6.0;
  double v = 4 - u;
  return v * v * v / 6.0;
}

/* The closure basis at r: first index (-3 .. NF - 1) and four values,
 * zero for indices outside 0 .. NF - 1. */
static void basis_at(double r, int *bi, double bv[4]) {
  double u = r * NB;
  int iv = (int)floor(u);
  if (iv < 0) iv = 0;
  if (iv > NB - 1) iv = NB - 1;
  int i0 = iv - 3;
  for (int k = 0; k < 4; k++) {
    int i = i0 + k;
    bv[k] = (i >= 0 && i < NF) ? km__bspline3(u - i) : 0.0;
  }
  *bi = i0;
}

/* psi at break k, from the basis values there (computed once per plan). */
static double psi_at_break(const km__frame_plan *p, const double *c, size_t k) {
  const gnode *b = &p->at_break[k];
  double v = 0.0;
  for (int q = 0; q < 4; q++)
    if (b->bi + q >= 0 && b->bi + q < NF) v += c[b->bi + q] * b->bv[q];
  return v;
}

void km__closure_metric_weighted(const double *w, double *M) {
  /* per interval the four basis derivatives are quadratics: three Gauss
   * points integrate their products exactly */
  static const double X[3] = {0.11270166537925831, 0.5, 0.88729833462074169};
  static const double W[3] = {5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0};
  memset(M, 0, NF * NF * sizeof(double));
  for (int iv = 0; iv < NB; iv++)
    for (int g = 0; g < 3; g++) {
      double u = iv + X[g], d[NF];
      for (int i = 0; i < NF; i++) d[i] = km__bspline3_d(u - i);
      for (int i = 0; i < NF; i++) {
        if (d[i] == 0.0) continue;
        for (int j = 0; j < NF; j++) M[i * NF + j] += w[iv] * W[g] * d[i] * d[j];
      }
    }
}

void km__closure_metric(double *M) {
  static const double band[4] = {2.0 / 3.0, -1.0 / 8.0, -1.0 / 5.0, -1.0 / 120.0};
  for (int i = 0; i < NF; i++)
    for (int j = 0; j < NF; j++) {
      int d = i > j ? i - j : j - i;
      M[i * NF + j] = d < 4 ? band[d] : 0.0;
    }
}

/* Cholesky of the Toeplitz metric (exact entries, see DESIGN). */
static bool metric_factor(double *Lc) {
  double M[NF * NF];
  km__closure_metric(M);
  memset(Lc, 0, NF * NF * sizeof(double));
  for (int i = 0; i < NF; i++)
    for (int j = 0; j <= i; j++) {
      double v = M[i * NF + j];
      for (int k = 0; k < j; k++) v -= Lc[i * NF + k] * Lc[j * NF + k];
      if (i == j) {
        if (!(v > 0)) return false;
        Lc[i * NF + i] = sqrt(v);
      } else {
        Lc[i * NF + j] = v / Lc[j * NF + j];
      }
    }
  return true;
}

static void chol_solve(const double *Lc, double *y) {
  for (int i = 0; i < NF; i++) {
    double v = y[i];
    for (int k = 0; k < i; k++) v -= Lc[i * NF + k] * y[k];
    y[i] = v / Lc[i * NF + i];
  }
  for (int i = NF - 1; i >= 0; i--) {
    double v = y[i];
    for (int k = i + 1; k < NF; k++) v -= Lc[k * NF + i] * y[k];
    y[i] = v / Lc[i * NF + i];
  }
}

/* ---- one input over an interval of r --------------------------------- */

typedef struct side {
  const km_pp *kappa, *theta;
  double L, angle;
} side;

/* Piece of the input containing [r0, r1] and the local range there. */
static size_t side_piece(const side *sd, double r0, double r1, double *u0,
                         double *u1) {
  size_t i = km__pp_find(sd->theta, 0.5 * (r0 + r1) * sd->L);
  double a = sd->theta->x[i], h = sd->theta->x[i + 1] - a;
  *u0 = fmin(fmax((r0 * sd->L - a) / h, 0.0), 1.0);
  *u1 = fmin(fmax((r1 * sd->L - a) / h, 0.0), 1.0);
  return i;
}

/* D[j] >= |d^j theta / dr^j| on [r0, r1] for j = 1..nd. */
static void side_bounds(const side *sd, double r0, double r1, int nd,
                        double *D) {
  double u0, u1, kb[NDER];
  size_t i = side_piece(sd, r0, r1, &u0, &u1);
  int dk = sd->kappa->degree;
  double h = sd->kappa->x[i + 1] - sd->kappa->x[i];
  km__kappa_bounds(sd->kappa->c + i * (size_t)(dk + 1), dk, h, u0, u1, nd, kb);
  double Lj = sd->L;
  for (int j = 1; j <= nd; j++) {
    D[j] = Lj * kb[j - 1];
    Lj *= sd->L;
  }
}

/* The piece of an input at r, from the left (side_dir < 0) or the right
 * (side_dir > 0) at a break or wherever it falls (0), and u in it. */
static size_t side_piece_at(const side *sd, double r, int side_dir, double *u) {
  /* r comes from a break of one input divided by its length: times the
   * length it may miss that break by a rounding unit either way */
  double x = r * sd->L, eps = 1e-12 * sd->L;
  size_t i = km__pp_find(sd->theta, x);
  if (side_dir > 0 && i + 1 < sd->theta->m && x >= sd->theta->x[i + 1] - eps) i++;
  if (side_dir < 0 && i > 0 && x <= sd->theta->x[i] + eps) i--;
  double a = sd->theta->x[i], h = sd->theta->x[i + 1] - a;
  *u = fmin(fmax((r * sd->L - a) / h, 0.0), 1.0);
  return i;
}

/* theta (less the start angle), d theta/dr and d2 theta/dr2 at r, from the
 * piece on the side side_dir of r */
static void side_eval(const side *sd, double r, int side_dir, double v[3]) {
  double u;
  size_t i = side_piece_at(sd, r, side_dir, &u);
  double h = sd->theta->x[i + 1] - sd->theta->x[i];
  int dt = sd->theta->degree, dk = sd->kappa->degree;
  const double *kc = sd->kappa->c + i * (size_t)(dk + 1);
  v[0] = km__bern_eval(sd->theta->c + i * (size_t)(dt + 1), dt, u) - sd->angle;
  v[1] = sd->L * km__bern_eval(kc, dk, u);
  double dc[KM_MAX_FN_DEGREE + 1];
  if (dk > 0) {
    km__bern_derivative(kc, dk, h, dc);
    v[2] = sd->L * sd->L * km__bern_eval(dc, dk - 1, u);
  } else {
    v[2] = 0.0;
  }
}

/* theta alone (less the start angle) from the side side_dir of r */
static double side_angle(const side *sd, double r, int side_dir) {
  double u;
  size_t i = side_piece_at(sd, r, side_dir, &u);
  int dt = sd->theta->degree;
  return km__bern_eval(sd->theta->c + i * (size_t)(dt + 1), dt, u) - sd->angle;
}

/* ---- planning ---------------------------------------------------------- */

/* An atom: a stretch of r inside one piece of each input. */
typedef struct atom {
  double x0, x1;
  double m4;    /* max |C''''(r)| / L over the atom */
  double j2, j3; /* jumps of C'', C''' (over L) at x0, bounds for every t */
  bool corner;  /* theta jumps at x0 */
  size_t iv;    /* merged interval it lies in */
  bool whole;   /* it is the whole interval */
} atom;

typedef struct vec {
  void *p;
  size_t n, cap, size;
} vec;

static km_status vec_push(vec *v, const void *item) {
  if (v->n == v->cap) {
    size_t cap = v->cap ? 2 * v->cap : 256;
    if (cap > 64 * (size_t)KM_MAX_PIECES) return KM_ELIMIT;
    void *q = realloc(v->p, cap * v->size);
    if (!q) return KM_ENOMEM;
    v->p = q;
    v->cap = cap;
  }
  memcpy((char *)v->p + v->n * v->size, item, v->size);
  v->n++;
  return KM_OK;
}

static double m4_of(const double *D) {
  return D[1] * D[1] * D[1] + 3 * D[1] * D[2] + D[3];
}

static void both_bounds(const side sd[2], double r0, double r1, int nd,
                        double *D) {
  double Da[NDER + 1], Db[NDER + 1];
  side_bounds(&sd[0], r0, r1, nd, Da);
  side_bounds(&sd[1], r0, r1, nd, Db);
  for (int j = 1; j <= nd; j++) D[j] = fmax(Da[j], Db[j]);
}

/* Atoms of merged interval iv = [r0, r1] (derivative bounds D), split
 * until each meets tolp (relative to L: tolerances here are over
 * max(La, Lb)). */
static km_status plan_interval(vec *atoms, const side sd[2], double r0,
                               double r1, size_t iv, const double *D,
                               double tolp, double j2, double j3,
                               bool corner, size_t max_atoms, km__poll *poll) {
  double h = r1 - r0, e = pow(h, 4) / 384.0 * m4_of(D);
  int parts = 1;
  if (e > tolp) {
    double p = ceil(pow(e / tolp, 0.25) * 1.05);
    parts = p > 1e6 ? 1000000 : (int)p;
  }
  if (max_atoms > 0 && atoms->n + (size_t)parts > max_atoms) return KM_ELIMIT;
  for (int k = 0; k < parts; k++) {
    double a = r0 + h * k / parts, b = k + 1 == parts ? r1 : r0 + h * (k + 1) / parts;
    atom at = {a, b, 0.0, k ? 0.0 : j2, k ? 0.0 : j3, k ? false : corner, iv,
               parts == 1};
    double Dk[4];
    if (parts > 1)
      both_bounds(sd, a, b, 3, Dk);
    else
      memcpy(Dk, D, sizeof Dk);
    at.m4 = m4_of(Dk);
    if (km__poll_stop(poll, parts > 1 ? 32 : 1)) return KM_ECANCELLED;
    km_status st = vec_push(atoms, &at);
    if (st) return st;
  }
  return KM_OK;
}

void km__frame_plan_free(km__frame_plan *p) {
  if (!p) return;
  free(p->x);
  free(p->corner);
  free(p->ta_l);
  free(p->ta_r);
  free(p->tb_l);
  free(p->tb_r);
  free(p->first);
  free(p->at_break);
  free(p->node);
  free(p->corner_at);
  free(p);
}

static int cmp_dbl(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

/* Scratch a frame's closure needs: the pieces' sums (2 per piece) and
 * e^(i theta) at the nodes (2 per node). */
static size_t frame_scratch(const km__frame_plan *p) {
  return 2 * (p->np + p->nn);
}

static km_status close_frame(const km__frame_plan *p, double t, double theta0,
                             bool close_lsq, bool project, double *c,
                             double *sum, double *e, km__poll *poll);
static bool corner_closure(const km__frame_plan *p, double t, double *sum,
                           double *tau, double *delta, double *S,
                           double *dp);

km_status km__frame_plan_build(km__frame_plan **out, const km_pp theta[2], const double length[2],
                               const double angle[2], bool closed, double tol,
                               size_t max_pieces, km__poll *poll,
                               km_error *err) {
  km_status st = KM_OK;
  double *br = NULL, *Dall = NULL;
  vec atoms = {NULL, 0, 0, sizeof(atom)}, nodes = {NULL, 0, 0, sizeof(gnode)};
  km_pp mt[2], mk[2];
  for (int w = 0; w < 2; w++) {
    km__pp_init(&mt[w]);
    km__pp_init(&mk[w]);
  }
  gl_rules *g = malloc(sizeof *g);
  km__frame_plan *p = calloc(1, sizeof *p);
  if (!p || !g) {
    st = KM_ENOMEM;
    goto fail;
  }
  gl_make(g);
  double Lmax = fmax(length[0], length[1]);
  /* The inputs' pieces merged where one polynomial carries them within
   * MERGE_SHARE of the tolerance in position (|dC| <= L |d theta|): a
   * signature breaks at every knot of its curve, and every merged break of
   * the two inputs would otherwise cost output pieces and quadrature
   * nodes in every frame. */
  side sd[2];
  for (int w = 0; w < 2; w++) {
    st = km__pp_merge(&theta[w], MERGE_DEGREE, MERGE_SHARE * tol / Lmax, &mt[w]);
    if (!st) st = km__pp_derivative(&mt[w], &mk[w]);
    if (st) goto fail;
    sd[w].kappa = &mk[w];
    sd[w].theta = &mt[w];
    sd[w].L = length[w];
    sd[w].angle = angle[w];
  }
  p->La = length[0];
  p->Lb = length[1];
  p->tol = tol;
  p->closed = closed;
  if (!metric_factor(p->chol)) {
    st = KM_ENOCONVERGE;
    goto fail;
  }
  /* merged breaks of both inputs in r */
  size_t nbr = mt[0].m + mt[1].m + 2;
  br = malloc(nbr * sizeof(double));
  if (!br) {
    st = KM_ENOMEM;
    goto fail;
  }
  size_t q = 0;
  for (int w = 0; w < 2; w++)
    for (size_t i = 0; i <= mt[w].m; i++) br[q++] = mt[w].x[i] / length[w];
  qsort(br, q, sizeof(double), cmp_dbl);
  size_t m = 0;
  for (size_t i = 0; i < q; i++) {
    double v = fmin(fmax(br[i], 0.0), 1.0);
    if (m == 0 || v > br[m - 1] + 1e-14) br[m++] = v;
  }
  br[0] = 0.0;
  if (br[m - 1] < 1.0 - 1e-14)
    br[m++] = 1.0;
  else
    br[m - 1] = 1.0;
  if (m < 2) {
    st = KM_EDEGENERATE;
    goto fail;
  }
  /* bounds on theta's derivatives over every merged interval (once: the
   * planning and the quadrature both use them) */
  Dall = malloc((m - 1) * (NDER + 1) * sizeof(double));
  if (!Dall) {
    st = KM_ENOMEM;
    goto fail;
  }
  for (size_t i = 0; i + 1 < m; i++) {
    both_bounds(sd, br[i], br[i + 1], NDER, Dall + i * (NDER + 1));
    if (km__poll_stop(poll, 2 * NDER)) {
      st = KM_ECANCELLED;
      goto fail;
    }
  }
  /* atoms; jumps and corners at the merged breaks */
  double tolp = 0.5 * tol / Lmax;
  for (size_t i = 0; i + 1 < m; i++) {
    double j2 = 0.0, j3 = 0.0;
    bool corner = false;
    if (i > 0) {
      double D1 = fmax(Dall[(i - 1) * (NDER + 1) + 1], Dall[i * (NDER + 1) + 1]);
      for (int w = 0; w < 2; w++) {
        double vl[3], vr[3];
        side_eval(&sd[w], br[i], -1, vl);
        side_eval(&sd[w], br[i], 1, vr);
        if (fabs(vr[0] - vl[0]) > 1e-12) corner = true;
        double d1 = fabs(vr[1] - vl[1]), d2 = fabs(vr[2] - vl[2]);
        j2 = fmax(j2, d1);
        j3 = fmax(j3, d2 + d1 * 2 * D1);
      }
    }
    st = plan_interval(&atoms, sd, br[i], br[i + 1], i, Dall + i * (NDER + 1),
                       tolp, j2, j3, corner, 2 * max_pieces, poll);
    if (st) goto fail;
  }
  /* merge atoms greedily into output pieces while the bound holds */
  atom *A = atoms.p;
  size_t na = atoms.n;
  size_t *start = malloc((na + 1) * sizeof(size_t));
  if (!start) {
    st = KM_ENOMEM;
    goto fail;
  }
  size_t np = 0;
  {
    size_t k = 0;
    while (k < na) {
      start[np++] = k;
      double m4 = A[k].m4, s2 = 0.0, s3 = 0.0;
      size_t e = k + 1;
      while (e < na && !A[e].corner) {
        double h = A[e].x1 - A[k].x0;
        double m4n = fmax(m4, A[e].m4), s2n = s2 + A[e].j2, s3n = s3 + A[e].j3;
        double e_h = pow(h, 4) / 384.0 * m4n + KM__HERMITE_JUMP2 * h * h * s2n +
                     KM__HERMITE_JUMP3 * h * h * h * s3n;
        if (e_h > tolp) break;
        m4 = m4n;
        s2 = s2n;
        s3 = s3n;
        e++;
      }
      k = e;
    }
    start[np] = na;
  }
  if (max_pieces > 0 && np > max_pieces) {
    free(start);
    st = KM_ELIMIT;
    goto fail;
  }
  p->np = np;
  p->x = malloc((np + 1) * sizeof(double));
  p->corner = calloc(np + 1, 1);
  p->ta_l = malloc((np + 1) * sizeof(double));
  p->ta_r = malloc((np + 1) * sizeof(double));
  p->tb_l = malloc((np + 1) * sizeof(double));
  p->tb_r = malloc((np + 1) * sizeof(double));
  p->first = malloc((np + 1) * sizeof(size_t));
  if (!p->x || !p->corner || !p->ta_l || !p->ta_r || !p->tb_l || !p->tb_r ||
      !p->first) {
    free(start);
    st = KM_ENOMEM;
    goto fail;
  }
  /* quadrature share of the tolerance, per unit of r */
  double tolq = 0.1 * tol / Lmax;
  for (size_t k = 0; k < np && !st; k++) {
    p->x[k] = A[start[k]].x0;
    p->corner[k] = A[start[k]].corner;
    p->first[k] = nodes.n;
    for (size_t ai = start[k]; ai < start[k + 1] && !st; ai++) {
      double a = A[ai].x0, b = A[ai].x1;
      double Dpart[NDER + 1], B[NDER + 1], Dh[NDER + 1];
      const double *D = Dpart;
      if (A[ai].whole)
        D = Dall + A[ai].iv * (NDER + 1);
      else
        both_bounds(sd, a, b, NDER, Dpart);
      /* lowest order, then halving, whose bound meets tolq per unit r */
      int chunks = 1, n = 2;
      for (;;) {
        double h = (b - a) / chunks, hj = h;
        for (int j = 1; j <= NDER; j++) {
          Dh[j] = D[j] * hj;
          hj *= h;
        }
        bell(Dh, NDER, B);
        bool ok = false;
        for (n = 2; n <= MAX_RULE; n++)
          if (g->K[n] * B[2 * n] <= tolq) {
            ok = true;
            break;
          }
        if (ok || chunks >= (1 << 20)) {
          if (!ok) n = MAX_RULE;
          break;
        }
        chunks *= 2;
      }
      double hc = (b - a) / chunks;
      /* a node costs two angles and its basis: some 4 units */
      if (km__poll_stop(poll, 4L * chunks * n + 2 * NDER)) st = KM_ECANCELLED;
      for (int c = 0; c < chunks && !st; c++) {
        double mid = a + hc * (c + 0.5);
        for (int j = 0; j < n && !st; j++) {
          gnode nd;
          double r = mid + 0.5 * hc * g->x[n][j];
          nd.w = 0.5 * hc * g->w[n][j];
          nd.ta = side_angle(&sd[0], r, 0);
          nd.tb = side_angle(&sd[1], r, 0);
          basis_at(r, &nd.bi, nd.bv);
          st = vec_push(&nodes, &nd);
        }
      }
    }
  }
  free(start);
  if (st) goto fail;
  p->x[np] = 1.0;
  p->first[np] = nodes.n;
  p->at_break = malloc((np + 1) * sizeof(gnode));
  if (!p->at_break) {
    st = KM_ENOMEM;
    goto fail;
  }
  for (size_t k = 0; k <= np; k++) basis_at(p->x[k], &p->at_break[k].bi, p->at_break[k].bv);
  {
    const gnode *N = nodes.p;
    for (size_t j = 0; j < nodes.n; j++)
      for (int b = 0; b < 4; b++)
        if (N[j].bi + b >= 0 && N[j].bi + b < NF) p->wb[N[j].bi + b] += N[j].w * N[j].bv[b];
  }
  p->corner_at = malloc((np + 1) * sizeof(size_t));
  if (!p->corner_at) {
    st = KM_ENOMEM;
    goto fail;
  }
  for (size_t k = 1; k < np; k++)
    if (p->corner[k]) p->corner_at[p->ncorners++] = k;
  for (size_t k = 0; k <= np; k++) {
    p->ta_l[k] = side_angle(&sd[0], p->x[k], k == 0 ? 1 : -1);
    p->ta_r[k] = side_angle(&sd[0], p->x[k], k == np ? -1 : 1);
    p->tb_l[k] = side_angle(&sd[1], p->x[k], k == 0 ? 1 : -1);
    p->tb_r[k] = side_angle(&sd[1], p->x[k], k == np ? -1 : 1);
  }
  p->node = nodes.p;
  p->nn = nodes.n;
  nodes.p = NULL;
  if (closed) {
    /* Corners close the frames of this morph if they can at t = 1/4, 1/2
     * and 3/4; the choice holds for every frame, so that a sequence does
     * not switch between two closures (a frame where it fails takes the
     * smooth one). */
    size_t nc = p->ncorners;
    double *buf = nc >= 3 ? malloc((frame_scratch(p) + 4 * nc + 2 + np) *
                                   sizeof(double))
                          : NULL;
    if (buf) {
      double *tau = buf + frame_scratch(p), *delta = tau + nc, *S = delta + nc;
      double *dp = S + 2 * (nc + 1), c0[NF] = {0};
      p->by_corners = true;
      for (int k = 1; k <= 3 && p->by_corners; k++)
        p->by_corners = close_frame(p, k / 4.0, 0.0, false, false, c0, buf,
                                    buf + 2 * np, poll) == KM_OK &&
                        corner_closure(p, k / 4.0, buf, tau, delta, S, dp);
      free(buf);
    }
    /* The corrections frames start from, at t = k / WARM_POINTS: the
     * projection and steps from the closed correction found from zero at
     * t = 1/2, scaled by 4 t (1 - t) - a smooth family in t (the frames of
     * U_to_S took it, three or four passes each, before they started from
     * the polynomial through it, two passes each). One that does not
     * converge is zero, and so are all where corners close the frames
     * (a frame they cannot close takes steps from zero). */
    memset(p->c_at, 0, sizeof p->c_at);
    if (!p->by_corners) {
      double *sum = malloc(frame_scratch(p) * sizeof(double));
      if (!sum) {
        st = KM_ENOMEM;
        goto fail;
      }
      double c_half[NF] = {0};
      st = close_frame(p, 0.5, 0.0, true, true, c_half, sum, sum + 2 * np,
                       poll);
      if (st == KM_ENOCONVERGE) {
        memset(c_half, 0, sizeof c_half);
        st = KM_OK;
      }
      for (int k = 1; k < WARM_POINTS && !st; k++) {
        double t = (double)k / WARM_POINTS;
        for (int i = 0; i < NF; i++) p->c_at[k][i] = 4 * t * (1 - t) * c_half[i];
        st = close_frame(p, t, 0.0, true, true, p->c_at[k], sum, sum + 2 * np,
                         poll);
        if (st == KM_ENOCONVERGE) {
          memset(p->c_at[k], 0, sizeof p->c_at[k]);
          st = KM_OK;
        }
      }
      free(sum);
      if (st) goto fail;
    }
  }
  if (poll && poll->stopped) {
    st = KM_ECANCELLED;
    goto fail;
  }
  free(atoms.p);
  free(br);
  free(Dall);
  free(g);
  for (int w = 0; w < 2; w++) {
    km__pp_free(&mt[w]);
    km__pp_free(&mk[w]);
  }
  *out = p;
  return KM_OK;
fail:
  free(atoms.p);
  free(nodes.p);
  free(br);
  free(Dall);
  free(g);
  for (int w = 0; w < 2; w++) {
    km__pp_free(&mt[w]);
    km__pp_free(&mk[w]);
  }
  km__frame_plan_free(p);
  if (st == KM_ECANCELLED) return km__stopped(err);
  return km__fail(err, st, KM_FIELD_TOLERANCE, -1, NAN,
                  st == KM_ELIMIT ? "the frames need too many pieces at this "
                                    "tolerance: loosen it"
                                  : NULL);
}

size_t km__frame_plan_pieces(const km__frame_plan *p) { return p->np; }
size_t km__frame_plan_nodes(const km__frame_plan *p) { return p->nn; }
size_t km__frame_plan_points(const km__frame_plan *p) {
  size_t ncorner = 0;
  for (size_t k = 1; k < p->np; k++) ncorner += p->corner[k];
  return 2 * p->np + 2 + ncorner; /* as km__frame_plan_curve builds them */
}
const double *km__frame_plan_breaks(const km__frame_plan *p) { return p->x; }
bool km__frame_plan_by_corners(const km__frame_plan *p) { return p->by_corners; }

/* ---- closing by the corners ------------------------------------------- */

bool km__close_by_corners(const double *S, const double *tau, size_t nc,
                          double *delta) {
  if (nc < 3) return false;
  double *W = malloc((4 * nc + 1) * sizeof(double));
  if (!W) return false;
  double *D = W + nc, *J = W + 2 * nc + 1; /* J: 2 nc (suffix sums) */
  double wsum = 0.0;
  for (size_t k = 0; k < nc; k++) {
    W[k] = fabs(tau[k]);
    wsum += W[k];
    delta[k] = 0.0;
  }
  bool ok = false;
  for (int it = 0; it < 60 && wsum > 0; it++) {
    /* D_m = delta_1 + ... + delta_m; G = sum_m e^(i D_m) S_m and the
     * derivatives i sum_(m >= k) e^(i D_m) S_m (suffix sums) */
    D[0] = 0.0;
    for (size_t k = 0; k < nc; k++) D[k + 1] = D[k] + delta[k];
    double gx = 0.0, gy = 0.0;
    for (size_t m = nc + 1; m-- > 0;) {
      double c = cos(D[m]), sn = sin(D[m]);
      gx += c * S[2 * m] - sn * S[2 * m + 1];
      gy += sn * S[2 * m] + c * S[2 * m + 1];
      if (m >= 1) {
        J[2 * (m - 1)] = -gy; /* d gx / d delta_m */
        J[2 * (m - 1) + 1] = gx; /* d gy / d delta_m */
      }
    }
    if (hypot(gx, gy) <= 1e-14) {
      ok = true;
      break;
    }
    /* least sum delta^2 / W with the linearised constraints
     * A delta = A delta_old - (gx, gy, 0), A = (Jx; Jy; 1 ... 1):
     * delta = W A^T (A W A^T)^-1 rhs */
    double M[9] = {0}, rhs[3] = {-gx, -gy, 0.0};
    for (size_t k = 0; k < nc; k++) {
      double a[3] = {J[2 * k], J[2 * k + 1], 1.0};
      for (int r = 0; r < 3; r++) {
        rhs[r] += a[r] * delta[k];
        for (int q = 0; q < 3; q++) M[r * 3 + q] += W[k] * a[r] * a[q];
      }
    }
    if (!km__solve_dense(M, rhs, 3)) break;
    for (size_t k = 0; k < nc; k++)
      delta[k] = W[k] * (J[2 * k] * rhs[0] + J[2 * k + 1] * rhs[1] + rhs[2]);
  }
  /* a corner may change by at most half its turn: beyond that the shape
   * would be closed by corners it hardly has */
  for (size_t k = 0; ok && k < nc; k++)
    if (fabs(delta[k]) > 0.5 * fabs(tau[k])) ok = false;
  free(W);
  return ok;
}

/* ---- frames ------------------------------------------------------------ */

static double max_abs(const double *v, int n) {
  double m = 0.0;
  for (int i = 0; i < n; i++) m = fmax(m, fabs(v[i]));
  return m;
}

/* e^(i d) for |d| <= 0.1 by its Taylor series (the remainder is below
 * 0.1^10 / 10! < 3e-17), beyond that by sin and cos. */
static inline void exp_i_small(double d, double *cs, double *sn) {
  if (fabs(d) > 0.1) {
    km__sincos(d, sn, cs);
    return;
  }
  /* reciprocals, not divisions: a division takes some 15 cycles, and
   * these run at every node of every pass */
  double d2 = d * d;
  *cs = 1 - d2 * 0.5 * (1 - d2 * (1.0 / 12) * (1 - d2 * (1.0 / 30) *
        (1 - d2 * (1.0 / 56) * (1 - d2 * (1.0 / 90)))));
  *sn = d * (1 - d2 * (1.0 / 6) * (1 - d2 * (1.0 / 20) * (1 - d2 * (1.0 / 42) *
        (1 - d2 * (1.0 / 72)))));
}

/* e^(i d) for |d| <= 0.01: the series to d^7 (the remainder is below
 * 0.01^8 / 8! < 3e-21), for passes whose change is bounded so. */
static inline void exp_i_tiny(double d, double *cs, double *sn) {
  double d2 = d * d;
  *cs = 1 - d2 * 0.5 * (1 - d2 * (1.0 / 12) * (1 - d2 * (1.0 / 30)));
  *sn = d * (1 - d2 * (1.0 / 6) * (1 - d2 * (1.0 / 20) * (1 - d2 * (1.0 / 42))));
}

/* One pass over the nodes: sum[2k], sum[2k+1] = integral over piece k of
 * e^(i (theta_t + psi)), G their total. On the first pass (e_known false)
 * e^(i theta) is computed at every node; later ones turn the stored e by
 * the change of psi (coefficients dcp), which is small. With J, d G / d c
 * is accumulated too. Coefficients are padded by three zeros each side, so
 * that every node reads its four basis functions without a test
 * (basis_at). */
static void frame_pass(const km__frame_plan *p, double t, double theta0,
                       const double *cp, const double *dcp, bool e_known,
                       double *sum, double *e, double G[2], double J[2][NF],
                       km__poll *poll) {
  double al = 1 - t, be = t, Jp[2][NF + 6];
  if (J) memset(Jp, 0, sizeof Jp);
  G[0] = G[1] = 0.0;
  /* nodes mostly share their basis functions with the previous one: the
   * Jacobian is summed in registers while they do */
  int run = -1;
  double ax[4] = {0, 0, 0, 0}, ay[4] = {0, 0, 0, 0};
  /* the change at a node is at most the largest coefficient's (the basis
   * is a partition of unity): most passes need only the short series */
  bool tiny = e_known && max_abs(dcp + 3, NF) <= 0.01;
  for (size_t k = 0; k < p->np; k++) {
    double sx = 0.0, sy = 0.0;
    /* the caller sees poll->stopped: what was summed is then unused */
    if (km__poll_stop(poll, (long)(p->first[k + 1] - p->first[k]) + 1)) return;
    for (size_t j = p->first[k]; j < p->first[k + 1]; j++) {
      const gnode *nd = &p->node[j];
      const double *bv = nd->bv;
      int o = nd->bi + 3;
      double cs, sn;
      if (!e_known) {
        double th = theta0 + al * nd->ta + be * nd->tb + cp[o] * bv[0] +
                    cp[o + 1] * bv[1] + cp[o + 2] * bv[2] + cp[o + 3] * bv[3];
        km__sincos(th, &sn, &cs);
      } else {
        double d = dcp[o] * bv[0] + dcp[o + 1] * bv[1] + dcp[o + 2] * bv[2] +
                   dcp[o + 3] * bv[3];
        double dx, dy;
        if (tiny)
          exp_i_tiny(d, &dx, &dy);
        else
          exp_i_small(d, &dx, &dy);
        cs = e[2 * j] * dx - e[2 * j + 1] * dy;
        sn = e[2 * j] * dy + e[2 * j + 1] * dx;
      }
      e[2 * j] = cs;
      e[2 * j + 1] = sn;
      double wc = nd->w * cs, ws = nd->w * sn;
      sx += wc;
      sy += ws;
      if (J) {
        if (o != run) {
          if (run >= 0)
            for (int q = 0; q < 4; q++) {
              Jp[0][run + q] += ax[q];
              Jp[1][run + q] += ay[q];
            }
          run = o;
          for (int q = 0; q < 4; q++) ax[q] = ay[q] = 0.0;
        }
        for (int q = 0; q < 4; q++) {
          ax[q] -= ws * bv[q];
          ay[q] += wc * bv[q];
        }
      }
    }
    sum[2 * k] = sx;
    sum[2 * k + 1] = sy;
    G[0] += sx;
    G[1] += sy;
  }
  if (J) {
    if (run >= 0)
      for (int q = 0; q < 4; q++) {
        Jp[0][run + q] += ax[q];
        Jp[1][run + q] += ay[q];
      }
    for (int r = 0; r < 2; r++) memcpy(J[r], Jp[r] + 3, sizeof J[r]);
  }
}

/* The pieces' sums moved to first order by a step of psi (padded
 * coefficients dcp) from where e was stored: sum_k += integral over piece
 * k of i e^(i theta) dpsi. */
static void linear_finish(const km__frame_plan *p, const double *dcp,
                          const double *e, double *sum) {
  for (size_t k = 0; k < p->np; k++) {
    double dx = 0.0, dy = 0.0;
    for (size_t j = p->first[k]; j < p->first[k + 1]; j++) {
      const gnode *nd = &p->node[j];
      const double *bv = nd->bv;
      int o = nd->bi + 3;
      double d = nd->w * (dcp[o] * bv[0] + dcp[o + 1] * bv[1] +
                          dcp[o + 2] * bv[2] + dcp[o + 3] * bv[3]);
      dx -= e[2 * j + 1] * d;
      dy += e[2 * j] * d;
    }
    sum[2 * k] += dx;
    sum[2 * k + 1] += dy;
  }
}

/* Y = M^-1 J^T (rows) and S = J M^-1 J^T for the closure metric M: what
 * minimum-norm steps with this J need, kept for a chord step. */
static void metric_rows(const km__frame_plan *p, double J[2][NF],
                        double Y[2][NF], double S[4]) {
  for (int r = 0; r < 2; r++) {
    memcpy(Y[r], J[r], sizeof Y[r]);
    chol_solve(p->chol, Y[r]);
  }
  for (int r = 0; r < 2; r++)
    for (int k = 0; k < 2; k++) {
      double v = 0.0;
      for (int i = 0; i < NF; i++) v += J[r][i] * Y[k][i];
      S[r * 2 + k] = v;
    }
}

/* The minimum-norm step dc = M^-1 J^T lambda with J dc = rhs; false if J
 * is singular. */
static bool metric_step(double Y[2][NF], const double S[4], const double rhs[2],
                        double dc[NF]) {
  double A[4] = {S[0], S[1], S[2], S[3]}, l[2] = {rhs[0], rhs[1]};
  if (!km__solve_dense(A, l, 2)) return false;
  for (int i = 0; i < NF; i++) dc[i] = Y[0][i] * l[0] + Y[1][i] * l[1];
  return true;
}

/* theta_t plus the closure correction psi (coefficients c, started from
 * c), integrated over every piece: sum[2k], sum[2k+1] = integral of
 * e^(i theta) dr over piece k. scratch: e^(i theta) at the nodes (2 per
 * node).
 *
 * The lsq closure solves G(c) = 0 for the least change of curvature: with
 * project, a projection onto the linearised constraints (the minimum-norm
 * point of J c = J c_old - G in the metric integral psi'^2, whose Gram
 * matrix is Toeplitz with entries 2/3, -1/8, -1/5, -1/120) - how the
 * corrections frames start from are found - else a first step from c;
 * then steps dc = M^-1 J^T lambda with J dc = -G: with the first J (a
 * chord step) when the first change was at most 1e-3, else Newton steps
 * with fresh Jacobians, which converge quadratically. No pass follows the last
 * step when a bound on what it leaves says so:
 *   G(c + dc) = (J(c) - J(c0)) dc + R,
 * |J(c) - J(c0)| dc <= max|dc0| sum_i |dc_i| wb_i for the chord (|e^(i a)
 * - e^(i b)| <= |a - b|, and |psi change| <= max|dc| since the basis sums
 * to at most one; nothing for Newton), |R| <= max|dc|^2 / 2 (the Taylor
 * remainder of e^(i d), the weights summing to one). Below CLOSED_GAP the
 * pieces' sums take the linear change (linear_finish, each within its
 * share of the same bound) and the frame is closed to CLOSED_GAP of its
 * length, as by a further pass. */
static km_status close_frame(const km__frame_plan *p, double t, double theta0,
                             bool close_lsq, bool project, double *c,
                             double *sum, double *scratch, km__poll *poll) {
  double Lt = (1 - t) * p->La + t * p->Lb;
  bool lsq = close_lsq && p->closed;
  double *e = scratch;
  double cp[NF + 6] = {0}, dcp[NF + 6] = {0}, dc[NF], G[2], J[2][NF];
  double Y[2][NF], S[4];
  memcpy(cp + 3, c, sizeof dc);
  frame_pass(p, t, theta0, cp, NULL, false, sum, e, G, lsq ? J : NULL, poll);
  if (poll && poll->stopped) return KM_ECANCELLED;
  /* With the projection a start that is closed already is the answer
   * only if it is zero: the projection from it leads elsewhere, and the
   * frames beside it take that (a closed start kept at t = 1/2 stood 1.4%
   * of U_to_S's length off its neighbours at 1/2 +- 1e-6). */
  bool closed = Lt * hypot(G[0], G[1]) <= CLOSED_GAP * Lt;
  if (!lsq || (closed && (!project || max_abs(c, NF) == 0))) return KM_OK;
  metric_rows(p, J, Y, S);
  double rhs[2] = {-G[0], -G[1]};
  if (project) {
    for (int r = 0; r < 2; r++)
      for (int i = 0; i < NF; i++) rhs[r] += J[r][i] * c[i];
    if (!metric_step(Y, S, rhs, dc)) return KM_ENOCONVERGE;
    for (int i = 0; i < NF; i++) {
      double ci = dc[i];
      dc[i] = ci - c[i];
      c[i] = ci;
    }
  } else {
    if (!metric_step(Y, S, rhs, dc)) return KM_ENOCONVERGE;
    for (int i = 0; i < NF; i++) c[i] += dc[i];
  }
  /* A small first change leaves so little that a chord step with this
   * Jacobian finishes (the bound below); a large one needs Newton steps
   * with fresh Jacobians, which converge quadratically. */
  double dc0 = max_abs(dc, NF);
  bool chord = dc0 <= 1e-3;
  for (int it = 0;; it++) {
    memcpy(dcp + 3, dc, sizeof dc);
    frame_pass(p, t, theta0, cp, dcp, true, sum, e, G, chord ? NULL : J, poll);
    if (poll && poll->stopped) return KM_ECANCELLED;
    if (Lt * hypot(G[0], G[1]) <= CLOSED_GAP * Lt) return KM_OK;
    if (it == 40) return KM_ENOCONVERGE;
    if (!chord) metric_rows(p, J, Y, S);
    double r[2] = {-G[0], -G[1]}, cross = 0.0;
    if (!metric_step(Y, S, r, dc)) return KM_ENOCONVERGE;
    if (chord)
      for (int i = 0; i < NF; i++) cross += fabs(dc[i]) * p->wb[i];
    for (int i = 0; i < NF; i++) c[i] += dc[i];
    double d = max_abs(dc, NF);
    if (dc0 * cross + 0.5 * d * d <= CLOSED_GAP && isfinite(d)) {
      memcpy(dcp + 3, dc, sizeof dc);
      linear_finish(p, dcp, e, sum);
      return KM_OK;
    }
    chord = false; /* from here on, Newton */
  }
}

/* Closes a frame by its corners (km__close_by_corners) given the pieces'
 * integrals sum (rotated in place on success); dp[k] receives the turn
 * added before piece k. Scratch: tau, delta (nc each), S (2 (nc + 1)). */
static bool corner_closure(const km__frame_plan *p, double t, double *sum,
                           double *tau, double *delta, double *S,
                           double *dp) {
  size_t np = p->np, nc = p->ncorners, m = 0;
  S[0] = S[1] = 0.0;
  for (size_t k = 0; k < np; k++) {
    if (m < nc && p->corner_at[m] == k) {
      size_t b = p->corner_at[m];
      tau[m] = (1 - t) * (p->ta_r[b] - p->ta_l[b]) + t * (p->tb_r[b] - p->tb_l[b]);
      m++;
      S[2 * m] = S[2 * m + 1] = 0.0;
    }
    S[2 * m] += sum[2 * k];
    S[2 * m + 1] += sum[2 * k + 1];
  }
  if (!km__close_by_corners(S, tau, nc, delta)) return false;
  double d = 0.0;
  m = 0;
  for (size_t k = 0; k < np; k++) {
    if (m < nc && p->corner_at[m] == k) d += delta[m++];
    dp[k] = d;
    double cs = cos(d), sn = sin(d), x = sum[2 * k], y = sum[2 * k + 1];
    sum[2 * k] = cs * x - sn * y;
    sum[2 * k + 1] = sn * x + cs * y;
  }
  return true;
}

/* The closure correction a frame at t starts from: the polynomial through
 * the kept corrections (smooth in t, exact at each: frames move smoothly
 * through them, where a piecewise cubic left a kink). */
static void warm_start(const km__frame_plan *p, double t, double *c) {
  double x = t * WARM_POINTS;
  for (int i = 0; i < NF; i++) c[i] = 0.0;
  for (int j = 1; j < WARM_POINTS; j++) { /* the ends are zero */
    double l = 1.0;
    for (int q = 0; q <= WARM_POINTS; q++)
      if (q != j) l *= (x - q) / (double)(j - q);
    for (int i = 0; i < NF; i++) c[i] += l * p->c_at[j][i];
  }
}

km_status km__frame_plan_curve(const km__frame_plan *p, double t,
                               double theta0, bool close_lsq, km_curve *out,
                               double *ends, km__poll *poll, km_error *err) {
  double Lt = (1 - t) * p->La + t * p->Lb, al = 1 - t, be = t;
  size_t np = p->np;
  double c[NF] = {0};
  bool lsq = close_lsq && p->closed;
  /* sums of the pieces, scratch of the nodes, and per corner its turn,
   * its change and the stretch sums; per piece the turn added before it */
  size_t nc = p->ncorners;
  double *sum = malloc((frame_scratch(p) + 4 * nc + 2 + np) * sizeof(double));
  if (!sum) return km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
  double *tau = sum + frame_scratch(p), *delta = tau + nc, *S = delta + nc;
  double *dp = S + 2 * (nc + 1);
  for (size_t k = 0; k < np; k++) dp[k] = 0.0;
  km_status st = KM_OK;
  bool by_corners = false;
  if (lsq && p->by_corners) {
    st = close_frame(p, t, theta0, false, false, c, sum, sum + 2 * np, poll);
    by_corners = !st && corner_closure(p, t, sum, tau, delta, S, dp);
  }
  if (!st && !by_corners) {
    /* the smooth curvature takes the correction, by steps from the
     * cubic through the kept ones (warm_start): closed at those points
     * already, near it between them, so frames near each other take
     * nearly the same correction (continuous in t), and the ends none.
     * Should the steps fail, the projection from there, as the kept
     * corrections were found. */
    if (lsq) warm_start(p, t, c);
    st = close_frame(p, t, theta0, close_lsq, false, c, sum, sum + 2 * np,
                     poll);
    if (st == KM_ENOCONVERGE && lsq) {
      warm_start(p, t, c);
      st = close_frame(p, t, theta0, true, true, c, sum, sum + 2 * np, poll);
    }
  }
  if (st == KM_ECANCELLED || (poll && poll->stopped)) {
    free(sum);
    return km__stopped(err);
  }
  if (st) {
    free(sum);
    return km__fail(err, st, KM_FIELD_NONE, -1, NAN,
                    "closing the frame did not converge");
  }
  /* Hermite control points: P0, then Q1 Q2 of every piece, with the
   * junction point itself at corners (triple knots; double elsewhere) */
  size_t ncorner = 0;
  for (size_t k = 1; k < np; k++) ncorner += p->corner[k];
  size_t ncp = 2 * np + 2 + ncorner, nknots = ncp + 4;
  km_curve f;
  km_curve_init(&f);
  st = km__curve_alloc(&f, 3, ncp, false);
  if (st) {
    free(sum);
    return km__fail(err, st, KM_FIELD_NONE, -1, NAN, NULL);
  }
  size_t cc = 0, kk = 0;
  double P[2] = {0.0, 0.0};
  for (int r = 0; r < 4; r++) f.knots[kk++] = 0.0;
  f.cp[cc++] = 0.0;
  f.cp[cc++] = 0.0;
  if (ends) ends[0] = ends[1] = 0.0;
  /* the tangent a piece ends with is the next one's start but at corners
   * (theta is continuous there to 1e-12, and so is the turn dp) */
  double c1 = 0.0, s1 = 0.0;
  for (size_t k = 0; k < np; k++) {
    double h = Lt * (p->x[k + 1] - p->x[k]);
    double th1 = theta0 + al * p->ta_l[k + 1] + be * p->tb_l[k + 1] +
                 psi_at_break(p, c, k + 1) + dp[k];
    double Pn[2] = {P[0] + Lt * sum[2 * k], P[1] + Lt * sum[2 * k + 1]};
    if (k > 0 && p->corner[k]) {
      f.cp[cc++] = P[0];
      f.cp[cc++] = P[1];
    }
    double c0 = c1, s0 = s1;
    if (k == 0 || p->corner[k]) {
      double th0 = theta0 + al * p->ta_r[k] + be * p->tb_r[k] +
                   psi_at_break(p, c, k) + dp[k];
      km__sincos(th0, &s0, &c0);
    }
    km__sincos(th1, &s1, &c1);
    f.cp[cc++] = P[0] + h / 3.0 * c0;
    f.cp[cc++] = P[1] + h / 3.0 * s0;
    f.cp[cc++] = Pn[0] - h / 3.0 * c1;
    f.cp[cc++] = Pn[1] - h / 3.0 * s1;
    if (k + 1 < np) {
      int mult = p->corner[k + 1] ? 3 : 2;
      for (int r = 0; r < mult; r++) f.knots[kk++] = Lt * p->x[k + 1];
    }
    P[0] = Pn[0];
    P[1] = Pn[1];
    if (ends) {
      ends[2 * k + 2] = P[0];
      ends[2 * k + 3] = P[1];
    }
  }
  f.cp[cc++] = P[0];
  f.cp[cc++] = P[1];
  for (int r = 0; r < 4; r++) f.knots[kk++] = Lt;
  free(sum);
  if (cc != 2 * ncp || kk != nknots) {
    km_curve_free(&f);
    return km__fail(err, KM_EINVAL, KM_FIELD_NONE, -1, NAN,
                    "internal inconsistency building a frame");
  }
  f.closed = false;
  if (p->closed) {
    double g = hypot(P[0], P[1]);
    if (g <= p->tol) {
      f.cp[2 * (ncp - 1)] = f.cp[0];
      f.cp[2 * (ncp - 1) + 1] = f.cp[1];
      f.closed = true;
    }
  }
  *out = f;
  return KM_OK;
}
