#!/usr/bin/env bash
# Cargo runner (`cargo run --release -- IN OUT` in firmware/): runs the firmware ELF on
# QEMU's netduinoplus2 board (STM32F405) with semihosting, wrapped in a timeout because a
# locked-up core would otherwise keep QEMU running forever.
set -euo pipefail
elf=$1
shift
args="arg=$(basename "$elf")"
for a in "$@"; do args="$args,arg=$a"; done
exec timeout "${QEMU_TIMEOUT:-300}" qemu-system-arm -machine netduinoplus2 -nographic \
  -semihosting-config "enable=on,target=native,$args" -kernel "$elf"
