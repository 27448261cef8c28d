"""pairs.py - the pairs the end-to-end bench morphs, as request bodies.

Glyph and icon pairs come from tests/fixtures/compound/pairs.json: each
pair whole (its contours, a compound morph) and as its first contours
alone (a single-contour morph); the older pairs of tests/fixtures/shapes.json
as they are. Every pair carries its SVG path data for flubber, which takes
one contour (flubber's interpolate) or several (interpolateAll is not
comparable), so flubber gets the single-contour forms only.
"""
import json
import os
import re

ROOT = os.path.normpath(os.path.join(os.path.dirname(__file__), "..", ".."))
FIXTURES = os.path.join(ROOT, "tests", "fixtures")


def first_subpath(d):
    """The first subpath of SVG path data (up to the second moveto)."""
    moves = [m.start() for m in re.finditer(r"[Mm]", d)]
    return d[: moves[1]].strip() if len(moves) > 1 else d.strip()


def load_pairs(glyphs=4, icons=4):
    """[(name, kind, from_d, to_d)]: single-contour and compound pairs."""
    with open(os.path.join(FIXTURES, "compound", "pairs.json")) as f:
        pairs = json.load(f)["pairs"]
    with open(os.path.join(FIXTURES, "compound", "glyphs.json")) as f:
        by_id = {g["id"]: g["d"] for g in json.load(f)["glyphs"]}
    with open(os.path.join(FIXTURES, "compound", "icons.json")) as f:
        by_id.update({i["id"]: i["d"] for i in json.load(f)["icons"]})
    out, seen, taken = [], set(), {"glyph": 0, "icon": 0}
    for p in pairs:
        key = (p["from"], p["to"])
        limit = glyphs if p["kind"] == "glyph" else icons
        if key in seen or taken[p["kind"]] >= limit:
            continue
        seen.add(key)
        taken[p["kind"]] += 1
        a, b = by_id[p["from"]], by_id[p["to"]]
        name = p["from"].split("/")[-1] + "-" + p["to"].split("/")[-1]
        font = p["from"].split("/")[0]
        out.append((f"{font}:{name}", p["kind"], first_subpath(a),
                    first_subpath(b)))
        out.append((f"{font}:{name}+", p["kind"] + "-compound", a, b))
    with open(os.path.join(FIXTURES, "shapes.json")) as f:
        for p in json.load(f)["pairs"]:
            out.append((p["name"], "shape", p["a_d"], p["b_d"]))
    return out


def body(from_d, to_d, frames, metrics, svg=False, precision=None):
    """A POST /v1/morph body of frames frames between two path data."""
    b = {"from": {"type": "svg", "d": from_d},
         "to": {"type": "svg", "d": to_d},
         "frames": frames, "metrics": metrics}
    if svg:
        b["format"] = "svg"
    if precision is not None:
        b["precision"] = precision
    return json.dumps(b).encode()
