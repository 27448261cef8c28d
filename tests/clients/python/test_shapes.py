"""test_shapes.py - the Python client (clients/python/kmorph) and its
command line with compound shapes against a live kmorphd: real glyph and
icon pairs from tests/fixtures/compound morph with frames 0 and 1 equal
to the inputs' contours (each input path parsed and sampled here,
independently of the client and the service), a valid contour pairing, a
caller's pairing honoured, a vanishing contour None at t = 1 and
shrinking to a point in the interpolator, jobs, and errors naming the
contour. The paths are parsed by tests/clients/lib/svgpath.py."""
import json
import math
import re
import os
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "clients", "python"))
sys.path.insert(0, os.path.join(ROOT, "tests", "pylib"))
sys.path.insert(0, os.path.join(ROOT, "tests", "clients", "lib"))

import kmdaemon  # noqa: E402
from svgpath import subpaths, hausdorff, poly_length  # noqa: E402
import kmorph  # noqa: E402
from kmorph import (Client, KmorphError, ContourError, curve, shape, path_contours, morph_request,  # noqa: E402
                    is_compound, contour_pairs, frame_contours, frame_contour_paths,
                    frame_path, frame_paths, interpolator, bounds)

FIXTURES = os.path.join(ROOT, "tests", "fixtures", "compound")
DAEMON = None


def _load(name, key):
    with open(os.path.join(FIXTURES, name), encoding="utf-8") as f:
        return {x["id"]: x for x in json.load(f)[key]}


SHAPES = {**_load("glyphs.json", "glyphs"), **_load("icons.json", "icons")}
with open(os.path.join(FIXTURES, "pairs.json"), encoding="utf-8") as _f:
    PAIRS = json.load(_f)["pairs"]


def setUpModule():
    global DAEMON
    DAEMON = kmdaemon.Daemon()


def tearDownModule():
    if DAEMON:
        DAEMON.stop()


def url():
    return "http://%s:%d" % (kmdaemon.HOST, DAEMON.port)


# Tolerance of every request (font units of a 100-unit em, icon units of a
# 24-unit box) and the margin beyond it for the sampling of both sides (48
# points per input segment, 16 per frame Bezier: chords within 1e-4 of
# the curves at these sizes) and the 1e-6 rounding of path numbers: 2e-5
# of the shape's size.
TOL = {"glyph": 0.01, "icon": 0.003}
MARGIN = {"glyph": 0.002, "icon": 0.0005}


def pair(frm, to):
    for p in PAIRS:
        if p["from"] == frm and p["to"] == to:
            return p
    raise AssertionError("pair %s -> %s not in pairs.json" % (frm, to))


