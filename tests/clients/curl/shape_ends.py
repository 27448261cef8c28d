"""shape_ends.py - check what `km-morph -p` printed for a morph of two
compound shapes: FROM_D and TO_D are the inputs' path data, LINES the
"t<TAB>d" lines, PAIRING the "contours: ..." line from stderr.

  python3 shape_ends.py FROM_D TO_D LINES PAIRING BOUND [FRAMES]

Checks, with the inputs parsed and sampled by tests/clients/lib/svgpath.py
(not by the clients nor the service): the pairing is an assignment (every
contour of either side exactly once); the first line is at t = 0 and its
subpaths are, in slot order, the `from` contours of the slots that have
one, each within BOUND of it (Hausdorff distance); the last line likewise
at t = 1 for `to`; every line has one subpath per present contour (FRAMES
lines when given). Prints the largest distance; exits 1 on a failure."""
import os
import re
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
from svgpath import subpaths, hausdorff  # noqa: E402


def pairing(line):
    """[(from, to)] from 'contours: from 0 -> to 1, from 1 vanishes, to 2 appears'."""
    body = line.split("contours:", 1)[1]
    out = []
    for part in body.split(","):
        part = part.strip()
        m = re.fullmatch(r"from (\d+) -> to (\d+)", part)
        if m:
            out.append((int(m.group(1)), int(m.group(2))))
            continue
        m = re.fullmatch(r"from (\d+) vanishes", part)
        if m:
            out.append((int(m.group(1)), None))
            continue
        m = re.fullmatch(r"to (\d+) appears", part)
        if not m:
            raise SystemExit("not a pair: %r" % part)
        out.append((None, int(m.group(1))))
    return out


def main(from_d, to_d, lines_file, pairing_line, bound, frames=None):
    bound = float(bound)
    inputs = (subpaths(from_d), subpaths(to_d))
    pairs = pairing(pairing_line)
    for side, n in ((0, len(inputs[0])), (1, len(inputs[1]))):
        seen = sorted(p[side] for p in pairs if p[side] is not None)
        if seen != list(range(n)):
            raise SystemExit("side %d: contours %s in the pairing, want each of 0..%d once" % (side, seen, n - 1))
    with open(lines_file, encoding="utf-8") as f:
        lines = [ln.rstrip("\n").split("\t") for ln in f if ln.strip()]
    if frames is not None and len(lines) != int(frames):
        raise SystemExit("%d lines, want %s" % (len(lines), frames))
    if float(lines[0][0]) != 0 or float(lines[-1][0]) != 1:
        raise SystemExit("the lines run from t = %s to %s" % (lines[0][0], lines[-1][0]))
    for t, d in lines:
        n = len(subpaths(d, 2))
        inner = 0 < float(t) < 1
        want = len(pairs) if inner else sum(p[0 if float(t) == 0 else 1] is not None for p in pairs)
        if n != want:
            raise SystemExit("t = %s: %d subpaths, want %d" % (t, n, want))
    worst = 0.0
    for side, (t, d) in ((0, lines[0]), (1, lines[-1])):
        got = subpaths(d, 16)
        wanted = [p[side] for p in pairs if p[side] is not None]
        for k, c in enumerate(wanted):
            h = hausdorff(got[k], inputs[side][c], 4 * bound)
            if h > bound:
                raise SystemExit("t = %s: subpath %d (contour %d) is %g from the input, bound %g" % (t, k, c, h, bound))
            worst = max(worst, h)
    print("ends within %.3g" % worst)


if __name__ == "__main__":
    main(*sys.argv[1:])
