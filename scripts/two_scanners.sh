#!/usr/bin/env bash
# Two scanners in an X (docs/results.md, "Two scanners"): for each street, simulates it
# with `--scanners 2`, extracts scanner 0 alone, scanner 1 alone and both fused (the
# default), and scores all three at the 50 mm buffer against what either scanner observed
# (reference.geojson). Prints one table row per street and run.
# Usage: scripts/two_scanners.sh OUT_DIR SCENE:SEED...   (e.g. kawasaki:1 random:1001)
set -euo pipefail
OUT=$1
shift
BIN=${CURBTRACE:-${CARGO_TARGET_DIR:-target}/release/curbtrace}
mkdir -p "$OUT"
echo "| street | run | C % | P % | Q % | RMS mm | doubled m |"
echo "|---|---|---:|---:|---:|---:|---:|"
for item in "$@"; do
  scene=${item%%:*} seed=${item##*:} dir="$OUT/$scene-$seed"
  "$BIN" simulate --scene "$scene" --seed "$seed" --scanners 2 -o "$dir" > "$dir.simulate.txt"
  for run in 0 1 fused; do
    pick=()
    [ "$run" = fused ] || pick=(--scanner "$run")
    "$BIN" extract "$dir/points.laz" --trajectory "$dir/trajectory.csv" \
      --mounts "$dir/mounts.toml" "${pick[@]}" -o "$dir/$run.geojson" -q
    "$BIN" eval --reference "$dir/reference.geojson" --extracted "$dir/$run.geojson" \
      --buffer 0.05 --json "$dir/$run.eval.json" > /dev/null
    python3 - "$dir/$run.eval.json" "$dir/$run.geojson" "$scene $seed" "$run" <<'PY'
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
run = {"0": "scanner 0", "1": "scanner 1"}.get(sys.argv[4], "fused")
print(f"| {sys.argv[3]} | {run} | {m['completeness_pct']:.1f} | {m['correctness_pct']:.1f} | "
      f"{m['quality_pct']:.1f} | {m['rms_mm']:.1f} | {doubled:.2f} |")
PY
  done
done
