/* main.c - kmorphd: configuration, signals and the server's life cycle.
 *
 * DESIGN: SIGTERM and SIGINT are blocked before any thread starts, so every
 * thread inherits the mask and the main thread alone receives them with
 * sigwait: no handler runs in an arbitrary thread and nothing global is
 * needed. The main thread then drives the graceful shutdown.
 */
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "config.h"
#include "server.h"

int main(int argc, char **argv)
{
  srv_config cfg;
  srv_config_default(&cfg);
  int rc = srv_config_load(&cfg, argc, argv, stdout, stderr);
  if (rc != 0)
    return rc > 0 ? 0 : 2;
  if (cfg.workers == 0) {
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    cfg.workers = n > 0 ? (unsigned)n : 1;
  }

  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGTERM);
  sigaddset(&set, SIGINT);
  pthread_sigmask(SIG_BLOCK, &set, NULL);
  /* A peer closing early must not kill the process on write. */
  struct sigaction ign;
  memset(&ign, 0, sizeof ign);
  ign.sa_handler = SIG_IGN;
  sigaction(SIGPIPE, &ign, NULL);

  srv_server *srv = srv_server_create(&cfg, stderr);
  if (srv == NULL)
    return 1;
  if (srv_server_start(srv) != 0) {
    srv_server_destroy(srv);
    return 1;
  }
  fprintf(stderr,
          "kmorphd: listening on http://%s%s%s:%u (workers %u, queue %u, "
          "io threads %u)\n",
          strchr(cfg.bind, ':') ? "[" : "", cfg.bind,
          strchr(cfg.bind, ':') ? "]" : "", srv_server_port(srv), cfg.workers,
          cfg.queue, cfg.io_threads);

  int sig = 0;
  while (sigwait(&set, &sig) != 0)
    ;
  fprintf(stderr, "kmorphd: %s: shutting down (grace %g s)\n",
          sig == SIGTERM ? "SIGTERM" : "SIGINT", cfg.shutdown_grace);
  if (srv_server_shutdown(srv) != 0) {
    /* Work is still running past the deadline: the HTTP daemon cannot be
     * stopped with connections suspended, so leave at once. The stop was
     * requested, so this is still a normal exit. */
    fprintf(stderr, "kmorphd: stopped (forced after the grace period)\n");
    fflush(stderr);
    _exit(0);
  }
  srv_server_destroy(srv);
  fprintf(stderr, "kmorphd: stopped\n");
  return 0;
}
