"""tessera: crack-free adaptive tessellation of parametric surfaces, numpy arrays out.

Bicubic rational Bézier patches (``.patches``), cubic Bézier triangles (``.bezt``), triangle
meshes as PN triangles (``.obj``, ``.ply``, ``.stl``, ``.glb``, ``.gltf``) and Catmull-Clark
subdivision cages (``.obj`` with OpenSubdiv's tags) become one watertight indexed triangle
mesh — uniform, or adaptive with a guaranteed object-space (``tolerance``) or screen-space
(``pixel_error``) error, drawn by one of the published schemes.

>>> import tessera
>>> set = tessera.load("teapot.patches")                     # doctest: +SKIP
>>> mesh = tessera.tessellate(set, tolerance="0.1%")         # doctest: +SKIP
>>> mesh.vertices.shape, mesh.faces.shape                    # doctest: +SKIP
((9626, 3), (18880, 3))
>>> mesh.report["guaranteed_bound"] <= mesh.report["tolerance"]  # doctest: +SKIP
True

Everything is the Rust library's (the ``tessera`` crate), run as ``tessera mesh`` runs it:
the same file readers and repairs, schemes, criteria, checks and the same output, vertex for
vertex. The GIL is released while reading and tessellating.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Any, Dict, Optional, Sequence, Tuple, Union

import numpy as np

from . import _tessera
from ._tessera import Camera, SurfaceSet, __version__, load
from .errors import (
    Error,
    FileError,
    MeshError,
    OutputTooLargeError,
    ParameterError,
    ParseError,
    UnsupportedInputError,
)

#: Every scheme name ``scheme=`` takes.
SCHEMES: Tuple[str, ...] = tuple(_tessera.scheme_names())

PathLike = Union[str, "os.PathLike[str]"]

# The `--stats` keys that come from checking the mesh (the rest come with the frame).
_CHECKED_KEYS = ("boundary_edges", "nonmanifold_edges", "degenerate_triangles", "euler_characteristic", "problems")


class Mesh:
    """One tessellated frame: numpy arrays that own the engine's buffers (no copy).

    Attributes:
        vertices: ``(n, 3) float32`` positions.
        normals: ``(n, 3) float32`` unit surface normals.
        uvs: ``(n, 2) float32`` each vertex's parameters in the patch that evaluated it.
        patch_ids: ``(n,) uint32`` that patch.
        faces: ``(m, 3) uint32`` vertex indices, counter-clockwise seen from the normal side.
        face_patch_ids: ``(m,) uint32`` the patch of each triangle.
        corner_params: ``(m, 3, 2) float32`` each corner's parameters in its triangle's own
            patch (``corner_params=True``), else None.
        strips: ``(k,) uint32`` triangle strips, ``0xFFFFFFFF`` between strips
            (``strips=True``, schemes ``sd2`` and ``esc``), else None.
        set: the :class:`SurfaceSet` it was made from.
    """

    vertices: np.ndarray
    normals: np.ndarray
    uvs: np.ndarray
    patch_ids: np.ndarray
    faces: np.ndarray
    face_patch_ids: np.ndarray
    corner_params: Optional[np.ndarray]
    strips: Optional[np.ndarray]

    def __init__(self, drawn: tuple, set: SurfaceSet):
        (
            self.vertices,
            self.normals,
            self.uvs,
            self.patch_ids,
            self.faces,
            self.face_patch_ids,
            self.corner_params,
            self.strips,
            self._info,
        ) = drawn
        self.set = set
        self._report: Optional[Dict[str, Any]] = None

    @property
    def report(self) -> Dict[str, Any]:
        """The ``tessera mesh --stats`` figures of this frame as a dict: ``patches``,
        ``triangles``, ``vertices``, ``culled_patches``, ``boundary_edges``,
        ``nonmanifold_edges``, ``degenerate_triangles``, ``euler_characteristic`` (and the
        input's), ``seconds``, ``mtri_per_s``, ``threads``, ``stages`` (seconds per stage),
        ``repairs``, ``problems`` (what is wrong with the mesh that was not wrong with the
        input; empty when it is sound) and, for ``tolerance`` and ``pixel_error``,
        ``guaranteed_bound`` and ``bound_met``. The checked figures are computed on first
        access (one pass over the mesh)."""
        if self._report is None:
            checked = check(self)
            self._report = dict(self._info)
            for key in _CHECKED_KEYS:
                self._report[key] = checked[key]
        return self._report

    @property
    def vertex_count(self) -> int:
        return len(self.vertices)

    @property
    def triangle_count(self) -> int:
        return len(self.faces)

    def check(self) -> Dict[str, Any]:
        """:func:`tessera.check` of this mesh against the set it was made from."""
        return check(self)

    def measure_error(self, order: int = 6) -> Dict[str, float]:
        """The mesh's approximation error against the exact surface, measured (as ``tessera
        mesh --measure-error``): every triangle sampled at ``order``² points, each compared
        with the surface point at the same patch parameters. Returns ``max``, ``rms``,
        ``max_triangle`` and ``samples``. Needs ``corner_params=True`` when tessellating."""
        if self.corner_params is None:
            raise ParameterError("measure_error needs the corners' patch parameters: tessellate with corner_params=True")
        return _tessera.measure_error(
            self.set, self.vertices, self.faces, self.face_patch_ids, self.corner_params, order
        )

    def write(self, path: PathLike) -> None:
        """Writes the mesh by ``path``'s extension (``.obj``, ``.ply``, ``.stl``, ``.glb``)
        with tessera's writers, whole or not at all (as ``tessera mesh -o`` writes it)."""
        _tessera.write_mesh(
            os.fspath(path),
            self.vertices,
            self.faces,
            normals=self.normals,
            uvs=self.uvs,
            vertex_patch=self.patch_ids,
            face_patch=self.face_patch_ids,
            corner_params=self.corner_params,
        )

    def to_trimesh(self, process: bool = False, **kwargs: Any) -> "Any":
        """The mesh as a ``trimesh.Trimesh`` (needs ``pip install trimesh``), with its vertex
        normals. ``process=False`` (the default) keeps tessera's vertices as they are, so
        vertex ``i`` is still ``vertices[i]``; ``process=True`` lets trimesh merge vertices
        of equal position (tessera gives a vertex one copy per distinct normal where a
        mesh input has split normals)."""
        try:
            import trimesh
        except ImportError:
            raise ImportError("Mesh.to_trimesh needs trimesh: pip install trimesh") from None
        return trimesh.Trimesh(
            vertices=self.vertices, faces=self.faces, vertex_normals=self.normals, process=process, **kwargs
        )

    def __repr__(self) -> str:
        return f"<tessera.Mesh: {self.vertex_count} vertices, {self.triangle_count} triangles>"


