#!/usr/bin/env python3
"""The false-length budget of extracted edges on random streets: every extracted toe line
outside the buffer of every reference line, in 2 cm samples, sorted by

- its distance to the nearest reference line (0.05-0.1 m, 0.1-0.5 m, 0.5-2 m, > 2 m);
- whether the street's whole toe lies there: within the buffer of it ("on the toe, reference
  hole": the simulator kept no reference there because no return fell within 0.15 m on
  both sides of the toe, docs/simulator.md), 0.05-0.15 m from it ("near the toe"), or
  farther ("off any toe");
- its place: intersection (within 4 m of a side street's mouth, or of its corners and
  curbs), curb cut (lowered part or transition, with or without a lip), beside a parked
  vehicle (within 3 m of it, same side), drive start/end (within 5 m along the path of the
  trajectory's ends or beyond), else plain curb; and the near or far side of the street.

Usage: scripts/false_length_budget.py SIM_DIR EXT_DIR PLACES_DIR SEED...

SIM_DIR/seed-S holds `curbtrace simulate --scene random --seed S`'s reference.geojson,
trajectory.csv and simulate.txt; EXT_DIR/seed-S/bend.geojson the extraction;
PLACES_DIR/seed-S.json the street's whole toes and places
(`cargo run --release -p curbtrace-host-sim --example street_places -- S FILE`). Prints
Markdown tables (metres summed over the streets) and writes EXT_DIR/budget.json.
"""
import collections
import csv
import json
import math
import re
import sys

BUF = 0.05
STEP = 0.02
NEAR_TOE_M = 0.15
CELL = 1.0


def grid_of(segs):
    g = collections.defaultdict(list)
    for s in segs:
        a, b = s[0], s[1]
        for gx in range(math.floor(min(a[0], b[0]) / CELL) - 2, math.floor(max(a[0], b[0]) / CELL) + 3):
            for gy in range(math.floor(min(a[1], b[1]) / CELL) - 2, math.floor(max(a[1], b[1]) / CELL) + 3):
                g[(gx, gy)].append(s)
    return g


def dseg(p, a, b):
    ax, ay = b[0] - a[0], b[1] - a[1]
    ll = ax * ax + ay * ay
    t = 0 if ll == 0 else max(0, min(1, ((p[0] - a[0]) * ax + (p[1] - a[1]) * ay) / ll))
    return math.hypot(p[0] - a[0] - t * ax, p[1] - a[1] - t * ay)


def nearest(g, p):
    """Distance to the nearest segment within about 2 m, and the segment (99 m, None if none)."""
    best = (99.0, None)
    for s in g.get((math.floor(p[0] / CELL), math.floor(p[1] / CELL)), []):
        d = dseg(p, s[0], s[1])
        if d < best[0]:
            best = (d, s)
    return best


def samples(c):
    for a, b in zip(c, c[1:]):
        ll = math.hypot(b[0] - a[0], b[1] - a[1])
        n = max(1, round(ll / STEP))
        for i in range(n):
            f = (i + 0.5) / n
            yield (a[0] + (b[0] - a[0]) * f, a[1] + (b[1] - a[1]) * f), ll / n


def toe_lines(path):
    return [(f["properties"], [tuple(q[:2]) for q in f["geometry"]["coordinates"]])
            for f in json.load(open(path))["features"]
            if f["properties"].get("line", "toe") == "toe"]


def distance_class(d):
    if d <= 0.1:
        return "0.05–0.1 m"
    if d <= 0.5:
        return "0.1–0.5 m"
    if d <= 2.0:
        return "0.5–2 m"
    return "> 2 m"


def place_of(q, side, places, ends):
    for x in places["ints"]:
        if dseg(q, x["a"], x["b"]) < 4.0 or math.dist(q, x["c"]) < x["width"] / 2 + x["radius"] + 4.0:
            return "intersection"
    for k in places["cuts"]:
        if k["side"] != side or dseg(q, k["a"], k["b"]) >= 1.5:
            continue
        lowered = dseg(q, k["a0"], k["b0"]) < 0.2 and min(math.dist(q, k["a0"]), math.dist(q, k["b0"])) > 0.3
        return ("cut, lowered part" if lowered else "cut transition") + (" (no lip)" if k["lip"] < 0.001 else "")
    for v in places["parked"]:
        if v["side"] == side and dseg(q, v["a"], v["b"]) < 3.0:
            return "beside a parked vehicle"
    (t0, h0), (t1, h1) = ends
    if (q[0] - t0[0]) * h0[0] + (q[1] - t0[1]) * h0[1] < 5.0 or (q[0] - t1[0]) * h1[0] + (q[1] - t1[1]) * h1[1] > -5.0:
        return "drive start/end"
    return "plain curb"


