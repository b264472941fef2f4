"""Type stubs of the Rust extension viewsynth._viewsynth (re-exported by viewsynth)."""

import os
from types import TracebackType
from typing import Callable, Any, Dict, List, Literal, Mapping, Optional, Sequence, Tuple, TypedDict, Union

import numpy as np
import numpy.typing as npt

__version__: str
FACE_ORDER: Tuple[str, ...]
"""The cube faces of Renderer.stitch's face arrays, in order: pz, nz, up, down, px, nx."""

OutputName = Literal["rgb", "depth", "mask", "color", "colour"]
ArrayLike3x3 = Union[npt.NDArray[np.floating[Any]], npt.NDArray[np.integer[Any]], Sequence[Sequence[float]]]

class Timings(TypedDict):
    setup_ms: float
    render_ms: float
    gpu_ms: Optional[float]
    readback_ms: float

class RefocusView(TypedDict, total=False):
    """One target of Renderer.refocus. "rgb", "depth", "mask" are present when requested."""

    scale: float
    K: npt.NDArray[np.float64]
    coverage: Optional[float]
    timings: Timings
    rgb: npt.NDArray[np.uint8]
    depth: npt.NDArray[np.float32]
    mask: npt.NDArray[np.bool_]

class CyclopeanTimings(TypedDict):
    setup_ms: float
    render_ms: float
    gpu_ms: Optional[float]

class CyclopeanView(TypedDict, total=False):
    """Renderer.cyclopean's result. "rgb", "depth", "mask" are present when requested,
    "filled" with fill=True, "left_confidence" and "right_confidence" (each eye's matcher
    confidence in [0, 1], 0 where the disparity is unknown) with confidence=True."""

    coverage: float
    timings: CyclopeanTimings
    rgb: npt.NDArray[np.uint8]
    depth: npt.NDArray[np.float32]
    mask: npt.NDArray[np.bool_]
    filled: npt.NDArray[np.bool_]
    left_confidence: npt.NDArray[np.float32]
    right_confidence: npt.NDArray[np.float32]

class CameraDict(TypedDict, total=False):
    """One camera of a cameras.json: K (3x3, pixels), R (3x3) and t (3) world -> camera with
    OpenCV axes, width, height, near, far; or GL matrices view and proj (4x4, row-major)."""

    K: ArrayLike3x3
    R: ArrayLike3x3
    t: Union[Sequence[float], npt.NDArray[np.floating[Any]]]
    width: int
    height: int
    near: float
    far: float
    view: Any
    proj: Any

class CameraFileDict(TypedDict, total=False):
    """Renderer.cyclopean's cameras: the keys of `viewsynth cyclopean --cameras` files."""

    depth_kind: Literal["view-z", "device"]
    left: CameraDict
    right: CameraDict
    middle: CameraDict
    conventions: Dict[str, Any]
    gaze: Dict[str, Dict[str, Sequence[float]]]
    head_rotation: ArrayLike3x3
    fixation_distance: float
    fixation_range: Tuple[float, float]

class GlObjectCounts(TypedDict):
    """Renderer.gl_objects(): live GL objects of the context, by kind."""

    textures: int
    framebuffers: int
    buffers: int
    programs: int
    vertex_arrays: int
    queries: int
    syncs: int

class ReprojectedView(TypedDict, total=False):
    """One target eye of Renderer.reproject. "rgb", "depth", "mask" are present when requested."""

    coverage: float
    timings: CyclopeanTimings
    rgb: npt.NDArray[np.uint8]
    depth: npt.NDArray[np.float32]
    mask: npt.NDArray[np.bool_]

class StitchTimings(TypedDict):
    setup_ms: float
    render_ms: float
    gpu_ms: Optional[float]

class StitchResult(TypedDict, total=False):
    """Renderer.stitch's result: "rgb" is top-bottom (left eye on top); "left" and "right" are
    views of it; "depth" (with outputs including "depth") the distance in metres along each
    pixel's ODS ray from its origin on the viewing circle (0 = sky), "left_depth" and
    "right_depth" views of it."""

    rgb: npt.NDArray[np.uint8]
    left: npt.NDArray[np.uint8]
    right: npt.NDArray[np.uint8]
    depth: npt.NDArray[np.float32]
    left_depth: npt.NDArray[np.float32]
    right_depth: npt.NDArray[np.float32]
    fov: float
    overlap: float
    timings: StitchTimings

