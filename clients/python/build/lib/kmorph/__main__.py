"""python3 -m kmorph - the kmorph service from the command line.

Subcommands: signature, reconstruct, morph, job, status, cancel, health.
Curves are SVG path d strings ("M 0 0 L 10 0"; several subpaths make a
compound shape), JSON curve objects (a shape among them), or @FILE / @-
holding either, or an SVG document whose <path> elements together are
the shape, each subpath closed as SVG fills it, under the document's
fill rule (a file with a signature becomes a signature curve). Errors
print the service's problem detail on stderr and exit 1; usage errors
exit 2.
"""
import argparse
import json
import sys
import xml.etree.ElementTree as ET

from . import (__version__, Client, JobCancelled, KmorphError, DEFAULT_URL, contour_pairs, frame_path, is_compound,
               path_contours, shape)


def _read_arg(text):
    if text == "@-":
        return sys.stdin.read()
    if text.startswith("@"):
        try:
            with open(text[1:], encoding="utf-8") as f:
                return f.read()
        except OSError as e:
            raise SystemExit(_usage_error("cannot read %s: %s" % (text[1:], e.strerror)))
    return text


def _usage_error(msg):
    print("kmorph: " + msg, file=sys.stderr)
    return 2


def curve_arg(text):
    """A curve object from a command-line argument."""
    text = _read_arg(text)
    s = text.strip()
    if s.startswith("{"):
        try:
            obj = json.loads(s)
        except ValueError as e:
            raise SystemExit(_usage_error("not JSON: %s" % e))
        if "type" in obj:
            return obj
        if "signature" in obj:
            return {"type": "signature", "signature": obj["signature"]}
        if "kappa" in obj:
            return {"type": "signature", "signature": obj}
        if "control_points" in obj:
            return dict(obj, type="bspline")
        raise SystemExit(_usage_error("not a curve: expected type, signature, kappa or control_points"))
    if s[:1] in ("M", "m"):
        return {"type": "svg", "d": s}
    if s.startswith("<"):
        return _svg_document_curve(s)
    raise SystemExit(_usage_error("not an SVG path (must start with M), SVG document nor JSON: %.60s" % s))


def _fill_rule_of(el, inherited):
    rule = el.get("fill-rule")
    for decl in (el.get("style") or "").split(";"):
        key, _, value = decl.partition(":")
        if key.strip() == "fill-rule":
            rule = value.strip()
    return rule if rule in ("nonzero", "evenodd") else inherited


def _svg_document_curve(text):
    """The curve of an SVG document: the contours of all its <path>
    elements, closed (as SVG fills them), as one shape under their fill
    rule (inherited as in SVG). Transforms and other elements are not
    applied."""
    try:
        root = ET.fromstring(text)
    except ET.ParseError as e:
        raise SystemExit(_usage_error("not a well-formed SVG document: %s" % e))
    found = []

    def walk(el, rule):
        rule = _fill_rule_of(el, rule)
        if el.tag.rsplit("}", 1)[-1] == "path" and (el.get("d") or "").strip():
            found.append((el.get("d"), rule))
        for child in el:
            walk(child, rule)
    walk(root, "nonzero")
    if not found:
        raise SystemExit(_usage_error("the SVG document has no <path> with a d attribute"))
    rules = sorted({r for _, r in found})
    if len(rules) > 1:
        raise SystemExit(_usage_error("the SVG document's <path>s have different fill rules"))
    try:
        contours = [c for d, _ in found for c in path_contours(d)]
    except ValueError as e:
        raise SystemExit(_usage_error("in the SVG document: %s" % e))
    if not contours:
        raise SystemExit(_usage_error("the SVG document's paths draw nothing"))
    if len(contours) == 1:
        return {"type": "svg", "d": contours[0]}
    if rules[0] == "evenodd":
        return shape(contours, fill_rule="evenodd")
    return {"type": "svg", "d": " ".join(contours)}