def trajectory_ends(path):
    xy = []
    with open(path) as fh:
        r = csv.reader(fh)
        next(r)
        for i, row in enumerate(r):
            if i % 40 == 0:
                xy.append((float(row[1]), float(row[2])))
    k = min(5, len(xy) - 1)

    def unit(a, b):
        n = math.dist(a, b) or 1.0
        return ((b[0] - a[0]) / n, (b[1] - a[1]) / n)
    return (xy[0], unit(xy[0], xy[k])), (xy[-1], unit(xy[-1 - k], xy[-1]))


def street(sim, ext, places_path, seed, tot):
    sd = f"{sim}/seed-{seed}"
    far = re.search(r"far side (left|right)", open(sd + "/simulate.txt").readline()).group(1)
    ref = toe_lines(sd + "/reference.geojson")
    extracted = toe_lines(f"{ext}/seed-{seed}/bend.geojson")
    places = json.load(open(places_path))
    gref = grid_of([(a, b) for _, c in ref for a, b in zip(c, c[1:])])
    gtoe = grid_of([(tuple(t["pts"][i]), tuple(t["pts"][i + 1]))
                    for t in places["toes"] for i in range(len(t["pts"]) - 1)])
    ends = trajectory_ends(sd + "/trajectory.csv")
    length = false = 0.0
    for p, c in extracted:
        for q, w in samples(c):
            length += w
            d, _ = nearest(gref, q)
            if d <= BUF:
                continue
            false += w
            dt, _ = nearest(gtoe, q)
            toe = ("on the toe, reference hole" if dt <= BUF
                   else "near the toe (0.05–0.15 m)" if dt <= NEAR_TOE_M else "off any toe")
            key = (distance_class(d), toe, place_of(q, p["side"], places, ends),
                   "far" if p["side"] == far else "near", seed)
            tot[key] += w
    return length, false


def table(tot, row, col, title):
    rows = collections.Counter()
    cells = collections.Counter()
    cols = sorted({k[col] for k in tot})
    for k, v in tot.items():
        rows[k[row]] += v
        cells[(k[row], k[col])] += v
    print(f"| {title} | " + " | ".join(cols) + " | total |")
    print("|---|" + "---:|" * (len(cols) + 1))
    for r, v in rows.most_common():
        print(f"| {r} | " + " | ".join(f"{cells[(r, c)]:.1f}" for c in cols) + f" | {v:.1f} |")
    print()


def main():
    if len(sys.argv) < 5:
        sys.exit("usage: false_length_budget.py SIM_DIR EXT_DIR PLACES_DIR SEED...")
    sim, ext, places = sys.argv[1:4]
    tot = collections.Counter()
    length = false = 0.0
    per_seed = {}
    for seed in sys.argv[4:]:
        ln, fl = street(sim, ext, f"{places}/seed-{seed}.json", seed, tot)
        per_seed[seed] = (ln, fl)
        length += ln
        false += fl
    print(f"{len(per_seed)} streets: extracted {length:.1f} m, outside the {BUF * 1000:.0f} mm buffer "
          f"{false:.1f} m (correctness {100 * (1 - false / length):.1f} %)\n")
    table(tot, 0, 1, "distance to the reference [m of false length]")
    table(tot, 2, 1, "place")
    table(tot, 3, 1, "side")
    print("| street | extracted m | false m | on the toe, reference hole | near the toe | off any toe "
          "| correctness % | without the holes % |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|")
    for seed, (ln, fl) in per_seed.items():
        by = collections.Counter()
        for k, v in tot.items():
            if k[4] == seed:
                by[k[1]] += v
        hole = by["on the toe, reference hole"]
        print(f"| {seed} | {ln:.1f} | {fl:.1f} | {hole:.1f} | {by['near the toe (0.05–0.15 m)']:.1f} | "
              f"{by['off any toe']:.1f} | {100 * (1 - fl / ln):.1f} | {100 * (1 - (fl - hole) / (ln - hole)):.1f} |")
    json.dump({"length_m": length, "false_m": false, "classes": [[list(k), v] for k, v in tot.items()]},
              open(f"{ext}/budget.json", "w"))


if __name__ == "__main__":
    main()
