"""Renderer.refocus_batch (the library's batch on the Renderer's context) writes what
`viewsynth refocus --batch` writes for the same manifest: the same frame folders and files, byte
for byte; load_manifest names frames as the CLI does; bad frames and options raise clear errors."""

import subprocess

import pytest

import viewsynth as vs
from _batch_frames import SCALES, assert_same_batch_output, write_manifest

CLI_FLAGS = ["--zoom-range", ",".join(map(str, SCALES)), "--depth-format", "npy,png16", "--jobs", "1"]
OPTIONS = dict(scales=SCALES, depth_format=["npy", "png16"], jobs=1)


def run_cli_batch(cli, manifest, out, expect_rc=0):
    done = subprocess.run([str(cli), "refocus", "--batch", str(manifest), "--out-dir", str(out), "--device", "auto"]
                          + CLI_FLAGS, capture_output=True, text=True)
    assert done.returncode == expect_rc, done.stderr
    return done


def test_load_manifest_names_and_resolves_like_the_cli(tmp_path):
    manifest = write_manifest(tmp_path / "in")
    frames = vs.load_manifest(manifest)
    assert [f["name"] for f in frames] == ["00000_TUM_color", "00001_synth0", "second"]
    assert frames[1]["rgb"] == str(tmp_path / "in" / "synth0.png")  # relative to the manifest
    assert frames[0]["depth_scale"] == 5000.0 and frames[1]["depth_scale"] is None
    assert set(frames[0]) == {"name", "rgb", "depth", "fx", "fy", "cx", "cy", "depth_scale", "sun_bit_rotate"}
    with pytest.raises(vs.FileError) as err:
        vs.load_manifest(tmp_path / "nope.csv")
    assert "nope.csv" in str(err.value)


def test_refocus_batch_equals_cli_batch(renderer, cli, tmp_path):
    manifest = write_manifest(tmp_path / "in")
    run_cli_batch(cli, manifest, tmp_path / "cli")
    # Frames as dicts (a share of the manifest, as a Ray worker gets them) and as the path.
    frames = vs.load_manifest(manifest)
    summary = renderer.refocus_batch(frames[:2], tmp_path / "py", **OPTIONS)
    assert (summary["rendered"], summary["skipped"], summary["failed"]) == (2, 0, [])
    summary = renderer.refocus_batch(str(manifest), tmp_path / "py", **OPTIONS)
    assert (summary["rendered"], summary["skipped"]) == (1, 2)  # resume: the first two are done
    names = assert_same_batch_output(tmp_path / "cli", tmp_path / "py")
    assert names == ["00000_TUM_color", "00001_synth0", "second"]
    # Five files per scale: rgb, depth .npy and .png, mask; plus the manifest.
    assert len(list((tmp_path / "py" / "second").iterdir())) == 4 * len(SCALES) + 1
    summary = renderer.refocus_batch(frames, tmp_path / "py", resume=False, **OPTIONS)
    assert summary["rendered"] == 3
    assert set(summary) >= {"rendered", "skipped", "other_shards", "failed", "wall_s", "stages"}


def test_a_failed_frame_is_listed_and_the_others_complete(renderer, cli, tmp_path):
    manifest = write_manifest(tmp_path / "in", broken=True)
    done = run_cli_batch(cli, manifest, tmp_path / "cli", expect_rc=1)
    assert "broken" in done.stderr
    summary = renderer.refocus_batch(manifest, tmp_path / "py", **OPTIONS)
    assert summary["rendered"] == 3
    [(name, error)] = summary["failed"]
    assert name == "broken" and "missing_depth.npy" in error
    assert not (tmp_path / "py" / "broken").exists()
    assert_same_batch_output(tmp_path / "cli", tmp_path / "py")


def test_shares_without_index_then_write_index_equal_the_cli_index(renderer, cli, tmp_path):
    # A scheduler's shares (Ray, Dask): each call writes no index; one write_index over the whole
    # manifest then gives the CLI's index.jsonl byte for byte. Before index=False each share
    # wrote its own index.jsonl, numbered from 0 and holding only its frames.
    manifest = write_manifest(tmp_path / "in", broken=True)
    run_cli_batch(cli, manifest, tmp_path / "cli", expect_rc=1)
    frames = vs.load_manifest(manifest)
    for share in (frames[3:], frames[1:3], frames[:1]):
        renderer.refocus_batch(share, tmp_path / "py", index=False, **OPTIONS)
        assert not (tmp_path / "py" / "index.jsonl").exists()
    assert not list((tmp_path / "py").glob("index.part-*"))
    settings = {k: v for k, v in OPTIONS.items() if k not in ("resume", "jobs")}
    path, rows = vs.write_index(frames, tmp_path / "py", **settings)
    assert path == str(tmp_path / "py" / "index.jsonl") and rows == 3 * len(SCALES)
    assert_same_batch_output(tmp_path / "cli", tmp_path / "py")
    assert (tmp_path / "py" / "index.jsonl").read_text() == (tmp_path / "cli" / "index.jsonl").read_text()
    # Other settings than the frames were made with: no frame is theirs, so no row.
    _, rows = vs.write_index(frames, tmp_path / "py", **dict(settings, scales=[1.5]))
    assert rows == 0


