"""One row of the fusion tables in docs/results.md: completeness, correctness, quality,
RMS at the 50 mm buffer (from `curbtrace eval --json`) and the doubled length.

Usage: fused_row.py EVAL_JSON EXTRACTED_GEOJSON STREET RUN
"""
import json, math, sys
m = json.load(open(sys.argv[1]))["total"]
# Toe length of a stretch lying within 0.3 m and 15 deg of another stretch of the same
# side, away from that stretch's ends (where consecutive stretches meet).
feats = [f for f in json.load(open(sys.argv[2]))["features"]
         if f["properties"].get("line", "toe") == "toe"]
lines = [(f["properties"]["side"], f["geometry"]["coordinates"]) for f in feats]
def dist(q, a, b):
    dx, dy = b[0] - a[0], b[1] - a[1]
    l2 = dx * dx + dy * dy
    t = 0 if l2 == 0 else max(0, min(1, ((q[0] - a[0]) * dx + (q[1] - a[1]) * dy) / l2))
    return math.hypot(q[0] - a[0] - t * dx, q[1] - a[1] - t * dy)
doubled = 0.0
for i, (side, pts) in enumerate(lines):
    for a, b in zip(pts, pts[1:]):
        mid = [(a[0] + b[0]) / 2, (a[1] + b[1]) / 2]
        ang = math.atan2(b[1] - a[1], b[0] - a[0])
        hit = False
        for j, (s2, p2) in enumerate(lines):
            if j == i or s2 != side:
                continue
            if min(math.hypot(mid[0] - p2[0][0], mid[1] - p2[0][1]),
                   math.hypot(mid[0] - p2[-1][0], mid[1] - p2[-1][1])) < 0.6:
                continue
            for c, d in zip(p2, p2[1:]):
                if abs(c[0] - mid[0]) > 5 or abs(c[1] - mid[1]) > 5:
                    continue
                da = abs((ang - math.atan2(d[1] - c[1], d[0] - c[0]) + math.pi / 2) % math.pi - math.pi / 2)
                if da < math.radians(15) and dist(mid, c, d) < 0.3:
                    hit = True
                    break
            if hit:
                break
        if hit:
            doubled += math.hypot(b[0] - a[0], b[1] - a[1])
run = sys.argv[4]
print(f"| {sys.argv[3]} | {run} | {m['completeness_pct']:.1f} | {m['correctness_pct']:.1f} | "
      f"{m['quality_pct']:.1f} | {m['rms_mm']:.1f} | {doubled:.2f} |")
