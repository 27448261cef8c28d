#!/usr/bin/python3
"""compound_fixtures.py: writes the compound test shapes of
tests/fixtures/compound/ (glyphs.json, icons.json, pairs.json).

Glyph outlines come from the Debian font packages through Debian's
python3-fonttools (so run it with /usr/bin/python3); icons come from the
@mdi/svg npm package, installed into a temporary folder at the pinned
version. Only the npm step needs the network; the tests read the JSON.

Glyph coordinates are exact: font units are multiplied by 100 / unitsPerEm
and written as terminating decimals computed with fractions, so a TrueType
on-curve point, off-curve point or implied midpoint and a CFF control point
appear in the path data as the same rational number the font stores.

  /usr/bin/python3 tools/compound_fixtures.py [--out DIR] [--mdi DIR]

--mdi names an existing node_modules/@mdi/svg folder (skips npm).
"""

import argparse
import json
import math
import os
import re
import subprocess
import sys
import tempfile
from fractions import Fraction

try:
    from fontTools.ttLib import TTFont
    from fontTools.pens.boundsPen import BoundsPen
    from fontTools.pens.recordingPen import RecordingPen
except ImportError:
    sys.exit("needs Debian's python3-fonttools: apt-get install "
             "python3-fonttools, then run with /usr/bin/python3")

MDI_VERSION = "7.4.47"
EM = 100

# (id prefix, family label, file, Debian package). Two TrueType families
# (quadratic outlines, glyf), each in a sans and a serif cut; cubic
# outlines come from the icons. A CFF family (URW base35, cubic) is left
# out: its AGPL-3.0 licence would reach the outlines copied here. The
# reader still handles CFF.
FONTS = [
    ("dejavu-sans", "DejaVu Sans",
     "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf", "fonts-dejavu-core"),
    ("dejavu-serif", "DejaVu Serif",
     "/usr/share/fonts/truetype/dejavu/DejaVuSerif.ttf", "fonts-dejavu-core"),
    ("liberation-sans", "Liberation Sans",
     "/usr/share/fonts/truetype/liberation2/LiberationSans-Regular.ttf",
     "fonts-liberation2"),
    ("liberation-serif", "Liberation Serif",
     "/usr/share/fonts/truetype/liberation2/LiberationSerif-Regular.ttf",
     "fonts-liberation2"),
]

# Glyphs with holes, glyphs with dots, and the partners of the unequal
# pairs (C c l 3 have one contour), plus % (two rings and a bar).
GLYPHS = "abdegopqABDOPQR04689ij" + "Ccl3" + "%"

# A fixed selection of @mdi/svg icons with 2 to 6 subpaths, by kind.
ICONS = {
    "rings": ["circle-outline", "radiobox-marked", "record-circle-outline",
              "target", "bullseye", "circle-double", "stop-circle-outline"],
    "dots": ["dots-horizontal", "dots-vertical", "dice-1", "dice-2",
             "dice-3", "dice-4", "dice-5", "percent", "division"],
    "bars": ["equal", "pause", "menu", "reorder-horizontal",
             "signal-cellular-2", "signal-cellular-3",
             "format-align-left", "format-align-justify"],
    "cut-outs": ["lock", "lock-outline", "alert-circle",
                 "alert-circle-outline", "information",
                 "information-outline", "help-circle",
                 "help-circle-outline", "account", "account-outline",
                 "camera", "camera-outline", "key", "key-outline",
                 "eye", "eye-outline", "play-circle-outline",
                 "pause-circle-outline", "plus-circle-outline"],
}

