/* front.c - accept, frame and relay connections to libmicrohttpd (see
 * front.h). */
#define _GNU_SOURCE /* accept4 */
#include "front.h"

#include <arpa/inet.h>
#include <errno.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/epoll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include "framing.h"
#include "util.h"

/* Client-to-server buffer: a held header block and the line after it. */
#define IN_CAP (SRV_FRAMING_HEAD_MAX + 8192)
/* Server-to-client buffer; the socket pair's own buffer is larger. */
#define OUT_CAP 16384

/* Seconds a client may go on sending after the front closed its sending
 * side: what it sends is read and dropped, so that unread input does not
 * turn the close into a reset that destroys the answer in flight. */
static const double LINGER_TIME = 2.0;
/* Bytes read and dropped while lingering before the front gives up. */
static const size_t LINGER_BYTES = 1 << 20;
/* Seconds accepting pauses when descriptors ran out (nginx: 500 ms). */
static const double ACCEPT_PAUSE = 0.25;
/* Seconds the threads look at deadlines when nothing happens. */
static const int TICK_MS = 250;
/* Seconds to flush answers to clients once libmicrohttpd stopped. */
static const double STOP_FLUSH = 1.0;

/* epoll data: a connection's address, its low bit telling the pair end
 * from the client; 0 is the listening socket, 2 the wake-up eventfd. */
enum { TAG_PAIR = 1, TAG_LISTEN = 0, TAG_WAKE = 2 };

typedef struct relay relay;

typedef struct conn {
  struct conn *prev, *next;
  int client;             /* the accepted socket */
  int pair;               /* our end of the socket pair, -1 once closed */
  uint32_t client_events; /* registered for client */
  uint32_t pair_events;   /* registered for pair (0: not in the set) */
  srv_framing fr;         /* the client's requests so far */
  srv_framing_buf in;     /* client bytes: [sent, in.safe) to forward */
  size_t sent;            /* of in, written to the pair */
  char *out;              /* server bytes to the client */
  size_t out_len, out_sent;
  bool client_eof;   /* the client's FIN was read */
  bool pair_shut;    /* the pair was told end of input */
  bool client_ready; /* the client may have bytes to read (an event
                      * came and no short read since) */
  bool pair_ready;   /* the same for the pair */
  bool pair_refuses; /* a write to the pair failed: the server closed;
                      * what it wrote before is still to be read */
  bool pair_hup;     /* the server closed its end while out was full */
  bool answered;     /* the refusal was put into out, or is the
                        * server's to answer (srv_framing_ending) */
  bool ended;        /* the ending of a refused body was prepared */
  char ending[320];  /* its bytes, to the pair after in's safe part */
  size_t ending_len, ending_sent;
  bool wrote;      /* bytes went to the client */
  bool lingering;  /* our FIN is out; reading and dropping */
  size_t dropped;  /* bytes dropped while lingering */
  double deadline; /* lingering or draining ends: 0 = none */
  bool dead;       /* closed, freed after the current batch */
  char peer[48];   /* the client's address, for the log */
} conn;

struct relay {
  srv_front *f;
  int ep;
  int wake;
  pthread_t thread;
  bool started;
  conn *first; /* open connections */
  conn *dead;  /* closed, to free after the batch */
  size_t count;
  bool listening;     /* the listening socket is in this epoll set */
  double pause_until; /* accepting pauses until then (out of fds) */
};

struct srv_front {
  srv_front_options opt;
  int listen_fd;
  unsigned port;
  struct MHD_Daemon *daemon;
  relay *relays;
  unsigned nrelays;
  atomic_uint open;     /* connections relayed now */
  atomic_bool draining; /* stop accepting */
  atomic_bool stopping; /* close everything and leave */
  atomic_ulong refused; /* requests answered by the front */
  double stop_deadline; /* written before stopping is set */
};

/* ------------------------------------------------------------ epoll */

