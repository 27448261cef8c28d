/* log.c - kmorphd's log stream, its reopening and its rate limit (see
 * log.h).
 *
 * DESIGN: the log is stderr, and a log file is put on descriptor 2 with
 * dup2, so nothing else in the daemon needs to know a file exists. A
 * reopen opens the new file first (a failure keeps the old one), then
 * swaps the descriptor while holding stderr's stdio lock: a writer in the
 * middle of a line finishes it in the old file. The rate limit keeps one
 * slot per kind of message in a small table under a mutex; it is only
 * consulted for messages that can repeat without bound.
 */
#include "log.h"

#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "util.h"

typedef struct rl_slot {
  const void *kind; /* NULL: free */
  double last;      /* when a message of this kind was last written */
  unsigned long suppressed;
  char sample[96];
} rl_slot;

struct srv_log {
  FILE *stream;
  char path[512];
  pthread_mutex_t mu; /* guards slots */
  rl_slot slots[SRV_LOG_KINDS];
};

static int open_append(const char *path) {
  return open(path, O_WRONLY | O_APPEND | O_CREAT | O_CLOEXEC, 0640);
}

srv_log *srv_log_open(const char *path, FILE *err) {
  srv_log *l = calloc(1, sizeof *l);
  if (l == NULL) {
    fprintf(err, "kmorphd: out of memory for the log\n");
    return NULL;
  }
  l->stream = stderr;
  pthread_mutex_init(&l->mu, NULL);
  if (path != NULL && path[0] != '\0') {
    int fd = strlen(path) < sizeof l->path ? open_append(path) : -1;
    if (fd < 0) {
      fprintf(err, "kmorphd: --log-file \"%s\": %s\n", path,
              strlen(path) < sizeof l->path ? strerror(errno)
                                            : "path too long");
      goto fail;
    }
    fflush(stderr);
    int rc = fd == STDERR_FILENO ? 0 : dup2(fd, STDERR_FILENO);
    if (rc < 0)
      fprintf(err, "kmorphd: --log-file \"%s\": %s\n", path, strerror(errno));
    if (fd != STDERR_FILENO) close(fd);
    if (rc < 0) goto fail;
    snprintf(l->path, sizeof l->path, "%s", path);
  }
  return l;
fail:
  pthread_mutex_destroy(&l->mu);
  free(l);
  return NULL;
}

FILE *srv_log_stream(const srv_log *l) {
  return l->stream;
}

const char *srv_log_path(const srv_log *l) {
  return l->path;
}

int srv_log_reopen(srv_log *l) {
  if (l->path[0] == '\0') return 0;
  int fd = open_append(l->path);
  if (fd < 0) return -1;
  int rc = 1;
  flockfile(l->stream);
  fflush(l->stream);
  if (dup2(fd, fileno(l->stream)) < 0) rc = -1;
  int saved = errno;
  funlockfile(l->stream);
  close(fd);
  errno = saved;
  return rc;
}

/* Written once before threads start (srv_log_set_format), read after. */
static srv_log_format log_format = SRV_LOG_KV;

void srv_log_set_format(srv_log_format f) {
  log_format = f;
}

bool srv_log_json(void) {
  return log_format == SRV_LOG_JSON;
}

void srv_log_time(char *out, size_t cap) {
  time_t now = time(NULL);
  struct tm tm;
  gmtime_r(&now, &tm);
  strftime(out, cap, "%Y-%m-%dT%H:%M:%SZ", &tm);
}

static void notice_v(FILE *f, const char *fmt, va_list ap) {
  if (log_format == SRV_LOG_KV) {
    vfprintf(f, fmt, ap);
    return;
  }
  char msg[1024], esc[2100], when[32];
  vsnprintf(msg, sizeof msg, fmt, ap);
  size_t n = strlen(msg);
  while (n > 0 && msg[n - 1] == '\n') msg[--n] = '\0';
  const char *m = strncmp(msg, "kmorphd: ", 9) == 0 ? msg + 9 : msg;
  srv_json_escape(esc, sizeof esc, m);
  srv_log_time(when, sizeof when);
  fprintf(f, "{\"time\":\"%s\",\"level\":\"notice\",\"msg\":\"%s\"}\n", when,
          esc);
}

void srv_log_notice(FILE *f, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  notice_v(f, fmt, ap);
  va_end(ap);
}

void srv_log_printf(srv_log *l, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  notice_v(l->stream, fmt, ap);
  va_end(ap);
}

/* The slot of kind, or the one to give it (free, else least recent). */
static rl_slot *slot_for(srv_log *l, const void *kind) {
  rl_slot *pick = &l->slots[0];
  for (size_t i = 0; i < SRV_LOG_KINDS; i++) {
    rl_slot *sl = &l->slots[i];
    if (sl->kind == kind) return sl;
    if (pick->kind != NULL && (sl->kind == NULL || sl->last < pick->last))
      pick = sl;
  }
  pick->kind = NULL;
  return pick;
}

bool srv_log_admit(srv_log *l, const void *kind, const char *sample,
                   unsigned long *suppressed) {
  double now = srv_now();
  bool ok;
  pthread_mutex_lock(&l->mu);
  rl_slot *sl = slot_for(l, kind);
  if (sl->kind == NULL) {
    sl->kind = kind;
    sl->suppressed = 0;
    ok = true;
  } else {
    ok = now - sl->last >= SRV_LOG_INTERVAL;
  }
  if (ok) {
    *suppressed = sl->suppressed;
    sl->suppressed = 0;
    sl->last = now;
    snprintf(sl->sample, sizeof sl->sample, "%s", sample ? sample : "");
  } else {
    sl->suppressed++;
  }
  pthread_mutex_unlock(&l->mu);
  return ok;
}

void srv_log_close(srv_log *l) {
  if (l == NULL) return;
  pthread_mutex_lock(&l->mu);
  for (size_t i = 0; i < SRV_LOG_KINDS; i++) {
    const rl_slot *sl = &l->slots[i];
    if (sl->kind != NULL && sl->suppressed > 0)
      srv_log_notice(l->stream, "kmorphd: %lu more suppressed like \"%s\"\n",
                     sl->suppressed, sl->sample);
  }
  pthread_mutex_unlock(&l->mu);
  fflush(l->stream);
  pthread_mutex_destroy(&l->mu);
  free(l);
}
