#!/usr/bin/env python3
"""Where a random street's bend edges lose length: every missed reference toe and every
extracted toe outside the buffer, in 2 cm samples, by side (near or far), category and
place (`false_length_budget.py`'s places), and for each why:

- missed: "extracted 0.05-0.5 m off" (a line of that side within 0.5 m: misplaced), "other
  side's line near", or "nothing within 0.5 m" (never tracked there, or stopped short);
- false: on the street's whole toe where the reference has a hole, near it (0.05-0.15 m),
  or off any toe.

Then every run of at least 1 m of one kind, longest first, with its station u along the
trajectory and its offset v (left positive) at both ends, its distance range to the nearest
line of the other kind, and its first sample's coordinates (for `curbtrace eval --picture`
on a reference and extraction clipped around it).

Usage: scripts/loss_attribution.py SIM_DIR EXT_DIR PLACES_DIR SEED...

SIM_DIR/seed-S holds `curbtrace simulate --scene random --seed S`'s reference.geojson,
trajectory.csv and simulate.txt; EXT_DIR/S.geojson the extraction; PLACES_DIR/seed-S.json
the street's places (`cargo run --release -p curbtrace-host-sim --example street_places --
S FILE`). Prints one Markdown table and run list per street.
"""
import collections
import csv
import json
import math
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import false_length_budget as F  # noqa: E402


def trajectory(path):
    xy = []
    with open(path) as fh:
        r = csv.reader(fh)
        next(r)
        for i, row in enumerate(r):
            if i % 20 == 0:
                xy.append((float(row[1]), float(row[2])))
    us = [0.0]
    for a, b in zip(xy, xy[1:]):
        us.append(us[-1] + math.dist(a, b))
    return xy, us


def station(q, xy, us):
    """Station along the trajectory and offset (left positive) of q, metres."""
    best = (1e9, 0.0, 0.0)
    for i in range(len(xy) - 1):
        a, b = xy[i], xy[i + 1]
        ax, ay = b[0] - a[0], b[1] - a[1]
        ll = ax * ax + ay * ay or 1e-9
        t = max(0.0, min(1.0, ((q[0] - a[0]) * ax + (q[1] - a[1]) * ay) / ll))
        d = math.hypot(q[0] - a[0] - t * ax, q[1] - a[1] - t * ay)
        if d < best[0]:
            n = math.sqrt(ll)
            best = (d, us[i] + t * n, (ax * (q[1] - a[1]) - ay * (q[0] - a[0])) / n)
    return best[1], best[2]


def runs(samples):
    out, cur = [], None
    for q, w, key, d in samples:
        if cur and cur["key"] == key and math.dist(cur["last"], q) < 0.3:
            cur["len"] += w
            cur["last"] = q
            cur["d"].append(d)
        else:
            if cur:
                out.append(cur)
            cur = {"key": key, "len": w, "first": q, "last": q, "d": [d]}
    if cur:
        out.append(cur)
    return out


def street(sim, ext, places_dir, seed):
    sd = f"{sim}/seed-{seed}"
    far = re.search(r"far side (left|right)", open(sd + "/simulate.txt").readline()).group(1)
    ref = F.toe_lines(sd + "/reference.geojson")
    extracted = F.toe_lines(f"{ext}/{seed}.geojson")
    places = json.load(open(f"{places_dir}/seed-{seed}.json"))
    ends = F.trajectory_ends(sd + "/trajectory.csv")
    xy, us = trajectory(sd + "/trajectory.csv")
    gtoe = F.grid_of([(tuple(t["pts"][i]), tuple(t["pts"][i + 1]))
                      for t in places["toes"] for i in range(len(t["pts"]) - 1)])
    gall = F.grid_of([(a, b) for _, c in extracted for a, b in zip(c, c[1:])])
    tot = collections.Counter()
    found = []
    for side in ("left", "right"):
        near_far = "far" if side == far else "near"
        gref = F.grid_of([(a, b) for p, c in ref if p["side"] == side for a, b in zip(c, c[1:])])
        gext = F.grid_of([(a, b) for p, c in extracted if p["side"] == side for a, b in zip(c, c[1:])])
        for p, c in ref:
            if p["side"] != side:
                continue
            ss = []
            for q, w in F.samples(c):
                d, _ = F.nearest(gext, q)
                if d <= F.BUF:
                    continue
                why = ("extracted 0.05-0.5 m off" if d <= 0.5
                       else "other side's line near" if F.nearest(gall, q)[0] <= 0.5
                       else "nothing within 0.5 m")
                key = ("missed", near_far, p["category"], F.place_of(q, side, places, ends), why)
                tot[key] += w
                ss.append((q, w, key, d))
            found += runs(ss)
        for p, c in extracted:
            if p["side"] != side:
                continue
            ss = []
            for q, w in F.samples(c):
                d, _ = F.nearest(gref, q)
                if d <= F.BUF:
                    continue
                dt, _ = F.nearest(gtoe, q)
                why = ("on the toe, reference hole" if dt <= F.BUF
                       else "near the toe" if dt <= F.NEAR_TOE_M else "off any toe")
                cat = p["category"] + (" bridged" if p.get("bridged") else "")
                key = ("false", near_far, cat, F.place_of(q, side, places, ends), why)
                tot[key] += w
                ss.append((q, w, key, d))
            found += runs(ss)
    print(f"## seed {seed} (far side {far})\n")
    print("| kind | side | category | place | why | m |\n|---|---|---|---|---|---:|")
    for k, v in sorted(tot.items(), key=lambda kv: -kv[1]):
        if v >= 0.3:
            print("| " + " | ".join(k) + f" | {v:.1f} |")
    print("\nRuns of 1 m or more:\n")
    for r in sorted(found, key=lambda r: -r["len"]):
        if r["len"] < 1.0:
            continue
        u0, v0 = station(r["first"], xy, us)
        u1, v1 = station(r["last"], xy, us)
        print(f"- {r['len']:.1f} m {' / '.join(r['key'])}: u {u0:.1f} to {u1:.1f}, v {v0:.1f} to "
              f"{v1:.1f}, {min(r['d']):.2f}-{max(r['d']):.2f} m from the other kind, at "
              f"{r['first'][0]:.1f}, {r['first'][1]:.1f}")
    print()


def main():
    if len(sys.argv) < 5:
        sys.exit("usage: loss_attribution.py SIM_DIR EXT_DIR PLACES_DIR SEED...")
    sim, ext, places = sys.argv[1:4]
    for seed in sys.argv[4:]:
        street(sim, ext, places, seed)


if __name__ == "__main__":
    main()