def test_write_index_takes_refocus_batchs_settings_with_the_same_defaults():
    # write_index keeps a frame's rows only where its manifest records these settings, so its
    # keywords must be refocus_batch's settings, same names, order and defaults. pyo3 takes each
    # signature as a literal (python/src/index.rs and batch.rs write the list twice): this
    # holds the two together. What only steers a run (resume, verify, jobs, shard, progress, index)
    # is not a setting.
    import inspect

    run_only = {"self", "resume", "verify", "jobs", "shard", "progress", "index"}
    batch = inspect.signature(vs.Renderer.refocus_batch).parameters.values()
    index = inspect.signature(vs.write_index).parameters.values()
    want = [(p.name, p.kind, p.default) for p in batch if p.name not in run_only]
    assert [(p.name, p.kind, p.default) for p in index] == want


def batch_error(renderer, tmp_path, frames, parameter, words, **options):
    with pytest.raises(vs.InvalidInputError) as err:
        renderer.refocus_batch(frames, tmp_path / "out", **options)
    message = str(err.value)
    assert parameter in message, message
    for w in words:
        assert w in message, message


def test_refocus_batch_bad_inputs(renderer, tmp_path):
    frame = {"name": "a", "rgb": "a.png", "depth": "a.npy", "fx": 1.0, "fy": 1.0, "cx": 0.0, "cy": 0.0}
    batch_error(renderer, tmp_path, [dict(frame, colour="x")], "frames[0]", ["unknown key 'colour'"])
    batch_error(renderer, tmp_path, [{k: v for k, v in frame.items() if k != "name"}], "frames[0]", ["missing key 'name'"])
    batch_error(renderer, tmp_path, [dict(frame, name="../up")], "frames[0]", ["'../up'"])
    batch_error(renderer, tmp_path, [frame, frame], "frames[1]", ["'a' repeated"])
    batch_error(renderer, tmp_path, [dict(frame, fx="wide")], "frames[0]", ["'fx'"])
    batch_error(renderer, tmp_path, [], "frames", ["no frame"])
    batch_error(renderer, tmp_path, [42], "frames[0]", ["expected a dict"])
    batch_error(renderer, tmp_path, [frame], "depth_format", ["'tiff'"], depth_format="tiff")
    batch_error(renderer, tmp_path, [frame], "rgb_format", ["'bmp'"], rgb_format="bmp")
    batch_error(renderer, tmp_path, [frame], "invalid png_compression", ["'huge'"], png_compression="huge")
    batch_error(renderer, tmp_path, [frame], "shard", ["'3/2'"], shard="3/2")
    # One file tag in the range, two samples asked for: refused (it drew forever).
    batch_error(renderer, tmp_path, [frame], "zoom_random/samples", ["1 distinct scale"], zoom_random=(1.0, 1.0000001), samples=2)
    batch_error(renderer, tmp_path, [frame], "depth_preview", ["outputs"], depth_preview=True, outputs=["rgb"])
    batch_error(renderer, tmp_path, [frame], "scales", ["no target given"], scales=[])
    batch_error(renderer, tmp_path, [frame], "tau", [], tau_rel=-1.0)
    assert not (tmp_path / "out").exists()  # nothing written for a refused call


def test_verify_redoes_a_frame_whose_file_changed_with_its_size_kept(renderer, tmp_path):
    frames = vs.load_manifest(write_manifest(tmp_path / "in"))[1:2]
    out = tmp_path / "py"
    assert renderer.refocus_batch(frames, out, scales=[1.0], jobs=1)["rendered"] == 1
    rgb = out / frames[0]["name"] / "s1_rgb.png"
    good = rgb.read_bytes()
    changed = bytearray(good)
    changed[len(changed) // 2] ^= 0xFF
    rgb.write_bytes(bytes(changed))
    # Resume checks sizes (the commit journal makes a frame all-or-none); verify=True, as the
    # CLI's --verify, checks every file's CRC-32 and redoes the frame.
    assert renderer.refocus_batch(frames, out, scales=[1.0], jobs=1)["skipped"] == 1
    summary = renderer.refocus_batch(frames, out, scales=[1.0], jobs=1, verify=True)
    assert (summary["rendered"], summary["skipped"]) == (1, 0)
    assert rgb.read_bytes() == good
    assert renderer.refocus_batch(frames, out, scales=[1.0], jobs=1, verify=True)["skipped"] == 1
