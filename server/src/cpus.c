/* cpus.c - the CPUs this process may use (see cpus.h).
 *
 * DESIGN: a container limited with --cpus=1.5 still sees every CPU of the
 * host in its affinity mask; only cgroup v2's cpu.max says it will be
 * throttled past 1.5 CPUs. Workers beyond that only add contention, so
 * the quota caps the mask's count. The cgroup is the one /proc/self/cgroup
 * names ("0::/path"), read under /sys/fs/cgroup; inside a cgroup
 * namespace that path is "/", whose cpu.max the container's limit is.
 */
#define _GNU_SOURCE
#include "cpus.h"

#include <math.h>
#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

unsigned srv_cpu_max_quota(const char *text) {
  char quota[32];
  double period = 0;
  if (text == NULL || sscanf(text, "%31s %lf", quota, &period) != 2 ||
      strcmp(quota, "max") == 0 || !(period > 0))
    return 0;
  char *end = NULL;
  double q = strtod(quota, &end);
  if (end == quota || !(q > 0)) return 0;
  double n = ceil(q / period);
  return n < 1 ? 1 : n > 65536 ? 65536 : (unsigned)n;
}

/* The text of the process's cgroup v2 cpu.max, or "" if there is none. */
static void read_cpu_max(char *out, size_t cap) {
  char line[512] = "", path[640];
  out[0] = '\0';
  FILE *f = fopen("/proc/self/cgroup", "r");
  if (f != NULL) {
    while (fgets(line, sizeof line, f) != NULL)
      if (strncmp(line, "0::", 3) == 0) break;
    fclose(f);
  }
  line[strcspn(line, "\n")] = '\0';
  const char *rel = strncmp(line, "0::", 3) == 0 && line[3] ? line + 3 : "/";
  snprintf(path, sizeof path, "/sys/fs/cgroup%s%scpu.max", rel,
           rel[strlen(rel) - 1] == '/' ? "" : "/");
  f = fopen(path, "r");
  if (f == NULL) f = fopen("/sys/fs/cgroup/cpu.max", "r");
  if (f == NULL) return;
  if (fgets(out, (int)cap, f) == NULL) out[0] = '\0';
  fclose(f);
}

unsigned srv_usable_cpus(void) {
  cpu_set_t set;
  long n = 0;
  if (sched_getaffinity(0, sizeof set, &set) == 0) n = CPU_COUNT(&set);
  if (n <= 0) n = sysconf(_SC_NPROCESSORS_ONLN);
  if (n <= 0) n = 1;
  char text[64];
  read_cpu_max(text, sizeof text);
  unsigned q = srv_cpu_max_quota(text);
  if (q > 0 && q < (unsigned long)n) n = q;
  return (unsigned)n;
}
