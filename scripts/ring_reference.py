#!/usr/bin/env python3
"""The simulator's reference under a sensor-aware "observed" rule for spinning sensors.

usage: ring_reference.py REFERENCE.geojson TRAJECTORY.csv OUT.geojson [--rate-hz 10] [--cap-m 1.0]

The simulator keeps a toe vertex where a ground return fell within ±0.15 m along the toe on
both its road and its curb side (docs/simulator.md, *Reference*). A ring crosses a curb beside
the path once per revolution, so its crossings lie one revolution's advance of the vehicle
apart along the curb (0.8 m at 30 km/h and 10 Hz), and the rings together leave the reference
in pieces with holes between crossings. This script fills a hole between two consecutive
pieces of one toe where the hole is no longer than the sensor's own along-curb sampling gap
G = (largest advance of the vehicle in one revolution), capped at `--cap-m`: a surveyor
drawing from the scan joins two crossings that close. Longer holes (a parked car, a stretch
no ring reached) and the ends beyond the first and last crossing stay out.

Pieces are joined only when they are consecutive in the file (the simulator writes each toe's
pieces in order along it), on the same side, and the hole's chord runs within 30° of both
pieces' directions at the hole (the same toe, not a corner). A bridged segment takes the
category of its neighbours, the special one when they differ (the simulator's rule). Only toe
lines are written; `curbtrace eval` compares toe lines.
"""
import argparse
import csv
import json
import math


def advance_per_revolution(traj_csv, rate_hz):
    rows = []
    with open(traj_csv) as fh:
        r = csv.reader(fh)
        next(r)
        for row in r:
            rows.append((float(row[0]), float(row[1]), float(row[2])))
    period = 1.0 / rate_hz
    best, j = 0.0, 0
    for i, (t, x, y) in enumerate(rows):
        while j < len(rows) and rows[j][0] - t < period:
            j += 1
        if j == len(rows):
            break
        best = max(best, math.hypot(rows[j][1] - x, rows[j][2] - y))
    return best


def direction(a, b):
    return math.atan2(b[1] - a[1], b[0] - a[0])


def angle_between(u, v):
    d = abs(u - v) % (2 * math.pi)
    return min(d, 2 * math.pi - d)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("reference")
    ap.add_argument("trajectory")
    ap.add_argument("out")
    ap.add_argument("--rate-hz", type=float, default=10.0)
    ap.add_argument("--cap-m", type=float, default=1.0)
    a = ap.parse_args()
    gap = min(advance_per_revolution(a.trajectory, a.rate_hz), a.cap_m)
    j = json.load(open(a.reference))
    toes = [f for f in j["features"] if f["properties"].get("line", "toe") == "toe"]
    out, bridged, holes = [], 0.0, 0
    for f in toes:
        c = f["geometry"]["coordinates"]
        if out:
            prev = out[-1]
            pc = prev["geometry"]["coordinates"]
            hole = math.hypot(c[0][0] - pc[-1][0], c[0][1] - pc[-1][1])
            chord = direction(pc[-1], c[0])
            same_toe = (
                prev["properties"]["side"] == f["properties"]["side"]
                and hole <= gap
                and (hole < 1e-6 or (
                    angle_between(chord, direction(pc[-2], pc[-1])) < math.radians(30)
                    and angle_between(chord, direction(c[0], c[1])) < math.radians(30)))
            )
            if same_toe and hole > 1e-6:
                cp, cn = prev["properties"]["category"], f["properties"]["category"]
                cat = cp if cp == cn or cn == "curb" else cn
                out.append(bridge(pc[-1], c[0], prev["properties"], cat))
                bridged += hole
                holes += 1
        out.append(f)
    j["features"] = out
    json.dump(j, open(a.out, "w"))
    print(f"G = {gap:.3f} m; bridged {holes} holes, {bridged:.1f} m")


def bridge(p, q, props, cat):
    pr = {k: v for k, v in props.items() if k not in ("heights_m",)}
    pr["category"] = cat
    pr["length_m"] = math.hypot(q[0] - p[0], q[1] - p[1])
    return {"type": "Feature", "properties": pr,
            "geometry": {"type": "LineString", "coordinates": [p, q]}}


if __name__ == "__main__":
    main()
