"""A small refocus manifest for the batch tests: the TUM frame of the shared data (16-bit PNG
depth, depth_scale 5000) and two synthetic frames (PNG colour, .npy depth), one with a name."""

import csv
import filecmp
import json
import os
from pathlib import Path

import numpy as np
from PIL import Image

from conftest import REPO, make_frame

TUM = Path(os.environ.get("VIEWSYNTH_DATA_DIR") or REPO.parent / "shared" / "data") / "rgbd_open3d_testdata"
SCALES = [0.5, 1.0, 2.0]
# Timings differ between runs; everything else in a frame's manifest.json must not.
TIMING_KEYS = ("render_ms", "readback_ms", "write_ms")


def write_manifest(folder, broken=False):
    """frames.csv in `folder` (paths relative to it); with `broken`, a fourth frame whose depth
    file is missing. Returns the manifest's path."""
    folder.mkdir(parents=True, exist_ok=True)
    rows = []
    assert (TUM / "TUM_color.png").is_file(), f"test data missing under {TUM} (fetch it with `python3 ci/fetch-data.py`, or set VIEWSYNTH_DATA_DIR)"
    rows.append({"rgb": str(TUM / "TUM_color.png"), "depth": str(TUM / "TUM_depth.png"),
                 "fx": 525.0, "fy": 525.0, "cx": 319.5, "cy": 239.5, "depth_scale": 5000, "name": ""})
    for i, (w, h) in enumerate([(96, 72), (80, 60)]):
        rgb, depth, K = make_frame(w, h, seed=i)
        Image.fromarray(rgb).save(folder / f"synth{i}.png")
        np.save(folder / f"synth{i}_depth.npy", depth)
        rows.append({"rgb": f"synth{i}.png", "depth": f"synth{i}_depth.npy", "fx": K[0, 0], "fy": K[1, 1],
                     "cx": K[0, 2], "cy": K[1, 2], "depth_scale": "", "name": "second" if i == 1 else ""})
    if broken:
        rows.append({"rgb": "synth0.png", "depth": "missing_depth.npy", "fx": 80, "fy": 80, "cx": 40, "cy": 30,
                     "depth_scale": "", "name": "broken"})
    path = folder / "frames.csv"
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=["rgb", "depth", "fx", "fy", "cx", "cy", "depth_scale", "name"])
        w.writeheader()
        w.writerows(rows)
    return path


def without_timings(manifest):
    for entry in manifest["outputs"]:
        for key in TIMING_KEYS:
            assert key in entry
            del entry[key]
    return manifest


def assert_same_batch_output(a: Path, b: Path):
    """Two batch output folders hold the same frame folders and the same files, byte for byte,
    and the same manifests but for the timings; the same index rows where both have an index.
    Returns the frame folder names."""
    frames = sorted(p.name for p in a.iterdir() if p.is_dir())
    assert frames == sorted(p.name for p in b.iterdir() if p.is_dir())
    if (a / "index.jsonl").is_file() and (b / "index.jsonl").is_file():
        assert (a / "index.jsonl").read_text() == (b / "index.jsonl").read_text()
    for name in frames:
        files = sorted(p.name for p in (a / name).iterdir())
        assert files == sorted(p.name for p in (b / name).iterdir()), name
        assert "manifest.json" in files and len(files) > 1
        for f in files:
            if f == "manifest.json":
                ma = without_timings(json.loads((a / name / f).read_text()))
                mb = without_timings(json.loads((b / name / f).read_text()))
                assert ma == mb, name
            else:
                assert filecmp.cmp(a / name / f, b / name / f, shallow=False), f"{name}/{f} differs"
    return frames
