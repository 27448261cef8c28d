"""test_contract.py - every endpoint and every documented error status of
kmorphd, each answer checked against its schema in api/openapi.yaml."""
import json
import math
import os
import re
import subprocess
import time
import unittest

import yaml

from kmtest import (DAEMON, ROOT, SPEC, ContractCase, Daemon, DaemonCase,
                    circle_svg, close_to, component, heavy_morph_body, metric,
                    morph_body, open_arc, raw_exchange, raw_status,
                    ring_morph_body, run_job, schema_errors, wait_for)

TWO_PI = 2 * math.pi


class OperationsEndpoints(ContractCase):
    @classmethod
    def setUpClass(cls):
        # CORS is off by default: the CORS tests here configure any origin.
        cls.d = Daemon("--threads", "2", "--max-body", "4096",
                       "--cors-origins", "*")

    @classmethod
    def tearDownClass(cls):
        cls.d.stop()

    def test_healthz_and_readyz_answer_ok(self):
        doc = self.assertDocumented(self.d.request("GET", "/healthz"),
                                    "/healthz", "get")
        self.assertEqual(doc["status"], "ok")
        doc = self.assertDocumented(self.d.request("GET", "/readyz"),
                                    "/readyz", "get")
        self.assertEqual(doc["status"], "ready")

    def test_head_healthz_has_headers_and_no_body(self):
        r = self.d.request("HEAD", "/healthz")
        self.assertEqual(r.status, 200)
        self.assertEqual(r.body, b"")
        self.assertTrue(r.header("X-Request-Id"))

    def test_openapi_json_is_the_yaml_contract(self):
        r = self.d.request("GET", "/openapi.json")
        self.assertDocumented(r, "/openapi.json", "get")
        with open(os.path.join(ROOT, "api", "openapi.yaml"),
                  encoding="utf-8") as f:
            self.assertEqual(r.json(), yaml.safe_load(f))

    def test_index_is_html_listing_the_endpoints(self):
        r = self.d.request("GET", "/")
        self.assertDocumented(r, "/", "get")
        self.assertIn(b"<html", r.body.lower())
        if not os.path.exists(os.path.join(ROOT, "clients", "web",
                                           "index.html")):
            for path in (b"/v1/morph", b"/v1/jobs", b"/healthz"):
                self.assertIn(path, r.body)

    def test_metrics_are_prometheus_text_with_every_family(self):
        self.d.request("GET", "/healthz")
        self.d.request("GET", "/v1/nowhere")
        r = self.d.request("GET", "/metrics")
        self.assertDocumented(r, "/metrics", "get")
        self.assertIn("version=0.0.4", r.header("Content-Type"))
        text = r.body.decode()
        for family, kind in [
                ("kmorph_http_requests_total", "counter"),
                ("kmorph_http_request_duration_seconds", "histogram"),
                ("kmorph_queue_depth", "gauge"),
                ("kmorph_workers_busy", "gauge"),
                ("kmorph_jobs", "gauge")]:
            self.assertIn("# TYPE %s %s" % (family, kind), text)
        self.assertGreaterEqual(metric(text, "kmorph_http_requests_total",
                                       {"route": "healthz",
                                        "method": "GET",
                                        "code": "200"}), 1)
        self.assertGreaterEqual(metric(text, "kmorph_http_requests_total",
                                       {"route": "other",
                                        "method": "GET",
                                        "code": "404"}), 1)
        self.assertEqual(metric(text, "kmorph_workers"), 2)
        # A histogram's buckets are cumulative and end with the count.
        inf = metric(text, "kmorph_http_request_duration_seconds_bucket",
                     {"route": "healthz", "le": "+Inf"})
        cnt = metric(text, "kmorph_http_request_duration_seconds_count",
                     {"route": "healthz"})
        self.assertEqual(inf, cnt)
        for state in ("queued", "running", "done", "failed", "cancelled"):
            self.assertIsNotNone(metric(text, "kmorph_jobs",
                                        {"state": state}))

    def test_sane_request_id_is_echoed_in_header_body_and_log(self):
        rid = "client-42.a:b_c"
        r = self.d.request("GET", "/v1/nothing", headers={"X-Request-Id": rid})
        self.assertEqual(r.status, 404)
        self.assertEqual(r.header("X-Request-Id"), rid)
        self.assertEqual(r.json()["request_id"], rid)
        # The line is written when MHD completes the request, which may be
        # just after the client has read the answer.
        def lines():
            return [l for l in self.d.text().splitlines()
                    if "request_id=%s" % rid in l]
        wait_for(lines, 5)
        time.sleep(0.1)
        lines = lines()
        self.assertEqual(len(lines), 1, "one access-log line per request")
        for part in ("method=GET", 'path="/v1/nothing"', "status=404",
                     "bytes=", "duration_ms="):
            self.assertIn(part, lines[0])

    def test_insane_request_id_is_replaced_by_a_generated_one(self):
        for bad in ("has space", "x" * 65, "semi;colon"):
            r = self.d.request("GET", "/healthz", headers={"X-Request-Id": bad})
            rid = r.header("X-Request-Id")
            self.assertNotEqual(rid, bad)
            self.assertRegex(rid, r"^[0-9a-f]{16}$")

    def test_generated_request_ids_differ(self):
        ids = {self.d.request("GET", "/healthz").header("X-Request-Id")
               for _ in range(20)}
        self.assertEqual(len(ids), 20)

    def test_unknown_path_is_404_problem(self):
        for path in ("/v2/morph", "/v1/jobs/x/y", "/metrics/x"):
            r = self.d.request("GET", path)
            self.assertEqual(r.status, 404)
            self.assertEqual(r.ctype, "application/problem+json")
            self.assertEqual(schema_errors(r.json(), component("Problem")), [])

    def test_wrong_method_is_405_with_allow(self):
        cases = [("GET", "/v1/morph", "POST"), ("PUT", "/healthz", "GET"),
                 ("POST", "/v1/jobs/0123/result", "GET"),
                 ("PATCH", "/v1/jobs/0123", "DELETE")]
        for method, path, allowed in cases:
            r = self.d.request(method, path)
            self.assertEqual(r.status, 405, (method, path))
            doc = self.assertResponse(r, "MethodNotAllowed")
            self.assertIn(allowed, r.header("Allow"))
            self.assertIn(method, doc["detail"])

    def test_wrong_content_type_is_415(self):
        for path in ("/v1/signature", "/v1/morph", "/v1/jobs"):
            r = self.d.request("POST", path, body=b"a=1",
                               headers={"Content-Type":
                                        "application/x-www-form-urlencoded"})
            self.assertProblem(r, 415, path, "post")

    def test_json_with_charset_and_problem_suffix_are_accepted_types(self):
        r = self.d.request("POST", "/v1/signature", body=b"{",
                           headers={"Content-Type":
                                    "application/json; charset=utf-8"})
        self.assertNotEqual(r.status, 415)

    def test_malformed_json_is_400_problem(self):
        for path in ("/v1/signature", "/v1/reconstruct", "/v1/morph",
                     "/v1/jobs"):
            rid = "malformed-1"
            r = self.d.request("POST", path, body=b'{"curve": [1, 2',
                               headers={"X-Request-Id": rid})
            self.assertProblem(r, 400, path, "post", rid=rid)

    def test_declared_body_over_the_limit_is_413_before_reading_it(self):
        # Headers only: the server must answer without waiting for a body.
        raw = raw_exchange(self.d.port,
                           b"POST /v1/morph HTTP/1.1\r\nHost: x\r\n"
                           b"Content-Type: application/json\r\n"
                           b"Content-Length: 1000000000\r\n\r\n", timeout=5)
        self.assertEqual(raw_status(raw), 413, raw[:200])
        self.assertIn(b"application/problem+json", raw)
        self.assertIn(b"KMORPH_MAX_BODY", raw)

    def test_chunked_body_over_the_limit_is_counted_then_413(self):
        chunk = b"x" * 1000
        body = b"".join(b"%x\r\n%s\r\n" % (len(chunk), chunk)
                        for _ in range(6)) + b"0\r\n\r\n"
        raw = raw_exchange(self.d.port,
                           b"POST /v1/signature HTTP/1.1\r\nHost: x\r\n"
                           b"Content-Type: application/json\r\n"
                           b"Transfer-Encoding: chunked\r\n"
                           b"Connection: close\r\n\r\n" + body, timeout=5)
        self.assertEqual(raw_status(raw), 413, raw[:200])
        body_text = raw.split(b"\r\n\r\n", 1)[1]
        doc = json.loads(body_text)
        self.assertEqual(schema_errors(doc, component("Problem")), [])
        self.assertIn("6000", doc["detail"], "the counted size is reported")

    def test_cors_preflight_is_204_with_allow_and_expose_headers(self):
        r = self.d.request("OPTIONS", "/v1/morph", headers={
            "Origin": "http://front.example",
            "Access-Control-Request-Method": "POST",
            "Access-Control-Request-Headers": "content-type"})
        self.assertEqual(r.status, 204)
        self.assertEqual(r.header("Access-Control-Allow-Origin"), "*")
        self.assertIn("POST", r.header("Access-Control-Allow-Methods"))
        self.assertIn("Content-Type", r.header("Access-Control-Allow-Headers"))
        expose = r.header("Access-Control-Expose-Headers")
        for h in ("Location", "Retry-After", "X-Request-Id"):
            self.assertIn(h, expose)

    def test_cors_headers_on_plain_answers_only_with_origin(self):
        r = self.d.request("GET", "/healthz",
                           headers={"Origin": "http://front.example"})
        self.assertEqual(r.header("Access-Control-Allow-Origin"), "*")
        r = self.d.request("GET", "/healthz")
        self.assertIsNone(r.header("Access-Control-Allow-Origin"))


