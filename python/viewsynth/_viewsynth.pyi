"""Type stubs of the Rust extension viewsynth._viewsynth (re-exported by viewsynth)."""

from types import TracebackType
from typing import Any, Dict, List, Literal, Optional, Sequence, Tuple, TypedDict, Union

import numpy as np
import numpy.typing as npt

__version__: str

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

class Renderer:
    """An OpenGL 4.5 context over EGL for refocusing numpy RGB-D frames.

    Thread-affine (WrongThreadError on another thread; open one per thread) and process-affine
    (create it inside each worker; with "fork" workers only if the parent never opened one,
    else RendererForkedError). See help(viewsynth.Renderer).
    """

    def __init__(self, device: str = "auto", require_gpu: bool = False) -> None: ...
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
        scales: Optional[Sequence[float]] = None,
        K_out: Optional[Union[Sequence[ArrayLike3x3], npt.NDArray[np.floating[Any]]]] = None,
        size: Optional[Tuple[int, int]] = None,
        principal: Optional[Tuple[float, float]] = None,
        outputs: Optional[Union[OutputName, Sequence[OutputName]]] = None,
        tau_rel: float = 0.05,
        tau_abs: float = 0.2,
        method: Literal["fullscreen", "mesh"] = "fullscreen",
    ) -> List[RefocusView]:
        """Re-render rgb uint8[H, W, 3] + depth float32[H, W] (metres) with intrinsics K at
        other focal lengths (scales=[...] or K_out=[...]), same pose. size is (width, height).
        See help(viewsynth.Renderer.refocus)."""
        ...

def info(device: str = "auto") -> Dict[str, Any]:
    """Describe the EGL/OpenGL context viewsynth renders with."""
    ...
