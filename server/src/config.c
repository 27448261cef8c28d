/* config.c - parse kmorphd flags and KMORPH_* environment variables.
 *
 * DESIGN: one table names every setting once (flag, variable, type,
 * bounds, help); defaults live in srv_config_default. Bounds refuse values
 * that would make the daemon useless or unsafe (a zero-length queue, a
 * body limit of 0) with a message rather than clamping silently.
 */
#include "config.h"
#include "web_root.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* The build passes the tree's VERSION; a stray compile without it still
 * says something true. */
#ifndef KMORPH_VERSION
#define KMORPH_VERSION "unknown"
#endif

typedef enum { OPT_STR, OPT_UINT, OPT_SIZE, OPT_SECONDS, OPT_BOOL } opt_kind;

typedef struct opt_def {
  const char *flag;
  const char *env;
  opt_kind kind;
  size_t offset;
  size_t size; /* buffer size for OPT_STR */
  double min, max;
  const char *help;
} opt_def;

#define F(m) offsetof(srv_config, m)
static const opt_def OPTS[] = {
    {"bind", "KMORPH_BIND", OPT_STR, F(bind), sizeof(((srv_config *)0)->bind),
     0, 0, "listen address"},
    {"port", "KMORPH_PORT", OPT_UINT, F(port), 0, 0, 65535,
     "TCP port (0: any free port, printed at start); PORT is read when "
     "neither is set"},
    {"io-threads", "KMORPH_IO_THREADS", OPT_UINT, F(io_threads), 0, 1, 64,
     "HTTP I/O threads"},
    {"threads", "KMORPH_THREADS", OPT_UINT, F(workers), 0, 0, 1024,
     "compute workers (0: the CPUs the process may use: affinity, cgroup "
     "cpu.max)"},
    {"queue", "KMORPH_QUEUE", OPT_UINT, F(queue), 0, 1, 1000000,
     "compute requests waiting before 503"},
    {"max-connections", "KMORPH_MAX_CONNECTIONS", OPT_UINT, F(max_connections),
     0, 1, 100000, "concurrent connections"},
    {"timeout", "KMORPH_TIMEOUT", OPT_UINT, F(timeout), 0, 1, 86400,
     "idle seconds before a connection is closed"},
    {"request-time", "KMORPH_REQUEST_TIME", OPT_SECONDS, F(request_time), 0,
     0.01, 86400, "seconds to receive one whole request"},
    {"morph-time", "KMORPH_MORPH_TIME", OPT_SECONDS, F(morph_time), 0, 0.01,
     86400, "compute seconds per POST /v1/morph (past it: 422)"},
    {"compute-time", "KMORPH_COMPUTE_TIME", OPT_SECONDS, F(compute_time), 0,
     0.01, 86400,
     "compute seconds per POST /v1/signature or /v1/reconstruct (past it: "
     "422)"},
    {"header-time", "KMORPH_HEADER_TIME", OPT_SECONDS, F(header_time), 0, 0.05,
     3600, "seconds to receive a request's header (past it: 408)"},
    {"send-time", "KMORPH_SEND_TIME", OPT_SECONDS, F(send_time), 0, 0.05, 86400,
     "seconds to deliver one answer before the connection is cut"},
    {"per-ip", "KMORPH_PER_IP", OPT_UINT, F(per_ip), 0, 1, 100000,
     "concurrent connections from one client address"},
    {"reserved-connections", "KMORPH_RESERVED_CONNECTIONS", OPT_UINT,
     F(reserved), 0, 0, 10000,
     "slots beyond --max-connections kept for quick requests (/healthz)"},
    {"max-body", "KMORPH_MAX_BODY", OPT_SIZE, F(max_body), 0, 1, 1e12,
     "request body bytes (larger: 413)"},
    {"max-output", "KMORPH_MAX_OUTPUT", OPT_SIZE, F(max_output), 0, 1024, 1e13,
     "bytes of one answer, predicted before work (larger: 422)"},
    {"body-memory", "KMORPH_BODY_MEMORY", OPT_SIZE, F(body_memory), 0, 1, 1e13,
     "bytes of all request bodies in flight (past it: 503)"},
    {"result-memory", "KMORPH_RESULT_MEMORY", OPT_SIZE, F(result_memory), 0, 1,
     1e13, "bytes of kept job results (oldest evicted: 410)"},
    {"max-points", "KMORPH_MAX_POINTS", OPT_SIZE, F(max_points), 0, 1, 1e9,
     "control points per curve, given or returned"},
    {"max-contours", "KMORPH_MAX_CONTOURS", OPT_SIZE, F(max_contours), 0, 1,
     4096, "contours (subpaths) per shape"},
    {"max-frames", "KMORPH_MAX_FRAMES", OPT_SIZE, F(max_frames), 0, 1, 1e9,
     "frames per POST /v1/morph"},
    {"max-job-frames", "KMORPH_MAX_JOB_FRAMES", OPT_SIZE, F(max_job_frames), 0,
     1, 1e9, "frames per POST /v1/jobs"},
    {"max-samples", "KMORPH_MAX_SAMPLES", OPT_SIZE, F(max_samples), 0, 1, 1e9,
     "curvature samples per request"},
    {"max-jobs", "KMORPH_MAX_JOBS", OPT_UINT, F(max_jobs), 0, 1, 1000000,
     "queued + running jobs before 429"},
    {"job-time", "KMORPH_JOB_TIME", OPT_SECONDS, F(job_time), 0, 0.01, 1e7,
     "wall seconds per job before it fails"},
    {"job-ttl", "KMORPH_JOB_TTL", OPT_SECONDS, F(job_ttl), 0, 0, 1e7,
     "seconds a finished job stays readable"},
    {"job-keep", "KMORPH_JOB_KEEP", OPT_UINT, F(job_keep), 0, 1, 10000000,
     "finished jobs kept at most (oldest dropped)"},
    {"shutdown-grace", "KMORPH_SHUTDOWN_GRACE", OPT_SECONDS, F(shutdown_grace),
     0, 0, 3600,
     "seconds to finish work on SIGTERM (below a container's 10 s stop "
     "timeout)"},
    {"retry-after", "KMORPH_RETRY_AFTER", OPT_UINT, F(retry_after), 0, 0, 3600,
     "Retry-After seconds sent with 429/503"},
    {"cors-origins", "KMORPH_CORS_ORIGINS", OPT_STR, F(cors_origins),
     sizeof(((srv_config *)0)->cors_origins), 0, 0,
     "allowed CORS origins, comma-separated; * = any; empty = none"},
    {"web-root", "KMORPH_WEB_ROOT", OPT_STR, F(web_root),
     sizeof(((srv_config *)0)->web_root), 0, 0,
     "folder whose index.html is served at /"},
    {"access-log", "KMORPH_ACCESS_LOG", OPT_BOOL, F(access_log), 0, 0, 1,
     "one line per request on stderr (1/0)"},
    {"log-file", "KMORPH_LOG_FILE", OPT_STR, F(log_file),
     sizeof(((srv_config *)0)->log_file), 0, 0,
     "append the log here instead of stderr (reopened on SIGHUP)"},
    {"jobs", "KMORPH_JOBS", OPT_STR, F(jobs), sizeof(((srv_config *)0)->jobs),
     0, 0,
     "share jobs with other instances through Redis: redis://HOST:PORT/DB "
     "(empty: jobs in this process's memory)"},
    {"job-reclaim", "KMORPH_JOB_RECLAIM", OPT_SECONDS, F(job_reclaim), 0, 0.5,
     3600,
     "with --jobs: seconds before the frames another instance took and did "
     "not finish are rendered here"},
    {"log-format", "KMORPH_LOG_FORMAT", OPT_STR, F(log_format),
     sizeof(((srv_config *)0)->log_format), 0, 0,
     "log lines: kv (key=value text) or json (one object per line)"},
};
#undef F
#define NOPTS (sizeof OPTS / sizeof OPTS[0])

