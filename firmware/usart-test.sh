#!/usr/bin/env bash
# firmware/usart-test.sh STREAM.bin [MAX_BYTES|all [BYTES_PER_S]] — the firmware's USART
# links under QEMU, against the host core.
#
# Builds the QEMU firmware with the `usart` feature and runs it on the netduinoplus2 board
# (STM32F405) with `--usart=SIZE`: fw-feed (host-check/) writes STREAM.bin — or its first
# whole packets up to MAX_BYTES (fw-head), since QEMU's emulated USART moves only some tens of
# kB/s — into USART3 through a Unix socket chardev, optionally paced to BYTES_PER_S, and the
# output packets
# leave on USART6 into a file chardev. The packets are compared with `curbtrace kernel` on
# the same stream. Prints `name: value` figures (the firmware's counters, the receive
# queue's, the feed rate) ending with `identical: yes|no`; exits 0 only when the output is
# byte-identical and the receive side lost no byte (queue full, overrun or line error).
# Progress goes to stderr.
#
# Needs what firmware/check.sh needs. Environment: CURBTRACE_BIN (a built `curbtrace` to
# use instead of building one), FIRMWARE_TARGET_DIR (default
# firmware/target), CARGO_TARGET_DIR (host build, default target/), QEMU_TIMEOUT seconds
# (default 300), CHECK_KEEP=1 keeps the work directory.
set -euo pipefail

FW=$(cd "$(dirname "$0")" && pwd)
ROOT=$(cd "$FW/.." && pwd)
log() { echo "usart-test.sh: $*" >&2; }
die() { log "$*"; exit 1; }

[ $# -ge 1 ] && [ $# -le 3 ] || die "usage: firmware/usart-test.sh STREAM.bin [MAX_BYTES|all [BYTES_PER_S]]"
[ -f "$1" ] || die "$1: no such file"
STREAM=$(realpath "$1")
MAX_BYTES=${2:-all}
RATE=${3:-}
cd "$ROOT"
FW_TARGET=${FIRMWARE_TARGET_DIR:-$FW/target}
HOST_TARGET=${CARGO_TARGET_DIR:-$ROOT/target}
QEMU_TIMEOUT=${QEMU_TIMEOUT:-300}
WORK=$(mktemp -d "${TMPDIR:-/tmp}/curbtrace-usart.XXXXXX")
QEMU_PID=""
cleanup() {
  [ -n "$QEMU_PID" ] && kill "$QEMU_PID" 2>/dev/null || true
  if [ "${CHECK_KEEP:-0}" = 1 ]; then log "work directory: $WORK"; else rm -rf "$WORK"; fi
}
trap cleanup EXIT

log "building the firmware (usart)"
(cd "$FW" && RUSTC_BOOTSTRAP=1 RUSTC=/usr/bin/rustc CARGO_TARGET_DIR="$FW_TARGET/usart" \
  /usr/bin/cargo build --release --quiet --features usart) >&2
ELF="$FW_TARGET/usart/thumbv7em-none-eabihf/release/curbtrace-firmware"

log "building the host side (host-check; curbtrace)"
cargo build --release --quiet --manifest-path "$FW/host-check/Cargo.toml" \
  --target-dir "$HOST_TARGET/firmware-host-check" >&2
HC="$HOST_TARGET/firmware-host-check/release"
if [ "$MAX_BYTES" != all ]; then
  "$HC/fw-head" "$STREAM" "$WORK/stream.bin" "$MAX_BYTES" >&2
  STREAM="$WORK/stream.bin"
fi
CURBTRACE=${CURBTRACE_BIN:-}
if [ -z "$CURBTRACE" ]; then
  cargo build --release --quiet -p curbtrace-host-sim --bin curbtrace >&2
  CURBTRACE="$HOST_TARGET/release/curbtrace"
fi
"$CURBTRACE" kernel "$STREAM" -o "$WORK/out-host.bin" >&2

# QEMU's serial chardevs map in order onto USART1, USART2, USART3, UART4, UART5, USART6.
SOCK="$WORK/usart3.sock"
size=$(stat -c %s "$STREAM")
log "running the firmware under QEMU: $size bytes into USART3${RATE:+ at $RATE bytes/s}"
timeout "$QEMU_TIMEOUT" qemu-system-arm -machine netduinoplus2 -nographic -monitor none \
  -serial null -serial null -serial "unix:$SOCK,server=on,wait=on" -serial null -serial null \
  -serial "file:$WORK/out-fw.bin" \
  -semihosting-config "enable=on,target=native,arg=fw,arg=--usart=$size" \
  -kernel "$ELF" > "$WORK/fw.txt" 2> "$WORK/fw.err" < /dev/null &
QEMU_PID=$!
feed_rc=0
timeout "$QEMU_TIMEOUT" "$HC/fw-feed" "$SOCK" "$STREAM" $RATE > "$WORK/feed.txt" 2> "$WORK/feed.err" || feed_rc=$?
qemu_rc=0
wait "$QEMU_PID" || qemu_rc=$?
QEMU_PID=""
if [ "$qemu_rc" -ne 0 ] || [ "$feed_rc" -ne 0 ]; then
  cat "$WORK/fw.txt" "$WORK/fw.err" "$WORK/feed.err" >&2
  [ "$qemu_rc" -eq 124 ] && die "the firmware did not finish within ${QEMU_TIMEOUT}s"
  die "the run failed (QEMU exit status $qemu_rc, feeder $feed_rc)"
fi

fig() { awk -v k="$1" -F': ' '$1 == k { print $2; exit }' "$2"; }   # NAME FILE
echo "stream: $(basename "$1") ($size bytes$([ "$MAX_BYTES" != all ] && echo ", cut at $MAX_BYTES"))"
for k in points_in lines bytes_in bytes_dropped_full crc_errors seq_gaps packets_out bytes_out \
  usart_rx_bytes usart_rx_dropped_full usart_rx_overruns usart_rx_line_errors \
  usart_rx_queue_bytes usart_rx_queue_high_water usart_run_ms stack_high_water_bytes; do
  echo "$k: $(fig "$k" "$WORK/fw.txt")"
done
cat "$WORK/feed.txt"
"$HC/fw-compare" "$WORK/out-host.bin" "$WORK/out-fw.bin" > "$WORK/cmp.txt" ||
  die "comparing the output failed: $(cat "$WORK/cmp.txt")"
echo "reference: curbtrace kernel"
echo "output_bytes: $(fig output_bytes "$WORK/cmp.txt")"
status=0
lost=0
for k in usart_rx_dropped_full usart_rx_overruns usart_rx_line_errors bytes_dropped_full; do
  v=$(fig "$k" "$WORK/fw.txt")
  [ "$v" = 0 ] || { log "$k: $v (expected 0)"; lost=1; }
done
[ "$(fig usart_rx_bytes "$WORK/fw.txt")" = "$size" ] || { log "USART3 received $(fig usart_rx_bytes "$WORK/fw.txt") of $size bytes"; lost=1; }
[ "$lost" = 0 ] || status=1
identical=$(fig identical "$WORK/cmp.txt")
echo "identical: $identical"
[ "$identical" = yes ] || status=1
exit $status
