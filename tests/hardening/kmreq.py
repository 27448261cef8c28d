"""kmreq.py - valid kmorph requests built from docs/examples and
tests/fixtures (small ones plus variants of every option), shared by the
fuzz seed corpora, the bad-input barrage and the CLI leak check.

    python3 tests/hardening/kmreq.py corpus   # rewrite the api_* seeds
    python3 tests/hardening/kmreq.py list     # route and name of each

Standard library only.
"""
import glob
import hashlib
import json
import math
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                "..", "pylib"))
from kmdaemon import ROOT, circle_svg, square_svg  # noqa: E402,F401


def _load(rel):
    with open(os.path.join(ROOT, rel), encoding="utf-8") as f:
        return json.load(f)


def compact(doc):
    return json.dumps(doc, separators=(",", ":")).encode()


def cubic_bspline():
    """An open cubic B-spline with one interior knot."""
    return {"type": "bspline", "degree": 3,
            "knots": [0, 0, 0, 0, 0.5, 1, 1, 1, 1],
            "control_points": [[0, 0], [1, 2], [3, 3], [4, 1], [5, 0]],
            "closed": False}


def nurbs_circle():
    """The unit circle as a closed rational quadratic (exact)."""
    w = math.sqrt(0.5)
    return {"type": "bspline", "degree": 2,
            "knots": [0, 0, 0, .25, .25, .5, .5, .75, .75, 1, 1, 1],
            "control_points": [[1, 0], [1, 1], [0, 1], [-1, 1], [-1, 0],
                               [-1, -1], [0, -1], [1, -1], [1, 0]],
            "weights": [1, w, 1, w, 1, w, 1, w, 1], "closed": True}


def line_signature(length=2.0):
    return {"length": length, "start": {"point": [0, 0], "angle": 0},
            "kappa": {"degree": 0, "knots": [0, length], "coefficients": [0]},
            "closed": False}


