"""test_shutdown.py - SIGTERM drains and exits 0 within the grace period,
also while a job is running and while a request computes."""
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

from kmtest import HOST, ContractCase, Daemon, heavy_morph_body, wait_for


class GracefulShutdown(ContractCase):
    def test_sigterm_during_a_running_job_exits_0_within_the_grace(self):
        d = Daemon("--threads", "2", "--shutdown-grace", "5")
        try:
            r = d.request("POST", "/v1/jobs", body=heavy_morph_body(10000))
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
                                     body=heavy_morph_body(400), timeout=30)

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

    def test_sigint_also_stops_with_status_0(self):
        d = Daemon("--threads", "1")
        try:
            d.proc.send_signal(signal.SIGINT)
            self.assertEqual(d.proc.wait(timeout=15), 0)
        finally:
            d.stop()


if __name__ == "__main__":
    unittest.main()
