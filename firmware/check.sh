#!/usr/bin/env bash
# firmware/check.sh STREAM.bin — the firmware against the host, with its budgets.
#
# Builds the firmware twice (default libm maths, and micromath), runs each under QEMU's
# netduinoplus2 board (STM32F405) on STREAM.bin (a `curbtrace replay` byte stream) with the
# instruction-counting plugin (tools/), runs the host build of the core on the same stream
# (`curbtrace kernel`), compares the output packets and prints the figures, one
# `name: value` per line, ending with `identical: yes` or
# `identical: no (N of M scanlines differ)`. Exits 0 only when the libm firmware's output is
# byte-identical to the host's and the micromath build agrees with it on the candidates of
# at least 99 % of the scanlines. Progress goes to stderr, figures to stdout. The stream's
# config packet sets the output mode and the region of interest (`mode:` says which);
# docs/benchmarks.md shows the runs for both modes.
#
# Real time (tools/realtime-lib.sh, as firmware/realtime.sh): the libm build once more with
# `--realtime` under QEMU's `-icount shift=3,sleep=off` (8 ns per instruction, 1.344 cycles
# per instruction at 168 MHz), the stream delivered at CHECK_REALTIME_RATE points/s scaled to
# the 1.5 cycles per instruction of docs/benchmarks.md (default 200 000, the scanner's rate:
# 200 000 · 1.5 / 1.344 = 223 215 points/s at shift 3); `realtime_dropped_bytes:` says what
# that run lost, and any loss fails the check (CHECK_REALTIME_RATE=0 skips the run). Then a
# bisection of CHECK_REALTIME_BISECT steps (default 7, 0 for none) between 50 000 and
# 400 000 points/s at shift 3 prints the largest rate with no byte dropped, also scaled to
# CPI 1.5 (`realtime_max_no_drop_points_per_s_cpi1.5:`). Each run takes the whole stream (1.5–3 s on
# the tiny stream, about 20 s on curvy).
#
# Needs Debian's rustc-web, cargo-web, rust-web-src, lld-19, qemu-system-arm (scripts/test.sh
# installs them), gcc, binutils and rustup's stable cargo for the host side.
# Environment: CURBTRACE_BIN (a built `curbtrace` to use instead of building one),
# FIRMWARE_TARGET_DIR (default firmware/target), CARGO_TARGET_DIR (host build,
# default target/), QEMU_TIMEOUT seconds per QEMU run (default 600), CHECK_KEEP=1 keeps the
# work directory, CHECK_REALTIME_RATE and CHECK_REALTIME_BISECT (above).
set -euo pipefail

FW=$(cd "$(dirname "$0")" && pwd)
ROOT=$(cd "$FW/.." && pwd)
log() { echo "check.sh: $*" >&2; }
die() { log "$*"; exit 1; }

[ $# -eq 1 ] || die "usage: firmware/check.sh STREAM.bin"
[ -f "$1" ] || die "$1: no such file"
STREAM=$(realpath "$1")
# Host cargo commands run from the root: inside firmware/, firmware/.cargo/config.toml would
# make them build for the Cortex-M4F.
cd "$ROOT"
case "$STREAM" in *[[:space:],]*) die "$STREAM: the path must not contain spaces or commas (QEMU's -semihosting-config splits on them)";; esac
FW_TARGET=${FIRMWARE_TARGET_DIR:-$FW/target}
HOST_TARGET=${CARGO_TARGET_DIR:-$ROOT/target}
QEMU_TIMEOUT=${QEMU_TIMEOUT:-600}
WORK=$(mktemp -d "${TMPDIR:-/tmp}/curbtrace-fw.XXXXXX")
if [ "${CHECK_KEEP:-0}" = 1 ]; then log "work directory: $WORK"; else trap 'rm -rf "$WORK"' EXIT; fi

