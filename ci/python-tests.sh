#!/usr/bin/env bash
# The Python package (python/): build and install it as the README says (pip install ./python)
# into a venv under target/, lint its Rust, and run its pytest suite on EGL (llvmpipe without a
# GPU). Run by .ci/run after the Rust tests; the comparison tests call target/release/viewsynth.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ -f "$HOME/.cargo/env" ]; then . "$HOME/.cargo/env"; fi

VENV="${VIEWSYNTH_PY_VENV:-$PWD/target/python-venv}"
python3 -m venv "$VENV"
# Ray (with Ray Data's pandas/pyarrow) runs the Ray example's test; pinned, wheels only (about a
# minute to install). pyrender, for python/bench/bench_pyrender.py only, is not installed.
"$VENV/bin/python" -m pip install -q --disable-pip-version-check --only-binary ray,pyarrow,pandas \
  "maturin>=1.7,<2" numpy pytest pillow "ray[data]==2.60.0"
cargo build --release --locked --bin viewsynth
"$VENV/bin/python" -m pip install -q --disable-pip-version-check --force-reinstall --no-deps ./python

export PYO3_PYTHON="$VENV/bin/python"
cargo fmt --manifest-path python/Cargo.toml --check
cargo clippy --manifest-path python/Cargo.toml --release --locked --all-targets -- -D warnings
# `compare` and nv-flip's C++ are the command line's only: the extension builds without them
# (issue 45; tests/features.rs reads the manifests, this asks cargo).
python_tree=$(cargo tree --manifest-path python/Cargo.toml --locked -e normal,build --prefix none)
if grep -q '^nv-flip ' <<<"$python_tree"; then
  echo "python extension depends on nv-flip: build viewsynth without its compare feature" >&2
  exit 1
fi
# Small single-purpose files: none under python/src over 500 lines (issue 37; each capability's
# Renderer method lives in its own file, so renderer.rs does not grow with each capability).
too_long=$(find python/src -type f -exec awk 'END { if (NR > 500) print FILENAME ": " NR " lines" }' {} \;)
if [ -n "$too_long" ]; then
  echo "python/src files over 500 lines (split them):" >&2
  echo "$too_long" >&2
  exit 1
fi

# From the repository root, so `import viewsynth` is the installed package, not python/viewsynth.
set +e
VIEWSYNTH_CLI="$PWD/target/release/viewsynth" "$VENV/bin/python" -m pytest -q -p no:cacheprovider python/tests
rc=$?
set -e
case $rc in
  0) ;;
  5) echo "python tests: pytest collected no tests (exit 5): failing" >&2; exit 1 ;;
  *) echo "python tests: pytest failed (exit $rc)" >&2; exit "$rc" ;;
esac