static void set_events(relay *r, int fd, uint32_t *cur, uint32_t want,
                       uint64_t tag, bool keep) {
  if (want == *cur && (want != 0 || keep)) return;
  struct epoll_event ev = {.events = want, .data.u64 = tag};
  int op = *cur == 0 && !keep ? EPOLL_CTL_ADD : EPOLL_CTL_MOD;
  if (want == 0 && !keep)
    epoll_ctl(r->ep, EPOLL_CTL_DEL, fd, NULL);
  else
    epoll_ctl(r->ep, op, fd, &ev);
  *cur = want;
}

/* What each end waits for, from the state of the buffers. The client
 * stays in the set with no events so that its reset (EPOLLERR/HUP, always
 * reported) is seen at once: the server's client-gone check relies on it.
 * The pair leaves the set when nothing is wanted, as its end of file
 * would otherwise be reported again and again. */
static void arm(relay *r, conn *c) {
  uint32_t want = 0;
  bool in_room = c->in.len < IN_CAP || c->sent > 0;
  if (c->lingering || (!c->client_eof && c->fr.status == 0 && in_room &&
                       c->pair >= 0 && !c->pair_refuses))
    want |= EPOLLIN;
  if (c->out_sent < c->out_len) want |= EPOLLOUT;
  set_events(r, c->client, &c->client_events, want, (uint64_t)(uintptr_t)c,
             true);
  if (c->pair < 0) return;
  want = 0;
  if (!c->pair_hup && (c->out_len < OUT_CAP || c->out_sent == c->out_len))
    want |= EPOLLIN;
  if (!c->pair_refuses &&
      (c->sent < c->in.safe || c->ending_sent < c->ending_len))
    want |= EPOLLOUT;
  set_events(r, c->pair, &c->pair_events, want,
             (uint64_t)(uintptr_t)c | TAG_PAIR, false);
}

/* ------------------------------------------------------ connections */

/* Close both sockets and set c aside: an event for its other end may
 * still be in the batch being served, so the memory goes after it. */
static void conn_free(relay *r, conn *c) {
  if (c->prev)
    c->prev->next = c->next;
  else
    r->first = c->next;
  if (c->next) c->next->prev = c->prev;
  r->count--;
  epoll_ctl(r->ep, EPOLL_CTL_DEL, c->client, NULL);
  close(c->client);
  if (c->pair >= 0) close(c->pair);
  c->pair = -1;
  c->dead = true;
  c->next = r->dead;
  r->dead = c;
  if (!c->lingering) atomic_fetch_sub(&r->f->open, 1);
}

static void reap(relay *r) {
  while (r->dead) {
    conn *c = r->dead;
    r->dead = c->next;
    free(c->in.data);
    free(c->out);
    free(c);
  }
}

static void close_pair(relay *r, conn *c) {
  if (c->pair < 0) return;
  if (c->pair_events != 0) epoll_ctl(r->ep, EPOLL_CTL_DEL, c->pair, NULL);
  c->pair_events = 0;
  close(c->pair);
  c->pair = -1;
}

static bool would_block(void) {
  return errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR;
}

/* The answer to a request the parser refused, after what the server
 * wrote for the requests before it. */
