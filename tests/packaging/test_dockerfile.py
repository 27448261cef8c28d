"""test_dockerfile.py - the Dockerfile, read: no container engine can build
it here (podman and buildah install from Debian 12, but the base image
debian:12-slim comes only from a registry), so each property the image
must have is checked on the file and, where the file names a command or a
path, on the real thing: the build stage installs every build dependency
(the Makefile's, libc6-dev included), the runtime stage exactly the
runtime libraries of those -dev packages (from dpkg's own Depends) and no
HTTP client, the labels are the OCI ones with the version from VERSION,
the files it copies exist after `make install` into a staging folder as
the build stage does, and its HEALTHCHECK command, run by sh, passes on a
live daemon and fails once it is gone.
"""
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "tests", "pylib"))
import kmdaemon  # noqa: E402

BUILD = os.environ.get("KM_BUILD", "build")
VERSION = open(os.path.join(ROOT, "VERSION")).read().strip()


def instructions(text):
    """[(stage index, INSTRUCTION, arguments)] with continuation lines
    joined and comments dropped."""
    out, stage, cur = [], -1, ""
    for line in text.splitlines():
        if not cur and (not line.strip() or line.lstrip().startswith("#")):
            continue
        if line.rstrip().endswith("\\"):
            cur += line.rstrip()[:-1] + " "
            continue
        cur += line
        word, _, rest = cur.strip().partition(" ")
        if word.upper() == "FROM":
            stage += 1
        out.append((stage, word.upper(), rest.strip()))
        cur = ""
    return out


def apt_installs(args):
    """Package names of the apt-get install commands in a RUN line."""
    names = []
    for cmd in re.split(r"&&|\|\||;", args):
        words = shlex.split(cmd)
        if "apt-get" in words and "install" in words:
            names += [w for w in words[words.index("install") + 1:]
                      if not w.startswith("-")]
    return names


def needed_packages():
    """The Debian packages of the Makefile's NEEDED_HEADERS."""
    with open(os.path.join(ROOT, "Makefile")) as f:
        text = f.read()
    m = re.search(r"^NEEDED_HEADERS \?=((?:.*\\\n)*.*)$", text, re.M)
    return [hp.split(":")[1] for hp in m.group(1).replace("\\\n", " ").split()]


