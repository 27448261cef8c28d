/* log.h - kmorphd's log: one stream, reopened on SIGHUP, with a rate limit
 * for messages that repeat.
 *
 * The stream is always stderr. With a log file, the file's descriptor is
 * placed on stderr's, so every writer (the access log, libmicrohttpd's
 * messages, the job notices, a sanitizer's report) lands in the file, and
 * a reopen swaps the descriptor under stderr's lock: the FILE that the
 * rest of the daemon holds never changes, and no line is split between
 * the old file and the new one.
 */
#ifndef SRV_LOG_H
#define SRV_LOG_H

#include <stdbool.h>
#include <stdio.h>

typedef struct srv_log srv_log;

/* Most kinds of message rate-limited at a time (srv_log_admit): more
 * kinds than this share slots, the least recently seen giving way. */
#define SRV_LOG_KINDS 16

/* Seconds between two lines of one kind: at most one a second, so a
 * flood (accept failing with EMFILE in a loop) costs a line a second,
 * not the disk. */
#define SRV_LOG_INTERVAL 1.0

/* Open the log. path "" (or NULL) keeps stderr as it is; otherwise the
 * file is opened for appending (created 0640 if missing) and takes
 * stderr's place. Returns the log (free with srv_log_close), or NULL with
 * a message on err when the file cannot be opened or memory is short.
 * Call before any thread starts: it changes descriptor 2. */
srv_log *srv_log_open(const char *path, FILE *err);

/* The stream to write to: stderr, the same FILE for the log's whole
 * life (across reopens). fprintf on it is thread-safe (stdio locks it
 * per call). */
FILE *srv_log_stream(const srv_log *l);

/* The log file's path, or "" when the log is stderr as given. */
const char *srv_log_path(const srv_log *l);

/* Reopen the log file at its path (after logrotate moved it away): the
 * new file receives every later line. Returns 1 when the file was
 * reopened, 0 when there is no log file (stderr is the caller's), or -1
 * with errno set when the path cannot be opened (the old file is kept).
 * Thread-safe: concurrent writers are held off for the swap alone. */
int srv_log_reopen(srv_log *l);

/* printf one notice line (the caller supplies the newline) to the log,
 * as srv_log_notice does. */
void srv_log_printf(srv_log *l, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

/* The shape of log lines: "key=value" text (the default) or one JSON
 * object per line (--log-format=json, for log shippers). */
typedef enum srv_log_format { SRV_LOG_KV, SRV_LOG_JSON } srv_log_format;

/* Choose the shape of every log line of the process. The log is the
 * process's stderr, so its shape is the process's too: call once at
 * start-up, before any thread starts (threads only read it). */
void srv_log_set_format(srv_log_format f);

/* True when lines are JSON objects (for writers of structured lines: the
 * access log). */
bool srv_log_json(void);

/* Write one notice (fmt formats a line ending in a newline, starting
 * "kmorphd: " by custom) to f: as it is, or as {"time": ..., "level":
 * "notice", "msg": ...} with the message JSON-escaped and the prefix and
 * newline dropped. One fprintf, so lines from threads never interleave. */
void srv_log_notice(FILE *f, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

/* The current UTC time as RFC 3339 ("2026-12-04T16:41:15Z") into out
 * (at least 21 bytes). */
void srv_log_time(char *out, size_t cap);

/* Rate limit: may a message of this kind be written now? kind is any
 * stable pointer naming the kind (a format string). At most one message
 * of a kind is admitted per SRV_LOG_INTERVAL; the others are counted.
 * When one is admitted, *suppressed receives how many of its kind were
 * dropped since the last admitted one (0 usually), for the caller to
 * say so on the line. sample (may be NULL) is kept to name the kind in
 * srv_log_close's summary. Thread-safe. */
bool srv_log_admit(srv_log *l, const void *kind, const char *sample,
                   unsigned long *suppressed);

/* Write a line for each kind with messages still suppressed, flush and
 * free. The file stays on stderr until the process exits, so that late
 * writers (a sanitizer's leak report) still reach it. Accepts NULL. */
void srv_log_close(srv_log *l);

#endif
