"""stitch from Python equals `viewsynth stitch --faces DIR` on the same faces (decoded PNG pixels
of the top-bottom and per-eye images, and the depth panorama's EXR), for every method, fov and
overlap defaults and device depth; the depth panorama is the room's distance along each ODS ray;
bad input raises InvalidInputError naming the argument."""

import subprocess

import numpy as np
import pytest
from PIL import Image

import viewsynth as vs

# World from face camera rotations (columns: the face's x, y, z axes; OpenCV axes), in
# vs.FACE_ORDER, as src/stitch/mod.rs's CubeFace::rotation.
ROTATIONS = {
    "pz": [[1, 0, 0], [0, 1, 0], [0, 0, 1]],
    "nz": [[-1, 0, 0], [0, 1, 0], [0, 0, -1]],
    "up": [[1, 0, 0], [0, 0, -1], [0, 1, 0]],
    "down": [[1, 0, 0], [0, 0, 1], [0, -1, 0]],
    "px": [[0, 0, 1], [0, 1, 0], [-1, 0, 0]],
    "nx": [[0, 0, -1], [0, 1, 0], [1, 0, 0]],
}
ROOM = 3.0  # half-size of the box room around the rig, metres


def room_faces(side, n=48, fov=110.0, ipd=0.064):
    """Six faces of one eye inside a textured box room (a sphere in front, a hole of background
    on the front face): rgb uint8[6, n, n, 3], view Z float32[6, n, n]. Side faces are seen from
    IPD/2 along their right axis (the left eye from -IPD/2), up and down from the centre."""
    sign = -1.0 if side == "left" else 1.0
    f = 0.5 * n / np.tan(np.radians(fov) / 2)
    c = (n - 1) / 2
    y, x = np.mgrid[0:n, 0:n].astype(np.float64)
    cam = np.stack([(x - c) / f, (y - c) / f, np.ones_like(x)], axis=-1)  # view Z = 1
    rgbs, depths = [], []
    for tag in vs.FACE_ORDER:
        R = np.array(ROTATIONS[tag], dtype=np.float64)
        eye = np.zeros(3) if tag in ("up", "down") else sign * ipd / 2 * R[:, 0]
        d = cam @ R.T
        with np.errstate(divide="ignore", invalid="ignore"):
            t = np.where(d != 0, (np.sign(d) * ROOM - eye) / d, np.inf).min(axis=-1)
        # A sphere of radius 0.5 m, 1.5 m in front: its silhouette breaks the faces' depth.
        centre = np.array([0.3, 0.2, 1.5])
        oc = eye - centre
        b = d @ oc
        disc = b * b - (d * d).sum(-1) * (oc @ oc - 0.25)
        ts = (-b - np.sqrt(np.maximum(disc, 0))) / (d * d).sum(-1)
        hit_sphere = (disc > 0) & (ts > 0) & (ts < t)
        t = np.where(hit_sphere, ts, t)
        p = eye + t[..., None] * d
        checker = (np.floor(p * 2).sum(-1) % 2).astype(np.float64)
        rgb = np.stack([0.5 + 0.5 * np.sin(p[..., 0] * 3), 0.5 + 0.5 * np.cos(p[..., 1] * 2), 0.3 + 0.5 * checker], -1)
        rgb[hit_sphere] = [0.9, 0.2, 0.1]
        depth = t.astype(np.float32)  # the ray's view Z: d has z = 1 in the camera
        if tag == "pz":
            depth[2:6, 3:9] = 0.0  # background (no depth)
        rgbs.append(np.clip(rgb * 255 + 0.5, 0, 255).astype(np.uint8))
        depths.append(depth)
    return np.stack(rgbs), np.stack(depths)


@pytest.fixture(scope="module")
def faces():
    return {side: room_faces(side) for side in ("left", "right")}


