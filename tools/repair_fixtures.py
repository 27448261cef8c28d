#!/usr/bin/python3
"""repair_fixtures.py: writes tests/fixtures/avoid/repair.json, single-contour
glyph pairs whose frames still crossed after the free choices of
intersections "avoid" (start point, matches): the cases the repair is for.

The pairs were found by morphing random pairs of one-contour letters of the
fonts below (41 frames each, about 1,200 pairs): 21 of them kept crossing
frames. Outlines are read as tools/compound_fixtures.py reads them (exact
rationals on the 100-unit em, y down). Run with Debian's python3-fonttools:

  /usr/bin/python3 tools/repair_fixtures.py [--out DIR]
"""

import argparse
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import compound_fixtures as cf  # noqa: E402
from fontTools.ttLib import TTFont  # noqa: E402

DEJAVU = "/usr/share/fonts/truetype/dejavu/"
LIBERATION = "/usr/share/fonts/truetype/liberation2/"
FONTS = {
    "dejavu-sans": (DEJAVU + "DejaVuSans.ttf", "fonts-dejavu-core"),
    "dejavu-serif": (DEJAVU + "DejaVuSerif.ttf", "fonts-dejavu-core"),
    "dejavu-sans-bold": (DEJAVU + "DejaVuSans-Bold.ttf", "fonts-dejavu-core"),
    "dejavu-sans-oblique": (DEJAVU + "DejaVuSans-Oblique.ttf",
                            "fonts-dejavu-core"),
    "dejavu-serif-italic": (DEJAVU + "DejaVuSerif-Italic.ttf",
                            "fonts-dejavu-extra"),
    "liberation-sans": (LIBERATION + "LiberationSans-Regular.ttf",
                        "fonts-liberation2"),
    "liberation-serif": (LIBERATION + "LiberationSerif-Regular.ttf",
                         "fonts-liberation2"),
}

# The letters whose outlines share a band per font (as the survey read
# them, so that sizes agree with it).
BAND = "12357CGJLMNSUVWZcfhlmnrsuvwyz"

PAIRS = [
    ("dejavu-serif-italic/y", "dejavu-sans/N"),
    ("dejavu-serif/W", "dejavu-sans-bold/y"),
    ("liberation-sans/m", "liberation-sans/V"),
    ("dejavu-sans-bold/M", "dejavu-sans-bold/m"),
    ("dejavu-sans-bold/w", "dejavu-sans-bold/m"),
    ("dejavu-serif-italic/S", "dejavu-sans-oblique/w"),
    ("dejavu-sans/m", "dejavu-sans/W"),
    ("dejavu-serif/G", "dejavu-sans-bold/r"),
    ("dejavu-serif/G", "liberation-serif/5"),
    ("dejavu-serif/G", "dejavu-serif/N"),
    ("dejavu-serif/G", "dejavu-serif/y"),
    ("liberation-sans/S", "liberation-sans/M"),
    ("dejavu-sans-oblique/7", "dejavu-serif/2"),
    ("dejavu-sans/G", "liberation-serif/h"),
    ("liberation-serif/m", "liberation-serif/M"),
    ("liberation-serif/h", "dejavu-serif-italic/W"),
    ("dejavu-sans/y", "dejavu-sans/3"),
    ("dejavu-serif/r", "dejavu-serif/S"),
    ("dejavu-sans/m", "liberation-serif/3"),
    ("dejavu-serif-italic/Z", "dejavu-serif-italic/y"),
    ("dejavu-serif/m", "dejavu-sans-bold/M"),
]


def outlines(ids):
    out, fonts = {}, {}
    for gid in sorted(ids):
        fid, ch = gid.split("/")
        path, pkg = FONTS[fid]
        if fid not in fonts:
            font = TTFont(path)
            cmap = font.getBestCmap()
            ext = cf.band(font.getGlyphSet(), [cmap[ord(c)] for c in BAND])
            fonts[fid] = (font, cmap, ext)
        font, cmap, ext = fonts[fid]
        gname = cmap[ord(ch)]
        frame = cf.Frame(font, font["hmtx"][gname][0], ext)
        cs = cf.glyf_path(font, gname, frame)
        if len(cs) != 1:
            sys.exit("%s: %d contours, not one" % (gid, len(cs)))
        out[gid] = {"id": gid, "package": pkg,
                    "font_version": font["name"].getDebugName(5),
                    "d": cs[0]}
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default=os.path.join(
        os.path.dirname(os.path.abspath(__file__)), "..", "tests",
        "fixtures", "avoid"))
    args = ap.parse_args()
    gl = outlines({g for p in PAIRS for g in p})
    cf.write(os.path.join(args.out, "repair.json"), {
        "about": "Single-contour glyph pairs whose frames still crossed "
                 "after the free choices of intersections avoid (41 "
                 "frames); outlines as SVG path data as in glyphs.json.",
        "license": "DejaVu fonts: Bitstream Vera / DejaVu license; "
                   "Liberation fonts: SIL Open Font License 1.1.",
        "glyphs": [gl[k] for k in sorted(gl)],
        "pairs": [{"from": a, "to": b} for a, b in PAIRS]})
    print("%d glyphs, %d pairs" % (len(gl), len(PAIRS)))


if __name__ == "__main__":
    main()
