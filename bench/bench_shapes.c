/* bench_shapes.c - time 60-frame morphs of compound shapes: glyphs with
 * holes and multi-part icons of tests/fixtures/compound, beside flubber.
 *
 * For each pair of bench/shape_pairs.json, per frame (setup amortised over
 * 60 frames, t = i / 59, as bench_morph.c and bench/flubber time theirs),
 * wall and CPU time (on a shared machine the CPU time is the figure that
 * keeps; flubber's runs are short enough for their best wall time to):
 *   cli     end to end: `kmorph morph` started on a request of 60 frames
 *           with "include": ["svg_d"] (the contract's default tolerance,
 *           1e-5 of the longer shape's total length), its answer written
 *           to a file; best of the runs made over at least a second (at
 *           least 3); the process start and the shell that starts it are
 *           in the figure;
 *   core    in-process, the component: km_shape_create of both shapes,
 *           km_shape_morph_create (automatic pairing) and 60
 *           km_shape_morph_frame_until, at the same tolerance; the SVG
 *           parsing, not timed, is done once before; best over a second
 *           of runs (at least 3);
 *   flubber the figure of bench/flubber/bench_flubber_shapes.js for the
 *           pair, when its output file is given.
 *
 * Usage: bench_shapes PAIRS_JSON CLI [FLUBBER_RESULTS] (from the repository
 * root; the requests and answers are written under build/bench/).
 */
#include <cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>

#include "km/kmorph.h"
#include "km/shape.h"
#include "svg.h"

