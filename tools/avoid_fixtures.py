#!/usr/bin/python3
"""avoid_fixtures.py: writes tests/fixtures/avoid/glyphs.json, single-contour
glyphs whose morphs tend to cross themselves (2, 5, U, S, Z, N, 7, C) in the
Debian DejaVu and Liberation fonts, and the pairs the intersection tests
morph.

Outlines are read as tools/compound_fixtures.py reads them (its Frame and
TrueType contour reader, so coordinates are the font's exact rationals on
the 100-unit em, y down). Run it with Debian's python3-fonttools:

  /usr/bin/python3 tools/avoid_fixtures.py [--out DIR]
"""

import argparse
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import compound_fixtures as cf  # noqa: E402
from fontTools.ttLib import TTFont  # noqa: E402

FONTS = cf.FONTS + [
    ("dejavu-sans-bold", "DejaVu Sans Bold",
     "/usr/share/fonts/truetype/dejavu/DejaVuSans-Bold.ttf",
     "fonts-dejavu-core"),
    ("liberation-sans-bold", "Liberation Sans Bold",
     "/usr/share/fonts/truetype/liberation2/LiberationSans-Bold.ttf",
     "fonts-liberation2"),
]

# Letters of one contour each, in every font above.
GLYPHS = "25USZN7C"

# (from glyph, to glyph): morphed in every font.
PAIRS = [("2", "5"), ("U", "S"), ("S", "2"), ("5", "S"), ("Z", "S"),
         ("N", "U"), ("7", "2"), ("C", "S")]


def glyphs():
    out = []
    for fid, label, path, pkg in FONTS:
        font = TTFont(path)
        cmap = font.getBestCmap()
        gset = font.getGlyphSet()
        names = [cmap[ord(ch)] for ch in GLYPHS]
        ext = cf.band(gset, names)
        for ch in GLYPHS:
            gname = cmap[ord(ch)]
            adv = font["hmtx"][gname][0]
            frame = cf.Frame(font, adv, ext)
            cs = cf.glyf_path(font, gname, frame)
            if len(cs) != 1:
                sys.exit("%s/%s: %d contours, not one" % (fid, ch, len(cs)))
            out.append({"id": fid + "/" + ch, "font": label, "glyph": ch,
                        "package": pkg,
                        "font_version": font["name"].getDebugName(5),
                        "d": cs[0]})
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default=os.path.join(
        os.path.dirname(os.path.abspath(__file__)), "..", "tests",
        "fixtures", "avoid"))
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    gl = glyphs()
    pairs = [{"from": fid + "/" + a, "to": fid + "/" + b}
             for fid, _, _, _ in FONTS for a, b in PAIRS]
    cf.write(os.path.join(args.out, "glyphs.json"), {
        "about": "Single-contour glyph outlines as SVG path data (font "
                 "units times 100 / unitsPerEm, y down, as in "
                 "../compound/glyphs.json) and the pairs morphed by the "
                 "intersection tests.",
        "license": "DejaVu fonts: Bitstream Vera / DejaVu license; "
                   "Liberation fonts: SIL Open Font License 1.1.",
        "glyphs": gl, "pairs": pairs})
    print("%d glyphs, %d pairs" % (len(gl), len(pairs)))


if __name__ == "__main__":
    main()