GLYPH_PAIRS = [
    # unequal contour counts: a hole or a dot appears or vanishes
    ("dejavu-sans/O", "dejavu-sans/C", "ring opens: the hole has no partner"),
    ("dejavu-sans/i", "dejavu-sans/l", "the dot vanishes into the stem"),
    ("dejavu-sans/8", "dejavu-sans/3", "two holes vanish"),
    ("dejavu-sans/B", "dejavu-sans/R", "two holes become one"),
    ("dejavu-sans/e", "dejavu-sans/c", "the eye of e closes away"),
    ("dejavu-serif/O", "dejavu-serif/C", "ring opens, serif strokes"),
    ("dejavu-serif/B", "dejavu-serif/R", "two holes become one, serifs"),
    ("dejavu-serif/i", "dejavu-serif/l", "dot and serifed stem"),
    ("liberation-sans/8", "liberation-sans/3", "two holes vanish"),
    ("liberation-sans/e", "liberation-sans/c", "hole vanishes"),
    ("liberation-sans/%", "liberation-sans/o", "five contours to two"),
    ("liberation-serif/g", "liberation-serif/q",
     "double-storey g: two holes become one"),
    ("liberation-serif/8", "liberation-serif/0", "two holes become one"),
    ("dejavu-serif/O", "dejavu-serif/C", "ring opens, serif"),
    ("dejavu-serif/i", "dejavu-serif/l", "dot vanishes, serif"),
    ("liberation-serif/B", "liberation-serif/R", "two holes become one, serif"),
    ("liberation-serif/e", "liberation-serif/c", "hole vanishes, serif"),
    # equal contour counts: holes pair with holes
    ("dejavu-sans/b", "dejavu-sans/d", "mirror images, one hole each"),
    ("dejavu-sans/p", "dejavu-sans/q", "mirror images below the baseline"),
    ("dejavu-sans/6", "dejavu-sans/9", "a half turn, one hole each"),
    ("dejavu-serif/A", "dejavu-serif/R", "one hole each, different outer"),
    ("liberation-sans/D", "liberation-sans/O", "one hole each"),
    ("liberation-sans/i", "liberation-sans/j", "stem and dot each"),
    ("liberation-serif/P", "liberation-serif/R", "one hole, a leg grows"),
    ("liberation-serif/a", "liberation-serif/e", "one hole each"),
    ("dejavu-serif/0", "dejavu-serif/O", "one hole each, serif"),
    ("liberation-sans/4", "liberation-sans/A", "triangular hole each"),
    ("dejavu-serif/o", "dejavu-serif/p", "one hole each, a stem grows"),
    ("dejavu-serif/8", "dejavu-serif/B", "two holes each"),
    # across fonts: the same letter, a different design
    ("dejavu-sans/g", "liberation-serif/g",
     "single-storey g to double-storey g"),
    ("dejavu-sans/a", "liberation-serif/a", "sans to serif"),
    ("liberation-sans/Q", "dejavu-serif/Q", "tail drawn two ways"),
]

ICON_PAIRS = [
    ("mdi/dice-1", "mdi/dice-2", "one pip becomes two"),
    ("mdi/dice-3", "mdi/dice-5", "two pips appear"),
    ("mdi/dice-2", "mdi/dice-4", "pips appear at the corners"),
    ("mdi/circle-outline", "mdi/radiobox-marked", "a dot appears in a ring"),
    ("mdi/radiobox-marked", "mdi/record-circle-outline",
     "dot in a ring, sizes differ"),
    ("mdi/target", "mdi/bullseye", "three contours to five"),
    ("mdi/circle-double", "mdi/target", "four rings to three"),
    ("mdi/equal", "mdi/menu", "two bars to three"),
    ("mdi/menu", "mdi/reorder-horizontal", "three bars to four"),
    ("mdi/pause", "mdi/equal", "bars turn a quarter"),
    ("mdi/signal-cellular-3", "mdi/signal-cellular-2",
     "a bar empties into an outline"),
    ("mdi/lock", "mdi/lock-outline", "filled body hollows out"),
    ("mdi/alert-circle", "mdi/alert-circle-outline",
     "filled disc becomes a ring"),
    ("mdi/information", "mdi/help-circle", "same ring, different glyph"),
    ("mdi/account", "mdi/account-outline", "two parts hollow out"),
    ("mdi/camera", "mdi/camera-outline", "filled body hollows out"),
    ("mdi/key", "mdi/key-outline", "filled key hollows out"),
    ("mdi/play-circle-outline", "mdi/pause-circle-outline",
     "one triangle becomes two bars"),
    ("mdi/dots-horizontal", "mdi/dots-vertical", "three dots turn"),
]


