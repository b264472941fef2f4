#!/usr/bin/env python3
"""Where the squared error of two_image_pairs.py's views is (issue 48): per pair, the share of
pixels and of the squared error in each mask class (255 rendered from matched disparities, 128
inferred/densified or filled, 0 left empty) with its PSNR, the error held by the 1 % worst
pixels, and the 8 x 6 block grid's largest cells (share of the pair's error, block's row and
column). With --images, also writes each pair's error image (|view - truth| x 3) as error.png.

Usage: error_classes.py OUT_DIR [--images]   (OUT_DIR: what two_image_pairs.py wrote; numpy, Pillow)
"""
import sys
from pathlib import Path

import numpy as np
from PIL import Image

sys.path.insert(0, str(Path(__file__).resolve().parent))
from two_image_pairs import pairs, rgb  # noqa: E402


def db(se):
    return 10 * np.log10(255.0**2 / se.mean())


def main():
    out, images = Path(sys.argv[1]), "--images" in sys.argv[2:]
    for name, _l, _r, m, crop in pairs():
        case = out / name / "out"
        if not (case / "middle_rgb.png").exists():
            continue
        truth = rgb(m)
        if crop:
            w = truth.shape[1] - crop
            truth = truth[:, crop // 2 : crop // 2 + w]
        view = rgb(case / "middle_rgb.png")
        mask = np.asarray(Image.open(case / "middle_mask.png").convert("L"))
        se = ((view - truth) ** 2).mean(axis=2)
        total = se.sum()
        print(f"{name}: {db(se):.2f} dB")
        for c in (255, 128, 0):
            k = mask == c
            if k.any():
                print(f"  mask {c:3d}: {100 * k.mean():5.1f} % of pixels, {100 * se[k].sum() / total:5.1f} % of the error, {db(se[k]):.2f} dB")
        worst = np.sort(se.ravel())[::-1][: se.size // 100]
        print(f"  worst 1 % of pixels: {100 * worst.sum() / total:.1f} % of the error")
        h, w = se.shape
        by, bx = h // 6, w // 8
        cells = sorted(
            ((se[i * by : (i + 1) * by, j * bx : (j + 1) * bx].sum() / total, i, j) for i in range(6) for j in range(8)),
            reverse=True,
        )
        print("  largest blocks: " + ", ".join(f"{100 * s:.1f} % (rows {i * by}-{(i + 1) * by}, cols {j * bx}-{(j + 1) * bx})" for s, i, j in cells[:4]))
        if images:
            Image.fromarray(np.clip(3 * np.sqrt(se), 0, 255).astype(np.uint8)).save(out / name / "error.png")


if __name__ == "__main__":
    main()
