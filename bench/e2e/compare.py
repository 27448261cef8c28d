#!/usr/bin/env python3
"""compare.py - two kmorph CLIs give the same answers: every JSON answer
parsed (Python's json) and compared value by value, every SVG answer
compared byte by byte and checked well-formed with xmllint.

Usage: bench/e2e/compare.py OLD_CLI NEW_CLI [FRAMES]
Prints one line per request and a summary; exits 1 on a difference.
"""
import json
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(__file__))
from pairs import load_pairs  # noqa: E402

VARIANTS = [
    ("json", {"metrics": False}),
    ("json+metrics", {"metrics": True}),
    ("json+svg_d", {"metrics": False, "include": ["svg_d"]}),
    ("json+animate_d", {"metrics": False, "include": ["animate_d"]}),
    ("svg filmstrip", {"format": "svg"}),
    ("svg curvature_plot", {"format": "svg",
                            "svg": {"layout": "curvature_plot"}}),
]


def run(cli, body):
    r = subprocess.run([cli, "morph"], input=body, capture_output=True,
                       timeout=600)
    return r.stdout


def same(a, b, where=""):
    """None when equal (types too: 1 and 1.0 differ), else where not."""
    if isinstance(a, dict):
        if not isinstance(b, dict) or list(a) != list(b):
            return where + " (members)"
        for k in a:
            d = same(a[k], b[k], where + "/" + k)
            if d:
                return d
        return None
    if isinstance(a, list):
        if not isinstance(b, list) or len(a) != len(b):
            return where + " (length)"
        for i, (x, y) in enumerate(zip(a, b)):
            d = same(x, y, f"{where}/{i}")
            if d:
                return d
        return None
    if type(a) is not type(b) or a != b:
        return f"{where}: {a!r} != {b!r}"
    return None


def main():
    old, new = sys.argv[1], sys.argv[2]
    frames = int(sys.argv[3]) if len(sys.argv) > 3 else 5
    bad = 0
    total = 0
    for name, kind, a, b in load_pairs():
        for label, extra in VARIANTS:
            if "compound" in kind and "curvature_plot" in label:
                continue
            req = {"from": {"type": "svg", "d": a},
                   "to": {"type": "svg", "d": b}, "frames": frames}
            req.update(extra)
            body = json.dumps(req).encode()
            x, y = run(old, body), run(new, body)
            total += 1
            if label.startswith("svg"):
                lint = subprocess.run(["xmllint", "--noout", "-"], input=y,
                                      capture_output=True)
                ok = x == y and lint.returncode == 0
                note = "same bytes" if x == y else \
                    f"DIFFERENT ({len(x)} -> {len(y)} bytes)"
                if lint.returncode != 0:
                    note += " NOT WELL-FORMED"
            else:
                jx, jy = json.loads(x), json.loads(y)
                d = same(jx, jy)
                ok = d is None
                note = (f"values equal, {len(x)} -> {len(y)} bytes" if ok
                        else "DIFFERENT at " + d)
            bad += 0 if ok else 1
            print(f"{name:32} {label:20} {note}")
    print(f"{total - bad} of {total} answers the same")
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
