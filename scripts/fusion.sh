#!/usr/bin/env bash
# One street seen twice, by two scanners in an X or by two passes (docs/results.md, "Two
# scanners" and "Two passes"): for each street, simulates it with `--scanners 2` or
# `--passes 2` (the second pass driven back, its GNSS offset by OFFSET metres, 0.10 by
# default), extracts view 0 alone, view 1 alone and both fused (the default), and scores all
# three at the 50 mm buffer against what either view observed (reference.geojson). Prints
# one table row per street and run.
# Usage: [OFFSET=0.1] scripts/fusion.sh scanners|passes OUT_DIR SCENE:SEED...
#        (e.g. scripts/fusion.sh scanners out kawasaki:1 random:1001)
set -euo pipefail
KIND=$1 OUT=$2
shift 2
case $KIND in
  scanners) make=(--scanners 2) pick_flag=--scanner label=scanner ;;
  passes) make=(--passes 2 --pass-offset "${OFFSET:-0.1}") pick_flag=--pass label=pass ;;
  *) echo "fusion.sh: the first argument is 'scanners' or 'passes', not '$KIND'" >&2; exit 2 ;;
esac
BIN=${CURBTRACE:-${CARGO_TARGET_DIR:-target}/release/curbtrace}
mkdir -p "$OUT"
echo "| street | run | C % | P % | Q % | RMS mm | doubled m |"
echo "|---|---|---:|---:|---:|---:|---:|"
for item in "$@"; do
  scene=${item%%:*} seed=${item##*:} dir="$OUT/$scene-$seed"
  "$BIN" simulate --scene "$scene" --seed "$seed" "${make[@]}" -o "$dir" > "$dir.simulate.txt"
  mounts=()
  [ "$KIND" = scanners ] && mounts=(--mounts "$dir/mounts.toml")
  for run in 0 1 fused; do
    pick=()
    [ "$run" = fused ] || pick=("$pick_flag" "$run")
    "$BIN" extract "$dir/points.laz" --trajectory "$dir/trajectory.csv" \
      "${mounts[@]}" "${pick[@]}" -o "$dir/$run.geojson" -q
    "$BIN" eval --reference "$dir/reference.geojson" --extracted "$dir/$run.geojson" \
      --buffer 0.05 --json "$dir/$run.eval.json" > /dev/null
    python3 "$(dirname "$0")/fused_row.py" "$dir/$run.eval.json" "$dir/$run.geojson" "$scene $seed" \
      "$( case $run in 0|1) echo "$label $run" ;; *) echo fused ;; esac )"
  done
done
