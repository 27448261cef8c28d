/* kmorph.c - the command-line face of the v1 contract: one request read
 * from standard input, the response body written to standard output.
 *
 * Usage: kmorph signature|reconstruct|morph [--pretty] [--svg] < request.json
 * Exit status: 0 for a 2xx answer, 1 for a problem (the problem+json is on
 * stdout), 2 for a usage error (usage on stderr). The request goes through
 * api_handle exactly as the daemon's would, so the CLI is also a way to
 * reproduce any server answer without a network.
 *
 * A morph's frames are rendered on as many threads as the process may use
 * CPUs (--threads N to choose): the plan allows distinct frames at once,
 * and the answer, assembled by api_morph_result in frame order, is the
 * same bytes whatever the count.
 *
 * The process lives some milliseconds and every page it touches is new:
 * where a page fault is dear (some 10 us a 4 KB page on a virtual
 * machine, a third of a 1,000-frame morph's time) its heap is one large
 * region advised to use huge pages (prefer_huge_pages).
 */
#define _GNU_SOURCE /* sched_getaffinity */
#include <malloc.h>
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#include "kmapi/api.h"

/* The build passes the tree's VERSION; a stray compile without it still
 * says something true. */
#ifndef KMORPH_VERSION
#define KMORPH_VERSION "unknown"
#endif

static void usage(FILE *to) {
  fputs("usage: kmorph signature|reconstruct|morph [--pretty] [--svg] "
        "[--threads N] "
        "< request.json\n"
        "\n"
        "Reads one request body (JSON, as for POST /v1/<command>) from\n"
        "standard input and writes the response body to standard output.\n"
        "\n"
        "  --pretty   indent JSON output\n"
        "  --svg      ask for SVG (as the header Accept: image/svg+xml)\n"
        "  --threads N  render a morph's frames on N threads (default: the\n"
        "             CPUs this process may run on; 1: one thread)\n"
        "  --help     this text\n"
        "  --version  the version, then exit\n"
        "\n"
        "Exit status: 0 on success, 1 when the answer is a problem\n"
        "(application/problem+json on stdout), 2 on a usage error.\n",
        to);
}

/* Read all of stdin, at most max bytes; *too_big when there was more. */
static char *read_all(FILE *in, size_t max, size_t *len, bool *too_big) {
  size_t cap = 65536, n = 0;
  char *buf = malloc(cap);
  *too_big = false;
  if (buf == NULL) return NULL;
  for (;;) {
    size_t got;
    if (n == cap) {
      char *nb;
      if (cap > max) {
        *too_big = true;
        break;
      }
      cap *= 2;
      nb = realloc(buf, cap);
      if (nb == NULL) {
        free(buf);
        return NULL;
      }
      buf = nb;
    }
    got = fread(buf + n, 1, cap - n, in);
    n += got;
    if (got == 0) break;
    if (n > max) {
      *too_big = true;
      break;
    }
  }
  *len = n;
  return buf;
}

static void indent(FILE *out, int depth) {
  fputc('\n', out);
  for (int i = 0; i < depth; i++) fputs("  ", out);
}

/* Re-indent compact JSON (the api layer prints it without whitespace).
 * Only structure outside strings is touched. */
static void print_pretty(FILE *out, const char *s, size_t n) {
  int depth = 0;
  bool in_str = false;
  for (size_t i = 0; i < n; i++) {
    char c = s[i];
    if (in_str) {
      fputc(c, out);
      if (c == '\\' && i + 1 < n)
        fputc(s[++i], out);
      else if (c == '"')
        in_str = false;
      continue;
    }
    switch (c) {
    case '"':
      in_str = true;
      fputc(c, out);
      break;
    case '{':
    case '[':
      fputc(c, out);
      if (i + 1 < n && (s[i + 1] == '}' || s[i + 1] == ']')) {
        fputc(s[++i], out);
        break;
      }
      indent(out, ++depth);
      break;
    case '}':
    case ']':
      indent(out, --depth);
      fputc(c, out);
      break;
    case ',':
      fputc(c, out);
      indent(out, depth);
      break;
    case ':': fputs(": ", out); break;
    default: fputc(c, out);
    }
  }
}

/* Every allocation from one heap (no mmap per large block, no arena per
 * thread), grown once by far more than an answer may take (address
 * space only: pages count when touched), and that range advised to use
 * transparent huge pages, so that the answer and the frames fault in 2
 * MB at a time where the system allows it ("madvise" or "always"); an
 * advice refused changes nothing. */
static void prefer_huge_pages(void) {
  const size_t huge = (size_t)2 << 20;
  mallopt(M_MMAP_THRESHOLD, 512 << 20);
  mallopt(M_TOP_PAD, 256 << 20);
  mallopt(M_ARENA_MAX, 1);
  void *probe = malloc(1);
  if (probe == NULL) return;
  uintptr_t lo = ((uintptr_t)probe + huge - 1) & ~(uintptr_t)(huge - 1);
  uintptr_t hi = (uintptr_t)sbrk(0);
  if (hi != (uintptr_t)-1 && lo < hi)
    madvise((void *)lo, (size_t)(hi - lo), MADV_HUGEPAGE);
  free(probe);
}

/* The CPUs this process may run on (its affinity mask), at least 1. */
static int usable_cpus(void) {
  cpu_set_t set;
  if (sched_getaffinity(0, sizeof set, &set) == 0 && CPU_COUNT(&set) > 0)
    return CPU_COUNT(&set);
  return 1;
}