#define FRAMES 60
#define GLYPHS "tests/fixtures/compound/glyphs.json"
#define ICONS "tests/fixtures/compound/icons.json"

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* CPU seconds of this process. */
static double cpu_now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* CPU seconds (user + system) of the waited-for children. */
static double children_cpu(void) {
  struct rusage ru;
  getrusage(RUSAGE_CHILDREN, &ru);
  return (double)(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) +
         1e-6 * (double)(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
}

/* Best wall and CPU microseconds a frame of a series of runs. */
typedef struct figure {
  double wall, cpu;
} figure;

static char *read_text(const char *path) {
  FILE *f = fopen(path, "rb");
  if (f == NULL) return NULL;
  fseek(f, 0, SEEK_END);
  long n = ftell(f);
  fseek(f, 0, SEEK_SET);
  char *s = malloc((size_t)n + 1);
  if (s != NULL && fread(s, 1, (size_t)n, f) != (size_t)n) {
    free(s);
    s = NULL;
  }
  if (s != NULL) s[n] = '\0';
  fclose(f);
  return s;
}

/* The path data of fixture id ("mdi/..." from icons.json, others from
 * glyphs.json), malloc'd, or NULL. */
static char *fixture_d(const char *id) {
  bool icon = strncmp(id, "mdi/", 4) == 0;
  char *text = read_text(icon ? ICONS : GLYPHS), *d = NULL;
  cJSON *root = text != NULL ? cJSON_Parse(text) : NULL, *g;
  cJSON_ArrayForEach(
      g, cJSON_GetObjectItemCaseSensitive(root, icon ? "icons" : "glyphs")) {
    const cJSON *gid = cJSON_GetObjectItemCaseSensitive(g, "id");
    const cJSON *gd = cJSON_GetObjectItemCaseSensitive(g, "d");
    if (cJSON_IsString(gid) && cJSON_IsString(gd) &&
        strcmp(gid->valuestring, id) == 0) {
      d = malloc(strlen(gd->valuestring) + 1);
      if (d != NULL) strcpy(d, gd->valuestring);
    }
  }
  cJSON_Delete(root);
  free(text);
  return d;
}

typedef struct side {
  km_curve *contours;
  size_t n;
  double length; /* of all contours */
} side;

static int parse_side(const char *d, side *s) {
  size_t *off = NULL, err_off = 0;
  char msg[200];
  km_status st = api_svg_parse_subpaths(d, strlen(d), 1e-9, 4096, &s->contours,
                                        &off, &s->n, &err_off, msg, sizeof msg);
  free(off);
  if (st != KM_OK) {
    fprintf(stderr, "parse at %zu: %s\n", err_off, msg);
    return -1;
  }
  s->length = 0;
  for (size_t i = 0; i < s->n; i++)
    s->length += km_curve_length(&s->contours[i]);
  return 0;
}

static void free_side(side *s) {
  for (size_t i = 0; i < s->n; i++) km_curve_free(&s->contours[i]);
  free(s->contours);
}

/* One compound morph of 60 frames from scratch; the middle frame's
 * control points into *points. 0 on success. */
static int morph_once(const side *a, const side *b, double tol,
                      size_t *points) {
  km_shape sa, sb;
  km_shape_morph *m = NULL;
  km_shape_morph_options o;
  km_error err;
  int rc = -1;
  km_shape_init(&sa);
  km_shape_init(&sb);
  if (km_shape_create(&sa, a->contours, a->n, KM_FILL_NONZERO, NULL, &err) !=
          KM_OK ||
      km_shape_create(&sb, b->contours, b->n, KM_FILL_NONZERO, NULL, &err) !=
          KM_OK)
    goto done;
  km_shape_morph_options_default(&o);
  o.morph.tolerance = tol;
  if (km_shape_morph_create(&m, &sa, &sb, &o, NULL, &err) != KM_OK) goto done;
  for (int i = 0; i < FRAMES; i++) {
    km_shape_frame f;
    km_shape_frame_init(&f);
    if (km_shape_morph_frame_until(m, (double)i / (FRAMES - 1), NULL, &f,
                                   &err) != KM_OK)
      goto done;
    if (i == FRAMES / 2) {
      *points = 0;
      for (size_t k = 0; k < f.ncontours; k++)
        *points += f.present[k] ? f.contours[k].n : 0;
    }
    km_shape_frame_free(&f);
  }
  rc = 0;
done:
  if (rc != 0) fprintf(stderr, "morph: %s\n", err.message);
  km_shape_morph_free(m);
  km_shape_free(&sa);
  km_shape_free(&sb);
  return rc;
}

/* Best microseconds a frame of the in-process morphs made over a second
 * (at least 3). */
static figure best_core(const side *a, const side *b, double tol,
                        size_t *points) {
  figure best = {INFINITY, INFINITY};
  double start = now();
  for (int r = 0; r < 3 || now() - start < 1.0; r++) {
    double t0 = now(), c0 = cpu_now();
    if (morph_once(a, b, tol, points) != 0) return (figure){NAN, NAN};
    best.wall = fmin(best.wall, now() - t0);
    best.cpu = fmin(best.cpu, cpu_now() - c0);
  }
  return (figure){1e6 * best.wall / FRAMES, 1e6 * best.cpu / FRAMES};
}

/* The CLI end to end on the request for (from, to); *bytes the answer's
 * size. */
static figure best_cli(const char *cli, const char *from_d, const char *to_d,
                       int index, long *bytes) {
  char req[64], out[64], cmd[256];
  snprintf(req, sizeof req, "build/bench/shape-%d.json", index);
  snprintf(out, sizeof out, "build/bench/shape-%d.out.json", index);
  FILE *f = fopen(req, "w");
  if (f == NULL) return (figure){NAN, NAN};
  fprintf(f,
          "{\"from\":{\"type\":\"svg\",\"d\":\"%s\"},\"to\":{\"type\":\"svg\","
          "\"d\":\"%s\"},\"frames\":%d,\"include\":[\"svg_d\"]}\n",
          from_d, to_d, FRAMES);
  fclose(f);
  snprintf(cmd, sizeof cmd, "%s morph < %s > %s", cli, req, out);
  figure best = {INFINITY, INFINITY};
  double start = now();
  for (int r = 0; r < 3 || now() - start < 1.0; r++) {
    double t0 = now(), c0 = children_cpu();
    if (system(cmd) != 0) {
      fprintf(stderr, "%s failed\n", cmd);
      return (figure){NAN, NAN};
    }
    best.wall = fmin(best.wall, now() - t0);
    best.cpu = fmin(best.cpu, children_cpu() - c0);
  }
  if ((f = fopen(out, "rb")) != NULL) {
    fseek(f, 0, SEEK_END);
    *bytes = ftell(f);
    fclose(f);
  }
  return (figure){1e6 * best.wall / FRAMES, 1e6 * best.cpu / FRAMES};
}

/* flubber's per-frame figure and point count for the pair, from lines
 * "flubber FROM TO US_PER_FRAME POINTS". */
static bool flubber_figure(const char *path, const char *from, const char *to,
                           double *us, long *points) {
  FILE *f = path != NULL ? fopen(path, "r") : NULL;
  char line[512], a[200], b[200];
  bool found = false;
  while (f != NULL && !found && fgets(line, sizeof line, f) != NULL)
    found =
        sscanf(line, "flubber %199s %199s %lf %ld", a, b, us, points) == 4 &&
        strcmp(a, from) == 0 && strcmp(b, to) == 0;
  if (f != NULL) fclose(f);
  return found;
}

/* The comment lines of flubber's output (its version, how each pair was
 * morphed). */
static void print_comments(const char *path) {
  FILE *f = path != NULL ? fopen(path, "r") : NULL;
  char line[512];
  while (f != NULL && fgets(line, sizeof line, f) != NULL)
    if (line[0] == '#') fputs(line, stdout);
  if (f != NULL) fclose(f);
}

static int bench_pair(const char *cli, const char *flubber, const char *from,
                      const char *to, int index) {
  char *fd = fixture_d(from), *td = fixture_d(to);
  side a = {0}, b = {0};
  size_t points = 0;
  long bytes = 0, fpoints = 0;
  double fus = NAN;
  int rc = -1;
  if (fd == NULL || td == NULL) {
    fprintf(stderr, "no fixture %s or %s\n", from, to);
    goto done;
  }
  if (parse_side(fd, &a) != 0 || parse_side(td, &b) != 0) goto done;
  double tol = 1e-5 * fmax(a.length, b.length);
  figure core = best_core(&a, &b, tol, &points);
  figure end = best_cli(cli, fd, td, index, &bytes);
  bool have = flubber_figure(flubber, from, to, &fus, &fpoints);
  printf("%-22s -> %-22s %zu -> %zu contours\n", from, to, a.n, b.n);
  printf("  kmorph cli (end to end)  %9.1f us/frame wall %9.1f cpu  answer "
         "%ld bytes\n",
         end.wall, end.cpu, bytes);
  printf("  kmorph core (in-process) %9.1f us/frame wall %9.1f cpu  %zu "
         "control points at t = 0.5\n",
         core.wall, core.cpu, points);
  if (have)
    printf("  flubber                  %9.1f us/frame wall            %ld "
           "points at t = 0.5 (cli cpu / flubber %.0fx, core cpu / flubber "
           "%.0fx)\n",
           fus, fpoints, end.cpu / fus, core.cpu / fus);
  rc = isfinite(core.wall) && isfinite(end.wall) ? 0 : -1;
done:
  free_side(&a);
  free_side(&b);
  free(fd);
  free(td);
  return rc;
}

int main(int argc, char **argv) {
  if (argc < 3) {
    fprintf(stderr, "usage: bench_shapes PAIRS_JSON CLI [FLUBBER_RESULTS]\n");
    return 2;
  }
  char *text = read_text(argv[1]);
  cJSON *root = text != NULL ? cJSON_Parse(text) : NULL, *p;
  int rc = root != NULL ? 0 : 1, index = 0;
  printf("compound shapes, %d frames (t = i/%d), setup amortised: per "
         "frame\n",
         FRAMES, FRAMES - 1);
  print_comments(argc > 3 ? argv[3] : NULL);
  cJSON_ArrayForEach(p, cJSON_GetObjectItemCaseSensitive(root, "pairs")) {
    const cJSON *from = cJSON_GetArrayItem(p, 0),
                *to = cJSON_GetArrayItem(p, 1);
    if (!cJSON_IsString(from) || !cJSON_IsString(to) ||
        bench_pair(argv[2], argc > 3 ? argv[3] : NULL, from->valuestring,
                   to->valuestring, index++) != 0)
      rc = 1;
  }
  cJSON_Delete(root);
  free(text);
  return rc;
}
