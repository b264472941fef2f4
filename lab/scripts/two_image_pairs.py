#!/usr/bin/env python3
"""`cyclopean --fill` from two images alone on the issue-48 pairs (8 Middlebury 2005/2006 dev
scenes, Cones, two Tsukuba pairs, the two cropped pairs of docs/cyclopean.md): PSNR over all
pixels and over the rendered (mask 255) pixels, with their share, against the true middle view.

Usage: two_image_pairs.py BIN OUT_DIR [extra cyclopean args...]   (needs numpy and Pillow)
"""
import subprocess, sys, time
from pathlib import Path

import numpy as np
from PIL import Image

DATA = Path(__file__).resolve().parents[3] / "shared" / "data"


def rgb(p):
    return np.asarray(Image.open(p).convert("RGB"), dtype=np.float64)


def psnr(a, b, keep=None):
    se = (a - b) ** 2
    if keep is not None:
        se = se[keep]
    return 10 * np.log10(255.0**2 / se.mean())


def pairs():
    dev = DATA / "middlebury2005_2006_dev"
    for s in sorted(p.name for p in dev.iterdir() if p.is_dir()):
        yield s, dev / s / "view1.png", dev / s / "view5.png", dev / s / "view3.png", None
    c = DATA / "middlebury2003_cones"
    yield "cones", c / "im2.png", c / "im6.png", c / "im4.png", None
    t = DATA / "tsukuba_5view_no_gt"
    yield "tsukuba24", t / "tsukuba2.png", t / "tsukuba4.png", t / "tsukuba3.png", None
    yield "tsukuba15", t / "tsukuba1.png", t / "tsukuba5.png", t / "tsukuba3.png", None
    yield "cones_crop24", c / "im2.png", c / "im6.png", c / "im4.png", 24
    yield "tsukuba24_crop16", t / "tsukuba2.png", t / "tsukuba4.png", t / "tsukuba3.png", 16


def main():
    bin_, out = sys.argv[1], Path(sys.argv[2])
    extra = sys.argv[3:]
    rows = []
    for name, l, r, m, crop in pairs():
        case = out / name
        case.mkdir(parents=True, exist_ok=True)
        truth = rgb(m)
        if crop:
            # The left image loses its first `crop` columns, the right its last: every
            # disparity d becomes d - crop; the middle view loses crop / 2 on each side.
            w = truth.shape[1] - crop
            Image.fromarray(rgb(l)[:, crop:].astype(np.uint8)).save(case / "l.png")
            Image.fromarray(rgb(r)[:, :w].astype(np.uint8)).save(case / "r.png")
            truth = truth[:, crop // 2 : crop // 2 + w]
            l, r = case / "l.png", case / "r.png"
        t0 = time.time()
        o = subprocess.run(
            [bin_, "cyclopean", "--left-rgb", str(l), "--right-rgb", str(r), "--fill", "--out-dir", str(case / "out"), *extra],
            capture_output=True, text=True,
        )
        secs = time.time() - t0
        if o.returncode != 0:
            print(f"{name}: FAILED {o.stderr}", flush=True)
            continue
        view = rgb(case / "out" / "middle_rgb.png")
        mask = np.asarray(Image.open(case / "out" / "middle_mask.png").convert("L")) == 255
        a, rd, share = psnr(view, truth), psnr(view, truth, mask), mask.mean() * 100
        rows.append((name, a, rd, share))
        print(f"{name:18s} all {a:6.2f}  rendered {rd:6.2f} ({share:5.1f} %)  {secs:5.1f} s", flush=True)
    print(f"{'mean':18s} all {np.mean([r[1] for r in rows]):6.2f}  rendered {np.mean([r[2] for r in rows]):6.2f} ({np.mean([r[3] for r in rows]):5.1f} %)")


if __name__ == "__main__":
    main()
