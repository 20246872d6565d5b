#!/usr/bin/env bash
# Fuzz smoke runs (part of scripts/test.sh): lint fuzz/, then each core target for 20 s from
# its committed corpus and every saved crash of those targets; any crash fails. Installs
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
for t in $TARGETS; do
  step "fuzz: $t for 20 s from fuzz/corpus/$t (any crash fails)"
  work=$(mktemp -d)
  # The smoke runs go without AddressSanitizer (-s none): the core forbids unsafe code,
  # the build is much shorter and the targets run ~8x faster (docs/robustness.md); the
  # long runs in docs/robustness.md used ASan.
  san=(-s none); dir="$FUZZ_TARGET"
  feat=(); if [ "$t" = host_inputs ]; then feat=(--features host); fi
  (cd fuzz && cargo "${FUZZ_TC[@]}" fuzz run "${san[@]}" "${feat[@]}" --target-dir "$dir" \
    "$t" "$work" "corpus/$t" -- -max_total_time=20 -max_len=65536 -rss_limit_mb=2048 \
    -malloc_limit_mb=512 -artifact_prefix="$work/")
  rm -rf "$work"
done
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
