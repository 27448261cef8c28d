"""test_conventions.py - kmorphd's HTTP conventions and safe defaults:
problem types that resolve and carry `instance`, content negotiation (406,
Vary, q-values), ETag / Cache-Control / 304, Retry-After for polling,
gzip, CORS off by default, PORT, the worker count from the usable CPUs,
the metrics' labels and process_* series, JSON logs."""
import gzip
import json
import os
import re
import socket
import subprocess
import time
import unittest

from kmtest import (DAEMON, HOST, ROOT, SPEC, ContractCase, Daemon,
                    DaemonCase, deref,
                    component,
                    metric, morph_body, raw_exchange, ring_morph_body,
                    run_job, schema_errors, wait_for)

WEB_ROOT = os.path.join(ROOT, "clients", "web")
WEB = os.path.exists(os.path.join(WEB_ROOT, "index.html"))


def problem_types_in_sources():
    """Every /problems/<name> the C sources of the daemon name."""
    names = set()
    for folder in ("server/src", "api/src"):
        for f in os.listdir(os.path.join(ROOT, folder)):
            if f.endswith((".c", ".h")) and f != "openapi.c":
                with open(os.path.join(ROOT, folder, f)) as fh:
                    names |= set(re.findall(r'"/problems/([a-z-]+)"',
                                            fh.read()))
    return sorted(names)


def free_port():
    with socket.socket() as s:
        s.bind((HOST, 0))
        return s.getsockname()[1]


def slurp(path):
    with open(path, encoding="utf-8", errors="replace") as f:
        return f.read()


def listening_port(proc, log, timeout=20):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        with open(log, encoding="utf-8", errors="replace") as f:
            m = re.search(r"listening on http://[^ ]*:(\d+)", f.read())
        if m:
            return int(m.group(1))
        if proc.poll() is not None:
            break
        time.sleep(0.02)
    return None


class Problems(ContractCase):
    @classmethod
    def setUpClass(cls):
        cls.d = Daemon("--threads", "1")

    @classmethod
    def tearDownClass(cls):
        cls.d.stop()

    def test_every_problem_type_in_the_sources_resolves_as_json(self):
        names = problem_types_in_sources()
        self.assertIn("invalid-request", names)
        self.assertIn("not-acceptable", names)
        for name in names:
            r = self.d.request("GET", "/problems/" + name)
            self.assertEqual(r.status, 200, name)
            self.assertEqual(r.ctype, "application/json", name)
            doc = r.json()
            self.assertEqual(doc["type"], "/problems/" + name)
            self.assertTrue(doc["title"] and doc["description"], name)
            self.assertTrue(400 <= doc["status"] <= 599, name)
            self.assertIn("Accept", r.header("Vary"))
            self.assertDocumented(r, "/problems/{name}", "get")

    def test_problem_type_is_html_when_the_client_prefers_it(self):
        r = self.d.request("GET", "/problems/job-gone", headers={
            "Accept": "text/html,application/xhtml+xml,*/*;q=0.8"})
        self.assertEqual(r.status, 200)
        self.assertEqual(r.ctype, "text/html")
        self.assertIn(b"/problems/job-gone", r.body)
        self.assertIn(b"410", r.body)

    def test_unknown_problem_type_is_404(self):
        r = self.d.request("GET", "/problems/no-such-thing")
        self.assertEqual(r.status, 404)
        self.assertEqual(r.ctype, "application/problem+json")

    def test_problems_carry_instance_as_the_request_id_urn(self):
        cases = [self.d.request("GET", "/v1/nowhere"),
                 self.d.request("POST", "/v1/morph", body={"frames": 3}),
                 self.d.request("GET", "/v1/jobs/0123abcd"),
                 self.d.request("GET", "/healthz",
                                headers={"X-Request-Id": "trace-42"})]
        cases[-1] = self.d.request("PUT", "/healthz",
                                   headers={"X-Request-Id": "trace-42"})
        for r in cases:
            self.assertEqual(r.ctype, "application/problem+json")
            doc = r.json()
            self.assertEqual(doc["instance"],
                             "urn:kmorph:request:" + doc["request_id"])
            self.assertEqual(doc["request_id"], r.header("X-Request-Id"))
            self.assertEqual(schema_errors(doc, component("Problem")), [])
        self.assertEqual(cases[-1].json()["instance"],
                         "urn:kmorph:request:trace-42")

    def test_a_framing_refusal_carries_instance_too(self):
        raw = raw_exchange(self.d.port, [b"GET / HTTP/1.1\r\nHost: x\r\n"
                                         b"Content-Length: 1\r\n"
                                         b"Content-Length: 2\r\n\r\n"])
        doc = json.loads(raw.split(b"\r\n\r\n", 1)[1])
        self.assertTrue(doc["instance"].startswith("urn:kmorph:request:"))


