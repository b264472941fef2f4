"""Augmentation from Python: rgb_everywhere (colour inside the whole source frame, mask and
depth unchanged), random zoom in refocus_batch (the CLI's --zoom-random draws), progress
reports, the dataset index (read_index) and read_depth for every depth format the CLI writes."""

import subprocess

import numpy as np
import pytest

import viewsynth as vs
from _batch_frames import write_manifest
from conftest import make_frame


def test_rgb_everywhere_colours_the_frame_and_keeps_mask_and_depth(renderer, frame):
    rgb, depth, K = frame
    plain = renderer.refocus(rgb, depth, K, scales=[1.0, 2.0])
    every = renderer.refocus(rgb, depth, K, scales=[1.0, 2.0], rgb_everywhere=True)
    for a, b in zip(plain, every):
        assert np.array_equal(a["mask"], b["mask"])
        assert np.array_equal(a["depth"].view(np.uint32), b["depth"].view(np.uint32))
        assert np.array_equal(a["rgb"][a["mask"]], b["rgb"][b["mask"]])
    # The frame has holes (0 and NaN depth) and a box whose edges break the mesh: black without
    # the option, the source's colour with it (s = 1: the source itself, within a level).
    assert (~plain[0]["mask"]).sum() > 0
    assert np.abs(every[0]["rgb"].astype(int) - rgb.astype(int)).max() <= 1


