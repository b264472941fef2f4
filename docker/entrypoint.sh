#!/bin/sh
# The image's entry point. With no arguments: show what this container renders with
# (`viewsynth info`: renderer, every EGL device, which one `auto` picks), run the demo into
# /work/out/demo, and say where that is. With arguments: run `viewsynth` with them
# (`docker run IMAGE refocus ...`), or, when the first is python, python3 or pip, that program
# (the image's venv with the Python package: `docker run IMAGE python3 augment.py`).
#
# Outputs go under the working directory /work. Unless a host folder is mounted there (or at
# /work/out), they stay inside the container and are lost with it: say so, and how to mount.
set -e

mounted() {
    # Field 5 of /proc/self/mountinfo is the mount point.
    awk '$5 == "/work" || $5 == "/work/out" { found = 1 } END { exit !found }' /proc/self/mountinfo
}

mount_hint() {
    echo "note: /work is not a mounted folder: outputs written here are lost when the container exits." >&2
    echo "      To keep them, mount one, e.g.: docker run --rm -v \"\$PWD/out:/work/out\" --user \"\$(id -u):\$(id -g)\" IMAGE ..." >&2
}

if [ "$#" -eq 0 ]; then
    viewsynth info
    viewsynth demo --out-dir out/demo
    if mounted; then
        echo "demo outputs: /work/out/demo in the container, in the host folder mounted at /work or /work/out"
    else
        echo "demo outputs: /work/out/demo inside the container (not kept)"
        mount_hint
    fi
    exit 0
fi
case "$1" in
    info | bench | help | -h | --help | -V | --version | pip) ;;
    *) mounted || mount_hint ;;
esac
case "$1" in
    python | python3 | pip) exec "$@" ;;
esac
exec viewsynth "$@"
