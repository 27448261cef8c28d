/* testmain.c - the shared main of the C test binaries (see testmain.h):
 * reads the filter from -t or KM_TEST and runs the binary's table.
 *
 * A name without wildcards is turned into a cmocka glob here, because
 * cmocka 1.1's filter matches whole names only: an exact name stays
 * itself (so one test runs alone even when its name is part of
 * another's), anything else becomes *NAME*.
 */
#include "testmain.h"

#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* Large enough for any test name with the two wildcards and the NUL. */
#define TM_PATTERN_MAX 512

static void usage(FILE *to, const char *prog) {
  fprintf(to,
          "usage: %s [-t NAME] [-l]\n"
          "  -t NAME  run the test called NAME, or else those whose name\n"
          "           contains NAME (* and ? make it a glob over whole\n"
          "           names); KM_TEST=NAME does the same\n"
          "  -l       list the tests' names\n",
          prog);
}

static bool has_test_named(const tm_suite *s, const char *name) {
  for (size_t i = 0; i < s->count; i++)
    if (strcmp(s->tests[i].name, name) == 0) return true;
  return false;
}

/* The cmocka pattern for the user's NAME, in out; false if it is too
 * long to hold. */
static bool pattern_for(const tm_suite *s, const char *name, char *out,
                        size_t size) {
  int n;
  if (strpbrk(name, "*?") != NULL || has_test_named(s, name))
    n = snprintf(out, size, "%s", name);
  else
    n = snprintf(out, size, "*%s*", name);
  return n >= 0 && (size_t)n < size;
}

int main(int argc, char **argv) {
  const tm_suite *s = &tm_this_suite;
  const char *name = getenv("KM_TEST");
  char pattern[TM_PATTERN_MAX];
  int opt;

  while ((opt = getopt(argc, argv, "t:lh")) != -1) {
    switch (opt) {
    case 't': name = optarg; break;
    case 'l':
      for (size_t i = 0; i < s->count; i++) printf("%s\n", s->tests[i].name);
      return 0;
    case 'h': usage(stdout, argv[0]); return 0;
    default: usage(stderr, argv[0]); return 2;
    }
  }
  if (optind < argc) {
    usage(stderr, argv[0]);
    return 2;
  }
  if (name != NULL && name[0] != '\0') {
    if (!pattern_for(s, name, pattern, sizeof pattern)) {
      fprintf(stderr, "%s: test name too long\n", argv[0]);
      return 2;
    }
    cmocka_set_test_filter(pattern);
  }
  return _cmocka_run_group_tests(s->group, s->tests, s->count, s->setup,
                                 s->teardown);
}