class LateRequestProblem(unittest.TestCase):
    def test_a_late_request_408_carries_instance_and_its_request_id(self):
        d = Daemon("--header-time", "0.2")
        try:
            raw = raw_exchange(d.port, [b"GET /healthz HTTP/1.1\r\nHo"],
                               timeout=10)
        finally:
            d.stop()
        head, body = raw.split(b"\r\n\r\n", 1)
        self.assertIn(b" 408 ", head.split(b"\r\n")[0])
        doc = json.loads(body)
        rid = re.search(rb"X-Request-Id: (\S+)", head).group(1).decode()
        self.assertEqual(doc["request_id"], rid)
        self.assertEqual(doc["instance"], "urn:kmorph:request:" + rid)
        self.assertEqual(schema_errors(doc, component("Problem")), [])


class Negotiation(ContractCase):
    @classmethod
    def setUpClass(cls):
        cls.d = Daemon("--threads", "2", "--web-root", WEB_ROOT)

    @classmethod
    def tearDownClass(cls):
        cls.d.stop()

    def test_accept_the_route_cannot_produce_is_406_problem(self):
        for method, path, body, accept in [
                ("POST", "/v1/morph", morph_body(3), "image/png"),
                ("POST", "/v1/signature", {}, "text/html"),
                ("GET", "/healthz", None, "text/html"),
                ("GET", "/openapi.json", None, "application/yaml"),
                ("GET", "/metrics", None, "application/json"),
                ("POST", "/v1/morph", morph_body(3),
                 "application/json;q=0, image/svg+xml;q=0, */*;q=0")]:
            r = self.d.request(method, path, body=body,
                               headers={"Accept": accept})
            self.assertEqual(r.status, 406, (path, accept))
            self.assertEqual(r.ctype, "application/problem+json")
            self.assertEqual(r.json()["type"], "/problems/not-acceptable")
            self.assertIn("Accept", r.header("Vary"))

    def test_wildcards_and_q_values_are_honoured(self):
        ok = [("GET", "/healthz", None, "*/*"),
              ("GET", "/healthz", None, "application/*;q=0.1"),
              ("GET", "/healthz", None, "text/html, application/json;q=0.5"),
              ("GET", "/metrics", None, "text/plain;version=0.0.4"),
              ("POST", "/v1/morph", morph_body(3), "image/*")]
        for method, path, body, accept in ok:
            r = self.d.request(method, path, body=body,
                               headers={"Accept": accept})
            self.assertEqual(r.status, 200, (path, accept))
        r = self.d.request("POST", "/v1/morph", body=morph_body(3), headers={
            "Accept": "application/json;q=0, image/svg+xml"})
        self.assertEqual(r.ctype, "image/svg+xml")

    def test_odd_headers_fall_back_to_what_they_can_mean(self):
        # a malformed q counts as 1 (no 406 for a typo); an empty Accept
        # accepts anything; x-gzip is gzip; q=0.0 excludes
        for accept in ("application/json;q=abc", "", " , ,"):
            r = self.d.request("GET", "/healthz",
                               headers={"Accept": accept})
            self.assertEqual(r.status, 200, repr(accept))
        r = self.d.request("GET", "/openapi.json",
                           headers={"Accept-Encoding": "x-gzip"})
        self.assertEqual(r.header("Content-Encoding"), "gzip")
        r = self.d.request("GET", "/openapi.json",
                           headers={"Accept-Encoding": "gzip;q=0.0, *;q=0"})
        self.assertIsNone(r.header("Content-Encoding"))
        r = self.d.request("GET", "/openapi.json",
                           headers={"Accept": "APPLICATION/JSON"})
        self.assertEqual(r.status, 200, "media types are case-insensitive")

    def test_vary_accept_on_answers_that_depend_on_it(self):
        for method, path, body in [("POST", "/v1/morph", morph_body(3)),
                                   ("GET", "/openapi.json", None),
                                   ("GET", "/", None),
                                   ("GET", "/problems/not-found", None)]:
            r = self.d.request(method, path, body=body)
            vary = [v.strip() for v in (r.header("Vary") or "").split(",")]
            self.assertIn("Accept", vary, path)
        for path in ("/", "/openapi.json"):
            r = self.d.request("GET", path)
            self.assertIn("Accept-Encoding", r.header("Vary"), path)


