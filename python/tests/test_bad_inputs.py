"""Bad input raises InvalidInputError (a ValueError and a ViewsynthError) naming the argument,
before any GPU work; the Renderer stays usable afterwards."""

import math

import numpy as np
import pytest

import viewsynth as vs


def check(renderer, frame, parameter, words, **change):
    rgb, depth, K = frame
    args = dict(rgb=rgb, depth=depth, K=K, scales=[1.5])
    args.update(change)
    with pytest.raises(vs.InvalidInputError) as err:
        renderer.refocus(args.pop("rgb"), args.pop("depth"), args.pop("K"), **args)
    assert isinstance(err.value, ValueError) and isinstance(err.value, vs.ViewsynthError)
    message = str(err.value)
    assert parameter in message, message
    for w in words:
        assert w in message, message
    return err.value


def test_wrong_dtypes(renderer, frame):
    rgb, depth, K = frame
    check(renderer, frame, "rgb", ["float32", "uint8[H, W, 3]"], rgb=rgb.astype(np.float32))
    e = check(renderer, frame, "depth", ["float64", "float32[H, W]"], depth=depth.astype(np.float64))
    assert e.parameter == "depth"
    check(renderer, frame, "depth", ["uint16"], depth=np.zeros(depth.shape, np.uint16))
    check(renderer, frame, "rgb", ["expected a numpy array", "list"], rgb=rgb.tolist())
    check(renderer, frame, "K", ["3x3 matrix of numbers"], K=[["a", 0, 1], [0, 1, 1], [0, 0, 1]])


def test_strided_arrays_are_taken_as_their_contiguous_copies(renderer, frame):
    # A BGR image turned RGB, a Fortran-ordered depth, a transposed view: each gives what its
    # C-contiguous copy gives (the binding copies once, in C order).
    rgb, depth, K = frame
    bgr = np.ascontiguousarray(rgb[..., ::-1])
    want = renderer.refocus(rgb, depth, K, scales=[0.8, 1.5])
    for got in (renderer.refocus(bgr[..., ::-1], depth, K, scales=[0.8, 1.5]),
                renderer.refocus(rgb, np.asfortranarray(depth), K, scales=[0.8, 1.5]),
                renderer.refocus(rgb, depth.T.copy().T, K, scales=[0.8, 1.5])):
        for a, b in zip(want, got):
            for key in ("rgb", "depth", "mask"):
                assert np.array_equal(a[key], b[key], equal_nan=True), key
    wide = np.zeros((72, 192, 3), np.uint8)
    wide[:, ::2] = rgb
    one = renderer.refocus(rgb, depth, K, scales=[1.0])[0]["rgb"]
    assert np.array_equal(renderer.refocus(wide[:, ::2], depth, K, scales=[1.0])[0]["rgb"], one)


def test_wrong_shapes(renderer, frame):
    rgb, depth, K = frame
    check(renderer, frame, "rgb", ["(72, 96, 4)", "no alpha"], rgb=np.zeros((72, 96, 4), np.uint8))
    check(renderer, frame, "rgb", ["(72, 96)"], rgb=np.zeros((72, 96), np.uint8))
    check(renderer, frame, "depth", ["(72, 96, 1)"], depth=depth[..., None])
    check(renderer, frame, "size mismatch", ["96x72", "95x72"], depth=np.ascontiguousarray(depth[:, :95]))
    check(renderer, frame, "source size", ["0x72"], rgb=np.zeros((72, 0, 3), np.uint8), depth=np.zeros((72, 0), np.float32))
    check(renderer, frame, "K", ["(2, 3)", "3x3"], K=K[:2])


def test_bad_intrinsics(renderer, frame):
    rgb, depth, K = frame
    nan_k = K.copy()
    nan_k[0, 0] = math.nan
    check(renderer, frame, "K", ["NaN is not finite"], K=nan_k)
    inf_k = K.copy()
    inf_k[1, 2] = math.inf
    check(renderer, frame, "K", ["inf is not finite"], K=inf_k)
    neg = K.copy()
    neg[1, 1] = -5
    check(renderer, frame, "K fy", ["must be in [1e-3, 1e6]"], K=neg)
    skew = K.copy()
    skew[0, 1] = 0.5
    check(renderer, frame, "K", ["K[0, 1] is 0.5", "no skew"], K=skew)
    check(renderer, frame, "K_out[1]", ["not finite"], scales=None, K_out=[K, nan_k])


def test_bad_targets_and_options(renderer, frame):
    rgb, depth, K = frame
    check(renderer, frame, "scales", ["-2: must be finite and > 0"], scales=[1.0, -2.0])
    check(renderer, frame, "scales", ["NaN"], scales=[math.nan])
    check(renderer, frame, "scales", ["no target given"], scales=[])
    # Neither scales nor K_out: the CLI's default scales (one request default for both).
    assert [t["scale"] for t in renderer.refocus(rgb, depth, K, outputs="mask")] == [0.5, 0.75, 1.0, 1.5, 2.0]
    check(renderer, frame, "scales", ["not both"], K_out=[K])
    check(renderer, frame, "K_out", ["no target"], scales=None, K_out=[])
    check(renderer, frame, "principal", ["K_out"], scales=None, K_out=[K], principal=(1.0, 2.0))
    check(renderer, frame, "target camera width", ["at least 1"], size=(0, 10))
    # The upper limit comes from the GL context (16384 on llvmpipe, 32768 on NVIDIA).
    info = vs.info()
    limit = min(info["max_texture_size"], *info["max_viewport"])
    check(renderer, frame, "output size", ["exceeds this GPU's limit"], size=(10, limit + 1))
    check(renderer, frame, "outputs", ["'normals'"], outputs=("rgb", "normals"))
    check(renderer, frame, "outputs", ["at least one"], outputs=())
    check(renderer, frame, "tau-rel", [">= 0"], tau_rel=-0.1)
    check(renderer, frame, "tau-abs", [">= 0"], tau_abs=math.nan)
    check(renderer, frame, "method", ["'raytrace'"], method="raytrace")
    # After all that the renderer still renders.
    (view,) = renderer.refocus(rgb, depth, K, scales=[1.5], outputs="rgb")
    assert view["rgb"].shape == rgb.shape


def test_bad_device_and_closed_renderer():
    with pytest.raises(vs.InvalidInputError, match="device"):
        vs.Renderer(device="gpu0")
    with vs.Renderer() as r:
        assert not r.closed
    assert r.closed
    with pytest.raises(vs.RendererClosedError, match="closed"):
        r.refocus(np.zeros((2, 2, 3), np.uint8), np.ones((2, 2), np.float32), np.eye(3), scales=[1])
