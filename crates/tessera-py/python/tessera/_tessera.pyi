"""Type stubs of the extension module behind the tessera package (written in Rust with PyO3).

The public API is :mod:`tessera`; this module is its native half.
"""

from os import PathLike
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

class SurfaceSet:
    """Patches with the topology that ties them together, read by :func:`load`."""

    @property
    def patch_count(self) -> int: ...
    @property
    def path(self) -> str: ...
    @property
    def bounds(self) -> Tuple[Tuple[float, float, float], Tuple[float, float, float]]: ...
    @property
    def diagonal(self) -> float: ...
    @property
    def up(self) -> str: ...
    @property
    def is_subdivision_cage(self) -> bool: ...
    @property
    def patch_faces(self) -> Optional[List[int]]: ...
    @property
    def topology(self) -> Dict[str, Any]: ...
    @property
    def repairs(self) -> Dict[str, Any]: ...
    def __len__(self) -> int: ...

class Camera:
    """A perspective camera; ``size`` is the viewport in pixels of ``pixel_error``."""

    def __init__(
        self,
        eye: Tuple[float, float, float],
        target: Tuple[float, float, float],
        up: Tuple[float, float, float] = (0.0, 0.0, 1.0),
        fov: float = 45.0,
        size: Tuple[int, int] = (1280, 720),
        near: Optional[float] = None,
        far: Optional[float] = None,
    ) -> None: ...
    @staticmethod
    def framing(set: SurfaceSet, size: Tuple[int, int] = (1280, 720)) -> "Camera": ...
    @staticmethod
    def parse(spec: str, set: SurfaceSet) -> "Camera": ...
    def moved_to(self, eye: Tuple[float, float, float]) -> "Camera": ...
    @property
    def eye(self) -> List[float]: ...
    @property
    def target(self) -> List[float]: ...
    @property
    def up(self) -> List[float]: ...
    @property
    def fov(self) -> float: ...
    @property
    def size(self) -> Tuple[int, int]: ...
    @property
    def near(self) -> float: ...
    @property
    def far(self) -> float: ...

class Tessellator:
    def __init__(
        self,
        set: SurfaceSet,
        *,
        scheme: Optional[str] = None,
        factor: Optional[float] = None,
        tolerance: Union[float, str, None] = None,
        pixel_error: Optional[float] = None,
        distance: Optional[Tuple[float, float]] = None,
        silhouette: Optional[Tuple[float, float]] = None,
        silhouette_mode: Optional[str] = None,
        mapping: str = "linear",
        camera: Optional[Camera] = None,
        cull: bool = False,
        max_factor: int = 64,
        max_level: Optional[int] = None,
        level: Optional[int] = None,
        quality: Optional[str] = None,
        threshold: Optional[float] = None,
        warp: bool = False,
        bound: str = "hessian",
        strips: bool = False,
        corner_params: bool = False,
        max_triangles: Optional[int] = None,
    ) -> None: ...
    @property
    def scheme(self) -> str: ...
    @property
    def set(self) -> SurfaceSet: ...
    def frame(
        self, camera: Optional[Camera] = None
    ) -> Tuple[
        npt.NDArray[np.float32],
        npt.NDArray[np.float32],
        npt.NDArray[np.float32],
        npt.NDArray[np.uint32],
        npt.NDArray[np.uint32],
        npt.NDArray[np.uint32],
        Optional[npt.NDArray[np.float32]],
        Optional[npt.NDArray[np.uint32]],
        Dict[str, Any],
    ]: ...

def load(
    path: Union[str, "PathLike[str]"],
    surface: str = "auto",
    weld: Optional[float] = None,
    keep_orientation: bool = False,
    flip_normals: bool = False,
    allow_outside_uris: bool = False,
    isolation_smooth: int = 2,
    isolation_sharp: int = 6,
) -> SurfaceSet: ...
def check(
    vertices: npt.NDArray[np.float32],
    faces: npt.NDArray[np.uint32],
    set: Optional[SurfaceSet] = None,
    culled: int = 0,
) -> Dict[str, Any]: ...
def write_mesh(
    path: Union[str, "PathLike[str]"],
    vertices: npt.NDArray[np.float32],
    faces: npt.NDArray[np.uint32],
    normals: Optional[npt.NDArray[np.float32]] = None,
    uvs: Optional[npt.NDArray[np.float32]] = None,
    vertex_patch: Optional[npt.NDArray[np.uint32]] = None,
    face_patch: Optional[npt.NDArray[np.uint32]] = None,
    corner_params: Optional[npt.NDArray[np.float32]] = None,
) -> None: ...
def measure_error(
    set: SurfaceSet,
    vertices: npt.NDArray[np.float32],
    faces: npt.NDArray[np.uint32],
    face_patch: npt.NDArray[np.uint32],
    corner_params: npt.NDArray[np.float32],
    order: int = 6,
) -> Dict[str, float]: ...
def pattern(
    scheme: str,
    domain: str,
    edges: Sequence[float] = ...,
    inside: Sequence[float] = ...,
    level: int = 2,
    mask: str = "10",
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.uint32], npt.NDArray[np.uint32], str, List[float], List[float]]: ...
def scheme_names() -> List[str]: ...