# --- build ----------------------------------------------------------------------------------
build_fw() { # NAME CARGO-ARGS…: one firmware variant, in its own target dir (no rebuild ping-pong)
  local name=$1; shift
  log "building the firmware ($name)"
  (cd "$FW" && RUSTC_BOOTSTRAP=1 RUSTC=/usr/bin/rustc CARGO_TARGET_DIR="$FW_TARGET/$name" \
    /usr/bin/cargo build --release --quiet "$@") >&2
  cp "$FW_TARGET/$name/thumbv7em-none-eabihf/release/curbtrace-firmware" "$WORK/fw-$name.elf"
}
build_fw libm
build_fw micromath --no-default-features --features micromath

log "building the host side (host-check; curbtrace)"
cargo build --release --quiet --manifest-path "$FW/host-check/Cargo.toml" \
  --target-dir "$HOST_TARGET/firmware-host-check" >&2
HC="$HOST_TARGET/firmware-host-check/release"
# The host program's `curbtrace kernel` is the reference; until it exists, fw-kernel (the
# firmware's own loop compiled for the host) is.
CURBTRACE=""
if [ -n "${CURBTRACE_BIN:-}" ]; then
  CURBTRACE="$CURBTRACE_BIN"
elif cargo build --release --quiet -p curbtrace-host-sim --bin curbtrace >&2 &&
  "$HOST_TARGET/release/curbtrace" kernel --help > /dev/null 2>&1; then
  CURBTRACE="$HOST_TARGET/release/curbtrace"
fi

gcc -O2 -Wall -shared -fPIC -fvisibility=hidden -o "$WORK/libinsncount.so" "$FW/tools/insncount.c"

# --- run ------------------------------------------------------------------------------------
run_fw() { # NAME: run the firmware under QEMU with the per-stage instruction counter
  local name=$1 rc=0
  "$FW/tools/stage-map.sh" "$WORK/fw-$name.elf" "$FW/tools/stages.txt" > "$WORK/$name.map"
  log "running the firmware ($name) under QEMU"
  timeout "$QEMU_TIMEOUT" qemu-system-arm -machine netduinoplus2 -nographic \
    -semihosting-config "enable=on,target=native,arg=fw,arg=$STREAM,arg=$WORK/out-$name.bin" \
    -plugin "$WORK/libinsncount.so,map=$WORK/$name.map" -d plugin -D "$WORK/counts-$name.log" \
    -kernel "$WORK/fw-$name.elf" > "$WORK/fw-$name.txt" 2> "$WORK/fw-$name.err" < /dev/null || rc=$?
  if [ "$rc" -ne 0 ]; then
    cat "$WORK/fw-$name.txt" "$WORK/fw-$name.err" >&2
    [ "$rc" -eq 124 ] && die "firmware ($name) did not finish within ${QEMU_TIMEOUT}s"
    die "firmware ($name) failed (exit status $rc)"
  fi
}
run_fw libm
run_fw micromath

log "running the firmware's loop on the host (fw-kernel)"
"$HC/fw-kernel" "$STREAM" "$WORK/out-hostloop.bin" >&2
if [ -n "$CURBTRACE" ]; then
  log "running the host core (curbtrace kernel)"
  "$CURBTRACE" kernel "$STREAM" -o "$WORK/out-host.bin" >&2
  reference="curbtrace kernel"
else
  log "no \`curbtrace kernel\` in this build: the reference is fw-kernel"
  cp "$WORK/out-hostloop.bin" "$WORK/out-host.bin"
  reference="fw-kernel (curbtrace kernel not available)"
fi

# --- figures --------------------------------------------------------------------------------
fig() { awk -v k="$1" -F': ' '$1 == k { print $2; exit }' "$2"; }   # NAME FILE
# Section sizes from the ELF: flash = everything loaded into FLASH (vector table, code,
# read-only data, the initial values of .data); static RAM = .data + .bss + .uninit; the stack
# is the .stack section (stack.x).
sizes() { # ELF → "flash static_ram stack"
  readelf -SW "$1" | awk '
    { sub(/^ *\[ *[0-9]+\] /, "") }
    $1 ~ /^\./ && NF >= 7 {
      name = $1; type = $2; addr = strtonum_hex($3); size = strtonum_hex($5)
      if (name == ".stack") { stack += size; next }
      if (addr >= 134217728 && addr < 268435456 && type == "PROGBITS") flash += size
      if (addr >= 536870912 && addr < 537001984) { ram += size; if (type == "PROGBITS") flash += size }
    }
    function strtonum_hex(h,   v, i) {
      v = 0; h = tolower(h)
      for (i = 1; i <= length(h); i++) v = v * 16 + index("0123456789abcdef", substr(h, i, 1)) - 1
      return v
    }
    END { printf "%d %d %d\n", flash, ram, stack }'
}
per_point() { awk -v n="$1" -v p="$2" 'BEGIN { if (p > 0) printf "%.1f\n", n / p; else print "n/a" }'; }
total() { sed -n 's/^insns_total=\([0-9]*\).*/\1/p' "$1"; }

