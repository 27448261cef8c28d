/* num_print.c - shortest round-trip decimals of doubles (Schubfach) and
 * their layout as JSON and SVG numbers.
 *
 * DESIGN. A double v = c * 2^q lies in the interval of reals that round
 * to it, [v - ulp/2, v + ulp/2] (half as far below at a power of two, the
 * ends included when c is even). Schubfach (R. Giulietti, "The Schubfach
 * way to render doubles", 2020) picks the decimal exponent k from q alone
 * so that the interval scaled by 10^-k holds at most one multiple of ten
 * and at least one integer: the shortest decimal is then the multiple of
 * ten when there is one, else the integer nearest to v * 10^-k. The ends
 * and v itself, scaled by 4 and by 10^-k, are computed with one 64 x 128
 * bit product each against a table of 128-bit upper bounds of powers of
 * ten (num_pow10.h, generated exactly by tools/gen_pow10_table.py), and
 * rounded to odd: the lowest bit says "inexact", which is all the
 * comparisons need. The product uses unsigned __int128 where the
 * compiler has it (gcc, clang) and four 32-bit products elsewhere.
 *
 * Layout is most of the rest of the cost, so the digits are made
 * sixteen at a time in one SSE2 register, or eight at a time in one
 * 64-bit word (no table, no loop), and moved to their final places with
 * fixed-size copies, the point or the leading zeros written around
 * them; the fixed/scientific choice is decided early for the common
 * "123.456" and computed from lengths only elsewhere.
 *
 * The SVG printer rounds the shortest digits to fewer significant
 * digits until the result lies within the budget, reading each
 * candidate back by one correctly rounded multiplication or division
 * (both operands exact doubles: Clinger's fast path) and by strtod only
 * where that path does not apply.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "num_pow10.h"
#include "num_print.h"

/* The printer of JSON numbers is one function, the shortest decimal and
 * its layout within: a call to each costs more than its arguments. */
#if defined(__GNUC__)
#define ALWAYS_INLINE inline __attribute__((always_inline))
#else
#define ALWAYS_INLINE inline
#endif

/* ---- 64 x 64 -> 128 bit products -------------------------------------- */

typedef struct u128 {
  uint64_t hi, lo;
} u128;

static inline u128 mul64(uint64_t a, uint64_t b) {
#if defined(__SIZEOF_INT128__)
  unsigned __int128 p = (unsigned __int128)a * b;
  return (u128){(uint64_t)(p >> 64), (uint64_t)p};
#else
  uint64_t a0 = (uint32_t)a, a1 = a >> 32, b0 = (uint32_t)b, b1 = b >> 32;
  uint64_t p00 = a0 * b0, p01 = a0 * b1, p10 = a1 * b0, p11 = a1 * b1;
  uint64_t mid = (p00 >> 32) + (uint32_t)p01 + (uint32_t)p10;
  return (u128){p11 + (p01 >> 32) + (p10 >> 32) + (mid >> 32),
                (mid << 32) | (uint32_t)p00};
#endif
}

/* floor(cp * g / 2^128) with its lowest bit set when the product is not
 * an integer (g is an upper bound, hence "> 1" rather than "!= 0"). */
static inline uint64_t round_to_odd(const uint64_t g[2], uint64_t cp) {
  u128 low = mul64(cp, g[1]);
  u128 high = mul64(cp, g[0]);
  uint64_t mid = high.lo + low.hi;
  uint64_t top = high.hi + (mid < high.lo);
  return top | (mid > 1);
}

/* floor(x / 2^s) for negative x too (x > -2^40, s <= 40), without
 * relying on how >> treats negative numbers and without a branch: x is
 * shifted up to a non-negative number by a multiple of 2^s first. */
static inline int floor_shift(int64_t x, int s) {
  return (int)(((x + ((int64_t)1 << 40)) >> s) - ((int64_t)1 << (40 - s)));
}

/* floor(log10(2^q)), floor(log10(3/4 2^q)) and floor(log2(10^k)) for the
 * exponents of doubles (checked exactly over the whole range when the
 * constants were chosen). */
static inline int floor_log10_pow2(int q) {
  return floor_shift((int64_t)q * 1262611, 22);
}
static inline int floor_log10_three_quarters_pow2(int q) {
  return floor_shift((int64_t)q * 1262611 - 524031, 22);
}
static inline int floor_log2_pow10(int k) {
  return floor_shift((int64_t)k * 1741647, 19);
}

