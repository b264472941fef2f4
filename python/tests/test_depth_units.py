"""Depth units are never assumed (issue 47): read_depth takes the CLI's rules (integer depth needs
depth_scale, device depth its planes), and png16 output is written in the units asked for,
recorded in the manifest and the index, and read back by a plain division."""

import json

import numpy as np
import pytest
from PIL import Image

import viewsynth as vs
from test_cyclopean import data_dir

TUM_MEDIAN_M = 2.415  # the TUM frame's median valid depth, raw 12075 / 5000


def tum():
    return data_dir() / "rgbd_open3d_testdata"


def test_integer_depth_without_its_scale_raises_naming_it():
    # Before: read as millimetres, a median of 12.08 m for a 2.42 m frame.
    with pytest.raises(vs.InvalidInputError, match="depth_scale") as e:
        vs.read_depth(tum() / "TUM_depth.png")
    assert e.value.parameter == "depth_scale" and "5000 for TUM" in str(e.value)
    z = vs.read_depth(tum() / "TUM_depth.png", depth_scale=5000)
    assert abs(np.median(z[z > 0]) - TUM_MEDIAN_M) < 1e-3


def test_device_depth_needs_its_planes(tmp_path):
    near, far, z_true = 0.1, 100.0, 2.0
    # GL standard-Z window depth of a surface at 2 m.
    ndc = (far + near) / (far - near) - 2 * far * near / ((far - near) * z_true)
    np.save(tmp_path / "d.npy", np.full((2, 3), (ndc + 1) / 2, np.float32))
    with pytest.raises(vs.InvalidInputError, match="near"):
        vs.read_depth(tmp_path / "d.npy", depth_kind="device")
    with pytest.raises(vs.InvalidInputError, match="near"):
        vs.read_depth(tmp_path / "d.npy", near=near, far=far)  # planes without device depth
    z = vs.read_depth(tmp_path / "d.npy", depth_kind="device", near=near, far=far)
    assert np.abs(z - z_true).max() < 1e-4


def test_png16_written_at_5000_units_reads_back_by_a_plain_division(renderer, tmp_path):
    manifest = tmp_path / "frames.json"
    frame = {"name": "tum", "rgb": str(tum() / "TUM_color.png"), "depth": str(tum() / "TUM_depth.png"),
             "depth_scale": 5000, "fx": 525.0, "fy": 525.0, "cx": 319.5, "cy": 239.5}
    manifest.write_text(json.dumps([frame]))
    out = tmp_path / "out"
    with pytest.raises(vs.InvalidInputError, match="depth_png_scale"):
        renderer.refocus_batch(manifest, out, scales=[1.0], depth_format="png16", depth_png_scale=0.0)
    with pytest.raises(vs.InvalidInputError, match="depth_png_scale"):
        renderer.refocus_batch(manifest, out, scales=[1.0], depth_png_scale=5000)  # no png16 asked for
    renderer.refocus_batch(manifest, out, scales=[1.0], outputs="depth", depth_format="png16", depth_png_scale=5000)
    raw = np.asarray(Image.open(out / "tum" / "s1_depth.png"))
    assert raw.dtype == np.uint16
    # Scale 1 reproduces the input where a triangle is kept: the same TUM units come back.
    source = np.asarray(Image.open(tum() / "TUM_depth.png")).astype(np.int64)
    kept = raw > 0
    assert kept.mean() > 0.75 and np.abs(raw[kept].astype(np.int64) - source[kept]).max() <= 1
    assert abs(np.median(raw[kept] / 5000.0) - TUM_MEDIAN_M) < 1e-3
    [entry] = json.loads((out / "tum" / "manifest.json").read_text())["outputs"]
    assert entry["depth_png16_units_per_metre"] == 5000
    [row] = vs.read_index(out)
    assert row["depth_scale"] == 5000
    z = vs.read_depth(row["depth"], depth_scale=row["depth_scale"])
    assert abs(np.median(z[z > 0]) - TUM_MEDIAN_M) < 1e-3
