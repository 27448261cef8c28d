"""test_kmorph.py - the Python client (clients/python/kmorph) and its
command line against a live kmorphd on a free loopback port. Expected
numbers come from closed forms (circles, squares, the paper's
linear-curvature spirals), not from the service."""
import json
import math
import os
import re
import subprocess
import sys
import tempfile
import threading
import time
import unittest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "clients", "python"))

import kmorph  # noqa: E402
from kmorph import Client, KmorphError, JobCancelled  # noqa: E402

DAEMON = os.environ.get("KMORPHD", os.path.join(ROOT, "build", "kmorphd"))
TAU = 2 * math.pi
PROC = None
URL = None
LOG = None


def setUpModule():
    global PROC, URL, LOG
    LOG = log = tempfile.TemporaryFile()
    env = {k: v for k, v in os.environ.items() if not k.startswith("KMORPH_")}
    PROC = subprocess.Popen([DAEMON, "--bind", "127.0.0.1", "--port", "0",
                             "--max-job-frames", "50000",
                             "--web-root", os.path.join(ROOT, "clients", "web")],
                            stdout=subprocess.DEVNULL, stderr=log, env=env)
    deadline = time.monotonic() + 10
    while time.monotonic() < deadline:
        log.seek(0)
        m = re.search(rb"listening on (http://[0-9.]+:\d+)", log.read())
        if m:
            URL = m.group(1).decode()
            return
        if PROC.poll() is not None:
            break
        time.sleep(0.05)
    PROC.kill()
    PROC.wait(10)
    log.close()
    raise RuntimeError("kmorphd did not start")


def tearDownModule():
    if PROC and PROC.poll() is None:
        PROC.terminate()
        try:
            PROC.wait(10)
        except subprocess.TimeoutExpired:
            PROC.kill()
            PROC.wait(10)
    if LOG:
        LOG.close()


def circle(r):
    return {"type": "svg", "d": "M %r 0 A %r %r 0 1 1 %r 0 A %r %r 0 1 1 %r 0 Z" % (r, r, r, -r, r, r, r)}


SQUARE100 = "M 0 0 L 100 0 L 100 100 L 0 100 Z"
CIRCLE50 = "M 150 50 A 50 50 0 1 1 50 50 A 50 50 0 1 1 150 50 Z"


def spiral(c, length=4.0):
    """kappa(s) = c s on [0, length]: the paper's Cornu spirals (Fig. 3)."""
    return {"type": "signature", "signature": {
        "length": length, "start": {"point": [0, 0], "angle": 0},
        "kappa": {"degree": 1, "knots": [0, 0, length, length], "coefficients": [0, c * length]}}}


UNIT_CIRCLE_SIG = {"length": TAU, "start": {"point": [0, 0], "angle": 0},
                   "kappa": {"degree": 1, "knots": [0, 0, TAU, TAU], "coefficients": [1, 1]},
                   "closed": True}


def path_numbers(d):
    return [float(x) for x in re.findall(r"-?\d*\.?\d+(?:e[-+]?\d+)?", d, re.I)]


