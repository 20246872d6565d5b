#!/usr/bin/env python3
"""Where an extraction's false length lies: in the reference's holes or off the curb.

Usage: scripts/false_length.py REFERENCE WHOLE_TOES EXTRACTED [EVAL_JSON] [--row NAME]

REFERENCE is the simulator's reference.geojson, WHOLE_TOES the same street's every toe line
(`curbtrace simulate ... --whole-toes FILE`), EXTRACTED the edges of `curbtrace extract`.
The extracted toe lines are sampled every 20 mm; a sample farther than the buffer (50 mm)
from every reference toe is false length, and is put in a class by its distance to the
nearest whole toe line:

- hole: within the buffer of a toe line the reference left out (the simulator keeps a toe
  only where returns lie within 0.15 m of it on both sides, docs/simulator.md);
- 0.05-0.10, 0.10-0.20, 0.20-0.50, 0.50-2.0 m, then road or walk: which side of that toe;
- off: farther than 2 m from every toe line.

Each class is reported per side (the extracted line's) and per category (the nearest
toe's). With EVAL_JSON (`curbtrace eval --json`, same buffer), the quality is also given
with the hole length not counted as false: TP / (TP + FP - hole + FN). --row NAME prints
one summary line instead of the table.
"""
import collections
import json
import math
import sys

BUFFER_M = 0.05
STEP_M = 0.02
REACH_M = 2.0


def toe_lines(path):
    """(side, category, [(x, y)]) of every toe line in a GeoJSON file."""
    out = []
    for f in json.load(open(path))["features"]:
        p = f["properties"]
        if p.get("line") == "toe":
            out.append((p["side"], p.get("category"), [tuple(c[:2]) for c in f["geometry"]["coordinates"]]))
    return out


class Segments:
    """The lines' segments in 1 m cells, for the nearest one within REACH_M."""

    def __init__(self, lines, cell=1.0):
        self.cell, self.cells, self.segs = cell, collections.defaultdict(list), []
        for side, cat, pts in lines:
            for a, b in zip(pts, pts[1:]):
                k = len(self.segs)
                self.segs.append((a, b, side, cat))
                for i in range(self._c(min(a[0], b[0])), self._c(max(a[0], b[0])) + 1):
                    for j in range(self._c(min(a[1], b[1])), self._c(max(a[1], b[1])) + 1):
                        self.cells[(i, j)].append(k)

    def _c(self, v):
        return int(math.floor(v / self.cell))

    def nearest(self, p):
        """(distance, segment, signed distance: + on the left of the toe's direction, the
        sidewalk's side in the simulator) of the nearest segment within REACH_M."""
        best = (math.inf, None, 0.0)
        r = int(math.ceil(REACH_M / self.cell))
        ci, cj = self._c(p[0]), self._c(p[1])
        seen = set()
        for i in range(ci - r, ci + r + 1):
            for j in range(cj - r, cj + r + 1):
                for k in self.cells.get((i, j), ()):
                    if k in seen:
                        continue
                    seen.add(k)
                    a, b = self.segs[k][:2]
                    dx, dy = b[0] - a[0], b[1] - a[1]
                    l2 = dx * dx + dy * dy
                    t = 0.0 if l2 == 0 else max(0.0, min(1.0, ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / l2))
                    d = math.hypot(p[0] - a[0] - t * dx, p[1] - a[1] - t * dy)
                    if d < best[0]:
                        cross = dx * (p[1] - a[1]) - dy * (p[0] - a[0])
                        best = (d, self.segs[k], math.copysign(d, cross))
        return best


def classes(reference, whole, extracted):
    """Metres of false length per (side, category, class)."""
    ref, toes = Segments(toe_lines(reference)), Segments(toe_lines(whole))
    out = collections.Counter()
    for side, _, pts in toe_lines(extracted):
        for a, b in zip(pts, pts[1:]):
            length = math.hypot(b[0] - a[0], b[1] - a[1])
            n = max(1, round(length / STEP_M))
            for k in range(n):
                f = (k + 0.5) / n
                p = (a[0] + (b[0] - a[0]) * f, a[1] + (b[1] - a[1]) * f)
                if ref.nearest(p)[0] <= BUFFER_M:
                    continue
                d, seg, signed = toes.nearest(p)
                if seg is None or d > REACH_M:
                    cls, cat = "off", "-"
                else:
                    cat = seg[3]
                    if d <= BUFFER_M:
                        cls = "hole"
                    else:
                        edges = [0.10, 0.20, 0.50, REACH_M]
                        lo = [BUFFER_M] + edges
                        i = next(i for i, e in enumerate(edges) if d <= e)
                        cls = f"{lo[i]:.2f}-{edges[i]:.2f} {'road' if signed < 0 else 'walk'}"
                out[(side, cat, cls)] += length / n
    return out


def main(argv):
    row = None
    if "--row" in argv:
        i = argv.index("--row")
        row = argv[i + 1]
        argv = argv[:i] + argv[i + 2 :]
    if len(argv) not in (3, 4):
        sys.exit(__doc__.strip().splitlines()[2])
    found = classes(*argv[:3])
    hole = sum(m for (_, _, c), m in found.items() if c == "hole")
    total = sum(found.values())
    by_side = collections.Counter()
    for (side, _, c), m in found.items():
        by_side[(side, c == "hole")] += m
    q = q_adj = None
    if len(argv) == 4:
        t = json.load(open(argv[3]))["total"]
        q = t["quality_pct"]
        q_adj = 100.0 * t["tp_m"] / (t["tp_m"] + max(0.0, t["fp_m"] - hole) + t["fn_m"])
    if row is not None:
        sides = " ".join(
            f"{s} {by_side[(s, True)]:.1f}/{by_side[(s, False)]:.1f}" for s in ("left", "right")
        )
        qs = f" Q {q:.1f} -> {q_adj:.1f}" if q is not None else ""
        print(f"{row} false {total:.1f} m, in holes {hole:.1f} m ({sides} hole/other){qs}")
        return
    for (side, cat, cls), m in sorted(found.items()):
        print(f"{side:6s} {cat:13s} {cls:16s} {m:7.2f} m")
    print(f"false length {total:.2f} m, of it in the reference's holes {hole:.2f} m")
    if q is not None:
        print(f"quality {q:.1f} %, {q_adj:.1f} % with the holes' length not counted as false")


if __name__ == "__main__":
    main(sys.argv[1:])
