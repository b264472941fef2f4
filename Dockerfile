# viewsynth for GPU servers: a build stage with the Rust toolchain, and a slim Debian runtime with
# glvnd's libEGL, Mesa (software fallback), the glvnd vendor file for NVIDIA's EGL, and the Python
# package (its wheel built in the build stage; the runtime holds only the wheel, numpy
# and Pillow).
#
#   docker build -t viewsynth .
#   docker run --rm --gpus all -e NVIDIA_DRIVER_CAPABILITIES=graphics,utility \
#       -v "$PWD/out:/work/out" --user "$(id -u):$(id -g)" viewsynth
#       NVIDIA: the toolkit mounts libEGL_nvidia.so.0 only with the `graphics` capability;
#       prints `info` (every EGL device, which one `auto` picks), then runs the demo into
#       ./out/demo. ci/docker-smoke.sh builds the image and tries it.
#   docker run --rm --gpus all -e NVIDIA_DRIVER_CAPABILITIES=graphics,utility \
#       -e VIEWSYNTH_REQUIRE_GPU=1 -v "$PWD:/work" viewsynth refocus ...
#       fails (exit 1) instead of rendering on llvmpipe when the GPU is not reachable.
#   docker run --rm viewsynth info
#       no GPU: Mesa llvmpipe (software), said as much by `info`.
#   docker run --rm --gpus all -e NVIDIA_DRIVER_CAPABILITIES=graphics,utility \
#       -v "$PWD:/work" viewsynth python3 my_augment.py
#       the Python package (`import viewsynth`, numpy in and out) in /opt/viewsynth, a venv whose
#       python3 comes first on PATH; `python`, `python3` and `pip` as the first argument run
#       themselves instead of `viewsynth`. The venv (numpy and Pillow too) belongs to the image's
#       user, so `FROM viewsynth` and `RUN pip install ...` extend it as that user.
# Outputs go under /work (the working directory, owned by the non-root user `viewsynth`, uid
# 1000): mount a host folder there or at /work/out, e.g. -v "$PWD/out:/work/out" --user
# "$(id -u):$(id -g)"; without one the entry point says the outputs will be lost, and how to
# mount. (No VOLUME: one at /work/out would hide the out/ of a folder mounted at /work.)