/* Answers up to this size are printed frame by frame on the rendering
 * threads (api_morph_print_while_rendering): the printed frames and the
 * answer are then both held for a moment. */
#define PRINT_WHILE_RENDERING_BYTES ((size_t)32 << 20)

/* Frames handed out one at a time to the rendering threads. */
typedef struct frame_queue {
  api_morph_plan *plan;
  size_t count;
  atomic_size_t next;
  atomic_bool failed; /* a frame could not be built: the rest are left to
                       * api_morph_result, which reports the first */
} frame_queue;

static void *render_frames(void *arg) {
  frame_queue *q = arg;
  while (!atomic_load(&q->failed)) {
    size_t i = atomic_fetch_add(&q->next, 1);
    if (i >= q->count) break;
    if (api_morph_render_frame(q->plan, i) != API_STEP_DONE)
      atomic_store(&q->failed, true);
  }
  return NULL;
}

/* POST /v1/morph as api_handle answers it, its frames rendered on up to
 * threads threads first (fewer when there are fewer frames, or a thread
 * cannot be started: the calling thread renders too). */
static void handle_morph(const api_config *cfg, const api_request *req,
                         int threads, api_response *out) {
  api_morph_plan *plan = NULL;
  if (api_morph_prepare(cfg, req, cfg->max_frames_sync, &plan, out) !=
      API_STEP_DONE)
    return;
  frame_queue q = {plan, api_morph_frame_count(plan), 0, false};
  if (threads > 1 && q.count > 1) {
    /* frames printed on the threads too, where the answer is small
     * enough to be held twice */
    api_morph_print_while_rendering(plan, PRINT_WHILE_RENDERING_BYTES);
    size_t extra = (size_t)threads - 1;
    if (extra > q.count - 1) extra = q.count - 1;
    pthread_t *tid = calloc(extra, sizeof *tid);
    size_t started = 0;
    while (tid != NULL && started < extra &&
           pthread_create(&tid[started], NULL, render_frames, &q) == 0)
      started++;
    render_frames(&q);
    for (size_t k = 0; k < started; k++) pthread_join(tid[k], NULL);
    free(tid);
  }
  api_morph_result(plan, out);
  api_morph_plan_free(plan);
}

int main(int argc, char **argv) {
  api_config cfg;
  api_request req;
  api_response res;
  const char *cmd = NULL;
  bool pretty = false, svg = false, too_big = false;
  int threads = 0;
  size_t len = 0;
  char *body;
  api_status status;

  for (int i = 1; i < argc; i++) {
    if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) {
      usage(stdout);
      return 0;
    } else if (strcmp(argv[i], "--version") == 0) {
      printf("kmorph %s\n", KMORPH_VERSION);
      return 0;
    } else if (strcmp(argv[i], "--pretty") == 0) {
      pretty = true;
    } else if (strcmp(argv[i], "--svg") == 0) {
      svg = true;
    } else if (strcmp(argv[i], "--threads") == 0 && i + 1 < argc) {
      char *end;
      long n = strtol(argv[++i], &end, 10);
      if (*end != '\0' || n < 1 || n > 1024) {
        fprintf(stderr, "kmorph: --threads takes a count from 1 to 1024\n");
        return 2;
      }
      threads = (int)n;
    } else if (argv[i][0] != '-' && cmd == NULL) {
      cmd = argv[i];
    } else {
      fprintf(stderr, "kmorph: unexpected argument '%s'\n", argv[i]);
      usage(stderr);
      return 2;
    }
  }
  memset(&req, 0, sizeof req);
  if (cmd == NULL) {
    usage(stderr);
    return 2;
  } else if (strcmp(cmd, "signature") == 0) {
    req.route = API_ROUTE_SIGNATURE;
  } else if (strcmp(cmd, "reconstruct") == 0) {
    req.route = API_ROUTE_RECONSTRUCT;
  } else if (strcmp(cmd, "morph") == 0) {
    req.route = API_ROUTE_MORPH;
  } else {
    fprintf(stderr, "kmorph: unknown command '%s'\n", cmd);
    usage(stderr);
    return 2;
  }

  prefer_huge_pages();
  api_config_default(&cfg);
  api_response_init(&res);
  body = read_all(stdin, cfg.max_body_bytes, &len, &too_big);
  if (body == NULL) {
    fputs("kmorph: out of memory reading the request\n", stderr);
    return 1;
  }
  if (too_big) {
    char detail[128];
    snprintf(detail, sizeof detail, "the request is larger than %zu bytes",
             cfg.max_body_bytes);
    api_problem(&res, 413, NULL, NULL, detail, NULL, NULL, NULL);
  } else {
    req.body = body;
    req.length = len;
    req.accept = svg ? "image/svg+xml" : "application/json";
    if (req.route == API_ROUTE_MORPH)
      handle_morph(&cfg, &req, threads > 0 ? threads : usable_cpus(), &res);
    else
      api_handle(&cfg, &req, &res);
  }
  free(body);
  status = res.status;
  if (res.body != NULL) {
    bool json =
        res.content_type != NULL && strstr(res.content_type, "json") != NULL;
    if (pretty && json)
      print_pretty(stdout, res.body, res.length);
    else
      fwrite(res.body, 1, res.length, stdout);
    if (res.length == 0 || res.body[res.length - 1] != '\n')
      fputc('\n', stdout);
  }
  api_response_free(&res);
  if (fflush(stdout) != 0) {
    perror("kmorph: writing the response");
    return 1;
  }
  return status >= 200 && status < 300 ? 0 : 1;
}
