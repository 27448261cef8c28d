"""load.py - kmorphd under sustained load and under faults, on loopback,
bounded in time.

  load      64 keep-alive clients for LOAD_SECONDS (20; 120 with
            HARDENING_LONG=1) of mixed signature / morph / job traffic,
            some jobs cancelled while running. Every answer must be its
            own correct answer or a documented 429/503 refusal with
            Retry-After; p50/p99 latency recorded; RSS peak within
            RSS_BOUND_MB; afterwards descriptors back to baseline.
  faults    clients that leave mid-request and mid-response, slow-body
            and slow-read clients, many idle connections opened and
            dropped (IDLE_CONNECTIONS: 10,000), while a
            well-behaved client keeps being served quickly; afterwards
            descriptors and memory back to baseline, /healthz fine.
  sigterm   SIGTERM while 32 clients and 8 jobs are busy: exit 0 within
            the grace period; every job last seen done or cancelled.

    python3 tests/hardening/load.py [load] [faults] [sigterm]

Appends "hardening/<part> passed failed" lines to build/test-results.txt
and a summary line per part to build/hardening-summary.txt.
"""
import http.client
import json
import math
import os
import random
import resource
import socket
import struct
import sys
import threading
import time

sys.path.insert(0, os.path.dirname(__file__))
import hlib  # noqa: E402
import kmreq  # noqa: E402

LONG = os.environ.get("HARDENING_LONG") == "1"
LOAD_SECONDS = float(os.environ.get("LOAD_SECONDS", 120 if LONG else 20))
IDLE_CONNECTIONS = int(os.environ.get("IDLE_CONNECTIONS", 10000))
CLIENTS = 64
RSS_BOUND_MB = 512
DAEMON = hlib.DAEMON
JSON = {"Content-Type": "application/json"}


def summary(line):
    print(line)
    with open(os.path.join(hlib.ROOT, "build", "hardening-summary.txt"),
              "a") as f:
        f.write(line + "\n")


def pct(xs, p):
    if not xs:
        return float("nan")
    xs = sorted(xs)
    return xs[min(len(xs) - 1, int(math.ceil(p / 100.0 * len(xs))) - 1)]


class Monitor(threading.Thread):
    """Samples the daemon's RSS and descriptors every 50 ms."""

    def __init__(self, d):
        super().__init__(daemon=True)
        self.d = d
        self.peak_rss = 0
        self.peak_fds = 0
        self.stop = False

    def run(self):
        while not self.stop and self.d.alive():
            try:
                self.peak_rss = max(self.peak_rss, self.d.rss_kb())
                self.peak_fds = max(self.peak_fds, self.d.fds())
            except OSError:
                pass
            time.sleep(0.05)


class Client:
    """One keep-alive connection that reconnects when the server closes."""

    def __init__(self, port):
        self.port = port
        self.conn = None

    def req(self, method, path, body=None, timeout=60):
        for attempt in (0, 1):
            if self.conn is None:
                self.conn = http.client.HTTPConnection(hlib.HOST, self.port,
                                                       timeout=timeout)
            try:
                hdrs = dict(JSON) if body is not None else {}
                data = json.dumps(body).encode() if body is not None else None
                self.conn.request(method, path, body=data, headers=hdrs)
                r = self.conn.getresponse()
                out = hlib.Reply(r.status, r.getheaders(), r.read())
                if r.will_close:
                    self.close()
                return out
            except (http.client.RemoteDisconnected, BrokenPipeError,
                    ConnectionResetError, http.client.CannotSendRequest):
                # a kept-alive connection the server closed meanwhile: one
                # retry on a fresh connection (requests here are idempotent
                # or harmless to repeat)
                self.close()
                if attempt:
                    raise

    def close(self):
        if self.conn is not None:
            self.conn.close()
            self.conn = None


def refusal_ok(r):
    return r.status in (429, 503) and r.headers.get("retry-after")


# ------------------------------------------------------------------ load