class ConfiguredOrigins(ContractCase):
    @classmethod
    def setUpClass(cls):
        cls.d = Daemon(env={"KMORPH_CORS_ORIGINS":
                            "https://a.example, https://b.example"})

    @classmethod
    def tearDownClass(cls):
        cls.d.stop()

    def test_listed_origin_is_echoed_with_vary(self):
        r = self.d.request("OPTIONS", "/v1/jobs",
                           headers={"Origin": "https://b.example"})
        self.assertEqual(r.status, 204)
        self.assertEqual(r.header("Access-Control-Allow-Origin"),
                         "https://b.example")
        self.assertIn("Origin", r.header("Vary"))

    def test_unlisted_origin_gets_no_cors_headers(self):
        r = self.d.request("OPTIONS", "/v1/jobs",
                           headers={"Origin": "https://evil.example"})
        self.assertEqual(r.status, 204)
        self.assertIsNone(r.header("Access-Control-Allow-Origin"))


class SharedFrames(unittest.TestCase):
    """A synchronous morph's frames are rendered by its worker and by
    workers with nothing else to do (frame_share.h): the answer is the
    same bytes as one worker's, for single curves and compound shapes,
    and a time limit still stops the work."""

    @classmethod
    def setUpClass(cls):
        cls.one = Daemon("--threads", "1")
        cls.many = Daemon("--threads", "3")

    @classmethod
    def tearDownClass(cls):
        cls.one.stop()
        cls.many.stop()

    def test_one_worker_and_three_give_the_same_bytes(self):
        for body in (heavy_morph_body(120), ring_morph_body(6),
                     dict(heavy_morph_body(50), intersections="avoid",
                          metrics=False)):
            a = self.one.request("POST", "/v1/morph", body=body)
            b = self.many.request("POST", "/v1/morph", body=body)
            self.assertEqual(a.status, 200, a.body[:300])
            self.assertEqual(a.body, b.body)

    def test_a_time_limit_stops_shared_frames(self):
        d = Daemon("--threads", "3", "--morph-time", "0.3",
                   "--max-output", LONG_RING_OUTPUT)
        try:
            t0 = time.monotonic()
            r = d.request("POST", "/v1/morph", body=long_ring_morph_body())
            took = time.monotonic() - t0
            self.assertEqual(r.status, 422, r.body[:300])
            self.assertIn("KMORPH_MORPH_TIME", r.json()["detail"])
            self.assertLess(took, 5.0)
            # the workers are free again: a small morph answers at once
            r = d.request("POST", "/v1/morph", body=morph_body(3))
            self.assertEqual(r.status, 200)
        finally:
            d.stop()


