"""test_install.py - `make install` into a temporary DESTDIR, and what it
installed used from there as a user would: a C program built with
`pkg-config --cflags --libs kmorph` and run against the installed shared
library (and linked statically), the exported symbols exactly the public
km_ functions, the installed daemon serving the installed web page with no
source tree around it, the man pages and the systemd unit checked by their
own tools, and `make uninstall` leaving nothing behind.

Run from tests/packaging (run.sh does), with KM_BUILD naming the build
folder whose binaries are installed (default build).
"""
import os
import re
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
PREFIX = "/usr/local"
VERSION = open(os.path.join(ROOT, "VERSION")).read().strip()
MAJOR = VERSION.split(".")[0]


def run(cmd, **kw):
    kw.setdefault("timeout", 300)
    return subprocess.run(cmd, capture_output=True, text=True, **kw)


def make(target, destdir):
    return run(["make", "--no-print-directory", "-C", ROOT, "BUILD=" + BUILD,
                "PREFIX=" + PREFIX, "DESTDIR=" + destdir, target])


def files_under(top):
    out = set()
    for d, _, names in os.walk(top):
        for n in names:
            out.add(os.path.relpath(os.path.join(d, n), top))
    return out


def public_functions(include_dir):
    """Names of the km_ functions the installed headers declare, KM_API
    or not (the internal km__ ones aside)."""
    names = set()
    decl = re.compile(r"^(?!static|typedef|#)[A-Za-z_][\w *]*?\b"
                      r"(km_[a-z]\w*)\s*\(", re.M)
    for h in os.listdir(include_dir):
        with open(os.path.join(include_dir, h)) as f:
            names.update(decl.findall(f.read()))
    return names