void srv_config_default(srv_config *cfg) {
  memset(cfg, 0, sizeof *cfg);
  snprintf(cfg->bind, sizeof cfg->bind, "127.0.0.1");
  cfg->port = 8080;
  cfg->io_threads = 2;
  cfg->workers = 0;
  cfg->queue = 64;
  cfg->max_connections = 512;
  cfg->timeout = 30;
  cfg->request_time = 60;
  cfg->morph_time = 60;
  cfg->compute_time = 60;
  cfg->header_time = 10;
  cfg->send_time = 300;
  cfg->per_ip = 128;
  cfg->reserved = 16;
  cfg->max_body = (size_t)8 << 20;
  cfg->max_output = (size_t)64 << 20;
  cfg->body_memory = (size_t)256 << 20;
  cfg->result_memory = (size_t)512 << 20;
  cfg->max_points = 100000;
  cfg->max_contours = 64;
  cfg->max_frames = 1000;
  cfg->max_job_frames = 10000;
  cfg->max_samples = 100000;
  cfg->max_jobs = 32;
  cfg->job_time = 300;
  cfg->job_ttl = 600;
  cfg->job_keep = 1000;
  cfg->shutdown_grace = 8;
  cfg->job_reclaim = 5;
  cfg->retry_after = 1;
  srv_default_web_root(cfg->web_root, sizeof cfg->web_root);
  cfg->access_log = true;
  snprintf(cfg->log_format, sizeof cfg->log_format, "kv");
}

static void print_default(FILE *out, const opt_def *o, const srv_config *d) {
  const char *p = (const char *)d + o->offset;
  switch (o->kind) {
  case OPT_STR: fprintf(out, "\"%s\"", p); break;
  case OPT_UINT: fprintf(out, "%u", *(const unsigned *)(const void *)p); break;
  case OPT_SIZE: fprintf(out, "%zu", *(const size_t *)(const void *)p); break;
  case OPT_SECONDS: fprintf(out, "%g", *(const double *)(const void *)p); break;
  case OPT_BOOL:
    fprintf(out, "%d", *(const bool *)(const void *)p ? 1 : 0);
    break;
  }
}

