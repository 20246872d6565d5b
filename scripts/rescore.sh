#!/usr/bin/env bash
# Re-scores a robustness run's streets with another build, for quick before/after loops
# (docs/results.md, "Random streets"): extracts each street's points.laz with the defaults,
# scores it at the 50 mm buffer and prints "seed before after change" against the run's
# own bend.eval.txt, then the median, 10th percentile and lowest of both and every street
# that moves by 0.5 pp or more. One street at a time, under nice.
# Usage: scripts/rescore.sh CURBTRACE RUN_DIR OUT_DIR [SEED...]
#        (e.g. scripts/rescore.sh target/release/curbtrace /tmp/tune /tmp/rescore;
#         RUN_DIR is a ROBUSTNESS_OUT of scripts/robustness.sh; default: all its seeds)
set -euo pipefail
BIN=$1
RUN=$2
OUT=$3
shift 3
if [ $# -gt 0 ]; then
  SEEDS="$*"
else
  SEEDS=$(find "$RUN" -maxdepth 1 -name 'seed-*' -printf '%f\n' | sed 's/seed-//' | sort -n)
fi
mkdir -p "$OUT"
quality() {
  awk -F'|' '/^\| Quality/ { gsub(/ /, "", $3); print $3 }' "$1"
}
for s in $SEEDS; do
  d=$RUN/seed-$s
  if ! nice "$BIN" extract "$d/points.laz" --trajectory "$d/trajectory.csv" \
    -o "$OUT/$s.geojson" >"$OUT/$s.extract.txt" 2>&1; then
    echo "seed $s: extract failed ($OUT/$s.extract.txt)" >&2
    continue
  fi
  nice "$BIN" eval --reference "$d/reference.geojson" --extracted "$OUT/$s.geojson" \
    --buffer 0.05 >"$OUT/$s.eval.txt"
  before=$(quality "$d/bend.eval.txt")
  after=$(quality "$OUT/$s.eval.txt")
  python3 -c "import sys; b, a = map(float, sys.argv[2:]); print(f'{sys.argv[1]} {b} {a} {a - b:+.1f}')" \
    "$s" "$before" "$after"
done | tee "$OUT/table.txt"
python3 - "$OUT/table.txt" <<'PY'
import statistics
import sys

rows = [line.split() for line in open(sys.argv[1]) if len(line.split()) == 4]
if not rows:
    sys.exit("no street scored")


def percentile(xs, p):
    xs = sorted(xs)
    k = (len(xs) - 1) * p
    f = int(k)
    c = min(f + 1, len(xs) - 1)
    return xs[f] + (xs[c] - xs[f]) * (k - f)


for i, name in ((1, "before"), (2, "after")):
    xs = [float(r[i]) for r in rows]
    print(f"{name}: {len(xs)} streets, median {statistics.median(xs):.1f}, "
          f"10th pct {percentile(xs, 0.1):.1f}, lowest {min(xs):.1f}")
moved = [r for r in rows if abs(float(r[3])) >= 0.5]
print("moves >= 0.5 pp:", ", ".join(f"{r[0]} {r[1]} -> {r[2]}" for r in moved) or "none")
PY