def part_load(ck):
    d = hlib.Daemon("--access-log", "0", "--max-jobs", "64",
                    "--queue", "128", exe=DAEMON)
    stats = {"sig": 0, "morph": 0, "job": 0, "cancelled": 0, "health": 0,
             "refused": 0}
    lat = []
    fails = []
    lock = threading.Lock()
    try:
        # warm up, then take the baseline
        c0 = Client(d.port)
        for r in range(8):
            c0.req("POST", "/v1/morph", kmreq_body_morph(3))
        c0.close()
        time.sleep(0.2)
        rss0, fds0 = d.rss_kb(), d.fds()
        mon = Monitor(d)
        mon.start()
        deadline = time.monotonic() + LOAD_SECONDS

        def worker(wid):
            rnd = random.Random(wid)
            cl = Client(d.port)
            try:
                while time.monotonic() < deadline:
                    k = rnd.random()
                    t0 = time.monotonic()
                    try:
                        if k < 0.45:
                            radius = 1 + rnd.random() * 10
                            r = cl.req("POST", "/v1/signature",
                                       {"curve": kmreq.circle_svg(radius)})
                            kind = "sig"
                            ok = r.status == 200 and math.isclose(
                                r.json()["signature"]["length"],
                                2 * math.pi * radius, rel_tol=1e-6)
                        elif k < 0.80:
                            frames = 2 + rnd.randrange(9)
                            r = cl.req("POST", "/v1/morph",
                                       kmreq_body_morph(frames))
                            kind = "morph"
                            ok = r.status == 200 and len(
                                r.json()["frames"]) == frames
                        elif k < 0.92:
                            kind, r, ok = one_job(cl, rnd, stats, lock)
                        else:
                            r = cl.req("GET", "/healthz")
                            kind = "health"
                            ok = r.status == 200
                    except Exception as e:  # noqa: BLE001
                        with lock:
                            fails.append("exception %r" % e)
                        cl.close()
                        continue
                    dt = time.monotonic() - t0
                    with lock:
                        if r is not None and refusal_ok(r):
                            stats["refused"] += 1
                        elif ok:
                            stats[kind] += 1
                            if kind in ("sig", "morph"):
                                lat.append(dt)
                        else:
                            fails.append("%s: %s %r" % (
                                kind, r.status if r else None,
                                r.body[:200] if r else None))
            finally:
                cl.close()

        ts = [threading.Thread(target=worker, args=(i,))
              for i in range(CLIENTS)]
        t0 = time.monotonic()
        for t in ts:
            t.start()
        for t in ts:
            t.join(timeout=LOAD_SECONDS + 120)
        wall = time.monotonic() - t0
        hung = sum(t.is_alive() for t in ts)
        mon.stop = True
        mon.join()
        time.sleep(1.0)
        rss1, fds1 = d.rss_kb(), d.fds()
        total = sum(stats.values())
        summary("load: %d clients, %.0f s: %d answers (%d signature, %d "
                "morph, %d jobs of which %d cancelled, %d health), %d "
                "refused 429/503, %d failed; %.0f req/s; latency p50 %.1f "
                "ms, p99 %.1f ms, max %.1f ms; RSS %d kB before, peak %d, "
                "after %d; fds %d before, peak %d, after %d" % (
                    CLIENTS, wall, total, stats["sig"], stats["morph"],
                    stats["job"], stats["cancelled"], stats["health"],
                    stats["refused"], len(fails), total / wall,
                    1e3 * pct(lat, 50), 1e3 * pct(lat, 99),
                    1e3 * max(lat or [0]), rss0, mon.peak_rss, rss1, fds0,
                    mon.peak_fds, fds1))
        for f in fails[:10]:
            print("  failure:", f)
        ck.check(hung == 0, "every client finished in time")
        ck.check(not fails, "no failed request except 429/503 with "
                 "Retry-After (%d failed)" % len(fails))
        ck.check(stats["sig"] > 0 and stats["morph"] > 0 and
                 stats["job"] > 0 and stats["cancelled"] > 0,
                 "the mix ran: signature, morph, jobs and cancellations")
        ck.check(mon.peak_rss <= RSS_BOUND_MB * 1024,
                 "RSS peak %d kB within the stated %d MiB" % (
                     mon.peak_rss, RSS_BOUND_MB))
        ck.check(fds1 <= fds0 + 2, "descriptors back to baseline after the "
                 "clients left (%d -> %d)" % (fds0, fds1))
        h = d.request("GET", "/healthz", timeout=10)
        ck.check(h.status == 200, "/healthz fine after the load")
        rc, dt = d.terminate(timeout=30)
        ck.check(rc == 0, "SIGTERM after the load: exit 0 (%s in %.1f s)"
                 % (rc, dt))
    finally:
        d.close()


def kmreq_body_morph(frames):
    return {"from": kmreq.circle_svg(1.0), "to": kmreq.square_svg(2.0),
            "frames": frames}


