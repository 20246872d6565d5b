#!/usr/bin/env bash
# Fuzz smoke runs (part of scripts/test.sh): lint fuzz/, then the core targets side by side
# from their committed corpora, then every saved crash of those targets; any crash fails. Installs
# cargo-fuzz when missing.
#
# `host_inputs` (the host's LAS/LAZ and trajectory readers) is not fuzzed here by default:
# its sanitizer-coverage build of the host's whole dependency tree costs about 7 minutes of
# CI for 20 s of fuzzing. Its corpus and saved crashes run in every `cargo test` instead
# (host-sim/tests/fuzz_replay.rs), and its long runs are in docs/robustness.md.
# FUZZ_SMOKE_TARGETS="wire_parse ingest kernel_points host_inputs" runs it here too.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$(pwd)
# Each step prints the minutes since the run began, so a slow step shows in CI's log.
T0=${CURBTRACE_T0:-$(date +%s)}; export CURBTRACE_T0=$T0
step() { printf '\n==> [%dm%02ds] %s\n' $((($(date +%s) - T0) / 60)) $((($(date +%s) - T0) % 60)) "$*"; }
step "fuzz: cargo fmt --check and clippy on the fuzz crate (-D warnings)"
command -v cargo-fuzz >/dev/null 2>&1 || cargo install cargo-fuzz --locked
FUZZ_TARGET="${CARGO_TARGET_DIR:-$ROOT/target}/fuzz"
cargo fmt --check --manifest-path fuzz/Cargo.toml
# Stable clippy, release profile, in the workspace's target directory: the host crate's
# dependencies checked for the Python package's clippy are mostly reused.
cargo clippy --release --manifest-path fuzz/Cargo.toml \
  --target-dir "${CARGO_TARGET_DIR:-$ROOT/target}" --all-targets --features host -- -D warnings
if rustup run nightly rustc --version >/dev/null 2>&1; then
  FUZZ_TC=(+nightly)
else
  # No nightly: cargo-fuzz's flags on stable through RUSTC_BOOTSTRAP.
  export RUSTC_BOOTSTRAP=1; FUZZ_TC=()
fi
TARGETS=${FUZZ_SMOKE_TARGETS:-wire_parse ingest kernel_points}
# The smoke runs go without AddressSanitizer (-s none): the core forbids unsafe code, the
# build is much shorter and the targets run ~8x faster (docs/robustness.md); the long runs
# in docs/robustness.md used ASan. Each libFuzzer run is one process on one core, so the
# targets are built first and then fuzzed side by side; each run's log is printed after.
step "fuzz: building $TARGETS"
for t in $TARGETS; do
  feat=(); if [ "$t" = host_inputs ]; then feat=(--features host); fi
  (cd fuzz && cargo "${FUZZ_TC[@]}" fuzz build -s none "${feat[@]}" --target-dir "$FUZZ_TARGET" "$t")
done
step "fuzz: $TARGETS side by side for 30 s each from fuzz/corpus/<target> (any crash fails)"
work=$(mktemp -d)
pids=()
for t in $TARGETS; do
  feat=(); if [ "$t" = host_inputs ]; then feat=(--features host); fi
  mkdir -p "$work/$t"
  (cd fuzz && cargo "${FUZZ_TC[@]}" fuzz run -s none "${feat[@]}" --target-dir "$FUZZ_TARGET" \
    "$t" "$work/$t" "corpus/$t" -- -max_total_time=30 -max_len=65536 -rss_limit_mb=2048 \
    -malloc_limit_mb=512 -artifact_prefix="$work/$t/") > "$work/$t.log" 2>&1 &
  pids+=("$!")
done
failed=()
i=0
for t in $TARGETS; do
  rc=0; wait "${pids[$i]}" || rc=$?
  i=$((i + 1))
  echo "--- fuzz $t (exit status $rc) ---"
  tail -n 15 "$work/$t.log"
  [ "$rc" -eq 0 ] || failed+=("$t")
done
rm -rf "$work"
if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz: ${failed[*]} failed (a crash, a leak or a timeout; the log above names the input)"; exit 1
fi
step "fuzz: every input that once crashed these targets (fuzz/regressions/) runs clean"
for f in fuzz/regressions/*/*; do
  [ -f "$f" ] || continue
  t=$(basename "$(dirname "$f")")
  case " $TARGETS " in *" $t "*) ;; *) continue ;; esac
  feat=(); if [ "$t" = host_inputs ]; then feat=(--features host); fi
  (cd fuzz && cargo "${FUZZ_TC[@]}" fuzz run -s none "${feat[@]}" --target-dir "$FUZZ_TARGET" \
    "$t" "../$f" -- -runs=1)
done
unset RUSTC_BOOTSTRAP
