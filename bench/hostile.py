#!/usr/bin/env python3
"""hostile.py - kmorphd under hostile clients: for each scenario, the
daemon's peak resident memory, the wall time until the scenario's requests
were answered or refused (and how), and whether a well-behaved probe kept
being answered meanwhile.

DESIGN: every scenario gets a fresh daemon (so VmHWM from /proc/PID/status
is that scenario's peak), started here on 127.0.0.1 with --port 0 and
stopped by its pid. A prober asks GET /healthz every 0.25 s from another
loopback address (127.0.0.2), each probe on a new connection, so that it
stands for an ordinary client that the hostile one shares the daemon with.
Each scenario gives up after --limit seconds (reported as "> N s"). Flags a
binary's --help does not list are dropped for that binary (and reported), so
one command measures an old and a new daemon with the same limits where
both have them. The daemon's address space is capped (--mem-cap) so that a
runaway cannot take the machine; reaching the cap shows as failed answers
or a dead daemon, not as a larger figure.

Only the standard library; loopback only; every wait is bounded.

    python3 bench/hostile.py --daemon build/kmorphd [--only s1,s5]
"""
import argparse
import json
import math
import os
import re
import resource
import selectors
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time

HOST = "127.0.0.1"
PROBE_ADDR = "127.0.0.2"
MIB = 1 << 20


# ---------------------------------------------------------------- curves

def circle_svg(r):
    return {"type": "svg",
            "d": "M %r 0 A %r %r 0 1 1 %r 0 A %r %r 0 1 1 %r 0 Z" % (
                r, r, r, -r, r, r, r)}


def square_svg(side):
    return {"type": "svg",
            "d": "M 0 0 L %r 0 L %r %r L 0 %r Z" % (side, side, side, side)}


def wavy_points(n, amp=0.3, waves=40):
    """A closed polygon of n points on a wavy circle of radius 10, its
    coordinates rounded to 1e-6 to keep the body small."""
    pts = []
    for k in range(n):
        a = 2 * math.pi * k / n
        r = 10 * (1 + amp * math.sin(waves * a))
        pts.append([round(r * math.cos(a), 6), round(r * math.sin(a), 6)])
    return {"type": "points", "points": pts, "closed": True}


def dumps(doc):
    return json.dumps(doc, separators=(",", ":")).encode()


# ------------------------------------------------------------------ HTTP

def post_bytes(path, data, extra=b""):
    return (b"POST %s HTTP/1.1\r\nHost: x\r\nConnection: close\r\n"
            b"Content-Type: application/json\r\nContent-Length: %d\r\n%s\r\n"
            % (path.encode(), len(data), extra)) + data


def get_bytes(path):
    return b"GET %s HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n" % \
        path.encode()


def status_of(raw):
    if not raw.startswith(b"HTTP/1."):
        return None
    try:
        return int(raw.split(b" ", 2)[1])
    except (IndexError, ValueError):
        return None


def exchange(port, data, deadline, src=None, keep=1 << 20):
    """Send one request and read until the server closes or deadline (a
    time.monotonic() value) passes. Returns a dict: status (None if none
    came), bytes (all bytes read), head (the first keep bytes), seconds,
    end ("closed", "reset" or "timeout")."""
    t0 = time.monotonic()
    out = {"bytes": 0, "end": "timeout"}
    buf = bytearray()
    s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    try:
        s.settimeout(max(0.05, min(10.0, deadline - t0)))
        if src:
            s.bind((src, 0))
        s.connect((HOST, port))
        s.settimeout(max(0.05, deadline - time.monotonic()))
        s.sendall(data)
        while True:
            left = deadline - time.monotonic()
            if left <= 0:
                break
            s.settimeout(left)
            b = s.recv(1 << 20)
            if not b:
                out["end"] = "closed"
                break
            out["bytes"] += len(b)
            if len(buf) < keep:
                buf += b[:keep - len(buf)]
    except socket.timeout:
        pass
    except OSError:
        out["end"] = "reset"
    finally:
        s.close()
    out["head"] = bytes(buf)
    out["status"] = status_of(out["head"])
    out["seconds"] = time.monotonic() - t0
    return out


