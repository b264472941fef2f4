#!/usr/bin/env bash
# Resume cost per done frame at N frames (issue 44): a batch of N finished frames rerun, every
# frame skipped. One 32x24 frame is rendered, its folder copied to N names (a frame's manifest
# does not name its folder), then each binary reruns the batch; the median wall time of RUNS
# runs, divided by N, is the cost per done frame (process start, GL context and index write
# included: what a user waits). Usage: bench-resume.sh NEW_BIN [OLD_BIN] [N] [RUNS]
# Prints a table and writes resume-bench.json in the working folder.
set -euo pipefail
new=$1 old=${2:-} n=${3:-10000} runs=${4:-3}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
python3 - "$work" <<'PY'
import struct, sys, zlib, os
d = sys.argv[1]
w, h = 32, 24
raw = b"".join(b"\0" + bytes((x * 7 + y * 3) % 251 for x in range(w) for _ in range(3)) for y in range(h))
chunk = lambda t, b: struct.pack(">I", len(b)) + t + b + struct.pack(">I", zlib.crc32(t + b))
open(os.path.join(d, "rgb.png"), "wb").write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)) + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))
hdr = "{'descr': '<f4', 'fortran_order': False, 'shape': (%d, %d), }" % (h, w)
hdr += " " * (63 - (10 + len(hdr)) % 64) + "\n"
open(os.path.join(d, "depth.npy"), "wb").write(b"\x93NUMPY\x01\x00" + struct.pack("<H", len(hdr)) + hdr.encode() + struct.pack("<%df" % (w * h), *[1.0 + 0.01 * (i % w) for i in range(w * h)]))
PY
make_done() { # BIN OUT: render f0 with BIN, then copy it to f1..f(n-1)
  printf 'rgb,depth,fx,fy,cx,cy,name\nrgb.png,depth.npy,40,40,15.5,11.5,f0\n' > "$work/one.csv"
  "$1" refocus --zoom-range 0.5,1.5 --jobs 1 --batch "$work/one.csv" --out-dir "$2" > /dev/null
  rm -f "$2"/index*.jsonl
  for ((i = 1; i < n; i++)); do cp -r "$2/f0" "$2/f$i"; done
}
{ echo 'rgb,depth,fx,fy,cx,cy,name'; for ((i = 0; i < n; i++)); do echo "rgb.png,depth.npy,40,40,15.5,11.5,f$i"; done; } > "$work/frames.csv"
median_ms() { # BIN OUT ARGS...: median wall ms of $runs reruns, checking 0 rendered
  local bin=$1 out=$2; shift 2; local t=()
  for ((r = 0; r < runs; r++)); do
    local t0=$(date +%s%N)
    local line=$("$bin" refocus --zoom-range 0.5,1.5 --batch "$work/frames.csv" --out-dir "$out" "$@" 2>&1 | grep ' rendered')
    t+=($(( ($(date +%s%N) - t0) / 1000000 )))
    [[ $line == *" 0 rendered, $n already done"* ]] || { echo "not all resumed: $line" >&2; exit 1; }
  done
  printf '%s\n' "${t[@]}" | sort -n | sed -n "$(( (runs + 1) / 2 ))p"
}
rows=()
if [[ -n $old ]]; then
  make_done "$old" "$work/out-old"
  rows+=("old (manifest read + CRC-32 of every output),$(median_ms "$old" "$work/out-old")")
fi
make_done "$new" "$work/out-new"
rows+=("new (manifest read + stat),$(median_ms "$new" "$work/out-new")")
rows+=("new --verify (+ CRC-32 of outputs and inputs),$(median_ms "$new" "$work/out-new" --verify)")
printf '| resume of %d done frames | median wall ms (%d runs) | per done frame, us |\n|---|---:|---:|\n' "$n" "$runs"
json="["
for r in "${rows[@]}"; do
  name=${r%,*} ms=${r##*,}
  printf '| %s | %d | %.1f |\n' "$name" "$ms" "$(echo "$ms * 1000 / $n" | bc -l)"
  json+="{\"case\":\"$name\",\"frames\":$n,\"runs\":$runs,\"median_ms\":$ms,\"per_frame_us\":$(echo "scale=1; $ms * 1000 / $n" | bc -l)},"
done
echo "${json%,}]" > resume-bench.json
