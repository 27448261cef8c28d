/* healthcheck.c - the daemon as its own health probe: one HTTP GET over a
 * TCP socket, the exit status from the status line.
 *
 * DESIGN: a container image would otherwise need curl or wget only to ask
 * /healthz; the daemon already links everything it takes, and the probe
 * is a few system calls. It speaks just enough HTTP/1.1 for that: one
 * request with Connection: close, the status line read back, nothing
 * else parsed. Every step is bounded by one deadline, so a daemon that
 * accepts but never answers fails the check instead of hanging it.
 */
#include "healthcheck.h"

#include <errno.h>
#include <netdb.h>
#include <poll.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/types.h>
#include <time.h>
#include <unistd.h>

#include <fcntl.h>

typedef struct {
  char host[256];
  char port[8];
  char path[1024];
} hc_url;

bool srv_healthcheck_requested(const char *arg) {
  return strcmp(arg, "--healthcheck") == 0 ||
         strncmp(arg, "--healthcheck=", 14) == 0;
}

/* http://host[:port][/path] into u; 0, or -1 with a reason on err. */
static int parse_url(const char *url, hc_url *u, FILE *err) {
  static const char scheme[] = "http://";
  if (strncmp(url, scheme, sizeof scheme - 1) != 0) {
    fprintf(err, "kmorphd: --healthcheck: \"%s\" is not an http:// URL\n", url);
    return -1;
  }
  const char *p = url + sizeof scheme - 1;
  const char *host_end;
  const char *after;
  if (*p == '[') {
    host_end = strchr(p, ']');
    if (host_end == NULL) goto bad_host;
    p++;
    after = host_end + 1;
  } else {
    host_end = p + strcspn(p, ":/?#");
    after = host_end;
  }
  size_t hlen = (size_t)(host_end - p);
  if (hlen == 0 || hlen >= sizeof u->host) goto bad_host;
  memcpy(u->host, p, hlen);
  u->host[hlen] = '\0';
  snprintf(u->port, sizeof u->port, "80");
  if (*after == ':') {
    const char *digits = after + 1;
    size_t dlen = strspn(digits, "0123456789");
    long port = dlen > 0 && dlen < 6 ? strtol(digits, NULL, 10) : 0;
    if (port < 1 || port > 65535 ||
        (digits[dlen] != '\0' && digits[dlen] != '/')) {
      fprintf(err, "kmorphd: --healthcheck: bad port in \"%s\"\n", url);
      return -1;
    }
    snprintf(u->port, sizeof u->port, "%ld", port);
    after = digits + dlen;
  }
  if (*after != '\0' && *after != '/') goto bad_host;
  const char *path = *after == '/' ? after : "/";
  if (strlen(path) >= sizeof u->path || strpbrk(path, " \r\n") != NULL) {
    fprintf(err, "kmorphd: --healthcheck: bad path in \"%s\"\n", url);
    return -1;
  }
  snprintf(u->path, sizeof u->path, "%s", path);
  return 0;
bad_host:
  fprintf(err, "kmorphd: --healthcheck: bad host in \"%s\"\n", url);
  return -1;
}

static double now_seconds(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + (double)ts.tv_nsec / 1e9;
}

/* Wait until fd is ready for events or the deadline passes; 1 ready, 0
 * not (timed out or failed). */
static int wait_fd(int fd, short events, double deadline) {
  for (;;) {
    double left = deadline - now_seconds();
    if (left <= 0) return 0;
    struct pollfd pfd = {.fd = fd, .events = events, .revents = 0};
    int rc = poll(&pfd, 1, (int)(left * 1000.0) + 1);
    if (rc > 0) return 1;
    if (rc == 0) return 0;
    if (errno != EINTR) return 0;
  }
}