def one_job(cl, rnd, stats, lock):
    """Submit a job; cancel it at once half the time, else wait for it.
    Returns (kind, last reply, ok)."""
    frames = 20 + rnd.randrange(40)
    r = cl.req("POST", "/v1/jobs", kmreq_body_morph(frames))
    if r.status != 202:
        return "job", r, False
    jid = r.json()["id"]
    if rnd.random() < 0.5:
        c = cl.req("DELETE", "/v1/jobs/" + jid)
        if c.status != 204:
            return "job", c, False
        s = cl.req("GET", "/v1/jobs/" + jid)
        st = s.json().get("state") if s.status == 200 else None
        if st == "cancelled":
            res = cl.req("GET", "/v1/jobs/%s/result" % jid)
            with lock:
                stats["cancelled"] += 1
            return "job", res, res.status == 409
        # finished before the cancel arrived: a finished job is forgotten
        return "job", s, s.status == 404 or st == "done"
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        s = cl.req("GET", "/v1/jobs/" + jid)
        st = s.json().get("state") if s.status == 200 else None
        if st == "done":
            res = cl.req("GET", "/v1/jobs/%s/result" % jid)
            return "job", res, res.status == 200 and len(
                res.json()["frames"]) == frames
        if st not in ("queued", "running"):
            return "job", s, False
        time.sleep(0.05)
    return "job", None, False


# ---------------------------------------------------------------- faults

def rst_close(s):
    """Close with RST (SO_LINGER 0), as a client that vanishes."""
    try:
        s.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER,
                     struct.pack("ii", 1, 0))
    except OSError:
        pass
    s.close()


def connect(port, rcvbuf=None):
    s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    if rcvbuf:
        s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, rcvbuf)
    s.settimeout(10)
    s.connect((hlib.HOST, port))
    return s


def http_head(path, length, ctype="application/json"):
    return ("POST %s HTTP/1.1\r\nHost: x\r\nContent-Type: %s\r\n"
            "Content-Length: %d\r\n\r\n" % (path, ctype, length)).encode()


class Prober(threading.Thread):
    """A well-behaved client: one signature request every 50 ms on fresh
    connections; records latencies and failures."""

    def __init__(self, port):
        super().__init__(daemon=True)
        self.port = port
        self.lat = []
        self.fail = []
        self.stop = False

    def run(self):
        body = json.dumps({"curve": kmreq.circle_svg(3.0)}).encode()
        while not self.stop:
            t0 = time.monotonic()
            try:
                r = hlib.request(self.port, "POST", "/v1/signature", body,
                                 JSON, timeout=10)
                if r.status != 200:
                    self.fail.append(r.status)
            except Exception as e:  # noqa: BLE001
                self.fail.append(repr(e))
            self.lat.append(time.monotonic() - t0)
            time.sleep(0.05)


