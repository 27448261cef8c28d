"""test_bounds.py - every request's time, memory and connection slot is
bounded, as a hostile client would test it: compute time limits that hold
inside a computation and stop work for a client that left, result memory
within its budget (410 for what was let go), answers sent without copies,
bodies in flight within their budget, and header slowloris answered 408
while probes keep being served."""
import json
import os
import socket
import threading
import time
import unittest

from kmtest import (HOST, ContractCase, Daemon, circle_svg, metric, request,
                    raw_status, square_svg, wait_for)


def wavy_points(n, amp=0.3, waves=40):
    """A closed polygon of n points on a wavy circle: costly to morph with
    automatic matches and metrics at a tight tolerance."""
    import math
    pts = []
    for k in range(n):
        a = 2 * math.pi * k / n
        r = 10 * (1 + amp * math.sin(waves * a))
        pts.append([r * math.cos(a), r * math.sin(a)])
    return {"type": "points", "points": pts, "closed": True}


def wavy_bspline(n, amp, waves):
    """An open cubic B-spline whose n control points lie on a wavy circle:
    a signature of many pieces at a tight tolerance."""
    import math
    pts = []
    for k in range(n):
        a = 2 * math.pi * k / n
        r = 10 * (1 + amp * math.sin(waves * a))
        pts.append([r * math.cos(a), r * math.sin(a)])
    knots = [0] * 4 + list(range(1, n - 3)) + [n - 3] * 4
    return {"type": "bspline", "degree": 3, "knots": knots,
            "control_points": pts, "closed": False}


def heavy_prepare_body(frames=2):
    """A morph whose preparation alone takes seconds (two wavy outlines of
    2,000 points at 1e-9 with automatic matches)."""
    return {"from": wavy_points(2000), "to": wavy_points(2000, 0.25, 37),
            "frames": frames, "tolerance": 1e-9, "matches": "auto",
            "metrics": True}


def connect_from(addr, port, timeout=10.0):
    """A TCP connection to the daemon from a chosen loopback address, so
    that tests can stand for clients of different addresses."""
    s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    s.settimeout(timeout)
    s.bind((addr, 0))
    s.connect((HOST, port))
    return s


def get_from(addr, port, path, timeout=10.0):
    """GET path from a chosen address; (status or None, seconds)."""
    t0 = time.monotonic()
    try:
        s = connect_from(addr, port, timeout)
        s.sendall(("GET %s HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n"
                   % path).encode())
        out = b""
        while True:
            b = s.recv(65536)
            if not b:
                break
            out += b
        s.close()
        return raw_status(out), time.monotonic() - t0
    except OSError:
        return None, time.monotonic() - t0


