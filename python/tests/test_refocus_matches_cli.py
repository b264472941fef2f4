"""refocus from Python equals `viewsynth refocus` on the same inputs: decoded PNG pixels, the
depth .npy and the mask, for scales and explicit K', both methods, size and principal changes."""

import json
import subprocess

import numpy as np
import pytest
from PIL import Image


def run_cli(cli, tmp_path, rgb, depth, K, extra):
    src_rgb = tmp_path / "src_rgb.png"
    src_depth = tmp_path / "src_depth.npy"
    Image.fromarray(rgb).save(src_rgb)
    np.save(src_depth, depth)
    out = tmp_path / "out"
    cmd = [
        str(cli), "refocus", "--rgb", str(src_rgb), "--depth", str(src_depth),
        "--fx", repr(float(K[0, 0])), "--fy", repr(float(K[1, 1])), "--cx", repr(float(K[0, 2])), "--cy", repr(float(K[1, 2])),
        "--out-dir", str(out), "--depth-format", "npy", "--device", "auto",
    ] + extra
    done = subprocess.run(cmd, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return out, json.loads((out / "manifest.json").read_text())


CASES = {
    "scales": (dict(scales=[0.5, 1.0, 1.7]), ["--zoom-range", "0.5,1,1.7"]),
    "mesh": (dict(scales=[0.6, 2.0], method="mesh"), ["--zoom-range", "0.6,2", "--method", "mesh"]),
    "size_and_principal": (
        dict(scales=[0.8, 1.25], size=(64, 40), principal=(30.0, 21.5)),
        ["--zoom-range", "0.8,1.25", "--width-out", "64", "--height-out", "40", "--cx-out", "30", "--cy-out", "21.5"],
    ),
    "taus": (dict(scales=[1.3], tau_rel=0.01, tau_abs=float("inf")), ["--zoom-range", "1.3", "--tau-rel", "0.01", "--tau-abs", "inf"]),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_refocus_equals_cli_files(renderer, cli, frame, tmp_path, case):
    rgb, depth, K = frame
    kwargs, flags = CASES[case]
    views = renderer.refocus(rgb, depth, K, **kwargs)
    out, manifest = run_cli(cli, tmp_path, rgb, depth, K, flags)
    assert len(views) == len(manifest["outputs"]) == len(kwargs["scales"])
    for view, entry in zip(views, manifest["outputs"]):
        assert view["scale"] == pytest.approx(entry["scale"], rel=1e-12)
        k = entry["intrinsics"]
        assert np.array_equal(view["K"], [[k["fx"], 0, k["cx"]], [0, k["fy"], k["cy"]], [0, 0, 1]])
        cli_rgb = np.asarray(Image.open(out / entry["rgb"]).convert("RGB"))
        assert view["rgb"].shape == cli_rgb.shape == (entry["height"], entry["width"], 3)
        assert np.array_equal(view["rgb"], cli_rgb)
        cli_depth = np.load(out / entry["depth_npy"])
        assert view["depth"].dtype == cli_depth.dtype == np.float32
        assert np.array_equal(view["depth"], cli_depth)
        cli_mask = np.asarray(Image.open(out / entry["mask"]))
        assert view["mask"].dtype == np.bool_
        assert np.array_equal(view["mask"], cli_mask == 255)
        assert view["coverage"] == pytest.approx(entry["coverage"], abs=1e-12)
        # The frame has holes and a broken box edge: the comparison covered invalid pixels too.
        assert 0.0 < view["coverage"] < 1.0


def test_k_out_equals_scales(renderer, frame):
    rgb, depth, K = frame
    by_scale = renderer.refocus(rgb, depth, K, scales=[0.7, 1.9])
    k_out = [v["K"] for v in by_scale]
    by_k = renderer.refocus(rgb, depth, K, K_out=np.stack(k_out))
    for a, b in zip(by_scale, by_k):
        assert np.array_equal(a["K"], b["K"])
        assert a["scale"] == pytest.approx(b["scale"])
        for name in ("rgb", "depth", "mask"):
            assert np.array_equal(a[name], b[name])


def test_outputs_subset_and_identity_scale(renderer, frame):
    rgb, depth, K = frame
    (view,) = renderer.refocus(rgb, depth, K, scales=[1.0], outputs=("depth",))
    assert set(view) == {"scale", "K", "coverage", "timings", "depth"}
    assert set(view["timings"]) == {"setup_ms", "render_ms", "gpu_ms", "readback_ms"}
    # At scale 1 a covered pixel samples its own source pixel centre: the depth comes back up to
    # float32 interpolation rounding on the GPU (a few ulps), and holes stay holes.
    ok = view["depth"] > 0
    assert ok.mean() > 0.5
    np.testing.assert_allclose(view["depth"][ok], depth[ok], rtol=1e-6)
    assert not ok[~(depth > 0)].any()
    (view,) = renderer.refocus(rgb, depth, K, scales=[1.0], outputs=["rgb"])
    assert "rgb" in view and "depth" not in view and "mask" not in view
    assert view["coverage"] is None
    # Nearest-pixel colour at scale 1: every covered pixel keeps its colour exactly.
    (full,) = renderer.refocus(rgb, depth, K, scales=[1.0])
    assert np.array_equal(full["rgb"][full["mask"]], rgb[full["mask"]])


def test_outputs_are_owned_writable_arrays(renderer, frame):
    rgb, depth, K = frame
    (view,) = renderer.refocus(rgb, depth, K, scales=[2.0])
    for name in ("rgb", "depth", "mask"):
        a = view[name]
        assert a.flags["C_CONTIGUOUS"] and a.flags["WRITEABLE"]
        a[...] = 0  # the caller owns them: writing must not disturb the next call
    (again,) = renderer.refocus(rgb, depth, K, scales=[2.0])
    assert again["rgb"].any()