def test_refocus_batch_random_zoom_progress_and_index(renderer, cli, tmp_path):
    manifest = write_manifest(tmp_path / "in")
    calls = []
    options = dict(zoom_random=(0.6, 1.8), samples=3, seed=7, jobs=1, depth_format="npy,png16,exr")
    summary = renderer.refocus_batch(manifest, tmp_path / "py", progress=lambda d, t: calls.append((d, t)),
                                     rgb_everywhere=True, **options)
    assert summary["rendered"] == 3
    assert calls == [(1, 3), (2, 3), (3, 3)]
    rows = vs.read_index(tmp_path / "py")
    assert len(rows) == 3 * 3
    by_frame = {}
    for r in rows:
        by_frame.setdefault(r["frame"], []).append(r["scale"])
        assert 0.6 <= r["scale"] <= 1.8
        z = vs.read_depth(r["depth"])
        assert z.dtype == np.float32 and z.shape == (r["height"], r["width"])
    assert all(len(set(s)) == 3 for s in by_frame.values())
    assert len({tuple(s) for s in by_frame.values()}) == 3
    # The CLI draws the same scales for the same frames and seed.
    done = subprocess.run([str(cli), "refocus", "--batch", str(manifest), "--out-dir", str(tmp_path / "cli"),
                           "--zoom-random", "0.6,1.8", "--samples", "3", "--seed", "7", "--jobs", "1",
                           "--rgb-everywhere", "--depth-format", "npy,png16,exr"], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    cli_rows = vs.read_index(tmp_path / "cli", absolute=False)
    assert [(r["frame"], r["scale"]) for r in cli_rows] == [(r["frame"], r["scale"]) for r in rows]


def test_progress_errors_are_raised_after_the_batch(renderer, tmp_path):
    manifest = write_manifest(tmp_path / "in")

    def fail(done, total):
        raise RuntimeError("stop here")

    with pytest.raises(RuntimeError, match="stop here"):
        renderer.refocus_batch(manifest, tmp_path / "out", scales=[1.0], jobs=0, progress=fail)
    with pytest.raises(vs.InvalidInputError, match="progress"):
        renderer.refocus_batch(manifest, tmp_path / "out", scales=[1.0], progress="yes")


def test_read_depth_reads_every_format_the_cli_writes(renderer, tmp_path):
    rgb, depth, K = make_frame(48, 36)
    depth = np.nan_to_num(depth, nan=0.0)
    np.save(tmp_path / "d.npy", depth)
    from PIL import Image
    Image.fromarray(rgb).save(tmp_path / "c.png")
    manifest = tmp_path / "frames.csv"
    manifest.write_text(f"rgb,depth,fx,fy,cx,cy,name\nc.png,d.npy,{K[0, 0]},{K[1, 1]},{K[0, 2]},{K[1, 2]},f\n")
    renderer.refocus_batch(manifest, tmp_path / "out", scales=[1.0], depth_format="exr,npy,png16")
    [row] = vs.read_index(tmp_path / "out")
    folder = tmp_path / "out" / "f"
    exr, npy = (vs.read_depth(folder / f"s1_depth.{ext}") for ext in ("exr", "npy"))
    # The png16 file's units come from its row, never assumed.
    assert row["depth"].endswith("s1_depth.exr") and "depth_scale" not in row
    png = vs.read_depth(folder / "s1_depth.png", depth_scale=1000)
    assert np.array_equal(exr, npy)
    valid = npy > 0
    assert np.abs(png[valid] - npy[valid]).max() <= 0.0005 + 1e-6  # millimetres, rounded
    with pytest.raises(vs.FileError, match="missing.exr"):
        vs.read_depth(tmp_path / "missing.exr")


def test_a_stack_of_four_equals_four_single_calls(renderer):
    frames = [make_frame(64, 48, seed=s) for s in range(4)]
    rgb = np.stack([f[0] for f in frames])
    depth = np.stack([f[1] for f in frames])
    Ks = np.stack([f[2] for f in frames])
    for K in (Ks, frames[0][2]):  # one K per frame, or one for all
        stacked = renderer.refocus(rgb, depth, K, scales=[0.7, 1.3], rgb_everywhere=True)
        assert len(stacked) == 4
        for i, views in enumerate(stacked):
            k = K[i] if K.ndim == 3 else K
            single = renderer.refocus(rgb[i], depth[i], k, scales=[0.7, 1.3], rgb_everywhere=True)
            for a, b in zip(views, single):
                for key in ("rgb", "depth", "mask", "K"):
                    assert np.array_equal(a[key], b[key]), (i, key)
    # A strided stack (BGR turned RGB) too.
    bgr = np.ascontiguousarray(rgb[..., ::-1])
    strided = renderer.refocus(bgr[..., ::-1], depth, Ks, scales=[1.0])
    assert all(np.array_equal(s[0]["rgb"], renderer.refocus(rgb[i], depth[i], Ks[i], scales=[1.0])[0]["rgb"])
               for i, s in enumerate(strided))
    with pytest.raises(vs.InvalidInputError, match="depth"):
        renderer.refocus(rgb, depth[0], Ks)
    with pytest.raises(vs.InvalidInputError, match="K"):
        renderer.refocus(rgb, depth, Ks[:3])


def test_a_stack_takes_scales_per_sample(renderer):
    frames = [make_frame(48, 36, seed=s) for s in range(3)]
    rgb = np.stack([f[0] for f in frames])
    depth = np.stack([f[1] for f in frames])
    K = frames[0][2]
    draws = np.array([[0.6, 1.2], [0.8, 1.7], [1.1, 0.9]])  # (N, k), as Kornia draws per sample
    for scales in (draws, draws.tolist()):
        stacked = renderer.refocus(rgb, depth, K, scales=scales)
        assert len(stacked) == 3
        for i, views in enumerate(stacked):
            assert [v["scale"] for v in views] == pytest.approx(list(draws[i]))
            single = renderer.refocus(rgb[i], depth[i], K, scales=list(draws[i]))
            for a, b in zip(views, single):
                assert np.array_equal(a["rgb"], b["rgb"]) and np.array_equal(a["mask"], b["mask"]), i
    # An (N, 1) array is one scale per sample, never N scales for every frame.
    per_sample = renderer.refocus(rgb, depth, K, scales=draws[:, :1])
    assert [len(views) for views in per_sample] == [1, 1, 1]
    assert [views[0]["scale"] for views in per_sample] == pytest.approx([0.6, 0.8, 1.1])
    with pytest.raises(vs.InvalidInputError, match=r"scales: 2 lists of scales for a stack of 3 frames"):
        renderer.refocus(rgb, depth, K, scales=draws[:2])
    with pytest.raises(vs.InvalidInputError, match=r"scales: a list per sample is for a stack"):
        renderer.refocus(rgb[0], depth[0], K, scales=draws)
    with pytest.raises(vs.InvalidInputError, match=r"scales\[1\]"):
        renderer.refocus(rgb, depth, K, scales=[[1.0], "x", [1.0]])
    with pytest.raises(vs.InvalidInputError, match=r"scales: a 3-D array"):
        renderer.refocus(rgb, depth, K, scales=draws[None])
