/* limits.h - every hard bound of libkmorph in one place, each with why.
 *
 * The contract layer enforces its own, configurable limits (control points
 * per curve, frames per request) before calling the core; these are the
 * bounds the core itself will not go past whatever it is asked.
 */
#ifndef KM_LIMITS_H
#define KM_LIMITS_H

/* Degrees 1..9: the range; above 9 Bernstein bases lose digits. */
#define KM_MIN_DEGREE 1
#define KM_MAX_DEGREE 9

/* Scalar functions (kappa) up to degree 20: a blended frame's curvature
 * under a smooth correspondence composes degree-6 pieces with quadratic
 * reparameterisations (degree 13); 20 leaves room for user input. */
#define KM_MAX_FN_DEGREE 20

/* Coordinates and lengths beyond 1e15 leave fewer than one digit of
 * sub-unit precision in a double; refuse rather than compute noise. */
#define KM_MAX_COORDINATE 1e15

/* Smallest relative tolerance honoured: below ~1e-13 of the length the
 * answer is rounding noise, so tighter requests are clamped to it. */
#define KM_MIN_RELATIVE_TOLERANCE 1e-13

/* Nor below the rounding of the curve itself: its points are known to a
 * few ulps of its largest coordinate M, and directions computed from them
 * move a span by up to 8 p ulps of M (p the degree). A signature's
 * tolerance is at least KM_MIN_TOLERANCE_ULPS * p * DBL_EPSILON * M; a
 * curve so small beside its distance from the origin that this exceeds
 * the default tolerance (1e-5 of its length) is refused (KM_ERANGE). */
#define KM_MIN_TOLERANCE_ULPS 16

/* Output pieces one signature or reconstruction may create. Bounds memory
 * and time for adversarial input (~100 bytes a piece). */
#define KM_MAX_PIECES 2000000

/* Output pieces of one reconstruction beyond two per piece of its
 * signature: a curve that turns hundreds of thousands of times (kappa in
 * the hundreds of thousands over a few units) would otherwise come back
 * as a B-spline of 400,000 control points, seconds to build and larger
 * than any input the service takes. */
#define KM_MAX_OUTPUT_PIECES 20000

/* Turns a signature given as input may make: at most this many plus one
 * for every four coefficients of kappa, counted as sum |c_i| (t_(i+p+1) -
 * t_i) / (p + 1) plus the corners' |turn|, over 2 pi (a bound on the
 * integral of |kappa|). Tracing a curve costs some 16 evaluations of theta
 * a radian it turns (reconstruction, a morph's tables and plan), whatever
 * the tolerance: a curve of length 4 whose kappa falls from 666,660 to -2
 * turns 212,204 times and took seconds at a tolerance that wanted only
 * 12,800 pieces. A span of degree p turns fewer than p times, so
 * signatures of curves stay well inside; 2,000 turns cost a morph some
 * 0.3 s to prepare in the fuzzing build (20 ms at -O2). */
#define KM_MAX_SIGNATURE_TURNS 2000.0

/* Work of one signature, in evaluations of the curve and its derivative
 * (a piece's fit counts as many again as its nodes): 0.03 to 0.1 us each
 * at -O2, some 1 to 2 us in the fuzzing build (AddressSanitizer and
 * coverage). Legitimate curves at the default tolerance need about 60 a
 * span, up to about 550 a control point with a degenerate leg at every
 * joint (an outline of 200 cubics; 800 at 1e-7 of its length, 1,600 at
 * 2e-10, which is refused), up to 80,000 in one span (bisecting toward a
 * cusp or a degenerate end). The budget is what a second of the fuzzing
 * build affords, some 70 ms at -O2. A span whose directions are not resolved in double precision at
 * the asked tolerance would need ever more: it is refused after its own
 * share, and a curve after the whole budget, so that a refusal comes
 * within a few hundredths of a second at -O2 (under a second fuzzed)
 * whatever the curve. */
#define KM_SIGNATURE_WORK_BASE 200000L
#define KM_SIGNATURE_WORK_PER_POINT 1000L
#define KM_SIGNATURE_WORK_PER_SPAN 250000L

/* Bisection depth when refining toward a singular point (a degenerate
 * control leg makes curvature grow like 1/sqrt(s)); 2^-60 of a span is
 * below double resolution. */
#define KM_MAX_REFINE_DEPTH 60

/* Newton iterations for arc-length inversion before falling back to
 * bisection. */
#define KM_MAX_NEWTON_ITERATIONS 50

#endif
