/* test_json_parse.c - request bodies are parsed within a memory budget
 * proportional to their size, repeated member names are refused with
 * their place, and arrays of numbers read the same values and name the
 * same bad elements however the tree stores them.
 *
 * The heap a parse takes is counted through cJSON's hooks, which every
 * allocation of the parser goes through: each block is charged its size
 * plus 16 bytes, glibc's header and rounding on average.
 */
#include "api_testutil.h"

#include "../../api/src/internal.h"
#include "testmain.h"

#define SIG API_ROUTE_SIGNATURE
#define MORPH API_ROUTE_MORPH

/* ------------------------------------------------------ counting heap */

static size_t heap_now, heap_peak, heap_blocks;

/* Each block carries its size in front of it. */
static void *counting_malloc(size_t n) {
  max_align_t *b = malloc(sizeof(max_align_t) + n);
  if (b == NULL) return NULL;
  *(size_t *)(void *)b = n;
  heap_now += n + 16;
  heap_blocks++;
  if (heap_now > heap_peak) heap_peak = heap_now;
  return b + 1;
}

static void counting_free(void *p) {
  max_align_t *b;
  if (p == NULL) return;
  b = (max_align_t *)p - 1;
  heap_now -= *(size_t *)(void *)b + 16;
  free(b);
}

static void count_heap(bool on) {
  cJSON_Hooks hooks = {counting_malloc, counting_free};
  cJSON_InitHooks(on ? &hooks : NULL);
  heap_now = heap_peak = heap_blocks = 0;
}

/* ------------------------------------------------------------ helpers */

static const char *detail_of(const cJSON *problem) {
  const cJSON *d = cJSON_GetObjectItemCaseSensitive(problem, "detail");
  assert_true(cJSON_IsString(d));
  return d->valuestring;
}

/* The answer to body is 400 malformed-json whose detail is want. */
static void expect_detail(api_route route, const char *body, const char *want) {
  cJSON *j = at_expect_problem(route, body, 400, NULL);
  const cJSON *t = cJSON_GetObjectItemCaseSensitive(j, "type");
  assert_string_equal(t->valuestring, "/problems/malformed-json");
  if (strcmp(detail_of(j), want) != 0)
    print_error("detail \"%s\", expected \"%s\"\n", detail_of(j), want);
  assert_string_equal(detail_of(j), want);
  cJSON_Delete(j);
}

/* Byte offset of the n-th (1-based) occurrence of needle in hay. */
static size_t nth_offset(const char *hay, const char *needle, int n) {
  const char *p = hay - 1;
  for (int i = 0; i < n; i++) {
    p = strstr(p + 1, needle);
    assert_non_null(p);
  }
  return (size_t)(p - hay);
}

static api_config default_config(void) {
  api_config cfg;
  api_config_default(&cfg);
  return cfg;
}

/* ------------------------------------------------- duplicate members */

static void duplicate_top_level_member_is_400_naming_it(void **state) {
  (void)state;
  const char *body = "{\"tolerance\":1e-3,\"curve\":{\"type\":\"svg\","
                     "\"d\":\"M0 0L1 0\"},\"tolerance\":1e-6}";
  char want[200];
  snprintf(want, sizeof want,
           "duplicate member \"tolerance\" at the top level (byte %zu)",
           nth_offset(body, "\"tolerance\"", 2));
  expect_detail(SIG, body, want);
}

static void duplicate_nested_member_is_400_naming_its_object(void **state) {
  (void)state;
  const char *body =
      "{\"from\":{\"type\":\"bspline\",\"degree\":1,"
      "\"control_points\":[[0,0],[1,0]],\"knots\":[0,0,1,1],\"degree\":2},"
      "\"to\":{\"type\":\"svg\",\"d\":\"M0 0L1 0\"}}";
  char want[200];
  snprintf(want, sizeof want, "duplicate member \"degree\" at /from (byte %zu)",
           nth_offset(body, "\"degree\"", 2));
  expect_detail(MORPH, body, want);
}

static void duplicate_in_an_array_element_names_the_element(void **state) {
  (void)state;
  /* the key "a/b" is written ~1 in a pointer (RFC 6901) */
  const char *body =
      "{\"x\":{\"a/b\":[{\"s\":1},{\"s\":1,\"turn\":0,\"s\":2}]}}";
  char want[200];
  snprintf(want, sizeof want, "duplicate member \"s\" at /x/a~1b/1 (byte %zu)",
           nth_offset(body, "\"s\"", 3));
  expect_detail(SIG, body, want);
}

