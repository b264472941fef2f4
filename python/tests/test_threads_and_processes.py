"""A Renderer is thread-affine and process-affine: another thread gets WrongThreadError (and can
open its own Renderer), a forked child gets RendererForkedError instead of a hang, spawned
workers (and forked workers of a parent that never opened a context) render the same pixels."""

import multiprocessing as mp
import subprocess
import sys
import textwrap
import threading
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np
import pytest

import viewsynth as vs

import _workers

SCALES = [0.75, 1.5]


def same_views(a, b):
    assert len(a) == len(b)
    for x, y in zip(a, b):
        assert set(x) - {"timings"} == set(y) - {"timings"}
        for key in ("rgb", "depth", "mask", "K"):
            assert np.array_equal(x[key], y[key]), key


def in_thread(fn):
    out = {}

    def run():
        try:
            out["value"] = fn()
        except BaseException as e:  # handed to the test's thread
            out["error"] = e

    t = threading.Thread(target=run)
    t.start()
    t.join()
    return out


def test_other_thread_gets_wrong_thread_error_and_its_own_renderer_works(renderer, frame):
    rgb, depth, K = frame
    out = in_thread(lambda: renderer.refocus(rgb, depth, K, scales=SCALES))
    assert isinstance(out.get("error"), vs.WrongThreadError), out
    assert isinstance(out["error"], RuntimeError)
    assert "one Renderer per thread" in str(out["error"])
    assert "owned by another thread" in in_thread(lambda: repr(renderer))["value"]
    mine = renderer.refocus(rgb, depth, K, scales=SCALES)
    theirs = in_thread(lambda: _workers.refocus_in_worker(SCALES))
    assert "error" not in theirs, theirs
    same_views(mine, theirs["value"])


def test_renderers_on_one_thread_share_its_context(renderer, frame):
    rgb, depth, K = frame
    with vs.Renderer() as second:
        same_views(second.refocus(rgb, depth, K, scales=SCALES), renderer.refocus(rgb, depth, K, scales=SCALES))
    # Closing the second one left the first one's context in place.
    assert renderer.refocus(rgb, depth, K, scales=[1.0])[0]["mask"].any()
    with pytest.raises(vs.InvalidInputError, match="one EGL context per thread"):
        vs.Renderer(device="surfaceless")


def test_renderer_does_not_pickle_and_says_why(renderer):
    import pickle

    with pytest.raises(TypeError, match="create one inside each worker"):
        pickle.dumps(renderer)


def test_forked_child_refuses_instead_of_hanging(renderer):
    ctx = mp.get_context("fork")
    _workers.INHERITED = renderer
    try:
        with ProcessPoolExecutor(1, mp_context=ctx) as pool:
            errors = pool.submit(_workers.inherited_renderer_errors).result(timeout=60)
    finally:
        _workers.INHERITED = None
    assert len(errors) == 2
    assert "forked after it was created" in errors[0]
    assert "spawn" in errors[1] and "forkserver" in errors[1]


def test_spawned_workers_render_the_same_pixels(renderer, frame):
    rgb, depth, K = frame
    ctx = mp.get_context("spawn")
    with ProcessPoolExecutor(2, mp_context=ctx) as pool:
        results = list(pool.map(_workers.refocus_in_worker, [SCALES, SCALES], timeout=120))
    mine = renderer.refocus(rgb, depth, K, scales=SCALES)
    for r in results:
        same_views(mine, r)


def test_fork_workers_work_when_the_parent_never_opened_a_context(renderer, frame, tmp_path):
    # This pytest process has a context open, so the parent here is a fresh interpreter.
    script = textwrap.dedent(
        f"""
        import multiprocessing as mp, sys
        import numpy as np
        sys.path.insert(0, {str(Path(__file__).parent)!r})
        import _workers
        if __name__ == "__main__":
            with mp.get_context("fork").Pool(2) as pool:
                views = pool.map(_workers.refocus_in_worker, [{SCALES!r}] * 2)
            np.save({str(tmp_path / "rgb.npy")!r}, np.stack([v[1]["rgb"] for v in views]))
        """
    )
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    rgb, depth, K = frame
    mine = renderer.refocus(rgb, depth, K, scales=SCALES)[1]["rgb"]
    for theirs in np.load(tmp_path / "rgb.npy"):
        assert np.array_equal(mine, theirs)
