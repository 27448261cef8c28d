"""test_shapes.py - compound shapes against the live daemon: a glyph pair
of tests/fixtures/compound morphed by POST /v1/morph and by a job, the
signature of a ring, and the problems of bad shapes, every answer checked
against api/openapi.yaml. Contour counts come from pairs.json."""
import json
import math
import os
import unittest
import xml.etree.ElementTree as ET

from kmtest import ROOT, ContractCase, Daemon, DaemonCase, circle_svg, run_job

FIXTURES = os.path.join(ROOT, "tests", "fixtures", "compound")


def load(name):
    with open(os.path.join(FIXTURES, name), encoding="utf-8") as f:
        return json.load(f)


GLYPHS = {g["id"]: g for g in load("glyphs.json")["glyphs"]}
# the first glyph pair whose two sides have different contour counts
PAIR = next(p for p in load("pairs.json")["pairs"]
            if p["kind"] == "glyph" and p["counts"][0] != p["counts"][1])


def glyph(gid):
    return {"type": "svg", "d": GLYPHS[gid]["d"]}


def ring(r_out, r_in):
    """Two concentric circles as one path, both counter-clockwise: under
    the nonzero rule the inner one is filled twice over, not a hole."""
    return {"type": "svg", "d": circle_svg(r_out)["d"] + " " +
            circle_svg(r_in)["d"]}


class CompoundMorphs(DaemonCase):
    def body(self, frames=5):
        return {"from": glyph(PAIR["from"]), "to": glyph(PAIR["to"]),
                "frames": frames, "include": ["svg_d"]}

    def check_glyph_answer(self, doc):
        used = doc["contour_matches_used"]
        n_from, n_to = PAIR["counts"]
        # every contour of each side in exactly one pair
        self.assertEqual(sorted(p[0] for p in used if p[0] is not None),
                         list(range(n_from)))
        self.assertEqual(sorted(p[1] for p in used if p[1] is not None),
                         list(range(n_to)))
        frames = doc["frames"]
        self.assertEqual(frames[0]["t"], 0)
        self.assertEqual(frames[-1]["t"], 1)
        for f in frames:
            self.assertEqual(len(f["contours"]), len(used))
            present = [c for c in f["contours"] if c is not None]
            # one closed subpath a present contour
            self.assertEqual(f["svg_d"].count("M"), len(present))
            self.assertEqual(f["svg_d"].count("Z"), len(present))
            for c in present:
                self.assertTrue(c["closed"])
        # at the ends, the inputs' contours: a slot is null exactly where
        # its pair has no contour on that side
        for f, side, count in ((frames[0], 0, n_from), (frames[-1], 1, n_to)):
            self.assertEqual(sum(c is not None for c in f["contours"]),
                             count)
            for k, pr in enumerate(used):
                self.assertEqual(f["contours"][k] is None, pr[side] is None)

    def test_glyph_pair_morph_is_documented(self):
        r = self.d.request("POST", "/v1/morph", body=self.body())
        self.assertEqual(r.status, 200, r.body[:300])
        doc = self.assertDocumented(r, "/v1/morph", "post")
        self.check_glyph_answer(doc)

    def test_glyph_pair_job_gives_the_synchronous_answer(self):
        sync = self.d.request("POST", "/v1/morph", body=self.body(7))
        self.assertEqual(sync.status, 200, sync.body[:300])
        r, jid, s = run_job(self.d, self.body(7))
        self.assertEqual(r.status, 202, r.body[:300])
        self.assertDocumented(r, "/v1/jobs", "post")
        self.assertTrue(s, "the job ends")
        self.assertEqual(s["state"], "done", s)
        res = self.d.request("GET", "/v1/jobs/%s/result" % jid)
        doc = self.assertDocumented(res, "/v1/jobs/{id}/result", "get")
        self.check_glyph_answer(doc)
        self.assertEqual(doc, sync.json())

    def test_ring_signature_has_one_signature_per_contour(self):
        for fill, roles in (("nonzero", ["outer", "outer"]),
                            ("evenodd", ["outer", "hole"])):
            shape = {"type": "shape", "fill_rule": fill,
                     "contours": [circle_svg(2.0), circle_svg(1.0)]}
            r = self.d.request("POST", "/v1/signature",
                               body={"curve": shape})
            doc = self.assertDocumented(r, "/v1/signature", "post")
            self.assertEqual(r.status, 200)
            lengths = [s["length"] for s in doc["signatures"]]
            self.assertAlmostEqual(lengths[0], 4 * math.pi, places=9)
            self.assertAlmostEqual(lengths[1], 2 * math.pi, places=9)
            self.assertEqual(doc["fill_rule"], fill)
            self.assertEqual(doc["roles"], roles)
        # the svg form of the same contours is the nonzero shape
        r = self.d.request("POST", "/v1/signature",
                           body={"curve": ring(2.0, 1.0)})
        doc = self.assertDocumented(r, "/v1/signature", "post")
        self.assertEqual(doc["roles"], ["outer", "outer"])

    def test_bad_contour_is_a_documented_problem(self):
        shape = {"type": "shape", "contours": [
            circle_svg(2.0), {"type": "svg", "d": "M 0 0 L 1 0 L 1 1"}]}
        r = self.d.request("POST", "/v1/morph",
                           body={"from": shape, "to": ring(2.0, 1.0)})
        doc = self.assertDocumented(r, "/v1/morph", "post")
        self.assertEqual(r.status, 422)
        self.assertEqual(doc["errors"][0]["pointer"], "/from/contours/1")

    def test_svg_documents_of_shapes_are_filled(self):
        body = self.body(4)
        del body["include"]
        r = self.d.request("POST", "/v1/morph", body=body,
                           headers={"Accept": "image/svg+xml"})
        self.assertEqual(r.status, 200, r.body[:300])
        svg = self.assertDocumented(r, "/v1/morph", "post").decode()
        root = ET.fromstring(svg)
        paths = root.findall(".//{http://www.w3.org/2000/svg}path")
        # one filled path a frame; the ends have the inputs' contour counts
        self.assertEqual(len(paths), 4)
        for p in paths:
            self.assertIn(p.get("fill-rule"), ("nonzero", "evenodd"))
            self.assertNotEqual(p.get("fill"), "none")
        self.assertEqual(paths[0].get("d").count("M"), PAIR["counts"][0])
        self.assertEqual(paths[-1].get("d").count("M"), PAIR["counts"][1])
        # the animation: one <animate> of d, a value a frame, every value
        # one subpath a slot (a collapsed contour is a point)
        body["svg"] = {"layout": "animate"}
        r = self.d.request("POST", "/v1/morph", body=body,
                           headers={"Accept": "image/svg+xml"})
        self.assertEqual(r.status, 200, r.body[:300])
        root = ET.fromstring(self.assertDocumented(r, "/v1/morph", "post"))
        anims = [a for a in root.iter("{http://www.w3.org/2000/svg}animate")
                 if a.get("attributeName") == "d"]
        self.assertEqual(len(anims), 1)
        values = anims[0].get("values").split(";")
        self.assertEqual(len(values), 4)
        subpaths = {v.count("M") for v in values}
        self.assertEqual(len(subpaths), 1)
        self.assertGreaterEqual(subpaths.pop(), max(PAIR["counts"]))