static void queue_refusal(relay *r, conn *c) {
  const srv_framing *fr = &c->fr;
  const char *type = fr->status == 501   ? "/problems/not-implemented"
                     : fr->status == 431 ? "/problems/header-too-large"
                                         : "/problems/bad-request";
  const char *title = fr->status == 501   ? "Not implemented"
                      : fr->status == 431 ? "Request header too large"
                                          : "Bad request";
  const char *reason = fr->status == 501   ? "Not Implemented"
                       : fr->status == 431 ? "Request Header Fields Too Large"
                                           : "Bad Request";
  char detail[2 * sizeof fr->detail];
  srv_json_escape(detail, sizeof detail, fr->detail);
  char rid[17];
  srv_random_hex(rid, 16);
  char body[1024];
  int bn = snprintf(body, sizeof body,
                    "{\"type\":\"%s\",\"title\":\"%s\",\"status\":%d,"
                    "\"detail\":\"%s\",\"request_id\":\"%s\","
                    "\"instance\":\"urn:kmorph:request:%s\"}",
                    type, title, fr->status, detail, rid, rid);
  if (bn < 0 || (size_t)bn >= sizeof body) bn = (int)strlen(body);
  char date[64], when[32];
  time_t now = time(NULL);
  struct tm tm;
  gmtime_r(&now, &tm);
  strftime(date, sizeof date, "%a, %d %b %Y %H:%M:%S GMT", &tm);
  strftime(when, sizeof when, "%Y-%m-%dT%H:%M:%SZ", &tm);
  if (c->out == NULL) c->out = malloc(OUT_CAP);
  int n = c->out == NULL ? -1
                         : snprintf(c->out, OUT_CAP,
                                    "HTTP/1.1 %d %s\r\n"
                                    "Date: %s\r\n"
                                    "Content-Type: application/problem+json\r\n"
                                    "Connection: close\r\n"
                                    "Cache-Control: no-store\r\n"
                                    "X-Request-Id: %s\r\n"
                                    "Content-Length: %d\r\n"
                                    "\r\n%s",
                                    fr->status, reason, date, rid, bn, body);
  c->out_len = n > 0 && n < OUT_CAP ? (size_t)n : 0;
  c->out_sent = 0;
  c->answered = true;
  atomic_fetch_add(&r->f->refused, 1);
  if (r->f->opt.access_log && srv_log_json())
    fprintf(r->f->opt.log,
            "{\"time\":\"%s\",\"event\":\"access\",\"refused_framing\":"
            "true,\"status\":%d,\"peer\":\"%s\",\"request_id\":\"%s\","
            "\"detail\":\"%s\"}\n",
            when, fr->status, c->peer, rid, detail);
  else if (r->f->opt.access_log)
    fprintf(r->f->opt.log,
            "%s access refused_framing status=%d peer=%s request_id=%s "
            "detail=\"%s\"\n",
            when, fr->status, c->peer, rid, detail);
}

/* Client to the front: returns false if the connection is gone. */
static bool client_in(relay *r, conn *c, bool *moved) {
  char drop[4096];
  if (c->lingering) {
    ssize_t n = recv(c->client, drop, sizeof drop, MSG_DONTWAIT);
    if (n > 0) c->dropped += (size_t)n;
    if (n == 0 || (n < 0 && !would_block()) || c->dropped > LINGER_BYTES) {
      conn_free(r, c);
      return false;
    }
    return true;
  }
  if (c->client_eof || c->fr.status != 0 || c->pair < 0 || c->pair_refuses)
    return true;
  if (c->sent > 0 && (c->sent == c->in.len || c->in.len == IN_CAP)) {
    /* Move what is not yet written down to the buffer's start. */
    memmove(c->in.data, c->in.data + c->sent, c->in.len - c->sent);
    c->in.len -= c->sent;
    c->in.pos -= c->sent;
    c->in.safe -= c->sent;
    c->sent = 0;
  }
  if (c->in.len == IN_CAP || !c->client_ready) return true;
  if (c->in.data == NULL && (c->in.data = malloc(IN_CAP)) == NULL) {
    conn_free(r, c);
    return false;
  }
  size_t want = IN_CAP - c->in.len;
  ssize_t n = recv(c->client, c->in.data + c->in.len, want, MSG_DONTWAIT);
  /* A short read took all there was: the next waits for an event. */
  if (n < 0 || (size_t)n < want) c->client_ready = false;
  if (n > 0) {
    c->in.len += (size_t)n;
    srv_framing_scan(&c->fr, &c->in);
    *moved = true;
  } else if (n == 0) {
    c->client_eof = true;
    *moved = true;
  } else if (!would_block()) {
    conn_free(r, c);
    return false;
  }
  return true;
}

/* The front to the server, and the server's end of input once no more
 * will come (the client's FIN, or a refused request). */