def valid_requests():
    """[(route, name, body dict)] - every one is answered 200."""
    out = []
    ex = {os.path.basename(p)[:-5]: _load(os.path.relpath(p, ROOT))
          for p in sorted(glob.glob(os.path.join(ROOT, "docs", "examples",
                                                 "*.json")))}
    for name, body in ex.items():
        route = ("signature" if "curve" in body else
                 "reconstruct" if "signature" in body else "morph")
        out.append((route, "example-" + name, body))

    shapes = _load("tests/fixtures/shapes.json")["pairs"]
    analytic = _load("tests/fixtures/analytic.json")["cases"]

    # signature: every curve type, options, every fixture shape
    out += [
        ("signature", "cubic", {"curve": cubic_bspline()}),
        ("signature", "nurbs-circle-samples",
         {"curve": nurbs_circle(), "samples": 4, "tolerance": 1e-4}),
        ("signature", "points-open",
         {"curve": {"type": "points", "points": [[0, 0], [1, 1], [2, 0]]}}),
        ("signature", "points-closed",
         {"curve": {"type": "points", "closed": True,
                    "points": [[0, 0], [2, 0], [2, 1], [0, 1]]}}),
        ("signature", "svg-every-command",
         {"curve": {"type": "svg",
                    "d": "M0 0 H10 V10 h-2 v-2 L5 5 l1 2 C6 8 7 9 8 9 "
                         "S10 10 11 12 c1 1 2 1 3 0 s2 -2 3 0 Q20 20 22 20 "
                         "q1 1 2 0 T28 20 t2 0 A3 3 0 0 1 36 20 "
                         "a2 1 30 1 0 4 0"}}),
        ("signature", "svg-circle", {"curve": circle_svg(5.0), "samples": 3}),
        ("signature", "svg-square", {"curve": square_svg(3.0)}),
        ("signature", "signature-curve",
         {"curve": {"type": "signature", "signature": line_signature()}}),
    ]
    for p in shapes:
        out.append(("signature", "shape-%s-a" % p["name"], {"curve": p["a"]}))
        out.append(("signature", "shape-%s-b-svg" % p["name"],
                    {"curve": {"type": "svg", "d": p["b_d"]},
                     "tolerance": 0.01}))

    # reconstruct: the analytic signatures at both degrees
    for i, c in enumerate(analytic):
        out.append(("reconstruct", "analytic-%s" % c["name"],
                    {"signature": c["signature"], "tolerance": 1e-4,
                     "degree": 3 if i % 2 == 0 else 5}))
    out += [
        ("reconstruct", "line", {"signature": line_signature()}),
        ("reconstruct", "corner-svg",
         {"signature": {"length": 2, "start": {"point": [1, 1], "angle": 0.5},
                        "kappa": {"degree": 0, "knots": [0, 2],
                                  "coefficients": [0]},
                        "corners": [{"s": 1, "turn": 1.5}], "closed": False},
          "degree": 5, "include": ["svg_d"]}),
        ("reconstruct", "closed-circle",
         {"signature": {"length": 2 * math.pi,
                        "start": {"point": [0, 0], "angle": 0},
                        "kappa": {"degree": 0, "knots": [0, 2 * math.pi],
                                  "coefficients": [1]},
                        "closed": True}}),
    ]

    # morph: every option on small closed and open pairs
    cc = {"from": circle_svg(1.0), "to": square_svg(2.0), "frames": 3}
    variants = [
        ("circle-square", {}),
        ("linear", {"method": "linear"}),
        ("paper", {"blend": "paper", "times": [0, 0.5, 1]}),
        ("closure-c0", {"closure": "c0"}), ("closure-c1", {"closure": "c1"}),
        ("closure-g2", {"closure": "g2"}), ("closure-none", {"closure": "none"}),
        ("closure-lsq", {"closure": "lsq"}),
        ("anchor-start", {"anchor": "start"}),
        ("anchor-centroid", {"anchor": "centroid", "orient": "keep"}),
        ("matches", {"matches": [[0.25, 0.3], [0.5, 0.6]]}),
        ("matches-auto", {"matches": "auto"}),
        ("metrics-svg-d", {"metrics": True, "include": ["svg_d"],
                           "tolerance": 1e-3, "degree": 5}),
        ("svg-filmstrip", {"format": "svg", "svg": {"layout": "filmstrip"}}),
        ("svg-overlay", {"format": "svg", "svg": {"layout": "overlay"}}),
        ("svg-animate", {"format": "svg", "svg": {"layout": "animate"}}),
        ("svg-plot", {"format": "svg", "svg": {"layout": "curvature_plot"}}),
    ]
    for name, extra in variants:
        body = dict(cc)
        body.update(extra)
        if "times" in extra:
            del body["frames"]
        out.append(("morph", name, body))
    out.append(("morph", "open-bspline-signature",
                {"from": cubic_bspline(),
                 "to": {"type": "signature", "signature": line_signature(4)},
                 "frames": 2}))
    out.append(("morph", "nurbs-points",
                {"from": nurbs_circle(),
                 "to": {"type": "points", "closed": True,
                        "points": [[0, 0], [2, 0], [2, 1], [0, 1]]},
                 "frames": 2}))
    for p in shapes:
        out.append(("morph", "shape-%s" % p["name"],
                    {"from": {"type": "svg", "d": p["a_d"]},
                     "to": {"type": "svg", "d": p["b_d"]}, "frames": 3}))
    return out


def write_corpus():
    """Seeds for tests/fuzz/api_<route>/corpus, named by content."""
    for route in ("signature", "reconstruct", "morph"):
        d = os.path.join(ROOT, "tests", "fuzz", "api_" + route, "corpus")
        os.makedirs(d, exist_ok=True)
        for f in glob.glob(os.path.join(d, "*")):
            os.unlink(f)
        for r, name, body in valid_requests():
            if r != route:
                continue
            data = compact(body)
            h = hashlib.sha1(data).hexdigest()[:8]
            with open(os.path.join(d, "%s-%s" % (name, h)), "wb") as f:
                f.write(data)


if __name__ == "__main__":
    cmd = sys.argv[1] if len(sys.argv) > 1 else "list"
    if cmd == "corpus":
        write_corpus()
    else:
        for r, name, body in valid_requests():
            print(r, name, len(compact(body)))