class Caching(ContractCase):
    @classmethod
    def setUpClass(cls):
        cls.d = Daemon("--threads", "1", "--web-root", WEB_ROOT)

    @classmethod
    def tearDownClass(cls):
        cls.d.stop()

    def paths(self):
        return ["/openapi.json", "/"] + (["/app.js"] if WEB else [])

    def test_static_answers_have_a_strong_etag_and_cache_control(self):
        for path in self.paths():
            r = self.d.request("GET", path)
            self.assertEqual(r.status, 200, path)
            etag = r.header("ETag")
            self.assertRegex(etag, r'^"[^"]+"$', path)  # strong: no W/
            self.assertTrue(r.header("Cache-Control"), path)
            again = self.d.request("GET", path)
            self.assertEqual(again.header("ETag"), etag, "stable " + path)
            r304 = self.d.request("GET", path,
                                  headers={"If-None-Match": etag})
            self.assertEqual(r304.status, 304, path)
            self.assertEqual(r304.body, b"")
            self.assertEqual(r304.header("ETag"), etag)
            other = self.d.request("GET", path,
                                   headers={"If-None-Match": '"nope", ' +
                                            'W/' + etag})
            self.assertEqual(other.status, 304, "weak comparison " + path)
            miss = self.d.request("GET", path,
                                  headers={"If-None-Match": '"nope"'})
            self.assertEqual(miss.status, 200)

    def test_finished_job_result_is_immutable_with_etag_and_304(self):
        r, jid, final = run_job(self.d, morph_body(5))
        self.assertEqual(r.status, 202)
        self.assertEqual(final["state"], "done")
        res = self.d.request("GET", "/v1/jobs/%s/result" % jid)
        self.assertEqual(res.status, 200)
        cc = res.header("Cache-Control")
        self.assertIn("immutable", cc)
        self.assertIn("private", cc)
        etag = res.header("ETag")
        self.assertTrue(etag)
        r304 = self.d.request("GET", "/v1/jobs/%s/result" % jid,
                              headers={"If-None-Match": etag})
        self.assertEqual(r304.status, 304)
        self.assertEqual(r304.body, b"")
        # The job's state is not cacheable: it changes.
        st = self.d.request("GET", "/v1/jobs/" + jid)
        self.assertEqual(st.header("Cache-Control"), "no-store")

    def test_retry_after_hints_polling_on_202_and_on_unfinished_jobs(self):
        r = self.d.request("POST", "/v1/jobs", body=ring_morph_body(400))
        self.assertEqual(r.status, 202)
        self.assertTrue(int(r.header("Retry-After")) >= 1)
        jid = r.json()["id"]
        st = self.d.request("GET", "/v1/jobs/" + jid)
        self.assertIn(st.json()["state"], ("queued", "running"))
        self.assertTrue(int(st.header("Retry-After")) >= 1)
        self.d.request("DELETE", "/v1/jobs/" + jid)
        done = wait_for(lambda: self.d.request("GET", "/v1/jobs/" + jid)
                        .json()["state"] == "cancelled" or None, 30)
        self.assertTrue(done)
        st = self.d.request("GET", "/v1/jobs/" + jid)
        self.assertIsNone(st.header("Retry-After"))


