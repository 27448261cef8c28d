/* test_num_print.c - the shortest round-trip printer of doubles and the
 * printer within a budget.
 *
 * Oracles: the C library's correctly rounded conversions, which are an
 * independent implementation. A printed number must read back (strtod)
 * as the very double printed; it is the shortest such string when
 * snprintf's "%.*e" with one significant digit fewer does not read back
 * (a shorter decimal that reads back would make the nearest one of that
 * length read back too); and among decimals of its length it is the
 * nearest to the double, so it equals snprintf's whenever that reads
 * back. The text must be a JSON number by the grammar of RFC 8259.
 */
#include <ctype.h>
#include <float.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../api/src/num_print.h"
#include "testmain.h"

/* xorshift64*: reproducible bit patterns without the C library's rand. */
static uint64_t next_bits(uint64_t *state) {
  uint64_t x = *state;
  x ^= x >> 12;
  x ^= x << 25;
  x ^= x >> 27;
  *state = x;
  return x * 0x2545F4914F6CDD1Dull;
}

static double from_bits(uint64_t b) {
  double v;
  memcpy(&v, &b, sizeof v);
  return v;
}

static uint64_t to_bits(double v) {
  uint64_t b;
  memcpy(&b, &v, sizeof b);
  return b;
}

/* RFC 8259: -? (0 | [1-9][0-9]*) (. [0-9]+)? ([eE] [+-]? [0-9]+)? */
static bool is_json_number(const char *s) {
  if (*s == '-') s++;
  if (*s == '0')
    s++;
  else if (*s >= '1' && *s <= '9')
    while (isdigit((unsigned char)*s)) s++;
  else
    return false;
  if (*s == '.') {
    s++;
    if (!isdigit((unsigned char)*s)) return false;
    while (isdigit((unsigned char)*s)) s++;
  }
  if (*s == 'e' || *s == 'E') {
    s++;
    if (*s == '+' || *s == '-') s++;
    if (!isdigit((unsigned char)*s)) return false;
    while (isdigit((unsigned char)*s)) s++;
  }
  return *s == '\0';
}

/* Significant digits of a decimal string (leading and trailing zeros of
 * the digit sequence dropped) into digits, and the power of ten of its
 * first one. */
static void significand(const char *s, char *digits, size_t cap, int *lead) {
  size_t n = 0;
  int point = -1, count = 0, first = -1, exp = 0;
  for (const char *p = s; *p && *p != 'e' && *p != 'E'; p++) {
    if (*p == '.') {
      point = count;
      continue;
    }
    if (!isdigit((unsigned char)*p)) continue;
    if (first < 0 && *p != '0') first = count;
    if (first >= 0 && n + 1 < cap) digits[n++] = *p;
    count++;
  }
  const char *e = strpbrk(s, "eE");
  if (e) exp = atoi(e + 1);
  while (n > 1 && digits[n - 1] == '0') n--;
  digits[n] = '\0';
  if (point < 0) point = count;
  *lead = first < 0 ? 0 : point - first - 1 + exp;
}

/* Check everything the printer promises about v; returns the number of
 * significant digits printed. */
static int check_shortest(double v) {
  char out[API_NUM_PRINT_MAX], ref[64], mine[32], theirs[32];
  size_t len = api__num_print(out, v);
  assert_int_equal(len, strlen(out));
  assert_true(len <= 24);
  if (!is_json_number(out)) fail_msg("%s is no JSON number", out);
  double back = strtod(out, NULL);
  if (to_bits(back) != to_bits(v))
    fail_msg("%s reads back as %.17g, not %.17g", out, back, v);
  if (v == 0) return 1;
  int lead, ref_lead;
  significand(out, mine, sizeof mine, &lead);
  int nd = (int)strlen(mine);
  assert_true(nd >= 1 && nd <= 17);
  /* never longer than %.17g, which always reads back */
  snprintf(ref, sizeof ref, "%.17g", v);
  if (strlen(ref) < len) fail_msg("%s is longer than %s", out, ref);
  if (nd > 1) {
    snprintf(ref, sizeof ref, "%.*e", nd - 2, v);
    if (strtod(ref, NULL) == v)
      fail_msg("%s is not the shortest: %s reads back too", out, ref);
  }
  snprintf(ref, sizeof ref, "%.*e", nd - 1, v);
  if (strtod(ref, NULL) == v) {
    significand(ref, theirs, sizeof theirs, &ref_lead);
    if (strcmp(mine, theirs) != 0 || lead != ref_lead)
      fail_msg("%s is not the nearest of its length: %s", out, ref);
  }
  return nd;
}