class Tessellator:
    """A surface set prepared once for a scheme and a criterion, tessellated per frame.

    Preparing computes what does not depend on the view (topology minimums, every patch's
    error bound); each :meth:`frame` then plans and writes one frame, from its camera for the
    view-dependent criteria. The keyword arguments are ``tessera mesh``'s flags:

    Args:
        set: a :class:`SurfaceSet` (or a path, loaded with :func:`load`'s defaults).
        scheme: one of :data:`SCHEMES`; default ``"uniform"`` for ``factor``, ``"esc"`` for
            its own criterion, ``"transition"`` for the adaptive criteria.
        factor: uniform factor (every edge cut into that many segments; reals for ``sd2``
            and the fractional schemes). The default criterion, 8.
        tolerance: guaranteed object-space error: a distance, or text such as ``"0.1%"`` of
            the bounding-box diagonal.
        pixel_error: guaranteed screen-space error in pixels of ``camera``.
        distance: ``(fmin, fmax)`` factors from the distance to the eye plane.
        silhouette: ``(fmin, fmax)``, silhouette edges refined to ``fmax``.
        silhouette_mode: ``"silhouetteness"`` or ``"vertices"`` (default: the scheme's).
        mapping: ``"linear"`` or ``"quadratic"``, the mapping of ``distance``.
        camera: the :class:`Camera`; default ``Camera.framing(set)``, the command line's.
        cull: leave out patches outside the view or facing away (the mesh is open there).
        max_factor: largest adaptive factor (default 64).
        max_level: semi-uniform's highest level M, or ESC's Lmax.
        level, quality, threshold: ESC's fixed level, ``"high"``/``"medium"`` preset, or
            distance threshold in model units.
        warp: SD-2's reverse projection.
        bound: the guaranteed bound ``tolerance`` and ``pixel_error`` plan with: ``"hessian"``
            (default; one second-derivative bound per patch, cheap to plan) or ``"taylor"``
            (the second derivatives where each triangle is, with a third-derivative remainder,
            and the error sampled on coarse triangles: fewer triangles for the same guarantee
            on every surface kind, slower to plan) or ``"expansion"`` (the Taylor expansion
            without the sampling, on polynomial patches and triangles: between the two).
        strips: also make triangle strips (``sd2``, ``esc``).
        corner_params: also give each triangle corner's patch parameters.
        max_triangles: refuse larger outputs (default: what 3/4 of the available memory holds).

    Raises:
        ParameterError: for a request the library refuses (a tolerance for a hardware
            partitioning, SD-2 on quads, a factor out of range, ...).
    """

    def __init__(self, set: Union[SurfaceSet, PathLike], **options: Any):
        if not isinstance(set, SurfaceSet):
            set = load(os.fspath(set))
        self.set = set
        self._native = _tessera.Tessellator(set, **options)

    @property
    def scheme(self) -> str:
        """The scheme's name."""
        return self._native.scheme

    def frame(self, camera: Optional[Camera] = None) -> Mesh:
        """Tessellates one frame seen from ``camera`` (None: the tessellator's camera) and
        returns it; the mesh's arrays own their buffers, so each frame allocates its own."""
        return Mesh(self._native.frame(camera), self.set)