class ContourLimit(ContractCase):
    """--max-contours bounds the contours of a shape: at the limit a shape
    morphs, one past it is a 422 naming the side."""
    @classmethod
    def setUpClass(cls):
        cls.d = Daemon("--threads", "1", "--max-contours", "3")

    @classmethod
    def tearDownClass(cls):
        cls.d.stop()

    @staticmethod
    def squares(n):
        """n unit squares side by side, 2 apart: n contours, no nesting."""
        return {"type": "svg", "d": " ".join(
            "M %d 0 H %d V 1 H %d Z" % (2 * i, 2 * i + 1, 2 * i)
            for i in range(n))}

    def test_three_contours_morph_and_four_are_refused(self):
        r = self.d.request("POST", "/v1/morph", body={
            "from": self.squares(3), "to": self.squares(3), "frames": 3})
        doc = self.assertDocumented(r, "/v1/morph", "post")
        self.assertEqual(r.status, 200)
        self.assertEqual(len(doc["contour_matches_used"]), 3)
        r = self.d.request("POST", "/v1/morph", body={
            "from": self.squares(3), "to": self.squares(4), "frames": 3})
        doc = self.assertProblem(r, 422, "/v1/morph", "post")
        self.assertTrue(doc["errors"][0]["pointer"].startswith("/to"),
                        doc["errors"])


if __name__ == "__main__":
    unittest.main()