/* A connected non-blocking socket to one of the addresses, or -1. */
static int connect_any(const struct addrinfo *ai, double deadline) {
  for (; ai != NULL; ai = ai->ai_next) {
    int fd = socket(ai->ai_family, ai->ai_socktype, ai->ai_protocol);
    if (fd < 0) continue;
    int flags = fcntl(fd, F_GETFL);
    if (flags >= 0) fcntl(fd, F_SETFL, flags | O_NONBLOCK);
    int soerr = 0;
    socklen_t len = sizeof soerr;
    if (connect(fd, ai->ai_addr, ai->ai_addrlen) == 0 ||
        (errno == EINPROGRESS && wait_fd(fd, POLLOUT, deadline) &&
         getsockopt(fd, SOL_SOCKET, SO_ERROR, &soerr, &len) == 0 && soerr == 0))
      return fd;
    close(fd);
  }
  return -1;
}

static int send_all(int fd, const char *buf, size_t len, double deadline) {
  while (len > 0) {
    ssize_t n = send(fd, buf, len, MSG_NOSIGNAL);
    if (n > 0) {
      buf += n;
      len -= (size_t)n;
    } else if (n < 0 && (errno == EAGAIN || errno == EINTR)) {
      if (!wait_fd(fd, POLLOUT, deadline)) return -1;
    } else {
      return -1;
    }
  }
  return 0;
}

/* The status code of the answer's first line, or -1. */
static int read_status(int fd, double deadline) {
  char line[128];
  size_t got = 0;
  while (got < sizeof line - 1 && memchr(line, '\n', got) == NULL) {
    ssize_t n = recv(fd, line + got, sizeof line - 1 - got, 0);
    if (n > 0) {
      got += (size_t)n;
    } else if (n < 0 && (errno == EAGAIN || errno == EINTR)) {
      if (!wait_fd(fd, POLLIN, deadline)) return -1;
    } else {
      break;
    }
  }
  line[got] = '\0';
  /* "HTTP/1.x NNN reason" */
  if (strncmp(line, "HTTP/1.", 7) != 0 || line[8] != ' ') return -1;
  const char *code = line + 9;
  if (strspn(code, "0123456789") != 3 ||
      (code[3] != ' ' && code[3] != '\r' && code[3] != '\n'))
    return -1;
  return (int)strtol(code, NULL, 10);
}

static int check(const hc_url *u, FILE *err) {
  double deadline = now_seconds() + SRV_HEALTHCHECK_SECONDS;
  struct addrinfo hints;
  memset(&hints, 0, sizeof hints);
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  struct addrinfo *ai = NULL;
  int gai = getaddrinfo(u->host, u->port, &hints, &ai);
  if (gai != 0) {
    fprintf(err, "kmorphd: --healthcheck: %s: %s\n", u->host,
            gai_strerror(gai));
    return 1;
  }
  int fd = connect_any(ai, deadline);
  freeaddrinfo(ai);
  if (fd < 0) {
    fprintf(err, "kmorphd: --healthcheck: cannot connect to %s port %s\n",
            u->host, u->port);
    return 1;
  }
  char req[1400];
  bool v6 = strchr(u->host, ':') != NULL;
  int len = snprintf(req, sizeof req,
                     "GET %s HTTP/1.1\r\nHost: %s%s%s:%s\r\n"
                     "User-Agent: kmorphd-healthcheck\r\n"
                     "Connection: close\r\n\r\n",
                     u->path, v6 ? "[" : "", u->host, v6 ? "]" : "", u->port);
  int status = -1;
  if (len > 0 && (size_t)len < sizeof req &&
      send_all(fd, req, (size_t)len, deadline) == 0)
    status = read_status(fd, deadline);
  close(fd);
  if (status == 200) return 0;
  if (status < 0)
    fprintf(err, "kmorphd: --healthcheck: no HTTP answer within %d s\n",
            SRV_HEALTHCHECK_SECONDS);
  else
    fprintf(err, "kmorphd: --healthcheck: status %d\n", status);
  return 1;
}

int srv_healthcheck_main(int argc, char **argv, FILE *err) {
  const char *url = NULL;
  if (strncmp(argv[1], "--healthcheck=", 14) == 0 && argc == 2)
    url = argv[1] + 14;
  else if (strcmp(argv[1], "--healthcheck") == 0 && argc == 3)
    url = argv[2];
  if (url == NULL) {
    fprintf(err, "kmorphd: usage: kmorphd --healthcheck URL\n");
    return 2;
  }
  hc_url u;
  if (parse_url(url, &u, err) != 0) return 2;
  return check(&u, err);
}
