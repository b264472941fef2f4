"""The optical-flow peer for middle views: what a user without viewsynth writes in ten lines of
OpenCV. DIS optical flow both ways (preset MEDIUM, on grey levels), a backward warp of each image
by half its flow (bilinear, borders replicated), and the average of the two warps.

    python python/peers/flow_interpolation.py LEFT.png RIGHT.png OUT.png [--truth MIDDLE.png]

Writes the interpolated middle view to OUT.png and, with --truth, prints its PSNR over all
pixels (8-bit peak) as JSON on stdout: {"psnr_db": ...}. `viewsynth report --data-dir DATA
--flow-peer DIR` scores images written this way beside viewsynth's own rows, one per real pair
with a true middle view, each named after its pair: DIR/cones_2_6_4.png (Middlebury 2003 Cones
im2 + im6 -> im4), DIR/tsukuba_2_4_3.png and DIR/tsukuba_1_5_3.png (Tsukuba views 2 + 4 and
1 + 5 -> 3), DIR/art_1_5_3.png ... DIR/midd2_1_5_3.png (the Middlebury 2005/2006 development
scenes, view1 + view5 -> view3); a pair whose set DATA holds and whose file is missing fails the
report. python/peers/rife_interpolation.py writes the RIFE peer's the same way (--rife-peer).
docs/report.md ("The optical-flow peer") has the shell loop that writes them all. Needs
opencv-python(-headless) and numpy; neither is a dependency of viewsynth.
"""

import argparse
import json

import cv2
import numpy as np


def interpolate(left, right):
    """The middle view of a rectified (or any) pair by half-flow warps of both images."""
    grey = [cv2.cvtColor(im, cv2.COLOR_BGR2GRAY) for im in (left, right)]
    dis = cv2.DISOpticalFlow_create(cv2.DISOPTICAL_FLOW_PRESET_MEDIUM)
    flow_lr = dis.calc(grey[0], grey[1], None)
    flow_rl = dis.calc(grey[1], grey[0], None)
    h, w = grey[0].shape
    xs, ys = np.meshgrid(np.arange(w, dtype=np.float32), np.arange(h, dtype=np.float32))

    def warp(image, flow):
        return cv2.remap(image, xs - 0.5 * flow[..., 0], ys - 0.5 * flow[..., 1],
                         cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)

    both = warp(left, flow_lr).astype(np.float32) + warp(right, flow_rl).astype(np.float32)
    return np.clip(np.rint(both / 2), 0, 255).astype(np.uint8)


def psnr(a, b):
    mse = np.mean((a.astype(np.float64) - b.astype(np.float64)) ** 2)
    return float("inf") if mse == 0 else 10 * np.log10(255.0 ** 2 / mse)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("left")
    p.add_argument("right")
    p.add_argument("out")
    p.add_argument("--truth")
    a = p.parse_args()
    left, right = cv2.imread(a.left, cv2.IMREAD_COLOR), cv2.imread(a.right, cv2.IMREAD_COLOR)
    if left is None or right is None:
        raise SystemExit(f"cannot read {a.left if left is None else a.right}")
    middle = interpolate(left, right)
    if not cv2.imwrite(a.out, middle):
        raise SystemExit(f"cannot write {a.out}")
    if a.truth:
        truth = cv2.imread(a.truth, cv2.IMREAD_COLOR)
        print(json.dumps({"psnr_db": psnr(middle, truth)}))


if __name__ == "__main__":
    main()