void srv_config_usage(FILE *out) {
  srv_config d;
  srv_config_default(&d);
  fprintf(out,
          "usage: kmorphd [--flag value | --flag=value]...\n"
          "kmorph HTTP service: curvature-blended morphs of planar curves.\n"
          "Each setting is a flag or an environment variable (the flag "
          "wins).\n\n");
  for (size_t i = 0; i < NOPTS; i++) {
    const opt_def *o = &OPTS[i];
    fprintf(out, "  --%-16s %-24s %s (default ", o->flag, o->env, o->help);
    print_default(out, o, &d);
    fprintf(out, ")\n");
  }
  fprintf(out,
          "\n  --help                                    this text\n"
          "  --version                                 version\n"
          "  --healthcheck URL                         GET URL once, exit 0 "
          "on 200 (no server)\n");
  fprintf(out, "\nSignals: SIGTERM, SIGINT drain and stop; SIGHUP reopens "
               "--log-file;\nSIGUSR1, SIGUSR2, SIGALRM, SIGVTALRM are logged "
               "and ignored.\n");
}

static int set_value(srv_config *cfg, const opt_def *o, const char *v,
                     const char *from, FILE *err) {
  char *p = (char *)cfg + o->offset;
  if (o->kind == OPT_STR) {
    if (strlen(v) >= o->size) {
      fprintf(err, "kmorphd: %s: value too long\n", from);
      return -1;
    }
    memcpy(p, v, strlen(v) + 1);
    return 0;
  }
  errno = 0;
  char *end = NULL;
  double x = strtod(v, &end);
  if (end == v || *end != '\0' || errno != 0 || !isfinite(x)) {
    fprintf(err, "kmorphd: %s: \"%s\" is not a number\n", from, v);
    return -1;
  }
  if (o->kind != OPT_SECONDS && x != floor(x)) {
    fprintf(err, "kmorphd: %s: \"%s\" must be a whole number\n", from, v);
    return -1;
  }
  if (x < o->min || x > o->max) {
    fprintf(err, "kmorphd: %s: %s is out of range [%g, %g]\n", from, v, o->min,
            o->max);
    return -1;
  }
  switch (o->kind) {
  case OPT_UINT: *(unsigned *)(void *)p = (unsigned)x; break;
  case OPT_SIZE: *(size_t *)(void *)p = (size_t)x; break;
  case OPT_SECONDS: *(double *)(void *)p = x; break;
  case OPT_BOOL: *(bool *)(void *)p = x != 0; break;
  case OPT_STR: break;
  }
  return 0;
}

/* The setting whose flag is name[0..nlen-1], or NULL. */
static const opt_def *find_opt(const char *name, size_t nlen) {
  for (size_t i = 0; i < NOPTS; i++)
    if (strlen(OPTS[i].flag) == nlen && strncmp(OPTS[i].flag, name, nlen) == 0)
      return &OPTS[i];
  return NULL;
}

int srv_config_load(srv_config *cfg, int argc, char **argv, FILE *out,
                    FILE *err) {
  /* PORT, the generic variable platforms set (Heroku, Cloud Run), is the
   * fallback under KMORPH_PORT and --port. */
  const char *generic_port = getenv("PORT");
  if (generic_port != NULL && generic_port[0] != '\0' &&
      set_value(cfg, find_opt("port", 4), generic_port, "PORT", err) != 0)
    return -1;
  for (size_t i = 0; i < NOPTS; i++) {
    const char *v = getenv(OPTS[i].env);
    if (v != NULL && set_value(cfg, &OPTS[i], v, OPTS[i].env, err) != 0)
      return -1;
  }
  for (int a = 1; a < argc; a++) {
    const char *arg = argv[a];
    if (strcmp(arg, "--help") == 0 || strcmp(arg, "-h") == 0) {
      srv_config_usage(out);
      return 1;
    }
    if (strcmp(arg, "--version") == 0) {
      fprintf(out, "kmorphd %s (API v1)\n", KMORPH_VERSION);
      return 1;
    }
    if (strncmp(arg, "--", 2) != 0) {
      fprintf(err, "kmorphd: unexpected argument \"%s\" (see --help)\n", arg);
      return -1;
    }
    const char *name = arg + 2;
    const char *eq = strchr(name, '=');
    size_t nlen = eq ? (size_t)(eq - name) : strlen(name);
    const opt_def *o = find_opt(name, nlen);
    if (o == NULL) {
      fprintf(err, "kmorphd: unknown flag \"%s\" (see --help)\n", arg);
      return -1;
    }
    const char *v;
    if (eq != NULL) {
      v = eq + 1;
    } else if (a + 1 < argc) {
      v = argv[++a];
    } else {
      fprintf(err, "kmorphd: --%s needs a value\n", o->flag);
      return -1;
    }
    if (set_value(cfg, o, v, arg, err) != 0) return -1;
  }
  if (strcmp(cfg->log_format, "kv") != 0 &&
      strcmp(cfg->log_format, "json") != 0) {
    fprintf(err, "kmorphd: --log-format: \"%s\" is not kv or json\n",
            cfg->log_format);
    return -1;
  }
  return 0;
}
