"""Functions run in worker processes by test_threads_and_processes.py (importable by spawn)."""

import viewsynth as vs

from conftest import make_frame


def refocus_in_worker(scales):
    """Open a Renderer in this process and refocus the test frame."""
    rgb, depth, K = make_frame()
    with vs.Renderer() as r:
        return [{k: v for k, v in view.items() if k != "timings"} for view in r.refocus(rgb, depth, K, scales=scales)]


# Set by the parent before forking (a Renderer does not pickle; a forked child inherits it).
INHERITED = None


def inherited_renderer_errors():
    """In a forked child: both the parent's Renderer and a new one refuse, with messages."""
    renderer = INHERITED
    rgb, depth, K = make_frame()
    errors = []
    try:
        renderer.refocus(rgb, depth, K, scales=[1.0])
    except vs.RendererForkedError as e:
        errors.append(str(e))
    try:
        vs.Renderer()
    except vs.RendererForkedError as e:
        errors.append(str(e))
    return errors