def body_of(reply):
    head = reply["head"]
    i = head.find(b"\r\n\r\n")
    return head[i + 4:] if i >= 0 else b""


def json_of(reply):
    try:
        return json.loads(body_of(reply).decode("utf-8"))
    except ValueError:
        return None


def kind(reply):
    """How a request ended, in a few words: its status (with the limit or
    field a problem names), or how the connection ended without one."""
    if reply["status"] is not None:
        doc = json_of(reply) if reply["status"] >= 400 else None
        if not isinstance(doc, dict):
            return str(reply["status"])
        m = re.search(r"KMORPH_[A-Z_]+", str(doc.get("detail", "")))
        errs = doc.get("errors") or [{}]
        why = m.group(0) if m else errs[0].get("pointer") or doc.get("title")
        return "%d %s" % (reply["status"], why) if why else \
            str(reply["status"])
    return {"closed": "closed", "reset": "reset",
            "timeout": "no answer"}[reply["end"]]


# ---------------------------------------------------------------- daemon

def help_flags(path):
    """The --flags a kmorphd binary lists in its --help."""
    txt = subprocess.run([path, "--help"], capture_output=True, text=True,
                         timeout=10)
    flags = set()
    for line in (txt.stdout + txt.stderr).splitlines():
        w = line.strip().split(" ", 1)[0]
        if w.startswith("--"):
            flags.add(w)
    return flags


class Daemon:
    """A kmorphd process on a port the OS chose; a sampler thread keeps its
    latest VmHWM and the largest VmRSS since mark()."""

    def __init__(self, path, flags, mem_cap_mib):
        self.log = tempfile.NamedTemporaryFile(prefix="kmorphd-hostile-",
                                               suffix=".log", delete=False)
        env = {k: v for k, v in os.environ.items()
               if not k.startswith("KMORPH_")}
        cap = mem_cap_mib * MIB

        def limit():
            if cap:
                resource.setrlimit(resource.RLIMIT_AS, (cap, cap))
        self.proc = subprocess.Popen(
            [path, "--bind", HOST, "--port", "0", "--access-log", "0",
             *flags], stdout=subprocess.DEVNULL, stderr=self.log, env=env,
            preexec_fn=limit)
        self.hwm_kb = 0
        self.rss_max_kb = 0
        self._stop = threading.Event()
        self.port = self._read_port()
        self._sampler = threading.Thread(target=self._sample, daemon=True)
        self._sampler.start()

    def _read_port(self):
        deadline = time.monotonic() + 10
        while time.monotonic() < deadline:
            if self.proc.poll() is not None:
                raise RuntimeError("kmorphd exited: " + self.text()[-500:])
            for line in self.text().splitlines():
                if "listening on http://" in line:
                    return int(line.split("http://", 1)[1].split(" ", 1)[0]
                               .rsplit(":", 1)[1])
            time.sleep(0.02)
        self.stop()
        raise RuntimeError("kmorphd did not start: " + self.text()[-500:])

    def text(self):
        with open(self.log.name, encoding="utf-8", errors="replace") as f:
            return f.read()

    def status_kb(self):
        """(VmHWM, VmRSS) in KiB, or None once the process is gone."""
        try:
            with open("/proc/%d/status" % self.proc.pid) as f:
                v = {}
                for line in f:
                    if line.startswith(("VmHWM:", "VmRSS:")):
                        v[line[:5]] = int(line.split()[1])
                return v.get("VmHWM", 0), v.get("VmRSS", 0)
        except OSError:
            return None

    def _sample(self):
        while not self._stop.is_set() and self.proc.poll() is None:
            self.update()
            time.sleep(0.05)

    def update(self):
        """Take one sample now."""
        st = self.status_kb()
        if st:
            self.hwm_kb = max(self.hwm_kb, st[0])
            self.rss_max_kb = max(self.rss_max_kb, st[1])

    def mark(self):
        """Start a new window for the largest VmRSS; returns VmRSS now."""
        st = self.status_kb()
        self.rss_max_kb = st[1] if st else 0
        return self.rss_max_kb

    def alive(self):
        return self.proc.poll() is None

    def stop(self):
        """SIGTERM by pid, then SIGKILL if it has not left in 15 s."""
        self._stop.set()
        if self.proc.poll() is None:
            self.update()
            self.proc.send_signal(signal.SIGTERM)
            try:
                self.proc.wait(timeout=15)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait(timeout=5)
        self.log.close()
        try:
            os.unlink(self.log.name)
        except OSError:
            pass


