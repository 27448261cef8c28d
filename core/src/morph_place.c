/* morph_place.c - where a frame goes.
 *
 * DESIGN. Curvature fixes a frame up to a rigid motion; "fit" takes the
 * rigid motion (2-D Procrustes, closed form) that best maps the frame onto
 * the linear blend of the two inputs at corresponding points, which keeps
 * frames where the eye expects them instead of swinging about the start.
 * "start" (the paper's) blends the start points and angles; "centroid"
 * keeps the blended start angle and moves the wire centroid along the line
 * between the inputs'.
 */
#include <math.h>

#include "internal.h"
#include "km/alloc.h"
#include "morph_blend.h"
#include "morph_place.h"

#define FIT_N 256 /* frame samples for the Procrustes fit */

/* A planned frame is placed by its pieces' ends, at the plan's breaks x_k
 * of normalised arc length with trapezoid weights: the same fractions of
 * both inputs whatever t (no matches), so their points A_k, B_k and means
 * are taken once here, and "fit" needs per frame only sums over the
 * frame's own points (see km__place_planned). */
km_status km__place_plan_targets(km_morph *m, km_error *err) {
  size_t nb = km__frame_plan_pieces(m->plan) + 1;
  const double *x = km__frame_plan_breaks(m->plan);
  m->place_ab = km__malloc(nb * sizeof *m->place_ab);
  if (!m->place_ab)
    return km__fail(err, KM_ENOMEM, KM_FIELD_NONE, -1, NAN, NULL);
  double W = 0.0, qa[2] = {0, 0}, qb[2] = {0, 0};
  for (size_t k = 0; k < nb; k++) {
    double w =
        0.5 * ((k + 1 < nb ? x[k + 1] : x[k]) - (k > 0 ? x[k - 1] : x[k]));
    m->place_ab[k][4] = w;
    km__input_point_at(&m->in[0], x[k], m->place_ab[k]);
    km__input_point_at(&m->in[1], x[k], m->place_ab[k] + 2);
    for (int c = 0; c < 2; c++) {
      qa[c] += w * m->place_ab[k][c];
      qb[c] += w * m->place_ab[k][2 + c];
    }
    W += w;
  }
  m->place_w_sum = W;
  for (int c = 0; c < 2; c++) {
    m->place_qa[c] = qa[c] / W;
    m->place_qb[c] = qb[c] / W;
  }
  return KM_OK;
}

/* The rotation about the origin (*rot) and translation T that map the
 * points F (weights w, weighted mean fc) best onto Q (mean qc) in the
 * least-squares sense: 2-D Procrustes in closed form. */
static void procrustes(const double (*F)[2], const double (*Q)[2],
                       const double *w, size_t n, const double fc[2],
                       const double qc[2], double *rot, double T[2]) {
  double sx = 0.0, sy = 0.0;
  for (size_t j = 0; j < n; j++) {
    double fx = F[j][0] - fc[0], fy = F[j][1] - fc[1];
    double qx = Q[j][0] - qc[0], qy = Q[j][1] - qc[1];
    sx += w[j] * (fx * qx + fy * qy);
    sy += w[j] * (fx * qy - fy * qx);
  }
  *rot = atan2(sy, sx);
  double cr = cos(*rot), sr = sin(*rot);
  T[0] = qc[0] - (cr * fc[0] - sr * fc[1]);
  T[1] = qc[1] - (sr * fc[0] + cr * fc[1]);
}

/* Rigid motion (rotation about the origin by *rot, then translation) that
 * places a frame given by samples F at frame arc lengths s[j] (weights w,
 * arc length the samples stand for): "fit" maps them in the least-squares
 * sense onto the linear blend Q of the inputs at corresponding points. */
