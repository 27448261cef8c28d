"""test_http_framing.py - kmorphd frames requests one way only: requests
whose length could be read two ways (request smuggling), malformed field
lines and request targets are refused with 400 (RFC 9112 3.2, 5.1, 6.1,
6.3), unknown transfer codings with 501, each a problem+json naming the
header at fault, and the connection is closed after it; the same for
faults libmicrohttpd 0.9.75 used to answer by itself (a first
Content-Length of -1, a chunk-size line longer than its buffer), for
every request of a kept-alive or pipelined connection, however the bytes
are cut into segments. Plus the request target's forms and a client that
half-closes its sending side."""
import http.client
import json
import re
import socket
import time

CHUNK_LINE_MAX = 4096  # the documented bound of a chunk-size line
import unittest

from kmtest import (HOST, ContractCase, Daemon, circle_svg, morph_body,
                    ring_morph_body)

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


def trickle(port, pieces, timeout=10.0, pause=0.005):
    """Send each piece as its own TCP segment (Nagle off, a pause
    between), then read like exchange."""
    t0 = time.monotonic()
    out = b""
    with socket.create_connection((HOST, port), timeout=timeout) as s:
        s.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        for p in pieces:
            s.sendall(p)
            time.sleep(pause)
        while time.monotonic() - t0 < timeout:
            try:
                b = s.recv(65536)
            except (socket.timeout, OSError):
                break
            if not b:
                break
            out += b
    return out


SIGNATURE_BODY = json.dumps({"curve": circle_svg(1.0)}).encode()


def chunked(body, sizes, ext=b""):
    """body as chunks of the given sizes (the rest in one more chunk),
    each size line followed by ext, then the last chunk."""
    out, i = b"", 0
    for n in list(sizes) + [len(body)]:
        piece = body[i:i + n]
        i += len(piece)
        if piece:
            out += b"%x%s\r\n%s\r\n" % (len(piece), ext, piece)
    return out + b"0\r\n\r\n"


def signature_request(framing, close=True):
    """POST /v1/signature of a circle; framing is b"" for Content-Length
    or the chunked body to send."""
    head = (b"POST /v1/signature HTTP/1.1\r\nHost: k\r\n"
            b"Content-Type: application/json\r\n")
    if close:
        head += b"Connection: close\r\n"
    if not framing:
        return head + b"Content-Length: %d\r\n\r\n" % len(
            SIGNATURE_BODY) + SIGNATURE_BODY
    return head + b"Transfer-Encoding: chunked\r\n\r\n" + framing


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

    # Faults libmicrohttpd 0.9.75 answered itself, before any handler:
    # its 400 had its header block twice; a long chunk line got its 500.

    def test_invalid_first_content_length_gets_one_answer(self):
        for value in (b"-1", b"+5", b"", b"5 ", b"0x5"):
            with self.subTest(value=value):
                data = (b"GET /healthz HTTP/1.1\r\nHost: k\r\n"
                        b"Content-Length: %s\r\n\r\n" % value + HIDDEN)
                raw, _, _ = exchange(self.d.port, data)
                self.assertEqual(raw.count(b"HTTP/1."), 1, raw[:600])
                self.refused(data, 400, "Content-Length")

    def test_64_kib_chunk_extension_is_400_not_500(self):
        ext = b";" + b"e" * 65536
        self.refused(signature_request(chunked(SIGNATURE_BODY, [], ext)),
                     400, "chunk-size line")

    def test_chunk_size_line_one_byte_over_the_limit_is_refused(self):
        size = b"%x" % len(SIGNATURE_BODY)
        ext = b";" + b"e" * (CHUNK_LINE_MAX + 1 - len(size) - 1)
        self.assertEqual(len(size + ext), CHUNK_LINE_MAX + 1)
        self.refused(signature_request(chunked(SIGNATURE_BODY, [], ext)),
                     400, "chunk-size line")

    def test_chunk_data_longer_than_its_size_is_refused(self):
        self.refused(signature_request(b"2\r\n{}x\r\n0\r\n\r\n"), 400,
                     "chunk")

    def test_chunk_size_that_is_not_hexadecimal_is_refused(self):
        for line in (b"-2", b"0x2", b" 2", b"2 ;a", b"", b"12345678901234567"):
            with self.subTest(line=line):
                self.refused(signature_request(line + b"\r\n{}\r\n0\r\n\r\n"),
                             400, "chunk-size line")

    def test_folded_trailer_line_is_refused(self):
        self.refused(signature_request(b"2\r\n{}\r\n0\r\nX-T: a\r\n b\r\n\r\n"
                                       + HIDDEN), 400, "header")

    def test_transfer_encoding_not_exactly_chunked_is_refused(self):
        # libmicrohttpd reads a chunked body only for the exact value.
        for value in (b"chunked ", b"chunked,", b", chunked"):
            with self.subTest(value=value):
                self.refused(b"POST /v1/signature HTTP/1.1\r\nHost: k\r\n"
                             b"Transfer-Encoding: %s\r\n\r\n0\r\n\r\n" % value
                             + HIDDEN, 400, "Transfer-Encoding")

    def test_lone_cr_in_the_request_line_is_refused(self):
        self.refused(b"GET /healthz\rContent-Length: 5 HTTP/1.1\r\nHost: k"
                     b"\r\n\r\n" + HIDDEN, 400, "request line")

    def test_header_block_over_16_kib_is_431(self):
        # libmicrohttpd closed without an answer from about 32,380 bytes.
        for n in (16400, 33000):
            self.refused(b"GET /healthz HTTP/1.1\r\nHost: k\r\nX-Pad: "
                         + b"p" * n + b"\r\n\r\n", 431, "16384")

    def test_more_than_100_fields_is_431(self):
        head = b"GET /healthz HTTP/1.1\r\nHost: k\r\n" + b"".join(
            b"X-F%d: v\r\n" % i for i in range(98))
        raw, _, _ = exchange(self.d.port, head + b"Connection: close\r\n\r\n")
        self.assertEqual([g[0] for g in answers(raw)], [200])
        self.refused(head + b"X-F: v\r\nX-G: v\r\n\r\n", 431, "100")


