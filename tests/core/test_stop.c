/* test_stop.c - every long core entry point ends with KM_ECANCELLED at
 * the first "stop" of its caller's km_stop, asks nothing after it, frees
 * what it built (the ASan build checks), and polls at bounded intervals:
 * between two questions at most a few KM_STOP_POLL_UNITS of work, which a
 * stop set by another thread measures in time.
 */
#include <math.h>
#include <pthread.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <cmocka.h>

#include "km/kmorph.h"
#include "km/stop.h"
#include "testutil.h"
#include "testmain.h"

/* A closed cubic B-spline of n control points on a wavy circle. */
static void wavy(km_curve *c, size_t n, int waves, double amp) {
  double *knots = malloc((n + 4) * sizeof *knots);
  double *cp = malloc(2 * n * sizeof *cp);
  for (size_t i = 0; i < n + 4; i++)
    knots[i] = i < 4 ? 0.0 : i >= n ? (double)(n - 3) : (double)(i - 3);
  for (size_t i = 0; i < n; i++) {
    double a =
        2 * 3.14159265358979323846 * (double)(i % (n - 1)) / (double)(n - 1);
    double r = 1 + amp * sin(waves * a);
    cp[2 * i] = r * cos(a);
    cp[2 * i + 1] = r * sin(a);
  }
  km_curve_init(c);
  assert_int_equal(km_curve_create(c, 3, n, knots, cp, NULL, true, NULL),
                   KM_OK);
  free(knots);
  free(cp);
}

typedef struct fixture {
  km_curve a, b;
  km_signature sa;
} fixture;

static int setup(void **state) {
  fixture *f = calloc(1, sizeof *f);
  wavy(&f->a, 300, 7, 0.2);
  wavy(&f->b, 300, 5, 0.3);
  km_signature_init(&f->sa);
  assert_int_equal(km_signature_compute(&f->a, 1e-9, &f->sa, NULL), KM_OK);
  *state = f;
  return 0;
}

static int teardown(void **state) {
  fixture *f = *state;
  km_curve_free(&f->a);
  km_curve_free(&f->b);
  km_signature_free(&f->sa);
  free(f);
  return 0;
}

/* One entry point run under a stop; returns its status. */
typedef km_status (*entry)(fixture *f, const km_stop *stop);

static km_status run_signature(fixture *f, const km_stop *stop) {
  km_signature s;
  km_signature_init(&s);
  km_status st = km_signature_compute_until(&f->a, 1e-9, stop, &s, NULL);
  km_signature_free(&s);
  return st;
}

static km_status run_reconstruct(fixture *f, const km_stop *stop) {
  km_curve c;
  km_curve_init(&c);
  km_status st =
      km_reconstruct_until(&f->sa, 3, 1e-10, 0, stop, &c, NULL, NULL);
  km_curve_free(&c);
  return st;
}

static km_status run_morph(fixture *f, const km_stop *stop, bool autom,
                           km_morph_method method) {
  km_morph_options o;
  km_morph_options_default(&o);
  o.tolerance = 1e-8;
  o.auto_matches = autom;
  o.method = method;
  o.stop = stop;
  km_morph_input fi = {&f->a, NULL}, ti = {&f->b, NULL};
  km_morph *m = NULL;
  km_status st = km_morph_create(&m, &fi, &ti, &o, NULL);
  km_morph_free(m);
  return st;
}
static km_status run_create(fixture *f, const km_stop *s) {
  return run_morph(f, s, false, KM_METHOD_CURVATURE);
}
static km_status run_create_auto(fixture *f, const km_stop *s) {
  return run_morph(f, s, true, KM_METHOD_CURVATURE);
}
static km_status run_create_linear(fixture *f, const km_stop *s) {
  return run_morph(f, s, false, KM_METHOD_LINEAR);
}