class Compression(ContractCase):
    @classmethod
    def setUpClass(cls):
        cls.d = Daemon("--threads", "2", "--web-root", WEB_ROOT)

    @classmethod
    def tearDownClass(cls):
        cls.d.stop()

    def test_static_files_are_gzip_when_accepted_with_a_correct_length(self):
        for path in ["/openapi.json", "/"] + (["/app.js"] if WEB else []):
            plain = self.d.request("GET", path)
            gz = self.d.request("GET", path,
                                headers={"Accept-Encoding": "br, gzip"})
            self.assertEqual(gz.header("Content-Encoding"), "gzip", path)
            self.assertEqual(int(gz.header("Content-Length")), len(gz.body))
            self.assertEqual(gzip.decompress(gz.body), plain.body, path)
            self.assertEqual(int(gz.header("X-Uncompressed-Length")),
                             len(plain.body))
            self.assertLess(len(gz.body), len(plain.body))
            self.assertNotEqual(gz.header("ETag"), plain.header("ETag"))
            head = self.d.request("HEAD", path,
                                  headers={"Accept-Encoding": "gzip"})
            self.assertEqual(head.header("Content-Length"),
                             gz.header("Content-Length"), "HEAD " + path)
            self.assertIsNone(plain.header("Content-Encoding"))

    def test_q_zero_and_small_bodies_are_sent_as_they_are(self):
        r = self.d.request("GET", "/openapi.json",
                           headers={"Accept-Encoding": "gzip;q=0, br"})
        self.assertIsNone(r.header("Content-Encoding"))
        r = self.d.request("GET", "/openapi.json",
                           headers={"Accept-Encoding": "*;q=0.5"})
        self.assertEqual(r.header("Content-Encoding"), "gzip")
        r = self.d.request("GET", "/healthz",
                           headers={"Accept-Encoding": "gzip"})
        self.assertIsNone(r.header("Content-Encoding"))
        r = self.d.request("POST", "/v1/morph", body=morph_body(1),
                           headers={"Accept-Encoding": "gzip"})
        self.assertIsNone(r.header("Content-Encoding"), "under 1 KiB")

    def test_large_morph_and_job_results_are_gzip_streamed(self):
        body = morph_body(400)
        plain = self.d.request("POST", "/v1/morph", body=body)
        gz = self.d.request("POST", "/v1/morph", body=body,
                            headers={"Accept-Encoding": "gzip"})
        self.assertEqual(plain.status, 200)
        self.assertEqual(gz.header("Content-Encoding"), "gzip")
        self.assertEqual(gzip.decompress(gz.body), plain.body)
        self.assertLess(len(gz.body), len(plain.body) / 2)
        self.assertEqual(int(gz.header("X-Uncompressed-Length")),
                         len(plain.body), "for download progress")
        r, jid, final = run_job(self.d, morph_body(1000), timeout=60)
        self.assertEqual(final["state"], "done")
        url = "/v1/jobs/%s/result" % jid
        plain = self.d.request("GET", url)
        gz = self.d.request("GET", url, headers={"Accept-Encoding": "gzip"})
        self.assertGreater(len(plain.body), 1 << 20, "megabytes")
        self.assertEqual(gz.header("Content-Encoding"), "gzip")
        self.assertEqual(gzip.decompress(gz.body), plain.body)
        self.assertLess(len(gz.body), len(plain.body) / 2)
        r304 = self.d.request("GET", url, headers={
            "Accept-Encoding": "gzip", "If-None-Match": gz.header("ETag")})
        self.assertEqual(r304.status, 304)


