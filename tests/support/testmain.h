/* testmain.h - the one main of every C test binary: a test file defines
 * its table with TM_SUITE and links tests/support/testmain.c, which runs
 * the table with cmocka, whole or filtered by name.
 *
 * Usage of a test binary (from the repository root, where fixtures are
 * found):
 *   build/tests/core/test_morph              every test, cmocka's output
 *   build/tests/core/test_morph -t NAME      only the tests NAME selects
 *   KM_TEST=NAME build/tests/core/test_morph the same through the
 *                                            environment (`KM_TEST=NAME
 *                                            make test-unit` filters every
 *                                            binary)
 *   build/tests/core/test_morph -l           the names, one a line
 * NAME selects the test of exactly that name if the table has one, else
 * every test whose name contains it; `*` and `?` make it a cmocka glob
 * over whole names instead. Without a filter the output is cmocka's own,
 * so tests/run-tests.sh reads the same summary lines.
 */
#ifndef KM_TESTMAIN_H
#define KM_TESTMAIN_H

/* cmocka needs these before its own header. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

/* One binary's tests: a group name for cmocka's reports, the table and
 * the group's fixtures (either may be NULL). */
typedef struct tm_suite {
  const char *group;
  const struct CMUnitTest *tests;
  size_t count;
  CMFixtureFunction setup;
  CMFixtureFunction teardown;
} tm_suite;

/* Defined once per test binary, by TM_SUITE. */
extern const tm_suite tm_this_suite;

/* TM_SUITE(group, table, setup, teardown): hand the file-scope array
 * `table` of cmocka_unit_test entries to the shared main. */
#define TM_SUITE(group_, table_, setup_, teardown_)                            \
  const tm_suite tm_this_suite = {(group_), (table_),                          \
                                  sizeof(table_) / sizeof((table_)[0]),        \
                                  (setup_), (teardown_)}

#endif