static km_status place_samples(const km_morph *m, double t,
                               const double (*F)[2], const double *s,
                               const double *w, size_t n, double *rot,
                               double T[2]) {
  const km__input *a = &m->in[0], *b = &m->in[1];
  *rot = 0.0;
  T[0] = (1 - t) * a->sig.start[0] + t * b->sig.start[0];
  T[1] = (1 - t) * a->sig.start[1] + t * b->sig.start[1];
  if (t == 0.0 || t == 1.0 || m->opt.anchor == KM_ANCHOR_START || n == 0)
    return KM_OK;
  double fc[2] = {0, 0}, qc[2] = {0, 0}, W = 0.0;
  double(*Q)[2] = km__malloc(n * sizeof *Q);
  if (!Q) return KM_ENOMEM;
  for (size_t j = 0; j < n; j++) {
    double ra, rb, pa[2], pb[2];
    km__corresponding(m, t, s[j], &ra, &rb);
    km__input_point_at(a, ra, pa);
    km__input_point_at(b, rb, pb);
    Q[j][0] = (1 - t) * pa[0] + t * pb[0];
    Q[j][1] = (1 - t) * pa[1] + t * pb[1];
    for (int k = 0; k < 2; k++) {
      fc[k] += w[j] * F[j][k];
      qc[k] += w[j] * Q[j][k];
    }
    W += w[j];
  }
  for (int k = 0; k < 2; k++) {
    fc[k] /= W;
    qc[k] /= W;
  }
  if (m->opt.anchor == KM_ANCHOR_CENTROID) {
    /* the blended start angle is kept; the wire centroid follows the
     * line between the inputs' centroids */
    T[0] = (1 - t) * a->centroid[0] + t * b->centroid[0] - fc[0];
    T[1] = (1 - t) * a->centroid[1] + t * b->centroid[1] - fc[1];
  } else {
    procrustes(F, (const double(*)[2])Q, w, n, fc, qc, rot, T);
  }
  km__free(Q);
  return KM_OK;
}

/* Placement of a frame curve whose parameter is arc length: samples at the
 * midpoints of FIT_N equal parts. */
km_status km__place_frame(const km_morph *m, double t, const km_curve *f,
                          double Lt, double *rot, double T[2]) {
  static const size_t N = FIT_N;
  double(*F)[2] = km__malloc(N * sizeof *F);
  double *s = km__malloc(2 * N * sizeof(double));
  double *w = s ? s + N : NULL;
  km_status st = KM_ENOMEM;
  if (!F || !s) goto done;
  for (size_t j = 0; j < N; j++) {
    double d[1][2];
    s[j] = Lt * ((double)j + 0.5) / (double)N;
    w[j] = 1.0;
    km_curve_eval(f, s[j], 0, d);
    F[j][0] = d[0][0];
    F[j][1] = d[0][1];
  }
  st = place_samples(m, t, (const double(*)[2])F, s, w, N, rot, T);
done:
  km__free(F);
  km__free(s);
  return st;
}

/* place_samples for a planned frame given by its points F at the plan's
 * breaks: the targets Q_k = (1 - t) A_k + t B_k are linear in t, so the
 * fit's sums split into a part of each input. */
void km__place_planned(const km_morph *m, double t, const double (*F)[2],
                       size_t nb, double *rot, double T[2]) {
  const km__input *a = &m->in[0], *b = &m->in[1];
  *rot = 0.0;
  T[0] = (1 - t) * a->sig.start[0] + t * b->sig.start[0];
  T[1] = (1 - t) * a->sig.start[1] + t * b->sig.start[1];
  if (t == 0.0 || t == 1.0 || m->opt.anchor == KM_ANCHOR_START) return;
  double fc[2] = {0, 0};
  for (size_t k = 0; k < nb; k++) {
    double w = m->place_ab[k][4];
    fc[0] += w * F[k][0];
    fc[1] += w * F[k][1];
  }
  fc[0] /= m->place_w_sum;
  fc[1] /= m->place_w_sum;
  if (m->opt.anchor == KM_ANCHOR_CENTROID) {
    T[0] = (1 - t) * a->centroid[0] + t * b->centroid[0] - fc[0];
    T[1] = (1 - t) * a->centroid[1] + t * b->centroid[1] - fc[1];
    return;
  }
  /* sum w (F - fc) . (Q - qc) = sum w (F - fc) . Q, as sum w (F - fc) = 0 */
  double sa = 0.0, ca = 0.0, sb = 0.0, cb = 0.0;
  for (size_t k = 0; k < nb; k++) {
    const double *q = m->place_ab[k];
    double fx = q[4] * (F[k][0] - fc[0]), fy = q[4] * (F[k][1] - fc[1]);
    sa += fx * q[0] + fy * q[1];
    ca += fx * q[1] - fy * q[0];
    sb += fx * q[2] + fy * q[3];
    cb += fx * q[3] - fy * q[2];
  }
  *rot = atan2((1 - t) * ca + t * cb, (1 - t) * sa + t * sb);
  double cr = cos(*rot), sr = sin(*rot);
  double qc[2] = {(1 - t) * m->place_qa[0] + t * m->place_qb[0],
                  (1 - t) * m->place_qa[1] + t * m->place_qb[1]};
  T[0] = qc[0] - (cr * fc[0] - sr * fc[1]);
  T[1] = qc[1] - (sr * fc[0] + cr * fc[1]);
}