class CommandLine(unittest.TestCase):
    def test_help_lists_every_setting_and_exits_0(self):
        out = subprocess.run([DAEMON, "--help"], capture_output=True,
                             timeout=10, text=True)
        self.assertEqual(out.returncode, 0)
        for name in ("KMORPH_PORT", "KMORPH_BIND", "KMORPH_THREADS",
                     "KMORPH_QUEUE", "KMORPH_MAX_BODY", "KMORPH_TIMEOUT",
                     "KMORPH_JOB_TTL", "KMORPH_JOB_TIME", "KMORPH_MORPH_TIME",
                     "KMORPH_CORS_ORIGINS", "--port", "--bind"):
            self.assertIn(name, out.stdout)

    def test_bad_flags_and_values_exit_2_with_a_message(self):
        for args in (["--no-such-flag"], ["--port", "70000"],
                     ["--queue", "0"], ["--threads", "two"],
                     ["--morph-time", "0"]):
            out = subprocess.run([DAEMON, *args], capture_output=True,
                                 timeout=10, text=True)
            self.assertEqual(out.returncode, 2, args)
            self.assertIn("kmorphd:", out.stderr)

    def test_environment_sets_limits_and_flags_override_it(self):
        d = Daemon("--max-body", "300", env={"KMORPH_MAX_BODY": "100"})
        try:
            body = json.dumps({"curve": circle_svg(1.0), "pad": "x" * 150})
            r = d.request("POST", "/v1/signature", body=body.encode())
            self.assertNotEqual(r.status, 413, "the flag wins over the env")
        finally:
            d.stop()
        d = Daemon(env={"KMORPH_MAX_BODY": "100"})
        try:
            r = d.request("POST", "/v1/signature", body=body.encode())
            self.assertEqual(r.status, 413)
        finally:
            d.stop()


