"""Renderer.cyclopean with depth input equals `viewsynth cyclopean --left-depth ... --cameras
cams.json` on the same inputs: the Cones crop of test_cyclopean with metric depth Z = f B / d
(view-z, and the same depth as GL device depth), the eyes and the view given in the camera file's
computer-vision form (K, R, t, size, near/far). The cameras go to Python as a dict of numpy
arrays and to the CLI as the JSON file; decoded PNG pixels, the mask and the depth must be equal.
Bad inputs raise InvalidInputError naming the argument (and, for cameras, the field).

All camera numbers are dyadic (700, 63.5, 0.125, ...): the JSON text the CLI parses denotes
exactly the floats Python holds, so the two runs see bit-identical matrices."""

import json
import subprocess

import numpy as np
import pytest
from PIL import Image

import viewsynth as vs

from test_cyclopean import cones_crop, depth_difference

FOCAL, BASELINE, NEAR, FAR = 700.0, 0.125, 0.5, 64.0


def camera(h, w, centre_x):
    """A rectified camera of the rig with its centre at x = centre_x (world = left camera)."""
    K = np.array([[FOCAL, 0.0, (w - 1) / 2], [0.0, FOCAL, (h - 1) / 2], [0.0, 0.0, 1.0]])
    # World -> camera: x_cam = R x_world + t, so t = -R c for the centre c.
    return {"K": K, "R": np.eye(3), "t": np.array([-centre_x, 0.0, 0.0]), "width": w, "height": h,
            "near": NEAR, "far": FAR}


def cameras(h, w, depth_kind="view-z", middle_x=BASELINE / 2):
    return {
        "depth_kind": depth_kind,
        "left": camera(h, w, 0.0),
        "right": camera(h, w, BASELINE),
        "middle": camera(h, w, middle_x),
        "fixation_distance": 4.0,
    }


def as_json(value):
    if isinstance(value, dict):
        return {k: as_json(v) for k, v in value.items()}
    return value.tolist() if isinstance(value, np.ndarray) else value


def device(z):
    """View Z -> GL window depth (ndc z in [-1, 1], not reversed) of the rig's planes, in float64
    then float32; unknown depth is the far plane (background)."""
    z = z.astype(np.float64)
    with np.errstate(divide="ignore"):
        ndc = (FAR + NEAR) / (FAR - NEAR) - 2 * FAR * NEAR / ((FAR - NEAR) * z)
    window = np.where(z > 0, (ndc + 1) / 2, 1.0)
    return window.astype(np.float32)


@pytest.fixture(scope="module")
def pair():
    """Colour and view-z depth (metres) of both eyes."""
    left_rgb, right_rgb, left_d, right_d = cones_crop()
    z = lambda d: np.where(d > 0, FOCAL * BASELINE / np.maximum(d, 1e-6), 0).astype(np.float32)
    return left_rgb, right_rgb, z(left_d), z(right_d)


