#!/usr/bin/env bash
# System packages viewsynth needs at build and run time: glvnd's libEGL with Mesa as the vendor
# (llvmpipe software rendering, EGL device + surfaceless platforms), the Vulkan loader with Mesa
# lavapipe and glslang (SPIR-V at build time), a C toolchain for linking,
# and a Rust toolchain >= MIN_RUST with rustfmt and clippy (installed with rustup, profile
# minimal, when cargo is missing or older). Used by .ci/run, the README and the Dockerfile.
#
# Runs as root, or as a user with sudo. Rust goes to $HOME/.cargo (rustup also adds it to the
# shell profile for new shells); afterwards, in the same shell,
#   export PATH="$HOME/.cargo/bin:$PATH"
# (printed at the end when needed).
set -euo pipefail

# Keep in step with rust-version in Cargo.toml.
MIN_RUST=1.88
RUSTUP_URL=${VIEWSYNTH_RUSTUP_URL:-https://sh.rustup.rs}

die() {
  echo "install-deps: $*" >&2
  exit 1
}

# --- system packages -------------------------------------------------------------------------
PKGS=(libegl1 libegl-mesa0 libgl1-mesa-dri libgles2 ca-certificates curl pkg-config build-essential)
# The Python package's build and tests (ci/python-tests.sh): an interpreter with venv + ensurepip.
PKGS+=(python3 python3-venv)
# The Vulkan backend (--backend vulkan, its tests): the loader, Mesa's lavapipe (software
# Vulkan) and glslangValidator, which build.rs runs to compile the shaders to SPIR-V.
PKGS+=(libvulkan1 mesa-vulkan-drivers glslang-tools)
# The Khronos validation layer: a test runs one case of every Vulkan pass under it and fails on
# any message (viewsynth_tests/tests/library/vulkan/passes.rs).
PKGS+=(vulkan-validationlayers)
missing=()
if command -v dpkg >/dev/null 2>&1; then
  for p in "${PKGS[@]}"; do
    dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
  done
else
  die "no dpkg: this script knows Debian/Ubuntu only; install by hand: ${PKGS[*]} (or your distribution's equivalents)"
fi

if [ "${#missing[@]}" -gt 0 ]; then
  if [ "$(id -u)" -eq 0 ]; then
    SUDO=()
  elif command -v sudo >/dev/null 2>&1; then
    SUDO=(sudo)
  else
    die "missing packages: ${missing[*]}; run this script as root, or install sudo, or install them yourself: apt-get install ${missing[*]}"
  fi
  export DEBIAN_FRONTEND=noninteractive
  echo "install-deps: installing ${missing[*]}" >&2
  ${SUDO[@]+"${SUDO[@]}"} apt-get update -qq || die "apt-get update failed (offline? no apt sources?)"
  ${SUDO[@]+"${SUDO[@]}"} env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" ||
    die "apt-get install ${missing[*]} failed"
fi

# --- Rust ------------------------------------------------------------------------------------
# "cargo 1.63.0 (...)" -> 0 if at least MIN_RUST, 1 otherwise (or when cargo does not run).
cargo_recent_enough() {
  local v
  v=$("$1" --version 2>/dev/null | awk '{print $2}') || return 1
  [ -n "$v" ] || return 1
  awk -v have="$v" -v need="$MIN_RUST" 'BEGIN {
    split(have, h, "."); split(need, n, ".");
    if (h[1] + 0 != n[1] + 0) exit !(h[1] + 0 > n[1] + 0);
    exit !(h[2] + 0 >= n[2] + 0) }'
}

# rustup's cargo wins over a distribution's (e.g. Debian 12's cargo 1.63), as after the PATH line.
CARGO_BIN="$HOME/.cargo/bin"
ORIGINAL_PATH=$PATH
export PATH="$CARGO_BIN:$PATH"

found=$(command -v cargo || true)
if [ -n "$found" ] && cargo_recent_enough "$found"; then
  echo "install-deps: $("$found" --version) at $found" >&2
else
  if [ -n "$found" ]; then
    echo "install-deps: $("$found" --version 2>/dev/null || echo "$found") is older than $MIN_RUST: installing a current stable toolchain with rustup" >&2
  else
    echo "install-deps: no cargo: installing Rust (stable) with rustup" >&2
  fi
  if command -v rustup >/dev/null 2>&1; then
    rustup toolchain install stable --profile minimal --component rustfmt,clippy ||
      die "rustup toolchain install stable failed (offline?)"
    rustup default stable
  else
    init=$(mktemp)
    trap 'rm -f "$init"' EXIT
    if ! curl --proto '=https' --tlsv1.2 -sSf --retry 2 --connect-timeout 20 "$RUSTUP_URL" -o "$init"; then
      die "could not download rustup from $RUSTUP_URL (offline, or a proxy/firewall in the way?).
  Install Rust >= $MIN_RUST with rustfmt and clippy yourself (https://rustup.rs), then run this script again."
    fi
    sh "$init" -y --profile minimal --default-toolchain stable --component rustfmt,clippy ||
      die "rustup-init failed (offline?); install Rust >= $MIN_RUST yourself (https://rustup.rs)"
  fi
  found=$(command -v cargo || true)
  [ -n "$found" ] && cargo_recent_enough "$found" ||
    die "after installing, cargo is still missing or older than $MIN_RUST (${found:-not found})"
  echo "install-deps: installed $("$found" --version) in $CARGO_BIN" >&2
fi

# .ci/run checks formatting and lints: rustfmt and clippy must be there too.
if ! cargo fmt --version >/dev/null 2>&1 || ! cargo clippy --version >/dev/null 2>&1; then
  if command -v rustup >/dev/null 2>&1; then
    rustup component add rustfmt clippy || die "rustup component add rustfmt clippy failed (offline?)"
  else
    echo "install-deps: warning: cargo fmt / cargo clippy missing and no rustup to add them" >&2
  fi
fi

case ":$ORIGINAL_PATH:" in
  *":$CARGO_BIN:"*) ;;
  *)
    if [ "$(command -v cargo)" = "$CARGO_BIN/cargo" ]; then
      echo "install-deps: done. In this shell, before cargo, run:" >&2
      echo "  export PATH=\"\$HOME/.cargo/bin:\$PATH\"" >&2
    fi
    ;;
esac
