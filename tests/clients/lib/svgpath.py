"""svgpath.py - SVG path data sampled and compared for the client tests,
written from the SVG 1.1 specification and independent of the clients
and the service: the subpaths of a d string as dense polylines, and the
Hausdorff distance between two of them. Standard library only."""
import math
import re


def subpaths(d, per=48):
    """The subpaths of SVG path data as dense polylines (SVG 1.1 section
    8.3: M L H V C S Q T A Z, absolute and relative; arcs by the endpoint
    to centre conversion of implementation note F.6.5)."""
    tokens = re.findall(r"[MmLlHhVvCcSsQqTtAaZz]|[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?", d)
    out, cur = [], None
    i, cmd = 0, None
    x = y = sx = sy = 0.0
    last_c = last_q = None

    def num():
        nonlocal i
        i += 1
        return float(tokens[i - 1])

    def bez(ctrl):
        for k in range(1, per + 1):
            t = k / per
            pts = [tuple(p) for p in ctrl]
            while len(pts) > 1:
                pts = [(a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])) for a, b in zip(pts, pts[1:])]
            cur.append(pts[0])

    def arc(rx, ry, phi_deg, large, sweep, x2, y2):
        if rx == 0 or ry == 0:
            cur.append((x2, y2))
            return
        rx, ry = abs(rx), abs(ry)
        phi = math.radians(phi_deg)
        c, s = math.cos(phi), math.sin(phi)
        dx, dy = (x - x2) / 2, (y - y2) / 2
        x1p, y1p = c * dx + s * dy, -s * dx + c * dy
        lam = x1p ** 2 / rx ** 2 + y1p ** 2 / ry ** 2
        if lam > 1:
            rx, ry = rx * math.sqrt(lam), ry * math.sqrt(lam)
        num2 = rx * rx * ry * ry - rx * rx * y1p * y1p - ry * ry * x1p * x1p
        f = math.sqrt(max(0.0, num2 / (rx * rx * y1p * y1p + ry * ry * x1p * x1p)))
        if large == sweep:
            f = -f
        cxp, cyp = f * rx * y1p / ry, -f * ry * x1p / rx
        cx, cy = c * cxp - s * cyp + (x + x2) / 2, s * cxp + c * cyp + (y + y2) / 2

        def ang(ux, uy, vx, vy):
            return math.atan2(ux * vy - uy * vx, ux * vx + uy * vy)
        t1 = ang(1, 0, (x1p - cxp) / rx, (y1p - cyp) / ry)
        dt = ang((x1p - cxp) / rx, (y1p - cyp) / ry, (-x1p - cxp) / rx, (-y1p - cyp) / ry)
        if not sweep and dt > 0:
            dt -= 2 * math.pi
        if sweep and dt < 0:
            dt += 2 * math.pi
        n = max(4, math.ceil(abs(dt) / (2 * math.pi) * 4 * per))
        for k in range(1, n + 1):
            a = t1 + dt * k / n
            cur.append((cx + rx * math.cos(a) * c - ry * math.sin(a) * s,
                        cy + rx * math.cos(a) * s + ry * math.sin(a) * c))

    while i < len(tokens):
        if tokens[i].isalpha():
            cmd = tokens[i]
            i += 1
        rel = cmd.islower()
        ox, oy = (x, y) if rel else (0.0, 0.0)
        u = cmd.upper()
        if u == "M":
            x, y = ox + num(), oy + num()
            sx, sy = x, y
            cur = [(x, y)]
            out.append(cur)
            cmd = "l" if rel else "L"
            last_c = last_q = None
        elif u == "Z":
            x, y = sx, sy
            cur.append((x, y))
            cur = [(x, y)]
            out.append(cur)
            last_c = last_q = None
        elif u in "LHV":
            nx = ox + num() if u != "V" else x
            ny = oy + num() if u == "L" else ((y if rel else 0.0) + num() if u == "V" else y)
            bez([(x, y), (nx, ny)])
            x, y = nx, ny
            last_c = last_q = None
        elif u in "CS":
            if u == "C":
                c1 = (ox + num(), oy + num())
            else:
                c1 = (2 * x - last_c[0], 2 * y - last_c[1]) if last_c else (x, y)
            c2 = (ox + num(), oy + num())
            e = (ox + num(), oy + num())
            bez([(x, y), c1, c2, e])
            last_c, last_q = c2, None
            x, y = e
        elif u in "QT":
            if u == "Q":
                c1 = (ox + num(), oy + num())
            else:
                c1 = (2 * x - last_q[0], 2 * y - last_q[1]) if last_q else (x, y)
            e = (ox + num(), oy + num())
            bez([(x, y), c1, e])
            last_q, last_c = c1, None
            x, y = e
        elif u == "A":
            rx, ry, phi, large, sweep = num(), num(), num(), num() != 0, num() != 0
            nx, ny = ox + num(), oy + num()
            arc(rx, ry, phi, large, sweep, nx, ny)
            x, y = nx, ny
            last_c = last_q = None
        else:
            raise ValueError("path command %s" % cmd)
    return [p for p in out if len(p) > 1]


class Polyline:
    """A dense polyline with its segments in a grid of cells, so that the
    distance from a point is found among the segments near it."""

    def __init__(self, pts, cell):
        self.pts, self.cell, self.grid = pts, cell, {}
        for k in range(1, len(pts)):
            (ax, ay), (bx, by) = pts[k - 1], pts[k]
            for gx in range(int(math.floor(min(ax, bx) / cell)), int(math.floor(max(ax, bx) / cell)) + 1):
                for gy in range(int(math.floor(min(ay, by) / cell)), int(math.floor(max(ay, by) / cell)) + 1):
                    self.grid.setdefault((gx, gy), []).append(k)

    def distance(self, q, reach):
        """Distance from q, or infinity if no segment is within reach."""
        best = math.inf
        c = self.cell
        seen = set()
        for gx in range(int(math.floor((q[0] - reach) / c)), int(math.floor((q[0] + reach) / c)) + 1):
            for gy in range(int(math.floor((q[1] - reach) / c)), int(math.floor((q[1] + reach) / c)) + 1):
                for k in self.grid.get((gx, gy), ()):
                    if k in seen:
                        continue
                    seen.add(k)
                    (ax, ay), (bx, by) = self.pts[k - 1], self.pts[k]
                    vx, vy = bx - ax, by - ay
                    l2 = vx * vx + vy * vy
                    u = min(1.0, max(0.0, ((q[0] - ax) * vx + (q[1] - ay) * vy) / l2)) if l2 > 0 else 0.0
                    best = min(best, math.hypot(ax + u * vx - q[0], ay + u * vy - q[1]))
        return best if best <= reach else math.inf


def hausdorff(p, q, reach):
    """Symmetric Hausdorff distance of two dense polylines, infinity when
    it exceeds reach (every third point queried against every segment)."""
    xs = [pt[0] for pt in p + q]
    ys = [pt[1] for pt in p + q]
    # Cells no smaller than 1/256 of the extent, so that a tight reach does
    # not make a grid of more cells than segments.
    cell = max(reach, (max(xs) - min(xs) + max(ys) - min(ys)) / 512, 1e-12)
    a, b = Polyline(p, cell), Polyline(q, cell)
    h = 0.0
    for pt in p[::3]:
        h = max(h, b.distance(pt, reach))
    for pt in q[::3]:
        h = max(h, a.distance(pt, reach))
    return h


def poly_length(p):
    return sum(math.dist(a, b) for a, b in zip(p, p[1:]))