def run_cli(cli, tmp_path, left_rgb, right_rgb, left_depth, right_depth, cams, flags):
    paths = {n: tmp_path / n for n in ("left_rgb.png", "right_rgb.png", "left_depth.npy", "right_depth.npy")}
    Image.fromarray(left_rgb).save(paths["left_rgb.png"])
    Image.fromarray(right_rgb).save(paths["right_rgb.png"])
    np.save(paths["left_depth.npy"], left_depth)
    np.save(paths["right_depth.npy"], right_depth)
    cams_path = tmp_path / "cams.json"
    cams_path.write_text(json.dumps(as_json(cams)))
    out = tmp_path / "out"
    cmd = [
        str(cli), "cyclopean", "--left-rgb", str(paths["left_rgb.png"]), "--right-rgb", str(paths["right_rgb.png"]),
        "--left-depth", str(paths["left_depth.npy"]), "--right-depth", str(paths["right_depth.npy"]),
        "--cameras", str(cams_path), "--out-dir", str(out), "--device", "auto",
    ] + flags
    done = subprocess.run(cmd, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return out, cams_path


CASES = {
    "splat_gather_view_z": ("view-z", dict(), []),
    "splat_gather_device": ("device", dict(), []),
    "seed_view_z": ("view-z", dict(method="seed"), ["--method", "seed"]),
    "refine_device": ("device", dict(method="refine"), ["--method", "refine"]),
    "forward_view_z": ("view-z", dict(method="forward"), ["--method", "forward"]),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_cyclopean_depth_equals_cli_files(renderer, cli, pair, tmp_path, case):
    kind, kwargs, flags = CASES[case]
    left_rgb, right_rgb, left_z, right_z = pair
    left_depth, right_depth = (device(left_z), device(right_z)) if kind == "device" else (left_z, right_z)
    h, w = left_z.shape
    cams = cameras(h, w, kind)
    view = renderer.cyclopean(left_rgb, right_rgb, left_depth=left_depth, right_depth=right_depth, cameras=cams, **kwargs)
    out, cams_path = run_cli(cli, tmp_path, left_rgb, right_rgb, left_depth, right_depth, cams, flags)
    # Depth input is metric: all three outputs by default, as the CLI writes.
    assert set(view) == {"coverage", "timings", "rgb", "depth", "mask"}
    cli_rgb = np.asarray(Image.open(out / "middle_rgb.png").convert("RGB"))
    assert view["rgb"].dtype == np.uint8 and view["rgb"].shape == cli_rgb.shape == (h, w, 3)
    assert np.array_equal(view["rgb"], cli_rgb)
    cli_mask = np.asarray(Image.open(out / "middle_mask.png"))
    assert view["mask"].dtype == np.bool_ and np.array_equal(view["mask"], cli_mask == 255)
    # Occlusions and unknown depth at the crop's borders: invalid pixels were compared too.
    assert 0.5 < view["coverage"] < 1.0
    assert view["depth"].dtype == np.float32 and view["depth"].shape == (h, w)
    assert depth_difference(cli, out / "middle_depth.exr", view["depth"], tmp_path) == (0.0, 0)
    # The file itself, by path, is the same cameras.
    by_path = renderer.cyclopean(left_rgb, right_rgb, left_depth=left_depth, right_depth=right_depth,
                                 cameras=cams_path, **kwargs)
    assert np.array_equal(by_path["rgb"], view["rgb"]) and np.array_equal(by_path["depth"], view["depth"])


def test_view_at_the_left_eye_keeps_its_depth(renderer, pair):
    """A middle camera placed at the left eye sees the left eye's own surfaces: its depth is the
    left depth wherever the left eye had one and the view is valid (float32 round trip through
    the GPU; sub-pixel refinement may pick a neighbour's surface at edges)."""
    left_rgb, right_rgb, left_z, right_z = pair
    h, w = left_z.shape
    view = renderer.cyclopean(left_rgb, right_rgb, left_depth=left_z, right_depth=right_z,
                              cameras=cameras(h, w, middle_x=0.0))
    known = view["mask"] & (left_z > 0)
    assert known.mean() > 0.8
    close = np.isclose(view["depth"][known], left_z[known], rtol=1e-3)
    assert close.mean() > 0.95, close.mean()


def check(renderer, pair, parameter, words, cams=None, **change):
    left_rgb, right_rgb, left_z, right_z = pair
    h, w = left_z.shape
    args = dict(left_rgb=left_rgb, right_rgb=right_rgb, left_depth=left_z, right_depth=right_z,
                cameras=cams if cams is not None else cameras(h, w))
    args.update(change)
    with pytest.raises(vs.InvalidInputError) as err:
        renderer.cyclopean(**args)
    assert isinstance(err.value, ValueError)
    message = str(err.value)
    assert err.value.parameter == parameter, (err.value.parameter, message)
    for word in words:
        assert word in message, message
    return err.value


def test_bad_inputs(renderer, pair):
    left_rgb, right_rgb, left_z, right_z = pair
    h, w = left_z.shape
    check(renderer, pair, "left_depth", ["float64", "float32[H, W]"], left_depth=left_z.astype(np.float64))
    check(renderer, pair, "right_depth", ["shape (96, 128, 1)"], right_depth=right_z[..., None])
    check(renderer, pair, "right_depth", ["differs from left_rgb"], right_depth=np.ascontiguousarray(right_z[1:]))

    def with_camera(side, key, value, base=None):
        cams = base or cameras(h, w)
        cams[side] = dict(cams[side], **{key: value})
        return cams

    K = cameras(h, w)["left"]["K"].copy()
    K[0, 2] = np.nan
    check(renderer, pair, "cameras", ['cameras["left"]["K"][0][2]', "NaN", "finite"], with_camera("left", "K", K))
    check(renderer, pair, "cameras", ["right.R", "not orthonormal"], with_camera("right", "R", np.diag([1.01, 1.0, 1.0])))
    check(renderer, pair, "cameras", ["middle.K", "3x3"], with_camera("middle", "K", np.eye(3)[:2]))
    check(renderer, pair, "cameras", ["left.K", "skew"], with_camera("left", "K", [[700, 1, 63.5], [0, 700, 47.5], [0, 0, 1]]))
    check(renderer, pair, "cameras", ["right.t"], with_camera("right", "t", [0.0, 0.0]))
    cams = cameras(h, w)
    del cams["fixation_distance"]
    check(renderer, pair, "cameras", ["fixation_distance"], cams)
    cams = cameras(h, w, depth_kind="disparity")
    check(renderer, pair, "cameras", ["depth_kind", "view-z"], cams)
    cams = dict(cameras(h, w), bogus=1)
    check(renderer, pair, "cameras", ["bogus"], cams)
    check(renderer, pair, "cameras", ["set"], dict(cameras(h, w), fixation_distance={1.0}))
    check(renderer, pair, "cameras", ["expected a dict"], cameras=[1, 2])
    check(renderer, pair, "left_rgb", ["left_rgb is 128x96, its camera in the camera file 64x96"], with_camera("left", "width", 64))
    check(renderer, pair, "position", ["the camera file places the view"], position=0.3)
    check(renderer, pair, "baseline", ["the camera file places the view"], baseline=0.1)
    check(renderer, pair, "cameras", ["missing"], cameras=None)
    check(renderer, pair, "left_disparity", ["not both"], left_disparity=left_z)
    with pytest.raises(vs.InvalidInputError) as err:
        renderer.cyclopean(left_rgb, right_rgb, right_depth=right_z, cameras=cameras(h, w))
    assert err.value.parameter == "left_depth"
    with pytest.raises(vs.InvalidInputError) as err:
        renderer.cyclopean(left_rgb, right_rgb, left_depth=left_z, right_depth=right_z, cameras=cameras(h, w),
                           max_disparity=16)
    assert err.value.parameter == "max_disparity", str(err.value)
    with pytest.raises(vs.FileError):
        renderer.cyclopean(left_rgb, right_rgb, left_depth=left_z, right_depth=right_z, cameras="/nonexistent/cams.json")
    # Nothing was left broken: a good call still works.
    assert renderer.cyclopean(left_rgb, right_rgb, left_depth=left_z, right_depth=right_z,
                              cameras=cameras(h, w))["coverage"] > 0.5