def dec(q):
    """Exact decimal text of a rational whose denominator divides
    2^a 5^b (font units scaled by 100 / unitsPerEm always are)."""
    q = Fraction(q)
    if q == 0:
        return "0"
    sign = "-" if q < 0 else ""
    q = abs(q)
    whole = q.numerator // q.denominator
    rest = q - whole
    digits = ""
    while rest and len(digits) < 40:
        rest *= 10
        d = rest.numerator // rest.denominator
        digits += str(d)
        rest -= d
    if rest:
        raise ValueError("not a terminating decimal: %r" % (q,))
    return sign + str(whole) + ("." + digits if digits else "")


class Frame:
    """Font units to the 100-unit em, y down. The advance box is centred
    across the em, and down it the vertical extent of the font's selected
    glyphs (band: whole font units around their union), so that all of
    them share a baseline and lie inside [0, 100]^2. The typographic
    ascender and descender would not do: digits and round letters
    overshoot them (a serif 6 by a unit)."""

    def __init__(self, font, advance, band):
        upm = font["head"].unitsPerEm
        self.k = Fraction(EM, upm)
        self.dx = Fraction(upm - advance, 2)
        self.top = Fraction(upm + band[0] + band[1], 2)

    def pt(self, x, y):
        x = (Fraction(x) + self.dx) * self.k
        y = (self.top - Fraction(y)) * self.k
        return x, y


def band(gset, names):
    """(lowest, highest) y of the outlines, rounded out to whole units."""
    lo, hi = 0, 0
    for n in names:
        bp = BoundsPen(gset)
        gset[n].draw(bp)
        if bp.bounds:
            lo = min(lo, math.floor(bp.bounds[1]))
            hi = max(hi, math.ceil(bp.bounds[3]))
    return lo, hi


def fmt(p):
    return dec(p[0]) + " " + dec(p[1])


def quad_contour(pts, frame):
    """One TrueType contour (x, y, on) as M/L/Q commands, ending with Z.
    Between two off-curve points lies the implied on-curve midpoint."""
    n = len(pts)
    p = [(Fraction(x), Fraction(y), on) for x, y, on in pts]
    start = next((i for i in range(n) if p[i][2]), None)
    if start is None:  # all off-curve: start at an implied midpoint
        a, b = p[0], p[1]
        p = [((a[0] + b[0]) / 2, (a[1] + b[1]) / 2, True)] + p[1:] + p[:1]
        start = 0
    p = p[start:] + p[:start]
    p.append(p[0])
    segs = []
    cur = p[0]
    ctrl = None
    for q in p[1:]:
        if q[2]:
            if ctrl is None:
                if (q[0], q[1]) != (cur[0], cur[1]):
                    segs.append(("L", [q]))
            else:
                segs.append(("Q", [ctrl, q]))
            cur, ctrl = q, None
        else:
            if ctrl is not None:
                mid = ((ctrl[0] + q[0]) / 2, (ctrl[1] + q[1]) / 2, True)
                segs.append(("Q", [ctrl, mid]))
                cur = mid
            ctrl = q
    return emit(p[0], segs, frame)


def emit(first, segs, frame):
    """M first, the segments, Z; a final line back to the start is left
    to Z, which draws the same segment."""
    if segs and segs[-1][0] == "L" and \
            (segs[-1][1][0][0], segs[-1][1][0][1]) == (first[0], first[1]):
        segs = segs[:-1]
    out = ["M " + fmt(frame.pt(first[0], first[1]))]
    for op, args in segs:
        out.append(op + " " + " ".join(fmt(frame.pt(a[0], a[1]))
                                       for a in args))
    out.append("Z")
    return " ".join(out)


def glyf_path(font, gname, frame):
    glyf = font["glyf"]
    coords, ends, flags = glyf[gname].getCoordinates(glyf)
    contours, s = [], 0
    for e in ends:
        pts = [(coords[i][0], coords[i][1], bool(flags[i] & 1))
               for i in range(s, e + 1)]
        s = e + 1
        if len(pts) >= 2:
            contours.append(quad_contour(pts, frame))
    return contours


