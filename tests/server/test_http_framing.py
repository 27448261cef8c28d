"""test_http_framing.py - kmorphd frames requests one way only: requests
whose length could be read two ways (request smuggling), malformed field
lines and request targets are refused with 400 (RFC 9112 3.2, 5.1, 6.1,
6.3), unknown transfer codings with 501, each a problem+json naming the
header at fault, and the connection is closed after it. Plus the request
target's forms and a client that half-closes its sending side."""
import http.client
import json
import re
import socket
import time
import unittest

from kmtest import HOST, ContractCase, Daemon, heavy_morph_body, morph_body

MAX_FRAMES = 1000  # the daemon's default --max-frames
HIDDEN = b"GET /readyz HTTP/1.1\r\nHost: k\r\n\r\n"


def exchange(port, data, timeout=5.0, half_close=False):
    """Send data on a new connection, read until the server closes it or
    timeout passes: (bytes read, whether the server closed, seconds)."""
    t0 = time.monotonic()
    out, closed = b"", False
    with socket.create_connection((HOST, port), timeout=timeout) as s:
        try:
            s.sendall(data)
            if half_close:
                s.shutdown(socket.SHUT_WR)
        except OSError:
            pass
        while time.monotonic() - t0 < timeout:
            try:
                b = s.recv(65536)
            except socket.timeout:
                break
            except OSError:
                closed = True
                break
            if not b:
                closed = True
                break
            out += b
    return out, closed, time.monotonic() - t0


def answers(raw):
    """The answers in raw, in order: (status, headers dict, body)."""
    res = []
    while raw.startswith(b"HTTP/1."):
        head, _, rest = raw.partition(b"\r\n\r\n")
        lines = head.split(b"\r\n")
        status = int(lines[0].split(b" ", 2)[1])
        hdrs = {}
        for ln in lines[1:]:
            k, _, v = ln.partition(b":")
            hdrs[k.strip().lower().decode()] = v.strip().decode("latin1")
        n = 0 if status < 200 else int(hdrs.get("content-length", "0"))
        res.append((status, hdrs, rest[:n]))
        raw = rest[n:]
    return res