static const uint64_t pow10_u64[20] = {1u,
                                       10u,
                                       100u,
                                       1000u,
                                       10000u,
                                       100000u,
                                       1000000u,
                                       10000000u,
                                       100000000u,
                                       1000000000u,
                                       10000000000u,
                                       100000000000u,
                                       1000000000000u,
                                       10000000000000u,
                                       100000000000000u,
                                       1000000000000000u,
                                       10000000000000000u,
                                       100000000000000000u,
                                       1000000000000000000u,
                                       10000000000000000000u};

static int count_digits(uint64_t d) {
#if defined(__GNUC__)
  /* from the bit length: 1233 / 2^12 is just above log10(2), so t is the
   * digit count of the lowest number of that many bits, less one, or the
   * count itself; one comparison tells */
  if (d == 0) return 1;
  int t = ((64 - __builtin_clzll(d)) * 1233) >> 12;
  return t + 1 - (d < pow10_u64[t] ? 1 : 0);
#else
  int n = 1;
  while (n < 20 && d >= pow10_u64[n]) n++;
  return n;
#endif
}

/* The number of zero bits below the lowest one bit of c (c > 0). */
static inline int trailing_zeros(uint64_t c) {
#if defined(__GNUC__)
  return __builtin_ctzll(c);
#else
  int n = 0;
  while ((c & 1) == 0) {
    c >>= 1;
    n++;
  }
  return n;
#endif
}

static api_decimal normalised(uint64_t digits, int exp10) {
  while (digits % 10 == 0) {
    digits /= 10;
    exp10++;
  }
  return (api_decimal){digits, exp10, count_digits(digits)};
}

/* ---- the shortest decimal ---------------------------------------------- */

/* api__shortest_decimal of the double with these bits (sign clear),
 * inlined into the printers. */
static ALWAYS_INLINE api_decimal shortest(uint64_t bits) {
  uint64_t fraction = bits & (((uint64_t)1 << 52) - 1);
  int biased = (int)((bits >> 52) & 0x7ff);
  uint64_t c;
  int q;
  if (biased != 0) {
    c = fraction | ((uint64_t)1 << 52);
    q = biased - 1075;
    /* an integer below 2^53 is its own shortest decimal */
    if ((unsigned)-q <= 52 && trailing_zeros(c) >= -q)
      return normalised(c >> -q, 0);
  } else {
    c = fraction;
    q = -1074;
  }
  bool even = (c & 1) == 0;
  bool lower_closer = fraction == 0 && biased > 1;
  uint64_t cbl = 4 * c - 2 + (lower_closer ? 1 : 0);
  uint64_t cb = 4 * c, cbr = 4 * c + 2;
  int k =
      lower_closer ? floor_log10_three_quarters_pow2(q) : floor_log10_pow2(q);
  int h = q + floor_log2_pow10(-k) + 1;
  const uint64_t *g = api_pow10_g[-k - API_POW10_K_MIN];
  uint64_t vbl = round_to_odd(g, cbl << h);
  uint64_t vb = round_to_odd(g, cb << h);
  uint64_t vbr = round_to_odd(g, cbr << h);
  uint64_t lower = vbl + (even ? 0 : 1), upper = vbr - (even ? 0 : 1);
  uint64_t s = vb / 4;
  if (s >= 10) {
    /* a multiple of ten inside the interval is shorter; at most one of
     * the two neighbours of v * 10^-k among them can be inside */
    uint64_t sp = s / 10;
    bool below_inside = lower <= 40 * sp, above_inside = 40 * sp + 40 <= upper;
    if (below_inside != above_inside)
      return normalised(sp + (above_inside ? 1 : 0), k + 1);
  }
  bool below_inside = lower <= 4 * s, above_inside = 4 * s + 4 <= upper;
  if (below_inside != above_inside)
    return normalised(s + (above_inside ? 1 : 0), k);
  /* both neighbours are inside: the nearer one, the even one on a tie */
  uint64_t mid = 4 * s + 2;
  bool up = vb > mid || (vb == mid && (s & 1) != 0);
  return normalised(s + (up ? 1 : 0), k);
}

api_decimal api__shortest_decimal(double v) {
  uint64_t bits;
  memcpy(&bits, &v, sizeof bits);
  return shortest(bits);
}

/* ---- layout --------------------------------------------------------- */