class Prober:
    """GET /healthz from PROBE_ADDR every 0.25 s, each probe on its own
    connection and thread (a stuck probe does not delay the next one), each
    bounded to 5 s."""

    def __init__(self, port):
        self.port = port
        self.results = []
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._threads = []
        self._main = threading.Thread(target=self._run, daemon=True)
        self._main.start()

    def _one(self):
        r = exchange(self.port, get_bytes("/healthz"),
                     time.monotonic() + 5.0, src=PROBE_ADDR, keep=4096)
        with self._lock:
            self.results.append((r["status"], r["seconds"]))

    def _run(self):
        while not self._stop.is_set():
            t = threading.Thread(target=self._one, daemon=True)
            t.start()
            self._threads.append(t)
            self._stop.wait(0.25)

    def finish(self):
        self._stop.set()
        self._main.join(timeout=2)
        for t in self._threads:
            t.join(timeout=6)
        ok = [dt for st, dt in self.results if st == 200]
        sent = len(self.results)
        return {"sent": sent, "ok": len(ok),
                "slowest": max((dt for _, dt in self.results), default=0.0)}


# ------------------------------------------------------------- scenarios
#
# Each takes (daemon, limit seconds) and returns a dict: seconds (None: not
# all answered or refused within the limit), answers (a short text), and
# optionally note. Flags are the scenario's daemon flags.

def huge_morph_body():
    """About 200 bytes asking for about 60 MB (frames of a circle of radius
    100 turning into a square of side 150, each within 1e-9)."""
    return {"from": circle_svg(100.0), "to": square_svg(150.0),
            "frames": 1000, "tolerance": 1e-9}


def s1_huge_answer(d, limit):
    """A tiny morph whose answer is huge."""
    data = dumps(huge_morph_body())
    r = exchange(d.port, post_bytes("/v1/morph", data),
                 time.monotonic() + limit, keep=4096)
    done = r["end"] == "closed" and r["status"] is not None
    return {"seconds": r["seconds"] if done else None,
            "answers": "%s, %.1f MB" % (kind(r), r["bytes"] / 1e6),
            "note": "%d-byte request" % len(data)}


def wait_job(d, jid, deadline):
    """Poll a job until it ends; its last state or None."""
    state = None
    while time.monotonic() < deadline:
        r = exchange(d.port, get_bytes("/v1/jobs/" + jid),
                     min(deadline, time.monotonic() + 10), keep=65536)
        doc = json_of(r)
        if doc is not None:
            state = doc.get("state")
            if state in ("done", "failed", "cancelled"):
                return state, doc
        elif not d.alive():
            return "daemon died", None
        time.sleep(0.25)
    return None, None


def post_job(d, body, deadline):
    r = exchange(d.port, post_bytes("/v1/jobs", dumps(body)), deadline,
                 keep=65536)
    doc = json_of(r)
    jid = doc.get("id") if r["status"] == 202 and doc else None
    return r, jid


