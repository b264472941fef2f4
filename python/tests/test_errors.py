"""Every error the package raises is a ViewsynthError (issue 46): files are read by the
library's rules (a FIFO or a device is refused at once, never read; a missing file, a folder and
bad UTF-8 are FileError, also an OSError), and a Renderer used to render or close from inside
one of its own calls raises RendererBusyError (also a RuntimeError)."""

import contextlib
import os
import signal

import numpy as np
import pytest
from PIL import Image

import viewsynth as vs
from conftest import make_frame


@contextlib.contextmanager
def deadline(seconds):
    """Fails the test instead of hanging the suite (opening a FIFO blocked forever before)."""
    def expired(signum, frame):
        raise AssertionError(f"still blocked after {seconds} s")
    previous = signal.signal(signal.SIGALRM, expired)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)


BAD_FILES = {
    "missing": lambda p: None,
    "directory": lambda p: p.mkdir(),
    "fifo": lambda p: os.mkfifo(p),
    "device": lambda p: p.symlink_to("/dev/zero"),
    "bad utf-8": lambda p: p.write_bytes(b'{"frame": "\xff\xfe"}\n'),
}

# Each public function that reads a file, and the name it reads in the folder it is given.
READERS = {
    "read_index": ("index.jsonl", lambda out: vs.read_index(out)),
    "load_manifest": ("frames.csv", lambda out: vs.load_manifest(out / "frames.csv")),
    "read_depth": ("depth.npy", lambda out: vs.read_depth(out / "depth.npy")),
}


@pytest.mark.parametrize("reader", sorted(READERS))
@pytest.mark.parametrize("bad", sorted(BAD_FILES))
def test_a_bad_file_raises_file_error(tmp_path, reader, bad):
    name, read = READERS[reader]
    BAD_FILES[bad](tmp_path / name)
    with deadline(20), pytest.raises(vs.ViewsynthError) as err:
        read(tmp_path)
    assert isinstance(err.value, vs.FileError) and isinstance(err.value, OSError), repr(err.value)
    assert name in str(err.value), str(err.value)


def test_a_renderer_used_from_inside_its_own_call_is_busy(renderer, tmp_path):
    rgb, depth, K = make_frame(32, 24)
    Image.fromarray(rgb).save(tmp_path / "c.png")
    np.save(tmp_path / "d.npy", depth)
    frames = [{"name": "f", "rgb": str(tmp_path / "c.png"), "depth": str(tmp_path / "d.npy"),
               "fx": K[0, 0], "fy": K[1, 1], "cx": K[0, 2], "cy": K[1, 2]}]
    refused, read = [], []

    def progress(done, total):
        for use in (lambda: renderer.refocus(rgb, depth, K, scales=[1.0]), renderer.close):
            try:
                use()
            except Exception as e:  # what each raises is the test's subject
                refused.append(e)
        read.append((renderer.backend, renderer.closed))

    renderer.refocus_batch(frames, tmp_path / "out", scales=[1.0], progress=progress)
    assert [type(e) for e in refused] == [vs.RendererBusyError] * 2, refused
    assert all(isinstance(e, vs.ViewsynthError) and isinstance(e, RuntimeError) for e in refused)
    assert "busy" in str(refused[0]), str(refused[0])
    # Its properties stay readable meanwhile, and it renders again once the call returned.
    assert read == [("gl", False)]
    assert renderer.refocus(rgb, depth, K, scales=[1.0])[0]["rgb"].shape == (24, 32, 3)