class ComputeTime(ContractCase):
    """Time limits hold inside a computation, on every compute route: a
    request whose preparation alone takes T is stopped near its limit of
    0.05 s, not after T (the limits were checked only between frames)."""

    LIMIT = 0.05
    # 20,000 spans with twice the waves: about 0.6 s unlimited (10,000
    # spans came down to 0.27 s as reconstruction and printing got faster)
    SIGNATURE = {"curve": wavy_bspline(20000, 0.2, 400), "tolerance": 1e-9}

    @classmethod
    def setUpClass(cls):
        cls.d = Daemon("--threads", "1", "--morph-time", str(cls.LIMIT),
                       "--compute-time", str(cls.LIMIT),
                       "--job-time", str(cls.LIMIT))
        free = Daemon("--threads", "1")
        try:
            t0 = time.monotonic()
            r = free.request("POST", "/v1/morph", body=heavy_prepare_body(),
                             timeout=120)
            cls.heavy_time = time.monotonic() - t0
            cls.heavy_status = r.status
            t0 = time.monotonic()
            r = free.request("POST", "/v1/signature", body=cls.SIGNATURE,
                             timeout=120)
            cls.signature_time = time.monotonic() - t0
            cls.signature_status = r.status
        finally:
            free.stop()

    @classmethod
    def tearDownClass(cls):
        cls.d.stop()

    def assertStoppedInTime(self, path, body):
        self.assertEqual(self.heavy_status, 200)
        self.assertGreater(self.heavy_time, 0.3, "the heavy request must "
                           "take long enough to tell (took %.2f s)"
                           % self.heavy_time)
        t0 = time.monotonic()
        r = self.d.request("POST", path, body=body, timeout=60)
        dt = time.monotonic() - t0
        doc = self.assertProblem(r, 422, path, "post")
        self.assertEqual(doc["type"], "/problems/limit-exceeded")
        bound = self.heavy_time / 2
        self.assertLess(dt, bound, "answered %.3f s after a %g s limit "
                        "(unlimited: %.2f s)" % (dt, self.LIMIT,
                                                 self.heavy_time))
        return doc

    def test_preparing_a_morph_stops_at_the_morph_time(self):
        doc = self.assertStoppedInTime("/v1/morph", heavy_prepare_body())
        self.assertIn("KMORPH_MORPH_TIME", doc["detail"])

    def test_posting_a_job_stops_at_the_job_time(self):
        doc = self.assertStoppedInTime("/v1/jobs", heavy_prepare_body())
        self.assertIn("KMORPH_JOB_TIME", doc["detail"])

    def test_a_signature_stops_at_the_compute_time(self):
        self.assertGreater(self.signature_time, 0.3)
        t0 = time.monotonic()
        r = self.d.request("POST", "/v1/signature", body=self.SIGNATURE,
                           timeout=60)
        dt = time.monotonic() - t0
        doc = self.assertProblem(r, 422, "/v1/signature", "post")
        self.assertIn("KMORPH_COMPUTE_TIME", doc["detail"])
        self.assertLess(dt, self.signature_time / 2, "answered %.3f s after "
                        "a %g s limit (unlimited: %.2f s)"
                        % (dt, self.LIMIT, self.signature_time))

    def test_a_small_request_behind_a_stopped_one_waits_little(self):
        out = {}

        def heavy():
            out["r"] = self.d.request("POST", "/v1/morph",
                                      body=heavy_prepare_body(), timeout=60)
        t = threading.Thread(target=heavy)
        t.start()
        time.sleep(0.02)
        t0 = time.monotonic()
        r = self.d.request("POST", "/v1/signature",
                           body={"curve": circle_svg(1.0)})
        dt = time.monotonic() - t0
        t.join(timeout=60)
        self.assertEqual(r.status, 200)
        self.assertLess(dt, self.heavy_time / 2,
                        "one worker: the small request waited %.3f s "
                        "behind a %g s limit" % (dt, self.LIMIT))


class ClientLeaves(ContractCase):
    """A client that leaves stops its work, inside the computation: the
    one worker is free again well before the computation would end."""

    def test_work_stops_when_the_client_closes(self):
        d = Daemon("--threads", "1", "--morph-time", "120")
        try:
            t0 = time.monotonic()
            r = d.request("POST", "/v1/morph", body=heavy_prepare_body(),
                          timeout=120)
            heavy = time.monotonic() - t0
            self.assertEqual(r.status, 200)
            self.assertGreater(heavy, 0.3)
            data = json.dumps(heavy_prepare_body()).encode()
            s = socket.create_connection((HOST, d.port))
            s.sendall(("POST /v1/morph HTTP/1.1\r\nHost: x\r\n"
                       "Content-Type: application/json\r\n"
                       "Content-Length: %d\r\n\r\n" % len(data)).encode()
                      + data)
            time.sleep(0.05)
            s.close()
            t0 = time.monotonic()
            r = d.request("POST", "/v1/signature",
                          body={"curve": circle_svg(1.0)}, timeout=60)
            dt = time.monotonic() - t0
            self.assertEqual(r.status, 200)
            self.assertLess(dt, heavy / 2, "the worker was freed %.3f s "
                            "after the client left (the work takes %.2f s)"
                            % (dt, heavy))
        finally:
            d.stop()