static void pair_out(relay *r, conn *c, bool *moved) {
  if (c->pair < 0 || c->pair_refuses) return;
  if (c->sent < c->in.safe) {
    ssize_t n = send(c->pair, c->in.data + c->sent, c->in.safe - c->sent,
                     MSG_DONTWAIT | MSG_NOSIGNAL);
    if (n > 0) {
      c->sent += (size_t)n;
      *moved = true;
    } else if (n < 0 && !would_block()) {
      c->pair_refuses = true;
      *moved = true;
      return;
    }
  }
  if (c->fr.status != 0 && c->sent == c->in.safe && !c->ended) {
    c->ended = true;
    c->ending_len = srv_framing_ending(&c->fr, c->ending, sizeof c->ending);
    if (c->ending_len > 0) {
      c->answered = true; /* by the server, in the requests' order */
      atomic_fetch_add(&r->f->refused, 1);
    }
  }
  if (c->ending_sent < c->ending_len) {
    ssize_t n =
        send(c->pair, c->ending + c->ending_sent,
             c->ending_len - c->ending_sent, MSG_DONTWAIT | MSG_NOSIGNAL);
    if (n > 0) {
      c->ending_sent += (size_t)n;
      *moved = true;
    } else if (n < 0 && !would_block()) {
      c->pair_refuses = true;
      *moved = true;
      return;
    }
    if (c->ending_sent < c->ending_len) return;
  }
  if (!c->pair_shut && c->sent == c->in.safe &&
      (c->client_eof || c->fr.status != 0)) {
    shutdown(c->pair, SHUT_WR);
    c->pair_shut = true;
  }
}

/* The server to the front; its end of file closes the pair. Returns
 * false if the connection is gone. */
static bool pair_in(relay *r, conn *c, bool *moved) {
  if (c->pair < 0) return true;
  if (c->out_sent == c->out_len) c->out_len = c->out_sent = 0;
  if (c->out_len == OUT_CAP || !c->pair_ready) return true;
  if (c->out == NULL && (c->out = malloc(OUT_CAP)) == NULL) {
    conn_free(r, c);
    return false;
  }
  size_t want = OUT_CAP - c->out_len;
  ssize_t n = recv(c->pair, c->out + c->out_len, want, MSG_DONTWAIT);
  if (n < 0 || (size_t)n < want) c->pair_ready = false;
  if (n > 0) {
    c->out_len += (size_t)n;
    *moved = true;
  } else if (n == 0 || !would_block()) {
    close_pair(r, c);
    *moved = true;
  }
  return true;
}

/* The front to the client: returns false if the connection is gone. */
static bool client_out(relay *r, conn *c, bool *moved) {
  if (c->out_sent == c->out_len) return true;
  ssize_t n = send(c->client, c->out + c->out_sent, c->out_len - c->out_sent,
                   MSG_DONTWAIT | MSG_NOSIGNAL);
  if (n > 0) {
    c->out_sent += (size_t)n;
    c->wrote = true;
    *moved = true;
  } else if (n < 0 && !would_block()) {
    conn_free(r, c);
    return false;
  }
  return true;
}

/* The server closed and everything it wrote reached the client: the
 * refusal, if any, then our FIN. Returns false if the connection is gone. */
static bool finish(relay *r, conn *c) {
  if (c->pair >= 0 || c->out_sent < c->out_len || c->lingering) return true;
  if (c->fr.status != 0 && !c->answered) {
    queue_refusal(r, c);
    return true;
  }
  /* Nothing was ever written (the server refused the connection at its
   * limits) or the client sends no more: close at once. */
  if (c->client_eof || !c->wrote) {
    conn_free(r, c);
    return false;
  }
  shutdown(c->client, SHUT_WR);
  c->lingering = true;
  c->deadline = srv_now() + LINGER_TIME;
  /* A lingering client holds no server slot. */
  atomic_fetch_sub(&r->f->open, 1);
  return true;
}

/* Buffers are held only while bytes pass: an idle kept-alive connection
 * (thousands may be open) holds none. */
static void release_idle_buffers(conn *c) {
  if (c->in.data != NULL && c->sent == c->in.len && srv_framing_idle(&c->fr)) {
    free(c->in.data);
    c->in.data = NULL;
    c->in.len = c->in.pos = c->in.safe = c->sent = 0;
  }
  if (c->out != NULL && c->out_sent == c->out_len && c->in.data == NULL) {
    free(c->out);
    c->out = NULL;
    c->out_len = c->out_sent = 0;
  }
}