def s2_huge_job(d, limit):
    """The same morph as a job, then GET its result."""
    t0 = time.monotonic()
    deadline = t0 + limit
    r, jid = post_job(d, huge_morph_body(), deadline)
    if jid is None:
        return {"seconds": time.monotonic() - t0, "answers":
                "POST %s" % kind(r)}
    state, doc = wait_job(d, jid, deadline)
    if state != "done":
        err = (doc or {}).get("error") or {}
        what = state or "not ended"
        if isinstance(err, dict) and err.get("status"):
            what += " (%s)" % err["status"]
        return {"seconds": time.monotonic() - t0 if state else None,
                "answers": "POST 202, job %s" % what}
    g = exchange(d.port, get_bytes("/v1/jobs/%s/result" % jid), deadline,
                 keep=4096)
    done = g["end"] == "closed" and g["status"] is not None
    return {"seconds": time.monotonic() - t0 if done else None,
            "answers": "POST 202, job done, result %s %.1f MB"
            % (kind(g), g["bytes"] / 1e6)}


def heavy_prepare_body():
    return {"from": wavy_points(2000), "to": wavy_points(2000, 0.25, 37),
            "frames": 2, "tolerance": 1e-9, "matches": "auto",
            "metrics": True}


def s3_heavy_prepare(d, limit):
    """A morph whose preparation is heavy, and a small morph behind it on
    the one worker."""
    t0 = time.monotonic()
    deadline = t0 + limit
    out = {}

    def heavy():
        out["heavy"] = exchange(d.port, post_bytes(
            "/v1/morph", dumps(heavy_prepare_body())), deadline, keep=65536)
    t = threading.Thread(target=heavy)
    t.start()
    time.sleep(0.2)
    small = {"from": circle_svg(1.0), "to": circle_svg(2.0), "frames": 2}
    s = exchange(d.port, post_bytes("/v1/morph", dumps(small)), deadline,
                 keep=4096)
    t.join(timeout=limit + 5)
    h = out["heavy"]
    ends = [r["seconds"] + (0.2 if r is s else 0.0) for r in (h, s)
            if r["status"] is not None]
    return {"seconds": max(ends) if len(ends) == 2 else None,
            "answers": "heavy %s at %.1f s; small %s after %.1f s" % (
                kind(h), h["seconds"], kind(s), s["seconds"])}


def s4_heavy_signature(d, limit):
    """A signature of tens of thousands of points at a tight tolerance."""
    body = {"curve": wavy_points(99000, 0.3, 40), "tolerance": 1e-11}
    data = dumps(body)
    r = exchange(d.port, post_bytes("/v1/signature", data),
                 time.monotonic() + limit, keep=4096)
    return {"seconds": r["seconds"] if r["status"] is not None else None,
            "answers": "%s, %.1f MB" % (kind(r), r["bytes"] / 1e6),
            "note": "%.1f MB request" % (len(data) / 1e6)}


def s5_slow_readers(d, limit):
    """Eight readers of one large job result (about 18 MB: 6,000 frames,
    under a 64 MiB bound on predicted answers), each with a small receive
    buffer reading 1 KiB a second."""
    t0 = time.monotonic()
    body = {"from": circle_svg(10.0), "to": square_svg(15.0),
            "frames": 6000, "tolerance": 1e-4}
    r, jid = post_job(d, body, t0 + limit)
    if jid is None:
        return {"seconds": None, "answers": "job POST %s" % kind(r)}
    state, _ = wait_job(d, jid, t0 + limit)
    if state != "done":
        return {"seconds": None, "answers": "job %s" % state}
    path = "/v1/jobs/%s/result" % jid
    full = exchange(d.port, get_bytes(path), time.monotonic() + limit,
                    keep=0)["bytes"]
    time.sleep(0.3)
    rss0 = d.mark()
    t1 = time.monotonic()
    socks = []
    for _ in range(8):
        s = socket.socket()
        s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
        s.settimeout(5)
        s.connect((HOST, d.port))
        s.sendall(get_bytes(path))
        s.setblocking(False)
        socks.append([s, 0, None])  # socket, bytes read, end
    cut_at = read_slowly(d, socks, full, t1, t1 + limit)
    rss1 = d.rss_max_kb
    for item in socks:
        item[0].close()
    ends = [e for _, _, e in socks if e is not None]
    counts = {}
    for e in ends:
        counts[e[0]] = counts.get(e[0], 0) + 1
    text = ", ".join("%d %s by %.1f s" % (n, k, max(
        e[1] for e in ends if e[0] == k)) for k, n in sorted(counts.items()))
    if len(ends) < 8:
        text += (", " if text else "") + "%d still reading" % (8 - len(ends))
    if cut_at is not None:
        text += "; the daemon cut all 8 by %.1f s" % cut_at
    seconds = cut_at if cut_at is not None else (
        max(e[1] for e in ends) if len(ends) == 8 else None)
    return {"seconds": seconds, "answers": text,
            "note": "result %.1f MB; RSS %.0f -> max %.0f MiB while read"
            % (full / 1e6, rss0 / 1024, rss1 / 1024)}