class Metrics(ContractCase):
    @classmethod
    def setUpClass(cls):
        cls.d = Daemon("--threads", "1")

    @classmethod
    def tearDownClass(cls):
        cls.d.stop()

    def test_request_counters_have_code_and_method_and_start_at_zero(self):
        text = self.d.request("GET", "/metrics").body.decode()
        for route, method in [("morph", "POST"), ("jobs", "POST"),
                              ("job", "DELETE"), ("job_result", "GET"),
                              ("healthz", "GET"), ("static", "HEAD")]:
            for code in ("200", "404", "422", "503"):
                self.assertEqual(metric(text, "kmorph_http_requests_total",
                                        {"route": route, "method": method,
                                         "code": code}), 0,
                                 (route, method, code))
        self.assertNotIn('status="', text)
        self.d.request("GET", "/healthz")
        self.d.request("POST", "/healthz")
        self.d.request("BREW", "/healthz")
        text = self.d.request("GET", "/metrics").body.decode()
        self.assertEqual(metric(text, "kmorph_http_requests_total",
                                {"route": "healthz", "method": "GET",
                                 "code": "200"}), 1)
        self.assertEqual(metric(text, "kmorph_http_requests_total",
                                {"route": "healthz", "method": "POST",
                                 "code": "405"}), 1)
        self.assertGreaterEqual(metric(text, "kmorph_http_requests_total",
                                       {"route": "healthz",
                                        "method": "other",
                                        "code": "405"}) or 0, 0)

    def test_process_metrics_come_from_proc_self(self):
        text = self.d.request("GET", "/metrics").body.decode()
        for family, kind in [("process_cpu_seconds_total", "counter"),
                             ("process_resident_memory_bytes", "gauge"),
                             ("process_open_fds", "gauge"),
                             ("process_max_fds", "gauge"),
                             ("process_start_time_seconds", "gauge")]:
            self.assertIn("# TYPE %s %s" % (family, kind), text)
        rss = metric(text, "process_resident_memory_bytes")
        self.assertAlmostEqual(rss / 1024, self.d.rss_kb(),
                               delta=self.d.rss_kb() * 0.5 + 1024)
        self.assertAlmostEqual(metric(text, "process_open_fds"),
                               self.d.fds(), delta=4)
        start = metric(text, "process_start_time_seconds")
        self.assertLess(abs(start - time.time()), 120)
        self.assertGreaterEqual(metric(text, "process_cpu_seconds_total"), 0)
        self.assertGreater(metric(text, "process_max_fds"), 0)


class JsonLogs(unittest.TestCase):
    def test_every_line_is_one_json_object_with_strings_escaped(self):
        import signal
        import tempfile
        tmp = tempfile.mkdtemp(prefix='kmorphd-"json\\log-')
        path = os.path.join(tmp, 'a "quoted"\\name.log')
        e = {k: v for k, v in os.environ.items()
             if not k.startswith("KMORPH_")}
        e["KMORPH_LOG_FORMAT"] = "json"
        proc = subprocess.Popen([DAEMON, "--bind", HOST, "--port", "0",
                                 "--log-file", path],
                                stdout=subprocess.DEVNULL,
                                stderr=subprocess.DEVNULL, env=e)
        try:
            self.assertTrue(wait_for(lambda: os.path.exists(path) and
                                     "listening" in slurp(path)
                                     or None, 20))
            port = int(re.search(r"http://[^ ]*:(\d+)",
                                 slurp(path)).group(1))
            from kmtest import request
            request(port, "GET", "/healthz", headers={"X-Request-Id": "id-7"})
            request(port, "GET", "/v1/nowhere")
            raw_exchange(port, [b"GET / HTTP/1.1\r\nHost: x\r\n"
                                b"Content-Length: 1\r\n"
                                b"Content-Length: 2\r\n\r\n"])
            proc.send_signal(signal.SIGHUP)
            wait_for(lambda: "reopened" in slurp(path) or None, 10)
        finally:
            proc.terminate()
            proc.wait(timeout=30)
        lines = [json.loads(l) for l in slurp(path).splitlines() if l.strip()]
        import shutil
        shutil.rmtree(tmp)
        access = [l for l in lines if l.get("event") == "access"]
        notices = [l for l in lines if l.get("level") == "notice"]
        ok = [l for l in access if l.get("request_id") == "id-7"][0]
        self.assertEqual((ok["method"], ok["path"], ok["status"]),
                         ("GET", "/healthz", 200))
        self.assertIsInstance(ok["duration_ms"], float)
        self.assertTrue(any(l.get("status") == 404 for l in access))
        self.assertTrue(any(l.get("refused_framing") for l in access))
        reopened = [n for n in notices if "reopened" in n["msg"]]
        self.assertTrue(reopened)
        self.assertIn(path, reopened[0]["msg"])  # quotes, backslash intact
        self.assertTrue(any("listening on http://" in n["msg"]
                            for n in notices))
        for l in lines:
            self.assertRegex(l["time"], r"^\d{4}-\d\d-\d\dT[\d:]{8}Z$")

    def test_an_unknown_log_format_is_refused(self):
        out = subprocess.run([DAEMON, "--log-format", "xml"],
                             capture_output=True, text=True, timeout=10)
        self.assertEqual(out.returncode, 2)
        self.assertIn("log-format", out.stderr)


