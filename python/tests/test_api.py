"""The public surface: info(), require_gpu, the .pyi stubs against the module, the example."""

import ast
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import viewsynth as vs

PACKAGE = Path(vs.__file__).parent
EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def test_info_describes_the_context(renderer):
    i = vs.info()
    assert i["gl_major"] * 10 + i["gl_minor"] >= 45
    assert i["renderer"] == renderer.info["renderer"]
    assert i["viewsynth_version"] == vs.__version__
    assert isinstance(i["software"], bool)
    assert i["software"] == ("llvmpipe" in i["renderer"].lower() or "softpipe" in i["renderer"].lower())


def test_require_gpu_follows_the_renderer(renderer):
    if renderer.info["software"]:
        with pytest.raises(vs.GpuUnavailableError, match="software renderer"):
            vs.Renderer(require_gpu=True)
    else:
        with vs.Renderer(require_gpu=True) as r:
            assert not r.info["software"]


def test_stubs_name_what_the_module_has():
    tree = ast.parse((PACKAGE / "_viewsynth.pyi").read_text())
    stub = {n.name for n in tree.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
    from viewsynth import _viewsynth

    assert {"Renderer", "info"} <= stub
    # The result dicts' TypedDicts exist in the stubs only.
    typed = {n.name for n in tree.body if isinstance(n, ast.ClassDef) and any(getattr(b, "id", "") == "TypedDict" for b in n.bases)}
    assert {"RefocusView", "StitchResult", "BatchSummary", "ManifestFrame"} <= typed
    for name in stub - typed:
        assert hasattr(_viewsynth, name), name
    assert {"load_manifest", "Renderer", "info"} <= stub
    assert vs.FACE_ORDER == ("pz", "nz", "up", "down", "px", "nx")
    (renderer_stub,) = [n for n in tree.body if isinstance(n, ast.ClassDef) and n.name == "Renderer"]
    methods = {n.name for n in renderer_stub.body if isinstance(n, ast.FunctionDef)}
    for name in methods:
        assert hasattr(vs.Renderer, name), name
    assert (PACKAGE / "py.typed").exists()
    assert "Thread" in vs.Renderer.__doc__ and "fork" in vs.Renderer.__doc__
    assert "tau_rel" in vs.Renderer.refocus.__doc__
    assert "position" in vs.Renderer.cyclopean.__doc__ and "doffs" in vs.Renderer.cyclopean.__doc__
    assert "cameras" in vs.Renderer.cyclopean.__doc__ and "left_depth" in vs.Renderer.cyclopean.__doc__
    assert "leak" in vs.Renderer.gl_objects.__doc__
    assert "depth_kind" in vs.Renderer.reproject.__doc__ and "separation" in vs.Renderer.reproject.__doc__
    assert "FACE_ORDER" in vs.Renderer.stitch.__doc__ and "top-bottom" in vs.Renderer.stitch.__doc__
    assert "--batch" in vs.Renderer.refocus_batch.__doc__ and "resume" in vs.Renderer.refocus_batch.__doc__
    assert "manifest" in vs.load_manifest.__doc__


def test_stub_signatures_are_the_modules():
    """Every function and Renderer method of the stubs takes the module's parameters: the same
    names in the same order, the same positional/keyword-only split and the same defaults (a
    keyword argument added to the binding but not to the stubs fails here)."""
    import inspect
    from viewsynth import _viewsynth

    tree = ast.parse((PACKAGE / "_viewsynth.pyi").read_text())

    def stub_params(fn):
        a = fn.args
        positional = [p.arg for p in a.posonlyargs + a.args if p.arg != "self"]
        pos_defaults = [None] * (len(a.posonlyargs + a.args) - len(a.defaults)) + list(a.defaults)
        pos_defaults = pos_defaults[len(a.posonlyargs + a.args) - len(positional):]
        rows = [(n, "positional", d) for n, d in zip(positional, pos_defaults)]
        rows += [(p.arg, "keyword", d) for p, d in zip(a.kwonlyargs, a.kw_defaults)]
        return [(n, kind, None if d is None else ast.literal_eval(d)) for n, kind, d in rows]

    def runtime_params(obj):
        rows = []
        for p in inspect.signature(obj).parameters.values():
            if p.name == "self":
                continue
            kind = "keyword" if p.kind == p.KEYWORD_ONLY else "positional"
            rows.append((p.name, kind, None if p.default is p.empty else p.default))
        return rows

    checked = 0
    for node in tree.body:
        if isinstance(node, ast.FunctionDef) and hasattr(_viewsynth, node.name):
            assert stub_params(node) == runtime_params(getattr(_viewsynth, node.name)), node.name
            checked += 1
        if isinstance(node, ast.ClassDef) and node.name == "Renderer":
            for fn in node.body:
                # Protocol methods (__enter__, __exit__, ...) are typed by the protocol's names.
                if not isinstance(fn, ast.FunctionDef) or (fn.name.startswith("__") and fn.name != "__init__"):
                    continue
                # The constructor's signature is the class's own (pyo3's #[new]).
                runtime = vs.Renderer if fn.name == "__init__" else getattr(vs.Renderer, fn.name, None)
                if runtime is None or not getattr(runtime, "__text_signature__", None):
                    continue
                assert stub_params(fn) == runtime_params(runtime), f"Renderer.{fn.name}"
                checked += 1
    assert checked >= 7, checked


def test_augment_example_draws_seeded_zooms():
    sys.path.insert(0, str(EXAMPLES))
    try:
        from refocus_augment import RefocusAugment, synthetic_frame
    finally:
        sys.path.pop(0)
    data = RefocusAugment([synthetic_frame()] * 3, zoom_min=0.6, zoom_max=1.8, seed=3)
    items = [data[i] for i in range(len(data))]
    scales = [it["scale"] for it in items]
    assert len(set(scales)) == 3 and all(0.6 <= s <= 1.8 for s in scales)
    assert [data[i]["scale"] for i in range(3)] == scales  # same epoch, same draws
    data.set_epoch(1)
    assert [data[i]["scale"] for i in range(3)] != scales
    for it in items:
        assert it["rgb"].shape == (120, 160, 3) and it["K"][0, 0] == pytest.approx(140.0 * it["scale"])
        m = it["mask"]
        # Zooming out leaves a border the source never saw; zooming in fills the frame's edges.
        border = np.concatenate([m[0], m[-1], m[:, 0], m[:, -1]])
        assert not border.any() if it["scale"] < 0.95 else border.all()
        # The box's silhouette breaks the mesh: invalid pixels inside the frame either way.
        assert not m[10:-10, 10:-10].all()
    # The example's script entry point runs as documented: items drawn in two spawned worker
    # processes (a subprocess, as spawn re-imports the script as its workers' main module).
    done = subprocess.run([sys.executable, str(EXAMPLES / "refocus_augment.py")], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert len(lines) == 4 and all(line.startswith("worker ") for line in lines), done.stdout