static const char two_digits[201] = "00010203040506070809"
                                    "10111213141516171819"
                                    "20212223242526272829"
                                    "30313233343536373839"
                                    "40414243444546474849"
                                    "50515253545556575859"
                                    "60616263646566676869"
                                    "70717273747576777879"
                                    "80818283848586878889"
                                    "90919293949596979899";

#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
/* The 8 digits of d < 10^8, leading zeros included, into out[0 .. 8),
 * all in one 64-bit word: d splits into two 4-digit halves in 32-bit
 * lanes, each half into two 2-digit quarters in 16-bit lanes, each
 * quarter into two digits in bytes. A quotient by 100 (by 10) is a
 * product by 10486 / 2^20 (103 / 2^10), exact below 10^4 (below 100),
 * and no lane's product reaches the next lane; the remainder joins its
 * quotient in the lane above by one product with -(100 * 2^16 - 1)
 * (-(10 * 2^8 - 1)). Little-endian: the lowest lane is the first
 * character. */
static inline void put_8_digits(char *out, uint32_t d) {
  uint64_t halves = (d / 10000) | ((uint64_t)(d % 10000) << 32);
  uint64_t hundreds = ((halves * 10486) >> 20) & 0x0000007F0000007Full;
  uint64_t quarters = (halves << 16) - hundreds * 6553599;
  uint64_t tens = ((quarters * 103) >> 10) & 0x000F000F000F000Full;
  uint64_t digits = (quarters << 8) - tens * 2559;
  digits += 0x3030303030303030ull;
  memcpy(out, &digits, 8);
}
#else
/* The 8 digits of d < 10^8, leading zeros included, into out[0 .. 8):
 * two at a time, in 32-bit arithmetic */
static inline void put_8_digits(char *out, uint32_t d) {
  uint32_t hi = d / 10000, lo = d % 10000;
  memcpy(out, &two_digits[2 * (hi / 100)], 2);
  memcpy(out + 2, &two_digits[2 * (hi % 100)], 2);
  memcpy(out + 4, &two_digits[2 * (lo / 100)], 2);
  memcpy(out + 6, &two_digits[2 * (lo % 100)], 2);
}
#endif

#if defined(__SSE2__)
/* The 16 digits of high * 10^8 + low (both below 10^8), leading zeros
 * included, into out[0 .. 16): as put_8_digits does in a 64-bit word,
 * but for both halves at once in one 128-bit register, and with the
 * products' high parts as the quotients: by 10^4 a product by
 * 109951163 / 2^40 (exact below 10^8), by 100 one by 5243 / 2^19 (exact
 * below 10^4), by 10 one by 6554 / 2^16 (exact below 100). */
static inline void put_16_digits(char *out, uint32_t high, uint32_t low) {
  __m128i halves = _mm_set_epi64x((long long)low, (long long)high);
  __m128i first_four =
      _mm_srli_epi64(_mm_mul_epu32(halves, _mm_set1_epi32(109951163)), 40);
  __m128i last_four =
      _mm_sub_epi64(halves, _mm_mul_epu32(first_four, _mm_set1_epi32(10000)));
  __m128i groups = _mm_or_si128(first_four, _mm_slli_epi64(last_four, 32));
  __m128i hundreds =
      _mm_srli_epi16(_mm_mulhi_epu16(groups, _mm_set1_epi16(5243)), 3);
  __m128i rest =
      _mm_sub_epi16(groups, _mm_mullo_epi16(hundreds, _mm_set1_epi16(100)));
  __m128i pairs = _mm_or_si128(hundreds, _mm_slli_epi32(rest, 16));
  __m128i tens = _mm_mulhi_epu16(pairs, _mm_set1_epi16(6554));
  __m128i ones =
      _mm_sub_epi16(pairs, _mm_mullo_epi16(tens, _mm_set1_epi16(10)));
  __m128i digits = _mm_or_si128(tens, _mm_slli_epi16(ones, 8));
  digits = _mm_add_epi8(digits, _mm_set1_epi8('0'));
  _mm_storeu_si128((__m128i *)(void *)out, digits);
}
#else
static inline void put_16_digits(char *out, uint32_t high, uint32_t low) {
  put_8_digits(out, high);
  put_8_digits(out + 8, low);
}
#endif

/* Room for the digits of a decimal: they end at DIGITS_END, and every
 * writer below copies 16 or 24 bytes from anywhere among them in fixed
 * sizes (a few moves, no call) rather than exactly as many as there
 * are; the bytes after them are defined so that such a copy never
 * reads an indeterminate byte. */
#define DIGITS_END 24
#define DIGITS_ROOM 48

