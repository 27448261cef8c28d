#!/usr/bin/env python3
"""run.py - end-to-end per-frame figures of kmorph: a 1,000-frame morph
through the CLI (process start, parse, frames, printing) and over HTTP
(POST /v1/morph to a live kmorphd on loopback, one kept-alive
connection), JSON with metrics off and on and SVG, on glyph and icon
pairs (single-contour and compound) and the older shape pairs; bytes and
control points per frame; flubber's defaults and flubber at equal
accuracy beside them (flubber_e2e.js, single-contour pairs only).

With --before-cli/--before-daemon (another build, e.g. the previous
main) each figure is also measured there in the same run and the table
gives after/before ratios.

Each time is the best of --runs runs (a shared machine's load only ever
adds time).

Usage: bench/e2e/run.py [--frames N] [--runs R] [--cli PATH]
       [--daemon PATH] [--before-cli PATH --before-daemon PATH]
       [--precision P] [--no-flubber]
"""
import argparse
import http.client
import json
import os
import resource
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, "..", "..", "tests", "pylib"))
from pairs import ROOT, body, load_pairs  # noqa: E402
from kmdaemon import Daemon  # noqa: E402

MODES = [("json", False, False), ("json+metrics", True, False),
         ("svg", False, True)]


def control_points(answer):
    """Control points of all frames of a JSON answer."""
    n = 0
    for f in answer["frames"]:
        for c in f.get("contours", [f.get("curve")]):
            if c:
                n += len(c["control_points"])
    return n


def children_cpu():
    u = resource.getrusage(resource.RUSAGE_CHILDREN)
    return u.ru_utime + u.ru_stime


def time_cli(cli, req, runs):
    """Best elapsed time, the answer, and the CPU time (every thread's) of
    the run with the best elapsed time: the CLI renders frames on every
    CPU it may use, flubber on one."""
    best, out, cpu = None, b"", None
    for _ in range(runs):
        c0 = children_cpu()
        t0 = time.perf_counter()
        r = subprocess.run([cli, "morph"], input=req, capture_output=True)
        dt = time.perf_counter() - t0
        c = children_cpu() - c0
        if r.returncode != 0:
            raise RuntimeError(r.stdout[:300])
        if best is None or dt < best:
            best, cpu = dt, c
        out = r.stdout
    return best, out, cpu


def time_http(conn, req, runs):
    best, out = None, b""
    for _ in range(runs):
        t0 = time.perf_counter()
        conn.request("POST", "/v1/morph", body=req,
                     headers={"Content-Type": "application/json"})
        resp = conn.getresponse()
        data = resp.read()
        dt = time.perf_counter() - t0
        if resp.status != 200:
            raise RuntimeError(data[:300])
        best = dt if best is None or dt < best else best
        out = data
    return best, out, None


def measure(cli, daemon_exe, pairs, frames, runs, precision):
    """{(pair, mode, via): (us per frame, bytes per frame, cps per frame,
    CPU us per frame or None)}"""
    out = {}
    d = Daemon(exe=daemon_exe) if daemon_exe else None
    conn = http.client.HTTPConnection("127.0.0.1", d.port,
                                      timeout=600) if d else None
    try:
        for name, kind, a, b in pairs:
            for mode, metrics, svg in MODES:
                req = body(a, b, frames, metrics, svg, precision)
                vias = [("cli", lambda r: time_cli(cli, r, runs))]
                if conn:
                    vias.append(("http", lambda r: time_http(conn, r, runs)))
                for via, fn in vias:
                    dt, text, cpu = fn(req)
                    cps = None if svg else control_points(json.loads(text))
                    out[(name, mode, via)] = (
                        1e6 * dt / frames, len(text) / frames,
                        None if cps is None else cps / frames,
                        None if cpu is None else 1e6 * cpu / frames)
    finally:
        if conn:
            conn.close()
        if d:
            d.stop()
    return out


