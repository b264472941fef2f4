#!/bin/sh
# The image's entry point. With no arguments: show what this container renders with
# (`viewsynth info`: renderer, every EGL device, which one `auto` picks), then run the demo
# into /work/out/demo. With arguments: run `viewsynth` with them (`docker run IMAGE refocus ...`).
set -e
if [ "$#" -eq 0 ]; then
    viewsynth info
    exec viewsynth demo --out-dir out/demo
fi
exec viewsynth "$@"