static void escaped_spelling_of_a_name_is_the_same_member(void **state) {
  (void)state;
  /* "\u0063urve" is "curve" (RFC 8259 section 7) */
  const char *body = "{\"curve\":{},\"\\u0063urve\":{}}";
  char want[200];
  snprintf(want, sizeof want,
           "duplicate member \"curve\" at the top level (byte %zu)",
           nth_offset(body, "\"\\u0063", 1));
  expect_detail(SIG, body, want);
}

static void first_repeat_in_the_text_is_named(void **state) {
  (void)state;
  /* "b" repeats before "a" does */
  const char *body = "{\"a\":1,\"b\":2,\"b\":3,\"a\":4}";
  char want[200];
  snprintf(want, sizeof want,
           "duplicate member \"b\" at the top level (byte %zu)",
           nth_offset(body, "\"b\"", 2));
  expect_detail(SIG, body, want);
}

static void repeat_among_many_members_is_found(void **state) {
  (void)state;
  /* 50,000 distinct names, then the first again: a pairwise check would
   * make 1.25e9 comparisons. Long values keep the body within its memory
   * budget. */
  at_buf b = {0};
  size_t at;
  char want[200];
  at_printf(&b, "{");
  for (int i = 0; i < 50000; i++) at_printf(&b, "\"k%d\":\"%0100d\",", i, i);
  at = b.n;
  at_printf(&b, "\"k0\":1}");
  snprintf(want, sizeof want,
           "duplicate member \"k0\" at the top level (byte %zu)", at);
  expect_detail(SIG, b.s, want);
  free(b.s);
}

static void distinct_names_differing_late_are_accepted(void **state) {
  (void)state;
  /* names equal up to their last byte, and a prefix of another */
  api_config cfg = default_config();
  api_ctx ctx;
  const char *body = "{\"ab\":1,\"ac\":2,\"a\":3,\"abc\":4}";
  api__ctx_init(&ctx, &cfg);
  cJSON *root = api__parse_body(&ctx, body, strlen(body));
  assert_non_null(root);
  assert_int_equal(ctx.status, 0);
  cJSON_Delete(root);
}

/* ------------------------------------------- packed arrays, same reads */

static void packed_arrays_read_exact_values(void **state) {
  (void)state;
  api_config cfg = default_config();
  api_ctx ctx;
  const char *body =
      "{\"p\":[[1.5,-2],[3e2,0.1],[-0,1e-320]],\"n\":[7,-0.5,2.5e-3]}";
  double *pts = NULL, *nums = NULL;
  size_t np = 0, nn = 0;
  api__ctx_init(&ctx, &cfg);
  cJSON *root = api__parse_body(&ctx, body, strlen(body));
  assert_non_null(root);
  assert_true(api__point_array(&ctx, cJSON_GetObjectItem(root, "p"), "/p", 10,
                               &pts, &np));
  assert_true(api__num_array(&ctx, cJSON_GetObjectItem(root, "n"), "/n", 10,
                             &nums, &nn));
  assert_int_equal(np, 3);
  assert_int_equal(nn, 3);
  /* the decimal values, rounded once (C11 7.22.1.3) */
  const double want_p[] = {1.5, -2, 300, 0.1, -0.0, 1e-320};
  const double want_n[] = {7, -0.5, 2.5e-3};
  for (int i = 0; i < 6; i++)
    assert_memory_equal(&pts[i], &want_p[i], sizeof(double));
  for (int i = 0; i < 3; i++)
    assert_memory_equal(&nums[i], &want_n[i], sizeof(double));
  free(pts);
  free(nums);
  cJSON_Delete(root);
}

#define CP_CURVE(cp)                                                           \
  "{\"curve\":{\"type\":\"bspline\",\"degree\":1,\"knots\":[0,0,1,2,3,3],"     \
  "\"control_points\":" cp "}}"

static void bad_control_points_are_named_as_before(void **state) {
  (void)state;
  /* a string in a point */
  at_problem(SIG, CP_CURVE("[[0,0],[1,0],[2,0],[\"3\",0]]"), 422,
             "/curve/control_points/3/0");
  /* too few coordinates */
  at_problem(SIG, CP_CURVE("[[0,0],[1,0],[2,0],[3]]"), 422,
             "/curve/control_points/3");
  /* a number that overflows to infinity */
  at_problem(SIG, CP_CURVE("[[0,0],[1,0],[2,0],[3,1e999]]"), 422,
             "/curve/control_points/3/1");
  /* every point with three coordinates: the first is wrong */
  at_problem(SIG, CP_CURVE("[[0,0,0],[1,0,0],[2,0,0],[3,0,0]]"), 422,
             "/curve/control_points/0");
  /* numbers where points belong */
  at_problem(SIG, CP_CURVE("[0,0,1,0]"), 422, "/curve/control_points/0");
  /* points where numbers belong */
  at_problem(SIG,
             "{\"curve\":{\"type\":\"bspline\",\"degree\":1,"
             "\"knots\":[[0],[0],[1],[1]],\"control_points\":[[0,0],[1,0]]}}",
             422, "/curve/knots/0");
}