class ResultMemory(ContractCase):
    """Kept results stay within their byte budget; what was let go is 410
    with the reason; results are sent from one shared copy."""

    def test_oldest_results_are_evicted_and_answer_410(self):
        d = Daemon("--result-memory", "400000", "--job-keep", "100")
        try:
            body = {"from": circle_svg(1.0), "to": square_svg(2.0),
                    "frames": 40}
            ids = []
            for _ in range(12):
                r = d.request("POST", "/v1/jobs", body=body)
                self.assertEqual(r.status, 202, r.body[:200])
                jid = r.json()["id"]
                self.assertTrue(wait_for(lambda: d.request(
                    "GET", "/v1/jobs/" + jid).json()["state"] == "done", 20))
                ids.append(jid)
            sizes = []
            gone = []
            for jid in ids:
                r = d.request("GET", "/v1/jobs/%s/result" % jid)
                if r.status == 200:
                    sizes.append(len(r.body))
                else:
                    doc = self.assertProblem(r, 410, "/v1/jobs/{id}/result",
                                             "get")
                    self.assertIn("KMORPH_RESULT_MEMORY", doc["detail"])
                    gone.append(jid)
                    st = d.request("GET", "/v1/jobs/" + jid)
                    self.assertEqual(st.json()["state"], "done")
            self.assertTrue(sizes and gone, "some kept, some evicted")
            self.assertLessEqual(sum(sizes), 400000)
            self.assertEqual(gone, ids[:len(gone)], "oldest first")
            self.assertIn(ids[-1], ids[len(gone):])
        finally:
            d.stop()

    def test_slow_readers_share_the_result(self):
        d = Daemon("--access-log", "0")
        try:
            # frames of some 2 KB each: 6,000 make some 12 MB (at 1e-4
            # compact frames are half that: the readers' buffers, not
            # the result, then dominate the growth under ASan)
            body = {"from": circle_svg(10.0), "to": square_svg(15.0),
                    "frames": 6000, "tolerance": 1e-6}
            r = d.request("POST", "/v1/jobs", body=body)
            self.assertEqual(r.status, 202, r.body[:300])
            jid = r.json()["id"]
            self.assertTrue(wait_for(lambda: d.request(
                "GET", "/v1/jobs/" + jid).json()["state"] == "done", 60))
            size = len(d.request("GET", "/v1/jobs/%s/result" % jid).body)
            self.assertGreater(size, 4 << 20)
            time.sleep(0.3)
            rss0 = d.rss_kb()
            readers = []
            for _ in range(8):
                s = socket.socket()
                s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
                s.connect((HOST, d.port))
                s.sendall(("GET /v1/jobs/%s/result HTTP/1.1\r\nHost: x\r\n"
                           "\r\n" % jid).encode())
                readers.append(s)
            time.sleep(1.0)
            rss1 = d.rss_kb()
            for s in readers:
                s.close()
            grown = (rss1 - rss0) * 1024
            self.assertLess(grown, size, "8 slow readers of a %d-byte result "
                            "grew the daemon by %d bytes" % (size, grown))
        finally:
            d.stop()

    def test_a_reader_that_stops_reading_is_cut_at_the_send_time(self):
        # The answer (some 16 MB) is larger than what socket buffers hold
        # (at 1e-4 it was 35 MB before frames were made compact, 11 MB
        # after).
        d = Daemon("--send-time", "1")
        try:
            body = {"from": circle_svg(10.0), "to": square_svg(15.0),
                    "frames": 8000, "tolerance": 1e-6}
            r = d.request("POST", "/v1/jobs", body=body)
            self.assertEqual(r.status, 202, r.body[:300])
            jid = r.json()["id"]
            self.assertTrue(wait_for(lambda: d.request(
                "GET", "/v1/jobs/" + jid).json()["state"] == "done", 120))
            full = len(d.request("GET", "/v1/jobs/%s/result" % jid).body)
            self.assertGreater(full, 12 << 20)
            s = socket.socket()
            s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
            s.connect((HOST, d.port))
            s.sendall(("GET /v1/jobs/%s/result HTTP/1.1\r\nHost: x\r\n"
                       "\r\n" % jid).encode())
            time.sleep(3.0)
            s.settimeout(5)
            got = 0
            try:
                while True:
                    b = s.recv(65536)
                    if not b:
                        break
                    got += len(b)
            except OSError:
                pass
            s.close()
            self.assertLess(got, full, "the answer was cut (%d of %d bytes)"
                            % (got, full))
        finally:
            d.stop()


