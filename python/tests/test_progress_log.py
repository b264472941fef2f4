"""refocus_batch(progress=True) with stderr in a file (a log, no terminal): newline-terminated
lines with the count, the rate and the ETA (the CLI's log lines, from the library's rule), never
carriage-return updates that run together into one line."""

import re
import subprocess
import sys

import numpy as np
from PIL import Image

from conftest import make_frame

FRAMES = 12
LINE = re.compile(r"^refocus_batch frames: (\d+)/(\d+) \(\d+\.\d %\), \d+\.\d\d /s, ETA (\d+m\d\ds|\?)$")


def test_progress_true_into_a_file_writes_lines_with_rate_and_eta(tmp_path):
    rows = ["rgb,depth,fx,fy,cx,cy,name"]
    for i in range(FRAMES):
        rgb, depth, K = make_frame(32, 24, seed=i)
        Image.fromarray(rgb).save(tmp_path / f"f{i}.png")
        np.save(tmp_path / f"f{i}.npy", depth)
        rows.append(f"f{i}.png,f{i}.npy,{K[0, 0]},{K[1, 1]},{K[0, 2]},{K[1, 2]},")
    (tmp_path / "frames.csv").write_text("\n".join(rows) + "\n")
    script = (
        "import sys, viewsynth as vs\n"
        "vs.Renderer().refocus_batch(sys.argv[1], sys.argv[2], scales=[1.0], jobs=1, progress=True)\n"
    )
    log = tmp_path / "stderr.log"
    with open(log, "wb") as err:
        done = subprocess.run([sys.executable, "-c", script, str(tmp_path / "frames.csv"), str(tmp_path / "out")],
                              stderr=err)
    text = log.read_bytes().decode()
    assert done.returncode == 0, text
    assert "\r" not in text and text.endswith("\n"), repr(text)
    progress = [m for m in map(LINE.match, text.splitlines()) if m]
    assert progress, f"no progress line in {text!r}"
    # The first frame says the run started; the last line is the whole batch, its ETA zero.
    counts = [(int(m[1]), int(m[2])) for m in progress]
    assert counts[0] == (1, FRAMES) and counts[-1] == (FRAMES, FRAMES), counts
    assert progress[-1][3] == "0m00s", progress[-1][0]