class ClientTest(unittest.TestCase):
    def setUp(self):
        self.km = Client(URL)

    def test_signature_of_a_circle_has_length_2_pi_r_and_curvature_1_over_r(self):
        r = self.km.signature(circle(4.0), tolerance=1e-8, samples=11)
        self.assertAlmostEqual(r["signature"]["length"], 8 * math.pi, delta=1e-6)
        self.assertAlmostEqual(abs(r["signature"]["turning"]), TAU, delta=1e-7)
        self.assertEqual(len(r["samples"]), 11)
        for _, k in r["samples"]:
            self.assertAlmostEqual(abs(k), 0.25, delta=1e-7)

    def test_reconstruct_of_unit_curvature_is_the_unit_circle_within_the_bound(self):
        r = self.km.reconstruct(UNIT_CIRCLE_SIG, tolerance=1e-6)
        c, bound = r["curve"], r["error_bound"]
        self.assertTrue(0 < bound <= 1e-6)
        p, U = c["degree"], c["knots"]
        a, b = U[p], U[len(U) - p - 1]
        for i in range(301):
            (x, y), _ = kmorph.eval_curve(c, a + (b - a) * i / 300)
            self.assertLessEqual(abs(math.hypot(x, y - 1) - 1), bound + 1e-12)

    def test_curve_to_path_is_exact_for_cubics(self):
        r = self.km.reconstruct(UNIT_CIRCLE_SIG, tolerance=1e-7)
        d = kmorph.curve_to_path(r["curve"])
        self.assertTrue(d.startswith("M") and d.endswith("Z"))
        nums = path_numbers(d)
        x, y = nums[0], nums[1]
        for i in range(2, len(nums) - 5, 6):
            x1, y1, x2, y2, x3, y3 = nums[i:i + 6]
            for j in range(7):
                t = j / 6
                s = 1 - t
                px = s**3 * x + 3 * s * s * t * x1 + 3 * s * t * t * x2 + t**3 * x3
                py = s**3 * y + 3 * s * s * t * y1 + 3 * s * t * t * y2 + t**3 * y3
                self.assertLess(abs(math.hypot(px, py - 1) - 1), r["error_bound"] + 2e-6)
            x, y = x3, y3

    def test_sample_points_are_equally_spaced_along_the_arc(self):
        r = self.km.reconstruct(UNIT_CIRCLE_SIG, tolerance=1e-8)
        n = 48
        pts = kmorph.sample_points(r["curve"], n + 1, per_span=64)
        chord = 2 * math.sin(math.pi / n)
        for i in range(1, n + 1):
            self.assertAlmostEqual(math.dist(pts[i], pts[i - 1]), chord, delta=1e-4)

    def test_spiral_morph_blends_curvature_linearly(self):
        res = self.km.morph({"from": spiral(1), "to": spiral(-0.5), "frames": 5,
                             "metrics": True, "include": ["svg_d"]})
        self.assertEqual(len(res["frames"]), 5)
        for i, f in enumerate(res["frames"]):
            t = i / 4
            self.assertAlmostEqual(f["metrics"]["max_abs_kappa"], 4 * abs(1 - 1.5 * t), delta=1e-6)
            self.assertAlmostEqual(f["metrics"]["length"], 4, delta=1e-9)
        self.assertEqual(kmorph.frame_paths(res), [f["curve"]["svg_d"] for f in res["frames"]])

    def test_linear_spiral_morph_self_intersects_and_curvature_does_not(self):
        req = {"from": spiral(1), "to": spiral(-0.5), "frames": 5, "metrics": True}
        lin = self.km.morph(dict(req, method="linear"))
        cur = self.km.morph(req)
        self.assertTrue(any(f["metrics"]["self_intersections"] > 0 for f in lin["frames"]))
        self.assertTrue(all(f["metrics"]["self_intersections"] == 0 for f in cur["frames"]))

    def test_interpolator_between_concentric_circles_is_a_circle_of_the_mean_radius(self):
        res = self.km.morph({"from": circle(1), "to": circle(3), "frames": 3,
                             "anchor": "centroid", "tolerance": 1e-7})
        at = kmorph.interpolator(res, samples=256)
        for t, r in ((0.5, 2.0), (0.25, 1.5)):
            nums = path_numbers(at(t))
            pts = list(zip(nums[0::2], nums[1::2]))
            cx = sum(p[0] for p in pts) / len(pts)
            cy = sum(p[1] for p in pts) / len(pts)
            for p in pts:
                self.assertAlmostEqual(math.hypot(p[0] - cx, p[1] - cy), r, delta=2e-3)
        lo = kmorph.bounds(res)
        self.assertGreaterEqual(lo[2] - lo[0], 6 - 1e-6)

    def test_svg_format_returns_an_svg_document(self):
        svg = self.km.morph({"from": circle(1), "to": circle(2), "frames": 3,
                             "format": "svg", "svg": {"layout": "overlay"}})
        self.assertIsInstance(svg, str)
        self.assertIn("<svg", svg[:300])

    def test_morph_job_reports_rising_progress_and_matches_the_synchronous_morph(self):
        req = {"from": {"type": "svg", "d": SQUARE100}, "to": {"type": "svg", "d": CIRCLE50},
               "frames": 300, "metrics": True}
        seen = []
        res = self.km.morph_job(req, on_progress=seen.append)
        self.assertGreaterEqual(len(seen), 2)
        self.assertEqual([s["progress"] for s in seen], sorted(s["progress"] for s in seen))
        self.assertEqual(seen[-1]["state"], "done")
        self.assertEqual(seen[-1]["progress"], 1)
        sync = self.km.morph(req)
        self.assertEqual([f["metrics"] for f in res["frames"]], [f["metrics"] for f in sync["frames"]])
        # L_t = (1 - t) 400 + t 100 pi under the turning blend.
        f = res["frames"][150]
        self.assertAlmostEqual(f["metrics"]["length"], (1 - f["t"]) * 400 + f["t"] * 100 * math.pi, delta=1e-6)

    def test_setting_cancel_cancels_the_job_on_the_service(self):
        cancel = threading.Event()
        ids = []

        def progress(s):
            ids.append(s["id"])
            cancel.set()
        req = {"from": {"type": "svg", "d": SQUARE100}, "to": {"type": "svg", "d": CIRCLE50}, "frames": 50000}
        with self.assertRaises(JobCancelled):
            self.km.morph_job(req, on_progress=progress, cancel=cancel)
        s = self.km.job(ids[0])
        self.assertEqual(s["state"], "cancelled")
        self.assertLess(s["frames_done"], 50000)
        with self.assertRaises(KmorphError) as cm:
            self.km.job_result(ids[0])
        self.assertEqual(cm.exception.status, 409)

    def test_invalid_curve_raises_the_problem_with_its_pointer(self):
        bad = {"type": "bspline", "degree": 3, "knots": [0, 0, 0, 1, 1, 1],
               "control_points": [[0, 0], [1, 1], [2, 0]]}
        with self.assertRaises(KmorphError) as cm:
            self.km.morph({"from": circle(1), "to": bad})
        e = cm.exception
        self.assertEqual(e.status, 422)
        self.assertEqual(e.problem["type"], "/problems/invalid-curve")
        self.assertIsNotNone(e.message_for("/to"))
        self.assertIsNone(e.message_for("/from"))
        self.assertIn("422", str(e))

    def test_malformed_json_is_400_and_unknown_job_is_404(self):
        with self.assertRaises(KmorphError) as cm:
            self.km.request("POST", "/v1/morph", '{"from": ')
        self.assertEqual(cm.exception.status, 400)
        with self.assertRaises(KmorphError) as cm:
            self.km.job("0123456789abcdef0123456789abcdef")
        self.assertEqual(cm.exception.status, 404)

    def test_unreachable_service_raises_status_0_naming_the_url(self):
        with self.assertRaises(KmorphError) as cm:
            Client("http://127.0.0.1:9", timeout=5).health()
        self.assertEqual(cm.exception.status, 0)
        self.assertIn("127.0.0.1:9", cm.exception.detail)


