/* num_print.h - doubles as the shortest decimal that reads back exactly,
 * and as the shortest decimal within a stated distance, printed into a
 * caller's buffer without the C library's formatted output.
 *
 * Thread-safe and allocation-free: everything is on the caller's stack
 * and in a constant table.
 */
#ifndef KMAPI_NUM_PRINT_H
#define KMAPI_NUM_PRINT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* Bytes of the buffers the printers below write into, the terminating
 * NUL included; they may write past the NUL within them. A JSON number
 * is at most 24 characters (sign, 17 digits, point, "e-308"); an SVG
 * number, which prefers the fixed form by up to two characters, at most
 * 26. */
#define API_NUM_PRINT_MAX 32

/* A positive decimal digits * 10^exp10 with ndigits digits, the last one
 * non-zero (digits has no trailing zeros). */
typedef struct api_decimal {
  uint64_t digits;
  int exp10;
  int ndigits;
} api_decimal;

/* The shortest decimal that reads back as v (round to nearest, ties to
 * even, as strtod reads); among the shortest ones the nearest to v. v
 * must be finite and greater than zero. */
api_decimal api__shortest_decimal(double v);

/* v as a JSON number in its shortest round-trip form, NUL-terminated, in
 * out[0 .. API_NUM_PRINT_MAX), at most 24 characters; bytes after the
 * NUL within that room may be overwritten too. Integers below 1e15
 * are printed as integers (as %.15g would); others in the shorter of the
 * fixed and the scientific form ("0.25", "1.5e-7", "2e300"), fixed on a
 * tie. Negative zero is "-0".
 * Returns the length. JSON has no infinities: callers check finiteness
 * first, and a non-finite v prints as "null" rather than as garbage. */
size_t api__num_print(char *out, double v);

/* Write sign, digits * 10^exp10 (ndigits <= 17) into out[0 ..
 * API_NUM_PRINT_MAX) as api__num_print lays it out; returns the length
 * (at most 24 for exponents of doubles). */
size_t api__decimal_print(char *out, bool negative, api_decimal d);

/* The shortest decimal (fewest significant digits) within budget of x
 * among x rounded to 1, 2, ... significant digits, printed for SVG path
 * data: fixed ("120.5") below 1e16 unless it is more than two characters
 * longer than the scientific form ("1.2e-7"; no '+' and no leading zeros
 * in exponents); "0" when |x| <= budget. x must be finite, budget >= 0.
 * *got receives the double the printed text reads back as. Returns the
 * length (at most 26). */
size_t api__num_print_within(char *out, double x, double budget, double *got);

/* v rounded to the decimal grid 10^-decimals, by integer arithmetic: the
 * nearest integer N to v * 10^decimals printed as N * 10^-decimals in
 * api__num_print's layout ("0" for N = 0, the sign of a zero dropped).
 * Where the grid is finer than v's own precision (|v| 10^decimals >=
 * 2^53) or |decimals| > 22, v is printed exactly (api__num_print). *got
 * receives the double the text reads back as; |*got - v| <= 10^-decimals
 * / 2 + 2^-52 |v|. v must be finite. Returns the length (at most 24). */
size_t api__num_print_grid(char *out, double v, int decimals, double *got);

/* The double api__num_print_grid(_, v, decimals, &got) leaves in got,
 * without printing it (to try grids before printing on one). */
double api__num_grid_value(double v, int decimals);

/* The decimals of the coarsest grid 10^-decimals that is at most step
 * (> 0, finite): the grid "precision": "tolerance" prints on. */
int api__grid_decimals(double step);

#endif