class BatchSummary(TypedDict):
    """Renderer.refocus_batch's summary: "failed" lists [frame name, error message]."""

    rendered: int
    skipped: int
    other_shards: int
    failed: List[List[str]]
    wall_s: float
    frames_in_flight: int
    stages: Dict[str, List[float]]

class ManifestFrame(TypedDict):
    """One frame of a refocus manifest (viewsynth.load_manifest; Renderer.refocus_batch)."""

    name: str
    rgb: str
    depth: str
    fx: float
    fy: float
    cx: float
    cy: float
    depth_scale: Optional[float]
    sun_bit_rotate: bool

class Renderer:
    """An OpenGL 4.5 context over EGL (or a Vulkan device, backend="vulkan") for refocusing numpy RGB-D frames, synthesising
    in-between views of rectified stereo pairs and reprojecting a view to the other eye.

    Thread-affine (WrongThreadError on another thread; open one per thread) and process-affine
    (create it inside each worker; with "fork" workers only if the parent never opened one,
    else RendererForkedError). See help(viewsynth.Renderer).
    """

    def __init__(
        self, device: str = "auto", require_gpu: bool = False, backend: Literal["gl", "vulkan"] = "gl"
    ) -> None: ...
    @property
    def backend(self) -> Literal["gl", "vulkan"]: ...
    @property
    def info(self) -> Dict[str, Any]: ...
    @property
    def closed(self) -> bool: ...
    def close(self) -> None: ...
    def __enter__(self) -> "Renderer": ...
    def __exit__(
        self,
        exc_type: Optional[type],
        exc: Optional[BaseException],
        tb: Optional[TracebackType],
    ) -> bool: ...
    def refocus(
        self,
        rgb: npt.NDArray[np.uint8],
        depth: npt.NDArray[np.float32],
        K: ArrayLike3x3,
        *,
        scales: Optional[Union[Sequence[float], Sequence[Sequence[float]], npt.NDArray[np.floating[Any]]]] = None,
        K_out: Optional[Union[Sequence[ArrayLike3x3], npt.NDArray[np.floating[Any]]]] = None,
        size: Optional[Tuple[int, int]] = None,
        principal: Optional[Tuple[float, float]] = None,
        outputs: Optional[Union[OutputName, Sequence[OutputName]]] = None,
        tau_rel: float = 0.05,
        tau_abs: float = 0.2,
        method: Literal["fullscreen", "mesh"] = "fullscreen",
        rgb_everywhere: bool = False,
    ) -> List[RefocusView]:
        """Re-render rgb uint8[H, W, 3] + depth float32[H, W] (metres) with intrinsics K at
        other focal lengths (scales=[...] or K_out=[...]), same pose. size is (width, height).
        A stack (rgb [N, H, W, 3]) takes one list of scales or one per sample ([N, k]).
        See help(viewsynth.Renderer.refocus)."""
        ...
    def cyclopean(
        self,
        left_rgb: npt.NDArray[np.uint8],
        right_rgb: npt.NDArray[np.uint8],
        left_disparity: Optional[npt.NDArray[np.float32]] = None,
        right_disparity: Optional[npt.NDArray[np.float32]] = None,
        position: Optional[float] = None,
        *,
        left_depth: Optional[npt.NDArray[np.float32]] = None,
        right_depth: Optional[npt.NDArray[np.float32]] = None,
        cameras: Optional[Union[CameraFileDict, str, "os.PathLike[str]"]] = None,
        method: Optional[Literal["splat-gather", "seed", "refine", "forward"]] = None,
        refine_steps: Optional[int] = None,
        blend: Optional[Literal["hard", "soft"]] = None,
        z_threshold: Optional[float] = None,
        dominant: Optional[str] = None,
        focal: Optional[float] = None,
        baseline: Optional[float] = None,
        doffs: float = 0.0,
        outputs: Optional[Union[OutputName, Sequence[OutputName]]] = None,
        fill: bool = False,
        max_disparity: Optional[int] = None,
        min_confidence: Optional[float] = None,
        confidence: bool = False,
        matcher: Optional[Literal["census", "sgm"]] = None,
    ) -> CyclopeanView:
        """Synthesise an in-between view of a stereo pair (rgb uint8[H, W, 3] per eye), as
        `viewsynth cyclopean`, from either
        - disparities of a rectified pair: left_disparity, right_disparity float32[H, W] (pixels,
          0 = unknown), position t (0 = left eye, 0.5 default, 1 = right); depth (metres) needs
          focal and baseline; or
        - depth: left_depth, right_depth float32[H, W] (view-z metres or device depth, as
          cameras["depth_kind"]) with cameras: a cameras.json path or a dict with its keys
          (eyes and view as K, R, t, width, height, near, far, or GL view/proj; fixation_distance
          or gaze). The view is the middle camera's; or
        - the two images alone: the disparities are estimated by the semi-global matcher
          (matcher="sgm", the default: smooth where there is no texture; those the census
          matcher does not confirm are inferred, rendered only with fill=True) or the census
          matcher alone (matcher="census") over the estimated range or 0..=max_disparity px;
          min_confidence drops the estimates it trusts less, and confidence=True returns each
          eye's confidence ("left_confidence", "right_confidence"; an inferred one at most 0.25).
        See help(viewsynth.Renderer.cyclopean)."""
        ...
    def gl_objects(self) -> GlObjectCounts:
        """Live GL objects of this Renderer's context by kind; steady between same-sized calls
        (growth is a leak)."""
        ...
    def reproject(
        self,
        rgb: npt.NDArray[np.uint8],
        depth: npt.NDArray[np.float32],
        K: ArrayLike3x3,
        *,
        depth_kind: Literal["view-z", "device", "disparity"] = "view-z",
        baseline: Optional[float] = None,
        focal: Optional[float] = None,
        doffs: float = 0.0,
        separation: Optional[float] = None,
        convergence: Optional[float] = None,
        near: Optional[float] = None,
        far: Optional[float] = None,
        source: Literal["left", "centre", "center", "right"] = "left",
        target: Literal["left", "right", "both"] = "right",
        method: Optional[Literal["shift-scan", "shift", "gather3d"]] = None,
        steps: int = 3,
        tau_rel: float = 0.05,
        outputs: Optional[Union[OutputName, Sequence[OutputName]]] = None,
    ) -> Dict[str, ReprojectedView]:
        """Reproject a view of a parallel stereo rig (baseline=..., or separation= and
        convergence=) to the other eye(s), as `viewsynth reproject` with a rig: returns
        {"left": ..., "right": ...} for the targets. See help(viewsynth.Renderer.reproject)."""
        ...
    def stitch(
        self,
        left_rgb: npt.NDArray[np.uint8],
        left_depth: npt.NDArray[np.float32],
        right_rgb: npt.NDArray[np.uint8],
        right_depth: npt.NDArray[np.float32],
        *,
        fov: Optional[float] = None,
        overlap: Optional[float] = None,
        method: Literal["reproject", "blend", "border-weight"] = "reproject",
        width: int = 2048,
        height: int = 1024,
        ipd: float = 0.064,
        pole_fade: float = 45.0,
        depth_kind: Literal["view-z", "device"] = "view-z",
        near: Optional[float] = None,
        far: Optional[float] = None,
        ndc: Literal["gl", "vulkan"] = "gl",
        reversed_z: bool = False,
        outputs: Optional[Union[Literal["rgb", "depth"], Sequence[Literal["rgb", "depth"]]]] = None,
    ) -> StitchResult:
        """Stitch an ODS 360 (top-bottom, left eye on top) from each eye's six cube faces,
        rgb uint8[6, N, N, 3] and view Z float32[6, N, N] in FACE_ORDER, as `viewsynth stitch
        --faces DIR`. See help(viewsynth.Renderer.stitch)."""
        ...
    def refocus_batch(
        self,
        frames: Union[str, "os.PathLike[str]", Sequence[Mapping[str, Any]]],
        out_dir: Union[str, "os.PathLike[str]"],
        *,
        scales: Optional[Sequence[float]] = None,
        size: Optional[Tuple[int, int]] = None,
        principal: Optional[Tuple[float, float]] = None,
        outputs: Optional[Union[OutputName, Sequence[OutputName]]] = None,
        tau_rel: float = 0.05,
        tau_abs: float = 0.2,
        method: Literal["fullscreen", "mesh"] = "fullscreen",
        rgb_format: Literal["png", "jpeg", "jpg", "exr"] = "png",
        depth_format: Optional[Union[str, Sequence[Literal["exr", "npy", "png16"]]]] = None,
        depth_png_scale: Optional[float] = None,
        depth_preview: bool = False,
        png_compression: Literal["fast", "default", "best"] = "fast",
        exr_compression: Literal["none", "rle", "zip", "piz"] = "zip",
        depth_trunc: Optional[float] = None,
        resume: bool = True,
        verify: bool = False,
        jobs: Optional[int] = None,
        shard: Optional[str] = None,
        rgb_everywhere: bool = False,
        zoom_random: Optional[Tuple[float, float]] = None,
        samples: Optional[int] = None,
        seed: Optional[int] = None,
        progress: Union[None, bool, Callable[[int, int], Any]] = None,
        index: bool = True,
    ) -> BatchSummary:
        """`viewsynth refocus --batch` on this context: frames (a manifest path or dicts with
        its keys) from files into out_dir/<name>/, the CLI's files byte for byte.
        See help(viewsynth.Renderer.refocus_batch)."""
        ...

