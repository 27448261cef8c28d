/* config.h - kmorphd settings: defaults, environment variables, flags.
 *
 * Every limit of the daemon is here, set from (in rising precedence) the
 * built-in default, an environment variable KMORPH_*, and a command-line
 * flag --name. `kmorphd --help` prints the table below, so the help text
 * and the parser cannot disagree.
 */
#ifndef SRV_CONFIG_H
#define SRV_CONFIG_H

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

typedef struct srv_config {
  char bind[64];            /* listen address (IPv4 or IPv6 literal) */
  unsigned port;            /* 0: let the OS choose (printed at start) */
  unsigned io_threads;      /* libmicrohttpd I/O threads */
  unsigned workers;         /* compute workers; 0 = number of cores */
  unsigned queue;           /* pending compute requests before 503 */
  unsigned max_connections; /* concurrent connections */
  unsigned timeout;         /* idle seconds before a connection is cut */
  double request_time;      /* seconds to receive a whole request */
  double morph_time;        /* compute seconds per synchronous morph */
  double compute_time;      /* compute seconds per signature/reconstruct */
  double header_time;       /* seconds to receive a request's header */
  double send_time;         /* seconds to deliver one answer */
  unsigned per_ip;          /* connections per client address */
  unsigned reserved;        /* extra slots for quick probes when full */
  size_t max_body;          /* bytes; larger bodies are 413 */
  size_t max_output;        /* bytes of one answer, predicted before work */
  size_t body_memory;       /* bytes of all bodies in flight */
  size_t result_memory;     /* bytes of all kept job results */
  size_t max_points;        /* control points per curve */
  size_t max_contours;      /* contours per shape (at most 4,096) */
  size_t max_frames;        /* frames per POST /v1/morph */
  size_t max_job_frames;    /* frames per POST /v1/jobs */
  size_t max_samples;       /* kappa samples per request */
  unsigned max_jobs;        /* queued + running jobs before 429 */
  double job_time;          /* wall seconds per job before it fails */
  double job_ttl;           /* seconds a finished job stays readable */
  unsigned job_keep;        /* finished jobs kept at most */
  double shutdown_grace;    /* seconds to finish work on SIGTERM */
  unsigned retry_after;     /* Retry-After seconds on 429/503 */
  char cors_origins[512];   /* comma-separated, "*" = any, "" = no CORS */
  char web_root[512];       /* folder of the web page served at / */
  bool access_log;          /* one line per request on stderr */
  char log_file[512];       /* log to this file (reopened on SIGHUP) */
  char jobs[512];           /* redis://HOST:PORT/DB: jobs shared there;
                             * "" = in this process's memory */
  double job_reclaim;       /* seconds before a silent instance's batch
                             * of a shared job is taken over */
  char log_format[8];       /* "kv" (key=value lines) or "json" */
} srv_config;

/* Fill *cfg with the built-in defaults. */
void srv_config_default(srv_config *cfg);

/* Apply KMORPH_* environment variables, then argv flags, onto *cfg.
 * Returns 0 to run, 1 if --help or --version was printed (exit 0), or -1
 * after printing an error to err (exit 2). */
int srv_config_load(srv_config *cfg, int argc, char **argv, FILE *out,
                    FILE *err);

/* Print the flag/environment table with defaults to out. */
void srv_config_usage(FILE *out);

#endif
