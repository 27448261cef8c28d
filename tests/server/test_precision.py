"""test_precision.py - "precision": "tolerance" on glyph, icon and shape
pairs (single-contour and compound) over HTTP: every printed curve within
a tenth of the tolerance of the same request's exact curve, its knots
non-decreasing with their multiplicities kept, the answer valid JSON of
fewer bytes.

Oracle: the exact answer, compared span by span through the Bezier
points of both curves computed here (blossoms by de Boor's algorithm on
the numbers parsed back), which bound every point of a span at the same
local parameter.
"""
import json
import math
import os
import sys
import unittest

from kmtest import ROOT, DaemonCase

sys.path.insert(0, os.path.join(ROOT, "bench", "e2e"))
from pairs import load_pairs  # noqa: E402

FRAMES = 6
TOL = 2e-3  # the inputs are some 50 to 700 units long


def bezier_point(u, cp, p, j, k):
    """Bezier point k of span j: the blossom at k copies of u[j + 1] and
    p - k of u[j]."""
    d = [list(cp[j - p + i]) for i in range(p + 1)]
    for r in range(1, p + 1):
        a = u[j + 1] if r <= k else u[j]
        for i in range(p, r - 1, -1):
            lo, hi = u[j - p + i], u[j + 1 + i - r]
            al = (a - lo) / (hi - lo)
            d[i] = [(1 - al) * d[i - 1][0] + al * d[i][0],
                    (1 - al) * d[i - 1][1] + al * d[i][1]]
    return d[p]


def gap(exact, printed):
    """Largest distance between corresponding Bezier points of the spans
    of two curves with the same spans."""
    p, ue, ug = exact["degree"], exact["knots"], printed["knots"]
    worst = 0.0
    for j in range(p, len(exact["control_points"])):
        if ue[j] < ue[j + 1]:
            for k in range(p + 1):
                a = bezier_point(ue, exact["control_points"], p, j, k)
                b = bezier_point(ug, printed["control_points"], p, j, k)
                worst = max(worst, math.hypot(a[0] - b[0], a[1] - b[1]))
    return worst


def curves(frame):
    return frame["contours"] if "contours" in frame else [frame["curve"]]


class ToleranceGrids(DaemonCase):
    def answer(self, a, b, precision):
        body = {"from": {"type": "svg", "d": a}, "to": {"type": "svg", "d": b},
                "frames": FRAMES, "metrics": False, "tolerance": TOL,
                "precision": precision}
        r = self.d.request("POST", "/v1/morph", body=body)
        self.assertEqual(r.status, 200, r.body[:300])
        return len(r.body), json.loads(r.body.decode("utf-8"))

    def test_printed_curves_stay_within_a_tenth_of_the_tolerance(self):
        for name, kind, a, b in load_pairs(glyphs=3, icons=3):
            with self.subTest(pair=name):
                en, exact = self.answer(a, b, "exact")
                gn, grid = self.answer(a, b, "tolerance")
                checked = 0
                self.assertLess(gn, 0.6 * en)
                for fe, fg in zip(exact["frames"], grid["frames"]):
                    for ce, cg in zip(curves(fe), curves(fg)):
                        self.assertEqual(ce is None, cg is None)
                        if ce is None:
                            continue
                        ue, ug = ce["knots"], cg["knots"]
                        self.assertEqual(len(ue), len(ug))
                        for i in range(1, len(ue)):
                            self.assertLessEqual(ug[i - 1], ug[i])
                            self.assertEqual(ue[i - 1] == ue[i],
                                             ug[i - 1] == ug[i])
                        self.assertLessEqual(gap(ce, cg), 0.1 * TOL)
                        checked += 1
                self.assertGreaterEqual(checked, FRAMES)


if __name__ == "__main__":
    unittest.main()
