"""The kmorph Python package (clients/python) installed as a package: a
fresh venv, `pip install --no-index --no-build-isolation` of a copy of
the source (no package index is needed, nothing is written beside the
source), then the installed `kmorph` console script against a live
kmorphd: --version equal to the API's info.version, the curvature of a
circle of radius 10 (1/10 everywhere), and a usage error naming the
field. Also checks py.typed ships and the public functions are typed."""
import inspect
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "clients", "python"))
sys.path.insert(0, os.path.dirname(__file__))

import kmorph  # noqa: E402
import test_kmorph as live  # noqa: E402  (its daemon start and stop)

VENV = None
WORK = None


def api_version():
    with open(os.path.join(ROOT, "api", "openapi.yaml"), encoding="utf-8") as f:
        m = re.search(r"^info:\n(?:[ \t]+.*\n)*?[ \t]+version:[ \t]*[\"']?([^\"'\s]+)", f.read(), re.M)
    return m.group(1)


def setUpModule():
    global VENV, WORK
    live.setUpModule()
    WORK = tempfile.mkdtemp(prefix="kmorph-venv-")
    src = os.path.join(WORK, "src")
    shutil.copytree(os.path.join(ROOT, "clients", "python"), src,
                    ignore=shutil.ignore_patterns("__pycache__", "*.egg-info", "build"))
    VENV = os.path.join(WORK, "venv")
    # The system's site packages give the build its setuptools and wheel
    # (python3-setuptools, python3-wheel) with no index to fetch them from.
    subprocess.run(["/usr/bin/python3", "-m", "venv", "--system-site-packages", VENV], check=True, timeout=120)
    subprocess.run([os.path.join(VENV, "bin", "pip"), "install", "--quiet", "--no-index",
                    "--no-build-isolation", src], check=True, timeout=300,
                   env=dict(os.environ, PIP_DISABLE_PIP_VERSION_CHECK="1"))


def tearDownModule():
    live.tearDownModule()
    if WORK:
        shutil.rmtree(WORK, ignore_errors=True)


def run_kmorph(*args):
    env = {k: v for k, v in os.environ.items() if not k.startswith("KMORPH_")}
    return subprocess.run([os.path.join(VENV, "bin", "kmorph"), *args], capture_output=True,
                          text=True, timeout=60, env=env, cwd=WORK)


class InstalledPackage(unittest.TestCase):
    def test_version_is_the_api_version(self):
        out = run_kmorph("--version")
        self.assertEqual(out.returncode, 0, out.stderr)
        self.assertEqual(out.stdout.strip(), "kmorph " + api_version())
        self.assertEqual(kmorph.__version__, api_version())
        version_file = os.path.join(ROOT, "VERSION")
        if os.path.exists(version_file):
            with open(version_file, encoding="utf-8") as f:
                self.assertEqual(kmorph.__version__, f.read().strip())

    def test_installed_command_uses_the_installed_module(self):
        py = os.path.join(VENV, "bin", "python")
        out = subprocess.run([py, "-c", "import kmorph, os; print(kmorph.__file__); "
                              "print(os.path.exists(os.path.join(os.path.dirname(kmorph.__file__), 'py.typed')))"],
                             capture_output=True, text=True, timeout=60, cwd=WORK)
        self.assertEqual(out.returncode, 0, out.stderr)
        where, typed = out.stdout.split()
        self.assertTrue(where.startswith(VENV), where)
        self.assertEqual(typed, "True")

    def test_signature_of_a_circle_through_the_command(self):
        r = 10
        d = "M %d 0 A %d %d 0 1 1 %d 0 A %d %d 0 1 1 %d 0 Z" % (r, r, r, -r, r, r, r)
        out = run_kmorph("--url", live.URL, "signature", d, "--samples", "9")
        self.assertEqual(out.returncode, 0, out.stderr)
        answer = json.loads(out.stdout)
        samples = answer["samples"]
        self.assertEqual(len(samples), 9)
        for s, kappa in samples:
            self.assertAlmostEqual(kappa, 1 / r, delta=1e-4)
        self.assertAlmostEqual(answer["signature"]["length"], 2 * 3.141592653589793 * r, delta=1e-3 * r)

    def test_bad_curve_is_a_clear_error(self):
        out = run_kmorph("--url", live.URL, "signature", "M 0 0 Q")
        self.assertEqual(out.returncode, 1)
        self.assertIn("curve", out.stderr)
        self.assertNotIn("Traceback", out.stderr)


class Typed(unittest.TestCase):
    def test_public_functions_have_annotations(self):
        names = [n for n in kmorph.__all__ if callable(getattr(kmorph, n)) and inspect.isfunction(getattr(kmorph, n))]
        self.assertGreaterEqual(len(names), 10)
        for n in names:
            sig = inspect.signature(getattr(kmorph, n))
            self.assertIsNot(sig.return_annotation, inspect.Signature.empty, n + " has a return type")
            for p in sig.parameters.values():
                self.assertIsNot(p.annotation, inspect.Parameter.empty, "%s(%s) is typed" % (n, p.name))


if __name__ == "__main__":
    unittest.main()
