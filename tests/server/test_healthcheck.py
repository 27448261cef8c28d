"""test_healthcheck.py - `kmorphd --healthcheck URL`, the daemon as its own
container health probe: exit 0 when the URL answers 200, 1 for any other
status, a refused or silent port or a peer that does not speak HTTP, 2 for
a URL it cannot use; never longer than its 3 s bound."""
import os
import socket
import subprocess
import sys
import threading
import time
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "pylib"))
import kmdaemon  # noqa: E402

DAEMON = kmdaemon.DAEMON
BOUND = 3.0  # SRV_HEALTHCHECK_SECONDS


def probe(*args):
    t0 = time.monotonic()
    r = subprocess.run([DAEMON, *args], capture_output=True, text=True,
                       timeout=30)
    return r.returncode, r.stderr, time.monotonic() - t0


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Listener:
    """A loopback listener that accepts and then answers `reply` (None:
    nothing, holding the connection open)."""

    def __init__(self, reply):
        self.sock = socket.socket()
        self.sock.bind(("127.0.0.1", 0))
        self.sock.listen(4)
        self.port = self.sock.getsockname()[1]
        self.reply = reply
        self.conns = []
        self.thread = threading.Thread(target=self.serve, daemon=True)
        self.thread.start()

    def serve(self):
        try:
            c, _ = self.sock.accept()
        except OSError:
            return
        self.conns.append(c)
        c.recv(4096)
        if self.reply is not None:
            c.sendall(self.reply)
            c.close()

    def close(self):
        self.sock.close()
        for c in self.conns:
            c.close()


class LiveDaemon(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.d = kmdaemon.Daemon()

    @classmethod
    def tearDownClass(cls):
        cls.d.stop()

    def test_healthz_answering_200_passes(self):
        rc, err, _ = probe("--healthcheck",
                           "http://127.0.0.1:%d/healthz" % self.d.port)
        self.assertEqual((rc, err), (0, ""))

    def test_equals_form_and_host_name_pass(self):
        rc, err, _ = probe("--healthcheck=http://localhost:%d/readyz"
                           % self.d.port)
        self.assertEqual(rc, 0, err)

    def test_a_status_other_than_200_fails_and_is_named(self):
        rc, err, _ = probe("--healthcheck",
                           "http://127.0.0.1:%d/no-such-page" % self.d.port)
        self.assertEqual(rc, 1)
        self.assertIn("status 404", err)

    def test_the_probe_leaves_the_daemon_serving(self):
        self.assertEqual(self.d.request("GET", "/healthz").status, 200)
        self.assertTrue(self.d.alive())


class NoDaemon(unittest.TestCase):
    def test_a_refused_port_fails(self):
        rc, err, _ = probe("--healthcheck",
                           "http://127.0.0.1:%d/healthz" % free_port())
        self.assertEqual(rc, 1)
        self.assertIn("cannot connect", err)

    def test_a_peer_that_never_answers_fails_within_the_bound(self):
        quiet = Listener(None)
        try:
            rc, err, took = probe("--healthcheck",
                                  "http://127.0.0.1:%d/healthz" % quiet.port)
        finally:
            quiet.close()
        self.assertEqual(rc, 1)
        self.assertIn("no HTTP answer", err)
        # Not hung: the bound plus room for a loaded machine.
        self.assertLess(took, BOUND + 10)

    def test_a_peer_that_is_not_http_fails(self):
        other = Listener(b"SSH-2.0-OpenSSH_9.2\r\n")
        try:
            rc, err, _ = probe("--healthcheck",
                               "http://127.0.0.1:%d/" % other.port)
        finally:
            other.close()
        self.assertEqual(rc, 1)
        self.assertIn("no HTTP answer", err)

    def test_a_200_from_any_server_passes(self):
        ok = Listener(b"HTTP/1.0 200 OK\r\nContent-Length: 0\r\n\r\n")
        try:
            rc, err, _ = probe("--healthcheck",
                               "http://127.0.0.1:%d/" % ok.port)
        finally:
            ok.close()
        self.assertEqual(rc, 0, err)

    def test_unusable_urls_are_usage_errors(self):
        for url, why in [("https://127.0.0.1/healthz", "not an http:// URL"),
                         ("http://127.0.0.1:99999/", "bad port"),
                         ("http://127.0.0.1:80x/", "bad port"),
                         ("http:///healthz", "bad host"),
                         ("http://[::1/healthz", "bad host"),
                         ("http://127.0.0.1/a b", "bad path")]:
            rc, err, _ = probe("--healthcheck", url)
            self.assertEqual(rc, 2, url)
            self.assertIn(why, err, url)
        for args in [("--healthcheck",), ("--healthcheck", "http://a/", "x")]:
            rc, err, _ = probe(*args)
            self.assertEqual(rc, 2, args)
            self.assertIn("usage", err)


if __name__ == "__main__":
    unittest.main()