FROM rust:1-bookworm AS build
# glslangValidator: build.rs compiles the Vulkan backend's shaders to SPIR-V. python3 and a venv
# with maturin: the Python package's wheel (python/), as `pip install ./python` builds it.
RUN apt-get update -qq \
 && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
      glslang-tools python3 python3-venv \
 && rm -rf /var/lib/apt/lists/*
RUN python3 -m venv /opt/maturin \
 && /opt/maturin/bin/pip install -q --no-cache-dir --disable-pip-version-check "maturin>=1.7,<2"
WORKDIR /src
# One target dir for the binary and the extension: the extension's build reuses the viewsynth
# library and the dependencies the binary's build made (same profile, same versions).
ENV CARGO_TARGET_DIR=/src/target PYO3_PYTHON=python3
# Dependencies first, in their own layer: placeholder crates with the real manifests and lock
# files build every dependency, so editing src/, lab/, cli/, shaders/ or python/ rebuilds only
# the workspace's crates and the extension. The root placeholder has a stand-in build.rs too, so
# that the build script's own dependencies (gl_generator and the Khronos registries) are built in
# this layer; the real build.rs reads shaders/ and comes with the sources. The placeholders'
# outputs are removed: the real crates are never taken as built. The library's test crate
# (viewsynth_tests/) is a workspace member the image never builds: its manifest and an empty
# lib.rs are enough for cargo to load the workspace.
COPY Cargo.toml Cargo.lock ./
COPY lab/Cargo.toml lab/
COPY cli/Cargo.toml cli/
COPY viewsynth_tests/Cargo.toml viewsynth_tests/
COPY python/Cargo.toml python/Cargo.lock python/
RUN mkdir -p src lab/src cli/src python/src viewsynth_tests/src \
 && echo '' > src/lib.rs \
 && echo '' > lab/src/lib.rs \
 && echo 'fn main() {}' > cli/src/main.rs \
 && echo '' > viewsynth_tests/src/lib.rs \
 && echo 'fn main() {}' > build.rs \
 && echo '' > python/src/lib.rs \
 && cargo build --release --locked --bin viewsynth \
 && cargo build --release --locked --manifest-path python/Cargo.toml \
 && rm -rf src lab/src cli/src build.rs python/src target/release/.fingerprint/viewsynth-* \
      target/release/build/viewsynth-* target/release/deps/viewsynth-* target/release/deps/viewsynth_* \
      target/release/deps/libviewsynth-* target/release/deps/libviewsynth_* target/release/viewsynth \
      target/release/deps/_viewsynth* target/release/deps/lib_viewsynth* target/release/lib_viewsynth*
COPY build.rs ./
COPY src src
COPY lab/src lab/src
COPY cli/src cli/src
COPY shaders shaders
RUN cargo build --release --locked --bin viewsynth
# The wheel (abi3: any CPython >= 3.9), stripped, then installed with numpy into the venv the
# runtime stage copies: /opt/viewsynth, on the same Debian python3 as the runtime's.
COPY python/pyproject.toml python/
COPY python/src python/src
COPY python/viewsynth python/viewsynth
# With the `examples` extra (Pillow): the README's Python quick start reads PNGs with it.
RUN /opt/maturin/bin/maturin build --release --locked --strip --manifest-path python/Cargo.toml \
      --interpreter python3 --out /wheels \
 && python3 -m venv /opt/viewsynth \
 && /opt/viewsynth/bin/pip install -q --no-cache-dir --disable-pip-version-check "$(echo /wheels/viewsynth-*.whl)[examples]" \
 && /opt/viewsynth/bin/python -c "import viewsynth, numpy, PIL; print('viewsynth', viewsynth.__version__, 'numpy', numpy.__version__, 'Pillow', PIL.__version__)"

FROM debian:bookworm-slim
RUN apt-get update -qq \
 && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
      libegl1 libegl-mesa0 libgl1-mesa-dri libgles2 libvulkan1 mesa-vulkan-drivers ca-certificates \
      python3 \
 && rm -rf /var/lib/apt/lists/*
# glvnd finds EGL vendors through these JSON files. The NVIDIA toolkit mounts libEGL_nvidia.so.0
# (with NVIDIA_DRIVER_CAPABILITIES including graphics) but not always this file; without it only
# Mesa's software renderer would be found. Where the library is absent glvnd skips the vendor,
# and viewsynth does not count the file as a sign of a driver.
RUN mkdir -p /usr/share/glvnd/egl_vendor.d \
 && printf '{"file_format_version":"1.0.0","ICD":{"library_path":"libEGL_nvidia.so.0"}}\n' \
      > /usr/share/glvnd/egl_vendor.d/10_nvidia.json
ENV NVIDIA_VISIBLE_DEVICES=all \
    NVIDIA_DRIVER_CAPABILITIES=graphics,utility \
    PATH=/opt/viewsynth/bin:$PATH
RUN useradd --create-home --uid 1000 --user-group viewsynth \
 && mkdir -p /work/out && chown -R viewsynth:viewsynth /work
COPY --from=build /src/target/release/viewsynth /usr/local/bin/viewsynth
# The venv belongs to the image's user, so that `FROM viewsynth` + `RUN pip install ...` (run as
# that user) adds packages to it without a switch to root.
COPY --from=build --chown=viewsynth:viewsynth /opt/viewsynth /opt/viewsynth
COPY docker/entrypoint.sh /usr/local/bin/viewsynth-entrypoint
USER viewsynth
WORKDIR /work
ENTRYPOINT ["viewsynth-entrypoint"]
CMD []