class GeometryEndpoints(DaemonCase):
    """Real computations through HTTP; the expected numbers are those of
    circles (length 2 pi r, curvature 1/r, turning 2 pi)."""

    def test_signature_of_a_circle_has_length_2_pi_r_and_turning_2_pi(self):
        r = self.d.request("POST", "/v1/signature",
                           body={"curve": circle_svg(2.0), "samples": 9})
        doc = self.assertDocumented(r, "/v1/signature", "post")
        self.assertEqual(r.status, 200, r.body[:300])
        sig = doc["signature"]
        self.assertTrue(close_to(sig["length"], 2 * TWO_PI, 1e-6))
        self.assertTrue(close_to(sig["turning"], TWO_PI, 1e-6))
        self.assertEqual(len(doc["samples"]), 9)
        for s, kappa in doc["samples"]:
            self.assertTrue(close_to(kappa, 0.5, 1e-3), kappa)

    def test_reconstruct_of_a_circle_signature_has_its_length(self):
        sig = self.d.request("POST", "/v1/signature",
                             body={"curve": circle_svg(1.5)}).json()
        r = self.d.request("POST", "/v1/reconstruct",
                           body={"signature": sig["signature"]})
        doc = self.assertDocumented(r, "/v1/reconstruct", "post")
        self.assertEqual(r.status, 200, r.body[:300])
        self.assertTrue(close_to(doc["curve"]["length"], 1.5 * TWO_PI, 1e-4))
        self.assertGreaterEqual(doc["error_bound"], 0)

    def test_morph_of_circles_passes_through_the_mean_circle(self):
        r = self.d.request("POST", "/v1/morph", body=morph_body(3))
        doc = self.assertDocumented(r, "/v1/morph", "post")
        self.assertEqual(r.status, 200, r.body[:300])
        ts = [f["t"] for f in doc["frames"]]
        self.assertEqual(ts, [0, 0.5, 1])
        # Radius (1 - t) * 1 + t * 2: lengths 2pi, 3pi, 4pi.
        for f, radius in zip(doc["frames"], (1.0, 1.5, 2.0)):
            self.assertTrue(close_to(f["metrics"]["length"],
                                     radius * TWO_PI, 1e-4), f["metrics"])

    def test_morph_as_svg_when_accept_asks_for_it(self):
        r = self.d.request("POST", "/v1/morph", body=morph_body(3),
                           headers={"Accept": "image/svg+xml"})
        self.assertDocumented(r, "/v1/morph", "post")
        self.assertEqual(r.ctype, "image/svg+xml")
        self.assertIn(b"<svg", r.body)

    def test_invalid_curve_is_422_with_a_pointer(self):
        body = {"curve": {"type": "bspline", "degree": 3,
                          "knots": [0, 0, 0, 0, 1, 1, 1, 1],
                          "control_points": [[0, 0], [1, 1], [2, 0]]}}
        r = self.d.request("POST", "/v1/signature", body=body)
        doc = self.assertProblem(r, 422, "/v1/signature", "post")
        self.assertTrue(doc["errors"][0]["pointer"].startswith("/curve"))

    def test_morph_of_open_and_closed_curves_is_4xx_not_5xx(self):
        r = self.d.request("POST", "/v1/morph",
                           body={"from": open_arc(1.0), "to": circle_svg(1.0),
                                 "frames": 3})
        self.assertLess(r.status, 500, r.body[:300])
        self.assertDocumented(r, "/v1/morph", "post")

    def test_too_many_frames_is_422_naming_frames(self):
        r = self.d.request("POST", "/v1/morph", body=morph_body(1001))
        doc = self.assertProblem(r, 422, "/v1/morph", "post")
        self.assertEqual(doc["errors"][0]["pointer"], "/frames")

    def test_unknown_member_is_422_naming_it_on_every_route(self):
        # A misspelt option must never be dropped for its default: the
        # answer names the member by its pointer and the near miss.
        want = '/blending: unknown member; did you mean "blend"?'
        for path in ("/v1/morph", "/v1/jobs"):
            body = morph_body(3)
            body["blending"] = "paper"
            r = self.d.request("POST", path, body=body)
            doc = self.assertProblem(r, 422, path, "post")
            self.assertEqual(doc["errors"][0]["pointer"], "/blending")
            self.assertEqual(doc["detail"], want)
        r = self.d.request("POST", "/v1/signature",
                           body={"curve": dict(circle_svg(1.0), colour=1)})
        doc = self.assertProblem(r, 422, "/v1/signature", "post")
        self.assertEqual(doc["errors"][0]["pointer"], "/curve/colour")
        r = self.d.request("POST", "/v1/reconstruct",
                           body={"signature": {"length": 1, "kappa": {
                               "degree": 0, "knots": [0, 1],
                               "coefficients": [1]}}, "tolerence": 1e-3})
        doc = self.assertProblem(r, 422, "/v1/reconstruct", "post")
        self.assertEqual(doc["errors"][0]["message"],
                         'unknown member; did you mean "tolerance"?')

    def test_morph_of_a_few_tenths_of_a_second_is_answered(self):
        # Six times the limit of MorphTimeLimit below: the default limit
        # (60 s) lets it through.
        r = self.d.request("POST", "/v1/morph", body=heavy_morph_body(1000))
        doc = self.assertDocumented(r, "/v1/morph", "post")
        self.assertEqual(r.status, 200, r.body[:300])
        self.assertEqual(len(doc["frames"]), 1000)