class Refusals(ContractCase):
    """Each refusal: one answer only, problem+json naming the header,
    Connection: close, and the server closes (nothing hidden after it is
    answered)."""

    @classmethod
    def setUpClass(cls):
        cls.d = Daemon("--threads", "1", "--timeout", "10")

    @classmethod
    def tearDownClass(cls):
        cls.d.stop()

    def refused(self, data, status, names):
        raw, closed, dt = exchange(self.d.port, data)
        got = answers(raw)
        self.assertEqual(len(got), 1, raw[:600])
        st, hdrs, body = got[0]
        self.assertEqual(st, status, raw[:600])
        self.assertEqual(hdrs.get("content-type"), "application/problem+json")
        self.assertEqual(hdrs.get("connection", "").lower(), "close")
        doc = json.loads(body)
        self.assertEqual(doc["status"], status)
        self.assertIn(names, doc["detail"])
        self.assertTrue(closed, "the connection stays open after a refusal")
        self.assertLess(dt, 3.0)
        return doc

    def test_two_different_content_lengths_are_refused(self):
        self.refused(b"GET /healthz HTTP/1.1\r\nHost: k\r\nContent-Length: 0"
                     b"\r\nContent-Length: %d\r\n\r\n" % len(HIDDEN) + HIDDEN,
                     400, "Content-Length")

    def test_a_later_invalid_content_length_is_refused(self):
        self.refused(b"GET /healthz HTTP/1.1\r\nHost: k\r\nContent-Length: 0"
                     b"\r\nContent-Length: -1\r\n\r\n" + HIDDEN,
                     400, "Content-Length")

    def test_content_length_with_transfer_encoding_is_refused(self):
        self.refused(b"GET /healthz HTTP/1.1\r\nHost: k\r\nContent-Length: 5"
                     b"\r\nTransfer-Encoding: chunked\r\n\r\n0\r\n\r\n"
                     + HIDDEN, 400, "Transfer-Encoding")

    def test_space_before_the_colon_is_refused(self):
        self.refused(b"GET /healthz HTTP/1.1\r\nHost: k\r\nContent-Length : "
                     b"%d\r\n\r\n" % len(HIDDEN) + HIDDEN, 400,
                     "Content-Length")

    def test_nul_in_a_header_value_is_refused(self):
        self.refused(b"GET /healthz HTTP/1.1\r\nHost: k\r\nX-Note: a\x00b"
                     b"\r\n\r\n", 400, "X-Note")

    def test_nul_at_the_end_of_the_last_header_is_refused(self):
        self.refused(b"GET /healthz HTTP/1.1\r\nHost: k\r\nX-Note: ab\x00cd"
                     b"\r\n\r\n", 400, "header")

    def test_control_byte_in_a_header_value_is_refused(self):
        self.refused(b"GET /healthz HTTP/1.1\r\nHost: k\r\nX-Note: a\rb"
                     b"\r\n\r\n", 400, "X-Note")

    def test_folded_header_line_is_refused(self):
        self.refused(b"GET /healthz HTTP/1.1\r\nHost: k\r\nX-Note: a\r\n b"
                     b"\r\nAccept: */*\r\n\r\n", 400, "header")

    def test_empty_header_name_is_refused(self):
        self.refused(b"GET /healthz HTTP/1.1\r\nHost: k\r\n: v\r\n\r\n",
                     400, "empty field name")

    def test_missing_host_in_http11_is_refused(self):
        self.refused(b"GET /healthz HTTP/1.1\r\n\r\n", 400, "Host")

    def test_duplicate_host_is_refused(self):
        self.refused(b"GET /healthz HTTP/1.1\r\nHost: k\r\nHost: j\r\n\r\n",
                     400, "Host")

    def test_encoded_nul_in_the_path_is_refused(self):
        self.refused(b"GET /healthz%00x HTTP/1.1\r\nHost: k\r\n\r\n", 400,
                     "%00")
        body = json.dumps(morph_body(3)).encode()
        self.refused(b"POST /v1/morph%%00.png HTTP/1.1\r\nHost: k\r\n"
                     b"Content-Type: application/json\r\nContent-Length: %d"
                     b"\r\n\r\n" % len(body) + body, 400, "%00")

    def test_unknown_transfer_coding_is_501_at_once(self):
        doc = self.refused(b"POST /v1/morph HTTP/1.1\r\nHost: k\r\n"
                           b"Content-Type: application/json\r\n"
                           b"Transfer-Encoding: gzip\r\n\r\nabc", 501,
                           "Transfer-Encoding")
        self.assertIn("gzip", doc["detail"])

    def test_chunked_twice_is_refused(self):
        # RFC 9112 6.1: chunked is applied at most once.
        self.refused(b"POST /v1/morph HTTP/1.1\r\nHost: k\r\n"
                     b"Transfer-Encoding: chunked\r\n"
                     b"Transfer-Encoding: chunked\r\n\r\n0\r\n\r\n",
                     400, "Transfer-Encoding")


class Accepted(ContractCase):
    """What stays as it was, and the request target's forms."""

    @classmethod
    def setUpClass(cls):
        cls.d = Daemon("--threads", "1", "--timeout", "10")

    @classmethod
    def tearDownClass(cls):
        cls.d.stop()

    def test_identical_repeated_content_lengths_are_one_length(self):
        # RFC 9112 6.3 allows taking a repeated identical value as one.
        raw, _, _ = exchange(self.d.port,
                             b"GET /healthz HTTP/1.1\r\nHost: k\r\n"
                             b"Content-Length: 2\r\nContent-Length: 2\r\n"
                             b"Connection: close\r\n\r\nab")
        got = answers(raw)
        self.assertEqual([g[0] for g in got], [200])

    def test_keep_alive_serves_two_requests_on_one_connection(self):
        req = b"GET /healthz HTTP/1.1\r\nHost: k\r\n\r\n"
        raw, _, _ = exchange(self.d.port, req + req.replace(
            b"\r\n\r\n", b"\r\nConnection: close\r\n\r\n"))
        self.assertEqual([g[0] for g in answers(raw)], [200, 200])

    def test_absolute_form_targets_route_by_their_path(self):
        raw, _, _ = exchange(self.d.port,
                             b"GET http://k/healthz HTTP/1.1\r\nHost: k\r\n"
                             b"Connection: close\r\n\r\n")
        got = answers(raw)
        self.assertEqual(got[0][0], 200, raw[:300])
        self.assertEqual(json.loads(got[0][2]), {"status": "ok"})
        raw, _, _ = exchange(self.d.port,
                             b"GET HTTP://k:80 HTTP/1.1\r\nHost: k\r\n"
                             b"Connection: close\r\n\r\n")
        got = answers(raw)
        self.assertEqual(got[0][0], 200, raw[:300])
        self.assertIn(b"<html", got[0][2].lower())

    def test_access_log_method_cannot_add_fields_or_escapes(self):
        raw, _, _ = exchange(self.d.port,
                             b"GE\x1b[2J\tstatus=200 /healthz HTTP/1.1\r\n"
                             b"Host: k\r\nX-Request-Id: log-method-1\r\n"
                             b"Connection: close\r\n\r\n")
        self.assertTrue(raw.startswith(b"HTTP/1.1 "), raw[:200])

        def line():
            for ln in self.d.text().splitlines():
                if "request_id=log-method-1" in ln:
                    return ln
            return None
        deadline = time.monotonic() + 5
        ln = line()
        while ln is None and time.monotonic() < deadline:
            time.sleep(0.05)
            ln = line()
        self.assertIsNotNone(ln)
        self.assertNotIn("\x1b", ln)
        self.assertNotIn("\t", ln)
        self.assertEqual(len(re.findall(r"\bstatus=", ln)), 1, ln)


