/* morph_plan_internal.h - the frame plan's layout, shared by its builder
 * (morph_plan.c) and the frames built from it (morph_plan_frame.c);
 * internal to the core. */
#ifndef KM_MORPH_PLAN_INTERNAL_H
#define KM_MORPH_PLAN_INTERNAL_H

#include <stdbool.h>
#include <stddef.h>

#include "internal.h"
#include "morph_plan.h"

#define NB KM__CLOSURE_INTERVALS
#define NF (KM__CLOSURE_INTERVALS - 3)
/* Closure corrections kept at t = k / WARM_POINTS, from which frames start
 * theirs (WARM_POINTS + 1 of them, zero at both ends) */
#define WARM_POINTS 6

typedef struct gnode {
  double w;      /* weight in r */
  double ta, tb; /* Ta(r), Tb(r) at the node */
  int bi;        /* first closure basis function that may be nonzero */
  double bv[4];  /* basis values bi .. bi+3 (0 where outside 0..NF-1) */
} gnode;

struct km__frame_plan {
  double La, Lb, tol;
  bool closed;
  size_t np;             /* output pieces */
  double *x;             /* np + 1 breaks in r */
  unsigned char *corner; /* np + 1: theta jumps there (C0 junction) */
  double *ta_l, *ta_r;   /* Ta left / right of each break */
  double *tb_l, *tb_r;
  size_t *first;   /* nodes of piece k: first[k] .. first[k+1] - 1 */
  double wb[NF];   /* sum over the nodes of w B_i: integral of B_i */
  gnode *at_break; /* the closure basis at every break (bi, bv) */
  gnode *node;
  size_t nn;
  double chol[NF * NF]; /* Cholesky factor of the closure metric */
  double c_at[WARM_POINTS + 1]
             [NF];   /* closure corrections at t = k / WARM_POINTS */
  size_t *corner_at; /* breaks (1 .. np - 1) that are corners */
  size_t ncorners;
  bool by_corners; /* closed frames close by their corners */
};

/* Scratch a frame's closure needs: the pieces' sums (2 per piece) and
 * e^(i theta) at the nodes (2 per node). */
static inline size_t km__plan_frame_scratch(const km__frame_plan *p) {
  return 2 * (p->np + p->nn);
}

/* theta_t plus the closure correction psi (coefficients c, NF of them,
 * updated in place) integrated over every piece of the plan: sum[2k],
 * sum[2k+1] = integral of e^(i theta) dr over piece k; scratch holds
 * e^(i theta) at the nodes (km__plan_frame_scratch less 2 np values).
 * close_lsq: close a closed pair (else one pass, no closure); project:
 * start with the projection onto the linearised constraints (as the kept
 * corrections are found) instead of a step from c. KM_ECANCELLED when poll
 * says stop, KM_ENOCONVERGE; no message (the caller words it). */
km_status km__plan_close_frame(const km__frame_plan *p, double t, double theta0,
                               bool close_lsq, bool project, double *c,
                               double *sum, double *scratch, km__poll *poll);
/* Closes a frame by its corners (km__close_by_corners) given the pieces'
 * integrals sum (rotated in place when they close it); dp[k] receives the
 * turn added before piece k. Scratch: tau, delta (ncorners each), S (2
 * (ncorners + 1)). *closes false where the corners cannot close it;
 * KM_ENOMEM (*closes false) without memory. */
km_status km__plan_corner_closure(const km__frame_plan *p, double t,
                                  double *sum, double *tau, double *delta,
                                  double *S, double *dp, bool *closes);

#endif
