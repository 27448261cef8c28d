"""test_load.py - many clients at once: every request answered with its
own answer; a full queue refuses at once with Retry-After; a trickling
client is cut off and does not hold up others."""
import math
import threading
import time
import unittest
from concurrent.futures import ThreadPoolExecutor

from kmtest import (ContractCase, Daemon, circle_svg, close_to,
                    metric, morph_body, raw_exchange, ring_morph_body,
                    request, schema_errors, component)


class Concurrency(ContractCase):
    @classmethod
    def setUpClass(cls):
        cls.d = Daemon("--threads", "2", "--queue", "256",
                       "--access-log", "0")

    @classmethod
    def tearDownClass(cls):
        cls.d.stop()

    def one(self, i):
        """Request i of a mix; returns (i, error or None). Each kind checks
        a number that only its own request can produce."""
        rid = "mix-%d" % i
        kind = i % 5
        try:
            if kind == 0:
                r = self.d.request("GET", "/healthz",
                                   headers={"X-Request-Id": rid})
                ok = r.status == 200 and r.json()["status"] == "ok"
            elif kind == 1:
                radius = 1 + i / 100
                r = self.d.request("POST", "/v1/signature",
                                   body={"curve": circle_svg(radius)},
                                   headers={"X-Request-Id": rid})
                ok = r.status == 200 and close_to(
                    r.json()["signature"]["length"], 2 * math.pi * radius,
                    1e-6)
            elif kind == 2:
                frames = 2 + i % 7
                r = self.d.request("POST", "/v1/morph", body=morph_body(frames),
                                   headers={"X-Request-Id": rid})
                ok = r.status == 200 and len(r.json()["frames"]) == frames
            elif kind == 3:
                r = self.d.request("POST", "/v1/morph", body=b"{bad",
                                   headers={"X-Request-Id": rid})
                ok = r.status == 400 and r.json()["request_id"] == rid
            else:
                r = self.d.request("GET", "/openapi.json",
                                   headers={"X-Request-Id": rid})
                ok = r.status == 200 and r.json()["openapi"].startswith("3.")
            if r.header("X-Request-Id") != rid:
                return i, "request id %r came back as %r" % (
                    rid, r.header("X-Request-Id"))
            return i, None if ok else "status %d: %r" % (r.status,
                                                          r.body[:200])
        except Exception as e:  # noqa: BLE001 - any failure is reported
            return i, repr(e)

    def test_200_mixed_requests_from_16_clients_all_answered_correctly(self):
        with ThreadPoolExecutor(max_workers=16) as ex:
            results = list(ex.map(self.one, range(200), timeout=120))
        errors = [(i, e) for i, e in results if e]
        self.assertEqual(len(results), 200)
        self.assertEqual(errors, [])
        m = self.d.request("GET", "/metrics").body.decode()
        self.assertEqual(metric(m, "kmorph_queue_depth"), 0)
        total = sum(float(l.rsplit(" ", 1)[1]) for l in m.splitlines()
                    if l.startswith("kmorph_http_requests_total{"))
        self.assertGreaterEqual(total, 200)


class Overload(ContractCase):
    @classmethod
    def setUpClass(cls):
        cls.d = Daemon("--threads", "1", "--queue", "1", "--retry-after", "2")

    @classmethod
    def tearDownClass(cls):
        cls.d.stop()

    def test_full_queue_refuses_at_once_and_mixes_up_nothing(self):
        n = 12
        barrier = threading.Barrier(n)

        def client(i):
            frames = 80 + i  # the answer's frame count identifies it
            rid = "load-%d" % i
            barrier.wait(timeout=10)
            t0 = time.monotonic()
            r = self.d.request("POST", "/v1/morph",
                               body=ring_morph_body(frames),
                               headers={"X-Request-Id": rid}, timeout=120)
            return i, frames, rid, r, time.monotonic() - t0

        with ThreadPoolExecutor(max_workers=n) as ex:
            results = list(ex.map(client, range(n), timeout=300))
        self.assertEqual(len(results), n, "every client got an answer")
        served = refused = 0
        fastest_refusal = None
        for i, frames, rid, r, dt in results:
            self.assertEqual(r.header("X-Request-Id"), rid)
            if r.status == 200:
                served += 1
                self.assertEqual(len(r.json()["frames"]), frames,
                                 "client %d got someone else's answer" % i)
            else:
                refused += 1
                self.assertIn(r.status, (429, 503))
                self.assertEqual(r.header("Retry-After"), "2")
                doc = r.json()
                self.assertEqual(schema_errors(doc, component("Problem")), [])
                self.assertEqual(doc["request_id"], rid)
                fastest_refusal = dt if fastest_refusal is None else min(
                    fastest_refusal, dt)
        # One worker and one queue slot: at least one is served, and the
        # others (arriving together) cannot all fit.
        self.assertGreaterEqual(served, 1)
        self.assertGreaterEqual(refused, 1)
        self.assertLess(fastest_refusal, 1.0, "a refusal does not wait")
        m = self.d.request("GET", "/metrics").body.decode()
        self.assertEqual(metric(m, "kmorph_rejected_total",
                                {"reason": "queue_full"}), refused)


class SlowClient(ContractCase):
    @classmethod
    def setUpClass(cls):
        cls.d = Daemon("--threads", "1", "--io-threads", "1",
                       "--timeout", "2", "--request-time", "1.5")

    @classmethod
    def tearDownClass(cls):
        cls.d.stop()

    def test_trickling_body_is_cut_off_and_others_are_served_meanwhile(self):
        body = b'{"curve": {"type": "svg", "d": "M 0 0 L 1 0 L 1 1 Z"}}'
        head = (b"POST /v1/signature HTTP/1.1\r\nHost: x\r\n"
                b"Content-Type: application/json\r\n"
                b"Content-Length: %d\r\n\r\n" % len(body))
        out = {}

        def slow():
            t0 = time.monotonic()
            chunks = [head] + [body[k:k + 1] for k in range(len(body))]
            out["raw"] = raw_exchange(self.d.port, chunks, timeout=20,
                                      pause=0.1)
            out["dt"] = time.monotonic() - t0

        t = threading.Thread(target=slow)
        t.start()
        # While it trickles, other clients get quick answers (one I/O
        # thread, one worker: nothing is held by the slow client).
        time.sleep(0.3)
        latencies = []
        for _ in range(10):
            t0 = time.monotonic()
            r = self.d.request("POST", "/v1/signature",
                               body={"curve": circle_svg(1.0)}, timeout=10)
            latencies.append(time.monotonic() - t0)
            self.assertEqual(r.status, 200)
        t.join(timeout=30)
        self.assertFalse(t.is_alive())
        self.assertLess(max(latencies), 1.0)
        # The whole body would take ~5.5 s; the limit is 1.5 s.
        self.assertLess(out["dt"], 4.0, "cut off near the request time")
        self.assertFalse(out["raw"].startswith(b"HTTP/1.1 200"))
        self.assertIn('closed="request time limit"', self.d.text())

    def test_silent_client_is_closed_by_the_idle_timeout(self):
        t0 = time.monotonic()
        raw = raw_exchange(self.d.port, b"POST /v1/morph HTTP/1.1\r\nHo",
                           timeout=10)
        dt = time.monotonic() - t0
        self.assertEqual(raw, b"")
        self.assertLess(dt, 5.0)
        self.assertGreater(dt, 1.5)


if __name__ == "__main__":
    unittest.main()