def _morph_request(a):
    req = {}
    if a.request:
        try:
            req = json.loads(_read_arg("@" + a.request))
        except ValueError as e:
            raise SystemExit(_usage_error("the -r request is not JSON: %s" % e))
    if a.curves:
        if len(a.curves) != 2:
            raise SystemExit(_usage_error("give two curves, FROM and TO"))
        req["from"], req["to"] = curve_arg(a.curves[0]), curve_arg(a.curves[1])
    if "from" not in req or "to" not in req:
        raise SystemExit(_usage_error("FROM and TO curves are needed"))
    if a.frames is not None:
        req["frames"] = a.frames
        req.pop("times", None)
    if a.times is not None:
        req["times"] = [float(x) for x in a.times.split(",")]
        req.pop("frames", None)
    for key in ("method", "blend", "closure", "anchor", "orient", "tolerance", "degree"):
        if getattr(a, key) is not None:
            req[key] = getattr(a, key)
    if a.matches is not None:
        req["matches"] = "auto" if a.matches == "auto" else _json_arg(a.matches, "-M")
    if a.contour_matches is not None:
        req["contour_matches"] = _json_arg(a.contour_matches, "-C")
    if a.paths:
        req["include"] = sorted(set(req.get("include", []) + ["svg_d"]))
    if a.metrics:
        req["metrics"] = True
    if a.svg_d:
        req["include"] = sorted(set(req.get("include", []) + ["svg_d"]))
    if a.paths and a.layout:
        raise SystemExit(_usage_error("-p prints path data lines; it cannot be combined with -l"))
    layout = a.layout or ("filmstrip" if a.output and a.output.endswith(".svg") and not a.paths else None)
    if layout:
        req["format"] = "svg"
        req.setdefault("svg", {})["layout"] = layout
    return req


def _json_arg(text, option):
    try:
        return json.loads(text)
    except ValueError as e:
        raise SystemExit(_usage_error("%s needs JSON: %s" % (option, e)))


def _pairing_line(result):
    """'from 0 -> to 1, from 1 vanishes, appears as to 2' for a compound
    morph's contour_matches_used."""
    parts = []
    for _, i, j in contour_pairs(result):
        if i is None:
            parts.append("to %d appears" % j)
        elif j is None:
            parts.append("from %d vanishes" % i)
        else:
            parts.append("from %d -> to %d" % (i, j))
    return ", ".join(parts)


def _emit_morph(answer, a):
    """A morph answer as asked: with -p one line per frame (t, a tab, the
    frame's whole path data) and, for shapes, the pairing on stderr."""
    if not a.paths or isinstance(answer, str):
        return _emit(answer, a.output)
    if is_compound(answer):
        print("kmorph: contours: " + _pairing_line(answer), file=sys.stderr)
    _emit("".join("%r\t%s\n" % (f["t"], frame_path(f)) for f in answer["frames"]), a.output)


def _emit(answer, output):
    text = answer if isinstance(answer, str) else json.dumps(answer, indent=1)
    if output:
        with open(output, "w", encoding="utf-8") as f:
            f.write(text)
        print("kmorph: wrote %s (%d bytes)" % (output, len(text.encode())), file=sys.stderr)
    else:
        sys.stdout.write(text if text.endswith("\n") else text + "\n")


def _morph_options(p):
    p.add_argument("curves", nargs="*", metavar="CURVE", help="FROM and TO")
    p.add_argument("-n", "--frames", type=int, help="evenly spaced frames (default 11)")
    p.add_argument("-T", "--times", help="explicit times, comma-separated: 0,0.25,1")
    p.add_argument("-m", "--method", choices=["curvature", "linear"])
    p.add_argument("-b", "--blend", choices=["turning", "paper"])
    p.add_argument("-M", "--matches", help='"auto" or pairs as JSON: [[0.2,0.3]]')
    p.add_argument("-C", "--contour-matches",
                   help="shapes: pairs of contour indices as JSON, null for none: [[0,0],[1,null]]")
    p.add_argument("-c", "--closure", choices=["auto", "lsq", "c0", "c1", "g2", "none"])
    p.add_argument("-a", "--anchor", choices=["fit", "start", "centroid"])
    p.add_argument("-O", "--orient", choices=["auto", "keep"])
    p.add_argument("-t", "--tolerance", type=float)
    p.add_argument("-g", "--degree", type=int, choices=[3, 5])
    p.add_argument("-k", "--metrics", action="store_true", help="per-frame metrics")
    p.add_argument("-d", "--svg-d", action="store_true", help="include svg_d in each frame")
    p.add_argument("-p", "--paths", action="store_true",
                   help="print one line per frame: t, a tab, its path data (shapes: the pairing on stderr)")
    p.add_argument("-l", "--layout", choices=["filmstrip", "overlay", "animate", "curvature_plot"],
                   help="answer in SVG with this layout")
    p.add_argument("-o", "--output", help="write to this file (FILE.svg asks for SVG)")
    p.add_argument("-r", "--request", help="start from the morph request in this JSON file")


