# firmware/tools/realtime-lib.sh — real-time runs of the QEMU build, sourced by
# firmware/realtime.sh and firmware/check.sh.
#
# One run: the firmware with `--realtime=BYTES_PER_S` (src/realtime.rs: a SysTick interrupt
# delivers the stream at that rate into a queue the processing loop drains) under QEMU's
# `-icount shift=SHIFT,sleep=off`, where every guest instruction takes 2^SHIFT ns of the
# guest's clock: at 168 MHz that is 168e6 · 2^SHIFT · 1e-9 cycles per instruction (shift 3:
# 1.344). A rate measured so scales to the 1.5 cycles per instruction of docs/benchmarks.md
# as rate · CPI(shift) / 1.5. `sleep=off` makes the runs deterministic: while the loop
# sleeps (`WFI`) the guest's clock jumps to the next tick instead of following the host's
# clock, so the same rate gives the same bytes dropped and the same queue high water on
# every run, however busy the host is.
#
# The caller sets RT_ELF (the QEMU build), RT_STREAM (no spaces or commas), RT_BYTES and
# RT_POINTS (the stream's size and points), RT_SHIFT and RT_WORK (a directory for outputs),
# and defines die().

rt_cpi() { # → the cycles per instruction that RT_SHIFT implies at 168 MHz
  awk -v s="$RT_SHIFT" 'BEGIN { printf "%.3f", 168e6 * 2^s * 1e-9 }'
}

rt_unscaled() { # POINTS_PER_S at CPI 1.5 → the rate at RT_SHIFT that equals it (rounded up)
  awk -v r="$1" -v c="$(rt_cpi)" 'BEGIN { x = r * 1.5 / c; n = int(x); if (n < x) n++; print n }'
}

rt_scaled() { # POINTS_PER_S at RT_SHIFT → the same rate at CPI 1.5 (rounded down)
  awk -v r="$1" -v c="$(rt_cpi)" 'BEGIN { printf "%d\n", r * c / 1.5 }'
}

rt_run() { # POINTS_PER_S → bytes dropped; output in $RT_WORK/out-RATE.bin, figures in rt-RATE.txt
  local rate=$1 bps
  bps=$(awk -v r="$rate" -v b="$RT_BYTES" -v p="$RT_POINTS" 'BEGIN { printf "%d", r * b / p }')
  timeout 600 qemu-system-arm -machine netduinoplus2 -nographic -icount "shift=$RT_SHIFT,sleep=off" \
    -semihosting-config "enable=on,target=native,arg=fw,arg=--realtime=$bps,arg=$RT_STREAM,arg=$RT_WORK/out-$rate.bin" \
    -kernel "$RT_ELF" < /dev/null > "$RT_WORK/rt-$rate.txt" 2>&1 ||
    die "the real-time run at $rate points/s failed: $(cat "$RT_WORK/rt-$rate.txt")"
  rt_fig "$rate" realtime_dropped_bytes
}

rt_fig() { # POINTS_PER_S NAME → the run's figure NAME
  awk -F': ' -v k="$2" '$1 == k { print $2 }' "$RT_WORK/rt-$1.txt"
}

rt_bisect() { # LO HI STEPS → "lo hi": the largest rate found with no byte dropped, the first with drops
  # Runs in a command substitution, where `set -e` does not reach: each run's failure exits.
  local lo=$1 hi=$2 steps=$3 mid d
  d=$(rt_run "$lo") || exit 1
  [ "$d" = 0 ] || die "bytes dropped already at $lo points/s"
  for _ in $(seq "$steps"); do
    mid=$(((lo + hi) / 2))
    d=$(rt_run "$mid") || exit 1
    echo "real time: $mid points/s: $d bytes dropped" >&2
    if [ "$d" = 0 ]; then lo=$mid; else hi=$mid; fi
  done
  echo "$lo $hi"
}
