/* test_api_cli.c - the kmorph binary: a request file on stdin, the body on
 * stdout, exit status 0 / 1 / 2 for success / problem / usage. The binary
 * is the one the Makefile names in KMORPH_CLI (build/kmorph by default).
 */
#include <sys/wait.h>
#include <unistd.h>

#include "api_testutil.h"
#include "testmain.h"

typedef struct cli_env {
  const char *cli;
  char dir[64];
} cli_env;

static int setup(void **state) {
  static cli_env env;
  env.cli = getenv("KMORPH_CLI");
  if (env.cli == NULL || env.cli[0] == '\0') env.cli = "build/kmorph";
  snprintf(env.dir, sizeof env.dir, "/tmp/kmorph-cli-XXXXXX");
  if (mkdtemp(env.dir) == NULL) return -1;
  *state = &env;
  return 0;
}

static int teardown(void **state) {
  cli_env *env = *state;
  char cmd[128];
  snprintf(cmd, sizeof cmd, "rm -rf '%s'", env->dir);
  return system(cmd) == 0 ? 0 : -1;
}

/* Run `cli args < file(body)`; stdout into *out (malloc'd); exit status. */
static int run(const cli_env *env, const char *args, const char *body,
               char **out) {
  char path[128], cmd[512];
  FILE *f;
  snprintf(path, sizeof path, "%s/request.json", env->dir);
  f = fopen(path, "wb");
  assert_non_null(f);
  fwrite(body, 1, strlen(body), f);
  fclose(f);
  snprintf(cmd, sizeof cmd, "'%s' %s < '%s' 2>'%s/stderr'", env->cli, args,
           path, env->dir);
  f = popen(cmd, "r");
  assert_non_null(f);
  at_buf b = {0};
  at_printf(&b, "%s", "");
  char chunk[4096];
  size_t n;
  while ((n = fread(chunk, 1, sizeof chunk, f)) > 0)
    at_printf(&b, "%.*s", (int)n, chunk);
  int st = pclose(f);
  assert_true(WIFEXITED(st));
  *out = b.s;
  return WEXITSTATUS(st);
}

static void cli_signature_of_a_circle_succeeds(void **state) {
  cli_env *env = *state;
  at_buf b = {0};
  char *out;
  at_printf(&b, "{\"curve\":");
  at_circle_json(&b, 0, 0, 4, 1);
  at_printf(&b, ",\"samples\":5}");
  assert_int_equal(run(env, "signature", b.s, &out), 0);
  cJSON *j = cJSON_Parse(out);
  assert_non_null(j);
  const cJSON *sig = cJSON_GetObjectItem(j, "signature");
  assert_rel(cJSON_GetObjectItem(sig, "length")->valuedouble, 8 * M_PI, 1e-10);
  const cJSON *e;
  cJSON_ArrayForEach(e, cJSON_GetObjectItem(j, "samples")) {
    assert_close(cJSON_GetArrayItem(e, 1)->valuedouble, 0.25, 1e-9);
  }
  cJSON_Delete(j);
  free(out);

  /* --pretty gives the same document, indented. */
  assert_int_equal(run(env, "signature --pretty", b.s, &out), 0);
  assert_non_null(strstr(out, "\n  \"signature\": {"));
  j = cJSON_Parse(out);
  assert_non_null(j);
  assert_rel(cJSON_GetObjectItem(cJSON_GetObjectItem(j, "signature"), "length")
                 ->valuedouble,
             8 * M_PI, 1e-10);
  cJSON_Delete(j);
  free(out);
  free(b.s);
}

static void cli_problem_exits_1_with_problem_json(void **state) {
  cli_env *env = *state;
  char *out;
  assert_int_equal(run(env, "signature", "{\"curve\":", &out), 1);
  cJSON *j = cJSON_Parse(out);
  assert_non_null(j);
  assert_int_equal(cJSON_GetObjectItem(j, "status")->valueint, 400);
  cJSON_Delete(j);
  free(out);

  assert_int_equal(run(env, "reconstruct", "{\"signature\":{}}", &out), 1);
  j = cJSON_Parse(out);
  assert_non_null(j);
  assert_int_equal(cJSON_GetObjectItem(j, "status")->valueint, 422);
  assert_string_equal(
      cJSON_GetObjectItem(
          cJSON_GetArrayItem(cJSON_GetObjectItem(j, "errors"), 0), "pointer")
          ->valuestring,
      "/signature/length");
  cJSON_Delete(j);
  free(out);
}

