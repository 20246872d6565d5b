#!/usr/bin/env python3
"""Where a spinning-sensor drive's loss lies: missed and false length by place.

Usage: scripts/ring_loss.py DIR EXTRACTED [--buffer 0.2] [--reference FILE] [--rate-hz 10]
       [--json OUT] [--runs]

DIR is a `curbtrace simulate --sensor ...` output (reference.geojson, trajectory.csv),
EXTRACTED the edges of `curbtrace extract`. Toe lines are sampled every 20 mm and placed
along the path (station s from the trajectory's start, negative behind it, beyond its length
L past its end) and across it.

A reference sample farther than the buffer from every extracted toe is missed; the missed
length is split by
- side: near or far (the side whose reference lies nearer the path, by the median offset);
- place along the path: behind the start (s < 0), beyond the end (s > L), or within;
- category (curb, curb_cut, intersection, ...);
- piece: shorter than G, the vehicle's largest advance in one revolution (a piece one ring
  crossing long), or longer;
- whether an extracted toe passes within 2 m (misplaced) or none does (absent).

An extracted sample farther than the buffer from every reference toe is false; it is
- on the toe's line, in a hole: within the buffer of the line through the nearest reference
  segment, between the first and last reference station of that side;
- on the toe's line, beyond the ends: the same, outside that station range;
- off the toe: farther across than the buffer (by the nearest reference's category);
  unattributed where no reference toe lies within 30 m.

The matching is `curbtrace eval`'s (nearest line of any side); lengths agree with its FN and
FP within a few centimetres. --runs lists the missed stretches one by one.
"""
import argparse
import csv
import json
import math

STEP_M = 0.02
REACH_M = 2.0
CELL_M = 1.0


def toe_lines(path):
    """(points, properties) of every toe line of a GeoJSON file."""
    out = []
    for f in json.load(open(path))["features"]:
        p = f["properties"]
        if p.get("line", "toe") != "toe":
            continue
        g = f["geometry"]
        parts = [g["coordinates"]] if g["type"] == "LineString" else g["coordinates"]
        for c in parts:
            out.append(([(q[0], q[1]) for q in c], p))
    return out


def sample(pts, step):
    """Midpoints of equal pieces no longer than `step`, and the piece length."""
    seg = [math.dist(a, b) for a, b in zip(pts, pts[1:])]
    total = sum(seg)
    if total <= 0:
        return [], 0.0
    n = max(1, math.ceil(total / step - 1e-9))
    w = total / n
    out, k, start = [], 0, 0.0
    for i in range(n):
        s = (i + 0.5) * w
        while k + 1 < len(seg) and start + seg[k] < s:
            start += seg[k]
            k += 1
        t = (s - start) / seg[k] if seg[k] > 0 else 0.0
        t = min(max(t, 0.0), 1.0)
        a, b = pts[k], pts[k + 1]
        out.append((a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])))
    return out, w


class Segments:
    """Segments in a grid of CELL_M cells, for the nearest segment within a reach."""

    def __init__(self, lines):
        self.segs = []
        self.grid = {}
        for k, (pts, _) in enumerate(lines):
            for a, b in zip(pts, pts[1:]):
                if a == b:
                    continue
                j = len(self.segs)
                self.segs.append((a, b, k))
                for cx in range(math.floor(min(a[0], b[0]) / CELL_M), math.floor(max(a[0], b[0]) / CELL_M) + 1):
                    for cy in range(math.floor(min(a[1], b[1]) / CELL_M), math.floor(max(a[1], b[1]) / CELL_M) + 1):
                        self.grid.setdefault((cx, cy), []).append(j)

    def nearest(self, p, reach):
        """(distance, segment index, t along it) of the nearest segment within `reach`."""
        best = (math.inf, -1, 0.0)
        r = math.ceil(reach / CELL_M)
        cx, cy = math.floor(p[0] / CELL_M), math.floor(p[1] / CELL_M)
        seen = set()
        for dx in range(-r, r + 1):
            for dy in range(-r, r + 1):
                for j in self.grid.get((cx + dx, cy + dy), ()):
                    if j in seen:
                        continue
                    seen.add(j)
                    a, b, _ = self.segs[j]
                    vx, vy = b[0] - a[0], b[1] - a[1]
                    l2 = vx * vx + vy * vy
                    t = ((p[0] - a[0]) * vx + (p[1] - a[1]) * vy) / l2
                    tc = min(max(t, 0.0), 1.0)
                    d = math.hypot(p[0] - a[0] - tc * vx, p[1] - a[1] - tc * vy)
                    if d < best[0]:
                        best = (d, j, t)
        return best


class Path:
    """Station along and offset across the trajectory (left positive)."""

    def __init__(self, pts):
        self.seg = Segments([(pts, {})])
        self.cum = [0.0]
        for a, b in zip(pts, pts[1:]):
            self.cum.append(self.cum[-1] + math.dist(a, b))
        self.length = self.cum[-1]
        self.index = {}
        k = 0
        for a, b in zip(pts, pts[1:]):
            if a != b:
                self.index[len(self.index)] = k
            k += 1

    def place(self, p):
        for reach in (4.0, 30.0):
            d, j, t = self.seg.nearest(p, reach)
            if d <= reach:
                break
        if j < 0:
            return math.nan, math.nan
        a, b, _ = self.seg.segs[j]
        ln = math.dist(a, b)
        ux, uy = (b[0] - a[0]) / ln, (b[1] - a[1]) / ln
        s = self.cum[self.index[j]] + t * ln
        return s, ux * (p[1] - a[1]) - uy * (p[0] - a[0])


