#!/usr/bin/env bash
# Every example of README.md, of each docs/ page and of each command's --help, run as written:
# each ```sh and ```python block in order (see ci/readme_examples.py for the order), in a
# scratch folder laid out as the README assumes (the repository root, ../shared/data beside it),
# each `# => ...` line the README states checked against the block's output (a stale figure
# fails). Called by .ci/run after the Rust tests (target/release/viewsynth) and
# ci/python-tests.sh (its venv holds the package and Pillow/Ray for the Python examples); run by
# hand, it needs the same. The commands it replaces (cargo install, pip install, docker, ...)
# are listed at the end of its output: ci/readme_examples.py.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
BIN="$ROOT/target/release/viewsynth"
VENV="${VIEWSYNTH_PY_VENV:-$ROOT/target/python-venv}"
DATA="${VIEWSYNTH_DATA_DIR:-$ROOT/../shared/data}"

die() {
  echo "readme-examples: $*" >&2
  exit 1
}
[ -x "$BIN" ] || die "$BIN missing: run \`cargo build --release\` (or .ci/run) first"
[ -x "$VENV/bin/python" ] || die "$VENV missing: run ci/python-tests.sh first (it installs the package there)"
[ -d "$DATA" ] || die "test data missing: $DATA (fetch it with python3 ci/fetch-data.py, or set VIEWSYNTH_DATA_DIR)"
DATA=$(cd "$DATA" && pwd)

SCRATCH=$(mktemp -d "${TMPDIR:-/tmp}/viewsynth-readme.XXXXXX")
trap 'rm -rf "$SCRATCH"' EXIT
# The repository's tracked top-level entries, linked, so `./ci/...`, `python/...` and `.` are
# there; out/ is the scratch's own. ../shared/data is the test data.
mkdir -p "$SCRATCH/repo" "$SCRATCH/shared" "$SCRATCH/bin"
git ls-files | cut -d/ -f1 | sort -u | while read -r entry; do
  ln -s "$ROOT/$entry" "$SCRATCH/repo/$entry"
done
ln -s "$DATA" "$SCRATCH/shared/data"
ln -s "$BIN" "$SCRATCH/bin/viewsynth"

export VIEWSYNTH_BIN="$BIN"
export PATH="$SCRATCH/bin:$VENV/bin:$PATH"
python3 ci/readme_examples.py README.md "$SCRATCH" "$@"
