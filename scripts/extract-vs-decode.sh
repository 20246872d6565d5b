#!/usr/bin/env bash
# End to end against the decoder alone, side by side: alternates the LAZ/LAS decoder
# (examples/decode: the same `fill_points` reader, laz-rs's parallel decoder on both
# threads) and `curbtrace extract` on the same files, RUNS times each, and prints wall and
# CPU of every run with the ratios (docs/benchmarks.md).
#
#   scripts/extract-vs-decode.sh TRAJECTORY RUNS FILE...
set -euo pipefail
traj=$1; runs=$2; shift 2
bin=target/release
out=$(mktemp -d)
for i in $(seq "$runs"); do
  /usr/bin/time -f "%e %U %S %M" -o "$out/d" "$bin/examples/decode" 32768 "$@" > /dev/null
  /usr/bin/time -f "%e %U %S %M" -o "$out/e" "$bin/curbtrace" extract "$@" \
    --trajectory "$traj" -o "$out/edges.geojson" -q
  read -r dw du ds dm < "$out/d"
  read -r ew eu es em < "$out/e"
  awk -v i="$i" -v dw="$dw" -v dc="$(echo "$du + $ds" | bc)" -v ew="$ew" \
      -v ec="$(echo "$eu + $es" | bc)" -v em="$em" 'BEGIN {
    printf "run %d: decode %.2f s wall %.2f s CPU; extract %.2f s wall %.2f s CPU %d kB; ratio wall %.2f CPU %.2f\n",
      i, dw, dc, ew, ec, em, ew / dw, ec / dc }'
done
rm -rf "$out"
