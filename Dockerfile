# Multi-stage build: compile with the Rust image, run on a slim Debian with glvnd's libEGL.
# Rendering picks NVIDIA's EGL when the NVIDIA container toolkit mounts it
#   docker run --gpus all -e NVIDIA_DRIVER_CAPABILITIES=graphics,compute,utility viewsynth info
# and falls back to Mesa llvmpipe (software) otherwise:
#   docker run viewsynth info
FROM rust:1-bookworm AS build
WORKDIR /src
COPY Cargo.toml Cargo.lock rustfmt.toml ./
COPY src src
COPY shaders shaders
RUN cargo build --release --locked --bin viewsynth

FROM debian:bookworm-slim
COPY ci/install-deps.sh /tmp/install-deps.sh
# install-deps.sh would fetch Rust if cargo were missing; the runtime only needs the EGL packages.
RUN apt-get update -qq \
 && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
      libegl1 libegl-mesa0 libgl1-mesa-dri libgles2 ca-certificates \
 && rm -rf /var/lib/apt/lists/* /tmp/install-deps.sh
# glvnd picks EGL vendors from these JSON files, lowest number first. The NVIDIA toolkit mounts
# libEGL_nvidia.so.0 but not always this file; without it only Mesa would be found.
RUN mkdir -p /usr/share/glvnd/egl_vendor.d \
 && printf '{"file_format_version":"1.0.0","ICD":{"library_path":"libEGL_nvidia.so.0"}}\n' \
      > /usr/share/glvnd/egl_vendor.d/10_nvidia.json
ENV NVIDIA_DRIVER_CAPABILITIES=graphics,compute,utility
COPY --from=build /src/target/release/viewsynth /usr/local/bin/viewsynth
WORKDIR /work
ENTRYPOINT ["viewsynth"]
CMD ["info"]
