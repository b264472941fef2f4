"""No leak over 1,000 refocus calls: RSS and open file descriptors stay flat.

Each call uploads a source (textures, program, framebuffer) and frees it (RAII in the library),
and hands three numpy arrays to Python; a leak of any of these grows RSS linearly. The calls
are tiny (16x12) so the loop takes a few seconds on llvmpipe.
"""

import os

import numpy as np

from conftest import make_frame, rss_bytes

CALLS = 1000
# Bound on RSS growth over the measured 1,000 calls after a 100-call warm-up (allocator and
# driver caches settle in the warm-up). Leaking only the three output arrays (16x12: 1.2 KB)
# per call would add 1.2 MB, a source texture set per call more; 1 MiB is far below either.
RSS_BOUND = 1 << 20


def test_no_leak_over_1000_calls(renderer):
    rgb, depth, K = make_frame(width=16, height=12)

    def call():
        views = renderer.refocus(rgb, depth, K, scales=[0.9, 1.1])
        assert views[1]["mask"].any()

    for _ in range(100):
        call()
    fds = len(os.listdir("/proc/self/fd"))
    before = rss_bytes()
    for _ in range(CALLS):
        call()
    growth = rss_bytes() - before
    print(f"RSS growth over {CALLS} calls: {growth} bytes")
    assert growth < RSS_BOUND, f"RSS grew {growth} bytes over {CALLS} calls"
    assert len(os.listdir("/proc/self/fd")) == fds


def test_no_leak_over_200_contexts():
    """Opening and closing a Renderer frees its EGL context. Run on a thread of its own: the
    session's Renderer shares this thread's context, so a Renderer here would not open one."""
    import threading

    import viewsynth as vs

    rgb, depth, K = make_frame(width=8, height=6)
    result = {}

    def open_and_close(n):
        for _ in range(n):
            with vs.Renderer() as r:
                r.refocus(rgb, depth, K, scales=[1.0])

    def worker():
        try:
            open_and_close(20)
            result["fds"] = len(os.listdir("/proc/self/fd"))
            result["before"] = rss_bytes()
            open_and_close(200)
            result["growth"] = rss_bytes() - result["before"]
            result["fds_after"] = len(os.listdir("/proc/self/fd"))
        except Exception as e:  # reported on the test's thread below
            result["error"] = e

    t = threading.Thread(target=worker)
    t.start()
    t.join()
    assert "error" not in result, result.get("error")
    # A leaked llvmpipe context keeps its framebuffer state and shader variants: several MB each.
    print(f"RSS growth over 200 contexts: {result['growth']} bytes")
    assert result["growth"] < 4 * RSS_BOUND, f"RSS grew {result['growth']} bytes over 200 contexts"
    assert result["fds_after"] == result["fds"]