static void packed_elements_where_items_belong_are_named(void **state) {
  (void)state;
  /* corners must be objects, include names strings */
  at_problem(SIG,
             "{\"curve\":{\"type\":\"signature\",\"signature\":{\"length\":1,"
             "\"kappa\":{\"degree\":0,\"knots\":[0,1],\"coefficients\":[1]},"
             "\"corners\":[0.5]}}}",
             422, "/curve/signature/corners/0");
  at_problem(MORPH,
             "{\"from\":{\"type\":\"svg\",\"d\":\"M0 0L1 0\"},"
             "\"to\":{\"type\":\"svg\",\"d\":\"M0 0L2 0\"},"
             "\"include\":[1,2]}",
             422, "/include/0");
  /* a start point of three coordinates */
  at_problem(SIG,
             "{\"curve\":{\"type\":\"signature\",\"signature\":{\"length\":1,"
             "\"start\":{\"point\":[0,0,0]},"
             "\"kappa\":{\"degree\":0,\"knots\":[0,1],\"coefficients\":[1]}}}}",
             422, "/curve/signature/start/point");
}

static void matches_are_read_from_packed_pairs(void **state) {
  (void)state;
  const char *head = "{\"from\":{\"type\":\"svg\",\"d\":\"M0 0L1 0L1 1\"},"
                     "\"to\":{\"type\":\"svg\",\"d\":\"M0 0L2 0L2 2\"},"
                     "\"frames\":2,\"matches\":";
  char body[512];
  snprintf(body, sizeof body, "%s[[0.5,1.5]]}", head);
  at_problem(MORPH, body, 422, "/matches/0/1");
  snprintf(body, sizeof body, "%s[[0.5,0.5],[0.4,0.6]]}", head);
  at_problem(MORPH, body, 422, "/matches/1/0");
  snprintf(body, sizeof body, "%s[0.5,0.5]}", head);
  at_problem(MORPH, body, 422, "/matches/0");
}

/* ------------------------------------------------------ memory budget */

/* A body of just under limit bytes: a fixed head, then members made by
 * member(i) while they fit. Returned malloc'd, *len its length. */
static char *big_body(size_t limit, void (*member)(at_buf *, int),
                      size_t *len) {
  at_buf b = {0};
  at_printf(&b, "{\"curve\":{\"type\":\"svg\",\"d\":\"M0 0L1 0\"}");
  for (int i = 0;; i++) {
    size_t before = b.n;
    at_printf(&b, ",");
    member(&b, i);
    if (b.n + 1 > limit) {
      b.n = before;
      break;
    }
  }
  at_printf(&b, "}");
  *len = b.n;
  return b.s;
}

/* Members of about 60 kB, so that the body ends close to the limit. */

static void rows_member(at_buf *b, int i) {
  at_printf(b, "\"p%d\":[", i);
  for (int k = 0; k < 10000; k++) at_printf(b, "%s[0,0]", k ? "," : "");
  at_printf(b, "]");
}

static void flat_member(at_buf *b, int i) {
  at_printf(b, "\"p%d\":[", i);
  for (int k = 0; k < 10000; k++) at_printf(b, "%s%d", k ? "," : "", k % 10);
  at_printf(b, "]");
}

static void long_string_member(at_buf *b, int i) {
  at_printf(b, "\"s%d\":\"", i);
  for (int k = 0; k < 1000; k++) at_printf(b, "M0 0L1 0L1 1Z ");
  at_printf(b, "\"");
}

static void short_strings_member(at_buf *b, int i) {
  at_printf(b, "\"s%d\":[", i);
  for (int k = 0; k < 10000; k++) at_printf(b, "%s\"a\"", k ? "," : "");
  at_printf(b, "]");
}

static void objects_member(at_buf *b, int i) {
  at_printf(b, "\"o%d\":{", i);
  for (int k = 0; k < 10000; k++) at_printf(b, "%s\"k%d\":0", k ? "," : "", k);
  at_printf(b, "}");
}

