/* process_metrics.h - the standard process_* metrics of Prometheus'
 * client libraries, read from /proc/self: CPU seconds, resident memory,
 * open and maximum file descriptors, start time.
 *
 * Thread-safety: reads the kernel's files only; any thread.
 */
#ifndef SRV_PROCESS_METRICS_H
#define SRV_PROCESS_METRICS_H

#include <stddef.h>

/* Append the process_* families as Prometheus text to out (NUL-ended,
 * at most cap bytes with the NUL). A value that cannot be read is left
 * out with its family. Returns the length written. */
size_t srv_process_metrics(char *out, size_t cap);

#endif