def tessellate(set: Union[SurfaceSet, PathLike], *, camera: Optional[Camera] = None, **options: Any) -> Mesh:
    """Tessellates ``set`` once: ``Tessellator(set, camera=camera, **options).frame()``.

    >>> mesh = tessera.tessellate(tessera.load("cow.obj"), pixel_error=0.5, cull=True)  # doctest: +SKIP

    See :class:`Tessellator` for the options.
    """
    return Tessellator(set, camera=camera, **options).frame()


def check(mesh: Union[Mesh, Tuple[np.ndarray, np.ndarray]], set: Optional[SurfaceSet] = None) -> Dict[str, Any]:
    """Checks a mesh as ``tessera check`` does: positions welded by exact bits, then
    ``boundary_edges``, ``nonmanifold_edges``, ``misoriented_edges``,
    ``degenerate_triangles``, ``euler_characteristic``, ``is_closed`` and the triangle
    quality (``min_angle`` in degrees, ``max_aspect_ratio``, ``min_angle_histogram``).

    ``mesh`` is a :class:`Mesh` or a ``(vertices, faces)`` pair of arrays. Against the set it
    was made from (a Mesh's own, or ``set``) it also gives ``problems``: what is wrong with
    the mesh that was not wrong with the input, the rule behind ``tessera mesh``'s exit
    status 1.
    """
    if isinstance(mesh, Mesh):
        culled = mesh._info["culled_patches"]
        return _tessera.check(mesh.vertices, mesh.faces, set=set or mesh.set, culled=culled)
    vertices, faces = mesh
    vertices = np.ascontiguousarray(vertices, dtype=np.float32)
    faces = np.ascontiguousarray(faces, dtype=np.uint32)
    return _tessera.check(vertices, faces, set=set)


@dataclass(frozen=True)
class Pattern:
    """A scheme's pattern on a bare domain (:func:`pattern`)."""

    #: ``(k, 2) float64`` the ``(u, v)`` of every point.
    points: np.ndarray
    #: ``(t, 3) uint32`` point indices, counter-clockwise in ``(u, v)``.
    triangles: np.ndarray
    #: ``(t,) uint32`` the ring, band or strip that made each triangle.
    regions: np.ndarray
    #: ``"ring"``, ``"boundary band"`` or ``"strip"``.
    region_kind: str
    #: The edge factors used, Direct3D's order.
    edge_factors: Tuple[float, ...]
    #: The inside factors used.
    inside_factors: Tuple[float, ...]


def pattern(
    scheme: str,
    domain: str,
    edges: Sequence[float] = (),
    inside: Sequence[float] = (),
    level: int = 2,
    mask: str = "10",
) -> Pattern:
    """The domain pattern of ``scheme`` on a ``"tri"`` or ``"quad"`` domain for the given
    edge factors, in Direct3D's order (quad ``U==0, V==0, U==1, V==1``; tri ``U==0, V==0,
    W==0``) — what ``tessera pattern`` draws. ``inside`` defaults to Direct3D's max
    reduction; ``level`` and ``mask`` are ESC's.

    >>> p = tessera.pattern("transition", "quad", [5, 4, 7, 3])  # doctest: +SKIP
    """
    points, triangles, regions, kind, edge_factors, inside_factors = _tessera.pattern(
        scheme, domain, list(map(float, edges)), list(map(float, inside)), level, mask
    )
    return Pattern(points, triangles, regions, kind, tuple(edge_factors), tuple(inside_factors))


__all__ = [
    "Camera",
    "Error",
    "FileError",
    "Mesh",
    "MeshError",
    "OutputTooLargeError",
    "ParameterError",
    "ParseError",
    "Pattern",
    "SCHEMES",
    "SurfaceSet",
    "Tessellator",
    "UnsupportedInputError",
    "__version__",
    "check",
    "load",
    "pattern",
    "tessellate",
]