def part_faults(ck):
    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    want = min(hard, IDLE_CONNECTIONS + 1024)
    if soft < want:
        resource.setrlimit(resource.RLIMIT_NOFILE, (want, hard))
    batch = min(2000, max(100, (want - 512) // 2))
    # One address opens the idle connections here, so the limit per
    # address is lifted to the connection limit (test_bounds.py covers it).
    d = hlib.Daemon("--access-log", "0", "--timeout", "3",
                    "--request-time", "4", "--max-connections",
                    str(batch + 200), "--per-ip", str(batch + 200),
                    "--queue", "256", exe=DAEMON)
    try:
        body = json.dumps({"curve": kmreq.circle_svg(2.0)}).encode()
        for _ in range(5):
            hlib.request(d.port, "POST", "/v1/signature", body, JSON)
        rss0, fds0 = d.rss_kb(), d.fds()
        probe = Prober(d.port)
        probe.start()
        counts = {}

        # 1. leave mid-request: headers only, part of the body, part of
        #    the headers
        heavy = json.dumps({"from": kmreq.circle_svg(10.0),
                            "to": kmreq.square_svg(15.0), "frames": 300,
                            "metrics": True}).encode()
        n = 0
        for i in range(300):
            s = connect(d.port)
            if i % 3 == 0:
                s.sendall(http_head("/v1/morph", len(heavy)))
            elif i % 3 == 1:
                s.sendall(http_head("/v1/morph", len(heavy)) +
                          heavy[:len(heavy) // 2])
            else:
                s.sendall(b"POST /v1/morph HTTP/1.1\r\nHost: x\r\nCont")
            (rst_close if i % 2 else socket.socket.close)(s)
            n += 1
        counts["left mid-request"] = n

        # 2. leave mid-response: while computing, and after a few bytes
        n = 0
        socks = []
        for i in range(60):
            s = connect(d.port)
            s.sendall(http_head("/v1/morph", len(heavy)) + heavy)
            socks.append(s)
        time.sleep(0.05)
        for i, s in enumerate(socks):
            if i % 2:
                try:
                    s.recv(100)
                except OSError:
                    pass
            rst_close(s)
            n += 1
        counts["left mid-response"] = n

        # 3. slow body: one byte every 0.2 s, cut at --request-time
        slow_out = []

        def slow_body():
            try:
                s = connect(d.port)
                s.sendall(http_head("/v1/signature", len(body)))
                for k in range(len(body)):
                    s.sendall(body[k:k + 1])
                    time.sleep(0.2)
                slow_out.append("completed")
            except OSError:
                slow_out.append("cut")
        slows = [threading.Thread(target=slow_body) for _ in range(16)]
        for t in slows:
            t.start()

        # 4. slow read: a large answer read 1 KiB a second with a small
        #    receive buffer, then abandoned
        big = json.dumps({"from": kmreq.circle_svg(10.0),
                          "to": kmreq.square_svg(15.0),
                          "frames": 400}).encode()
        readers = []
        for i in range(16):
            s = connect(d.port, rcvbuf=4096)
            s.sendall(http_head("/v1/morph", len(big)) + big)
            readers.append(s)
        for _ in range(4):
            for s in readers:
                try:
                    s.recv(1024)
                except OSError:
                    pass
            time.sleep(1.0)
        for s in readers:
            rst_close(s)
        counts["slow readers"] = len(readers)
        for t in slows:
            t.join(timeout=30)
        counts["slow bodies"] = len(slows)

        # 5. idle connections opened and dropped, in batches below the
        #    connection limit; others are served meanwhile
        opened = 0
        served_during = 0
        while opened < IDLE_CONNECTIONS:
            k = min(batch, IDLE_CONNECTIONS - opened)
            idle = []
            for _ in range(k):
                try:
                    idle.append(connect(d.port))
                except OSError:
                    break
            opened += len(idle)
            r = hlib.request(d.port, "POST", "/v1/signature", body, JSON,
                             timeout=10)
            served_during += r.status == 200
            for j, s in enumerate(idle):
                (rst_close if j % 2 else socket.socket.close)(s)
            if len(idle) < k:
                break
        counts["idle connections"] = opened

        probe.stop = True
        probe.join(timeout=15)
        # connections the daemon still holds close at its idle timeout (3 s)
        deadline = time.monotonic() + 20
        while time.monotonic() < deadline and d.fds() > fds0 + 2:
            time.sleep(0.2)
        time.sleep(0.5)
        rss1, fds1 = d.rss_kb(), d.fds()
        h = d.request("GET", "/healthz", timeout=10)
        summary("faults: %s; prober %d requests, %d failed, p99 %.1f ms, max "
                "%.1f ms; slow bodies %s; RSS %d kB before, %d after; fds %d "
                "before, %d after" % (
                    ", ".join("%s %d" % kv for kv in counts.items()),
                    len(probe.lat), len(probe.fail),
                    1e3 * pct(probe.lat, 99), 1e3 * max(probe.lat or [0]),
                    "/".join(sorted(set(slow_out))), rss0, rss1, fds0,
                    fds1))
        ck.check(not probe.fail, "a well-behaved client was served "
                 "throughout (%d failures: %s)" % (len(probe.fail),
                                                   probe.fail[:5]))
        # While a batch of idle connections fills the connection limit a
        # new client waits for the oldest to reach the idle timeout (3 s
        # here); on top of that it may wait for its own compute and for a
        # machine busy with the test's thousands of sockets (up to 1.7 s
        # seen on 2 shared vCPUs), so the bound is 3 + 2.5 s. Work for
        # clients that left (up to 5 s a request before it was skipped)
        # would make it 8 s and more.
        ck.check(max(probe.lat or [0]) < 5.5, "and never waited much longer "
                 "than the idle timeout (max %.2f s, bound 3 + 2.5 s)"
                 % max(probe.lat or [0]))
        ck.check(opened >= IDLE_CONNECTIONS and served_during > 0,
                 "%d idle connections opened and dropped while serving "
                 "others" % opened)
        ck.check("completed" not in slow_out, "slow bodies are cut at the "
                 "request time limit")
        ck.check(fds1 <= fds0 + 2, "descriptors back to baseline (%d -> "
                 "%d)" % (fds0, fds1))
        # the abandoned 400-frame answers (MBs each) leave glibc arenas
        # of a few tens of MiB behind; a leak would grow without bound
        ck.check(rss1 <= rss0 + 64 * 1024, "memory back near baseline (%d "
                 "-> %d kB, bound +64 MiB)" % (rss0, rss1))
        ck.check(h.status == 200, "/healthz fine afterwards")
        rc, dt = d.terminate(timeout=30)
        ck.check(rc == 0, "SIGTERM afterwards: exit 0 (%s in %.1f s)" %
                 (rc, dt))
    finally:
        d.close()


# --------------------------------------------------------------- sigterm

def part_sigterm(ck):
    grace = 10.0
    d = hlib.Daemon("--access-log", "0", "--shutdown-grace",
                    str(grace), "--max-jobs", "64", exe=DAEMON)
    try:
        heavy = {"from": kmreq.circle_svg(10.0), "to": kmreq.square_svg(15.0),
                 "frames": 3000, "metrics": True}
        cl = Client(d.port)
        jobs = []
        for _ in range(8):
            r = cl.req("POST", "/v1/jobs", heavy)
            if r.status == 202:
                jobs.append(r.json()["id"])
        stop = [False]
        answered = [0, 0, 0]  # ok, refused, connection closed

        def worker():
            c = Client(d.port)
            while not stop[0]:
                try:
                    r = c.req("POST", "/v1/morph", kmreq_body_morph(20),
                              timeout=30)
                    if r.status == 200:
                        answered[0] += 1
                    elif refusal_ok(r):
                        answered[1] += 1
                    else:
                        answered[2] += 1
                except OSError:
                    answered[2] += 1
                    time.sleep(0.05)
            c.close()
        ts = [threading.Thread(target=worker) for _ in range(32)]
        for t in ts:
            t.start()
        time.sleep(2.0)
        before = {j: cl.req("GET", "/v1/jobs/" + j).json().get("state")
                  for j in jobs}
        # a kept-alive connection outlives the quiesced listener: use it to
        # watch the jobs wind down
        last = dict(before)
        t0 = time.monotonic()
        d.proc.send_signal(15)
        while d.alive() and time.monotonic() - t0 < grace + 5:
            for j in jobs:
                try:
                    r = cl.req("GET", "/v1/jobs/" + j, timeout=2)
                    if r.status == 200:
                        last[j] = r.json().get("state")
                except (OSError, http.client.HTTPException):
                    pass
            time.sleep(0.05)
        try:
            rc = d.proc.wait(timeout=max(1.0, grace + 5 -
                                         (time.monotonic() - t0)))
        except Exception:  # noqa: BLE001
            rc = None
        dt = time.monotonic() - t0
        stop[0] = True
        for t in ts:
            t.join(timeout=40)
        cl.close()
        states = {}
        for s in last.values():
            states[s] = states.get(s, 0) + 1
        summary("sigterm: %d jobs (%s at SIGTERM; last seen %s), 32 clients "
                "(%d answered, %d refused, %d cut by the shutdown); exit %s "
                "in %.1f s (grace %g s)" % (
                    len(jobs), ",".join(sorted(set(before.values()))),
                    states, answered[0], answered[1], answered[2], rc, dt,
                    grace))
        ck.check(len(jobs) == 8 and "running" in before.values(),
                 "jobs accepted and running when SIGTERM came")
        ck.check(rc == 0, "exit status 0 (%s)" % rc)
        ck.check(dt <= grace + 1.0, "exit within the grace period (%.1f s)"
                 % dt)
        # A job's fate must be observable: seen done or cancelled over HTTP
        # while the daemon drained, or reported by id in its log.
        log = d.text()
        unreported = [j for j in jobs if last[j] not in ("done", "cancelled")
                      and j not in log]
        ck.check(not unreported, "every accepted job finished or reported "
                 "cancelled (%d of %d last seen %s, not in the log)" % (
                     len(unreported), len(jobs),
                     sorted(set(last[j] for j in unreported))))
        ck.check("forced" not in d.text(), "no forced stop")
    finally:
        d.close()


def main():
    parts = sys.argv[1:] or ["load", "faults", "sigterm"]
    ok = True
    for p in parts:
        ck = hlib.Checks(p)
        try:
            {"load": part_load, "faults": part_faults,
             "sigterm": part_sigterm}[p](ck)
        except Exception as e:  # noqa: BLE001 - a crash of the test fails it
            import traceback
            traceback.print_exc()
            ck.check(False, "%s ran to its end" % p, repr(e))
        ok = ck.record() and ok
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