def device_depth(z, near, far):
    """OpenGL window depth of view Z (ndc [-1, 1], not reversed), 1 where there is no depth."""
    z = z.astype(np.float64)
    ndc = (far + near) / (far - near) - 2 * far * near / ((far - near) * np.where(z > 0, z, 1))
    return np.where(z > 0, (ndc + 1) / 2, 1.0).astype(np.float32)


def write_face_dir(path, faces, depth_of=lambda z: z):
    path.mkdir()
    for side, (rgbs, depths) in faces.items():
        for k, tag in enumerate(vs.FACE_ORDER):
            Image.fromarray(rgbs[k]).save(path / f"{side}_{tag}.png")
            np.save(path / f"{side}_{tag}_depth.npy", depth_of(depths[k]))
    return path


def run_cli(cli, face_dir, out, flags):
    cmd = [str(cli), "stitch", "--faces", str(face_dir), "--per-eye", "--out-dir", str(out), "--device", "auto"] + flags
    done = subprocess.run(cmd, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return {name: np.asarray(Image.open(out / f"ods_{name}.png").convert("RGB")) for name in ("top_bottom", "left", "right")}


CASES = {
    "reproject": (dict(fov=110.0, width=128, height=64), ["--fov", "110", "--width", "128", "--height", "64"]),
    "blend": (dict(method="blend", fov=110.0, overlap=8.0, width=96, height=48),
              ["--method", "blend", "--fov", "110", "--overlap", "8", "--width", "96", "--height", "48"]),
    "border_weight": (dict(method="border-weight", fov=110.0, overlap=6.0, width=100, height=50, ipd=0.1, pole_fade=30.0),
                      ["--method", "border-weight", "--fov", "110", "--overlap", "6", "--width", "100", "--height", "50",
                       "--ipd", "0.1", "--pole-fade", "30"]),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_stitch_equals_cli_files(renderer, cli, faces, tmp_path, case):
    kwargs, flags = CASES[case]
    face_dir = write_face_dir(tmp_path / "faces", faces)
    out = renderer.stitch(*faces["left"], *faces["right"], **kwargs)
    files = run_cli(cli, face_dir, tmp_path / "out", flags)
    w, h = kwargs["width"], kwargs["height"]
    assert out["rgb"].shape == files["top_bottom"].shape == (2 * h, w, 3)
    assert out["rgb"].dtype == np.uint8
    assert np.array_equal(out["rgb"], files["top_bottom"])
    assert np.array_equal(out["left"], files["left"]) and np.array_equal(out["right"], files["right"])
    # The eyes are views of the top-bottom image (left on top), and they differ (stereo).
    assert np.shares_memory(out["left"], out["rgb"]) and np.array_equal(out["rgb"][:h], out["left"])
    assert not np.array_equal(out["left"], out["right"])
    assert out["fov"] == 110.0 and out["overlap"] == kwargs.get("overlap", 10.0)
    assert set(out["timings"]) == {"setup_ms", "render_ms", "gpu_ms"}
    # Every pixel of the 360 sees the room (the stitch leaves no hole where the faces cover all).
    assert (out["rgb"].reshape(-1, 3).max(axis=1) > 0).mean() > 0.99


def test_stitch_device_depth_equals_cli(renderer, cli, faces, tmp_path):
    near, far = 0.1, 50.0
    face_dir = write_face_dir(tmp_path / "faces", faces, lambda z: device_depth(z, near, far))
    as_device = {s: (rgb, device_depth(z, near, far)) for s, (rgb, z) in faces.items()}
    out = renderer.stitch(*as_device["left"], *as_device["right"], width=96, height=48,
                          depth_kind="device", near=near, far=far)
    files = run_cli(cli, face_dir, tmp_path / "out",
                    ["--width", "96", "--height", "48", "--depth-kind", "device", "--near", str(near), "--far", str(far)])
    assert np.array_equal(out["rgb"], files["top_bottom"])
    # Device depth converted back to view Z stitches (nearly) as the view Z itself: the same
    # pixels up to the float32 rounding of the device depth (a rare 1-level step at most).
    direct = renderer.stitch(*faces["left"], *faces["right"], width=96, height=48)
    diff = np.abs(out["rgb"].astype(int) - direct["rgb"].astype(int))
    assert (diff > 1).mean() < 0.01, (diff > 1).mean()


def room_distance(side, width, height, ipd=0.064, pole_fade=45.0):
    """The distance along each ODS ray of one eye's equirect (rows top-down) to the room of
    room_faces, from the ray's origin on the pole-faded IPD/2 circle (src/stitch/mod.rs)."""
    v, u = np.mgrid[0:height, 0:width].astype(np.float64)
    lon = 2 * np.pi * (u + 0.5) / width - np.pi
    lat = np.pi / 2 - np.pi * (v + 0.5) / height
    d = np.stack([np.cos(lat) * np.sin(lon), -np.sin(lat), np.cos(lat) * np.cos(lon)], -1)
    a = np.radians(pole_fade)
    x = np.clip((np.abs(lat) - a) / (np.pi / 2 - a), 0, 1)
    r = (-1.0 if side == "left" else 1.0) * ipd / 2 * (1 - x * x * (3 - 2 * x))
    o = np.stack([r * np.cos(lon), np.zeros_like(r), -r * np.sin(lon)], -1)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(d != 0, (np.sign(d) * ROOM - o) / d, np.inf).min(axis=-1)
    oc = o - np.array([0.3, 0.2, 1.5])
    b = (d * oc).sum(-1)
    disc = b * b - ((oc * oc).sum(-1) - 0.25)
    ts = -b - np.sqrt(np.maximum(disc, 0))
    return np.where((disc > 0) & (ts > 0) & (ts < t), ts, t)


def test_stitch_depth_is_the_distance_along_each_ods_ray_and_equals_cli(renderer, cli, faces, tmp_path):
    w, h = 128, 64
    out = renderer.stitch(*faces["left"], *faces["right"], width=w, height=h, outputs=("rgb", "depth"))
    depth = out["depth"]
    assert depth.shape == (2 * h, w) and depth.dtype == np.float32
    assert np.shares_memory(out["left_depth"], depth) and np.array_equal(out["right_depth"], depth[h:])
    # Asking for depth changes no colour; depth alone gives the same distances and no colour.
    assert np.array_equal(out["rgb"], renderer.stitch(*faces["left"], *faces["right"], width=w, height=h)["rgb"])
    alone = renderer.stitch(*faces["left"], *faces["right"], width=w, height=h, outputs="depth")
    assert "rgb" not in alone and np.array_equal(alone["depth"], depth)
    # The room surrounds the rig: a distance everywhere but where the front face's hole of
    # background is seen; within 1 % of the analytic distance but at the sphere's silhouette
    # (a nearest-texel choice of 48 px faces).
    truth = np.concatenate([room_distance("left", w, h), room_distance("right", w, h)])
    valid = depth > 0
    assert valid.mean() > 0.98, valid.mean()
    rel = np.abs(depth[valid] - truth[valid]) / truth[valid]
    assert np.median(rel) < 1e-3 and (rel > 0.01).mean() < 0.02, (np.median(rel), (rel > 0.01).mean())
    face_dir = write_face_dir(tmp_path / "faces", faces)
    run_cli(cli, face_dir, tmp_path / "out", ["--width", str(w), "--height", str(h), "--outputs", "rgb,depth"])
    assert np.array_equal(vs.read_depth(tmp_path / "out" / "ods_top_bottom_depth.exr"), depth)
    assert np.array_equal(vs.read_depth(tmp_path / "out" / "ods_left_depth.exr"), out["left_depth"])
    stitch_error(renderer, faces, "outputs", ["no mask"], outputs=("rgb", "mask"))


def test_stitch_defaults_and_fov_alone(renderer, faces):
    out = renderer.stitch(*faces["left"], *faces["right"], width=64, height=32)
    assert (out["fov"], out["overlap"]) == (110.0, 10.0)
    # Either alone sets the other, as the CLI: overlap = (fov - 90) / 2.
    out = renderer.stitch(*faces["left"], *faces["right"], fov=120.0, width=64, height=32)
    assert (out["fov"], out["overlap"]) == (120.0, 15.0)
    out = renderer.stitch(*faces["left"], *faces["right"], overlap=8.0, width=64, height=32)
    assert (out["fov"], out["overlap"]) == (106.0, 8.0)


def stitch_error(renderer, faces, parameter, words, **change):
    args = dict(left_rgb=faces["left"][0], left_depth=faces["left"][1],
                right_rgb=faces["right"][0], right_depth=faces["right"][1], width=32, height=16)
    args.update(change)
    with pytest.raises(vs.InvalidInputError) as err:
        renderer.stitch(args.pop("left_rgb"), args.pop("left_depth"), args.pop("right_rgb"), args.pop("right_depth"), **args)
    message = str(err.value)
    assert parameter in message, message
    for w in words:
        assert w in message, message


def test_stitch_bad_inputs(renderer, faces):
    rgb, depth = faces["left"]
    stitch_error(renderer, faces, "left_rgb", ["float32", "uint8[6, N, N, 3]"], left_rgb=rgb.astype(np.float32))
    stitch_error(renderer, faces, "right_depth", ["float64", "float32[6, N, N]"], right_depth=depth.astype(np.float64))
    stitch_error(renderer, faces, "left_rgb", ["(5, 48, 48, 3)", "pz, nz, up, down, px, nx"], left_rgb=rgb[:5].copy())
    stitch_error(renderer, faces, "left_depth", ["(6, 48, 40)"], left_depth=depth[:, :, :40].copy())
    stitch_error(renderer, faces, "left_depth", ["40x40", "48x48"], left_depth=depth[:, :40, :40].copy())
    small = (rgb[:, :40, :40].copy(), depth[:, :40, :40].copy())
    stitch_error(renderer, faces, "right_rgb", ["40x40", "48x48"], right_rgb=small[0], right_depth=small[1])
    stitch_error(renderer, faces, "left_rgb", ["1x1", "at least 2x2"], left_rgb=rgb[:, :1, :1].copy(),
                 left_depth=depth[:, :1, :1].copy())
    stitch_error(renderer, faces, "fov", ["(90, 178)"], fov=90.0)
    stitch_error(renderer, faces, "overlap", ["(0, 44)"], overlap=45.0)
    stitch_error(renderer, faces, "overlap", ["outside (0, 10]"], fov=110.0, overlap=12.0)
    stitch_error(renderer, faces, "method", ["'warp'", "reproject"], method="warp")
    stitch_error(renderer, faces, "ipd", ["outside [0, 10)"], ipd=-0.1)
    stitch_error(renderer, faces, "equirect size", ["zero side"], width=0)
    stitch_error(renderer, faces, "near", ["device"], near=0.1, far=10.0)
    stitch_error(renderer, faces, "near", ["needs near and far"], depth_kind="device", near=0.1)
    stitch_error(renderer, faces, "depth_kind", ["'disparity'"], depth_kind="disparity")
    stitch_error(renderer, faces, "ndc", ["'dx'"], depth_kind="device", near=0.1, far=10.0, ndc="dx")
    # With view-Z faces the conventions only switch the pass's own (as the CLI's --ndc,
    # --reversed-z): the image must not depend on them.
    plain = renderer.stitch(*faces["left"], *faces["right"], width=32, height=16)["rgb"]
    for conv in (dict(reversed_z=True), dict(ndc="vulkan"), dict(ndc="vulkan", reversed_z=True)):
        switched = renderer.stitch(*faces["left"], *faces["right"], width=32, height=16, **conv)["rgb"]
        assert np.array_equal(switched, plain), conv
    with pytest.raises(TypeError):
        renderer.stitch(rgb, depth, width=32, height=16)  # the right eye is missing
    # Still usable after the errors.
    assert renderer.stitch(*faces["left"], *faces["right"], width=32, height=16)["rgb"].shape == (32, 32, 3)
