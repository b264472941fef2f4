"""Renderer.cyclopean equals `viewsynth cyclopean --left-disparity ...` on the same inputs (a crop
of Middlebury 2003 Cones, disparities written as float32 .npy): decoded PNG pixels and the mask,
for every method, positions, a metric rig with doffs; and bad inputs raise InvalidInputError
naming the argument."""

import os
import re
import subprocess
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

import viewsynth as vs

from conftest import REPO

def data_dir():
    """../shared/data beside the repository, or VIEWSYNTH_DATA_DIR (as the Rust tests)."""
    path = Path(os.environ.get("VIEWSYNTH_DATA_DIR", REPO.parent / "shared" / "data"))
    assert path.is_dir(), f"test data missing: {path} (fetch it with `python3 ci/fetch-data.py`, or set VIEWSYNTH_DATA_DIR)"
    return path


def cones_crop():
    """Left/right colour and disparity (pixels; the 2003 PGMs store 4 x d) of a 128x96 crop with
    cones, background and the occlusions between them."""
    cones = data_dir() / "middlebury2003_cones"
    box = (slice(140, 236), slice(150, 278))
    load = lambda name: np.asarray(Image.open(cones / name))[box]
    left_rgb = np.ascontiguousarray(load("im2.png"))
    right_rgb = np.ascontiguousarray(load("im6.png"))
    left_d = np.ascontiguousarray(load("disp2.pgm").astype(np.float32) / 4)
    right_d = np.ascontiguousarray(load("disp6.pgm").astype(np.float32) / 4)
    return left_rgb, right_rgb, left_d, right_d


@pytest.fixture(scope="module")
def pair():
    return cones_crop()


