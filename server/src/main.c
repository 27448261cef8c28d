/* main.c - kmorphd: configuration, signals and the server's life cycle.
 *
 * DESIGN: every signal the daemon answers is blocked before any thread
 * starts, so every thread inherits the mask and the main thread alone
 * receives them with sigwait: no handler runs in an arbitrary thread and
 * nothing global is needed. SIGTERM and SIGINT drain and stop; SIGHUP
 * reopens the log file (logrotate moves it away first); SIGUSR1, SIGUSR2,
 * SIGALRM and SIGVTALRM, whose default is to kill the process, are logged
 * and otherwise ignored, so a stray kill loses no work. SIGPIPE and
 * SIGXFSZ are ignored outright: a write to a closed peer or past the file
 * size limit then fails with EPIPE or EFBIG instead of killing the
 * process.
 *
 * The connection limits are lowered, if need be, so that every connection
 * the daemon may accept has its descriptors under RLIMIT_NOFILE: at its
 * limit the front stops polling the listening socket, while out of
 * descriptors accept fails with EMFILE as fast as it is retried.
 */
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>

#include "config.h"
#include "cpus.h"
#include "healthcheck.h"
#include "log.h"
#include "server.h"

static const struct {
  int sig;
  const char *name;
} SIGNALS[] = {{SIGTERM, "SIGTERM"},    {SIGINT, "SIGINT"},
               {SIGHUP, "SIGHUP"},      {SIGUSR1, "SIGUSR1"},
               {SIGUSR2, "SIGUSR2"},    {SIGALRM, "SIGALRM"},
               {SIGVTALRM, "SIGVTALRM"}};
#define NSIGNALS (sizeof SIGNALS / sizeof SIGNALS[0])

static const char *signal_name(int sig) {
  for (size_t i = 0; i < NSIGNALS; i++)
    if (SIGNALS[i].sig == sig) return SIGNALS[i].name;
  return "signal";
}

/* Block the answered signals (before any thread exists) and ignore the
 * ones whose only effect would be to kill the process on a write. */
static void setup_signals(sigset_t *set) {
  sigemptyset(set);
  for (size_t i = 0; i < NSIGNALS; i++) sigaddset(set, SIGNALS[i].sig);
  pthread_sigmask(SIG_BLOCK, set, NULL);
  struct sigaction ign;
  memset(&ign, 0, sizeof ign);
  ign.sa_handler = SIG_IGN;
  sigemptyset(&ign.sa_mask);
  sigaction(SIGPIPE, &ign, NULL);
  sigaction(SIGXFSZ, &ign, NULL);
}

static void reopen_log(srv_log *log) {
  int rc = srv_log_reopen(log);
  if (rc > 0)
    srv_log_printf(log, "kmorphd: SIGHUP: log file \"%s\" reopened\n",
                   srv_log_path(log));
  else if (rc == 0)
    srv_log_printf(log, "kmorphd: SIGHUP: no --log-file to reopen\n");
  else
    srv_log_printf(log,
                   "kmorphd: SIGHUP: cannot reopen \"%s\" (%s): still "
                   "writing to the file open before\n",
                   srv_log_path(log), strerror(errno));
}

/* Serve signals until one asks the daemon to stop; returns that one. */
static int wait_for_stop(srv_log *log, const sigset_t *set) {
  for (;;) {
    int sig = 0;
    if (sigwait(set, &sig) != 0) continue;
    if (sig == SIGTERM || sig == SIGINT) return sig;
    if (sig == SIGHUP)
      reopen_log(log);
    else
      srv_log_printf(log, "kmorphd: %s ignored (SIGTERM stops the daemon)\n",
                     signal_name(sig));
  }
}

/* Descriptors open now: new ones take the lowest free numbers, so EMFILE
 * comes when every number under the limit is taken. */
static unsigned long open_fds(unsigned long limit) {
  unsigned long n = 0;
  DIR *d = opendir("/proc/self/fd");
  if (d != NULL) {
    const struct dirent *e;
    while ((e = readdir(d)) != NULL) n += e->d_name[0] != '.';
    closedir(d);
    return n > 0 ? n - 1 : 0; /* the directory's own descriptor */
  }
  for (unsigned long fd = 0; fd < limit && fd < 65536; fd++)
    n += fcntl((int)fd, F_GETFD) != -1;
  return n;
}

