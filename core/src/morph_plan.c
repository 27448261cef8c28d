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
 *   - The output pieces: cubic Hermite pieces in r, within a share of the
 *     tolerance (KM__PLAN_PIECE_SHARE), so that each frame can merge runs
 *     of them into single cubics within the rest (morph_plan_frame.c).
 *     The derivatives of theta_t are convex combinations of the inputs',
 *     so the larger of the two inputs' bounds holds for every t (and L_t
 *     <= max(La, Lb)); the
 *     pieces are sized with the remainder bound of reconstruct.c
 *     (h^4 / 384 * B_3, plus jump terms where a piece spans a breakpoint of
 *     either input's curvature), so every frame meets the tolerance.
 *   - Gauss-Legendre nodes on every piece with Ta, Tb and the closure basis
 *     evaluated there. Each chunk gets the lowest rule order whose error
 *     bound, K_n h^(2n+1) max|f^(2n)| with |d^m e^(i theta)| <= B_m(|theta'|,
 *     ..., |theta^(m)|) (complete Bell polynomial), meets its share of the
 *     tolerance: smooth inputs need two or three nodes a piece, not eight.
 * Frames are built from the plan in morph_plan_frame.c.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "km/alloc.h"
#include "km/limits.h"
#include "morph_plan.h"
#include "morph_plan_internal.h"

#define MAX_RULE 8 /* highest Gauss-Legendre order used */
#define NDER (2 * MAX_RULE)
#define MERGE_DEGREE 7  /* of theta on merged input pieces */
#define MERGE_SHARE 0.1 /* of the tolerance, for merging them */

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
  if (side_dir > 0 && i + 1 < sd->theta->m && x >= sd->theta->x[i + 1] - eps)
    i++;
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
  double m4;     /* max |C''''(r)| / L over the atom */
  double j2, j3; /* jumps of C'', C''' (over L) at x0, bounds for every t */
  bool corner;   /* theta jumps at x0 */
  size_t iv;     /* merged interval it lies in */
  bool whole;    /* it is the whole interval */
} atom;

typedef struct vec {
  void *p;
  size_t n, cap, size;
} vec;