class Segments(ContractCase):
    """Framing read the same way however the bytes are cut: the same
    signature answer through Content-Length, chunks of any size, chunk
    lines and header lines arriving a byte at a time, and a chunk-size
    line of exactly the documented bound."""

    @classmethod
    def setUpClass(cls):
        cls.d = Daemon("--threads", "1", "--timeout", "10")
        raw, _, _ = exchange(cls.d.port, signature_request(b""))
        cls.expected = json.loads(answers(raw)[0][2])

    @classmethod
    def tearDownClass(cls):
        cls.d.stop()

    def same_signature(self, raw):
        got = answers(raw)
        self.assertEqual([g[0] for g in got], [200], raw[:400])
        self.assertEqual(json.loads(got[0][2]), self.expected)

    def test_chunks_of_every_size_give_the_same_answer(self):
        for sizes in ([1] * 40, [7, 300, 2], [len(SIGNATURE_BODY) - 1]):
            raw, _, _ = exchange(self.d.port, signature_request(
                chunked(SIGNATURE_BODY, sizes, b";name=value;x")))
            self.same_signature(raw)

    def test_chunk_and_header_lines_split_byte_by_byte(self):
        head, _, _ = signature_request(b"x").partition(b"\r\n\r\n")
        head += b"\r\n\r\n"
        body = chunked(SIGNATURE_BODY, [10], b";ext=1")
        # Header lines and every chunk line a byte a segment; chunk data in
        # pieces cut across its CRLF.
        pieces = [head[i:i + 1] for i in range(len(head))]
        i = 0
        while i < len(body):
            j = body.find(b"\r\n", i)
            j = len(body) if j < 0 else j + 2
            line = body[i:j]
            if line[:1].isalnum() and b"{" not in line and b'"' not in line:
                pieces += [line[k:k + 1] for k in range(len(line))]
            else:
                pieces += [line[:-1], line[-1:]]
            i = j
        self.assertGreater(len(pieces), 100)
        self.same_signature(trickle(self.d.port, pieces))

    def test_chunk_size_line_at_exactly_the_limit_is_accepted(self):
        size = b"%x" % len(SIGNATURE_BODY)
        ext = b";" + b"e" * (CHUNK_LINE_MAX - len(size) - 1)
        self.assertEqual(len(size + ext), CHUNK_LINE_MAX)
        raw, _, _ = exchange(self.d.port, signature_request(
            chunked(SIGNATURE_BODY, [], ext)))
        self.same_signature(raw)

    def test_trailers_pass(self):
        raw, _, _ = exchange(self.d.port, signature_request(
            chunked(SIGNATURE_BODY, [5])[:-2] + b"X-Sum: 1\r\n\r\n"))
        self.same_signature(raw)


