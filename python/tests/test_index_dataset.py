"""viewsynth.IndexDataset: a batch's index.jsonl as a map-style dataset, usable as a plain
sequence without torch (this test runs where torch is not installed, and checks that torch
was not imported), and, where torch is installed, as a torch Dataset behind a DataLoader."""

import subprocess
import sys

import numpy as np
import pytest

import viewsynth as vs
from conftest import make_frame


@pytest.fixture(scope="module")
def batch(renderer, tmp_path_factory):
    """Two small frames at two scales, depth as a 16-bit PNG (read back with its row's scale)."""
    folder = tmp_path_factory.mktemp("index-dataset")
    frames = []
    for i in range(2):
        rgb, depth, K = make_frame(48, 36, seed=i)
        from PIL import Image
        Image.fromarray(rgb).save(folder / f"c{i}.png")
        np.save(folder / f"d{i}.npy", np.nan_to_num(depth))
        frames.append({"name": f"f{i}", "rgb": str(folder / f"c{i}.png"), "depth": str(folder / f"d{i}.npy"),
                       "fx": K[0, 0], "fy": K[1, 1], "cx": K[0, 2], "cy": K[1, 2]})
    out = folder / "out"
    renderer.refocus_batch(frames, out, scales=[0.8, 1.25], depth_format="png16", depth_png_scale=5000, jobs=1)
    return out


def test_a_plain_sequence_of_the_index_targets(batch):
    ds = vs.IndexDataset(batch)
    rows = vs.read_index(batch)
    assert len(ds) == len(rows) == 4
    items = list(ds)
    assert [(it["frame"], it["scale"]) for it in items] == [(r["frame"], r["scale"]) for r in rows]
    for item, row in zip(items, rows):
        h, w = row["height"], row["width"]
        assert item["rgb"].dtype == np.uint8 and item["rgb"].shape == (h, w, 3)
        assert item["mask"].dtype == np.bool_ and item["mask"].shape == (h, w)
        assert item["depth"].dtype == np.float32 and item["depth"].shape == (h, w)
        # Depth in metres from the 16-bit PNG (its row's scale), valid where the mask says.
        assert np.array_equal(item["depth"] > 0, item["mask"])
        assert 2.0 < float(np.median(item["depth"][item["mask"]])) < 4.0
        assert item["mask"].mean() == pytest.approx(row["coverage"], abs=1e-6)
        assert item["K"][0, 0] == row["intrinsics"]["fx"] and item["K"][1, 2] == row["intrinsics"]["cy"]
    assert ds[-1]["frame"] == "f1"
    with pytest.raises(IndexError):
        ds[len(ds)]
    only = vs.IndexDataset(batch, outputs="depth", transform=lambda it: it["depth"].shape)
    assert only[0] == (rows[0]["height"], rows[0]["width"])
    with pytest.raises(vs.InvalidInputError, match="outputs: 'normals'"):
        vs.IndexDataset(batch, outputs=["normals"])
    with pytest.raises(vs.FileError):
        vs.IndexDataset(batch / "f0")


def test_the_package_and_the_dataset_never_import_torch(batch):
    code = ("import sys, viewsynth as vs; ds = vs.IndexDataset(sys.argv[1]); ds[0]; list(ds); "
            "print('torch' in sys.modules)")
    done = subprocess.run([sys.executable, "-c", code, str(batch)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "False"


@pytest.mark.filterwarnings("error")  # e.g. torch's warning on a read-only array
def test_torch_dataset_behind_a_dataloader(batch):
    ds = vs.IndexDataset(batch)
    try:
        import torch  # noqa: F401
    except ImportError:
        with pytest.raises(ImportError, match="pip install torch"):
            ds.torch()
        return
    from torch.utils.data import DataLoader, Dataset

    tds = ds.torch()
    assert isinstance(tds, Dataset) and len(tds) == 4
    [first, second] = DataLoader(tds, batch_size=2)
    # Targets of one frame share a size: they stack into [2, H, W, 3] tensors.
    assert tuple(first["rgb"].shape) == (2, 36, 48, 3) and first["rgb"].dtype == torch.uint8
    assert first["depth"].dtype == torch.float32 and first["mask"].dtype == torch.bool
    assert np.array_equal(first["rgb"][1].numpy(), ds[1]["rgb"])
    assert list(second["frame"]) == ["f1", "f1"]
