#!/usr/bin/env python3
"""The longer misses of intersection curb: every stretch of at least 1 m of a reference
intersection toe that lies farther than 0.5 m from every extracted toe, with where it lies
beside the drive and how near the closest extracted line's end is.

Usage: scripts/intersection_misses.py DIR [EXTRACTED]

DIR holds reference.geojson and trajectory.csv (`curbtrace simulate -o DIR`) and the
extracted GeoJSON (EXTRACTED, default bend.geojson). One line per stretch: its length, its
position in the drive's frame (u along the trajectory, offset left positive, both metres,
at its two ends), its angle to the driving direction, and the distance from each end to the
nearest end of an extracted line ("track end"): a stretch with an extracted line ending
within about 1 m of it is where a track stopped short; one with none near was never
tracked (or its track was filtered out).
"""
import json
import math
import sys


def toes(path):
    return [
        (f["properties"], f["geometry"]["coordinates"])
        for f in json.load(open(path))["features"]
        if f["properties"].get("line") == "toe"
    ]


def main():
    d = sys.argv[1]
    name = sys.argv[2] if len(sys.argv) > 2 else "bend.geojson"
    ref = toes(f"{d}/reference.geojson")
    ext = toes(f"{d}/{name}")
    tr = []
    with open(f"{d}/trajectory.csv") as f:
        rows = f.readlines()[1:]
    for row in rows[::20]:
        a = row.split(",")
        tr.append((float(a[1]), float(a[2])))
    us = [0.0]
    for a, b in zip(tr, tr[1:]):
        us.append(us[-1] + math.hypot(b[0] - a[0], b[1] - a[1]))

    def frame(x, y):
        k = min(range(len(tr)), key=lambda i: (tr[i][0] - x) ** 2 + (tr[i][1] - y) ** 2)
        k2 = min(k, len(tr) - 2)
        h = (tr[k2 + 1][0] - tr[k2][0], tr[k2 + 1][1] - tr[k2][1])
        n = math.hypot(*h)
        h = (h[0] / n, h[1] / n)
        dx, dy = x - tr[k][0], y - tr[k][1]
        return us[k] + dx * h[0] + dy * h[1], -dx * h[1] + dy * h[0], h

    segs = [(a, c) for _, g in ext for a, c in zip(g, g[1:])]

    def dist(x, y):
        best = math.inf
        for a, c in segs:
            dx, dy = c[0] - a[0], c[1] - a[1]
            q = dx * dx + dy * dy
            t = 0.0 if q == 0 else max(0.0, min(1.0, ((x - a[0]) * dx + (y - a[1]) * dy) / q))
            best = min(best, math.hypot(x - a[0] - t * dx, y - a[1] - t * dy))
        return best

    ends = [g[0] for _, g in ext] + [g[-1] for _, g in ext]

    def to_end(p):
        return min((math.hypot(e[0] - p[0], e[1] - p[1]) for e in ends), default=math.inf)

    for p, g in ref:
        if p["category"] != "intersection":
            continue
        pieces, run = [], []
        for a, c in zip(g, g[1:]):
            if dist((a[0] + c[0]) / 2, (a[1] + c[1]) / 2) > 0.5:
                run.append((a, c))
            elif run:
                pieces.append(run)
                run = []
        if run:
            pieces.append(run)
        for r in pieces:
            length = sum(math.hypot(c[0] - a[0], c[1] - a[1]) for a, c in r)
            if length < 1.0:
                continue
            s, e = r[0][0], r[-1][1]
            u0, o0, h = frame(s[0], s[1])
            u1, o1, _ = frame(e[0], e[1])
            ang = math.degrees(math.atan2(e[1] - s[1], e[0] - s[0]) - math.atan2(h[1], h[0])) % 180
            print(
                f"{d.rstrip('/').split('/')[-1]} {p['side']:5} edge {p['edge']:3} missed {length:5.1f} m"
                f" u {u0:6.1f} -> {u1:6.1f}  offset {o0:6.1f} -> {o1:6.1f}  angle {ang:5.1f}"
                f"  track end {to_end(s):4.1f} / {to_end(e):4.1f} m"
            )


if __name__ == "__main__":
    main()