def long_ring_morph_body(**extra):
    """1,000 frames of the ring morph (two contours a frame) at a
    hundredth of its tolerance: some 3 s of frames on one core, 1.5 s on
    two (at 1e-7 the frames fell to 0.9 s once they were shared between
    workers and the limit stopped nothing), prepared in about 0.06 s
    (0.15 s under ASan), so a limit between the two stops it in its
    frames, named /frames. Its answer is predicted at up to 109 MB: the
    daemons that take it allow LONG_RING_OUTPUT."""
    body = ring_morph_body(1000)
    body["tolerance"] = 1e-8
    body.update(extra)
    return body


LONG_RING_OUTPUT = str(256 << 20)


class MorphTimeLimit(ContractCase):
    """A synchronous morph stops at --morph-time: a 422 naming the frames,
    never a 5xx, and the daemon goes on serving. The limit leaves the
    preparation five times its time (more under ASan or a loaded machine:
    a preparation past it is refused naming /tolerance, which is another
    test's) and the frames fourteen times the limit."""
    LIMIT = 0.5

    @classmethod
    def setUpClass(cls):
        cls.d = Daemon("--threads", "2", "--morph-time", str(cls.LIMIT),
                       "--max-output", LONG_RING_OUTPUT)

    @classmethod
    def tearDownClass(cls):
        cls.d.stop()

    def refused(self, body, pointer):
        t0 = time.monotonic()
        r = self.d.request("POST", "/v1/morph", body=body)
        dt = time.monotonic() - t0
        doc = self.assertProblem(r, 422, "/v1/morph", "post")
        self.assertEqual(doc["type"], "/problems/limit-exceeded")
        self.assertEqual([e["pointer"] for e in doc["errors"]], [pointer])
        detail = doc["detail"]
        self.assertIn("%g s" % self.LIMIT, detail)
        self.assertIn("KMORPH_MORPH_TIME", detail)
        self.assertIn("POST /v1/jobs", detail)
        m = re.search(r"with (\d+) of (\d+) frames done", detail)
        self.assertTrue(m, detail)
        done, total = int(m.group(1)), int(m.group(2))
        self.assertEqual(total, 1000)
        self.assertLess(done, total, "the work stopped before its end")
        self.assertLess(dt, self.LIMIT + 2.0,
                        "the answer does not wait for every frame")
        return doc

    def test_long_morph_is_422_naming_frames_with_the_numbers(self):
        self.refused(long_ring_morph_body(), "/frames")

    def test_long_morph_given_times_is_422_naming_times(self):
        body = long_ring_morph_body(times=[i / 999 for i in range(1000)])
        del body["frames"]
        self.refused(body, "/times")

    def test_daemon_serves_normally_after_a_refusal(self):
        self.refused(long_ring_morph_body(), "/frames")
        self.assertEqual(self.d.request("GET", "/healthz").status, 200)
        r = self.d.request("POST", "/v1/morph", body=morph_body(3))
        doc = self.assertDocumented(r, "/v1/morph", "post")
        self.assertEqual(r.status, 200, r.body[:300])
        self.assertEqual([f["t"] for f in doc["frames"]], [0, 0.5, 1])

    def test_refusals_are_counted_in_the_metrics(self):
        def count():
            text = self.d.request("GET", "/metrics").body.decode()
            return metric(text, "kmorph_rejected_total",
                          {"reason": "morph_time"})
        before = count()
        self.refused(long_ring_morph_body(), "/frames")
        self.assertEqual(count(), before + 1)

    def test_the_same_morph_as_a_job_is_not_held_to_it(self):
        r, _, s = run_job(self.d, heavy_morph_body(1000))
        self.assertEqual(r.status, 202, r.body[:300])
        self.assertTrue(s, "the job ends")
        self.assertEqual(s["state"], "done", s)


if __name__ == "__main__":
    unittest.main()