class Installed(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="kmorph-install-")
        cls.dest = os.path.join(cls.tmp, "root")
        r = make("install", cls.dest)
        if r.returncode != 0:
            shutil.rmtree(cls.tmp, ignore_errors=True)
            raise AssertionError("make install failed:\n" + r.stdout[-3000:]
                                 + r.stderr[-3000:])
        cls.prefix = cls.dest + PREFIX
        cls.lib = os.path.join(cls.prefix, "lib")

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def path(self, rel):
        return os.path.join(self.prefix, rel)

    # ------------------------------------------------------------ files

    def test_every_part_is_installed_under_the_prefix(self):
        for rel in ["bin/kmorph", "sbin/kmorphd", "lib/libkmorph.a",
                    "lib/libkmorph.so.%s" % VERSION, "lib/libkmorph.so.%s"
                    % MAJOR, "lib/libkmorph.so", "lib/pkgconfig/kmorph.pc",
                    "include/km/kmorph.h", "include/km/version.h",
                    "include/km/export.h", "share/kmorph/web/index.html",
                    "share/kmorph/kmorphd.env", "share/man/man1/kmorph.1",
                    "share/man/man8/kmorphd.8",
                    "lib/systemd/system/kmorphd.service"]:
            self.assertTrue(os.path.exists(self.path(rel)), rel)
        for exe in ["bin/kmorph", "sbin/kmorphd"]:
            self.assertTrue(os.access(self.path(exe), os.X_OK), exe)
        # Nothing lands outside the prefix.
        self.assertEqual(os.listdir(self.dest), ["usr"])
        self.assertEqual(os.listdir(os.path.join(self.dest, "usr")),
                         ["local"])

    def test_every_header_the_umbrella_includes_is_installed(self):
        inc = self.path("include/km")
        with open(os.path.join(inc, "kmorph.h")) as f:
            wanted = re.findall(r'#include "(km/[\w.]+)"', f.read())
        self.assertGreater(len(wanted), 5)
        for h in wanted:
            self.assertTrue(os.path.exists(self.path("include/" + h)), h)

    def test_installed_binaries_report_the_version_file(self):
        for exe in ["bin/kmorph", "sbin/kmorphd"]:
            r = run([self.path(exe), "--version"])
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertIn(VERSION, r.stdout)

    # ---------------------------------------------------------- library

    def test_shared_library_has_the_major_version_as_soname(self):
        r = run(["readelf", "-d", self.path("lib/libkmorph.so")])
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertRegex(r.stdout, r"\(SONAME\)\s+Library soname: "
                         r"\[libkmorph\.so\.%s\]" % MAJOR)
        self.assertEqual(os.readlink(self.path("lib/libkmorph.so")),
                         "libkmorph.so." + MAJOR)
        self.assertEqual(os.readlink(self.path("lib/libkmorph.so." + MAJOR)),
                         "libkmorph.so." + VERSION)

    def test_shared_library_exports_exactly_the_public_functions(self):
        r = run(["nm", "-D", "--defined-only", self.path("lib/libkmorph.so")])
        self.assertEqual(r.returncode, 0, r.stderr)
        exported = {ln.split()[-1] for ln in r.stdout.splitlines()
                    if ln.split() and ln.split()[-2] in ("T", "W", "D", "B",
                                                         "R")}
        public = public_functions(self.path("include/km"))
        # km_version, the status names and the curve, fn, morph, path,
        # reconstruct, shape and signature functions: several dozen.
        self.assertGreater(len(public), 50)
        self.assertIn("km_version", public)
        self.assertEqual(sorted(exported - public), [],
                         "exported but not declared in km/")
        self.assertEqual(sorted(public - exported), [],
                         "declared in km/ but not exported (no KM_API?)")
        self.assertFalse([s for s in exported if s.startswith("km__")])

    def pkg_config(self, *args):
        env = dict(os.environ,
                   PKG_CONFIG_PATH=os.path.join(self.lib, "pkgconfig"),
                   PKG_CONFIG_SYSROOT_DIR=self.dest,
                   PKG_CONFIG_LIBDIR="")
        r = run(["pkg-config", *args, "kmorph"], env=env)
        self.assertEqual(r.returncode, 0, r.stderr)
        return r.stdout.split()

    def test_pkg_config_gives_the_version_and_the_installed_paths(self):
        self.assertEqual(self.pkg_config("--modversion"), [VERSION])
        self.assertEqual(self.pkg_config("--cflags"),
                         ["-I" + self.path("include")])
        self.assertEqual(self.pkg_config("--libs"),
                         ["-L" + self.lib, "-lkmorph"])
        self.assertIn("-lm", self.pkg_config("--static", "--libs"))

    def build_program(self, out, libs):
        src = os.path.join(HERE, "circle_length.c")
        r = run(["cc", "-std=c11", "-pedantic", "-Wall", "-Wextra", "-Werror",
                 *self.pkg_config("--cflags"), src, "-o", out, *libs])
        self.assertEqual(r.returncode, 0, r.stderr)

    def test_program_built_with_pkg_config_runs_on_the_shared_library(self):
        exe = os.path.join(self.tmp, "circle_shared")
        self.build_program(exe, self.pkg_config("--libs") + ["-lm"])
        needed = run(["readelf", "-d", exe]).stdout
        self.assertIn("[libkmorph.so.%s]" % MAJOR, needed)
        r = run([exe], env=dict(os.environ, LD_LIBRARY_PATH=self.lib))
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        self.assertEqual(r.stdout.splitlines(),
                         ["header %s library %s" % (VERSION, VERSION), "ok"])

    def test_program_links_the_static_library_alone(self):
        exe = os.path.join(self.tmp, "circle_static")
        static = [a for a in self.pkg_config("--static", "--libs")
                  if a != "-lkmorph"]
        self.build_program(exe, [self.path("lib/libkmorph.a")] + static)
        self.assertNotIn("libkmorph", run(["readelf", "-d", exe]).stdout)
        r = run([exe])
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        self.assertEqual(r.stdout.splitlines()[-1], "ok")

    # ----------------------------------------------------------- daemon

    def test_installed_daemon_serves_the_installed_page(self):
        web = self.path("share/kmorph/web")
        # A mark only the installed copy has: the page served must be it,
        # not the source tree's.
        mark = "<!-- installed copy -->\n"
        with open(os.path.join(web, "index.html"), "a") as f:
            f.write(mark)
        with open(os.path.join(web, "index.html"), "rb") as f:
            index = f.read()
        with open(os.path.join(web, "app.js"), "rb") as f:
            app = f.read()
        d = kmdaemon.Daemon(exe=self.path("sbin/kmorphd"))
        try:
            r = d.request("GET", "/")
            self.assertEqual(r.status, 200)
            self.assertEqual(r.ctype, "text/html")
            self.assertEqual(r.body, index)
            self.assertTrue(r.body.endswith(mark.encode()))
            r = d.request("GET", "/app.js")
            self.assertEqual(r.status, 200)
            self.assertEqual(r.body, app)
            self.assertEqual(d.request("GET", "/healthz").status, 200)
            hc = run([self.path("sbin/kmorphd"), "--healthcheck",
                      "http://127.0.0.1:%d/healthz" % d.port], timeout=30)
            self.assertEqual(hc.returncode, 0, hc.stderr)
        finally:
            d.stop()

    def test_installed_daemon_names_its_web_root_in_help(self):
        r = run([self.path("sbin/kmorphd"), "--help"], cwd=self.tmp)
        self.assertIn('"%s"' % self.path("share/kmorph/web"), r.stdout)

    # ------------------------------------------------------- man pages

    def man_text(self, page):
        r = run(["groff", "-man", "-ww", "-Tutf8", page])
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(r.stderr, "", "groff warnings")
        return re.sub(".\b", "", r.stdout)

    def test_man_page_of_the_daemon_lists_every_setting(self):
        text = self.man_text(self.path("share/man/man8/kmorphd.8"))
        helptext = run([self.path("sbin/kmorphd"), "--help"]).stdout
        flags = re.findall(r"^  --([a-z-]+)\s+(KMORPH_[A-Z_]+)", helptext,
                           re.M)
        self.assertGreater(len(flags), 20)
        for flag, env in flags:
            self.assertRegex(text, r"--%s value, %s=value" % (flag, env))
        for word in ["--healthcheck", "SIGHUP", "kmorphd.env",
                     PREFIX + "/share/kmorph/web", "kmorph(1)"]:
            self.assertIn(word, text)
        self.assertIn(VERSION, text)

    def test_man_page_of_the_cli_lists_every_option(self):
        text = self.man_text(self.path("share/man/man1/kmorph.1"))
        usage = run([self.path("bin/kmorph"), "--help"])
        options = re.findall(r"^  (--[a-z]+)", usage.stdout + usage.stderr,
                             re.M)
        self.assertGreaterEqual(len(options), 4)
        for opt in options:
            self.assertIn(opt, text)
        for cmd in ["signature", "reconstruct", "morph", "kmorphd(8)"]:
            self.assertIn(cmd, text)

    # ------------------------------------------------------ systemd unit

    def unit(self):
        return self.path("lib/systemd/system/kmorphd.service")

    def verify(self, unit, root):
        """systemd-analyze verify of unit with root as the file system:
        (exit status, its complaints)."""
        r = run(["systemd-analyze", "verify", "--man=no", "--root=" + root,
                 unit])
        return r.returncode, (r.stdout + r.stderr).strip()

    @unittest.skipUnless(shutil.which("systemd-analyze"), "no systemd")
    def test_unit_passes_systemd_analyze_verify(self):
        # The unit's dependencies (sysinit.target, ...) come from the
        # system's unit folder, copied into the installed tree's root.
        shutil.copytree("/lib/systemd/system",
                        os.path.join(self.dest, "usr/lib/systemd/system"),
                        symlinks=True, dirs_exist_ok=True)
        try:
            rc, said = self.verify(self.unit(), self.dest)
            self.assertEqual((rc, said), (0, ""))
            # The check can fail: a misspelt key and a missing binary.
            with open(self.unit()) as f:
                good = f.read()
            bad = os.path.join(self.prefix, "lib/systemd/system/"
                               "kmorphd-bad.service")
            with open(bad, "w") as f:
                f.write(good.replace("DynamicUser=", "DynamicUsr="))
            self.assertIn("Unknown key", self.verify(bad, self.dest)[1])
            with open(bad, "w") as f:
                f.write(good.replace("/sbin/kmorphd", "/sbin/kmorphd-none"))
            self.assertNotEqual(self.verify(bad, self.dest)[0], 0)
            os.unlink(bad)
            r = run(["systemd-analyze", "security", "--offline=yes",
                     "--root=" + self.dest, self.unit()])
            m = re.search(r"Overall exposure level for kmorphd\.service: "
                          r"([0-9.]+)", r.stdout)
            self.assertIsNotNone(m, r.stdout[-2000:] + r.stderr)
            # systemd rates 0-10; below 2 is its "OK" band.
            self.assertLess(float(m.group(1)), 2.0, r.stdout[-3000:])
        finally:
            shutil.rmtree(os.path.join(self.dest, "usr/lib"))

    def test_unit_runs_the_installed_daemon_as_a_dynamic_user(self):
        with open(self.unit()) as f:
            text = f.read()
        keys = {}
        for line in text.splitlines():
            if "=" in line and not line.startswith("#"):
                k, v = line.split("=", 1)
                keys.setdefault(k, []).append(v)
        self.assertEqual(keys["ExecStart"], [PREFIX + "/sbin/kmorphd"])
        self.assertEqual(keys["DynamicUser"], ["yes"])
        self.assertEqual(keys["EnvironmentFile"],
                         ["-/etc/kmorph/kmorphd.env"])
        self.assertEqual(keys["Environment"],
                         ["KMORPH_WEB_ROOT=%s/share/kmorph/web" % PREFIX])
        for k in ["ProtectSystem", "ProtectHome", "PrivateTmp",
                  "NoNewPrivileges", "CapabilityBoundingSet",
                  "RestrictAddressFamilies", "SystemCallFilter"]:
            self.assertIn(k, keys)
        # Every variable the environment file shows is one the daemon reads.
        helptext = run([self.path("sbin/kmorphd"), "--help"]).stdout
        with open(self.path("share/kmorph/kmorphd.env")) as f:
            shown = re.findall(r"^#?(KMORPH_[A-Z_]+)=", f.read(), re.M)
        self.assertGreater(len(shown), 2)
        for var in shown:
            self.assertIn(var, helptext)


class Uninstall(unittest.TestCase):
    def test_uninstall_removes_every_installed_file(self):
        tmp = tempfile.mkdtemp(prefix="kmorph-uninstall-")
        try:
            r = make("install", tmp)
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertGreater(len(files_under(tmp)), 20)
            r = make("uninstall", tmp)
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertEqual(sorted(files_under(tmp)), [])
            self.assertFalse(os.path.exists(tmp + PREFIX + "/share/kmorph"))
        finally:
            shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    unittest.main()
