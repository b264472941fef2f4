"""A map-style dataset over a batch's ``index.jsonl``: one item per target (frame x scale), its
images read on access, so a training loop (or a torch ``DataLoader``) reads what
``refocus --batch`` or ``refocus_batch`` wrote without walking the frame folders.

``IndexDataset`` needs only numpy and Pillow and is a plain sequence (``len``, indexing,
iteration). ``IndexDataset.torch()`` returns the same items as a ``torch.utils.data.Dataset``
of tensors; torch is imported there and nowhere else, so the package never needs it.
"""

import numpy as np

from ._viewsynth import read_depth
from .dataset import read_index

OUTPUTS = ("rgb", "depth", "mask")


class IndexDataset:
    """The targets of ``out_dir/index.jsonl``, in the index's order (manifest order, then each
    frame's targets).

    ``ds[i]`` is a dict: the index row's "frame", "frame_index", "target", "scale", "width",
    "height", "coverage"; "K", the target's intrinsics as float64[3, 3]; and, for each of
    ``outputs`` the batch wrote, "rgb" uint8[H, W, 3], "depth" float32[H, W] (metres, 0 where
    invalid; a 16-bit PNG read with its row's depth_scale) and "mask" bool[H, W]; colour is
    read from PNG or JPEG (rgb_format="exr" colour is refused: leave "rgb" out of outputs).
    ``transform``, when given, is applied to each item (a dict in, anything out).

    The index is read once, here: rerun a batch, then make a new dataset. Raises FileError
    for a missing or malformed index (see ``read_index``), InvalidInputError for an output the
    batch did not write, IndexError for an index out of range.
    """

    def __init__(self, out_dir, outputs=OUTPUTS, transform=None):
        from .errors import InvalidInputError

        self.rows = read_index(out_dir)
        self.outputs = tuple([outputs] if isinstance(outputs, str) else outputs)
        self.transform = transform
        for name in self.outputs:
            if name not in OUTPUTS:
                raise InvalidInputError(f"invalid outputs: '{name}' (expected any of {', '.join(OUTPUTS)})")
            if any(row.get(name) is None for row in self.rows):
                raise InvalidInputError(f"invalid outputs: the batch in {out_dir} wrote no '{name}' files")
        if "rgb" in self.outputs and any(row["rgb"].lower().endswith(".exr") for row in self.rows):
            raise InvalidInputError("invalid outputs: 'rgb' is read from PNG or JPEG (the batch wrote EXR colour)")

    def __len__(self):
        return len(self.rows)

    def __getitem__(self, i):
        row = self.rows[i]  # ints, negative ones included; IndexError past the end
        fx, fy, cx, cy = (row["intrinsics"][k] for k in ("fx", "fy", "cx", "cy"))
        item = {key: row[key] for key in ("frame", "frame_index", "target", "scale", "width", "height", "coverage")}
        item["K"] = np.array([[fx, 0.0, cx], [0.0, fy, cy], [0.0, 0.0, 1.0]])
        for name in self.outputs:
            item[name] = _read(name, row)
        return self.transform(item) if self.transform else item

    def __iter__(self):
        return (self[i] for i in range(len(self)))

    def torch(self):
        """This dataset as a ``torch.utils.data.Dataset`` whose items hold tensors (the arrays
        through ``torch.from_numpy``, same shapes and dtypes; "K" float64) for a ``DataLoader``.
        Imports torch (ImportError, saying so, where it is not installed)."""
        try:
            import torch.utils.data
        except ImportError as e:
            raise ImportError("IndexDataset.torch() needs PyTorch: pip install torch") from e
        return _torch_dataset(torch)(self)


def _read(name, row):
    from PIL import Image

    if name == "depth":
        return read_depth(row["depth"], depth_scale=row.get("depth_scale"))
    with Image.open(row[name]) as image:
        if name == "mask":
            return np.asarray(image.convert("L")) > 0
        # A copy: the caller's own, writable (torch.from_numpy warns on read-only arrays).
        return np.array(image.convert("RGB"))


def _torch_dataset(torch):
    """The torch Dataset class, made on first use (so torch is imported only then)."""

    class TorchIndexDataset(torch.utils.data.Dataset):
        def __init__(self, dataset):
            self.dataset = dataset

        def __len__(self):
            return len(self.dataset)

        def __getitem__(self, i):
            item = self.dataset[i]
            if not isinstance(item, dict):
                return item  # a transform's own output, as it made it
            return {k: torch.from_numpy(np.ascontiguousarray(v)) if isinstance(v, np.ndarray) else v
                    for k, v in item.items()}

    return TorchIndexDataset
