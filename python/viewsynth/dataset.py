"""The batch's dataset index: ``index.jsonl`` at a ``refocus --batch`` (or ``refocus_batch``)
out-dir's root, one row per target, so a data loader reads one file instead of walking every
frame folder."""

import json
import os

INDEX_NAME = "index.jsonl"


def read_index(out_dir, absolute=True):
    """The rows of ``out_dir/index.jsonl``, in manifest order: dicts with "frame",
    "frame_index", "target", "scale", "intrinsics" (fx, fy, cx, cy of K'), "width", "height",
    "coverage", and the files "rgb", "depth", "mask" (None when not written) and "manifest";
    a row whose "depth" is the 16-bit PNG also has "depth_scale", its raw units per metre
    (``read_depth(row["depth"], depth_scale=row.get("depth_scale"))``). With ``absolute`` (the default) the file paths are joined to ``out_dir``; otherwise they
    stay relative to it, as stored.

    The index is written when a run (or the last of its shards) ends; after shards ran
    separately, ``viewsynth index OUT`` joins their parts. Where a scheduler hands workers shares
    of a manifest (Ray, Dask), each calls ``refocus_batch(..., index=False)`` and the driver
    calls ``viewsynth.write_index`` once over the whole manifest.
    """
    path = os.path.join(os.fspath(out_dir), INDEX_NAME)
    rows = []
    with open(path, encoding="utf-8") as f:
        for line in f:
            if not line.strip():
                continue
            row = json.loads(line)
            if absolute:
                for key in ("rgb", "depth", "mask", "manifest"):
                    if row.get(key) is not None:
                        row[key] = os.path.join(os.fspath(out_dir), row[key])
            rows.append(row)
    return rows