static void random_bit_patterns_read_back_shortest_and_nearest(void **state) {
  (void)state;
  uint64_t s = 0x9E3779B97F4A7C15ull;
  long checked = 0;
  while (checked < 1000000) {
    double v = from_bits(next_bits(&s));
    if (!isfinite(v)) continue;
    check_shortest(v);
    checked++;
  }
}

static void every_shorter_candidate_fails_to_read_back(void **state) {
  (void)state;
  uint64_t s = 12345;
  char out[API_NUM_PRINT_MAX], ref[64], digits[32];
  for (int i = 0; i < 100000; i++) {
    /* doubles of ordinary magnitudes, where short decimals are common */
    double v = (double)(next_bits(&s) >> 11) * 0x1p-53 *
               pow(10.0, (double)(int)(next_bits(&s) % 20) - 10);
    if (i % 3 == 0) v = round(v * 1e6) / 1e6;
    api__num_print(out, v);
    int lead, nd;
    significand(out, digits, sizeof digits, &lead);
    nd = v == 0 ? 1 : (int)strlen(digits);
    for (int p = 1; p <= 16; p++) {
      snprintf(ref, sizeof ref, "%.*e", p - 1, v);
      bool reads_back = strtod(ref, NULL) == v;
      if (p < nd && reads_back)
        fail_msg("%s: %d digits (%s) read back", out, p, ref);
    }
    assert_true(strtod(out, NULL) == v);
  }
}

static void subnormals_and_the_ends_of_the_range_read_back(void **state) {
  (void)state;
  const double special[] = {5e-324,
                            -5e-324,
                            1e-323,
                            DBL_MIN,
                            -DBL_MIN,
                            DBL_MAX,
                            -DBL_MAX,
                            DBL_TRUE_MIN * 3,
                            nextafter(DBL_MIN, 0),
                            DBL_EPSILON,
                            1.0,
                            -1.0,
                            0.0,
                            -0.0,
                            2.2250738585072011e-308,
                            1.7976931348623157e308,
                            4.9406564584124654e-324};
  for (size_t i = 0; i < sizeof special / sizeof special[0]; i++)
    check_shortest(special[i]);
  char out[API_NUM_PRINT_MAX];
  api__num_print(out, 5e-324);
  assert_string_equal(out, "5e-324");
  api__num_print(out, DBL_MAX);
  assert_string_equal(out, "1.7976931348623157e308");
  api__num_print(out, DBL_MIN);
  assert_string_equal(out, "2.2250738585072014e-308");
  api__num_print(out, -0.0);
  assert_string_equal(out, "-0");
  api__num_print(out, 0.0);
  assert_string_equal(out, "0");
  /* every subnormal pattern of a sample, and each power of two with its
   * neighbours (where the interval of a double is lopsided) */
  uint64_t s = 7;
  for (int i = 0; i < 200000; i++)
    check_shortest(from_bits(next_bits(&s) & 0x000FFFFFFFFFFFFFull));
  for (int e = -1074; e <= 1023; e++) {
    double p = ldexp(1.0, e);
    check_shortest(p);
    check_shortest(nextafter(p, 0));
    check_shortest(nextafter(p, INFINITY));
  }
}

static void powers_of_ten_print_as_one_digit(void **state) {
  (void)state;
  char buf[64], out[API_NUM_PRINT_MAX], digits[32];
  for (int k = -323; k <= 308; k++) {
    snprintf(buf, sizeof buf, "1e%d", k);
    double v = strtod(buf, NULL);
    int lead;
    assert_int_equal(check_shortest(v), 1);
    api__num_print(out, v);
    significand(out, digits, sizeof digits, &lead);
    assert_int_equal(lead, k);
    check_shortest(nextafter(v, 0));
    check_shortest(nextafter(v, INFINITY));
  }
}

/* Doubles whose exact values sit on a tie of the decimal digit after the
 * shortest length: halves next to 2^52, where every double is an integer
 * or a half, and integers next to 2^53 and 2^54, where a double's
 * neighbours are 2 and 4 apart. */
static void halfway_cases_round_to_the_nearest_and_read_back(void **state) {
  (void)state;
  double bases[] = {0x1p52, 0x1p53, 0x1p54, 0x1p55, 0x1p60, 1e16, 1e17, 1e22};
  for (size_t b = 0; b < sizeof bases / sizeof bases[0]; b++) {
    double v = bases[b];
    for (int i = 0; i < 20000; i++) {
      check_shortest(v);
      v = nextafter(v, INFINITY);
    }
  }
  for (int i = 0; i < 20000; i++) check_shortest(0.5 + i);
  assert_int_equal(check_shortest(0.1 + 0.2), 17);
  assert_int_equal(check_shortest(9007199254740993.0), 16);
}

