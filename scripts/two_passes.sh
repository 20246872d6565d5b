#!/usr/bin/env bash
# Two passes (docs/results.md, "Two passes"): for each street, simulates it with
# `--passes 2` (the second pass driven back, its GNSS offset by OFFSET metres, 0.10 by
# default), extracts pass 0 alone, pass 1 alone and both fused (the default), and scores
# all three at the 50 mm buffer against what either pass observed (reference.geojson).
# Prints one table row per street and run.
# Usage: [OFFSET=0.1] scripts/two_passes.sh OUT_DIR SCENE:SEED...   (e.g. kawasaki:1)
set -euo pipefail
OUT=$1
shift
BIN=${CURBTRACE:-${CARGO_TARGET_DIR:-target}/release/curbtrace}
mkdir -p "$OUT"
echo "| street | run | C % | P % | Q % | RMS mm | doubled m |"
echo "|---|---|---:|---:|---:|---:|---:|"
for item in "$@"; do
  scene=${item%%:*} seed=${item##*:} dir="$OUT/$scene-$seed"
  "$BIN" simulate --scene "$scene" --seed "$seed" --passes 2 --pass-offset "${OFFSET:-0.1}" -o "$dir" > "$dir.simulate.txt"
  for run in 0 1 fused; do
    pick=()
    [ "$run" = fused ] || pick=(--pass "$run")
    "$BIN" extract "$dir/points.laz" --trajectory "$dir/trajectory.csv" \
      "${pick[@]}" -o "$dir/$run.geojson" -q
    "$BIN" eval --reference "$dir/reference.geojson" --extracted "$dir/$run.geojson" \
      --buffer 0.05 --json "$dir/$run.eval.json" > /dev/null
    python3 "$(dirname "$0")/fused_row.py" "$dir/$run.eval.json" "$dir/$run.geojson" "$scene $seed" \
      "$( case $run in 0|1) echo "pass $run" ;; *) echo fused ;; esac )"
  done
done