/* Move bytes until nothing moves, then wait for what is missing. */
static void pump(relay *r, conn *c) {
  for (int round = 0; round < 8; round++) {
    bool moved = false;
    if (!client_in(r, c, &moved)) return;
    pair_out(r, c, &moved);
    if (!pair_in(r, c, &moved)) return;
    if (!client_out(r, c, &moved)) return;
    if (!finish(r, c)) return;
    if (!moved) break;
  }
  release_idle_buffers(c);
  arm(r, c);
}

static void on_conn_event(relay *r, conn *c, bool pair_end, uint32_t ev) {
  if (ev & (EPOLLIN | EPOLLHUP | EPOLLERR)) {
    if (pair_end)
      c->pair_ready = true;
    else
      c->client_ready = true;
  }
  if (!pair_end && (ev & (EPOLLERR | EPOLLHUP))) {
    /* A reset, or both directions shut: nothing more can be delivered. */
    conn_free(r, c);
    return;
  }
  if (pair_end && (ev & EPOLLHUP) && c->out_len == OUT_CAP &&
      c->out_sent < c->out_len && !c->pair_hup) {
    /* The server is gone while the client is slow to read what it
     * wrote: the rest stays readable in the pair; the client has the
     * drain time to take it. */
    c->pair_hup = true;
    c->deadline = srv_now() + r->f->opt.drain_time;
  }
  pump(r, c);
}

/* ---------------------------------------------------------- accept */

static void pause_accepting(relay *r, const char *why) {
  static const char KIND[] = "front accept";
  unsigned long more = 0;
  if (srv_log_admit(r->f->opt.logger, KIND, why, &more))
    srv_log_notice(
        r->f->opt.log,
        "kmorphd: accept failed: %s; pausing %g s (%lu more suppressed)\n", why,
        ACCEPT_PAUSE, more);
  r->pause_until = srv_now() + ACCEPT_PAUSE;
}

static void peer_text(const struct sockaddr_storage *ss, char *out, size_t n) {
  out[0] = '\0';
  if (ss->ss_family == AF_INET)
    inet_ntop(AF_INET, &((const struct sockaddr_in *)ss)->sin_addr, out,
              (socklen_t)n);
  else if (ss->ss_family == AF_INET6)
    inet_ntop(AF_INET6, &((const struct sockaddr_in6 *)ss)->sin6_addr, out,
              (socklen_t)n);
}

/* One accepted client: its socket pair, its record, the server's end
 * handed to libmicrohttpd with the client's address. */
static void adopt(relay *r, int fd, const struct sockaddr_storage *ss,
                  socklen_t len) {
  int sv[2];
  if (socketpair(AF_UNIX, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0, sv) !=
      0) {
    close(fd);
    pause_accepting(r, strerror(errno));
    return;
  }
  conn *c = calloc(1, sizeof *c);
  if (c == NULL) {
    close(fd);
    close(sv[0]);
    close(sv[1]);
    return;
  }
  int one = 1;
  setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
  c->client = fd;
  c->pair = sv[0];
  srv_framing_init(&c->fr);
  peer_text(ss, c->peer, sizeof c->peer);
  c->next = r->first;
  if (r->first) r->first->prev = c;
  r->first = c;
  r->count++;
  atomic_fetch_add(&r->f->open, 1);
  /* The client is in the set for its life (arm only modifies it). */
  struct epoll_event ev = {.events = EPOLLIN, .data.u64 = (uintptr_t)c};
  epoll_ctl(r->ep, EPOLL_CTL_ADD, fd, &ev);
  c->client_events = EPOLLIN;
  arm(r, c);
  /* libmicrohttpd owns sv[1] from here, closing it itself if it refuses
   * the connection (its limits): the pair then reads end of file. */
  MHD_add_connection(r->f->daemon, sv[1], (const struct sockaddr *)ss, len);
}