def main(argv=None):
    ap = argparse.ArgumentParser(prog="python3 -m kmorph",
                                 description="Morph planar curves with a kmorph service.")
    ap.add_argument("-V", "--version", action="version", version="kmorph " + __version__)
    ap.add_argument("-u", "--url", help="the service (default $KMORPH_URL or %s)" % DEFAULT_URL)
    sub = ap.add_subparsers(dest="cmd", required=True)
    p = sub.add_parser("signature", help="curvature signature of a curve")
    p.add_argument("curve")
    p.add_argument("-t", "--tolerance", type=float)
    p.add_argument("-s", "--samples", type=int, help="also N samples [s, kappa]")
    p.add_argument("-o", "--output")
    p = sub.add_parser("reconstruct", help="the curve of a signature")
    p.add_argument("signature", help="JSON signature or /v1/signature answer, @FILE or @-")
    p.add_argument("-t", "--tolerance", type=float)
    p.add_argument("-g", "--degree", type=int, choices=[3, 5])
    p.add_argument("-p", "--path", action="store_true", help="print only the SVG path d")
    p.add_argument("-o", "--output")
    _morph_options(sub.add_parser("morph", help="a morph, synchronously"))
    p = sub.add_parser("job", help="a morph as a job, with progress on stderr")
    _morph_options(p)
    p.add_argument("-q", "--quiet", action="store_true", help="no progress lines")
    p = sub.add_parser("status", help="state and progress of a job")
    p.add_argument("id")
    p = sub.add_parser("cancel", help="cancel (or forget) a job")
    p.add_argument("id")
    sub.add_parser("health", help="is the service alive and ready")
    a = ap.parse_args(argv)
    km = Client(a.url)
    try:
        if a.cmd == "signature":
            _emit(km.signature(curve_arg(a.curve), a.tolerance, a.samples), a.output)
        elif a.cmd == "reconstruct":
            text = _read_arg(a.signature)
            try:
                sig = json.loads(text)
            except ValueError as e:
                return _usage_error("the signature is not JSON: %s" % e)
            sig = sig.get("signature", sig)
            r = km.reconstruct(sig, a.tolerance, a.degree, ["svg_d"] if a.path else None)
            _emit(r["curve"]["svg_d"] if a.path else r, a.output)
        elif a.cmd == "morph":
            _emit_morph(km.morph(_morph_request(a)), a)
        elif a.cmd == "job":
            last = [None]

            def progress(s):
                line = "job %s %s %d%% (%d/%d frames)" % (
                    s["id"], s["state"], int(s["progress"] * 100), s["frames_done"], s["frames_total"])
                if not a.quiet and line != last[0]:
                    print("kmorph: " + line, file=sys.stderr, flush=True)
                    last[0] = line
            _emit_morph(km.morph_job(_morph_request(a), on_progress=progress), a)
        elif a.cmd == "status":
            _emit(km.job(a.id), None)
        elif a.cmd == "cancel":
            km.cancel_job(a.id)
            print("kmorph: job %s cancelled" % a.id, file=sys.stderr)
        elif a.cmd == "health":
            print("%s %s" % (km.health()["status"], km.ready()["status"]))
    except JobCancelled as e:
        print("kmorph: %s" % e, file=sys.stderr)
        return 1
    except KmorphError as e:
        print("kmorph: %s" % e, file=sys.stderr)
        for err in e.errors:
            print("  at %s: %s" % (err.get("pointer"), err.get("message")), file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("kmorph: interrupted", file=sys.stderr)
        return 130
    return 0


if __name__ == "__main__":
    sys.exit(main())