def write_index(
    frames: Union[str, "os.PathLike[str]", Sequence[Mapping[str, Any]]],
    out_dir: Union[str, "os.PathLike[str]"],
    *,
    scales: Optional[Sequence[float]] = None,
    size: Optional[Tuple[int, int]] = None,
    principal: Optional[Tuple[float, float]] = None,
    outputs: Optional[Union[OutputName, Sequence[OutputName]]] = None,
    tau_rel: float = 0.05,
    tau_abs: float = 0.2,
    method: Literal["fullscreen", "mesh"] = "fullscreen",
    rgb_format: Literal["png", "jpeg", "jpg", "exr"] = "png",
    depth_format: Optional[Union[str, Sequence[Literal["exr", "npy", "png16"]]]] = None,
    depth_png_scale: Optional[float] = None,
    depth_preview: bool = False,
    png_compression: Literal["fast", "default", "best"] = "fast",
    exr_compression: Literal["none", "rle", "zip", "piz"] = "zip",
    depth_trunc: Optional[float] = None,
    rgb_everywhere: bool = False,
    zoom_random: Optional[Tuple[float, float]] = None,
    samples: Optional[int] = None,
    seed: Optional[int] = None,
) -> Tuple[str, int]:
    """out_dir/index.jsonl over the whole manifest `frames`, after shares of it were rendered with
    Renderer.refocus_batch(..., index=False) under the same settings; no GPU. Returns (path, rows)."""
    ...