class Pipelined(ContractCase):
    """Each request of a connection is framed, not only the first: the
    requests before a bad one are answered, in order, then the refusal,
    and nothing after it."""

    @classmethod
    def setUpClass(cls):
        cls.d = Daemon("--threads", "1", "--timeout", "10")

    @classmethod
    def tearDownClass(cls):
        cls.d.stop()

    def finals(self, data, timeout=10.0):
        raw, closed, _ = exchange(self.d.port, data, timeout=timeout)
        self.assertTrue(closed, "the connection stays open")
        return [g for g in answers(raw) if g[0] >= 200], raw

    def test_bad_content_length_in_the_second_request(self):
        good = b"GET /healthz HTTP/1.1\r\nHost: k\r\n\r\n"
        got, raw = self.finals(good + b"GET /healthz HTTP/1.1\r\nHost: k\r\n"
                               b"Content-Length: -1\r\n\r\n" + HIDDEN)
        self.assertEqual([g[0] for g in got], [200, 400], raw[:800])
        self.assertEqual(json.loads(got[0][2]), {"status": "ok"})
        self.assertEqual(got[1][1].get("connection", "").lower(), "close")
        self.assertIn("Content-Length", json.loads(got[1][2])["detail"])

    def test_refusal_waits_for_the_answer_computed_before_it(self):
        body = json.dumps(morph_body(60)).encode()
        morph = (b"POST /v1/morph HTTP/1.1\r\nHost: k\r\n"
                 b"Content-Type: application/json\r\nContent-Length: %d"
                 b"\r\n\r\n" % len(body) + body)
        got, raw = self.finals(morph + b"GET /healthz HTTP/1.1\r\nHost: k\r\n"
                               b"Content-Length: 0\r\nContent-Length: 5"
                               b"\r\n\r\n" + HIDDEN, timeout=20)
        self.assertEqual([g[0] for g in got], [200, 400], raw[:300])
        self.assertEqual(len(json.loads(got[0][2])["frames"]), 60)

    def test_bad_chunk_line_in_the_fourth_request(self):
        good = signature_request(chunked(SIGNATURE_BODY, [50], b";a=b"),
                                 close=False)
        bad = signature_request(b"2\r\n{}\r\n" + b"1;" + b"e" * 70000
                                + b"\r\n", close=False)
        got, raw = self.finals(good * 3 + bad + HIDDEN)
        self.assertEqual([g[0] for g in got], [200, 200, 200, 400],
                         raw[:300])
        self.assertIn("chunk-size line", json.loads(got[3][2])["detail"])

    def test_many_kept_alive_requests_pass_in_order(self):
        reqs = b"".join(b"GET /healthz HTTP/1.1\r\nHost: k\r\n"
                        b"X-Request-Id: pipe-%d\r\n\r\n" % i
                        for i in range(30))
        got, raw = self.finals(reqs + b"GET /healthz HTTP/1.1\r\nHost: k\r\n"
                               b"Connection: close\r\n\r\n")
        self.assertEqual([g[0] for g in got], [200] * 31)
        self.assertEqual([g[1].get("x-request-id") for g in got[:30]],
                         ["pipe-%d" % i for i in range(30)])


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
        body = json.dumps(ring_morph_body(300))
        conn = http.client.HTTPConnection(HOST, self.d.port, timeout=20)
        try:
            conn.request("POST", "/v1/morph", body=body,
                         headers={"Content-Type": "application/json"})
            conn.sock.shutdown(socket.SHUT_WR)
            r = conn.getresponse()
            self.assertEqual(r.status, 200)
            self.assertEqual(len(json.loads(r.read())["frames"]), 300)
        finally:
            conn.close()

    def test_closed_client_still_stops_the_work(self):
        # A morph that takes seconds; the client closes at once.
        body = json.dumps(ring_morph_body(MAX_FRAMES)).encode()
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