class SafeDefaults(unittest.TestCase):
    def test_no_cors_headers_unless_origins_are_configured(self):
        d = Daemon()
        try:
            r = d.request("GET", "/healthz",
                          headers={"Origin": "https://evil.example"})
            self.assertEqual(r.status, 200)
            self.assertIsNone(r.header("Access-Control-Allow-Origin"))
            r = d.request("OPTIONS", "/v1/morph", headers={
                "Origin": "https://evil.example",
                "Access-Control-Request-Method": "POST"})
            self.assertEqual(r.status, 204)
            self.assertIsNone(r.header("Access-Control-Allow-Origin"))
            self.assertIsNone(r.header("Access-Control-Allow-Methods"))
        finally:
            d.stop()

    def _run(self, args, env, tmp):
        log = os.path.join(tmp, "log")
        e = {k: v for k, v in os.environ.items()
             if not k.startswith("KMORPH_") and k != "PORT"}
        e.update(env)
        with open(log, "wb") as lf:
            p = subprocess.Popen([DAEMON, "--bind", HOST, *args],
                                 stdout=subprocess.DEVNULL, stderr=lf, env=e)
        try:
            return listening_port(p, log)
        finally:
            p.terminate()
            p.wait(timeout=30)

    def test_port_variable_is_the_fallback_under_kmorph_port_and_flag(self):
        import tempfile
        tmp = tempfile.mkdtemp(prefix="kmorphd-port-")
        a, b, c = free_port(), free_port(), free_port()
        self.assertEqual(self._run([], {"PORT": str(a)}, tmp), a)
        self.assertEqual(self._run([], {"PORT": str(a),
                                        "KMORPH_PORT": str(b)}, tmp), b)
        self.assertEqual(self._run(["--port", str(c)],
                                   {"PORT": str(a), "KMORPH_PORT": str(b)},
                                   tmp), c)

    def test_workers_default_to_the_cpus_the_process_may_use(self):
        mask = os.sched_getaffinity(0)
        os.sched_setaffinity(0, {min(mask)})
        try:
            d = Daemon()
        finally:
            os.sched_setaffinity(0, mask)
        try:
            text = d.request("GET", "/metrics").body.decode()
            self.assertEqual(metric(text, "kmorph_workers"), 1)
        finally:
            d.stop()

    def test_shutdown_grace_default_is_below_a_container_stop_timeout(self):
        out = subprocess.run([DAEMON, "--help"], capture_output=True,
                             text=True, timeout=10).stdout
        line = [l for l in out.splitlines() if "--shutdown-grace" in l][0]
        grace = float(re.search(r"\(default ([0-9.]+)\)", line).group(1))
        self.assertLess(grace, 10)
        self.assertGreater(grace, 0)


def operations():
    for path, ops in SPEC["paths"].items():
        for method, op in ops.items():
            if method in ("get", "post", "delete"):
                yield path, method, op


