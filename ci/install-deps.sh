#!/usr/bin/env bash
# System packages viewsynth needs at build and run time: glvnd's libEGL with Mesa as the vendor
# (llvmpipe software rendering, EGL device + surfaceless platforms), and a Rust toolchain when
# none is installed. Used by .ci/run, the README and the Dockerfile.
set -euo pipefail

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi

PKGS=(libegl1 libegl-mesa0 libgl1-mesa-dri libgles2 ca-certificates curl pkg-config)
# The Python package's build and tests (ci/python-tests.sh): an interpreter with venv + ensurepip.
PKGS+=(python3 python3-venv)
missing=()
for p in "${PKGS[@]}"; do
  dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
done
if [ "${#missing[@]}" -gt 0 ]; then
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" build-essential
fi

if ! command -v cargo >/dev/null 2>&1; then
  if [ -x "$HOME/.cargo/bin/cargo" ]; then
    echo "cargo is in \$HOME/.cargo/bin: run 'source \$HOME/.cargo/env' or add it to PATH" >&2
  else
    curl -sSf https://sh.rustup.rs | sh -s -- -y --profile minimal
    echo "installed Rust; run 'source \$HOME/.cargo/env' before cargo" >&2
  fi
fi