class ShapeTest(unittest.TestCase):
    def setUp(self):
        self.km = Client(url())

    def assert_ends_are_inputs(self, res, from_d, to_d, bound):
        """Slot k of frame 0 is contour i of `from` for the pair [i, j]
        (None when i is None), of frame 1 contour j of `to`; compared as
        point sets. Returns the largest distance."""
        worst = 0.0
        used = res["contour_matches_used"]
        for frame, inputs, side in ((res["frames"][0], subpaths(from_d), 0),
                                    (res["frames"][-1], subpaths(to_d), 1)):
            paths = frame_contour_paths(frame)
            self.assertEqual(len(paths), len(used))
            for k, pr in enumerate(used):
                want = pr[side]
                if want is None:
                    self.assertIsNone(paths[k], "slot %d at t = %d is collapsed" % (k, side))
                    continue
                self.assertIsNotNone(paths[k], "slot %d at t = %d is present" % (k, side))
                mine = subpaths(paths[k], 16)
                self.assertEqual(len(mine), 1)
                h = hausdorff(mine[0], inputs[want], 4 * bound)
                self.assertLessEqual(h, bound, "t = %d, slot %d (contour %d)" % (side, k, want))
                worst = max(worst, h)
        return worst

    def assert_assignment(self, used, n_from, n_to):
        """Every contour of either side appears exactly once across pairs."""
        seen_from, seen_to = [0] * n_from, [0] * n_to
        for i, j in used:
            self.assertFalse(i is None and j is None)
            if i is not None:
                seen_from[i] += 1
            if j is not None:
                seen_to[j] += 1
        self.assertEqual(seen_from, [1] * n_from)
        self.assertEqual(seen_to, [1] * n_to)

    def test_real_pairs_reproduce_their_inputs_at_both_ends_with_a_valid_pairing(self):
        cases = [("dejavu-serif/0", "dejavu-serif/O"), ("dejavu-sans/O", "dejavu-sans/C"),
                 ("dejavu-sans/i", "dejavu-sans/l"), ("mdi/circle-double", "mdi/target"),
                 ("mdi/dice-3", "mdi/dice-5")]
        for frm, to in cases:
            with self.subTest(pair="%s -> %s" % (frm, to)):
                p = pair(frm, to)
                tol = TOL[p["kind"]]
                res = self.km.morph(morph_request(SHAPES[frm]["d"], SHAPES[to]["d"], frames=5, tolerance=tol))
                self.assertTrue(is_compound(res))
                self.assert_assignment(res["contour_matches_used"], *p["counts"])
                self.assertEqual(contour_pairs(res), [(k, i, j) for k, (i, j) in
                                                      enumerate(res["contour_matches_used"])])
                worst = self.assert_ends_are_inputs(res, SHAPES[frm]["d"], SHAPES[to]["d"],
                                                    tol + MARGIN[p["kind"]])
                print("%s -> %s: ends within %.3g of the inputs (tolerance %g)" % (frm, to, worst, tol),
                      file=sys.stderr)
                for f in res["frames"]:
                    present = sum(c is not None for c in frame_contours(f))
                    d = frame_path(f)
                    self.assertEqual((d.count("M"), d.count("Z")), (present, present))
                # A B-spline lies in its control polygon's hull.
                x0, y0, x1, y1 = bounds(res)
                for f in res["frames"]:
                    for d in frame_contour_paths(f):
                        for x, y in (subpaths(d, 4)[0] if d else []):
                            self.assertTrue(x0 - 1e-6 <= x <= x1 + 1e-6 and y0 - 1e-6 <= y <= y1 + 1e-6)

    def test_o_to_c_counter_is_none_at_t_1_and_svg_d_is_the_combined_path(self):
        res = self.km.morph(morph_request(SHAPES["dejavu-sans/O"]["d"], SHAPES["dejavu-sans/C"]["d"],
                                          frames=3, tolerance=TOL["glyph"], include=["svg_d"]))
        slot = [j for _, j in res["contour_matches_used"]].index(None)
        self.assertIsNone(frame_contours(res["frames"][2])[slot])
        self.assertIsNotNone(frame_contours(res["frames"][1])[slot])
        self.assertEqual(frame_paths(res)[2], res["frames"][2]["svg_d"])
        self.assertEqual(res["frames"][2]["svg_d"].count("M"), 1)
        # Without svg_d the client writes the same shape itself, within the
        # tolerance the service writes its numbers to.
        bare = {"t": 1, "contours": [c and {k: v for k, v in c.items() if k != "svg_d"}
                                     for c in res["frames"][2]["contours"]]}
        mine, theirs = subpaths(frame_path(bare), 16), subpaths(res["frames"][2]["svg_d"], 16)
        self.assertEqual(len(mine), 1)
        self.assertLessEqual(hausdorff(mine[0], theirs[0], 0.04), TOL["glyph"])

    def test_o_to_c_interpolator_shrinks_the_counter_to_length_0_with_one_structure(self):
        res = self.km.morph(morph_request(SHAPES["dejavu-sans/O"]["d"], SHAPES["dejavu-sans/C"]["d"],
                                          frames=5, tolerance=TOL["glyph"]))
        slot = [j for _, j in res["contour_matches_used"]].index(None)
        per = interpolator(res, samples=120, per_contour=True)
        whole = interpolator(res, samples=120)
        structure = re.sub(r"-?[\d.e]+", "#", whole(0))
        prev = math.inf
        for k in range(41):
            t = k / 40
            d = per(t)[slot]
            self.assertIsNotNone(d)
            length = poly_length(subpaths(d, 1)[0])
            self.assertLessEqual(length, prev + 1e-9, "t = %g" % t)
            prev = length
            self.assertEqual(re.sub(r"-?[\d.e]+", "#", whole(t)), structure, "t = %g" % t)
        self.assertLess(prev, 1e-9)
        omit = interpolator(res, samples=120, collapsed="omit")
        self.assertEqual(omit(1).count("M"), 1)
        self.assertEqual(omit(0.99).count("M"), 2)
        mid = subpaths(per(0.5)[slot], 1)[0]
        frame = subpaths(frame_contour_paths(res["frames"][2])[slot], 16)[0]
        self.assertLess(hausdorff(mid, frame, 0.2), 0.05)

    def test_between_frames_the_vanishing_dot_of_i_follows_the_frames_into_its_point(self):
        frm, to = SHAPES["dejavu-sans/i"]["d"], SHAPES["dejavu-sans/l"]["d"]
        res = self.km.morph(morph_request(frm, to, frames=11, tolerance=0.001))
        slot = [j for _, j in res["contour_matches_used"]].index(None)
        truth = self.km.morph(morph_request(frm, to, times=[0.95, 0.99], tolerance=0.001,
                                            contour_matches=res["contour_matches_used"]))
        at = interpolator(res, samples=400, per_contour=True)
        # The dot's centre moves on a smooth track: carried on from the
        # frames at 0.8 and 0.9 it lands within 2e-4 of the em of the
        # service's dot (at most 2.2 long here: 400 samples cut its corners
        # by less than 0.003); the centre at 0.9 alone is 0.27 off.
        for f in truth["frames"]:
            h = hausdorff(subpaths(frame_contour_paths(f)[slot], 16)[0], subpaths(at(f["t"])[slot], 1)[0], 0.5)
            self.assertLess(h, 0.02, "t = %g" % f["t"])

    def test_a_callers_contour_matches_are_honoured(self):
        frm, to = SHAPES["mdi/dice-3"]["d"], SHAPES["mdi/dice-5"]["d"]
        auto = self.km.morph(morph_request(frm, to, frames=2, tolerance=TOL["icon"]))
        mine = [[0, 0], [1, 1], [2, 2], [3, 3], [None, 4], [None, 5]]
        self.assertNotEqual(auto["contour_matches_used"], mine)
        res = self.km.morph(morph_request(frm, to, frames=2, tolerance=TOL["icon"], contour_matches=mine))
        key = lambda p: (p[0] is None, p[0] or 0, p[1] is None, p[1] or 0)  # noqa: E731
        self.assertEqual(sorted(res["contour_matches_used"], key=key), sorted(mine, key=key))
        self.assert_ends_are_inputs(res, frm, to, TOL["icon"] + MARGIN["icon"])

    def test_a_shape_of_contours_morphs_as_the_compound_svg_path(self):
        d = SHAPES["liberation-sans/i"]["d"]
        parts = ["M" + s.strip() for s in d.split("M") if s.strip()]
        self.assertEqual(len(parts), 2)
        target = SHAPES["liberation-sans/j"]["d"]
        a = self.km.morph(morph_request(d, target, frames=3, tolerance=TOL["glyph"]))
        b = self.km.morph(morph_request(shape(parts, fill_rule="nonzero"), target, frames=3,
                                        tolerance=TOL["glyph"]))
        self.assertEqual(a, b)
        self.assertEqual(curve(parts), {"type": "shape", "contours": [{"type": "svg", "d": p} for p in parts]})

    def test_a_job_of_shapes_answers_the_synchronous_frames(self):
        req = morph_request(SHAPES["mdi/circle-double"]["d"], SHAPES["mdi/target"]["d"], frames=9,
                            tolerance=TOL["icon"])
        seen = []
        res = self.km.morph_job(req, on_progress=lambda s: seen.append(s["progress"]))
        self.assertEqual(seen[-1], 1)
        sync = self.km.morph(req)
        self.assertEqual(res["contour_matches_used"], sync["contour_matches_used"])
        self.assertEqual(frame_paths(res), frame_paths(sync))

    def test_errors_name_the_contour_and_the_subpath_offset(self):
        good = "M 0 0 L 10 0 L 10 10 Z"
        with self.assertRaises(KmorphError) as cm:
            self.km.morph(morph_request(shape([good, "M 20 0 L 30 0 L 30 10"]), good))
        e = cm.exception
        self.assertEqual(e.status, 422)
        self.assertIsNotNone(e.message_for("/from/contours/1"))
        self.assertEqual([(c.side, c.contour) for c in e.contour_errors()], [("from", 1)])
        self.assertIsInstance(e.contour_errors()[0], ContourError)
        bad = "M 0 0 L 10 0 L 10 10 Z M 20 0 L 20 0 Z"
        with self.assertRaises(KmorphError) as cm:
            self.km.morph(morph_request(good, bad))
        c = cm.exception.contour_errors()[0]
        self.assertEqual((c.side, c.contour, c.offset), ("to", 1, bad.index("M 20")))


    def test_path_contours_close_an_icons_open_subpaths_and_they_morph(self):
        icon, to = SHAPES["mdi/lock"], SHAPES["mdi/lock-outline"]["d"]
        self.assertNotEqual(icon["d_source"], icon["d"])
        with self.assertRaises(KmorphError) as cm:
            self.km.morph(morph_request(icon["d_source"], to, frames=2))
        self.assertEqual([(c.side, c.contour) for c in cm.exception.contour_errors()], [("from", 0)])
        parts = path_contours(icon["d_source"])
        self.assertEqual(len(parts), icon["subpaths"])
        for k, (p, want) in enumerate(zip(parts, subpaths(icon["d"]))):
            self.assertRegex(p, r"^M[^Mm]*[Zz]$")
            self.assertLess(hausdorff(subpaths(p)[0], want, 1e-6), 1e-9, "contour %d" % k)
        a = self.km.morph(morph_request(" ".join(parts), to, frames=3, tolerance=TOL["icon"]))
        b = self.km.morph(morph_request(icon["d"], to, frames=3, tolerance=TOL["icon"]))
        self.assertEqual(a, b)

    def test_path_contours_of_every_fixture_give_the_signatures_of_its_closed_d(self):
        for x in SHAPES.values():
            want = self.km.signature(curve(x["d"]))
            for d in [x["d"]] + ([x["d_source"]] if "d_source" in x else []):
                parts = path_contours(d)
                self.assertEqual(len(parts), len(want["signatures"]) if "signatures" in want else 1, x["id"])
                self.assertEqual(self.km.signature(curve(" ".join(parts))), want, x["id"])

    def test_path_contours_keep_relative_subpaths_where_they_were(self):
        # The second square is placed by a relative moveto from the open
        # first one's last point (10, 30): corners (15, 35) and (25, 45).
        parts = path_contours("m 10 10 h 20 v 20 h -20 m 5 5 h 10 v 10 h -10")
        self.assertEqual(len(parts), 2)

        def box(pts):
            return (min(p[0] for p in pts), min(p[1] for p in pts), max(p[0] for p in pts), max(p[1] for p in pts))
        self.assertEqual(box(subpaths(parts[0])[0]), (10, 10, 30, 30))
        self.assertEqual(box(subpaths(parts[1])[0]), (15, 35, 25, 45))
        self.assertAlmostEqual(poly_length(subpaths(parts[1])[0]), 40, delta=1e-9)
        self.assertEqual(path_contours("M 0 0 M 1 1 L 2 1 L 2 2 Z", close=False), ["M1,1L2 1L2 2Z"])
        self.assertEqual(path_contours("M0 0h5v5Z", close=False), ["M0,0h5v5Z"])
        with self.assertRaisesRegex(ValueError, "offset 6"):
            path_contours("M 0 0 X 1")

    def test_evenodd_makes_an_inner_square_of_the_same_turn_a_hole(self):
        d = "M 0 0 L 10 0 L 10 10 L 0 10 Z M 2 2 L 8 2 L 8 8 L 2 8 Z"
        # Inside both contours the winding number is 2: filled under
        # nonzero, empty (even) under evenodd.
        eo = self.km.signature(shape(d, fill_rule="evenodd"))
        self.assertEqual((eo["roles"], eo["fill_rule"]), (["outer", "hole"], "evenodd"))
        self.assertEqual(self.km.signature(shape(d))["roles"], ["outer", "outer"])


