"""Focal-length augmentation for a PyTorch data pipeline, built on viewsynth.Renderer.refocus.

`RefocusAugment` wraps any map-style dataset whose items are (rgb uint8[H, W, 3], depth
float32[H, W] in metres, K 3x3) and returns each item re-rendered at a random zoom s in
[zoom_min, zoom_max] (log-uniform, as `refocus --zoom-random`: zooming in and out equally often)
from the same pose, at the same size, with its new K and a validity mask (what the source did not
see stays invalid: mask False, depth 0). Colour is sampled everywhere inside the source frame
(`rgb_everywhere=True`), so training images have no black holes at depth gaps and edges. It has the
`__len__`/`__getitem__` of a torch.utils.data.Dataset, so it plugs into a DataLoader as is;
torch itself is not needed here.

Workers: the Renderer is opened lazily, once per worker process and thread, on first use; never
in the parent. With torch's default "fork" workers that works as long as the parent opens no
Renderer itself; otherwise use DataLoader(..., multiprocessing_context="spawn").

    from torch.utils.data import DataLoader
    loader = DataLoader(RefocusAugment(my_rgbd_dataset), batch_size=8, num_workers=4,
                        multiprocessing_context="spawn")

Run this file to refocus a synthetic frame in two spawned worker processes (as DataLoader
workers would): python examples/refocus_augment.py
"""

import multiprocessing
import os
import threading

import numpy as np

import viewsynth as vs


class RefocusAugment:
    """Dataset wrapper: item i of `base` at a random focal scale (seeded per item and epoch)."""

    def __init__(self, base, zoom_min=0.7, zoom_max=1.4, seed=0, device="auto", **refocus_options):
        if not 0 < zoom_min <= zoom_max:
            raise ValueError(f"need 0 < zoom_min <= zoom_max, got {zoom_min}, {zoom_max}")
        self.base = base
        self.zoom = (zoom_min, zoom_max)
        self.seed = seed
        self.epoch = 0
        self.device = device
        self.options = {"rgb_everywhere": True, **refocus_options}
        self._local = threading.local()

    def __getstate__(self):
        # Sent to spawned workers: everything but the per-thread Renderer.
        state = dict(self.__dict__)
        del state["_local"]
        return state

    def __setstate__(self, state):
        self.__dict__.update(state)
        self._local = threading.local()

    def set_epoch(self, epoch):
        """Draw other zooms next epoch (call it from the training loop)."""
        self.epoch = epoch

    def renderer(self):
        """This process's and thread's Renderer, opened on first use."""
        local = self._local
        if getattr(local, "pid", None) != os.getpid():
            local.renderer = vs.Renderer(device=self.device)
            local.pid = os.getpid()
        return local.renderer

    def __len__(self):
        return len(self.base)

    def __getitem__(self, index):
        rgb, depth, K = self.base[index]
        rng = np.random.default_rng((self.seed, self.epoch, index))
        scale = float(np.exp(rng.uniform(np.log(self.zoom[0]), np.log(self.zoom[1]))))
        (view,) = self.renderer().refocus(rgb, depth, K, scales=[scale], **self.options)
        return {
            "rgb": view["rgb"],
            "depth": view["depth"],
            "mask": view["mask"],
            "K": view["K"],
            "scale": scale,
        }


def synthetic_frame(width=160, height=120):
    """A tilted plane with a box in front of it and a colour gradient."""
    yy, xx = np.mgrid[0:height, 0:width].astype(np.float32)
    depth = (2.0 + 0.01 * yy).astype(np.float32)
    depth[30:70, 50:110] = 1.2
    rgb = np.stack([xx * 255 / width, yy * 255 / height, np.full_like(xx, 128)], axis=-1).astype(np.uint8)
    K = np.array([[140.0, 0, (width - 1) / 2], [0, 140.0, (height - 1) / 2], [0, 0, 1]])
    return rgb, depth, K


def _item(args):
    data, i = args
    return i, os.getpid(), data[i]


if __name__ == "__main__":
    data = RefocusAugment([synthetic_frame()] * 4, zoom_min=0.6, zoom_max=1.8)
    # Workers as a DataLoader's: spawned, each opening its own Renderer on its first item.
    with multiprocessing.get_context("spawn").Pool(2) as pool:
        items = pool.map(_item, [(data, i) for i in range(len(data))])
    for i, pid, item in items:
        print(
            f"worker {pid} "
            f"item {i}: zoom {item['scale']:.3f}  fx' {item['K'][0, 0]:.1f}  "
            f"rgb {item['rgb'].shape}  valid {item['mask'].mean():.1%}"
        )
