#!/usr/bin/env bash
# Reproduces docs/results.md: every simulated scene, both methods, scored at the 50 mm
# buffer (Honma et al.) and the 200 mm buffer (Qiu et al.), with throughput.
# Usage: scripts/results.sh [OUT_DIR]   (default: results-out/)
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-results-out}
mkdir -p "$OUT"
cargo build --release --quiet -p curbtrace-host-sim
BIN=${CARGO_TARGET_DIR:-target}/release/curbtrace
REPORT="$OUT/results.md"
: > "$REPORT"
run_scene() { # name [speed km/h; default: the scene's own]
  local name=$1 speed=${2:-} dir="$OUT/$1${2:+-$2kmh}"
  "$BIN" simulate --scene "$name" ${speed:+--speed "$speed"} -o "$dir" > "$dir.simulate.txt"
  for method in bend qiu; do
    local t0 t1 s
    t0=$(date +%s%N)
    "$BIN" extract "$dir/points.laz" --trajectory "$dir/trajectory.csv" \
      -o "$dir/$method.geojson" --method "$method" 2> "$dir/$method.summary.txt" \
      || { cat "$dir/$method.summary.txt" >&2; exit 1; }
    t1=$(date +%s%N)
    s=$(( (t1 - t0) / 1000000 ))
    {
      echo "### $name${speed:+ at $speed km/h} — method $method"
      echo
      echo '```'
      cat "$dir.simulate.txt"
      echo '```'
      echo
      echo '```'
      cat "$dir/$method.summary.txt"
      echo "wall milliseconds (extract, incl. LAZ decoding): $s"
      echo '```'
      echo
      echo "Buffer 50 mm:"
      echo
      "$BIN" eval --reference "$dir/reference.geojson" --extracted "$dir/$method.geojson" \
        --buffer 0.05 --json "$dir/$method.eval50.json"
      echo
      echo "Buffer 200 mm:"
      echo
      "$BIN" eval --reference "$dir/reference.geojson" --extracted "$dir/$method.geojson" \
        --buffer 0.2 --json "$dir/$method.eval200.json"
      echo
    } >> "$REPORT"
  done
}
for scene in tiny curvy sapporo kawasaki; do
  run_scene "$scene"
done
run_scene kawasaki 40
echo "wrote $REPORT"
python3 scripts/results_summary.py "$OUT" > "$OUT/summary.md"
echo "wrote $OUT/summary.md (the tables of docs/results.md)"
