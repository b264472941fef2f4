#!/usr/bin/env python3
"""Experiment (issue 48): the semi-global matcher's disparities with small segments removed
(Hirschmueller's peak filter, OpenCV's filterSpeckles), rendered by `cyclopean --fill` as given
disparities, over the uncropped issue-48 pairs whose estimated range starts at 0. Not a shipped
step: it measures whether one is worth building (docs/cyclopean.md, "Small segments").

A segment: known pixels joined to their 4-neighbours when the disparities differ by at most 1 px.
One of at most SIZE pixels (SIZE < 1: that share of the image's pixels) becomes unknown, and the
densify step fills it. Modes: `all` removes every small segment; `peak` only those nearer than
their border (mean disparity above the mean of the known pixels around them); `novalley` all but
those more than 2 px farther than their border. The `base` column renders the twin's disparities
unchanged (the default pipeline's all-pixel figure, through the given-disparity path).

Usage: segment_filter.py BIN OUT_DIR MODE SIZE...   (needs numpy, Pillow, scipy; builds nothing:
    run `cargo build --release -p viewsynth-lab --example twin_disparities` first)
Prints per pair: base PSNR, then per SIZE the PSNR over all pixels and the share removed (%).
"""
import re, subprocess, sys
from pathlib import Path

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

sys.path.insert(0, str(Path(__file__).resolve().parent))
from two_image_pairs import pairs, rgb, psnr  # noqa: E402

TWIN = Path(__file__).resolve().parents[2] / "target" / "release" / "examples" / "twin_disparities"


def segments(d):
    """Segment label per pixel, and each segment's size."""
    h, w = d.shape
    idx = np.arange(h * w).reshape(h, w)
    rows, cols = [], []
    for a, b, da, db in [(idx[:, :-1], idx[:, 1:], d[:, :-1], d[:, 1:]), (idx[:-1], idx[1:], d[:-1], d[1:])]:
        ok = (da > 0) & (db > 0) & (np.abs(da - db) <= 1.0)
        rows.append(a[ok])
        cols.append(b[ok])
    r, c = np.concatenate(rows), np.concatenate(cols)
    n, lab = connected_components(coo_matrix((np.ones(len(r)), (r, c)), shape=(h * w, h * w)), directed=False)
    return n, lab.reshape(h, w), np.bincount(lab.ravel(), minlength=n)


def filtered(d, size, mode):
    n, lab, counts = segments(d)
    known = d > 0
    drop = (counts[lab] <= size) & known
    if mode != "all":
        # Mean disparity of each segment's known 4-neighbours in other segments.
        sums, cnt = np.zeros(n), np.zeros(n)
        for p, q in [((slice(None), slice(None, -1)), (slice(None), slice(1, None))), ((slice(None, -1), slice(None)), (slice(1, None), slice(None)))]:
            for a, b in [(p, q), (q, p)]:
                ok = known[a] & known[b] & (lab[a] != lab[b])
                np.add.at(sums, lab[a][ok], d[b][ok])
                np.add.at(cnt, lab[a][ok], 1)
        mean = np.bincount(lab.ravel(), weights=d.ravel(), minlength=n) / np.maximum(counts, 1)
        border = sums / np.maximum(cnt, 1)
        keep = (cnt > 0) & (mean > border) if mode == "peak" else ~((cnt > 0) & (mean < border - 2.0))
        drop &= keep[lab]
    out = d.copy()
    out[drop] = 0
    return out, drop.mean() * 100


def render(bin_, case, l, r, m, dl, dr):
    case.mkdir(parents=True, exist_ok=True)
    np.save(case / "dl.npy", dl)
    np.save(case / "dr.npy", dr)
    o = subprocess.run([bin_, "cyclopean", "--left-rgb", str(l), "--right-rgb", str(r), "--left-disparity", str(case / "dl.npy"),
                        "--right-disparity", str(case / "dr.npy"), "--fill", "--out-dir", str(case / "out")], capture_output=True, text=True)
    if o.returncode:
        raise SystemExit(f"{case}: {o.stderr}")
    return psnr(rgb(case / "out" / "middle_rgb.png"), rgb(m))


def main():
    bin_, out, mode, sizes = sys.argv[1], Path(sys.argv[2]), sys.argv[3], [float(s) for s in sys.argv[4:]]
    assert mode in ("all", "peak", "novalley"), mode
    rows = []
    for name, l, r, m, crop in pairs():
        if crop:
            continue
        o = subprocess.run([bin_, "cyclopean", "--left-rgb", str(l), "--right-rgb", str(r), "--outputs", "mask", "--out-dir", str(out / name / "range")],
                           capture_output=True, text=True)
        lo, hi = map(int, re.search(r"disparity range (-?\d+)\.\.(-?\d+)", o.stdout + o.stderr).groups())
        if lo < 0:
            print(f"{name}: range {lo}..{hi} crosses 0, skipped")
            continue
        prefix = out / name / "twin"
        subprocess.run([str(TWIN), str(l), str(r), str(hi), str(prefix)], check=True)
        dl, dr = np.load(f"{prefix}_sgm_left.npy"), np.load(f"{prefix}_sgm_right.npy")
        row = [render(bin_, out / name / "base", l, r, m, dl, dr)]
        for s in sizes:
            size = s * dl.size if s < 1 else s
            (fl, share), (fr, _) = filtered(dl, size, mode), filtered(dr, size, mode)
            row += [render(bin_, out / name / f"{mode}{s}", l, r, m, fl, fr), share]
        rows.append(row)
        print(f"{name:18s} " + " ".join(f"{v:6.2f}" for v in row), flush=True)
    print(f"{'mean':18s} " + " ".join(f"{v:6.2f}" for v in np.mean(rows, axis=0)))


if __name__ == "__main__":
    main()