def read_trajectory(path):
    rows = []
    with open(path) as fh:
        for r in csv.DictReader(fh):
            rows.append((float(r["time"]), float(r["x"]), float(r["y"])))
    return rows


def advance_per_revolution(rows, rate_hz):
    best, j = 0.0, 0
    for t, x, y in rows:
        while j < len(rows) and rows[j][0] - t < 1.0 / rate_hz:
            j += 1
        if j == len(rows):
            break
        best = max(best, math.hypot(rows[j][1] - x, rows[j][2] - y))
    return best


def rounded(v):
    if isinstance(v, float):
        return round(v, 3)
    if isinstance(v, dict):
        return {k: rounded(x) for k, x in v.items()}
    return v


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("dir")
    ap.add_argument("extracted")
    ap.add_argument("--buffer", type=float, default=0.2)
    ap.add_argument("--reference", default=None)
    ap.add_argument("--rate-hz", type=float, default=10.0)
    ap.add_argument("--json")
    ap.add_argument("--runs", action="store_true")
    a = ap.parse_args()
    rows = read_trajectory(f"{a.dir}/trajectory.csv")
    x0, y0 = rows[0][1], rows[0][2]

    def local(lines):
        return [([(x - x0, y - y0) for x, y in pts], p) for pts, p in lines]

    ref = local(toe_lines(a.reference or f"{a.dir}/reference.geojson"))
    ext = local(toe_lines(a.extracted))
    path = Path([(x - x0, y - y0) for _, x, y in rows])
    gap = advance_per_revolution(rows, a.rate_hz)
    ref_seg, ext_seg = Segments(ref), Segments(ext)

    samples = []  # (line, side, category, piece length, distance, station, offset, weight)
    for k, (pts, p) in enumerate(ref):
        smp, w = sample(pts, STEP_M)
        piece = sum(math.dist(u, v) for u, v in zip(pts, pts[1:]))
        for q in smp:
            d = ext_seg.nearest(q, REACH_M)[0]
            s, off = path.place(q)
            samples.append((k, p["side"], p.get("category", "curb"), piece, d, s, off, w))
    med = {}
    for side in ("left", "right"):
        v = sorted(abs(r[6]) for r in samples if r[1] == side)
        med[side] = v[len(v) // 2] if v else math.inf
    near = min(med, key=med.get)
    L = path.length

    def where(s):
        return "behind_start" if s < 0 else ("beyond_end" if s > L else "within")

    out = {
        "reference_m": sum(r[7] for r in samples),
        "short_pieces_m": sum(r[7] for r in samples if r[3] < gap),
        "advance_per_revolution_m": gap,
        "path_m": L,
        "near_side": near,
        "missed": {},
        "false": {},
    }
    runs = []
    for r in samples:
        if r[4] <= a.buffer:
            continue
        m = out["missed"]
        for key in (
            "total",
            "near" if r[1] == near else "far",
            where(r[5]),
            r[2],
            "short_piece" if r[3] < gap else "long_piece",
            "misplaced" if r[4] <= REACH_M else "absent",
        ):
            m[key] = m.get(key, 0.0) + r[7]
        if runs and runs[-1][0] == r[0] and abs(r[5] - runs[-1][2]) < 0.1:
            runs[-1][2] = r[5]
            runs[-1][3] += r[7]
        else:
            runs.append([r[0], r[5], r[5], r[7], r[1], r[2], r[3], r[6]])
    ranges = {}
    for side in ("left", "right"):
        ss = [r[5] for r in samples if r[1] == side]
        ranges[side] = (min(ss), max(ss)) if ss else (0.0, 0.0)
    out["extracted_m"] = 0.0
    for pts, _ in ext:
        smp, w = sample(pts, STEP_M)
        out["extracted_m"] += w * len(smp)
        for q in smp:
            d, j, t = ref_seg.nearest(q, REACH_M)
            if d <= a.buffer:
                continue
            f = out["false"]
            if j < 0:
                # Farther than the eval's attribution reach: placed by the nearest toe all
                # the same.
                _, j, t = ref_seg.nearest(q, 30.0)
            if j < 0:
                kind = "off_unattributed"
            else:
                ra, rb, owner = ref_seg.segs[j]
                vx, vy = rb[0] - ra[0], rb[1] - ra[1]
                across = abs(vx * (q[1] - ra[1]) - vy * (q[0] - ra[0])) / math.hypot(vx, vy)
                props = ref[owner][1]
                if across <= a.buffer:
                    lo, hi = ranges[props["side"]]
                    s, _ = path.place(q)
                    kind = "toe_line_hole" if lo <= s <= hi else "toe_line_beyond_ends"
                else:
                    kind = "off_" + props.get("category", "curb")
            for key in ("total", kind):
                f[key] = f.get(key, 0.0) + w
    if a.runs:
        out["missed_runs"] = [
            f"{x[4]} {x[5]} s {min(x[1], x[2]):.1f}..{max(x[1], x[2]):.1f} "
            f"missed {x[3]:.2f} m, piece {x[6]:.2f} m, offset {x[7]:.1f} m"
            for x in runs
            if x[3] >= 0.1
        ]
    text = json.dumps(rounded(out), indent=1)
    if a.json:
        open(a.json, "w").write(text)
    print(text)


if __name__ == "__main__":
    main()