def cff_path(gset, gname, frame):
    rec = RecordingPen()
    gset[gname].draw(rec)
    contours, first, segs, cur = [], None, [], None
    for op, args in rec.value:
        pts = [(Fraction(x), Fraction(y), True) for x, y in args]
        if op == "moveTo":
            first, cur, segs = pts[0], pts[0], []
        elif op == "lineTo":
            if pts[0][:2] != cur[:2]:
                segs.append(("L", pts))
            cur = pts[0]
        elif op == "curveTo":
            segs.append(("C", pts))
            cur = pts[-1]
        elif op in ("closePath", "endPath"):
            if segs:
                contours.append(emit(first, segs, frame))
        else:
            raise ValueError("unexpected CFF pen operation " + op)
    return contours


def glyphs():
    out = []
    for fid, label, path, pkg in FONTS:
        font = TTFont(path)
        cmap = font.getBestCmap()
        gset = font.getGlyphSet()
        version = font["name"].getDebugName(5)
        names = [cmap[ord(ch)] for ch in GLYPHS]
        ext = band(gset, names)
        for ch in GLYPHS:
            gname = cmap[ord(ch)]
            adv = font["hmtx"][gname][0]
            frame = Frame(font, adv, ext)
            if "glyf" in font:
                cs = glyf_path(font, gname, frame)
            else:
                cs = cff_path(gset, gname, frame)
            out.append({
                "id": fid + "/" + ch, "font": label, "glyph": ch,
                "package": pkg, "font_version": version,
                "outline": "quadratic" if "glyf" in font else "cubic",
                "units_per_em": font["head"].unitsPerEm,
                "advance": float(Fraction(adv) * frame.k),
                "baseline": float(frame.top * frame.k),
                "d": " ".join(cs), "contours": len(cs)})
    return out


