#!/usr/bin/env bash
# Spinning lidars' 10 s drives (docs/results.md, "Spinning lidars"): for each scene, sensor
# and seed, simulates the drive (`--sensor S --duration 10 --seed N`), extracts it with the
# defaults and scores it at the 50 mm and 200 mm buffers against the curb the sensor
# observed within 20 m of the path. Prints one table row per drive (quality, %).
# Usage: [SCENES="kawasaki sapporo"] [SENSORS="hdl64 vlp16"] scripts/spinning.sh OUT_DIR SEED...
#        (e.g. scripts/spinning.sh out 1 11 12 13)
set -euo pipefail
OUT=$1
shift
BIN=${CURBTRACE:-${CARGO_TARGET_DIR:-target}/release/curbtrace}
mkdir -p "$OUT"
quality() {
  python3 -c "import json,sys; t=json.load(open(sys.argv[1]))['total']; print('%.1f' % t.get('metrics', t)['quality_pct'])" "$1"
}
echo "| drive | seed | Q at 50 mm % | Q at 200 mm % |"
echo "|---|---:|---:|---:|"
for scene in ${SCENES:-kawasaki sapporo}; do
  for sensor in ${SENSORS:-hdl64 vlp16}; do
    for seed in "$@"; do
      dir="$OUT/${scene}_${sensor}_s$seed"
      [ -f "$dir/reference.geojson" ] ||
        "$BIN" simulate --scene "$scene" --sensor "$sensor" --duration 10 --seed "$seed" \
          -o "$dir" > "$dir.simulate.txt"
      "$BIN" extract "$dir/points.laz" --trajectory "$dir/trajectory.csv" -o "$dir/edges.geojson" -q
      q=()
      for buffer in 0.05 0.2; do
        "$BIN" eval --reference "$dir/reference.geojson" --extracted "$dir/edges.geojson" \
          --buffer "$buffer" --json "$dir/eval-$buffer.json" > /dev/null
        q+=("$(quality "$dir/eval-$buffer.json")")
      done
      echo "| $scene $sensor | $seed | ${q[0]} | ${q[1]} |"
    done
  done
done