def late_sends(d):
    """The daemon's count of connections cut because their answer was not
    read in time (kmorph_connections_cut_total{reason="late_send"}), or
    None if it has no such metric."""
    r = exchange(d.port, get_bytes("/metrics"), time.monotonic() + 5)
    key = b'kmorph_connections_cut_total{reason="late_send"} '
    for line in body_of(r).splitlines():
        if line.startswith(key):
            return int(float(line[len(key):]))
    return None


def read_slowly(d, socks, full, t1, deadline):
    """Read 1 KiB a second from each socket until each has ended (EOF or
    reset), the daemon says it cut them all, or deadline. A connection the
    daemon cut still delivers what its kernel buffers hold, so the reader
    sees the end late: the daemon's own count says when it let go. Returns
    the seconds until the daemon had cut them all, or None."""
    cut_at = None
    while time.monotonic() < deadline and any(e is None for _, _, e in socks):
        for item in socks:
            if item[2] is not None:
                continue
            try:
                b = item[0].recv(1024)
                if not b:
                    item[2] = ("cut" if item[1] < full else "whole",
                               time.monotonic() - t1)
                item[1] += len(b)
            except BlockingIOError:
                pass
            except OSError:
                item[2] = ("reset", time.monotonic() - t1)
        n = late_sends(d)
        if n is not None and n >= len(socks):
            cut_at = time.monotonic() - t1
            break
        time.sleep(1.0)
    return cut_at