static void layout_is_fixed_for_integers_and_else_the_shorter(void **state) {
  (void)state;
  const struct {
    double v;
    const char *text;
  } cases[] = {
      {0.30000000000000004, "0.30000000000000004"},
      {1e20, "1e20"},
      {123456789012345.0, "123456789012345"},
      {1e15, "1e15"},
      {1e21, "1e21"},
      {123.456, "123.456"},
      {-2.5, "-2.5"},
      {0.25, "0.25"},
      {0.001, "1e-3"},
      {0.0015, "0.0015"},
      {1.5e-7, "1.5e-7"},
      {3.0, "3"},
      {1000.0, "1000"},
      {1e300, "1e300"},
      {-1.25e-300, "-1.25e-300"},
  };
  char out[API_NUM_PRINT_MAX];
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    api__num_print(out, cases[i].v);
    assert_string_equal(out, cases[i].text);
  }
}

/* The layout the header promises, built from significant digits and
 * the power of ten of the first one by plain string operations: fixed
 * when the leading digit is below 10^fixed_below and the number is an
 * integer below 10^integers_below or its fixed form is at most slack
 * characters longer than "d.ddde-x"; else that scientific form. */
static void expected_layout(char *out, bool negative, const char *digits,
                            int lead, int slack, int integers_below,
                            int fixed_below) {
  int nd = (int)strlen(digits), exp10 = lead - nd + 1;
  char fixed[400], sci[64];
  size_t f = 0;
  if (exp10 >= 0) {
    f += (size_t)sprintf(fixed, "%s", digits);
    for (int i = 0; i < exp10; i++) fixed[f++] = '0';
  } else if (lead >= 0) {
    memcpy(fixed, digits, (size_t)lead + 1);
    f = (size_t)lead + 1;
    fixed[f++] = '.';
    f += (size_t)sprintf(fixed + f, "%s", digits + lead + 1);
  } else {
    f += (size_t)sprintf(fixed, "0.");
    for (int i = 0; i < -lead - 1; i++) fixed[f++] = '0';
    f += (size_t)sprintf(fixed + f, "%s", digits);
  }
  fixed[f] = '\0';
  if (nd > 1)
    snprintf(sci, sizeof sci, "%c.%se%d", digits[0], digits + 1, lead);
  else
    snprintf(sci, sizeof sci, "%ce%d", digits[0], lead);
  bool use_fixed =
      lead < fixed_below && ((exp10 >= 0 && lead < integers_below) ||
                             (int)strlen(fixed) <= (int)strlen(sci) + slack);
  sprintf(out, "%s%s", negative ? "-" : "", use_fixed ? fixed : sci);
}

/* The shortest digits of v by the C library: the fewest significant
 * digits of %.*e that read back (nearest of their length, correctly
 * rounded), trailing zeros dropped. */
static int library_shortest(double v, char *digits, int *lead) {
  char ref[64];
  for (int p = 1; p <= 17; p++) {
    snprintf(ref, sizeof ref, "%.*e", p - 1, v);
    if (strtod(ref, NULL) == v) break;
  }
  significand(ref, digits, 32, lead);
  return (int)strlen(digits);
}

/* Every decimal exponent of doubles with every digit count 1 .. 17, and
 * the neighbours of each, against the layout built from the library's
 * digits; the printer writes nothing past API_NUM_PRINT_MAX. */
static void
every_exponent_and_digit_count_is_laid_out_as_promised(void **state) {
  (void)state;
  uint64_t s = 2024;
  char text[64], digits[32], want[400], out[API_NUM_PRINT_MAX + 16];
  for (int e = -324; e <= 308; e++) {
    for (int nd = 1; nd <= 17; nd++) {
      for (int k = 0; k < 6; k++) {
        double m = 1.0 + 8.999 * (double)(next_bits(&s) >> 11) * 0x1p-53;
        snprintf(text, sizeof text, "%.*fe%d", nd - 1, m, e);
        double v = strtod(text, NULL);
        double cases[] = {v, nextafter(v, 0), nextafter(v, INFINITY), -v};
        for (size_t c = 0; c < 4; c++) {
          double x = cases[c];
          if (!isfinite(x) || x == 0) continue;
          int lead;
          library_shortest(fabs(x), digits, &lead);
          expected_layout(want, x < 0, digits, lead, 0, 15, 21);
          memset(out, '#', sizeof out);
          size_t len = api__num_print(out, x);
          if (strcmp(out, want) != 0)
            fail_msg("%.17g printed as %s, not %s", x, out, want);
          assert_int_equal(len, strlen(want));
          for (size_t i = API_NUM_PRINT_MAX; i < sizeof out; i++)
            assert_int_equal(out[i], '#');
        }
      }
    }
  }
}

/* Round numbers near the fixed/scientific boundaries: integers with
 * trailing zeros up to and past 10^15 and 10^21, and small numbers
 * with up to four zeros after the point. */