/* The n <= 20 decimal digits of d, in text ending at DIGITS_END, eight
 * or sixteen at a time; where they start. */
static inline const char *put_digits(char text[DIGITS_ROOM], uint64_t d,
                                     int n) {
  memset(text + DIGITS_END, '0', DIGITS_ROOM - DIGITS_END);
  if (d < 100000000u) {
    put_8_digits(text + DIGITS_END - 8, (uint32_t)d);
  } else if (d < 10000000000000000u) {
    put_16_digits(text + DIGITS_END - 16, (uint32_t)(d / 100000000u),
                  (uint32_t)(d % 100000000u));
  } else {
    /* at most 4 digits before the last 16 (d < 2^64) */
    uint32_t top = (uint32_t)(d / 10000000000000000u);
    uint64_t r = d % 10000000000000000u;
    put_16_digits(text + DIGITS_END - 16, (uint32_t)(r / 100000000u),
                  (uint32_t)(r % 100000000u));
    memcpy(text + DIGITS_END - 20, &two_digits[2 * (top / 100)], 2);
    memcpy(text + DIGITS_END - 18, &two_digits[2 * (top % 100)], 2);
  }
  return text + DIGITS_END - n;
}

/* The n <= 17 digits at from into to: one fixed-size move and a byte. */
static inline void copy_digits(char *to, const char *from, int n) {
  memcpy(to, from, 16);
  if (n > 16) to[16] = from[16];
}

/* Characters of the fixed form of d (sign excluded). */
static int fixed_length(api_decimal d) {
  int lead = d.exp10 + d.ndigits - 1;
  if (d.exp10 >= 0) return d.ndigits + d.exp10;
  if (lead >= 0) return d.ndigits + 1;
  return 1 - lead + d.ndigits;
}

static int exponent_length(int e) {
  int a = e < 0 ? -e : e;
  return (e < 0 ? 1 : 0) + (a >= 100 ? 3 : a >= 10 ? 2 : 1);
}

static int scientific_length(api_decimal d) {
  int lead = d.exp10 + d.ndigits - 1;
  return d.ndigits + (d.ndigits > 1 ? 1 : 0) + 1 + exponent_length(lead);
}

/* The writers below put the n <= 17 digits at text (put_digits) at
 * their final places and return the length written. Fixed-size moves
 * cost less than exact ones, so they also write bytes past the end of
 * the number: up to 25 bytes past out for the layouts of this file
 * (the fixed form below one with at most 4 zeros after the point),
 * fewer than API_NUM_PRINT_MAX with a sign. */

/* d with its point inside the digits (exp10 < 0 <= lead): "123.456". */
static inline size_t put_point(char *out, const char *text, int n, int lead) {
  /* at most 16 digits before the point and at most 16 after it; more
   * than 8 after it only when at most 8 come before */
  memcpy(out, text, 16);
  out[lead + 1] = '.';
  if (n - lead - 1 <= 8)
    memcpy(out + lead + 2, text + lead + 1, 8);
  else
    memcpy(out + lead + 2, text + lead + 1, 16);
  return (size_t)n + 1;
}

/* d below 1 (lead < 0): "0.00123". */
static inline size_t put_below_one(char *out, const char *text, int n,
                                   int lead) {
  int zeros = -lead - 1;
  if (zeros <= 6)
    memcpy(out, "0.000000", 8);
  else {
    memcpy(out, "0.", 2);
    memset(out + 2, '0', (size_t)zeros);
  }
  copy_digits(out + 2 + zeros, text, n);
  return (size_t)(2 + zeros + n);
}

/* d an integer (exp10 >= 0): "1200". */
static inline size_t put_integer(char *out, const char *text, int n,
                                 int exp10) {
  copy_digits(out, text, n);
  if (exp10 <= 8)
    memcpy(out + n, "00000000", 8);
  else
    memset(out + n, '0', (size_t)exp10);
  return (size_t)(n + exp10);
}

/* d as "1.25e-7": no '+' and no leading zeros in the exponent. */
static inline size_t put_scientific(char *out, const char *text, int n,
                                    int lead) {
  size_t len = 1;
  out[0] = text[0];
  if (n > 1) {
    out[1] = '.';
    memcpy(out + 2, text + 1, 16);
    len = (size_t)n + 1;
  }
  out[len++] = 'e';
  if (lead < 0) {
    out[len++] = '-';
    lead = -lead;
  }
  if (lead < 10) {
    out[len++] = (char)('0' + lead);
  } else if (lead < 100) {
    memcpy(out + len, &two_digits[2 * lead], 2);
    len += 2;
  } else {
    out[len] = (char)('0' + lead / 100);
    memcpy(out + len + 1, &two_digits[2 * (lead % 100)], 2);
    len += 3;
  }
  return len;
}