def flubber(pairs, frames):
    """{pair: {"default": {...}, "equal": {...}}} or {} without node."""
    singles = []
    for name, kind, a, b in pairs:
        if "compound" in kind:
            continue
        # kmorph's default tolerance: 1e-5 of the longer length, here from
        # the pair's morph answer (frame 0's curve length)
        r = subprocess.run([os.path.join(ROOT, "build", "kmorph"), "morph"],
                           input=body(a, b, 2, False), capture_output=True)
        fr = json.loads(r.stdout)["frames"]
        tol = 1e-5 * max(f["curve"]["length"] for f in fr)
        singles.append({"name": name, "a": a, "b": b, "tol": tol})
    with tempfile.NamedTemporaryFile("w", suffix=".json", delete=False) as f:
        json.dump(singles, f)
        path = f.name
    try:
        r = subprocess.run(["node", os.path.join(HERE, "flubber_e2e.js"),
                            path, str(frames)], capture_output=True,
                           text=True, timeout=3600)
    except (OSError, subprocess.TimeoutExpired):
        return {}
    finally:
        os.unlink(path)
    res = {}
    for line in r.stdout.splitlines():
        x = json.loads(line)
        res[x["name"]] = x
    return res


def fmt(v, digits=1):
    return "-" if v is None else f"{v:.{digits}f}"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--frames", type=int, default=1000)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--cli", default=os.path.join(ROOT, "build", "kmorph"))
    ap.add_argument("--daemon",
                    default=os.path.join(ROOT, "build", "kmorphd"))
    ap.add_argument("--before-cli")
    ap.add_argument("--before-daemon")
    ap.add_argument("--precision")
    ap.add_argument("--glyphs", type=int, default=2)
    ap.add_argument("--icons", type=int, default=2)
    ap.add_argument("--no-flubber", action="store_true")
    args = ap.parse_args()
    pairs = load_pairs(args.glyphs, args.icons)
    after = measure(args.cli, args.daemon, pairs, args.frames, args.runs,
                    args.precision)
    before = (measure(args.before_cli, args.before_daemon, pairs,
                      args.frames, args.runs, None)
              if args.before_cli else None)
    fl = {} if args.no_flubber else flubber(pairs, args.frames)
    print(f"# {args.frames} frames a request, best of {args.runs}; "
          f"us, bytes and control points per frame"
          + (f"; precision {args.precision}" if args.precision else ""))
    head = ("| pair | kind | mode | CLI us | CLI CPU us | HTTP us | HTTP/CLI |"
            " bytes | cps |")
    rule = "|---|---|---|---:|---:|---:|---:|---:|---:|"
    if before:
        head += " CLI after/before | HTTP after/before | bytes after/before |"
        rule += "---:|---:|---:|"
    if fl:
        head += (" CLI / flubber default | CLI CPU / flubber default |"
                 " CLI / flubber equal |")
        rule += "---:|---:|---:|"
    print(head)
    print(rule)
    for name, kind, a, b in pairs:
        for mode, metrics, svg in MODES:
            c = after[(name, mode, "cli")]
            h = after.get((name, mode, "http"))
            row = (f"| {name} | {kind} | {mode} | {fmt(c[0])} | "
                   f"{fmt(c[3])} | {fmt(h[0] if h else None)} | "
                   f"{fmt(h[0] / c[0] if h else None, 2)} | {fmt(c[1], 0)} | "
                   f"{fmt(c[2])} |")
            if before:
                bc = before[(name, mode, "cli")]
                bh = before.get((name, mode, "http"))
                row += (f" {fmt(c[0] / bc[0], 2)} | "
                        f"{fmt(h[0] / bh[0] if h and bh else None, 2)} | "
                        f"{fmt(c[1] / bc[1], 2)} |")
            if fl:
                f = fl.get(name)
                row += (f" {fmt(c[0] / f['default']['us'] if f else None, 2)}"
                        f" | {fmt(c[3] / f['default']['us'] if f else None, 2)}"
                        f" | {fmt(c[0] / f['equal']['us'] if f else None, 3)}"
                        " |")
            print(row)
    if fl:
        print()
        print("| pair | flubber default us | bytes | points | "
              "flubber equal us | bytes | points | max segment |")
        print("|---|---:|---:|---:|---:|---:|---:|---:|")
        for name, x in fl.items():
            d, e = x["default"], x["equal"]
            print(f"| {name} | {fmt(d['us'])} | {fmt(d['bytes'], 0)} | "
                  f"{d['points']} | {fmt(e['us'])} | {fmt(e['bytes'], 0)} | "
                  f"{e['points']} | {e['max_segment']:.3g} |")


if __name__ == "__main__":
    main()