class CommandLineTest(unittest.TestCase):
    def run_cli(self, *args, stdin=None):
        env = dict(os.environ, KMORPH_URL=URL, PYTHONPATH=os.path.join(ROOT, "clients", "python"))
        return subprocess.run([sys.executable, "-m", "kmorph", *args], input=stdin,
                              capture_output=True, text=True, env=env, timeout=120)

    def test_health(self):
        r = self.run_cli("health")
        self.assertEqual((r.returncode, r.stdout.strip()), (0, "ok ready"))

    def test_signature_then_reconstruct_round_trips_a_circle(self):
        r = self.run_cli("signature", "M 10 0 A 10 10 0 1 1 -10 0 A 10 10 0 1 1 10 0 Z")
        self.assertEqual(r.returncode, 0, r.stderr)
        r2 = self.run_cli("reconstruct", "-t", "1e-7", "@-", stdin=r.stdout)
        self.assertEqual(r2.returncode, 0, r2.stderr)
        self.assertAlmostEqual(json.loads(r2.stdout)["curve"]["length"], 20 * math.pi, delta=1e-5)

    def test_morph_prints_frames_with_linear_lengths(self):
        r = self.run_cli("morph", "-n", "3", "-k", SQUARE100, CIRCLE50)
        self.assertEqual(r.returncode, 0, r.stderr)
        lengths = [f["metrics"]["length"] for f in json.loads(r.stdout)["frames"]]
        for got, want in zip(lengths, (400, 200 + 50 * math.pi, 100 * math.pi)):
            self.assertAlmostEqual(got, want, delta=1e-6)

    def test_job_prints_progress_and_saves_svg(self):
        with tempfile.TemporaryDirectory() as d:
            out = os.path.join(d, "m.svg")
            r = self.run_cli("job", "-n", "1000", "-o", out, SQUARE100, CIRCLE50)
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertRegex(r.stderr, r"job [0-9a-f]{32} done 100% \(1000/1000 frames\)")
            with open(out, encoding="utf-8") as f:
                self.assertIn("<svg", f.read(300))

    def test_errors_exit_1_with_the_problem_detail(self):
        r = self.run_cli("morph", "M 0 0 L 1 0", "M 0 0 L 1 0 Z")
        self.assertEqual(r.returncode, 1)
        self.assertIn("422 Invalid curve", r.stderr)
        self.assertIn("at /to/d:", r.stderr)
        self.assertEqual(r.stdout, "")

    def test_usage_errors_exit_2(self):
        self.assertEqual(self.run_cli("morph", "not a curve", "M 0 0 L 1 0").returncode, 2)
        self.assertEqual(self.run_cli("morph", SQUARE100).returncode, 2)
        self.assertEqual(self.run_cli().returncode, 2)


if __name__ == "__main__":
    unittest.main()
