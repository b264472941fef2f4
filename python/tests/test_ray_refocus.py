"""python/examples/ray_refocus.py on a local Ray instance (CPU, llvmpipe, a few frames, up to two
actors) writes the same files as `viewsynth refocus --batch` on the same manifest with the same
augmentation (random zoom drawn per frame name, rgb everywhere), and reports a failed frame with
exit status 1 (as the CLI); its options map onto refocus_batch's keyword arguments. Ray is a test dependency (ci/python-tests.sh
installs it): without it this module fails to import, it is never skipped."""

import importlib.util
import inspect
import subprocess
import sys

import ray  # noqa: F401  (a missing Ray fails here, loudly)

import viewsynth as vs

from _batch_frames import assert_same_batch_output, write_manifest
from conftest import REPO

EXAMPLE = REPO / "python" / "examples" / "ray_refocus.py"


AUGMENT = ["--zoom-random", "0.6,1.8", "--samples", "2", "--seed", "7", "--rgb-everywhere"]


def example():
    spec = importlib.util.spec_from_file_location("ray_refocus", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_ray_example_options_are_refocus_batch_keywords():
    ex = example()
    options = ex.batch_options(ex.parse_args(["m.csv", "out"] + AUGMENT + ["--size", "64,48", "--verify"]))
    assert options["zoom_random"] == (0.6, 1.8) and options["samples"] == 2 and options["seed"] == 7
    assert options["rgb_everywhere"] is True and options["size"] == (64, 48) and options["verify"] is True
    assert "scales" not in options
    assert ex.batch_options(ex.parse_args(["m.csv", "out", "--scales", "0.5,2"]))["scales"] == [0.5, 2.0]
    keywords = inspect.signature(vs.Renderer.refocus_batch).parameters
    assert set(options) <= set(keywords), set(options) - set(keywords)


def test_ray_example_writes_the_cli_batch_files(cli, tmp_path):
    manifest = write_manifest(tmp_path / "in", broken=True)
    cli_run = subprocess.run([str(cli), "refocus", "--batch", str(manifest), "--out-dir", str(tmp_path / "cli"),
                              "--depth-format", "exr,npy", "--device", "auto"] + AUGMENT,
                             capture_output=True, text=True)
    assert cli_run.returncode == 1 and "broken" in cli_run.stderr, cli_run.stderr
    # One frame per map_batches call, so frames spread over the (up to two) actors.
    ray_run = subprocess.run([sys.executable, str(EXAMPLE), str(manifest), str(tmp_path / "ray"),
                              "--depth-format", "exr,npy", "--batch-size", "1",
                              "--max-actors", "2", "--num-cpus", "2"] + AUGMENT,
                             capture_output=True, text=True, timeout=480)
    assert ray_run.returncode == 1, ray_run.stdout + ray_run.stderr
    assert "failed: broken:" in ray_run.stderr and "missing_depth.npy" in ray_run.stderr, ray_run.stderr
    assert "4 frames: 3 done, 1 failed" in ray_run.stdout, ray_run.stdout
    names = assert_same_batch_output(tmp_path / "cli", tmp_path / "ray")
    assert names == ["00000_TUM_color", "00001_synth0", "second"]
    # Augmented: two drawn scales per frame (z0_s*, z1_s*), every pixel coloured.
    drawn = sorted(p.name for p in (tmp_path / "ray" / "second").iterdir() if p.name.endswith("_rgb.png"))
    assert [n[:3] for n in drawn] == ["z0_", "z1_"], drawn