read -r flash ram stack < <(sizes "$WORK/fw-libm.elf")
read -r flash_mm ram_mm _ < <(sizes "$WORK/fw-micromath.elf")
points=$(fig points_in "$WORK/fw-libm.txt")
echo "stream: $(basename "$STREAM") ($(stat -c %s "$STREAM") bytes)"
echo "points: $points"
echo "scanlines: $(fig lines "$WORK/fw-libm.txt")"
# The stream's config packet chooses the output mode (kind 3 output packets, or kind 4
# candidates packets) and the region of interest: docs/wire-format.md, version 2.
kind=$(od -An -tu1 -j3 -N1 "$WORK/out-libm.bin" 2> /dev/null | tr -d ' ')
case "$kind" in 3) echo "mode: points";; 4) echo "mode: candidates";; *) echo "mode: none";; esac
echo "outside_roi_points: $(fig outside_roi "$WORK/fw-libm.txt")"
echo "flash_bytes: $flash (of 1048576)"
echo "static_ram_bytes: $ram"
echo "stack_reserved_bytes: $stack"
echo "ram_total_bytes: $((ram + stack)) (of 131072)"
echo "stack_high_water_bytes: $(fig stack_high_water_bytes "$WORK/fw-libm.txt")"
echo "stack_high_water_startup_bytes: $(fig stack_high_water_startup_bytes "$WORK/fw-libm.txt")"
echo "stack_high_water_run_bytes: $(fig stack_high_water_run_bytes "$WORK/fw-libm.txt")"
stage() { awk -v s="$1" '$1 == "stage" && $2 == s { n = $3 } END { print n + 0 }' "$2"; }
for name in libm micromath; do
  c="$WORK/counts-$name.log"
  t=$(total "$c")
  echo "insns_per_point_$name: $(per_point "$t" "$points")"
  echo "insns_per_point_${name}_ingest: $(per_point $(($(stage ingest "$c") + $(stage ingest+crc "$c"))) "$points")"
  echo "insns_per_point_${name}_ingest_crc_part: $(per_point "$(stage ingest+crc "$c")" "$points")"
  for s in assembly bend smoothing peaks; do
    echo "insns_per_point_${name}_$s: $(per_point "$(stage $s "$c")" "$points")"
  done
  echo "insns_per_point_${name}_kernel_partition: $(per_point "$(stage kernel "$c")" "$points")"
  # The kernel stages together: bend, smoothing, peaks and the partitions (region of
  # interest, kept points).
  echo "insns_per_point_${name}_kernel_stages: $(per_point $(($(stage bend "$c") + $(stage smoothing "$c") + $(stage peaks "$c") + $(stage kernel "$c"))) "$points")"
  echo "insns_per_point_${name}_output: $(per_point $(($(stage output "$c") + $(stage output+crc "$c"))) "$points")"
  echo "insns_per_point_${name}_output_crc_part: $(per_point "$(stage output+crc "$c")" "$points")"
  # The pipeline's per-line glue (Pipeline::run: events, config packets, counter sums)
  # counts with the firmware loop.
  echo "insns_per_point_${name}_other: $(per_point $(($(stage other "$c") + $(stage pipeline "$c"))) "$points")"
  # Real time on the STM32F405 at 168 MHz, assuming 1.5 cycles per instruction
  # (docs/benchmarks.md, "Firmware", says why).
  awk -v t="$t" -v p="$points" -v n="$name" 'BEGIN { if (t > 0) printf "points_per_s_168mhz_cpi1.5_%s: %d\n", n, 168e6 / (1.5 * t / p) }'
