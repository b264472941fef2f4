# viewsynth for GPU servers: a build stage with the Rust toolchain, and a slim Debian runtime with
# glvnd's libEGL, Mesa (software fallback) and the glvnd vendor file for NVIDIA's EGL.
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
# Outputs go under /work (the working directory, owned by the non-root user `viewsynth`, uid
# 1000): mount a host folder there or at /work/out, e.g. -v "$PWD/out:/work/out" --user
# "$(id -u):$(id -g)"; without one the entry point says the outputs will be lost, and how to
# mount. (No VOLUME: one at /work/out would hide the out/ of a folder mounted at /work.)

FROM rust:1-bookworm AS build
# glslangValidator: build.rs compiles the Vulkan backend's shaders to SPIR-V.
RUN apt-get update -qq \
 && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends glslang-tools \
 && rm -rf /var/lib/apt/lists/*
WORKDIR /src
# Dependencies first, in their own layer: a placeholder crate with the real manifest and lock
# file builds every dependency, so editing src/ or shaders/ rebuilds only viewsynth itself. It
# has a stand-in build.rs too, so that the build script's own dependencies (gl_generator and the
# Khronos registries) are built in this layer; the real build.rs reads shaders/ and comes with
# the sources. The placeholder's outputs are removed: the real crate is never taken as built.
COPY Cargo.toml Cargo.lock ./
RUN mkdir -p src/bin/viewsynth \
 && echo '' > src/lib.rs \
 && echo 'fn main() {}' > src/bin/viewsynth/main.rs \
 && echo 'fn main() {}' > build.rs \
 && cargo build --release --locked --bin viewsynth \
 && rm -rf src build.rs target/release/.fingerprint/viewsynth-* target/release/build/viewsynth-* \
      target/release/deps/viewsynth-* target/release/deps/libviewsynth-* target/release/viewsynth
COPY build.rs ./
COPY src src
COPY shaders shaders
RUN cargo build --release --locked --bin viewsynth

FROM debian:bookworm-slim
RUN apt-get update -qq \
 && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
      libegl1 libegl-mesa0 libgl1-mesa-dri libgles2 libvulkan1 mesa-vulkan-drivers ca-certificates \
 && rm -rf /var/lib/apt/lists/*
# glvnd finds EGL vendors through these JSON files. The NVIDIA toolkit mounts libEGL_nvidia.so.0
# (with NVIDIA_DRIVER_CAPABILITIES including graphics) but not always this file; without it only
# Mesa's software renderer would be found. Where the library is absent glvnd skips the vendor,
# and viewsynth does not count the file as a sign of a driver.
RUN mkdir -p /usr/share/glvnd/egl_vendor.d \
 && printf '{"file_format_version":"1.0.0","ICD":{"library_path":"libEGL_nvidia.so.0"}}\n' \
      > /usr/share/glvnd/egl_vendor.d/10_nvidia.json
ENV NVIDIA_VISIBLE_DEVICES=all \
    NVIDIA_DRIVER_CAPABILITIES=graphics,utility
COPY --from=build /src/target/release/viewsynth /usr/local/bin/viewsynth
COPY docker/entrypoint.sh /usr/local/bin/viewsynth-entrypoint
RUN useradd --create-home --uid 1000 --user-group viewsynth \
 && mkdir -p /work/out && chown -R viewsynth:viewsynth /work
USER viewsynth
WORKDIR /work
ENTRYPOINT ["viewsynth-entrypoint"]
CMD []
