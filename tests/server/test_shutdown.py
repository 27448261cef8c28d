"""test_shutdown.py - SIGTERM drains and exits 0 within the grace period,
also while a job is running and while a request computes: new
connections are refused at once, open ones are told 503 on /readyz, and
computations still running when the grace ends are stopped and answered
503."""
import http.client
import shutil
import subprocess
import tempfile
import json
import signal
import socket
import struct
import threading
import time
import unittest

from kmtest import (HOST, ContractCase, Daemon, Reply, heavy_morph_body,
                    ring_morph_body, wait_for)


class GracefulShutdown(ContractCase):
    def test_sigterm_during_a_running_job_exits_0_within_the_grace(self):
        d = Daemon("--threads", "2", "--shutdown-grace", "5")
        try:
            r = d.request("POST", "/v1/jobs", body=ring_morph_body(1000))
            self.assertEqual(r.status, 202, r.body[:300])
            jid = r.json()["id"]
            self.assertTrue(wait_for(lambda: d.request(
                "GET", "/v1/jobs/" + jid).json()["state"] == "running", 10))
            rc, dt = d.terminate(timeout=20)
            self.assertEqual(rc, 0, d.text()[-2000:])
            self.assertLess(dt, 5.0)
            self.assertIn("kmorphd: stopped", d.text())
        finally:
            d.stop()

    def test_sigterm_lets_a_computing_request_answer(self):
        d = Daemon("--threads", "1", "--shutdown-grace", "10")
        try:
            out = {}

            def client():
                out["r"] = d.request("POST", "/v1/morph",
                                     body=ring_morph_body(400), timeout=30)

            t = threading.Thread(target=client)
            t.start()
            self.assertTrue(wait_for(
                lambda: "kmorph_workers_busy 1" in d.request(
                    "GET", "/metrics").body.decode(), 10))
            rc, dt = d.terminate(timeout=30)
            t.join(timeout=30)
            self.assertEqual(rc, 0)
            self.assertLess(dt, 10.0)
            self.assertIn(out["r"].status, (200, 503))
            if out["r"].status == 200:
                self.assertEqual(len(out["r"].json()["frames"]), 400)
        finally:
            d.stop()

    @unittest.skipUnless(shutil.which("wrk"), "needs wrk")
    def test_clients_that_leave_mid_compute_do_not_hold_the_shutdown(self):
        # wrk stops with requests in flight on its keep-alive connections:
        # those connections are closed while suspended for compute.
        d = Daemon("--threads", "2", "--queue", "1024",
                   "--shutdown-grace", "10", "--access-log", "0")
        try:
            with tempfile.NamedTemporaryFile("w", suffix=".lua") as lua:
                lua.write('wrk.method = "POST"\n'
                          'wrk.headers["Content-Type"] = "application/json"\n'
                          "wrk.body = [==[%s]==]\n"
                          % json.dumps(heavy_morph_body(30)))
                lua.flush()
                subprocess.run(["wrk", "-t", "2", "-c", "16", "-d", "2s",
                                "-s", lua.name,
                                "http://%s:%d/v1/morph" % (HOST, d.port)],
                               capture_output=True, timeout=60, check=True)
            rc, dt = d.terminate(timeout=20)
            self.assertEqual(rc, 0)
            self.assertLess(dt, 3.0)
            self.assertNotIn("forced", d.text())
        finally:
            d.stop()

    def test_draining_refuses_new_connections_and_answers_open_ones(self):
        # Given a synchronous morph of a few seconds computing, and a
        # keep-alive connection opened before the stop,
        d = Daemon("--threads", "1", "--shutdown-grace", "20",
                   "--max-frames", "100000", "--max-output", "1000000000")
        try:
            keep = http.client.HTTPConnection(HOST, d.port, timeout=5)
            keep.request("GET", "/healthz")
            self.assertEqual(keep.getresponse().read(), b'{"status":"ok"}')
            out = {}

            def client():
                out["r"] = d.request("POST", "/v1/morph",
                                     body=ring_morph_body(400), timeout=60)

            t = threading.Thread(target=client)
            t.start()
            self.assertTrue(wait_for(
                lambda: "kmorph_workers_busy 1" in d.request(
                    "GET", "/metrics").body.decode(), 10))
            # when SIGTERM starts the drain,
            d.proc.send_signal(signal.SIGTERM)
            self.assertTrue(wait_for(lambda: "shutting down" in d.text(), 5))

            def refused():
                try:
                    socket.create_connection((HOST, d.port), timeout=1).close()
                    return False
                except ConnectionRefusedError:
                    return True
            # then a new connection is refused at once (load balancers
            # move on; nothing waits in an unserved backlog),
            self.assertTrue(wait_for(refused, 1.0),
                            "new connections are still accepted")
            # the open connection is told the instance is not ready and
            # is closed after the answer,
            keep.request("GET", "/readyz")
            raw = keep.getresponse()
            reply = Reply(raw.status, raw.getheaders(), raw.read())
            self.assertProblem(reply, 503, "/readyz", "GET")
            self.assertEqual((reply.header("Connection") or "").lower(),
                             "close")
            keep.close()
            # and the morph in flight still gets its whole answer.
            t.join(timeout=60)
            self.assertEqual(out["r"].status, 200, out["r"].body[:300])
            self.assertEqual(len(out["r"].json()["frames"]), 400)
            self.assertEqual(d.proc.wait(timeout=20), 0)
        finally:
            d.stop()

    def test_the_end_of_the_grace_stops_computations_and_answers_503(self):
        # Given two synchronous morphs that would compute for many
        # seconds, and a grace of 1 s,
        d = Daemon("--threads", "2", "--shutdown-grace", "1",
                   "--max-frames", "1000000", "--max-output", "1000000000",
                   "--morph-time", "600")
        try:
            out = [None, None]

            def client(i):
                try:
                    out[i] = d.request("POST", "/v1/morph",
                                       body=ring_morph_body(4000),
                                       headers={"X-Request-Id": "late-%d" % i},
                                       timeout=60)
                except OSError as e:
                    out[i] = e
            ts = [threading.Thread(target=client, args=(i,)) for i in (0, 1)]
            for t in ts:
                t.start()
            self.assertTrue(wait_for(
                lambda: "kmorph_workers_busy 2" in d.request(
                    "GET", "/metrics").body.decode(), 10))
            # when SIGTERM comes and the grace runs out,
            rc, dt = d.terminate(timeout=20)
            for t in ts:
                t.join(timeout=20)
            # then each computation is stopped and its client answered
            # 503 (no connection closed without an answer), and the daemon
            # exits 0 soon after the grace, not forced.
            for i, r in enumerate(out):
                self.assertNotIsInstance(r, OSError, "client %d: %r" % (i, r))
                doc = self.assertProblem(r, 503, "/v1/morph", "POST",
                                         rid="late-%d" % i)
                self.assertEqual(doc["type"], "/problems/shutting-down")
            self.assertEqual(rc, 0)
            self.assertLess(dt, 1.0 + 2.0 + 1.0)
            self.assertNotIn("forced", d.text())
        finally:
            d.stop()

    def test_sigint_also_stops_with_status_0(self):
        d = Daemon("--threads", "1")
        try:
            d.proc.send_signal(signal.SIGINT)
            self.assertEqual(d.proc.wait(timeout=15), 0)
        finally:
            d.stop()


if __name__ == "__main__":
    unittest.main()
