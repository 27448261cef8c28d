/* cpus.h - how many CPUs this process may use: its affinity mask, capped
 * by a cgroup v2 CPU quota (a container's --cpus), so that the default
 * worker count fits what the process is given rather than the machine.
 *
 * Thread-safety: reads the kernel's files and the calling thread's mask;
 * call at start-up.
 */
#ifndef SRV_CPUS_H
#define SRV_CPUS_H

/* The CPUs usable now: the number of CPUs in sched_getaffinity's mask
 * (the online count if that fails), lowered to ceil(quota / period) when
 * the process's cgroup v2 cpu.max sets a quota. At least 1. */
unsigned srv_usable_cpus(void);

/* ceil(quota / period) for the text of a cgroup v2 cpu.max file ("max
 * 100000" or "150000 100000"), or 0 when it sets no quota or cannot be
 * read. Exposed for tests. */
unsigned srv_cpu_max_quota(const char *text);

#endif