def s6_half_bodies(d, limit):
    """100 connections each announcing 8 MiB and sending half of it."""
    t0 = time.monotonic()
    deadline = t0 + limit
    n, total = 100, 8 * MIB
    head = (b"POST /v1/signature HTTP/1.1\r\nHost: x\r\n"
            b"Content-Type: application/json\r\nContent-Length: %d\r\n\r\n"
            % total)
    half = b'{"curve":{"type":"points","points":[' + \
        b"[0,0]," * ((total // 2 - 40) // 6)
    ends = [None] * n

    def one(i):
        s = socket.socket()
        try:
            s.settimeout(10)
            s.connect((HOST, d.port))
            try:
                s.sendall(head + half)
            except socket.timeout:
                pass  # the server stopped reading: wait for its verdict
            buf = b""
            while time.monotonic() < deadline:
                s.settimeout(max(0.05, deadline - time.monotonic()))
                try:
                    b = s.recv(4096)
                except socket.timeout:
                    break
                if not b:
                    ends[i] = (status_of(buf) or "closed",
                               time.monotonic() - t0)
                    return
                buf += b
                if status_of(buf) and b"\r\n\r\n" in buf:
                    ends[i] = (status_of(buf), time.monotonic() - t0)
                    return
        except OSError:
            ends[i] = ("reset", time.monotonic() - t0)
        finally:
            s.close()
    ts = [threading.Thread(target=one, args=(i,)) for i in range(n)]
    for t in ts:
        t.start()
    for t in ts:
        t.join(timeout=limit + 15)
    return tally(ends, n)


def tally(ends, n):
    """Seconds until every connection was answered or refused (None if some
    were still open at the limit) and the outcomes counted, each with the
    time of its last one."""
    counts, last = {}, {}
    for e in ends:
        k = str(e[0]) if e else "still open"
        counts[k] = counts.get(k, 0) + 1
        if e:
            last[k] = max(last.get(k, 0.0), e[1])
    done = [e[1] for e in ends if e]
    return {"seconds": max(done) if len(done) == n else None,
            "answers": ", ".join(
                "%d %s" % (c, k) + (" by %.1f s" % last[k] if k in last
                                    else "")
                for k, c in sorted(counts.items()))}


def flood_body(size, per_array=100000):
    """Just under size bytes of [0,0] pairs as the points of a curve, in
    groups of per_array pairs (an array of groups), so that no one array
    is longer than a parser's per-array bound: about one JSON value per two
    bytes, all to be parsed before the shape can be refused."""
    pre, post = b'{"curve":{"type":"points","points":[', b"]}}"
    group = b"[" + b",".join([b"[0,0]"] * per_array) + b"]"
    room = size - len(pre) - len(post)
    n_full = (room + 1) // (len(group) + 1)
    parts = [group] * n_full
    left = room - n_full * (len(group) + 1)
    if left > 8:
        parts.append(b"[" + b",".join([b"[0,0]"] * ((left - 2) // 6)) + b"]")
    data = pre + b",".join(parts) + post
    return data, (len(data) - len(pre)) // 6


def s7_json_flood(d, limit):
    """One body of just under 8 MiB of dense JSON numbers."""
    data, pairs = flood_body(8 * MIB)
    r = exchange(d.port, post_bytes("/v1/signature", data),
                 time.monotonic() + limit, keep=4096)
    return {"seconds": r["seconds"] if r["status"] is not None else None,
            "answers": kind(r),
            "note": "about %d [0,0] pairs in %d bytes" % (pairs, len(data))}


def s8_slowloris(d, limit):
    """600 sockets sending one header byte every 2 s for 20 s."""
    t0 = time.monotonic()
    deadline = t0 + limit
    msg = b"GET /healthz HTTP/1.1\r\nHost: x\r\nX-Pad: " + b"a" * 64
    sel = selectors.DefaultSelector()
    conns = []
    for _ in range(600):
        s = socket.socket()
        s.setblocking(False)
        try:
            s.connect((HOST, d.port))
        except BlockingIOError:
            pass
        except OSError:
            s.close()
            continue
        c = {"s": s, "buf": b"", "end": None}
        conns.append(c)
        sel.register(s, selectors.EVENT_READ, c)
    sent = 0
    next_send = time.monotonic()
    while time.monotonic() < deadline:
        now = time.monotonic()
        if sent < 10 and now >= next_send:
            for c in conns:
                if c["end"] is None:
                    try:
                        c["s"].send(msg[sent:sent + 1])
                    except BlockingIOError:
                        pass
                    except OSError:
                        pass  # not connected yet or refused: read tells
            sent += 1
            next_send += 2.0
        if sent >= 10 and all(c["end"] for c in conns):
            break
        until = min(next_send, deadline) if sent < 10 else deadline
        wait = min(0.5, max(0.01, until - time.monotonic()))
        for key, _ in sel.select(timeout=wait):
            c = key.data
            try:
                b = c["s"].recv(4096)
            except BlockingIOError:
                continue
            except OSError:
                b = None
            if b:
                c["buf"] += b
                if b"\r\n\r\n" not in c["buf"]:
                    continue
            c["end"] = ((status_of(c["buf"]) or
                         ("closed" if b is not None else "reset")),
                        time.monotonic() - t0)
            sel.unregister(c["s"])
    for c in conns:
        c["s"].close()
    sel.close()
    out = tally([c["end"] for c in conns], len(conns))
    out["note"] = "%d of 600 connected" % len(conns)
    return out


SCENARIOS = [
    ("s1", "tiny morph, huge answer (1,000 frames at 1e-9)", [],
     s1_huge_answer),
    ("s2", "the same as a job, then GET its result", [], s2_huge_job),
    ("s3", "heavy preparation (2 x 2,000 wavy points, auto matches) + "
     "a small morph behind it", ["--threads", "1", "--morph-time", "5"],
     s3_heavy_prepare),
    ("s4", "heavy /v1/signature (99,000 points at 1e-11)",
     ["--compute-time", "5"], s4_heavy_signature),
    ("s5", "8 slow readers (4 KiB buffer, 1 KiB/s) of a job result",
     ["--send-time", "10"], s5_slow_readers),
    ("s6", "100 connections, Content-Length 8 MiB, half sent",
     ["--request-time", "20"], s6_half_bodies),
    ("s7", "one 8 MiB body of dense JSON numbers", [], s7_json_flood),
    ("s8", "600 sockets, one header byte every 2 s for 20 s", [],
     s8_slowloris),
]


# ------------------------------------------------------------------ main

def run_one(path, known, sc, limit, mem_cap):
    name, title, flags, fn = sc
    keep, dropped, i = [], [], 0
    while i < len(flags):
        f = flags[i]
        has_value = i + 1 < len(flags) and not flags[i + 1].startswith("--")
        pair = flags[i:i + 2] if has_value else flags[i:i + 1]
        (keep if f in known else dropped).extend(pair)
        i += len(pair)
    d = Daemon(path, keep, mem_cap)
    try:
        time.sleep(0.3)
        idle = d.status_kb()[0]
        prober = Prober(d.port)
        try:
            res = fn(d, limit)
        except Exception as e:  # a broken scenario must not hide the rest
            res = {"seconds": None, "answers": "error: %r" % (e,)}
        probes = prober.finish()
        alive = d.alive()
        d.update()
        res.update({"name": name, "title": title, "flags": keep,
                    "dropped": dropped, "idle_mib": idle / 1024,
                    "peak_mib": d.hwm_kb / 1024, "probes": probes,
                    "alive": alive,
                    "exit": None if alive else d.proc.returncode})
        return res
    finally:
        d.stop()


def fmt_seconds(v, limit):
    return "> %g s" % limit if v is None else "%.1f s" % v


def table(results, limit):
    rows = ["| scenario | flags | peak RSS | time | answers | probes ok "
            "(slowest) | notes |",
            "|---|---|---:|---:|---|---|---|"]
    for r in results:
        flags = " ".join(r["flags"]) or "-"
        if r["dropped"]:
            flags += " (not in --help: %s)" % " ".join(r["dropped"])
        note = r.get("note", "")
        if not r["alive"]:
            note += ("; " if note else "") + \
                "daemon died (exit %s)" % r["exit"]
        p = r["probes"]
        rows.append("| %s %s | %s | %.0f MiB | %s | %s | %d/%d (%.2f s) | "
                    "%s |" % (r["name"], r["title"], flags, r["peak_mib"],
                              fmt_seconds(r["seconds"], limit),
                              r["answers"], p["ok"], p["sent"], p["slowest"],
                              note))
    return "\n".join(rows)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--daemon", default=os.path.join(
        os.path.dirname(os.path.abspath(__file__)), "..", "build",
        "kmorphd"))
    ap.add_argument("--only", default="",
                    help="comma-separated scenario names (s1..s8)")
    ap.add_argument("--limit", type=float, default=60.0,
                    help="seconds before a scenario gives up")
    ap.add_argument("--mem-cap", type=int, default=4096,
                    help="daemon address space in MiB (0: none)")
    ap.add_argument("--json", help="also write the results here")
    a = ap.parse_args()
    known = help_flags(a.daemon)
    want = set(a.only.split(",")) if a.only else None
    results = []
    for sc in SCENARIOS:
        if want and sc[0] not in want:
            continue
        r = run_one(a.daemon, known, sc, a.limit, a.mem_cap)
        print("%s: peak %.0f MiB, %s, %s, probes %d/%d" % (
            r["name"], r["peak_mib"], fmt_seconds(r["seconds"], a.limit),
            r["answers"], r["probes"]["ok"], r["probes"]["sent"]),
            file=sys.stderr, flush=True)
        results.append(r)
    print(table(results, a.limit))
    if a.json:
        with open(a.json, "w", encoding="utf-8") as f:
            json.dump(results, f, indent=1)


if __name__ == "__main__":
    main()