static km_status vec_push(vec *v, const void *item) {
  if (v->n == v->cap) {
    size_t cap = v->cap ? 2 * v->cap : 256;
    if (cap > 64 * (size_t)KM_MAX_PIECES) return KM_ELIMIT;
    void *q = km__realloc(v->p, cap * v->size);
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
                               double tolp, double j2, double j3, bool corner,
                               size_t max_atoms, km__poll *poll) {
  double h = r1 - r0, e = pow(h, 4) / 384.0 * m4_of(D);
  int parts = 1;
  if (e > tolp) {
    double p = ceil(pow(e / tolp, 0.25) * 1.05);
    parts = p > 1e6 ? 1000000 : (int)p;
  }
  if (max_atoms > 0 && atoms->n + (size_t)parts > max_atoms) return KM_ELIMIT;
  for (int k = 0; k < parts; k++) {
    double a = r0 + h * k / parts,
           b = k + 1 == parts ? r1 : r0 + h * (k + 1) / parts;
    atom at = {
        a,  b,         0.0, k ? 0.0 : j2, k ? 0.0 : j3, k ? false : corner,
        iv, parts == 1};
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
  km__free(p->x);
  km__free(p->corner);
  km__free(p->ta_l);
  km__free(p->ta_r);
  km__free(p->tb_l);
  km__free(p->tb_r);
  km__free(p->first);
  km__free(p->at_break);
  km__free(p->node);
  km__free(p->corner_at);
  km__free(p);
}

/* ---- the phases of planning --------------------------------------------
 * What planning needs beside the plan itself, freed once whatever the
 * outcome. */
typedef struct builder {
  km_pp mt[2], mk[2]; /* the inputs' theta pieces merged, and their kappa */
  side sd[2];
  gl_rules *g;
  double Lmax; /* the longer input: tolerances below are over it */
  double *br;  /* m merged breaks of both inputs in r */
  size_t m;
  double *Dall; /* bounds on theta's derivatives per merged interval */
  vec atoms, nodes;
  size_t *start; /* first atom of each output piece, np + 1 */
} builder;

static void builder_free(builder *b) {
  for (int w = 0; w < 2; w++) {
    km__pp_free(&b->mt[w]);
    km__pp_free(&b->mk[w]);
  }
  km__free(b->g);
  km__free(b->br);
  km__free(b->Dall);
  km__free(b->atoms.p);
  km__free(b->nodes.p);
  km__free(b->start);
}

/* The inputs' pieces merged where one polynomial carries them within
 * MERGE_SHARE of the tolerance in position (|dC| <= L |d theta|): a
 * signature breaks at every knot of its curve, and every merged break of
 * the two inputs would otherwise cost output pieces and quadrature nodes
 * in every frame. */
static km_status merge_inputs(builder *b, const km_pp theta[2],
                              const double length[2], const double angle[2],
                              double tol) {
  for (int w = 0; w < 2; w++) {
    km_status st = km__pp_merge(&theta[w], MERGE_DEGREE,
                                MERGE_SHARE * tol / b->Lmax, &b->mt[w]);
    if (!st) st = km__pp_derivative(&b->mt[w], &b->mk[w]);
    if (st) return st;
    b->sd[w].kappa = &b->mk[w];
    b->sd[w].theta = &b->mt[w];
    b->sd[w].L = length[w];
    b->sd[w].angle = angle[w];
  }
  return KM_OK;
}

/* The merged breaks of both inputs in r, from 0 to 1, and the bounds on
 * theta's derivatives over every interval between them (once: the
 * planning and the quadrature both use them). */
static km_status merged_breaks(builder *b, const double length[2],
                               km__poll *poll) {
  size_t nbr = b->mt[0].m + b->mt[1].m + 2, q = 0, m = 0;
  double *br = b->br = km__malloc(nbr * sizeof(double));
  if (!br) return KM_ENOMEM;
  for (int w = 0; w < 2; w++)
    for (size_t i = 0; i <= b->mt[w].m; i++)
      br[q++] = b->mt[w].x[i] / length[w];
  qsort(br, q, sizeof(double), km__cmp_double);
  for (size_t i = 0; i < q; i++) {
    double v = fmin(fmax(br[i], 0.0), 1.0);
    if (m == 0 || v > br[m - 1] + 1e-14) br[m++] = v;
  }
  br[0] = 0.0;
  if (br[m - 1] < 1.0 - 1e-14)
    br[m++] = 1.0;
  else
    br[m - 1] = 1.0;
  b->m = m;
  if (m < 2) return KM_EDEGENERATE;
  b->Dall = km__malloc((m - 1) * (NDER + 1) * sizeof(double));
  if (!b->Dall) return KM_ENOMEM;
  for (size_t i = 0; i + 1 < m; i++) {
    both_bounds(b->sd, br[i], br[i + 1], NDER, b->Dall + i * (NDER + 1));
    if (km__poll_stop(poll, 2 * NDER)) return KM_ECANCELLED;
  }
  return KM_OK;
}

/* Bounds on the jumps of C'' and C''' (over L) at merged break i > 0 for
 * every t, and whether theta jumps there. */
static void break_jumps(const builder *b, size_t i, double *j2, double *j3,
                        bool *corner) {
  const double *Dl = b->Dall + (i - 1) * (NDER + 1),
               *Dr = b->Dall + i * (NDER + 1);
  double D1 = fmax(Dl[1], Dr[1]);
  for (int w = 0; w < 2; w++) {
    double vl[3], vr[3];
    side_eval(&b->sd[w], b->br[i], -1, vl);
    side_eval(&b->sd[w], b->br[i], 1, vr);
    if (fabs(vr[0] - vl[0]) > 1e-12) *corner = true;
    double d1 = fabs(vr[1] - vl[1]), d2 = fabs(vr[2] - vl[2]);
    *j2 = fmax(*j2, d1);
    *j3 = fmax(*j3, d2 + d1 * 2 * D1);
  }
}

/* Atoms of every merged interval, with the jumps and corners at their
 * breaks; past 2 max_pieces of them (0: no bound) KM_ELIMIT. */
static km_status make_atoms(builder *b, double tolp, size_t max_pieces,
                            km__poll *poll) {
  for (size_t i = 0; i + 1 < b->m; i++) {
    double j2 = 0.0, j3 = 0.0;
    bool corner = false;
    if (i > 0) break_jumps(b, i, &j2, &j3, &corner);
    km_status st = plan_interval(&b->atoms, b->sd, b->br[i], b->br[i + 1], i,
                                 b->Dall + i * (NDER + 1), tolp, j2, j3, corner,
                                 2 * max_pieces, poll);
    if (st) return st;
  }
  return KM_OK;
}

/* Atoms merged greedily into output pieces while the Hermite bound holds
 * (b->start, *np of them); more than max_pieces (0: no bound) KM_ELIMIT. */
static km_status group_atoms(builder *b, double tolp, size_t max_pieces,
                             size_t *np_out) {
  const atom *A = b->atoms.p;
  size_t na = b->atoms.n, np = 0, k = 0;
  size_t *start = b->start = km__malloc((na + 1) * sizeof(size_t));
  if (!start) return KM_ENOMEM;
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
  if (max_pieces > 0 && np > max_pieces) return KM_ELIMIT;
  *np_out = np;
  return KM_OK;
}

/* The plan's per-break arrays for np pieces. */
static km_status alloc_breaks(km__frame_plan *p, size_t np) {
  p->np = np;
  p->x = km__malloc((np + 1) * sizeof(double));
  p->corner = km__calloc(np + 1, 1);
  p->ta_l = km__malloc((np + 1) * sizeof(double));
  p->ta_r = km__malloc((np + 1) * sizeof(double));
  p->tb_l = km__malloc((np + 1) * sizeof(double));
  p->tb_r = km__malloc((np + 1) * sizeof(double));
  p->first = km__malloc((np + 1) * sizeof(size_t));
  p->at_break = km__malloc((np + 1) * sizeof(gnode));
  p->corner_at = km__malloc((np + 1) * sizeof(size_t));
  bool ok = p->x && p->corner && p->ta_l && p->ta_r && p->tb_l && p->tb_r &&
            p->first && p->at_break && p->corner_at;
  return ok ? KM_OK : KM_ENOMEM;
}

/* The lowest Gauss-Legendre order n, then halvings of [a, b] into
 * *chunks, whose error bound meets tolq per unit r, for theta with
 * derivative bounds D there. */
static int atom_rule(const gl_rules *g, const double *D, double a, double b,
                     double tolq, int *chunks_out) {
  double B[NDER + 1], Dh[NDER + 1];
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
  *chunks_out = chunks;
  return n;
}

/* Quadrature nodes of atom ai (Ta, Tb and the closure basis at each). */
static km_status atom_nodes(builder *b, size_t ai, double tolq,
                            km__poll *poll) {
  const atom *A = b->atoms.p;
  double a = A[ai].x0, bb = A[ai].x1, Dpart[NDER + 1];
  const double *D = Dpart;
  if (A[ai].whole)
    D = b->Dall + A[ai].iv * (NDER + 1);
  else
    both_bounds(b->sd, a, bb, NDER, Dpart);
  int chunks, n = atom_rule(b->g, D, a, bb, tolq, &chunks);
  double hc = (bb - a) / chunks;
  /* a node costs two angles and its basis: some 4 units */
  if (km__poll_stop(poll, 4L * chunks * n + 2 * NDER)) return KM_ECANCELLED;
  for (int c = 0; c < chunks; c++) {
    double mid = a + hc * (c + 0.5);
    for (int j = 0; j < n; j++) {
      gnode nd;
      double r = mid + 0.5 * hc * b->g->x[n][j];
      nd.w = 0.5 * hc * b->g->w[n][j];
      nd.ta = side_angle(&b->sd[0], r, 0);
      nd.tb = side_angle(&b->sd[1], r, 0);
      basis_at(r, &nd.bi, nd.bv);
      km_status st = vec_push(&b->nodes, &nd);
      if (st) return st;
    }
  }
  return KM_OK;
}

/* The output pieces' breaks and nodes, the quadrature taking a tenth of
 * the tolerance; the nodes move from b into p. */
static km_status plan_nodes(builder *b, km__frame_plan *p, double tol,
                            km__poll *poll) {
  const atom *A = b->atoms.p;
  double tolq = 0.1 * tol / b->Lmax; /* per unit of r */
  for (size_t k = 0; k < p->np; k++) {
    p->x[k] = A[b->start[k]].x0;
    p->corner[k] = A[b->start[k]].corner;
    p->first[k] = b->nodes.n;
    for (size_t ai = b->start[k]; ai < b->start[k + 1]; ai++) {
      km_status st = atom_nodes(b, ai, tolq, poll);
      if (st) return st;
    }
  }
  p->x[p->np] = 1.0;
  p->first[p->np] = b->nodes.n;
  p->node = b->nodes.p;
  p->nn = b->nodes.n;
  b->nodes.p = NULL;
  return KM_OK;
}

/* At every break the closure basis and the inputs' angles either side;
 * the basis functions' integrals; the corners. */
static void break_tables(const builder *b, km__frame_plan *p) {
  size_t np = p->np;
  for (size_t k = 0; k <= np; k++)
    basis_at(p->x[k], &p->at_break[k].bi, p->at_break[k].bv);
  for (size_t j = 0; j < p->nn; j++) {
    const gnode *N = &p->node[j];
    for (int q = 0; q < 4; q++)
      if (N->bi + q >= 0 && N->bi + q < NF) p->wb[N->bi + q] += N->w * N->bv[q];
  }
  for (size_t k = 1; k < np; k++)
    if (p->corner[k]) p->corner_at[p->ncorners++] = k;
  for (size_t k = 0; k <= np; k++) {
    p->ta_l[k] = side_angle(&b->sd[0], p->x[k], k == 0 ? 1 : -1);
    p->ta_r[k] = side_angle(&b->sd[0], p->x[k], k == np ? -1 : 1);
    p->tb_l[k] = side_angle(&b->sd[1], p->x[k], k == 0 ? 1 : -1);
    p->tb_r[k] = side_angle(&b->sd[1], p->x[k], k == np ? -1 : 1);
  }
}

/* Corners close the frames of this morph if they can at t = 1/4, 1/2 and
 * 3/4; the choice holds for every frame, so that a sequence does not
 * switch between two closures (a frame where it fails takes the smooth
 * one). Fewer than three corners leave the smooth closure. Without memory
 * for the trial the morph fails: choosing the smooth closure instead would
 * answer with other frames than the same request with memory. */
static km_status choose_corner_closure(km__frame_plan *p, km__poll *poll) {
  size_t nc = p->ncorners, np = p->np;
  if (nc < 3) return KM_OK;
  double *buf = km__malloc((km__plan_frame_scratch(p) + 4 * nc + 2 + np) *
                           sizeof(double));
  if (!buf) return KM_ENOMEM;
  double *tau = buf + km__plan_frame_scratch(p), *delta = tau + nc,
         *S = delta + nc;
  double *dp = S + 2 * (nc + 1), c0[NF] = {0};
  km_status st = KM_OK;
  p->by_corners = true;
  for (int k = 1; k <= 3 && p->by_corners && !st; k++) {
    /* a trial frame that does not close smoothly (or is stopped) rules
     * the corners out; only running out of memory fails the morph */
    p->by_corners = km__plan_close_frame(p, k / 4.0, 0.0, false, false, c0, buf,
                                         buf + 2 * np, poll) == KM_OK;
    if (p->by_corners)
      st = km__plan_corner_closure(p, k / 4.0, buf, tau, delta, S, dp,
                                   &p->by_corners);
  }
  km__free(buf);
  return st;
}

/* The corrections frames start from, at t = k / WARM_POINTS: the
 * projection and steps from the closed correction found from zero at
 * t = 1/2, scaled by 4 t (1 - t) - a smooth family in t, from which frames
 * start on the polynomial through them (fewer passes than from the scaled
 * correction itself). One that does not converge is zero. */
static km_status warm_corrections(km__frame_plan *p, km__poll *poll) {
  size_t np = p->np;
  double *sum = km__malloc(km__plan_frame_scratch(p) * sizeof(double));
  if (!sum) return KM_ENOMEM;
  double c_half[NF] = {0};
  km_status st = km__plan_close_frame(p, 0.5, 0.0, true, true, c_half, sum,
                                      sum + 2 * np, poll);
  if (st == KM_ENOCONVERGE) {
    memset(c_half, 0, sizeof c_half);
    st = KM_OK;
  }
  for (int k = 1; k < WARM_POINTS && !st; k++) {
    double t = (double)k / WARM_POINTS;
    for (int i = 0; i < NF; i++) p->c_at[k][i] = 4 * t * (1 - t) * c_half[i];
    st = km__plan_close_frame(p, t, 0.0, true, true, p->c_at[k], sum,
                              sum + 2 * np, poll);
    if (st == KM_ENOCONVERGE) {
      memset(p->c_at[k], 0, sizeof p->c_at[k]);
      st = KM_OK;
    }
  }
  km__free(sum);
  return st;
}

/* ---- planning ---------------------------------------------------------- */

km_status km__frame_plan_build(km__frame_plan **out, const km_pp theta[2],
                               const double length[2], const double angle[2],
                               bool closed, double tol, double piece_share,
                               size_t max_pieces, km__poll *poll,
                               km_error *err) {
  builder b;
  memset(&b, 0, sizeof b);
  for (int w = 0; w < 2; w++) {
    km__pp_init(&b.mt[w]);
    km__pp_init(&b.mk[w]);
  }
  b.atoms.size = sizeof(atom);
  b.nodes.size = sizeof(gnode);
  b.Lmax = fmax(length[0], length[1]);
  /* the Hermite pieces take their share of the tolerance (per unit of
   * r), the frames' merging of them the rest of half of it */
  double tolp = piece_share * tol / b.Lmax;
  size_t np = 0;
  km_status st = KM_OK;
  b.g = km__malloc(sizeof *b.g);
  km__frame_plan *p = km__calloc(1, sizeof *p);
  if (!p || !b.g) {
    st = KM_ENOMEM;
    goto done;
  }
  gl_make(b.g);
  p->La = length[0];
  p->Lb = length[1];
  p->tol = tol;
  p->closed = closed;
  st = merge_inputs(&b, theta, length, angle, tol);
  if (!st && !km__closure_metric_factor(p->chol)) st = KM_ENOCONVERGE;
  if (!st) st = merged_breaks(&b, length, poll);
  if (!st) st = make_atoms(&b, tolp, max_pieces, poll);
  if (!st) st = group_atoms(&b, tolp, max_pieces, &np);
  if (!st) st = alloc_breaks(p, np);
  if (!st) st = plan_nodes(&b, p, tol, poll);
  if (st) goto done;
  break_tables(&b, p);
  /* corners or the kept corrections (zero where corners close the
   * frames: one they cannot close takes steps from zero) */
  if (closed) st = choose_corner_closure(p, poll);
  if (!st && closed && !p->by_corners) st = warm_corrections(p, poll);
  if (!st && poll && poll->stopped) st = KM_ECANCELLED;
  if (!st) {
    *out = p;
    p = NULL;
  }
done:
  builder_free(&b);
  km__frame_plan_free(p);
  if (!st) return KM_OK;
  if (st == KM_ECANCELLED) return km__stopped(err);
  return km__fail(err, st, KM_FIELD_TOLERANCE, -1, NAN,
                  st == KM_ELIMIT ? "the frames need too many pieces at this "
                                    "tolerance: loosen it"
                                  : NULL);
}

size_t km__frame_plan_pieces(const km__frame_plan *p) {
  return p->np;
}
size_t km__frame_plan_nodes(const km__frame_plan *p) {
  return p->nn;
}
size_t km__frame_plan_points(const km__frame_plan *p) {
  size_t ncorner = 0;
  for (size_t k = 1; k < p->np; k++) ncorner += p->corner[k];
  /* as km__frame_plan_curve builds them before merging runs: at most */
  return 2 * p->np + 2 + ncorner;
}
const double *km__frame_plan_breaks(const km__frame_plan *p) {
  return p->x;
}
bool km__frame_plan_by_corners(const km__frame_plan *p) {
  return p->by_corners;
}
