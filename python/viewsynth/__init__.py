"""viewsynth: headless GPU view synthesis from RGB-D images, numpy in, numpy out.

    import numpy as np, viewsynth as vs
    r = vs.Renderer()                        # one EGL context (GPU, or Mesa llvmpipe)
    views = r.refocus(rgb, depth, K, scales=[0.5, 2.0])
    views[0]["rgb"], views[0]["depth"], views[0]["mask"], views[0]["K"]
    mid = r.cyclopean(left_rgb, right_rgb, left_disparity, right_disparity, position=0.5)
    right = r.reproject(rgb, depth, K, baseline=0.1)["right"]
    ods = r.stitch(left_rgb, left_depth, right_rgb, right_depth, width=2048, height=1024)["rgb"]
    r.refocus_batch(vs.load_manifest("frames.csv"), "out/")   # files, as `viewsynth refocus --batch`
    rows = vs.read_index("out/")             # one dict per target; vs.read_depth(rows[0]["depth"],
                                             #   depth_scale=rows[0].get("depth_scale"))
    vs.write_index(frames, "out/")           # after shares rendered with refocus_batch(index=False)
    ds = vs.IndexDataset("out/")             # ds[i]: one target's arrays; ds.torch() for a DataLoader

A Renderer belongs to the thread that created it, and to the process that created it:
see the Renderer docstring for threads, fork and spawn.
"""

from ._viewsynth import FACE_ORDER, Renderer, __version__, info, load_manifest, read_depth, write_index
from .dataset import read_index
from .index_dataset import IndexDataset
from .errors import (
    FileError,
    GpuError,
    GpuUnavailableError,
    InvalidInputError,
    RendererBusyError,
    RendererClosedError,
    RendererForkedError,
    ViewsynthError,
    WrongThreadError,
)

__all__ = [
    "Renderer",
    "info",
    "load_manifest",
    "read_depth",
    "read_index",
    "IndexDataset",
    "write_index",
    "FACE_ORDER",
    "__version__",
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
