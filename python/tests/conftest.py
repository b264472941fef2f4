"""Shared fixtures: one Renderer per test session, the CLI binary, and a synthetic RGB-D frame.

The CLI is the repository's release build (``cargo build --release`` or ``cargo test --release``
makes it); set VIEWSYNTH_CLI to use another. A missing CLI fails the comparison tests (it never
skips them).
"""

import os
from pathlib import Path

import numpy as np
import pytest

import viewsynth as vs

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def renderer():
    r = vs.Renderer()
    yield r
    r.close()


@pytest.fixture(scope="session")
def cli():
    path = Path(os.environ.get("VIEWSYNTH_CLI", REPO / "target" / "release" / "viewsynth"))
    assert path.is_file(), f"viewsynth CLI not found at {path}: run cargo build --release first or set VIEWSYNTH_CLI"
    return path


def make_frame(width=96, height=72, seed=7):
    """A frame that exercises every rule: a tilted background, a box in front (its edges break
    the mesh), holes (0 and NaN) and textured colour. K as a 3x3 float64 matrix."""
    rng = np.random.default_rng(seed)
    yy, xx = np.mgrid[0:height, 0:width].astype(np.float32)
    depth = (3.0 + 0.01 * xx + 0.005 * yy).astype(np.float32)
    depth[height // 4 : height // 2, width // 3 : 2 * width // 3] = 1.5
    depth[5:9, 5:12] = 0.0
    depth[-6:-3, -10:-4] = np.nan
    rgb = rng.integers(0, 256, size=(height, width, 3), dtype=np.uint8)
    rgb[..., 0] = (xx * 255 / width).astype(np.uint8)
    K = np.array([[80.0, 0.0, (width - 1) / 2 + 0.3], [0.0, 78.0, (height - 1) / 2 - 0.2], [0.0, 0.0, 1.0]])
    return rgb, depth, K


@pytest.fixture(scope="session")
def frame():
    return make_frame()


def rss_bytes():
    """Resident set size of this process (Linux /proc)."""
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")