static void cli_usage_errors_exit_2(void **state) {
  cli_env *env = *state;
  char *out;
  assert_int_equal(run(env, "", "{}", &out), 2);
  assert_string_equal(out, "");
  free(out);
  assert_int_equal(run(env, "transmogrify", "{}", &out), 2);
  free(out);
  assert_int_equal(run(env, "signature --frobnicate", "{}", &out), 2);
  free(out);
  assert_int_equal(run(env, "--help", "", &out), 0);
  assert_non_null(strstr(out, "usage: kmorph"));
  free(out);
}

static void cli_morph_validation_goes_through_the_api(void **state) {
  cli_env *env = *state;
  char *out;
  assert_int_equal(run(env, "morph", "{\"frames\":0}", &out), 1);
  cJSON *j = cJSON_Parse(out);
  assert_non_null(j);
  assert_int_equal(cJSON_GetObjectItem(j, "status")->valueint, 422);
  cJSON_Delete(j);
  free(out);
}

/* Frames rendered on several threads give the answer of one thread, byte
 * for byte, and the lengths measured while rendering are the curves'
 * own: frame 0 is the circle of radius 2 (4 pi), the last the square of
 * side 4 (16). */
static void cli_morph_threads_give_the_same_answer(void **state) {
  cli_env *env = *state;
  at_buf b = {0};
  char *one, *many;
  at_printf(&b, "{\"from\":");
  at_circle_json(&b, 0, 0, 2, 1);
  at_printf(&b, ",\"to\":{\"type\":\"svg\",\"d\":\"M-2 -2 L2 -2 L2 2 L-2 "
                "2 Z\"},\"frames\":41,\"metrics\":true}");
  assert_int_equal(run(env, "morph --threads 1", b.s, &one), 0);
  assert_int_equal(run(env, "morph --threads 4", b.s, &many), 0);
  assert_string_equal(one, many);
  cJSON *j = cJSON_Parse(many);
  assert_non_null(j);
  const cJSON *frames = cJSON_GetObjectItem(j, "frames");
  assert_int_equal(cJSON_GetArraySize(frames), 41);
  const cJSON *c0 = cJSON_GetObjectItem(cJSON_GetArrayItem(frames, 0), "curve");
  const cJSON *c1 =
      cJSON_GetObjectItem(cJSON_GetArrayItem(frames, 40), "curve");
  assert_rel(cJSON_GetObjectItem(c0, "length")->valuedouble, 4 * M_PI, 1e-5);
  assert_rel(cJSON_GetObjectItem(c1, "length")->valuedouble, 16.0, 1e-9);
  cJSON_Delete(j);
  free(one);
  free(many);
  /* frames printed on the threads: on the tolerance grid, with svg_d */
  at_buf g = {0};
  at_printf(&g, "{\"from\":");
  at_circle_json(&g, 0, 0, 2, 1);
  at_printf(&g, ",\"to\":{\"type\":\"svg\",\"d\":\"M-2 -2 L2 -2 L2 2 L-2 "
                "2 Z\"},\"frames\":17,\"precision\":\"tolerance\","
                "\"include\":[\"svg_d\"]}");
  assert_int_equal(run(env, "morph --threads 1", g.s, &one), 0);
  assert_int_equal(run(env, "morph --threads 3", g.s, &many), 0);
  assert_string_equal(one, many);
  assert_non_null(strstr(many, "\"svg_d\":\"M"));
  free(one);
  free(many);
  free(g.s);
  assert_int_equal(run(env, "morph --threads 0", b.s, &one), 2);
  free(one);
  assert_int_equal(run(env, "morph --threads", b.s, &one), 2);
  free(one);
  free(b.s);
}

static const struct CMUnitTest tests[] = {
    cmocka_unit_test(cli_signature_of_a_circle_succeeds),
    cmocka_unit_test(cli_problem_exits_1_with_problem_json),
    cmocka_unit_test(cli_usage_errors_exit_2),
    cmocka_unit_test(cli_morph_validation_goes_through_the_api),
    cmocka_unit_test(cli_morph_threads_give_the_same_answer),
};

TM_SUITE("api_cli", tests, setup, teardown);