/* sign and d: fixed when its leading digit is below 10^fixed_below and
 * it is an integer below 10^integers_below or at most slack (>= 0)
 * characters longer than the scientific form. The first test is the
 * common case (a point among the digits, where the fixed form is the
 * shorter by at least two characters) decided early. */
static ALWAYS_INLINE size_t layout(char *out, bool negative, api_decimal d,
                                   int slack, int integers_below,
                                   int fixed_below) {
  char text[DIGITS_ROOM];
  const char *digits = put_digits(text, d.digits, d.ndigits);
  int lead = d.exp10 + d.ndigits - 1;
  out[0] = '-';
  char *at = out + (negative ? 1 : 0);
  size_t n;
  if (d.exp10 < 0 && lead >= 0 && lead < fixed_below)
    n = put_point(at, digits, d.ndigits, lead);
  else if (lead < fixed_below &&
           ((d.exp10 >= 0 && lead < integers_below) ||
            fixed_length(d) <= scientific_length(d) + slack))
    n = d.exp10 >= 0 ? put_integer(at, digits, d.ndigits, d.exp10)
                     : put_below_one(at, digits, d.ndigits, lead);
  else
    n = put_scientific(at, digits, d.ndigits, lead);
  at[n] = '\0';
  return (size_t)(at - out) + n;
}

size_t api__decimal_print(char *out, bool negative, api_decimal d) {
  return layout(out, negative, d, 0, 15, 21);
}

size_t api__num_print(char *out, double v) {
  uint64_t bits;
  memcpy(&bits, &v, sizeof bits);
  bool negative = bits >> 63 != 0;
  bits &= ~((uint64_t)1 << 63);
  if (bits >= (uint64_t)0x7ff << 52) {
    memcpy(out, "null", 5);
    return 4;
  }
  if (bits == 0) {
    size_t n = 0;
    if (negative) out[n++] = '-';
    out[n++] = '0';
    out[n] = '\0';
    return n;
  }
  return layout(out, negative, shortest(bits), 0, 15, 21);
}

/* ---- within a budget ------------------------------------------------ */

/* The double nearest to digits * 10^exp10, by one correctly rounded
 * operation on exact operands where it applies; false elsewhere. */
