#!/usr/bin/env bash
# firmware/realtime.sh STREAM.bin — the largest scanner rate the firmware keeps up with.
#
# Bisects the scanner's rate in points per second (bytes per point from the stream) for the
# largest with no dropped byte in a real-time run (tools/realtime-lib.sh: the QEMU build with
# `--realtime` under `-icount shift=SHIFT,sleep=off`), checks that run's output against
# `curbtrace kernel` byte for byte, and prints `name: value` lines, the rate also scaled to
# 1.5 cycles per instruction (the assumption of docs/benchmarks.md). With RATE set, runs once
# at RATE points/s scaled to CPI 1.5 instead and fails if any byte is dropped.
#
# Needs what firmware/check.sh needs. Environment: SHIFT (default 3), FIRMWARE_TARGET_DIR,
# CARGO_TARGET_DIR, CURBTRACE_BIN (a built `curbtrace` to use instead of building one),
# LO / HI (points/s bracket at SHIFT, default 50000 / 400000), STEPS (default 8), RATE.
set -euo pipefail
FW=$(cd "$(dirname "$0")" && pwd)
ROOT=$(cd "$FW/.." && pwd)
log() { echo "realtime.sh: $*" >&2; }
die() { log "$*"; exit 1; }
[ $# -eq 1 ] || die "usage: firmware/realtime.sh STREAM.bin"
[ -f "$1" ] || die "$1: no such file"
STREAM=$(realpath "$1")
case "$STREAM" in *[[:space:],]*) die "$STREAM: the path must not contain spaces or commas";; esac
cd "$ROOT"
SHIFT=${SHIFT:-3}
LO=${LO:-50000}
HI=${HI:-400000}
STEPS=${STEPS:-8}
RATE=${RATE:-}
FW_TARGET=${FIRMWARE_TARGET_DIR:-$FW/target}
HOST_TARGET=${CARGO_TARGET_DIR:-$ROOT/target}
WORK=$(mktemp -d "${TMPDIR:-/tmp}/curbtrace-rt.XXXXXX")
trap 'rm -rf "$WORK"' EXIT

log "building the firmware (libm)"
(cd "$FW" && RUSTC_BOOTSTRAP=1 RUSTC=/usr/bin/rustc CARGO_TARGET_DIR="$FW_TARGET/libm" \
  /usr/bin/cargo build --release --quiet) >&2
ELF="$FW_TARGET/libm/thumbv7em-none-eabihf/release/curbtrace-firmware"
CURBTRACE=${CURBTRACE_BIN:-}
if [ -z "$CURBTRACE" ]; then
  cargo build --release --quiet -p curbtrace-host-sim --bin curbtrace >&2
  CURBTRACE="$HOST_TARGET/release/curbtrace"
fi
"$CURBTRACE" kernel "$STREAM" -o "$WORK/host.bin" 2> "$WORK/host.txt"
points=$(sed -n 's/^points \([0-9]*\) in,.*/\1/p' "$WORK/host.txt")
[ -n "$points" ] && [ "$points" -gt 0 ] || die "$STREAM: no points"
bytes=$(stat -c %s "$STREAM")

# shellcheck source=tools/realtime-lib.sh
. "$FW/tools/realtime-lib.sh"
RT_ELF=$ELF RT_STREAM=$STREAM RT_BYTES=$bytes RT_POINTS=$points RT_SHIFT=$SHIFT RT_WORK=$WORK
echo "stream: $(basename "$STREAM") ($bytes bytes, $points points)"
echo "icount_shift: $SHIFT"
echo "cpi_implied_168mhz: $(rt_cpi)"
if [ -n "$RATE" ]; then
  lo=$(rt_unscaled "$RATE")
  dropped=$(rt_run "$lo")
  echo "rate_points_per_s_cpi1.5: $RATE"
  echo "rate_points_per_s: $lo"
  echo "dropped_bytes: $dropped"
  [ "$dropped" = 0 ] || { log "$dropped bytes dropped at $RATE points/s (CPI 1.5)"; exit 1; }
else
  bracket=$(rt_bisect "$LO" "$HI" "$STEPS")
  read -r lo hi <<< "$bracket"
  echo "max_points_per_s_no_drop: $lo"
  echo "first_rate_with_drops: $hi"
  echo "max_points_per_s_no_drop_cpi1.5: $(rt_scaled "$lo")"
fi
echo "queue_high_water_bytes: $(rt_fig "$lo" realtime_queue_high_water_bytes)"
if cmp -s "$WORK/host.bin" "$WORK/out-$lo.bin"; then echo "identical: yes"; else echo "identical: no"; exit 1; fi