class Dockerfile(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        with open(os.path.join(ROOT, "Dockerfile")) as f:
            cls.ins = instructions(f.read())
        cls.stages = max(s for s, _, _ in cls.ins) + 1

    def of(self, stage, word):
        return [a for s, w, a in self.ins if s == stage and w == word]

    def installs(self, stage):
        return [p for a in self.of(stage, "RUN") for p in apt_installs(a)]

    def test_two_stages_on_debian_12(self):
        self.assertEqual(self.stages, 2)
        self.assertEqual(self.of(0, "FROM"), ["debian:12-slim AS build"])
        self.assertEqual(self.of(1, "FROM"), ["debian:12-slim"])

    def test_build_stage_names_every_build_dependency(self):
        got = set(self.installs(0))
        wanted = {"gcc", "libc6-dev", "make", "pkg-config"}
        wanted |= {p for p in needed_packages() if p != "libcmocka-dev"}
        self.assertGreaterEqual(len(wanted), 6)
        self.assertEqual(sorted(wanted - got), [])

    @unittest.skipUnless(shutil.which("dpkg-query"), "no dpkg")
    def test_runtime_stage_has_the_libraries_of_the_dev_packages_only(self):
        runtime = set()
        for dev in self.installs(0):
            if not dev.endswith("-dev") or dev == "libc6-dev":
                continue
            r = subprocess.run(["dpkg-query", "-W", "-f=${Depends}", dev],
                               capture_output=True, text=True, timeout=30)
            self.assertEqual(r.returncode, 0, r.stderr)
            deps = [d.strip().split()[0] for d in r.stdout.split(",")]
            runtime |= {d for d in deps if not d.endswith("-dev")}
        self.assertEqual(runtime, {"libcjson1", "libmicrohttpd12", "zlib1g"})
        self.assertEqual(sorted(self.installs(1)), sorted(runtime))

    def test_runtime_stage_has_no_http_client(self):
        text = " ".join(a for s, _, a in self.ins if s == 1)
        for client in ["curl", "wget", "busybox"]:
            self.assertNotIn(client, text)

    def test_oci_labels_carry_the_version_of_the_tree(self):
        labels = dict(re.findall(r'(org\.opencontainers\.image\.[a-z.]+)='
                                 r'"([^"]*)"', " ".join(self.of(1, "LABEL"))))
        for key in ["title", "description", "version", "licenses"]:
            self.assertIn("org.opencontainers.image." + key, labels)
        self.assertEqual(labels["org.opencontainers.image.version"],
                         "${KMORPH_VERSION}")
        with open(os.path.join(ROOT, "LICENSE")) as f:
            self.assertIn(labels["org.opencontainers.image.licenses"],
                          f.readline())
        # The build argument is declared in both stages, the build refuses
        # one that is not VERSION, and `make image` passes VERSION.
        self.assertIn("KMORPH_VERSION=", self.of(0, "ARG"))
        self.assertIn("KMORPH_VERSION=", self.of(1, "ARG"))
        check = [a for a in self.of(0, "RUN") if "KMORPH_VERSION" in a]
        self.assertEqual(len(check), 1)
        for given, ok in [(VERSION, True), ("", True), ("0.0.0-other", False)]:
            with tempfile.TemporaryDirectory() as tree:
                with open(os.path.join(tree, "VERSION"), "w") as f:
                    f.write(VERSION + "\n")
                r = subprocess.run(["sh", "-c", check[0]], cwd=tree,
                                   env=dict(os.environ, KMORPH_VERSION=given),
                                   capture_output=True, timeout=30)
                self.assertEqual(r.returncode == 0, ok, given)
        r = subprocess.run(["make", "-n", "-C", ROOT, "image",
                            "ENGINE=podman"], capture_output=True,
                           text=True, timeout=60)
        made = " ".join(r.stdout.replace("\\\n", " ").split())
        # podman's default OCI format would drop the HEALTHCHECK.
        self.assertIn("podman build --format docker --build-arg "
                      "KMORPH_VERSION=%s " % VERSION, made)

    def test_runs_unprivileged_on_the_exposed_port(self):
        self.assertEqual(len(self.of(1, "USER")), 1)
        self.assertNotIn(self.of(1, "USER")[0], ("root", "0"))
        env = " ".join(self.of(1, "ENV"))
        self.assertIn("KMORPH_BIND=0.0.0.0", env)
        port = re.search(r"KMORPH_PORT=(\d+)", env).group(1)
        self.assertEqual(self.of(1, "EXPOSE"), [port])
        self.assertEqual(self.of(1, "ENTRYPOINT"),
                         ['["/usr/local/sbin/kmorphd"]'])


class StagedImage(unittest.TestCase):
    """What the runtime stage copies, staged as the build stage stages it."""

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="kmorph-image-")
        cls.staging = os.path.join(cls.tmp, "staging")
        r = subprocess.run(["make", "--no-print-directory", "-C", ROOT,
                            "BUILD=" + BUILD, "install", "PREFIX=/usr/local",
                            "DESTDIR=" + cls.staging], capture_output=True,
                           text=True, timeout=300)
        if r.returncode != 0:
            shutil.rmtree(cls.tmp, ignore_errors=True)
            raise AssertionError("make install: " + r.stderr[-3000:])
        with open(os.path.join(ROOT, "Dockerfile")) as f:
            cls.ins = instructions(f.read())

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def host_path(self, image_path):
        """Where a path of the build stage is on this machine."""
        if image_path.startswith("/staging/"):
            return os.path.join(self.staging, image_path[len("/staging/"):])
        self.assertTrue(image_path.startswith("/src/"), image_path)
        return os.path.join(ROOT, image_path[len("/src/"):])

    def test_every_copied_file_exists_after_make_install(self):
        copies = [a.split() for s, w, a in self.ins if s == 1 and w == "COPY"]
        self.assertGreaterEqual(len(copies), 3)
        for args in copies:
            self.assertEqual(args[0], "--from=build")
            self.assertTrue(os.path.exists(self.host_path(args[1])), args[1])
        dests = [args[2] for args in copies]
        self.assertIn("/usr/local/sbin/kmorphd", dests)
        self.assertIn("/usr/local/share/kmorph/web", dests)

    def test_healthcheck_command_passes_on_a_live_daemon_only(self):
        hc = [a for s, w, a in self.ins if s == 1 and w == "HEALTHCHECK"]
        self.assertEqual(len(hc), 1)
        cmd = hc[0].split(" CMD ", 1)[1]
        self.assertTrue(cmd.startswith("/usr/local/sbin/kmorphd --healthcheck"))
        self.assertIn("--timeout=3s", hc[0])
        exe = os.path.join(self.staging, "usr/local/sbin/kmorphd")
        cmd = cmd.replace("/usr/local/sbin/kmorphd", shlex.quote(exe), 1)
        d = kmdaemon.Daemon(exe=exe)
        try:
            env = dict(os.environ, KMORPH_PORT=str(d.port))
            r = subprocess.run(["sh", "-c", cmd], env=env, capture_output=True,
                               text=True, timeout=30)
            self.assertEqual(r.returncode, 0, r.stderr)
            # The staged daemon serves the staged page, as in the image.
            with open(os.path.join(self.staging, "usr/local/share/kmorph/web/"
                                   "index.html"), "rb") as f:
                self.assertEqual(d.request("GET", "/").body, f.read())
        finally:
            d.stop()
        r = subprocess.run(["sh", "-c", cmd], env=env, capture_output=True,
                           text=True, timeout=30)
        self.assertEqual(r.returncode, 1, r.stderr)


if __name__ == "__main__":
    unittest.main()