# Enough of SVG path data to find where each subpath of an mdi icon ends.
_TOK = re.compile(r"[MmLlHhVvCcSsQqTtAaZz]|"
                  r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")
_ARGS = dict(M=2, L=2, H=1, V=1, C=6, S=4, Q=4, T=2, A=7, Z=0)


def subpaths(d):
    """[(start offset, end offset, start point, end point, closed)]."""
    toks = [(m.group(), m.start()) for m in _TOK.finditer(d)]
    res, i, cmd = [], 0, None
    cx = cy = sx = sy = 0.0
    cur = None
    while i < len(toks):
        t, off = toks[i]
        if t.isalpha():
            cmd, i = t, i + 1
            if cmd in "Zz":
                cur["closed"] = True
                cur["end"] = off + 1
                cx, cy = sx, sy
                continue
            if cmd in "Mm":
                if cur:
                    res.append(cur)
                cur = {"start": off, "closed": False}
        elif cmd in "Zz":
            raise ValueError("number after Z")
        n = _ARGS[cmd.upper()]
        a = [float(toks[i + k][0]) for k in range(n)]
        end = toks[i + n - 1][1] + len(toks[i + n - 1][0])
        i += n
        rel = cmd.islower()
        up = cmd.upper()
        if up == "H":
            cx = a[0] + (cx if rel else 0)
        elif up == "V":
            cy = a[0] + (cy if rel else 0)
        else:
            x, y = a[-2], a[-1]
            cx, cy = (cx + x, cy + y) if rel else (x, y)
        if cmd in "Mm":
            if cur.get("p0") is None:
                sx, sy = cx, cy
                cur["p0"] = (sx, sy)
            cmd = "l" if rel else "L"
        if cur.get("closed"):  # drawing after Z starts a new subpath
            res.append(cur)
            cur = {"start": off, "closed": False, "p0": (sx, sy)}
        cur["p1"] = (cx, cy)
        cur["end"] = end
    if cur:
        res.append(cur)
    return res


def close_subpaths(d):
    """d with a Z after every subpath that has none. mdi icons are filled,
    and SVG fills an open subpath as if a closepath followed it (SVG 1.1,
    11.3 "Fill properties"), so the explicit Z changes no filled pixel; it
    makes each contour closed for a reader that takes only Z as closed."""
    out, pos, sps = [], 0, subpaths(d)
    for sp in sps:
        out.append(d[pos:sp["end"]])
        pos = sp["end"]
        if not sp["closed"]:
            out.append("Z")
    out.append(d[pos:])
    return "".join(out), len(sps)


def mdi_folder(arg, tmp):
    if arg:
        return arg
    subprocess.run(["npm", "install", "--no-audit", "--no-fund",
                    "--ignore-scripts", "--prefix", tmp,
                    "@mdi/svg@" + MDI_VERSION], check=True,
                   stdout=subprocess.DEVNULL)
    return os.path.join(tmp, "node_modules", "@mdi", "svg")


def icons(folder):
    with open(os.path.join(folder, "package.json")) as f:
        pkg = json.load(f)
    if pkg["version"] != MDI_VERSION:
        sys.exit("@mdi/svg %s found, %s pinned" % (pkg["version"],
                                                   MDI_VERSION))
    out = []
    for kind, names in ICONS.items():
        for name in names:
            with open(os.path.join(folder, "svg", name + ".svg")) as f:
                svg = f.read()
            ds = re.findall(r'<path d="([^"]*)"', svg)
            vb = re.search(r'viewBox="([^"]*)"', svg).group(1)
            if len(ds) != 1:
                sys.exit(name + ": expected one path element")
            d, n = close_subpaths(ds[0])
            if not 2 <= n <= 6:
                sys.exit("%s: %d subpaths, not 2 to 6" % (name, n))
            out.append({"id": "mdi/" + name, "icon": name, "kind": kind,
                        "viewBox": [float(v) for v in vb.split()],
                        "d": d, "d_source": ds[0], "subpaths": n})
    return out


def pairs(gl, ic):
    count = {g["id"]: g["contours"] for g in gl}
    count.update({i["id"]: i["subpaths"] for i in ic})
    res = []
    for kind, table in (("glyph", GLYPH_PAIRS), ("icon", ICON_PAIRS)):
        for a, b, why in table:
            res.append({"kind": kind, "from": a, "to": b, "why": why,
                        "counts": [count[a], count[b]]})
    return res


def write(path, obj):
    with open(path, "w") as f:
        json.dump(obj, f, indent=1, ensure_ascii=False)
        f.write("\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default=os.path.join(
        os.path.dirname(os.path.abspath(__file__)), "..", "tests",
        "fixtures", "compound"))
    ap.add_argument("--mdi", help="existing node_modules/@mdi/svg folder")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    gl = glyphs()
    with tempfile.TemporaryDirectory() as tmp:
        ic = icons(mdi_folder(args.mdi, tmp))
    write(os.path.join(args.out, "glyphs.json"), {
        "about": "Glyph outlines as SVG path data: font units times 100 / "
                 "unitsPerEm, y down, the advance box centred across the "
                 "100-unit em and the vertical extent of the font's glyphs "
                 "here centred down it (baseline at y = baseline). "
                 "TrueType glyphs are M/L/Q exactly as stored (implied "
                 "on-curve midpoints written out), CFF glyphs M/L/C. "
                 "contours counts the closed subpaths. Fill rule nonzero.",
        "license": "DejaVu fonts: Bitstream Vera / DejaVu license; "
                   "Liberation fonts: SIL Open Font License 1.1. "
                   "See README.md.",
        "glyphs": gl})
    write(os.path.join(args.out, "icons.json"), {
        "about": "@mdi/svg " + MDI_VERSION + " icons, 24-unit viewBox, y "
                 "down, fill rule nonzero. d_source is the path as "
                 "shipped; d is the same path with a Z after each subpath "
                 "without one, which SVG's fill implies.",
        "license": "Apache-2.0 (Pictogrammers, Material Design Icons)",
        "icons": ic})
    write(os.path.join(args.out, "pairs.json"), {
        "about": "Morph pairs by id (glyphs.json, icons.json); counts are "
                 "the contour counts of from and to.",
        "pairs": pairs(gl, ic)})
    print("%d glyphs, %d icons, %d pairs" % (
        len(gl), len(ic), len(GLYPH_PAIRS) + len(ICON_PAIRS)))


if __name__ == "__main__":
    main()
