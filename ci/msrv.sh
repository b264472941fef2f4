#!/usr/bin/env bash
# Builds (cargo check) the whole workspace, every target, with the toolchain the manifests
# declare as rust-version (tests/msrv.rs holds that equal to what the lock file needs). Installs
# that toolchain through rustup (profile minimal) when it is missing; fails, never skips, when
# rustup is not there to do it. Its own target dir, so the main build's is not invalidated.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ -f "$HOME/.cargo/env" ]; then . "$HOME/.cargo/env"; fi
msrv=$(sed -n 's/^rust-version = "\(.*\)"/\1/p' Cargo.toml | head -1)
[ -n "$msrv" ] || { echo "msrv: no rust-version in Cargo.toml" >&2; exit 1; }
command -v rustup >/dev/null || { echo "msrv: rustup is needed to install Rust $msrv" >&2; exit 1; }
rustup toolchain list | grep -q "^$msrv-" || rustup toolchain install "$msrv" --profile minimal
echo "msrv: cargo +$msrv check --workspace --all-targets --locked"
CARGO_TARGET_DIR=${VIEWSYNTH_MSRV_TARGET:-target/msrv} cargo "+$msrv" check --workspace --all-targets --locked