/* Lower --max-connections and --reserved-connections so that they, the
 * descriptors open now and those the daemon opens besides connections fit
 * under RLIMIT_NOFILE. A connection holds three (the client's socket and
 * a socket pair to libmicrohttpd, front.h). Besides connections: the
 * listening socket, an epoll set and an eventfd per I/O thread and per
 * relay thread (1 + 4 n, as counted in /proc/PID/fd), a file served from
 * the web root per I/O thread, a reopened log, and 8 spare. Returns 0, or -1 (with a message) when not
 * one connection per I/O thread fits. */
static int fit_connections_to_fds(srv_config *cfg, srv_log *log) {
  struct rlimit rl;
  if (getrlimit(RLIMIT_NOFILE, &rl) != 0 || rl.rlim_cur == RLIM_INFINITY)
    return 0;
  unsigned long limit = (unsigned long)rl.rlim_cur;
  unsigned long used = open_fds(limit) + 1 + 5ul * cfg->io_threads + 1 + 8;
  unsigned long room = limit > used ? (limit - used) / 3 : 0;
  unsigned long want = (unsigned long)cfg->max_connections + cfg->reserved;
  if (room >= want) return 0;
  if (room < 2ul * cfg->io_threads) {
    srv_log_printf(log,
                   "kmorphd: RLIMIT_NOFILE %lu leaves no descriptors for "
                   "connections (the daemon needs %lu itself); raise it "
                   "(ulimit -n)\n",
                   limit, used);
    return -1;
  }
  /* Probes keep at most a quarter of what is left. */
  unsigned long reserved = cfg->reserved < room / 4 ? cfg->reserved : room / 4;
  srv_log_printf(log,
                 "kmorphd: RLIMIT_NOFILE %lu leaves descriptors for %lu "
                 "connections: --max-connections %u lowered to %lu and "
                 "--reserved-connections %u to %lu\n",
                 limit, room, cfg->max_connections, room - reserved,
                 cfg->reserved, reserved);
  cfg->max_connections = (unsigned)(room - reserved);
  cfg->reserved = (unsigned)reserved;
  return 0;
}

int main(int argc, char **argv) {
  if (argc >= 2 && srv_healthcheck_requested(argv[1]))
    return srv_healthcheck_main(argc, argv, stderr);
  srv_config cfg;
  srv_config_default(&cfg);
  int rc = srv_config_load(&cfg, argc, argv, stdout, stderr);
  if (rc != 0) return rc > 0 ? 0 : 2;
  if (cfg.workers == 0) cfg.workers = srv_usable_cpus();

  sigset_t set;
  setup_signals(&set);
  srv_log_set_format(strcmp(cfg.log_format, "json") == 0 ? SRV_LOG_JSON
                                                         : SRV_LOG_KV);
  srv_log *log = srv_log_open(cfg.log_file, stderr);
  if (log == NULL) return 2;
  srv_server *srv = fit_connections_to_fds(&cfg, log) == 0
                        ? srv_server_create(&cfg, log)
                        : NULL;
  if (srv == NULL || srv_server_start(srv) != 0) {
    srv_server_destroy(srv);
    srv_log_close(log);
    return 1;
  }
  srv_log_printf(log,
                 "kmorphd: listening on http://%s%s%s:%u (workers %u, queue "
                 "%u, io threads %u)\n",
                 strchr(cfg.bind, ':') ? "[" : "", cfg.bind,
                 strchr(cfg.bind, ':') ? "]" : "", srv_server_port(srv),
                 cfg.workers, cfg.queue, cfg.io_threads);

  int sig = wait_for_stop(log, &set);
  srv_log_printf(log, "kmorphd: %s: shutting down (grace %g s)\n",
                 signal_name(sig), cfg.shutdown_grace);
  if (srv_server_shutdown(srv) != 0) {
    /* Work is still running past the deadline and the stop of its
     * computations: the HTTP daemon cannot be stopped with connections
     * suspended, so leave at once. The stop was requested, so this is
     * still a normal exit. */
    srv_log_printf(log, "kmorphd: stopped (forced after the grace period)\n");
    srv_log_close(log);
    _exit(0);
  }
  srv_server_destroy(srv);
  srv_log_printf(log, "kmorphd: stopped\n");
  srv_log_close(log);
  return 0;
}
