/* process_metrics.c - process_* metrics from /proc/self (see
 * process_metrics.h).
 *
 * DESIGN: the names, types and units are those of the Prometheus client
 * libraries (client_golang's process collector), so the dashboards and
 * alerts written for any exporter work unchanged: CPU in seconds (user +
 * system), memory in bytes, the start time in seconds since the epoch
 * (boot time from /proc/stat plus the start tick of /proc/self/stat).
 */
#include "process_metrics.h"

#include <dirent.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>

typedef struct out_buf {
  char *p;
  size_t cap, len;
} out_buf;

static void put(out_buf *b, const char *fmt, ...) {
  if (b->len >= b->cap) return;
  va_list ap;
  va_start(ap, fmt);
  int n = vsnprintf(b->p + b->len, b->cap - b->len, fmt, ap);
  va_end(ap);
  if (n <= 0) return;
  size_t room = b->cap - b->len;
  b->len += (size_t)n < room ? (size_t)n : room - 1;
}

/* Fields 14, 15 (utime, stime), 22 (starttime) and 24 (rss pages) of
 * /proc/self/stat; 0 when read. */
static int read_stat(double *utime, double *stime, double *start, double *rss) {
  char text[1024];
  FILE *f = fopen("/proc/self/stat", "r");
  if (f == NULL) return -1;
  size_t n = fread(text, 1, sizeof text - 1, f);
  fclose(f);
  text[n] = '\0';
  /* The command name may hold spaces and parentheses: fields start
   * after the last ')'. */
  char *p = strrchr(text, ')');
  if (p == NULL) return -1;
  unsigned long long v[24] = {0};
  int field = 2; /* the ')' ends field 2 */
  char *save = NULL;
  for (char *tok = strtok_r(p + 1, " ", &save); tok && field < 24;
       tok = strtok_r(NULL, " ", &save)) {
    field++;
    sscanf(tok, "%llu", &v[field - 1]);
  }
  if (field < 24) return -1;
  double hz = (double)sysconf(_SC_CLK_TCK);
  *utime = (double)v[13] / hz;
  *stime = (double)v[14] / hz;
  *start = (double)v[21] / hz;
  *rss = (double)v[23] * (double)sysconf(_SC_PAGESIZE);
  return 0;
}

static long long boot_time(void) {
  char line[256];
  long long bt = -1;
  FILE *f = fopen("/proc/stat", "r");
  if (f == NULL) return -1;
  while (fgets(line, sizeof line, f) != NULL)
    if (sscanf(line, "btime %lld", &bt) == 1) break;
  fclose(f);
  return bt;
}

static long open_fds(void) {
  DIR *d = opendir("/proc/self/fd");
  if (d == NULL) return -1;
  long n = 0;
  for (struct dirent *e; (e = readdir(d)) != NULL;)
    if (e->d_name[0] != '.') n++;
  closedir(d);
  return n - 1; /* the directory's own descriptor */
}

size_t srv_process_metrics(char *out, size_t cap) {
  out_buf b = {out, cap, 0};
  if (cap == 0) return 0;
  out[0] = '\0';
  double ut, st, start, rss;
  if (read_stat(&ut, &st, &start, &rss) == 0) {
    put(&b,
        "# HELP process_cpu_seconds_total Total user and system CPU time "
        "spent in seconds.\n"
        "# TYPE process_cpu_seconds_total counter\n"
        "process_cpu_seconds_total %.2f\n"
        "# HELP process_resident_memory_bytes Resident memory size in "
        "bytes.\n"
        "# TYPE process_resident_memory_bytes gauge\n"
        "process_resident_memory_bytes %.0f\n",
        ut + st, rss);
    long long bt = boot_time();
    if (bt >= 0)
      put(&b,
          "# HELP process_start_time_seconds Start time of the process "
          "since unix epoch in seconds.\n"
          "# TYPE process_start_time_seconds gauge\n"
          "process_start_time_seconds %.2f\n",
          (double)bt + start);
  }
  long fds = open_fds();
  if (fds >= 0)
    put(&b,
        "# HELP process_open_fds Number of open file descriptors.\n"
        "# TYPE process_open_fds gauge\n"
        "process_open_fds %ld\n",
        fds);
  struct rlimit rl;
  if (getrlimit(RLIMIT_NOFILE, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY)
    put(&b,
        "# HELP process_max_fds Maximum number of open file descriptors.\n"
        "# TYPE process_max_fds gauge\n"
        "process_max_fds %llu\n",
        (unsigned long long)rl.rlim_cur);
  return b.len;
}