class ShapeCommandLineTest(unittest.TestCase):
    def run_cli(self, *args):
        env = dict(os.environ, PYTHONPATH=os.path.join(ROOT, "clients", "python"), KMORPH_URL=url())
        return subprocess.run([sys.executable, "-m", "kmorph", *args], capture_output=True,
                              text=True, env=env, timeout=120)

    def test_paths_print_one_line_per_frame_and_the_pairing_with_contour_matches(self):
        frm, to = SHAPES["mdi/dice-3"], SHAPES["mdi/dice-5"]
        with tempfile.TemporaryDirectory() as tmp:
            # An SVG document as an icon ships: its <path> is the shape.
            svg = os.path.join(tmp, "dice-3.svg")
            with open(svg, "w", encoding="utf-8") as f:
                f.write('<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 24 24"><path d="%s" /></svg>'
                        % frm["d"])
            r = self.run_cli("morph", "-n", "3", "-p", "-t", "0.003",
                             "-C", "[[0,0],[1,1],[2,2],[3,3],[null,4],[null,5]]", "@" + svg, to["d"])
        self.assertEqual(r.returncode, 0, r.stderr)
        lines = r.stdout.splitlines()
        self.assertEqual([ln.split("\t")[0] for ln in lines], ["0", "0.5", "1"])
        self.assertIn("kmorph: contours: from 0 -> to 0, from 1 -> to 1, from 2 -> to 2, from 3 -> to 3, "
                      "to 4 appears, to 5 appears", r.stderr)
        # The pips that appear are points at t = 0 and present at t = 1.
        self.assertEqual([ln.split("\t")[1].count("M") for ln in lines], [4, 6, 6])
        first = subpaths(lines[0].split("\t")[1], 16)
        for k, want in enumerate(subpaths(frm["d"])):
            self.assertLessEqual(hausdorff(first[k], want, 0.02), TOL["icon"] + MARGIN["icon"])

    def test_svg_documents_close_their_subpaths_and_keep_their_fill_rule(self):
        with tempfile.TemporaryDirectory() as tmp:
            def doc(name, text):
                path = os.path.join(tmp, name)
                with open(path, "w", encoding="utf-8") as f:
                    f.write(text)
                return "@" + path
            squares = "M0 0h10v10h-10zM2 2h6v6h-6z"
            eo = doc("eo.svg", '<svg xmlns="http://www.w3.org/2000/svg"><g style="fill-rule: evenodd">'
                               '<path d="%s"/></g></svg>' % squares)
            nz = doc("nz.svg", '<svg xmlns="http://www.w3.org/2000/svg"><path d="%s"/></svg>' % squares)
            roles = []
            for arg in (eo, nz):
                r = self.run_cli("signature", arg)
                self.assertEqual(r.returncode, 0, r.stderr)
                roles.append(json.loads(r.stdout)["roles"])
            self.assertEqual(roles, [["outer", "hole"], ["outer", "outer"]])
            # The lock as mdi ships it, open subpaths and all.
            lock = doc("lock.svg", '<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 24 24">'
                                   '<path d="%s"/></svg>' % SHAPES["mdi/lock"]["d_source"])
            r = self.run_cli("morph", "-n", "3", "-p", "-t", "0.003", lock, SHAPES["mdi/lock-outline"]["d"])
            self.assertEqual(r.returncode, 0, r.stderr)
            first = subpaths(r.stdout.splitlines()[0].split("\t")[1], 16)
            self.assertEqual(len(first), 3)
            for got, want in zip(first, subpaths(SHAPES["mdi/lock"]["d"])):
                self.assertLessEqual(hausdorff(got, want, 0.02), TOL["icon"] + MARGIN["icon"])
            mixed = doc("mixed.svg", '<svg><path d="M0 0h1v1z"/><path fill-rule="evenodd" d="M2 2h1v1z"/></svg>')
            r = self.run_cli("signature", mixed)
            self.assertEqual(r.returncode, 2)
            self.assertIn("different fill rules", r.stderr)

    def test_a_bad_contour_exits_1_naming_it(self):
        r = self.run_cli("morph", json.dumps(shape(["M 0 0 L 10 0 L 10 10 Z", "M 20 0 L 30 0 L 30 10"])),
                         "M 0 0 L 10 0 L 10 10 Z")
        self.assertEqual(r.returncode, 1)
        self.assertIn("at /from/contours/1:", r.stderr)


if __name__ == "__main__":
    unittest.main()