static bool exact_value(uint64_t digits, int exp10, double *out) {
  static const double p10[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                 1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
  if (digits > ((uint64_t)1 << 53) || exp10 < -22 || exp10 > 22) return false;
  double m = (double)digits;
  *out = exp10 >= 0 ? m * p10[exp10] : m / p10[-exp10];
  return true;
}

/* The sign of a - d, exactly: the product a * 10^-exp10 is split into
 * its rounded value and its rounding error (fma), both exact doubles.
 * UNKNOWN_SIDE where that does not apply (d beyond 2^53, or a power of
 * ten that is no exact double). */
#define UNKNOWN_SIDE 2
static int side_of_decimal(double a, api_decimal d) {
  static const double p10[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                 1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
  if (d.digits <= ((uint64_t)1 << 53) && d.exp10 <= 0 && d.exp10 >= -22) {
    double scale = p10[-d.exp10];
    double product = a * scale;
    double error = fma(a, scale, -product);
    double m = (double)d.digits;
    double diff = (product - m) + error;
    return diff > 0 ? 1 : diff < 0 ? -1 : 0;
  }
  if (d.digits <= ((uint64_t)1 << 53) && d.exp10 > 0 && d.exp10 <= 22) {
    /* m * 10^e against a: a / 10^e compared through its remainder */
    double scale = p10[d.exp10];
    double m = (double)d.digits;
    double product = m * scale;
    double error = fma(m, scale, -product);
    double diff = (a - product) - error;
    return diff > 0 ? 1 : diff < 0 ? -1 : 0;
  }
  return UNKNOWN_SIDE;
}

/* The double digits * 10^exp10 reads back as; false only if it is not
 * finite. */
static bool candidate_value(uint64_t digits, int exp10, double *out) {
  if (exact_value(digits, exp10, out)) return true;
  char text[API_NUM_PRINT_MAX];
  layout(text, false, normalised(digits, exp10), 0, 0, 0);
  *out = strtod(text, NULL);
  return isfinite(*out);
}

/* a (> 0, with shortest decimal d) rounded to p < d.ndigits significant
 * digits, p = 0 meaning the decade above a (0.00087 to 0.001), as the
 * correctly rounded %.*e would: the shortest digits round the same way
 * as a itself except on a tie of those digits, where a lies on either
 * side; its side is found exactly, an exact tie goes to the even
 * neighbour. *value receives the double the result reads back as; false
 * when it is zero or not finite. */
static bool rounded_to(double a, api_decimal d, int p, api_decimal *out,
                       double *value) {
  int drop = d.ndigits - p;
  uint64_t unit = pow10_u64[drop];
  uint64_t r = d.digits / unit, rest = d.digits % unit;
  int exp10 = d.exp10 + drop;
  uint64_t cand = r;
  if (rest > unit - rest) {
    cand = r + 1;
  } else if (rest == unit - rest) {
    int side = side_of_decimal(a, d);
    if (side == UNKNOWN_SIDE) {
      /* the neighbour whose double is nearer */
      double below;
      if (r > 0 && candidate_value(r, exp10, &below) &&
          candidate_value(r + 1, exp10, value) &&
          fabs(below - a) < fabs(*value - a)) {
        *value = below;
        *out = normalised(r, exp10);
        return true;
      }
      cand = r + 1;
    } else {
      cand = r + (side > 0 || (side == 0 && r % 2 != 0) ? 1 : 0);
    }
  }
  if (cand == 0 || !candidate_value(cand, exp10, value)) return false;
  *out = normalised(cand, exp10);
  return true;
}

size_t api__num_print_within(char *out, double x, double budget, double *got) {
  double a = fabs(x);
  bool negative = x < 0;
  if (a <= budget) {
    out[0] = '0';
    out[1] = '\0';
    *got = 0.0;
    return 1;
  }
  uint64_t bits;
  memcpy(&bits, &a, sizeof bits);
  api_decimal d = shortest(bits);
  int lead = d.exp10 + d.ndigits - 1;
  int start = d.ndigits;
  if (budget > 0) {
    /* digits down to about the budget's decade, one less for the slack
     * of the estimate */
    start = lead - floor_log10_pow2(ilogb(budget)) - 1;
    if (start < 0) start = 0;
  }
  for (int p = start; p < d.ndigits; p++) {
    api_decimal c;
    double value;
    if (rounded_to(a, d, p, &c, &value) && fabs(value - a) <= budget) {
      *got = negative ? -value : value;
      return layout(out, negative, c, 2, 0, 16);
    }
  }
  *got = x;
  return layout(out, negative, d, 2, 0, 16);
}

/* ---- on a decimal grid ---------------------------------------------- */

static const double exact_pow10[23] = {
    1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
    1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

double api__num_grid_value(double v, int decimals) {
  if (decimals > 22 || decimals < -22) return v;
  double scaled =
      decimals >= 0 ? v * exact_pow10[decimals] : v / exact_pow10[-decimals];
  if (!(fabs(scaled) < 0x1p53)) return v;
  double n = nearbyint(scaled);
  if (n == 0) return 0.0;
  return decimals >= 0 ? n / exact_pow10[decimals] : n * exact_pow10[-decimals];
}

size_t api__num_print_grid(char *out, double v, int decimals, double *got) {
  if (decimals > 22 || decimals < -22) {
    *got = v;
    return api__num_print(out, v);
  }
  double scaled =
      decimals >= 0 ? v * exact_pow10[decimals] : v / exact_pow10[-decimals];
  if (!(fabs(scaled) < 0x1p53)) {
    *got = v;
    return api__num_print(out, v);
  }
  double n = nearbyint(scaled);
  if (n == 0) {
    out[0] = '0';
    out[1] = '\0';
    *got = 0.0;
    return 1;
  }
  uint64_t digits = (uint64_t)fabs(n);
  *got = decimals >= 0 ? n / exact_pow10[decimals] : n * exact_pow10[-decimals];
  return layout(out, n < 0, normalised(digits, -decimals), 0, 15, 21);
}

int api__grid_decimals(double step) {
  int d = (int)ceil(-log10(step));
  /* log10 may be off by an ulp at a power of ten: settle it exactly */
  while (d < 400 && pow(10.0, -d) > step) d++;
  while (d > -400 && pow(10.0, -(d - 1)) <= step) d--;
  return d;
}