def run_cli(cli, tmp_path, pair, flags):
    names = ("left_rgb.png", "right_rgb.png", "left_disparity.npy", "right_disparity.npy")
    paths = [tmp_path / n for n in names]
    Image.fromarray(pair[0]).save(paths[0])
    Image.fromarray(pair[1]).save(paths[1])
    np.save(paths[2], pair[2])
    np.save(paths[3], pair[3])
    out = tmp_path / "out"
    cmd = [
        str(cli), "cyclopean", "--left-rgb", str(paths[0]), "--right-rgb", str(paths[1]),
        "--left-disparity", str(paths[2]), "--right-disparity", str(paths[3]),
        "--out-dir", str(out), "--device", "auto",
    ] + flags
    done = subprocess.run(cmd, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return out


CASES = {
    "splat_gather": (dict(), []),
    "splat_gather_metric": (
        dict(position=0.3, focal=700.0, baseline=0.16, doffs=2.5, outputs=("rgb", "depth", "mask")),
        ["--position", "0.3", "--focal", "700", "--baseline", "0.16", "--doffs", "2.5"],
    ),
    "forward": (dict(method="forward", position=0.75), ["--method", "forward", "--position", "0.75"]),
    "seed": (dict(method="seed"), ["--method", "seed"]),
    "refine": (dict(method="refine", position=0.6), ["--method", "refine", "--position", "0.6"]),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_cyclopean_equals_cli_files(renderer, cli, pair, tmp_path, case):
    kwargs, flags = CASES[case]
    view = renderer.cyclopean(*pair, **kwargs)
    out = run_cli(cli, tmp_path, pair, flags)
    h, w = pair[2].shape
    cli_rgb = np.asarray(Image.open(out / "middle_rgb.png").convert("RGB"))
    assert view["rgb"].dtype == np.uint8 and view["rgb"].shape == cli_rgb.shape == (h, w, 3)
    assert np.array_equal(view["rgb"], cli_rgb)
    cli_mask = np.asarray(Image.open(out / "middle_mask.png"))
    assert view["mask"].dtype == np.bool_ and view["mask"].shape == (h, w)
    assert np.array_equal(view["mask"], cli_mask == 255)
    assert view["coverage"] == pytest.approx(view["mask"].mean(), abs=1e-12)
    # The crop has occlusions and unknown disparity at its borders: invalid pixels were compared.
    assert 0.5 < view["coverage"] < 1.0
    assert set(view["timings"]) == {"setup_ms", "render_ms", "gpu_ms"}
    metric = "focal" in kwargs
    assert ("depth" in view) == metric
    assert (out / "middle_depth.exr").is_file() == metric
    if metric:
        assert view["depth"].dtype == np.float32 and view["depth"].shape == (h, w)
        assert depth_difference(cli, out / "middle_depth.exr", view["depth"], tmp_path) == (0.0, 0)


def depth_difference(cli, exr, depth, tmp_path):
    """Max |a - b| (metres) and the count of pixels valid in only one, by `viewsynth compare`
    (no EXR reader is needed in Python: the CLI decodes its own file)."""
    ours = tmp_path / "python_depth.npy"
    np.save(ours, depth)
    rgb = tmp_path / "out" / "middle_rgb.png"
    cmd = [str(cli), "compare", "--a-rgb", str(rgb), "--b-rgb", str(rgb), "--a-depth", str(exr), "--b-depth", str(ours)]
    done = subprocess.run(cmd, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    found = re.search(r"depth: max abs (\S+) m, .*valid in only one: (\d+) pixels", done.stdout)
    assert found, done.stdout
    return float(found.group(1)), int(found.group(2))


def test_metric_depth(renderer, pair):
    """At the left eye (position 0) the view's depth is f B / (d + doffs) of the left eye where the
    splat-gather view shows the left eye's own surface (no resampling needed there)."""
    f, b, doffs = 700.0, 0.16, 2.5
    view = renderer.cyclopean(*pair, position=0.0, focal=f, baseline=b, doffs=doffs)
    left_d = pair[2]
    expected = f * b / (left_d + doffs)
    known = view["mask"] & (left_d > 0)
    assert known.mean() > 0.8
    z = view["depth"]
    assert z.dtype == np.float32 and np.all(z[~view["mask"]] == 0)
    close = np.isclose(z[known], expected[known], rtol=1e-3)
    # Sub-pixel refinement may pick a neighbour's surface at edges; nearly all pixels agree.
    assert close.mean() > 0.95, close.mean()


def test_outputs_subset_and_positions(renderer, pair):
    view = renderer.cyclopean(*pair, outputs="mask")
    assert set(view) == {"coverage", "timings", "mask"}
    middle = renderer.cyclopean(*pair)
    left = renderer.cyclopean(*pair, position=0.0)
    assert not np.array_equal(middle["rgb"], left["rgb"])
    # The outputs are new arrays owned by the caller: writable, and sharing no memory with
    # another call's (writing one changes nothing the renderer or a later call returns).
    assert middle["rgb"].flags.writeable
    again = renderer.cyclopean(*pair)
    assert np.array_equal(again["rgb"], middle["rgb"])
    assert not np.shares_memory(again["rgb"], middle["rgb"])
    middle["rgb"][:] = 0
    assert again["rgb"].any()
    assert renderer.cyclopean(*pair)["rgb"].any()


def check(renderer, pair, parameter, words, **change):
    args = dict(zip(("left_rgb", "right_rgb", "left_disparity", "right_disparity"), pair))
    args.update(change)
    with pytest.raises(vs.InvalidInputError) as err:
        renderer.cyclopean(**args)
    assert isinstance(err.value, ValueError)
    message = str(err.value)
    assert parameter in message, message
    for w in words:
        assert w in message, message
    return err.value


def test_bad_inputs(renderer, pair):
    left_rgb, right_rgb, left_d, right_d = pair
    e = check(renderer, pair, "right_rgb", ["float32", "uint8[H, W, 3]"], right_rgb=right_rgb.astype(np.float32))
    assert e.parameter == "right_rgb"
    e = check(renderer, pair, "left_disparity", ["float64", "float32[H, W]"], left_disparity=left_d.astype(np.float64))
    assert e.parameter == "left_disparity"
    check(renderer, pair, "left_rgb", ["no alpha"], left_rgb=np.zeros(left_rgb.shape[:2] + (4,), np.uint8))
    e = check(renderer, pair, "right_disparity", ["differs from left_rgb"], right_disparity=np.ascontiguousarray(right_d[:, 1:]))
    assert e.parameter == "right_disparity"
    check(renderer, pair, "right_rgb", ["differs from left_rgb"], right_rgb=np.ascontiguousarray(right_rgb[1:]))
    check(renderer, pair, "left_disparity", ["no known disparity"], left_disparity=np.zeros_like(left_d))
    check(renderer, pair, "position", ["outside [0, 1]"], position=1.5)
    # A library error naming request fields spells them as keywords, and names the first.
    e = check(renderer, pair, "focal/baseline", ["outside the usable depths"], focal=1e-3, baseline=1e-6)
    assert e.parameter == "focal" and "--" not in str(e), (e.parameter, str(e))
    check(renderer, pair, "position", ["outside [0, 1]"], position=float("nan"))
    check(renderer, pair, "method", ["'mesh'", "splat-gather"], method="mesh")
    check(renderer, pair, "baseline", ["focal needs baseline"], focal=700.0)
    check(renderer, pair, "focal", ["baseline needs focal"], baseline=0.1)
    check(renderer, pair, "focal", ["-1 must be in [1e-3, 1e6]"], focal=-1.0, baseline=0.1)
    check(renderer, pair, "doffs", ["finite"], doffs=float("inf"))
    check(renderer, pair, "outputs", ["needs focal and baseline"], outputs=("rgb", "depth"))
    check(renderer, pair, "outputs", [], outputs=("rgb", "normals"))
    check(renderer, pair, "matcher", ["two images alone"], matcher="sgm")
    # Nothing was left broken: a good call still works.
    assert renderer.cyclopean(*pair)["coverage"] > 0.5


def test_fill_equals_cli_fill(renderer, cli, pair, tmp_path):
    """fill=True is the CLI's --fill: the same colour, rendered pixels where the CLI's mask is
    255 and filled ones where it is 128, and every pixel of the crop one or the other."""
    view = renderer.cyclopean(*pair, fill=True)
    plain = renderer.cyclopean(*pair)
    out = run_cli(cli, tmp_path, pair, ["--fill"])
    cli_rgb = np.asarray(Image.open(out / "middle_rgb.png").convert("RGB"))
    cli_mask = np.asarray(Image.open(out / "middle_mask.png"))
    assert np.array_equal(view["rgb"], cli_rgb)
    assert np.array_equal(view["mask"], cli_mask == 255)
    assert np.array_equal(view["filled"], cli_mask == 128)
    assert np.array_equal(view["mask"], plain["mask"]), "the fill leaves rendered pixels alone"
    assert np.array_equal(view["filled"], ~plain["mask"]), "every hole of the crop is filled"
    assert np.array_equal(view["rgb"][plain["mask"]], plain["rgb"][plain["mask"]])
    assert "filled" not in plain


def test_vulkan_renderer_matches_gl(renderer, pair):
    """Renderer(backend="vulkan") runs the same passes on the Vulkan device (lavapipe here): the
    same coverage, and colour within the GL-vs-Vulkan agreement rule (one level on at least
    99.5 % of the pixels both render); a refocus likewise."""
    with vs.Renderer(backend="vulkan") as vk:
        assert vk.backend == "vulkan" and renderer.backend == "gl"
        assert vk.info["name"]
        a, b = renderer.cyclopean(*pair), vk.cyclopean(*pair)
        both = a["mask"] & b["mask"]
        assert (a["mask"] != b["mask"]).mean() <= 0.005
        diff = np.abs(a["rgb"].astype(int) - b["rgb"].astype(int)).max(axis=2)[both]
        assert (diff <= 1).mean() >= 0.995, np.bincount(diff)
        from conftest import make_frame

        rgb, depth, K = make_frame()
        for ra, rb in zip(renderer.refocus(rgb, depth, K, scales=[0.5, 1.5]), vk.refocus(rgb, depth, K, scales=[0.5, 1.5])):
            # The refocus bound of viewsynth_tests/tests/library/vulkan/refocus.rs: masks identical, colour
            # within one level.
            assert np.array_equal(ra["mask"], rb["mask"])
            assert np.abs(ra["rgb"].astype(int) - rb["rgb"].astype(int)).max() <= 1
        with pytest.raises(vs.InvalidInputError, match="backend"):
            vk.gl_objects()
    with pytest.raises(vs.InvalidInputError, match="backend"):
        vs.Renderer(backend="metal")


def test_two_images_alone_equal_cli(renderer, cli, pair, tmp_path):
    """Two images alone: the disparities are estimated by the census matcher (as the CLI with
    --left-rgb/--right-rgb only), the same view and mask as the CLI's."""
    view = renderer.cyclopean(pair[0], pair[1], max_disparity=32, confidence=True)
    paths = [tmp_path / "l.png", tmp_path / "r.png"]
    Image.fromarray(pair[0]).save(paths[0])
    Image.fromarray(pair[1]).save(paths[1])
    out = tmp_path / "out"
    done = subprocess.run([str(cli), "cyclopean", "--left-rgb", str(paths[0]), "--right-rgb", str(paths[1]),
                           "--max-disparity", "32", "--confidence", "--out-dir", str(out)],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert np.array_equal(view["rgb"], np.asarray(Image.open(out / "middle_rgb.png").convert("RGB")))
    # confidence=True: each eye's matcher confidence, the CLI's --confidence files exactly.
    for eye in ("left", "right"):
        c = view[f"{eye}_confidence"]
        assert c.dtype == np.float32 and c.shape == pair[0].shape[:2]
        assert 0.0 <= c.min() and c.max() <= 1.0 and c.max() > 0.5
        assert depth_difference(cli, out / f"{eye}_confidence.exr", c, tmp_path) == (0.0, 0)
    plain = renderer.cyclopean(pair[0], pair[1], max_disparity=32)
    assert "left_confidence" not in plain and np.array_equal(plain["rgb"], view["rgb"])
    with pytest.raises(vs.InvalidInputError) as err:
        renderer.cyclopean(*pair, confidence=True)
    assert err.value.parameter == "confidence" and "two images alone" in str(err.value)
    assert np.array_equal(view["mask"], np.asarray(Image.open(out / "middle_mask.png")) == 255)
    assert view["coverage"] > 0.5
    # A search past the matcher's bound is refused before any image is read; one within it
    # but as wide as the image, by the image.
    with pytest.raises(vs.InvalidInputError) as err:
        renderer.cyclopean(pair[0], pair[1], max_disparity=10_000)
    assert err.value.parameter == "max_disparity" and "more than its 1024" in str(err.value)
    with pytest.raises(vs.InvalidInputError) as err:
        renderer.cyclopean(pair[0], pair[1], max_disparity=pair[0].shape[1])
    assert err.value.parameter == "left_rgb" and "less than the width" in str(err.value)


def test_fill_densifies_a_hole_in_given_disparities(renderer):
    """fill=True densifies given disparities before rendering (the CLI's --fill): a hole in both
    maps on a textured plane at disparity 4 renders the plane's own texture, marked "filled", not
    the 2-D fill's guess from the sides (viewsynth_tests/tests/library/cyclopean/given_disparities.rs)."""
    h, w = 24, 48
    rng = np.random.default_rng(7)
    texture = rng.integers(0, 256, (h, w + 4, 3), dtype=np.uint8)  # middle column x at x + 2
    left, right, middle = (np.ascontiguousarray(texture[:, s : s + w]) for s in (0, 4, 2))
    rows, cols = slice(8, 16), slice(18, 26)  # the hole, in the middle view's columns

    def disparity(to_middle):
        d = np.full((h, w), 4.0, np.float32)
        d[rows, cols.start - to_middle : cols.stop - to_middle] = 0.0
        return d

    view = renderer.cyclopean(left, right, disparity(-2), disparity(2), fill=True)
    hole = np.zeros((h, w), bool)
    hole[rows, cols] = True
    assert view["filled"][hole].all() and not view["mask"][hole].any()
    assert view["mask"][~hole].all(), "pixels of given disparities stay rendered"
    diff = np.abs(view["rgb"].astype(int) - middle.astype(int))[hole]
    assert diff.max() <= 1, f"the hole is off by up to {diff.max()} levels: filled, not rendered"


def test_two_images_alone_with_the_semi_global_matcher_equal_cli(renderer, cli, pair, tmp_path):
    """matcher="sgm": the semi-global matcher, the CLI's --matcher sgm view exactly (not the
    census matcher's); an unknown matcher is refused by name."""
    view = renderer.cyclopean(pair[0], pair[1], max_disparity=32, matcher="sgm")
    paths = [tmp_path / "l.png", tmp_path / "r.png"]
    Image.fromarray(pair[0]).save(paths[0])
    Image.fromarray(pair[1]).save(paths[1])
    out = tmp_path / "out"
    done = subprocess.run([str(cli), "cyclopean", "--left-rgb", str(paths[0]), "--right-rgb", str(paths[1]),
                           "--max-disparity", "32", "--matcher", "sgm", "--out-dir", str(out)],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert np.array_equal(view["rgb"], np.asarray(Image.open(out / "middle_rgb.png").convert("RGB")))
    census = renderer.cyclopean(pair[0], pair[1], max_disparity=32, matcher="census")
    assert not np.array_equal(view["rgb"], census["rgb"])
    with pytest.raises(vs.InvalidInputError) as err:
        renderer.cyclopean(pair[0], pair[1], matcher="graph-cut")
    assert "graph-cut" in str(err.value)
