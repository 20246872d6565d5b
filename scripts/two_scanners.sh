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
    python3 "$(dirname "$0")/fused_row.py" "$dir/$run.eval.json" "$dir/$run.geojson" "$scene $seed" \
      "$( case $run in 0|1) echo "scanner $run" ;; *) echo fused ;; esac )"
  done
done