class BodyMemory(ContractCase):
    """Bodies in flight share one budget: past it, 503 naming it."""

    def test_bodies_past_the_budget_get_503(self):
        # Two unfinished bodies declare 1,000,000 bytes each, counted
        # before they are read; a third declaring some 700 kB does not fit
        # 2,500,000 and is refused at once, before its body is sent.
        d = Daemon("--body-memory", "2500000")
        try:
            holders = []
            for _ in range(2):
                s = socket.create_connection((HOST, d.port))
                s.sendall(b"POST /v1/signature HTTP/1.1\r\nHost: x\r\n"
                          b"Content-Type: application/json\r\n"
                          b"Content-Length: 1000000\r\n\r\n" +
                          b"x" * 500000)
                holders.append(s)
            time.sleep(0.5)
            big = json.dumps({"curve": {
                "type": "points", "closed": False,
                "points": [[i, (i * 7) % 13] for i in range(60000)]}})
            self.assertGreater(len(big), 600000)
            s = socket.create_connection((HOST, d.port))
            s.settimeout(10)
            t0 = time.monotonic()
            s.sendall(("POST /v1/signature HTTP/1.1\r\nHost: x\r\n"
                       "Content-Type: application/json\r\n"
                       "Content-Length: %d\r\n\r\n" % len(big)).encode())
            head = s.recv(65536)
            dt = time.monotonic() - t0
            s.close()
            self.assertEqual(raw_status(head), 503, head[:200])
            self.assertIn(b"KMORPH_BODY_MEMORY", head)
            self.assertLess(dt, 2.0, "refused before the body was sent")
            doc = json.loads(head.split(b"\r\n\r\n", 1)[1])
            self.assertEqual(doc["type"], "/problems/overloaded")
            m = d.request("GET", "/metrics").body.decode()
            self.assertEqual(
                metric(m, "kmorph_rejected_total", {"reason": "body_memory"}),
                1)
            for s in holders:
                s.close()
            time.sleep(0.3)
            r = d.request("POST", "/v1/signature",
                          body={"curve": circle_svg(1.0)})
            self.assertEqual(r.status, 200, "the budget is given back")
        finally:
            d.stop()


class Slowloris(ContractCase):
    """Clients trickling their headers are answered 408 at the header
    time; one address cannot take every slot; probes are answered from
    reserved slots when every ordinary one is taken."""

    def test_trickled_headers_get_408_and_probes_stay_served(self):
        d = Daemon("--header-time", "1.5", "--max-connections", "64",
                   "--per-ip", "32", "--access-log", "0")
        try:
            socks = []
            for _ in range(200):
                try:
                    socks.append(connect_from("127.0.0.1", d.port))
                except OSError:
                    break
            stop = threading.Event()

            def trickle():
                msg = b"GET /healthz HTTP/1.1\r\nHost: x\r\nX-Pad: " + \
                      b"a" * 200
                for k in range(len(msg)):
                    if stop.is_set():
                        return
                    for s in socks:
                        try:
                            s.send(msg[k:k + 1])
                        except OSError:
                            pass
                    time.sleep(0.3)
            t = threading.Thread(target=trickle, daemon=True)
            t.start()
            probes = []
            for _ in range(10):
                probes.append(get_from("127.0.0.2", d.port, "/healthz"))
                time.sleep(0.25)
            time.sleep(1.0)
            stop.set()
            answers = []
            for s in socks:
                s.settimeout(2)
                try:
                    answers.append(raw_status(s.recv(4096)))
                except OSError:
                    answers.append(None)
                s.close()
            self.assertTrue(all(st == 200 and dt < 2.0 for st, dt in probes),
                            "every probe answered at once: %r" % probes)
            self.assertGreater(answers.count(408), 0, "late headers get 408")
            self.assertLessEqual(answers.count(408), 32,
                                 "one address holds at most --per-ip slots")
        finally:
            d.stop()

    def test_probes_are_answered_when_every_slot_is_taken(self):
        d = Daemon("--max-connections", "40", "--per-ip", "8",
                   "--reserved-connections", "4", "--header-time", "30",
                   "--timeout", "30")
        try:
            idle = []
            for k in range(10):
                for _ in range(4):
                    idle.append(connect_from("127.0.0.%d" % (10 + k),
                                             d.port))
            time.sleep(0.5)
            st, dt = get_from("127.0.0.3", d.port, "/healthz")
            self.assertEqual(st, 200)
            self.assertLess(dt, 2.0)
            st, _ = get_from("127.0.0.4", d.port, "/openapi.json")
            self.assertEqual(st, 503, "only probes on a reserved slot")
            for s in idle:
                s.close()
        finally:
            d.stop()


if __name__ == "__main__":
    unittest.main()