static km_status run_frame(fixture *f, const km_stop *stop, bool metrics,
                           km_morph_method method) {
  km_morph_options o;
  km_morph_options_default(&o);
  o.tolerance = 1e-8;
  o.method = method;
  km_morph_input fi = {&f->a, NULL}, ti = {&f->b, NULL};
  km_morph *m = NULL;
  assert_int_equal(km_morph_create(&m, &fi, &ti, &o, NULL), KM_OK);
  km_curve c;
  km_frame_metrics mt;
  km_curve_init(&c);
  km_status st =
      km_morph_frame_until(m, 0.4, stop, &c, metrics ? &mt : NULL, NULL, NULL);
  km_curve_free(&c);
  km_morph_free(m);
  return st;
}
static km_status run_frame_planned(fixture *f, const km_stop *s) {
  return run_frame(f, s, false, KM_METHOD_CURVATURE);
}
static km_status run_frame_metrics(fixture *f, const km_stop *s) {
  return run_frame(f, s, true, KM_METHOD_CURVATURE);
}
static km_status run_frame_linear(fixture *f, const km_stop *s) {
  return run_frame(f, s, true, KM_METHOD_LINEAR);
}

static km_status run_crossings(fixture *f, const km_stop *stop) {
  long n = 0;
  return km_curve_self_intersections_until(&f->a, 1e-9, stop, &n);
}

static const struct {
  const char *name;
  entry run;
} entries[] = {
    {"signature", run_signature},
    {"reconstruct", run_reconstruct},
    {"morph_create", run_create},
    {"morph_create_auto", run_create_auto},
    {"morph_create_linear", run_create_linear},
    {"frame_planned", run_frame_planned},
    {"frame_metrics", run_frame_metrics},
    {"frame_linear", run_frame_linear},
    {"self_intersections", run_crossings},
};
#define NENTRIES (sizeof entries / sizeof entries[0])

/* Given a stop that answers "stop" at its k-th question (k = 1, the
 * middle one and the last one a full run asks), each entry point returns
 * KM_ECANCELLED and asks exactly k questions; a NULL stop and a stop that
 * never fires both give KM_OK. */
static void each_entry_point_stops_at_the_first_stop(void **state) {
  fixture *f = *state;
  for (size_t e = 0; e < NENTRIES; e++) {
    assert_int_equal(entries[e].run(f, NULL), KM_OK);
    countdown never = {1L << 40, 0};
    km_stop sn = {countdown_stop, &never};
    assert_int_equal(entries[e].run(f, &sn), KM_OK);
    print_message("%-20s asks %ld times\n", entries[e].name, never.asked);
    if (never.asked == 0) continue; /* too short to ask: nothing to stop */
    long ks[3] = {0, never.asked / 2, never.asked - 1};
    for (int k = 0; k < 3; k++) {
      countdown cd = {ks[k], 0};
      km_stop s = {countdown_stop, &cd};
      km_status st = entries[e].run(f, &s);
      if (st != KM_ECANCELLED)
        print_error("%s: status %d at stop %ld\n", entries[e].name, st, ks[k]);
      assert_int_equal(st, KM_ECANCELLED);
      assert_int_equal(cd.asked, ks[k] + 1);
    }
  }
}

/* Each of the long entry points above asks at least once for this input
 * (some of them hundreds of times): the prepare of a morph of two
 * 300-point curves at 1e-8 is work enough. */
static void long_entry_points_ask(void **state) {
  fixture *f = *state;
  const char *must[] = {"signature", "reconstruct", "morph_create",
                        "frame_metrics"};
  for (size_t e = 0; e < NENTRIES; e++)
    for (size_t k = 0; k < 4; k++)
      if (strcmp(entries[e].name, must[k]) == 0) {
        countdown never = {1L << 40, 0};
        km_stop s = {countdown_stop, &never};
        assert_int_equal(entries[e].run(f, &s), KM_OK);
        assert_true(never.asked >= 2);
      }
}

/* ---- a stop set by another thread ---- */

