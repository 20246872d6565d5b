#!/usr/bin/env bash
# firmware/realtime.sh STREAM.bin — the largest scanner rate the firmware keeps up with.
#
# Runs the QEMU build with `--realtime=BYTES_PER_S` (src/realtime.rs: a SysTick interrupt
# delivers the stream at that rate into a queue the processing loop drains) under QEMU's
# `-icount shift=SHIFT`, where every guest instruction takes 2^SHIFT ns of the guest's clock:
# at 168 MHz that is 168e6 · 2^SHIFT · 1e-9 cycles per instruction (shift 3: 1.344). Bisects
# the rate in points per second (bytes per point from the stream) for the largest with no
# dropped byte, checks that run's output against `curbtrace kernel` byte for byte, and
# prints `name: value` lines, the rate also scaled to 1.5 cycles per instruction (the
# assumption of docs/benchmarks.md): rate · CPI(shift) / 1.5. `sleep=off` makes the runs
# deterministic: while the loop sleeps (`WFI`) the guest's clock jumps to the next tick
# instead of following the host's clock, so the same rate gives the same bytes dropped and
# the same queue high water on every run, however busy the host is (with QEMU's default
# `sleep=on` the high water varied between runs, and bisections disagreed).
#
# Needs what firmware/check.sh needs. Environment: SHIFT (default 3), FIRMWARE_TARGET_DIR,
# CARGO_TARGET_DIR, LO / HI (points/s bracket, default 50000 / 400000), STEPS (default 8).
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
FW_TARGET=${FIRMWARE_TARGET_DIR:-$FW/target}
HOST_TARGET=${CARGO_TARGET_DIR:-$ROOT/target}
WORK=$(mktemp -d "${TMPDIR:-/tmp}/curbtrace-rt.XXXXXX")
trap 'rm -rf "$WORK"' EXIT

log "building the firmware (libm)"
(cd "$FW" && RUSTC_BOOTSTRAP=1 RUSTC=/usr/bin/rustc CARGO_TARGET_DIR="$FW_TARGET/libm" \
  /usr/bin/cargo build --release --quiet) >&2
ELF="$FW_TARGET/libm/thumbv7em-none-eabihf/release/curbtrace-firmware"
cargo build --release --quiet -p curbtrace-host-sim --bin curbtrace >&2
"$HOST_TARGET/release/curbtrace" kernel "$STREAM" -o "$WORK/host.bin" 2> "$WORK/host.txt"
points=$(sed -n 's/^points \([0-9]*\) in,.*/\1/p' "$WORK/host.txt")
[ -n "$points" ] && [ "$points" -gt 0 ] || die "$STREAM: no points"
bytes=$(stat -c %s "$STREAM")

run() { # POINTS_PER_S → dropped bytes (output in $WORK/out-RATE.bin)
  local rate=$1 bps
  bps=$(awk -v r="$rate" -v b="$bytes" -v p="$points" 'BEGIN { printf "%d", r * b / p }')
  timeout 600 qemu-system-arm -machine netduinoplus2 -nographic -icount "shift=$SHIFT,sleep=off" \
    -semihosting-config "enable=on,target=native,arg=fw,arg=--realtime=$bps,arg=$STREAM,arg=$WORK/out-$rate.bin" \
    -kernel "$ELF" < /dev/null > "$WORK/rt-$rate.txt" 2>&1 || die "the run at $rate points/s failed: $(cat "$WORK/rt-$rate.txt")"
  awk -F': ' '$1 == "realtime_dropped_bytes" { print $2 }' "$WORK/rt-$rate.txt"
}

lo=$LO hi=$HI
[ "$(run "$lo")" = 0 ] || die "bytes dropped already at $lo points/s"
for _ in $(seq "$STEPS"); do
  mid=$(((lo + hi) / 2))
  d=$(run "$mid")
  log "$mid points/s: $d bytes dropped"
  if [ "$d" = 0 ]; then lo=$mid; else hi=$mid; fi
done
cpi=$(awk -v s="$SHIFT" 'BEGIN { printf "%.3f", 168e6 * 2^s * 1e-9 }')
echo "stream: $(basename "$STREAM") ($bytes bytes, $points points)"
echo "icount_shift: $SHIFT"
echo "cpi_implied_168mhz: $cpi"
echo "max_points_per_s_no_drop: $lo"
echo "first_rate_with_drops: $hi"
awk -v r="$lo" -v c="$cpi" 'BEGIN { printf "max_points_per_s_no_drop_cpi1.5: %d\n", r * c / 1.5 }'
echo "queue_high_water_bytes: $(awk -F': ' '$1 == "realtime_queue_high_water_bytes" { print $2 }' "$WORK/rt-$lo.txt")"
if cmp -s "$WORK/host.bin" "$WORK/out-$lo.bin"; then echo "identical: yes"; else echo "identical: no"; exit 1; fi