/* numbers that cannot be packed: the array ends in null */
static void unpacked_numbers_member(at_buf *b, int i) {
  at_printf(b, "\"m%d\":[", i);
  for (int k = 0; k < 9999; k++) at_printf(b, "0,");
  at_printf(b, "null]");
}

/* Parse an 8 MiB body of member(); the heap's peak over the body's size
 * in *factor; returns the status (0: parsed). */
static int parse_big(void (*member)(at_buf *, int), double *factor,
                     size_t *blocks) {
  api_config cfg = default_config();
  api_ctx ctx;
  size_t len;
  char *body = big_body(cfg.max_body_bytes, member, &len);
  assert_true(len > cfg.max_body_bytes - 200000);
  api__ctx_init(&ctx, &cfg);
  count_heap(true);
  cJSON *root = api__parse_body(&ctx, body, len);
  *factor = (double)heap_peak / (double)len;
  *blocks = heap_blocks;
  cJSON_Delete(root);
  assert_int_equal(heap_now, 0);
  count_heap(false);
  print_message("    %zu bytes: status %d, peak %.2f times the body, %zu "
                "blocks\n",
                len, ctx.status, *factor, *blocks);
  free(body);
  return root != NULL ? 0 : ctx.status;
}

static void number_dense_bodies_take_at_most_4x(void **state) {
  (void)state;
  double f;
  size_t blocks;
  /* [0,0], is 6 bytes for 16 of doubles; 0, is 2 for 8 */
  assert_int_equal(parse_big(rows_member, &f, &blocks), 0);
  assert_true(f <= 16.0 / 6 + 0.1);
  assert_true(blocks < 8000); /* no block per number */
  assert_int_equal(parse_big(flat_member, &f, &blocks), 0);
  assert_true(f <= 4.0 + 0.1);
  assert_true(blocks < 8000);
}

static void string_dense_body_takes_about_its_size(void **state) {
  (void)state;
  double f;
  size_t blocks;
  assert_int_equal(parse_big(long_string_member, &f, &blocks), 0);
  assert_true(f <= 1.1);
}

static void costly_bodies_are_413_before_any_tree(void **state) {
  (void)state;
  void (*const costly[])(at_buf *, int) = {short_strings_member, objects_member,
                                           unpacked_numbers_member};
  for (size_t i = 0; i < sizeof costly / sizeof costly[0]; i++) {
    double f;
    size_t blocks;
    assert_int_equal(parse_big(costly[i], &f, &blocks), 413);
    assert_int_equal(blocks, 0);
  }
}

static void refusal_says_why(void **state) {
  (void)state;
  api_config cfg = default_config();
  size_t len;
  char *body = big_body(cfg.max_body_bytes, objects_member, &len);
  api_response res;
  cJSON *j = NULL;
  assert_int_equal(at_call_cfg(&cfg, SIG, body, len, &res, &j), 413);
  const cJSON *t = cJSON_GetObjectItemCaseSensitive(j, "type");
  assert_string_equal(t->valuestring, "/problems/body-too-large");
  assert_non_null(strstr(detail_of(j), "would take"));
  assert_non_null(strstr(detail_of(j), "times their size"));
  cJSON_Delete(j);
  api_response_free(&res);
  free(body);
}

static const struct CMUnitTest tests[] = {
    cmocka_unit_test(duplicate_top_level_member_is_400_naming_it),
    cmocka_unit_test(duplicate_nested_member_is_400_naming_its_object),
    cmocka_unit_test(duplicate_in_an_array_element_names_the_element),
    cmocka_unit_test(escaped_spelling_of_a_name_is_the_same_member),
    cmocka_unit_test(first_repeat_in_the_text_is_named),
    cmocka_unit_test(repeat_among_many_members_is_found),
    cmocka_unit_test(distinct_names_differing_late_are_accepted),
    cmocka_unit_test(packed_arrays_read_exact_values),
    cmocka_unit_test(bad_control_points_are_named_as_before),
    cmocka_unit_test(packed_elements_where_items_belong_are_named),
    cmocka_unit_test(matches_are_read_from_packed_pairs),
    cmocka_unit_test(number_dense_bodies_take_at_most_4x),
    cmocka_unit_test(string_dense_body_takes_about_its_size),
    cmocka_unit_test(costly_bodies_are_413_before_any_tree),
    cmocka_unit_test(refusal_says_why),
};

TM_SUITE("json_parse", tests, NULL, NULL);