typedef struct flag {
  atomic_bool stop;
  atomic_bool asked;          /* the entry under test has polled once */
  atomic_bool done;           /* the entry returned */
  struct timespec set_at;     /* wall clock when it was set */
  struct timespec cpu_set_at; /* the working thread's CPU clock then */
} flag;

static bool flag_stop(void *ctx) {
  flag *fl = ctx;
  atomic_store_explicit(&fl->asked, true, memory_order_relaxed);
  return atomic_load_explicit(&fl->stop, memory_order_relaxed);
}

typedef struct setter {
  flag *fl;
  long delay_us;
  clockid_t worker_cpu; /* the CPU clock of the thread that works */
} setter;

/* The delay counts from the entry's first poll, not from the thread's
 * start: the frame entries first build their morph without a stop, and
 * CPU spent there after the flag is no measure of how often the frame
 * asks (under the sanitizers that build alone takes tens of ms). */
static void *set_later(void *arg) {
  setter *s = arg;
  const struct timespec tick = {0, 50 * 1000};
  while (!atomic_load(&s->fl->asked))
    if (atomic_load(&s->fl->done))
      return NULL;
    else
      nanosleep(&tick, NULL);
  struct timespec d = {0, s->delay_us * 1000};
  nanosleep(&d, NULL);
  clock_gettime(s->worker_cpu, &s->fl->cpu_set_at);
  clock_gettime(CLOCK_MONOTONIC, &s->fl->set_at);
  atomic_store(&s->fl->stop, true);
  return NULL;
}

static double since_ms(clockid_t clock, const struct timespec *t0) {
  struct timespec t;
  clock_gettime(clock, &t);
  return (t.tv_sec - t0->tv_sec) * 1e3 + (t.tv_nsec - t0->tv_nsec) / 1e6;
}

/* A morph prepared while another thread sets the flag 2 ms after its
 * first poll returns
 * KM_ECANCELLED having worked at most 50 ms of CPU time after the flag
 * (the goal is ~10 ms at -O3; sanitizer builds get slack). The working
 * thread's own CPU clock is what is bounded: on a loaded machine the wall
 * clock also counts the time it waited for a core, which says nothing of
 * how often the core asks to stop. */
static void a_flag_set_by_another_thread_stops_promptly(void **state) {
  fixture *f = *state;
  for (size_t e = 0; e < NENTRIES; e++) {
    flag fl;
    atomic_init(&fl.stop, false);
    atomic_init(&fl.asked, false);
    atomic_init(&fl.done, false);
    setter s = {&fl, 2000, CLOCK_THREAD_CPUTIME_ID};
    assert_int_equal(pthread_getcpuclockid(pthread_self(), &s.worker_cpu), 0);
    pthread_t th;
    km_stop ks = {flag_stop, &fl};
    assert_int_equal(pthread_create(&th, NULL, set_later, &s), 0);
    km_status st = entries[e].run(f, &ks);
    atomic_store(&fl.done, true);
    bool was_set = atomic_load(&fl.stop);
    double late =
        was_set ? since_ms(CLOCK_THREAD_CPUTIME_ID, &fl.cpu_set_at) : 0.0;
    double wall = was_set ? since_ms(CLOCK_MONOTONIC, &fl.set_at) : 0.0;
    pthread_join(th, NULL);
    if (st == KM_ECANCELLED) {
      print_message("%-20s returned after %.3f ms of CPU (%.3f ms wall) "
                    "after the flag\n",
                    entries[e].name, late, wall);
      assert_true(late < 50.0);
    } else {
      assert_int_equal(st, KM_OK); /* finished before the flag */
    }
  }
}

static const struct CMUnitTest tests[] = {
    cmocka_unit_test(each_entry_point_stops_at_the_first_stop),
    cmocka_unit_test(long_entry_points_ask),
    cmocka_unit_test(a_flag_set_by_another_thread_stops_promptly),
};

TM_SUITE("stop", tests, setup, teardown);
