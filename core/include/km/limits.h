/* limits.h - every hard bound of libkmorph in one place, each with why.
 *
 * The contract layer enforces its own, configurable limits (control points
 * per curve, frames per request, bytes per answer) before calling the
 * core; these are the bounds the core itself will not go past whatever it
 * is asked. Each entry gives its default (what is used when the caller
 * asks for nothing), its hard bound (what no caller can get past) and the
 * reason; "where" names the functions that enforce it and the status they
 * return.
 */
#ifndef KM_LIMITS_H
#define KM_LIMITS_H

/* Curve degree. Default: none in the core (the service reconstructs at 3).
 * Bound: 1..9. Why: the range; above 9 Bernstein bases lose
 * digits, and per-span scratch is sized by it on the stack. Where:
 * km_curve_create (KM_EDEGREE), km_curve_elevate (KM_EDEGREE). */
#define KM_MIN_DEGREE 1
#define KM_MAX_DEGREE 9

/* Degree of scalar functions (kappa). Default: none. Bound: 0..20. Why: a
 * blended frame's curvature under a smooth correspondence composes
 * degree-6 pieces with quadratic reparameterisations (degree 13); 20
 * leaves room for user input. Where: km_fn_create, km_fn_antiderivative
 * (KM_EDEGREE). */
#define KM_MAX_FN_DEGREE 20

/* Magnitude of coordinates, knots, lengths and kappa coefficients; weights
 * lie in [1 / KM_MAX_COORDINATE, KM_MAX_COORDINATE]. Default: none. Bound:
 * 1e15. Why: beyond it a double keeps less than one binary digit below
 * the unit, so results would be noise; refuse rather than compute it.
 * Where: km_curve_create, km_fn_create, km_signature_create,
 * km_curve_interpolate, km_curve_transform, km_curve_reparam, the
 * km_path_* builders (KM_ERANGE; KM_EWEIGHT for weights). */
#define KM_MAX_COORDINATE 1e15

/* Smallest relative tolerance honoured. Default tolerance: 1e-5 of the
 * length in question. Bound: 1e-13 of it; tighter requests are raised to
 * it, not refused. Why: below ~1e-13 of the length the answer is rounding
 * noise. Where: km_signature_compute, km_reconstruct,
 * km_curve_self_intersections. */
#define KM_MIN_RELATIVE_TOLERANCE 1e-13

/* Nor below the rounding of the curve itself: its points are known to a
 * few ulps of its largest coordinate M, and directions computed from them
 * move a span by up to 8 p ulps of M (p the degree). Bound: a signature's
 * tolerance is at least KM_MIN_TOLERANCE_ULPS * p * DBL_EPSILON * M (twice
 * that movement); tighter requests are raised to it. A curve so small
 * beside its distance from the origin that this exceeds the default
 * tolerance (1e-5 of its length) is refused: its shape is rounding noise.
 * Where: km_signature_compute (KM_ERANGE). */
#define KM_MIN_TOLERANCE_ULPS 16

/* Pieces one signature, reconstruction or path may hold (the morph's
 * frame plans and closure tables: 64 times as many). Default: none (the
 * tolerance decides). Bound: 2,000,000. Why: bounds memory (~100 bytes a
 * piece) and time for adversarial input. Where: km_signature_compute,
 * km_reconstruct, km_path_line_to and the other builders, km_morph_create
 * and km_morph_frame (KM_ELIMIT). */
#define KM_MAX_PIECES 2000000

/* Output pieces of one reconstruction beyond two per piece of its
 * signature. Default: this bound, when the caller gives no bound of its
 * own (max_points 0 in km_reconstruct_within, km_morph_options). Bound:
 * 20,000. Why: a curve that turns hundreds of thousands of times (kappa
 * in the hundreds of thousands over a few units) would otherwise come
 * back as a B-spline of 400,000 control points, seconds to build and
 * larger than any input the service takes. Where: km_reconstruct and its
 * forms (KM_ELIMIT on the tolerance). */
#define KM_MAX_OUTPUT_PIECES 20000

/* Turns a signature given as input may make. Default: none. Bound: this
 * many plus one for every four coefficients of kappa, counted as sum
 * |c_i| (t_(i+p+1) - t_i) / (p + 1) plus the corners' |turn|, over 2 pi
 * (a bound on the integral of |kappa|). Why: tracing a curve costs some
 * 16 evaluations of theta a radian it turns (reconstruction, a morph's
 * tables and plan) whatever the tolerance, so turns, not pieces, bound
 * that work. A span of degree p turns fewer than p times, so signatures
 * computed from curves stay well inside; 2,000 turns keep preparing a
 * morph to some tens of milliseconds. Where: km_signature_create
 * (KM_ELIMIT, KM_FIELD_KAPPA_COEFFICIENTS). */
#define KM_MAX_SIGNATURE_TURNS 2000.0

/* Work of one signature, in evaluations of the curve and its derivative (a
 * piece's fit counts as many again as its nodes). Default: none. Bound:
 * BASE + PER_POINT per control point for the curve, and PER_SPAN for each
 * span. Why: legitimate curves at the default tolerance need about 60 a
 * span, up to about 550 a control point with a degenerate leg at every
 * joint (800 at 1e-7 of the length), and up to 80,000 in one span
 * (bisecting toward a cusp or a degenerate end); the budget is what about
 * a second of the fuzzing build (AddressSanitizer and coverage) affords.
 * A span whose directions are not resolved in double precision at the
 * asked tolerance would need ever more: it is refused after its own
 * share, and a curve after the whole budget, so that a refusal comes
 * within a few hundredths of a second at -O2 whatever the curve. Where:
 * km_signature_compute (KM_ELIMIT, KM_FIELD_TOLERANCE). */
#define KM_SIGNATURE_WORK_BASE 200000L
#define KM_SIGNATURE_WORK_PER_POINT 1000L
#define KM_SIGNATURE_WORK_PER_SPAN 250000L

/* Bisection depth when refining toward a singular point (a degenerate
 * control leg makes curvature grow like 1/sqrt(s)). Default and bound: 60
 * levels. Why: 2^-60 of a span is below double resolution. Where:
 * km_signature_compute (past it a piece whose direction barely moves is
 * taken as turning uniformly; any other is refused, KM_ENOCONVERGE). */
#define KM_MAX_REFINE_DEPTH 60

/* Steps of the safeguarded Newton iteration inverting arc length. Default
 * and bound: 50. Why: a step that leaves its bracket bisects instead, so
 * even 50 bisections reach 2^-50 of a span; Newton needs a handful. Where:
 * km_curve_param_at_length (it returns its best estimate, never fails). */
#define KM_MAX_NEWTON_ITERATIONS 50

#endif