static void accept_some(relay *r) {
  srv_front *f = r->f;
  for (int i = 0; i < 64; i++) {
    if (atomic_load(&f->open) >= f->opt.max_connections) return;
    struct sockaddr_storage ss;
    socklen_t len = sizeof ss;
    int fd = accept4(f->listen_fd, (struct sockaddr *)&ss, &len,
                     SOCK_NONBLOCK | SOCK_CLOEXEC);
    if (fd >= 0) {
      adopt(r, fd, &ss, len);
      continue;
    }
    if (errno == EINTR || errno == ECONNABORTED) continue;
    if (errno == EMFILE || errno == ENFILE || errno == ENOBUFS ||
        errno == ENOMEM)
      pause_accepting(r, strerror(errno));
    return; /* EAGAIN, or the socket was shut (draining) */
  }
}

/* The listening socket is in this thread's set while accepting is
 * wanted: not draining, under the limit, not pausing. */
static void arm_listen(relay *r, double now) {
  srv_front *f = r->f;
  bool want = !atomic_load(&f->draining) &&
              atomic_load(&f->open) < f->opt.max_connections &&
              now >= r->pause_until;
  if (want == r->listening) return;
  if (want) {
    struct epoll_event ev = {.events = EPOLLIN | EPOLLEXCLUSIVE,
                             .data.u64 = TAG_LISTEN};
    epoll_ctl(r->ep, EPOLL_CTL_ADD, f->listen_fd, &ev);
  } else {
    epoll_ctl(r->ep, EPOLL_CTL_DEL, f->listen_fd, NULL);
  }
  r->listening = want;
}

/* ------------------------------------------------------------ thread */

static void sweep_deadlines(relay *r, double now) {
  conn *c = r->first;
  while (c) {
    conn *next = c->next;
    if (c->deadline != 0 && now >= c->deadline) conn_free(r, c);
    c = next;
  }
}

static void *relay_main(void *arg) {
  relay *r = arg;
  srv_front *f = r->f;
  struct epoll_event evs[64];
  double next_sweep = srv_now();
  for (;;) {
    double now = srv_now();
    if (atomic_load(&f->stopping) && (r->count == 0 || now >= f->stop_deadline))
      break;
    arm_listen(r, now);
    int n = epoll_wait(r->ep, evs, 64, TICK_MS);
    for (int i = 0; i < n; i++) {
      uint64_t tag = evs[i].data.u64;
      if (tag == TAG_LISTEN) {
        accept_some(r);
      } else if (tag == TAG_WAKE) {
        uint64_t v;
        ssize_t k = read(r->wake, &v, sizeof v);
        (void)k;
      } else {
        conn *c = (conn *)(uintptr_t)(tag & ~(uint64_t)TAG_PAIR);
        if (!c->dead) on_conn_event(r, c, (tag & TAG_PAIR) != 0, evs[i].events);
      }
    }
    reap(r);
    now = srv_now();
    if (now >= next_sweep) {
      sweep_deadlines(r, now);
      reap(r);
      next_sweep = now + TICK_MS / 1000.0;
    }
  }
  while (r->first) conn_free(r, r->first);
  reap(r);
  return NULL;
}

/* ------------------------------------------------------- life cycle */