def read_depth(
    path: Union[str, "os.PathLike[str]"],
    *,
    depth_scale: Optional[float] = None,
    depth_kind: Literal["view-z", "metric", "device"] = "view-z",
    near: Optional[float] = None,
    far: Optional[float] = None,
) -> npt.NDArray[np.float32]:
    """A depth file the CLI writes or reads, as float32[H, W] view-space Z in metres, 0 where
    invalid, under the CLI's rules: integer files (16-bit PNG/PGM, uint16 NPY) need depth_scale,
    raw units per metre (5000 for TUM; the CLI's png16 output records its own as the index row's
    "depth_scale"); device depth (depth_kind="device") needs the near and far planes it was
    written with. Raises InvalidInputError when one is missing."""
    ...

def info(device: str = "auto") -> Dict[str, Any]:
    """Describe the EGL/OpenGL context viewsynth renders with."""
    ...

def _index_rows(out_dir: Union[str, "os.PathLike[str]"]) -> List[str]:
    """The rows of out_dir/index.jsonl as JSON text, read by the library's rules: the reader
    behind viewsynth.read_index."""
    ...

def load_manifest(path: Union[str, "os.PathLike[str]"]) -> List[ManifestFrame]:
    """Read a refocus manifest (CSV or JSON) as `viewsynth refocus --batch` does: paths resolved
    against its folder, every frame named."""
    ...
