#!/usr/bin/env bash
# The one command that checks everything the project checks (README: "Run all tests").
# Installs what it needs when missing. Keep the whole run well inside CI's 90 minutes on
# 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$(pwd)

step() { printf '\n==> %s\n' "$*"; }

# --- tools -----------------------------------------------------------------------------
need_apt=()
command -v /usr/bin/rustc >/dev/null 2>&1 && [ -d /usr/lib/rustlib/src/rust/library ] || need_apt+=(rustc-web cargo-web rust-web-src)
command -v ld.lld-19 >/dev/null 2>&1 || need_apt+=(lld-19)
command -v qemu-system-arm >/dev/null 2>&1 || need_apt+=(qemu-system-arm)
if [ ${#need_apt[@]} -gt 0 ]; then
  step "installing ${need_apt[*]} (Debian packages for the Cortex-M4F build and QEMU)"
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq "${need_apt[@]}" >/dev/null
fi

# --- host -------------------------------------------------------------------------------
step "cargo fmt --check"
cargo fmt --all --check

step "cargo clippy (workspace, all targets, -D warnings)"
cargo clippy --workspace --all-targets -- -D warnings

step "cargo test (workspace, release: the end-to-end tests run real scenes)"
cargo test --workspace --release

step "cargo test curbtrace-core with micromath (its rho against libm's, differential test)"
cargo test -p curbtrace-core --release --features micromath

# --- no_std core for the Cortex-M4F -----------------------------------------------------
for feat in libm micromath; do
  step "curbtrace-core for thumbv7em-none-eabihf (Debian toolchain, feature $feat)"
  RUSTC_BOOTSTRAP=1 RUSTC=/usr/bin/rustc CARGO_TARGET_DIR="$ROOT/target/thumb" \
    /usr/bin/cargo build -p curbtrace-core --release --target thumbv7em-none-eabihf \
    -Zbuild-std=core --no-default-features --features "$feat"
done

echo
echo "all checks passed"