def media_types():
    """(where, media type, its object) of every response with content."""
    for path, method, op in operations():
        for status, resp in op["responses"].items():
            for mt, obj in deref(resp).get("content", {}).items():
                yield "%s %s %s" % (method, path, status), mt, obj


class Examples(DaemonCase):
    """Every request and response of the contract has examples; request
    examples are the files of docs/examples, answered by the live daemon
    with a documented status and schema."""

    def test_every_request_body_has_examples_from_docs_examples(self):
        seen = 0
        for path, method, op in operations():
            if "requestBody" not in op:
                continue
            ex = op["requestBody"]["content"]["application/json"]["examples"]
            self.assertTrue(ex, path)
            for name, ref in ex.items():
                e = deref(ref)
                fname = e["description"]
                self.assertTrue(fname.startswith("docs/examples/"), name)
                with open(os.path.join(ROOT, fname)) as f:
                    self.assertEqual(e["value"], json.load(f), name)
                seen += 1
        self.assertGreaterEqual(seen, len(os.listdir(
            os.path.join(ROOT, "docs", "examples"))))

    def test_request_examples_are_answered_as_documented(self):
        for path, method, op in operations():
            if "requestBody" not in op:
                continue
            ex = op["requestBody"]["content"]["application/json"]["examples"]
            for name, ref in ex.items():
                r = self.d.request(method.upper(), path,
                                   body=deref(ref)["value"])
                self.assertIn(r.status, (200, 202), (path, name, r.body[:300]))
                self.assertDocumented(r, path, method)

    def test_served_contract_is_the_yaml_with_its_examples(self):
        served = self.d.request("GET", "/openapi.json").json()
        self.assertEqual(served, json.loads(json.dumps(SPEC)))
        self.assertIn("MorphSpirals", served["components"]["examples"])

    def test_every_response_has_examples_that_fit_its_schema(self):
        for where, mt, obj in media_types():
            ex = obj.get("examples")
            self.assertTrue(ex, "%s %s has no examples" % (where, mt))
            for name, ref in ex.items():
                value = deref(ref)["value"]
                if mt.endswith("json"):
                    self.assertEqual(schema_errors(value, obj["schema"]), [],
                                     "%s %s %s" % (where, mt, name))
                else:
                    self.assertIsInstance(value, str, name)


class Documented(unittest.TestCase):
    def test_new_settings_are_in_help_man_page_env_file_and_readme(self):
        out = subprocess.run([DAEMON, "--help"], capture_output=True,
                             text=True, timeout=10).stdout
        for word in ("--log-format", "KMORPH_LOG_FORMAT", "PORT",
                     "cgroup"):
            self.assertIn(word, out)
        texts = {}
        for name in ("packaging/kmorphd.8.in", "packaging/kmorphd.env",
                     "README.md"):
            texts[name] = slurp(os.path.join(ROOT, name))
        self.assertIn(".B PORT", texts["packaging/kmorphd.8.in"])
        self.assertIn("/problems/", texts["packaging/kmorphd.8.in"])
        for word in ("KMORPH_LOG_FORMAT", "KMORPH_SHUTDOWN_GRACE=8"):
            self.assertIn(word, texts["packaging/kmorphd.env"])
        for word in ("--log-format=json", "`PORT`", "cpu.max", "406",
                     "If-None-Match", "process_open_fds", "instance"):
            self.assertIn(word, texts["README.md"])


class CpuQuota(unittest.TestCase):
    def test_cgroup_cpu_max_is_read_by_the_running_daemon(self):
        """The quota parser is exercised through the daemon only where a
        cgroup v2 quota applies; here just check the daemon's count never
        exceeds the affinity mask."""
        d = Daemon()
        try:
            text = d.request("GET", "/metrics").body.decode()
            self.assertLessEqual(metric(text, "kmorph_workers"),
                                 len(os.sched_getaffinity(0)))
        finally:
            d.stop()


if __name__ == "__main__":
    unittest.main()