done
echo "flash_bytes_micromath: $flash_mm"
echo "static_ram_bytes_micromath: $ram_mm"
echo "stack_high_water_bytes_micromath: $(fig stack_high_water_bytes "$WORK/fw-micromath.txt")"

"$HC/fw-compare" --approx "$WORK/out-host.bin" "$WORK/out-micromath.bin" > "$WORK/cmp-micromath.txt" ||
  die "comparing the micromath output failed: $(cat "$WORK/cmp-micromath.txt")"
sed 's/^/micromath_/' "$WORK/cmp-micromath.txt"
"$HC/fw-compare" "$WORK/out-hostloop.bin" "$WORK/out-libm.bin" > "$WORK/cmp-hostloop.txt" ||
  die "comparing with fw-kernel failed: $(cat "$WORK/cmp-hostloop.txt")"
echo "identical_to_fw_kernel_on_host: $(fig identical "$WORK/cmp-hostloop.txt")"
"$HC/fw-compare" "$WORK/out-host.bin" "$WORK/out-libm.bin" > "$WORK/cmp-libm.txt" ||
  die "comparing the libm output failed: $(cat "$WORK/cmp-libm.txt")"
echo "reference: $reference"
echo "output_bytes: $(fig output_bytes "$WORK/cmp-libm.txt")"

# --- real time ------------------------------------------------------------------------------
# shellcheck source=tools/realtime-lib.sh
. "$FW/tools/realtime-lib.sh"
RT_ELF="$WORK/fw-libm.elf" RT_STREAM=$STREAM RT_BYTES=$(stat -c %s "$STREAM") RT_POINTS=$points
RT_SHIFT=3 RT_WORK="$WORK"
rt_rate=${CHECK_REALTIME_RATE:-200000}
rt_steps=${CHECK_REALTIME_BISECT:-7}
rt_dropped=0
echo "realtime_icount_shift: $RT_SHIFT (cpi $(rt_cpi) at 168 MHz)"
if [ "$rt_rate" != 0 ]; then
  log "real time: one run at $rt_rate points/s (CPI 1.5)"
  rt_at=$(rt_unscaled "$rt_rate")
  rt_dropped=$(rt_run "$rt_at")
  echo "realtime_points_per_s_cpi1.5: $rt_rate ($rt_at at shift $RT_SHIFT)"
  echo "realtime_dropped_bytes: $rt_dropped"
  echo "realtime_queue_high_water_bytes: $(rt_fig "$rt_at" realtime_queue_high_water_bytes)"
  if [ "$rt_dropped" = 0 ]; then
    if cmp -s "$WORK/out-host.bin" "$WORK/out-$rt_at.bin"; then rt_identical=yes; else rt_identical=no; fi
    echo "realtime_identical: $rt_identical"
  fi
fi
if [ "$rt_steps" != 0 ]; then
  log "real time: bisecting the largest rate with no drop ($rt_steps steps)"
  rt_bracket=$(rt_bisect 50000 400000 "$rt_steps")
  read -r rt_lo rt_hi <<< "$rt_bracket"
  echo "realtime_max_no_drop_points_per_s: $rt_lo (first with drops: $rt_hi; at shift $RT_SHIFT)"
  echo "realtime_max_no_drop_points_per_s_cpi1.5: $(rt_scaled "$rt_lo")"
fi

status=0
if [ "$rt_dropped" != 0 ]; then
  log "$rt_dropped bytes dropped at $rt_rate points/s (CPI 1.5)"
  status=1
fi
[ "${rt_identical:-yes}" = yes ] || status=1
agree=$(fig candidates_agree_percent "$WORK/cmp-micromath.txt")
if ! awk -v a="$agree" 'BEGIN { exit !(a >= 99) }'; then
  log "micromath candidates agree on only $agree % of the scanlines (need >= 99 %)"
  status=1
fi
identical=$(fig identical "$WORK/cmp-libm.txt")
echo "identical: $identical"
[ "$identical" = yes ] || status=1
exit $status
