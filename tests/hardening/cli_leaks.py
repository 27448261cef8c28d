"""cli_leaks.py - valgrind memcheck on the CLI (build/kmorph) for every
example request in docs/examples, every request built from the fixtures
(tests/hardening/kmreq.py) and a sample of malformed ones: zero bytes
definitely lost, no invalid reads or writes, the expected exit status.

    python3 tests/hardening/cli_leaks.py [--cli build/kmorph]

Appends "hardening/cli-valgrind passed failed" to build/test-results.txt.
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor

sys.path.insert(0, os.path.dirname(__file__))
import hlib  # noqa: E402
import kmreq  # noqa: E402

BAD = [("signature", b"{bad"), ("morph", b'{"from":1}'),
       ("reconstruct", b'{"signature":{"length":-1}}'),
       ("signature", b'{"curve":{"type":"svg","d":"M 0 0 L 1 0 L 0 0"}}'),
       ("morph", b'{"from":{"type":"svg","d":"M 0 0 L 1 0 L 1 1 Z"},'
                 b'"to":{"type":"svg","d":"M 0 0 L 1 0"},"frames":2}'),
       ("signature", b"[" * 100 + b"]" * 100)]


def run(cli, route, body, expect_ok):
    with tempfile.NamedTemporaryFile(suffix=".vg") as log:
        cmd = ["valgrind", "--tool=memcheck", "--leak-check=full",
               "--errors-for-leak-kinds=definite", "--error-exitcode=99",
               "--log-file=" + log.name, cli, route]
        t0 = time.monotonic()
        p = subprocess.run(cmd, input=body, capture_output=True, timeout=600)
        dt = time.monotonic() - t0
        text = open(log.name, encoding="utf-8", errors="replace").read()
    m = re.search(r"definitely lost: ([\d,]+) bytes", text)
    lost = int(m.group(1).replace(",", "")) if m else 0
    errs = re.search(r"ERROR SUMMARY: (\d+) errors", text)
    nerr = int(errs.group(1)) if errs else -1
    why = ""
    if p.returncode == 99 or lost or nerr != 0:
        why = "valgrind: %d bytes definitely lost, %d errors\n%s" % (
            lost, nerr, text[-3000:])
    elif p.returncode != (0 if expect_ok else 1):
        why = "exit status %d: %r" % (p.returncode, p.stdout[:200])
    return why, lost, dt


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cli", default=os.path.join(hlib.ROOT, "build",
                                                  "kmorph"))
    a = ap.parse_args()
    ck = hlib.Checks("cli-valgrind")
    jobs = [(r, n, kmreq.compact(b), True)
            for r, n, b in kmreq.valid_requests()]
    jobs += [(r, "bad-%d" % i, b, False) for i, (r, b) in enumerate(BAD)]
    t0 = time.monotonic()
    with ThreadPoolExecutor(max_workers=2) as ex:
        res = list(ex.map(lambda j: (j, run(a.cli, j[0], j[2], j[3])),
                          jobs))
    total_lost = 0
    for (route, name, _, _), (why, lost, dt) in res:
        total_lost += lost
        if why:
            ck.check(False, "%s %s under memcheck" % (route, name), why)
    bad = sum(1 for _, (why, _, _) in res if why)
    ck.check(bad == 0, "%d CLI runs under memcheck: 0 bytes definitely "
             "lost, no memory errors (%d bad)" % (len(res), bad))
    line = ("cli-valgrind: %d requests (examples, fixtures, malformed), %d "
            "bytes definitely lost, %d runs bad, %.0f s" % (
                len(res), total_lost, bad, time.monotonic() - t0))
    print(line)
    with open(os.path.join(hlib.ROOT, "build", "hardening-summary.txt"),
              "a") as f:
        f.write(line + "\n")
    return 0 if ck.record() else 1


if __name__ == "__main__":
    sys.exit(main())
