"""Renderer.reproject equals `viewsynth reproject` (parallel-rig mode) on the same inputs: decoded
PNG pixels, the depth .npy and the mask, for each method, source/target, depth kind and rig; and
bad inputs raise InvalidInputError naming the argument."""

import subprocess

import numpy as np
import pytest
from PIL import Image

import viewsynth as vs


def run_cli(cli, tmp_path, rgb, depth, K, flags):
    src_rgb = tmp_path / "src_rgb.png"
    src_depth = tmp_path / "src_depth.npy"
    Image.fromarray(rgb).save(src_rgb)
    np.save(src_depth, depth)
    out = tmp_path / "out"
    cmd = [
        str(cli), "reproject", "--rgb", str(src_rgb), "--depth", str(src_depth),
        "--fx", repr(float(K[0, 0])), "--fy", repr(float(K[1, 1])), "--cx", repr(float(K[0, 2])), "--cy", repr(float(K[1, 2])),
        "--out-dir", str(out), "--depth-format", "npy", "--device", "auto",
    ] + flags
    done = subprocess.run(cmd, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return out


def as_disparity(depth, focal, baseline, doffs):
    with np.errstate(divide="ignore", invalid="ignore"):
        d = focal * baseline / depth - doffs
    return np.where(np.isfinite(d) & (depth > 0), d, 0).astype(np.float32)


def as_device(depth, near, far):
    """OpenGL window depth of view Z (standard Z, NDC [-1, 1] mapped to [0, 1]); 1 = background."""
    with np.errstate(divide="ignore", invalid="ignore"):
        d = (1 / near - 1 / depth) / (1 / near - 1 / far)
    return np.where(np.isfinite(d) & (depth > 0), d, 1).astype(np.float32)


CASES = {
    "left_to_right": (dict(baseline=0.12), ["--baseline", "0.12"], None),
    "right_to_left_shift": (
        dict(baseline=0.2, source="right", target="left", method="shift", steps=5),
        ["--baseline", "0.2", "--from", "right", "--to", "left", "--method", "shift", "--steps", "5"],
        None,
    ),
    "centre_to_both_gather3d": (
        dict(baseline=0.1, source="centre", target="both", method="gather3d"),
        ["--baseline", "0.1", "--from", "centre", "--to", "both", "--method", "gather3d"],
        None,
    ),
    "disparity": (
        dict(depth_kind="disparity", baseline=0.16, focal=90.0, doffs=1.5),
        ["--depth-kind", "disparity", "--baseline", "0.16", "--focal", "90", "--doffs", "1.5"],
        lambda z: as_disparity(z, 90.0, 0.16, 1.5),
    ),
    "device": (
        dict(depth_kind="device", near=0.5, far=100.0, baseline=0.1),
        ["--depth-kind", "device", "--near", "0.5", "--far", "100", "--baseline", "0.1"],
        lambda z: as_device(z, 0.5, 100.0),
    ),
    "separation_convergence": (
        dict(separation=0.03, convergence=2.5, outputs=("rgb", "mask")),
        ["--separation", "0.03", "--convergence", "2.5", "--outputs", "rgb,mask"],
        None,
    ),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_reproject_equals_cli_files(renderer, cli, frame, tmp_path, case):
    rgb, depth, K = frame
    kwargs, flags, convert = CASES[case]
    if convert:
        depth = convert(depth)
    views = renderer.reproject(rgb, depth, K, **kwargs)
    out = run_cli(cli, tmp_path, rgb, depth, K, flags)
    targets = {"both": ["left", "right"]}.get(kwargs.get("target"), [kwargs.get("target", "right")])
    assert sorted(views) == sorted(targets)
    h, w = depth.shape
    for name in targets:
        view = views[name]
        cli_rgb = np.asarray(Image.open(out / f"{name}_rgb.png").convert("RGB"))
        assert view["rgb"].dtype == np.uint8 and view["rgb"].shape == cli_rgb.shape == (h, w, 3)
        assert np.array_equal(view["rgb"], cli_rgb)
        cli_mask = np.asarray(Image.open(out / f"{name}_mask.png"))
        assert view["mask"].dtype == np.bool_
        assert np.array_equal(view["mask"], cli_mask == 255)
        assert view["coverage"] == pytest.approx(view["mask"].mean(), abs=1e-12)
        # Disocclusions and the source's holes: invalid pixels were compared too.
        assert 0.3 < view["coverage"] < 1.0
        depth_file = out / f"{name}_depth.npy"
        if "depth" in view:
            cli_depth = np.load(depth_file)
            assert view["depth"].dtype == cli_depth.dtype == np.float32
            assert np.array_equal(view["depth"], cli_depth)
        else:
            assert not depth_file.exists()
        assert set(view["timings"]) == {"setup_ms", "render_ms", "gpu_ms"}


def check(renderer, frame, parameter, words, **change):
    rgb, depth, K = frame
    args = dict(rgb=rgb, depth=depth, K=K, baseline=0.1)
    args.update(change)
    with pytest.raises(vs.InvalidInputError) as err:
        renderer.reproject(args.pop("rgb"), args.pop("depth"), args.pop("K"), **args)
    assert isinstance(err.value, ValueError)
    message = str(err.value)
    assert parameter in message, message
    for w in words:
        assert w in message, message
    return err.value


def test_bad_inputs(renderer, frame):
    rgb, depth, K = frame
    e = check(renderer, frame, "depth", ["float64", "float32[H, W]"], depth=depth.astype(np.float64))
    assert e.parameter == "depth"
    e = check(renderer, frame, "depth", ["95x72", "differs from rgb's 96x72"], depth=np.ascontiguousarray(depth[:, :95]))
    assert e.parameter == "depth"
    nan_k = K.copy()
    nan_k[0, 2] = np.nan
    check(renderer, frame, "K", ["not finite"], K=nan_k)
    check(renderer, frame, "source", ["'middle'"], source="middle")
    check(renderer, frame, "target", ["'up'"], target="up")
    check(renderer, frame, "target", ["target both needs source centre"], target="both")
    check(renderer, frame, "target", ["source view itself"], source="right", target="right")
    check(renderer, frame, "method", ["'mesh'", "shift-scan"], method="mesh")
    check(renderer, frame, "steps", ["outside 1..=16"], method="shift", steps=0)
    check(renderer, frame, "tau_rel", [">= 0"], tau_rel=-1.0)
    check(renderer, frame, "depth_kind", ["'metres'"], depth_kind="metres")
    check(renderer, frame, "baseline", ["give the rig"], baseline=None)
    check(renderer, frame, "baseline", ["depth_kind disparity needs baseline"], baseline=None, depth_kind="disparity", separation=0.03, convergence=2.0)
    check(renderer, frame, "near", ["needs near and far"], depth_kind="device", near=0.5)
    check(renderer, frame, "near", ["apply to depth_kind device only"], far=10.0)
    check(renderer, frame, "convergence", ["separation needs convergence"], separation=0.03)
    check(renderer, frame, "depth", ["no pixel holds valid depth"], depth=np.zeros_like(depth))
    check(renderer, frame, "outputs", [], outputs=("rgb", "normals"))
    assert renderer.reproject(rgb, depth, K, baseline=0.1)["right"]["coverage"] > 0.3
