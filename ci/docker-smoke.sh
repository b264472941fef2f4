#!/usr/bin/env bash
# Builds the Docker image and tries it: `info`, a refocus into a mounted folder as a non-root
# uid, the Python package (a numpy frame refocused from `python3` in the container), the README's
# Python quick start, a derived image (`FROM` it, `RUN pip install` into its venv), the
# no-argument run (demo, and where its outputs went), and the VIEWSYNTH_REQUIRE_GPU=1 refusal of
# a software renderer. Prints the build time and the image size.
#
# Not part of .ci/run (it compiles the whole crate and the Python extension, 10 to 40 minutes on
# 2 cores): run it after changing the Dockerfile, docker/, python/, .dockerignore or the build.
# Needs root (or a docker group member) and the test data (../shared/data or VIEWSYNTH_DATA_DIR).
#
# Where no image registry is reachable, it makes the base images itself: a Debian bookworm root
# from debootstrap, imported as debian:bookworm-slim, and rust:1-bookworm built on it from this
# machine's Rust toolchain. Where no daemon runs, it starts one as
# `dockerd --iptables=false --bridge=none --storage-driver=overlay2` (vfs where overlay cannot be
# mounted; builds then use --network host).
#
#   VIEWSYNTH_IMAGE   tag to build (viewsynth:smoke)
#   DEBIAN_MIRROR     debootstrap mirror (http://deb.debian.org/debian)
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
IMAGE=${VIEWSYNTH_IMAGE:-viewsynth:smoke}
DATA=${VIEWSYNTH_DATA_DIR:-$ROOT/../shared/data}
MIRROR=${DEBIAN_MIRROR:-http://deb.debian.org/debian}
WORK=$(mktemp -d "${TMPDIR:-/tmp}/viewsynth-docker.XXXXXX")
DOCKERD_PID=

say() { echo "docker-smoke: $*" >&2; }
die() {
  say "FAILED: $*"
  exit 1
}
cleanup() {
  rm -rf "$WORK"
  if [ -n "$DOCKERD_PID" ]; then
    say "stopping the dockerd this script started (pid $DOCKERD_PID)"
    kill "$DOCKERD_PID" 2>/dev/null || true
    wait "$DOCKERD_PID" 2>/dev/null || true
  fi
}
trap cleanup EXIT
[ -d "$DATA" ] || die "test data missing: $DATA (fetch it with python3 ci/fetch-data.py, or set VIEWSYNTH_DATA_DIR)"
DATA=$(cd "$DATA" && pwd)
command -v docker >/dev/null || die "no docker client (Debian: apt-get install docker.io)"

# --- a daemon ----------------------------------------------------------------------------------
# Storage: overlay2 keeps each layer's changes only; vfs copies the whole tree per layer (over
# 30 GB for this build's 30-odd steps), so it is the fallback where overlay cannot be mounted.
start_dockerd() {
  say "starting dockerd ($1 storage, no bridge, no iptables)"
  dockerd --iptables=false --bridge=none --storage-driver="$1" >"$WORK/dockerd.log" 2>&1 &
  DOCKERD_PID=$!
  for _ in $(seq 60); do
    docker info >/dev/null 2>&1 && return 0
    if ! kill -0 "$DOCKERD_PID" 2>/dev/null; then
      wait "$DOCKERD_PID" 2>/dev/null || true
      DOCKERD_PID=
      return 1
    fi
    sleep 1
  done
  die "dockerd did not answer within 60 s: $(tail -5 "$WORK/dockerd.log")"
}
if ! docker info >/dev/null 2>&1; then
  command -v dockerd >/dev/null || die "no docker daemon and no dockerd to start (Debian: apt-get install docker.io)"
  [ "$(id -u)" -eq 0 ] || die "no docker daemon running, and starting one needs root"
  start_dockerd overlay2 || {
    say "overlay2 refused ($(tail -1 "$WORK/dockerd.log")): vfs instead"
    start_dockerd vfs || die "dockerd exited: $(tail -5 "$WORK/dockerd.log")"
  }
fi

# --- base images ---------------------------------------------------------------------------------
have() { docker image inspect "$1" >/dev/null 2>&1; }
if ! have debian:bookworm-slim && ! docker pull -q debian:bookworm-slim >/dev/null 2>&1; then
  command -v debootstrap >/dev/null || die "debian:bookworm-slim cannot be pulled and there is no debootstrap (apt-get install debootstrap)"
  say "no registry: debootstrap a bookworm root as debian:bookworm-slim (a few minutes)"
  t0=$(date +%s)
  debootstrap --variant=minbase bookworm "$WORK/rootfs" "$MIRROR" >"$WORK/debootstrap.log" 2>&1 ||
    die "debootstrap failed: $(tail -5 "$WORK/debootstrap.log")"
  rm -rf "$WORK/rootfs/var/cache/apt/archives/"*.deb "$WORK/rootfs/var/lib/apt/lists/"*
  tar -C "$WORK/rootfs" -c . | docker import - debian:bookworm-slim >/dev/null
  rm -rf "$WORK/rootfs"
  say "debian:bookworm-slim made in $(($(date +%s) - t0)) s"
fi
if ! have rust:1-bookworm && ! docker pull -q rust:1-bookworm >/dev/null 2>&1; then
  command -v rustc >/dev/null || die "rust:1-bookworm cannot be pulled and this machine has no Rust toolchain to build it from"
  SYSROOT=$(rustc --print sysroot)
  say "no registry: rust:1-bookworm from this machine's toolchain ($("$SYSROOT/bin/rustc" --version))"
  # The official image's layout: the toolchain under /usr/local, a C and C++ toolchain (linking,
  # and nv-flip-sys's C++).
  mkdir -p "$WORK/rust/ca"
  tar -C "$SYSROOT" -c bin/cargo bin/rustc bin/rustdoc lib libexec | tar -C "$WORK/rust" -x
  # This machine's own CA certificates (a TLS-intercepting proxy's, say): cargo in the image
  # then reaches crates.io as cargo here does.
  find /usr/local/share/ca-certificates -name '*.crt' -exec cp {} "$WORK/rust/ca/" \; 2>/dev/null || true
  cat >"$WORK/rust/Dockerfile" <<'EOF'
FROM debian:bookworm-slim
RUN apt-get update -qq \
 && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
      ca-certificates gcc g++ libc6-dev pkg-config \
 && rm -rf /var/lib/apt/lists/*
COPY ca /usr/local/share/ca-certificates
RUN update-ca-certificates
COPY bin /usr/local/bin
COPY lib /usr/local/lib
COPY libexec /usr/local/libexec
ENV CARGO_HOME=/usr/local/cargo PATH=/usr/local/cargo/bin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin
RUN ldconfig && cargo --version && rustc --version
EOF
  docker build -q --network host -t rust:1-bookworm "$WORK/rust" >/dev/null || die "building rust:1-bookworm failed"
  rm -rf "$WORK/rust"
fi

# --- the image -----------------------------------------------------------------------------------
say "building $IMAGE"
t0=$(date +%s)
docker build --network host -t "$IMAGE" . >"$WORK/build.log" 2>&1 || {
  tail -30 "$WORK/build.log" >&2
  die "docker build failed"
}
BUILD_S=$(($(date +%s) - t0))
SIZE=$(docker image inspect "$IMAGE" --format '{{.Size}}')
say "built $IMAGE in ${BUILD_S} s; image size $((SIZE / 1000000)) MB"

run() { docker run --rm --network none "$@"; }

# info: the renderer and the devices.
out=$(run "$IMAGE" info) || die "info failed"
grep -q "^renderer:" <<<"$out" || die "info printed no renderer: $out"
grep -q "^EGL devices:" <<<"$out" || die "info printed no EGL devices: $out"
say "info: $(grep '^renderer:' <<<"$out")"

# A refocus into a mounted folder as a non-root uid other than the image's (1000).
mkdir -p "$WORK/mnt/out"
chown -R 1234:1234 "$WORK/mnt"
run --user 1234:1234 -v "$WORK/mnt:/work" -v "$DATA:/data:ro" "$IMAGE" \
  refocus --rgb /data/rgbd_open3d_testdata/TUM_color.png --depth /data/rgbd_open3d_testdata/TUM_depth.png \
  --depth-scale 5000 --fx 525 --fy 525 --cx 319.5 --cy 239.5 --zoom-range 0.5,2 --out-dir out/tum \
  >"$WORK/refocus.log" 2>&1 || die "refocus failed: $(cat "$WORK/refocus.log")"
for f in s0.5_rgb.png s2_depth.exr s2_mask.png manifest.json; do
  [ -f "$WORK/mnt/out/tum/$f" ] || die "refocus did not write out/tum/$f into the mounted folder"
done
[ "$(stat -c %u "$WORK/mnt/out/tum/manifest.json")" = 1234 ] || die "the outputs are not owned by the container's uid"
grep -q "not a mounted folder" "$WORK/refocus.log" && die "the entry point warned although /work is mounted"
say "refocus as uid 1234 into a mounted folder: $(ls "$WORK/mnt/out/tum" | wc -l) files"

# The Python package: TUM's depth read by viewsynth.read_depth, a colour frame made in numpy and
# passed as a strided view (BGR reversed to RGB), refocused at s = 1 and 2. At s = 1 the output
# colour equals the input wherever the mask says the geometry is valid.
cat >"$WORK/smoke.py" <<'EOF'
import numpy as np
import viewsynth as vs

depth = vs.read_depth("/data/rgbd_open3d_testdata/TUM_depth.png", depth_scale=5000)
h, w = depth.shape
yy, xx = np.mgrid[0:h, 0:w]
bgr = np.stack([xx * 255 // (w - 1), yy * 255 // (h - 1), (3 * xx + 5 * yy) % 256], axis=-1).astype(np.uint8)
rgb = bgr[..., ::-1]
K = np.array([[525.0, 0, 319.5], [0, 525.0, 239.5], [0, 0, 1]])
one, two = vs.Renderer().refocus(rgb, depth, K, scales=[1.0, 2.0])
assert one["rgb"].shape == (h, w, 3) and two["rgb"].shape == (h, w, 3), (one["rgb"].shape, two["rgb"].shape)
valid = np.asarray(one["mask"]).astype(bool)
assert valid.sum() > 0.5 * h * w, f"only {valid.sum()} valid pixels at s = 1"
diff = np.abs(one["rgb"].astype(int) - rgb.astype(int)).max(axis=-1)[valid]
assert diff.max() <= 1, f"s = 1 colour differs from the input by up to {diff.max()} levels"
print(
    f"python: viewsynth {vs.__version__}, numpy {np.__version__}: refocused a {w}x{h} numpy frame "
    f"(strided RGB view, depth from read_depth) at s = 1, 2; at s = 1 the colour equals the input "
    f"on all {valid.sum()} valid pixels (max diff {diff.max()} levels)"
)
EOF
chmod 644 "$WORK/smoke.py"
out=$(run -v "$DATA:/data:ro" -v "$WORK/smoke.py:/smoke.py:ro" "$IMAGE" python3 /smoke.py 2>&1) ||
  die "the Python step failed: $out"
line=$(grep '^python: viewsynth' <<<"$out") || die "the Python step printed no result: $out"
say "$line"

# The README's Python quick start (its first ```python block after "## Quick start: Python"), run
# in the image from /work with the data at /shared/data (so its ../shared/data/ paths hold), its
# stated `# =>` outputs checked as ci/readme-examples.sh checks them.
python3 - "$ROOT" "$WORK/quickstart.py" <<'PY'
import sys
sys.path.insert(0, sys.argv[1] + "/ci")
from readme_examples import blocks
readme = open(sys.argv[1] + "/README.md", encoding="utf-8").read()
heading = readme.splitlines().index("## Quick start: Python") + 1
text = next(t for kind, line, t in blocks(readme) if kind == "python" and line > heading)
open(sys.argv[2], "w", encoding="utf-8").write(text)
PY
chmod 644 "$WORK/quickstart.py"
out=$(run -v "$DATA:/shared/data:ro" -v "$WORK/quickstart.py:/quickstart.py:ro" "$IMAGE" python3 /quickstart.py 2>&1) ||
  die "the README's Python quick start failed in the image: $out"
missing=$(
  python3 - "$ROOT" "$WORK/quickstart.py" "$out" <<'PY'
import sys
sys.path.insert(0, sys.argv[1] + "/ci")
from readme_examples import expectations, found
stated = expectations(open(sys.argv[2], encoding="utf-8").read())
print("; ".join(e for e in stated if not found(e, sys.argv[3])) if stated else "(it states no output)")
PY
)
[ -z "$missing" ] || die "the README's Python quick start did not print: $missing (it printed: $out)"
say "README Python quick start in the image: $(grep -v -e '^note:' -e '^ ' <<<"$out" | tr '\n' ';')"

# A derived image, as docs/docker.md says to extend it: `FROM $IMAGE` + `RUN pip install`, run as
# the image's user. It installs a one-module wheel made here (zipfile: no index needed), so the
# step proves that pip can write the image's venv, whatever the network.
DERIVED=$IMAGE-derived
mkdir -p "$WORK/derived"
python3 - "$WORK/derived" <<'PY'
import base64, hashlib, sys, zipfile
name = "viewsynth_smoke_ext-0.1"
files = {
    "viewsynth_smoke_ext.py": "MESSAGE = 'installed by RUN pip install in a derived image'\n",
    f"{name}.dist-info/METADATA": "Metadata-Version: 2.1\nName: viewsynth-smoke-ext\nVersion: 0.1\n",
    f"{name}.dist-info/WHEEL": "Wheel-Version: 1.0\nGenerator: docker-smoke\nRoot-Is-Purelib: true\nTag: py3-none-any\n",
}
def digest(text):
    return "sha256=" + base64.urlsafe_b64encode(hashlib.sha256(text.encode()).digest()).rstrip(b"=").decode()
record = "".join(f"{path},{digest(text)},{len(text.encode())}\n" for path, text in files.items())
files[f"{name}.dist-info/RECORD"] = record + f"{name}.dist-info/RECORD,,\n"
with zipfile.ZipFile(f"{sys.argv[1]}/{name}-py3-none-any.whl", "w") as whl:
    for path, text in files.items():
        whl.writestr(path, text)
PY
cat >"$WORK/derived/Dockerfile" <<DOCKERFILE
FROM $IMAGE
COPY viewsynth_smoke_ext-0.1-py3-none-any.whl /tmp/
RUN pip install --no-index --no-cache-dir /tmp/viewsynth_smoke_ext-0.1-py3-none-any.whl
DOCKERFILE
docker build --network host -t "$DERIVED" "$WORK/derived" >"$WORK/derived.log" 2>&1 ||
  die "building the derived image (FROM $IMAGE, RUN pip install) failed: $(tail -15 "$WORK/derived.log")"
out=$(run "$DERIVED" python3 -c "import viewsynth, PIL, viewsynth_smoke_ext as m; print(m.__file__, '-', m.MESSAGE)" 2>&1) ||
  die "the derived image cannot import what it installed: $out"
grep -q "^/opt/viewsynth/lib/python3[.0-9]*/site-packages/viewsynth_smoke_ext.py - " <<<"$out" ||
  die "the derived image's package is not in the image's venv: $out"
say "derived image (FROM $IMAGE, RUN pip install as $(docker image inspect "$DERIVED" --format '{{.Config.User}}')): $(grep '^/opt' <<<"$out")"
docker image rm "$DERIVED" >/dev/null 2>&1 || true

# No arguments, no mount: info, the demo, and the note that its outputs are not kept.
run "$IMAGE" >"$WORK/demo.log" 2>&1 || die "the no-argument run failed: $(tail -20 "$WORK/demo.log")"
grep -q "demo outputs: /work/out/demo inside the container (not kept)" "$WORK/demo.log" ||
  die "the no-argument run did not say where the demo went: $(tail -5 "$WORK/demo.log")"
grep -q -- '-v "$PWD/out:/work/out"' "$WORK/demo.log" || die "the no-argument run did not say how to mount"
say "no-argument run: demo written, and the mount hint given"

# VIEWSYNTH_REQUIRE_GPU=1 refuses the software renderer (no GPU is passed in).
set +e
err=$(run -e VIEWSYNTH_REQUIRE_GPU=1 "$IMAGE" scene --width 8 --height 8 --out-dir /tmp/scene 2>&1)
rc=$?
set -e
[ "$rc" -eq 1 ] || die "VIEWSYNTH_REQUIRE_GPU=1 on llvmpipe: exit $rc, expected 1: $err"
grep -qi "software" <<<"$err" || die "the refusal does not name the software renderer: $err"
say "VIEWSYNTH_REQUIRE_GPU=1: refused (exit 1): $(grep -i software <<<"$err" | head -1)"

echo "docker-smoke: ok: $IMAGE built in ${BUILD_S} s, $((SIZE / 1000000)) MB"