static int bind_listen(srv_front *f) {
  struct sockaddr_storage ss;
  memset(&ss, 0, sizeof ss);
  socklen_t len;
  struct sockaddr_in *v4 = (struct sockaddr_in *)&ss;
  struct sockaddr_in6 *v6 = (struct sockaddr_in6 *)&ss;
  if (inet_pton(AF_INET, f->opt.bind, &v4->sin_addr) == 1) {
    v4->sin_family = AF_INET;
    v4->sin_port = htons((uint16_t)f->opt.port);
    len = sizeof *v4;
  } else if (inet_pton(AF_INET6, f->opt.bind, &v6->sin6_addr) == 1) {
    v6->sin6_family = AF_INET6;
    v6->sin6_port = htons((uint16_t)f->opt.port);
    len = sizeof *v6;
  } else {
    srv_log_notice(f->opt.log,
                   "kmorphd: --bind \"%s\" is not an IPv4 or IPv6 "
                   "address\n",
                   f->opt.bind);
    return -1;
  }
  int fd = socket(ss.ss_family, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  int one = 1;
  if (fd >= 0) setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  if (fd >= 0 && ss.ss_family == AF_INET6)
    setsockopt(fd, IPPROTO_IPV6, IPV6_V6ONLY, &one, sizeof one);
  if (fd < 0 || bind(fd, (struct sockaddr *)&ss, len) != 0 ||
      listen(fd, 511) != 0) {
    srv_log_notice(f->opt.log, "kmorphd: cannot listen on %s port %u (%s)\n",
                   f->opt.bind, f->opt.port, strerror(errno));
    if (fd >= 0) close(fd);
    return -1;
  }
  len = sizeof ss;
  getsockname(fd, (struct sockaddr *)&ss, &len);
  f->port = ntohs(ss.ss_family == AF_INET ? v4->sin_port : v6->sin6_port);
  f->listen_fd = fd;
  return 0;
}

srv_front *srv_front_listen(const srv_front_options *o) {
  srv_front *f = calloc(1, sizeof *f);
  if (f == NULL) return NULL;
  f->opt = *o;
  if (f->opt.threads == 0) f->opt.threads = 1;
  f->listen_fd = -1;
  atomic_init(&f->open, 0);
  atomic_init(&f->draining, false);
  atomic_init(&f->stopping, false);
  atomic_init(&f->refused, 0);
  f->relays = calloc(f->opt.threads, sizeof *f->relays);
  if (f->relays == NULL || bind_listen(f) != 0) {
    srv_front_destroy(f);
    return NULL;
  }
  return f;
}

unsigned srv_front_port(const srv_front *f) {
  return f->port;
}

int srv_front_start(srv_front *f, struct MHD_Daemon *d) {
  f->daemon = d;
  for (unsigned i = 0; i < f->opt.threads; i++) {
    relay *r = &f->relays[i];
    r->f = f;
    r->ep = epoll_create1(EPOLL_CLOEXEC);
    r->wake = eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
    if (r->ep < 0 || r->wake < 0) {
      srv_log_notice(f->opt.log,
                     "kmorphd: cannot create the relay's epoll set (%s)\n",
                     strerror(errno));
      return -1;
    }
    struct epoll_event ev = {.events = EPOLLIN, .data.u64 = TAG_WAKE};
    epoll_ctl(r->ep, EPOLL_CTL_ADD, r->wake, &ev);
    if (pthread_create(&r->thread, NULL, relay_main, r) != 0) {
      srv_log_notice(f->opt.log, "kmorphd: cannot start a relay thread\n");
      return -1;
    }
    r->started = true;
    f->nrelays = i + 1;
  }
  return 0;
}

static void wake_all(srv_front *f) {
  uint64_t one = 1;
  for (unsigned i = 0; i < f->nrelays; i++) {
    ssize_t k = write(f->relays[i].wake, &one, sizeof one);
    (void)k;
  }
}

void srv_front_stop_listening(srv_front *f) {
  if (f == NULL || atomic_exchange(&f->draining, true)) return;
  /* Out of every set first: a shut listening socket is always readable. */
  for (unsigned i = 0; i < f->nrelays; i++)
    epoll_ctl(f->relays[i].ep, EPOLL_CTL_DEL, f->listen_fd, NULL);
  shutdown(f->listen_fd, SHUT_RDWR);
  wake_all(f);
}

unsigned long srv_front_refused(const srv_front *f) {
  return f ? atomic_load(&f->refused) : 0;
}

void srv_front_destroy(srv_front *f) {
  if (f == NULL) return;
  srv_front_stop_listening(f);
  f->stop_deadline = srv_now() + STOP_FLUSH;
  atomic_store(&f->stopping, true);
  wake_all(f);
  for (unsigned i = 0; f->relays != NULL && i < f->opt.threads; i++) {
    relay *r = &f->relays[i];
    if (r->started) pthread_join(r->thread, NULL);
    if (r->ep > 0) close(r->ep);
    if (r->wake > 0) close(r->wake);
  }
  if (f->listen_fd >= 0) close(f->listen_fd);
  free(f->relays);
  free(f);
}