class HalfClose(ContractCase):
    """A FIN after the request is not a client that left."""

    @classmethod
    def setUpClass(cls):
        cls.d = Daemon("--threads", "1", "--timeout", "10")

    @classmethod
    def tearDownClass(cls):
        cls.d.stop()

    def morph_request(self, frames, rid):
        body = json.dumps(morph_body(frames)).encode()
        return (b"POST /v1/morph HTTP/1.1\r\nHost: k\r\n"
                b"Content-Type: application/json\r\nX-Request-Id: %s\r\n"
                b"Content-Length: %d\r\n\r\n" % (rid.encode(), len(body))
                + body)

    def test_half_closed_client_gets_its_morph(self):
        raw, closed, _ = exchange(self.d.port,
                                  self.morph_request(24, "half-1"),
                                  timeout=20, half_close=True)
        got = answers(raw)
        finals = [g for g in got if g[0] >= 200]
        self.assertEqual(len(finals), 1, raw[:400])
        self.assertEqual(finals[0][0], 200, raw[:400])
        self.assertEqual(len(json.loads(finals[0][2])["frames"]), 24)
        self.assertTrue(all(100 <= g[0] < 200 for g in got[:-1]))

    def test_http_client_half_closed_reads_past_the_interim(self):
        # Long enough for the FIN to be seen during the work.
        body = json.dumps(heavy_morph_body(MAX_FRAMES))
        conn = http.client.HTTPConnection(HOST, self.d.port, timeout=20)
        try:
            conn.request("POST", "/v1/morph", body=body,
                         headers={"Content-Type": "application/json"})
            conn.sock.shutdown(socket.SHUT_WR)
            r = conn.getresponse()
            self.assertEqual(r.status, 200)
            self.assertEqual(len(json.loads(r.read())["frames"]),
                             MAX_FRAMES)
        finally:
            conn.close()

    def test_closed_client_still_stops_the_work(self):
        # A morph that takes seconds; the client closes at once.
        body = json.dumps(heavy_morph_body(MAX_FRAMES)).encode()
        with socket.create_connection((HOST, self.d.port)) as s:
            s.sendall(b"POST /v1/morph HTTP/1.1\r\nHost: k\r\n"
                      b"Content-Type: application/json\r\n"
                      b"X-Request-Id: gone-1\r\nContent-Length: %d\r\n\r\n"
                      % len(body) + body)
        deadline = time.monotonic() + 15
        line = None
        while line is None and time.monotonic() < deadline:
            for ln in self.d.text().splitlines():
                if "request_id=gone-1" in ln:
                    line = ln
            time.sleep(0.05)
        self.assertIsNotNone(line, "the work was not stopped")
        self.assertIn("status=503", line)
        ms = float(re.search(r"duration_ms=([0-9.]+)", line).group(1))
        self.assertLess(ms, 5000)


if __name__ == "__main__":
    unittest.main()