static void integers_and_small_numbers_at_the_form_boundaries(void **state) {
  (void)state;
  char digits[32], want[400], out[API_NUM_PRINT_MAX];
  for (int lead = -8; lead <= 23; lead++) {
    for (int nd = 1; nd <= 17; nd++) {
      for (int first = 1; first <= 9; first += 4) {
        char text[64];
        /* first, then nd - 2 nines, then a 3: no trailing zero */
        int n = 0;
        text[n++] = (char)('0' + first);
        for (int i = 1; i < nd - 1; i++) text[n++] = '9';
        if (nd > 1) text[n++] = '3';
        snprintf(text + n, sizeof text - (size_t)n, "e%d", lead - nd + 1);
        double v = strtod(text, NULL);
        int l;
        library_shortest(v, digits, &l);
        expected_layout(want, false, digits, l, 0, 15, 21);
        api__num_print(out, v);
        if (strcmp(out, want) != 0)
          fail_msg("%s printed as %s, not %s", text, out, want);
      }
    }
  }
}

/* The SVG form lays its digits out by its own rule: fixed below 1e16
 * unless more than two characters longer than the scientific form. */
static void within_budget_layout_prefers_fixed_by_two_characters(void **state) {
  (void)state;
  uint64_t s = 5;
  char out[API_NUM_PRINT_MAX], digits[32], want[400];
  for (int e = -30; e <= 30; e++) {
    for (int i = 0; i < 300; i++) {
      double x = ((double)(next_bits(&s) >> 11) * 0x1p-53 + 0.05) *
                 pow(10.0, e) * (i % 2 ? -1 : 1);
      double budget = fabs(x) * pow(10.0, -(double)(i % 18)), got;
      api__num_print_within(out, x, budget, &got);
      if (got == 0) continue;
      int lead;
      significand(out, digits, sizeof digits, &lead);
      expected_layout(want, got < 0, digits, lead, 2, 0, 16);
      if (strcmp(out, want) != 0)
        fail_msg("%.17g within %g printed as %s, not %s", x, budget, out, want);
    }
  }
}

/* The SVG form: within budget, read back as *got, and no candidate one
 * significant digit shorter (x rounded to nearest by snprintf) within
 * budget. */
static void within_budget_prints_few_digits_within_the_budget(void **state) {
  (void)state;
  uint64_t s = 99;
  char out[API_NUM_PRINT_MAX], ref[64], digits[32];
  for (int i = 0; i < 300000; i++) {
    double x = ((double)(next_bits(&s) >> 11) * 0x1p-53 - 0.5) *
               pow(10.0, (double)(int)(next_bits(&s) % 16) - 6);
    double budget = i % 7 == 0 ? 0.0
                               : fabs(x) * pow(10.0, -(double)(i % 18)) *
                                     ((double)(next_bits(&s) % 1000) / 500);
    double got;
    size_t len = api__num_print_within(out, x, budget, &got);
    assert_int_equal(len, strlen(out));
    assert_true(len <= 26);
    double back = strtod(out, NULL);
    if (back != got)
      fail_msg("%s reads back as %.17g, not %.17g", out, back, got);
    if (!(fabs(back - x) <= budget))
      fail_msg("%s is %g from %.17g, budget %g", out, fabs(back - x), x,
               budget);
    if (budget == 0) assert_true(back == x);
    int lead;
    significand(out, digits, sizeof digits, &lead);
    int nd = back == 0 ? 0 : (int)strlen(digits);
    if (nd > 1) {
      snprintf(ref, sizeof ref, "%.*e", nd - 2, x);
      if (fabs(strtod(ref, NULL) - x) <= budget)
        fail_msg("%s (budget %g of %.17g): %s is shorter and within", out,
                 budget, x, ref);
    }
  }
}

static const struct CMUnitTest tests[] = {
    cmocka_unit_test(random_bit_patterns_read_back_shortest_and_nearest),
    cmocka_unit_test(every_shorter_candidate_fails_to_read_back),
    cmocka_unit_test(subnormals_and_the_ends_of_the_range_read_back),
    cmocka_unit_test(powers_of_ten_print_as_one_digit),
    cmocka_unit_test(halfway_cases_round_to_the_nearest_and_read_back),
    cmocka_unit_test(layout_is_fixed_for_integers_and_else_the_shorter),
    cmocka_unit_test(within_budget_prints_few_digits_within_the_budget),
    cmocka_unit_test(every_exponent_and_digit_count_is_laid_out_as_promised),
    cmocka_unit_test(integers_and_small_numbers_at_the_form_boundaries),
    cmocka_unit_test(within_budget_layout_prefers_fixed_by_two_characters),
};

TM_SUITE("num_print", tests, NULL, NULL);
