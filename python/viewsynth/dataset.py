"""The batch's dataset index: ``index.jsonl`` at a ``refocus --batch`` (or ``refocus_batch``)
out-dir's root, one row per target, so a data loader reads one file instead of walking every
frame folder."""

import json
import os

from ._viewsynth import _index_rows

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

    Raises FileError (a ViewsynthError and an OSError) when the index is missing, not a regular
    file (a folder, FIFO or device), too large, not UTF-8 or not rows of the index.
    """
    # The library reads the file, by its rules for every input; rows come back as JSON text.
    rows = [json.loads(text) for text in _index_rows(os.fspath(out_dir))]
    if absolute:
        for row in rows:
            for key in ("rgb", "depth", "mask", "manifest"):
                if row.get(key) is not None:
                    row[key] = os.path.join(os.fspath(out_dir), row[key])
    return rows
