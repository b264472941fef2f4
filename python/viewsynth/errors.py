"""Exceptions raised by viewsynth.

Every exception derives from :class:`ViewsynthError`, and also from the built-in class a
caller would expect (``ValueError`` for bad input, ``RuntimeError`` for GPU trouble,
``OSError`` for files), so ``except ValueError`` keeps working. The message is the Rust
library's own; ``parameter`` names the argument at fault when one is known (else ``None``).
"""


class ViewsynthError(Exception):
    """Base class of every viewsynth error."""

    parameter = None


class InvalidInputError(ViewsynthError, ValueError):
    """An argument has the wrong dtype, shape or memory layout, or a value out of its domain."""


class GpuUnavailableError(ViewsynthError, RuntimeError):
    """No EGL / OpenGL 4.5 context could be opened (or only a software one with require_gpu)."""


class GpuError(ViewsynthError, RuntimeError):
    """A call of the GPU backend (OpenGL or Vulkan) or one of its objects failed (shader, framebuffer,
    pipeline, an API error, an output not read back)."""


class FileError(ViewsynthError, OSError):
    """A file could not be read, decoded or written."""


class RendererForkedError(ViewsynthError, RuntimeError):
    """A Renderer (or any EGL context) crossed a fork: open Renderers in spawned workers, or only
    in the forked workers and never in their parent."""


class RendererClosedError(ViewsynthError, RuntimeError):
    """A Renderer was used after close()."""


class RendererBusyError(ViewsynthError, RuntimeError):
    """A Renderer was used to render or close while one of its own calls was running (from a
    callback of that call, such as refocus_batch's progress): wait for the call to return."""


class WrongThreadError(ViewsynthError, RuntimeError):
    """A Renderer was used on a thread other than the one that created it: one per thread."""


__all__ = [
    "ViewsynthError",
    "InvalidInputError",
    "GpuUnavailableError",
    "GpuError",
    "FileError",
    "RendererForkedError",
    "RendererClosedError",
    "RendererBusyError",
    "WrongThreadError",
]
