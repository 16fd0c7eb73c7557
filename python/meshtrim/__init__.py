"""meshtrim: smooth, exact borders for meshes reconstructed from 3D scans.

The functions of the ``meshtrim`` command line on numpy arrays, run by the
same Rust library, with the same results bit for bit:

- :func:`detect`: boundary points of a cloud and its local resolution β;
- :func:`edges`: the smoothed boundary loops, corners and edges;
- :func:`trim`: a mesh reconstructed from a cloud (screened Poisson) cut
  along the cloud's smoothed boundary;
- :func:`mesh`: a Delaunay mesh of the cloud bounded by that boundary;
- :func:`clean`: a triangulated scan's jagged border replaced by its
  smoothed edge; :func:`border_edges` a mesh's border as loops and edges,
  for :func:`write_edges` (``clean --edges``);
- :func:`read_cloud`, :func:`read_mesh`, :func:`write_mesh`: the CLI's
  readers and writers, vertex normals and colours included;
- :func:`carry`: per-vertex values (normals, colours, anything) carried
  from a mesh to the mesh :func:`trim`, :func:`clean` or :func:`mesh`
  made from it, as the CLI carries normals and colours;
  :func:`carry_faces` per-face values, as the CLI carries materials;
  :func:`split_seams` the output's vertices split where the input's are
  (texture charts), as the CLI writes them;
- :func:`batch_plan`: which meshes ``meshtrim batch`` would take, where
  each output goes and which cloud trims it, for running a batch on
  another scheduler (Dask, say).

Points and vertices are ``(n, 3)`` arrays (float64, or anything numpy
converts to it, e.g. float32), faces ``(m, 3)`` integer arrays; any memory
layout. Results are new float64 and int64 arrays. Every function releases
the GIL while the library works, so other Python threads run meanwhile.

Adapters for host libraries are imported on demand:
``meshtrim.pymeshlab``, ``meshtrim.open3d`` and ``meshtrim.trimesh``.

Every problem with an input raises :class:`MeshtrimError` (a
``ValueError``) with the message the CLI prints.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any, Mapping, NamedTuple, Optional, Sequence, Union

import numpy as np

from . import _meshtrim
from ._meshtrim import FileMaterials, MeshtrimError

__all__ = [
    "MeshtrimError",
    "Detection",
    "Edge",
    "Loop",
    "Edges",
    "detect",
    "edges",
    "trim",
    "mesh",
    "clean",
    "border_edges",
    "read_cloud",
    "read_mesh",
    "write_mesh",
    "write_edges",
    "VertexAttributes",
    "ObjMaterial",
    "FileMaterials",
    "write_mesh_carrying",
    "carry",
    "split_seams",
    "SplitMesh",
    "carry_faces",
    "deviation",
    "BatchJob",
    "batch_plan",
]

__version__ = "0.1.0"

_ADAPTERS = ("pymeshlab", "open3d", "trimesh")


def __getattr__(name: str):
    # The adapters import their host library: only when first used.
    if name in _ADAPTERS:
        import importlib

        return importlib.import_module(f".{name}", __name__)
    raise AttributeError(f"module 'meshtrim' has no attribute {name!r}")

PathLike = Union[str, "os.PathLike[str]"]
Vector = Optional[Sequence[float]]


@dataclass(frozen=True)
class Detection:
    """Boundary points of a cloud (``meshtrim detect``).

    ``boundary`` is a bool array with one label per point, ``beta`` each
    point's local resolution β (the paper's eq. 3, the radius of the
    empty-circle test). ``summary`` has the keys of
    ``meshtrim detect --json``; the most used are attributes.
    """

    boundary: np.ndarray
    beta: np.ndarray
    summary: dict = field(repr=False)

    @property
    def boundary_points(self) -> int:
        """Points labelled boundary (duplicates counted)."""
        return self.summary["boundary_points"]

    @property
    def duplicates(self) -> int:
        """Points that were exact copies of an earlier one."""
        return self.summary["duplicates"]

    @property
    def detect_ms(self) -> float:
        """Time of the library's detection, in milliseconds."""
        return self.summary["detect_ms"]


@dataclass(frozen=True)
class Edge:
    """A smoothed edge: from corner to corner, or a whole loop (closed)."""

    closed: bool
    points: np.ndarray


@dataclass(frozen=True)
class Loop:
    """A closed boundary loop: its boundary points (indices into the
    cloud, in loop order), its corners' positions and its smoothed edges,
    as in ``meshtrim edges -o OUT.json``."""

    closed: bool
    boundary_points: np.ndarray
    corners: np.ndarray
    edges: list


class Edges(list):
    """The loops of :func:`edges` (a list of :class:`Loop`), with the
    detection they came from and the summary of ``meshtrim edges --json``
    (for :func:`border_edges`: no detection, and the summary's ``loops``
    and ``loops_from``)."""

    def __init__(self, loops: list, detection: Optional[Detection], summary: dict):
        super().__init__(loops)
        self.detection = detection
        self.summary = summary


def _real_array(array: Any, name: str, kinds: str = "fiu") -> np.ndarray:
    """``array`` as a numpy array of one of the dtype ``kinds`` (real
    numbers: not complex, text or objects, which would not convert or
    would lose their imaginary part)."""
    try:
        a = np.asarray(array)
    except Exception as e:  # e.g. ragged nested lists
        raise MeshtrimError(f"{name}: not an array of numbers: {e}") from None
    if a.dtype.kind not in kinds:
        raise MeshtrimError(f"{name}: expected real numbers, got dtype {a.dtype}")
    return a


def _float_rows(array: Any, name: str) -> np.ndarray:
    """``array`` as a C-order float64 ``(n, 3)`` array (no copy when it
    already is one)."""
    a = _real_array(array, name)
    if a.ndim != 2 or a.shape[1] != 3:
        raise MeshtrimError(f"{name}: expected an array of shape (n, 3), got {a.shape}")
    return np.ascontiguousarray(a, dtype=np.float64)


def _face_rows(array: Any, vertices: int) -> np.ndarray:
    """``array`` as a C-order uint32 ``(m, 3)`` array of indices below
    ``vertices``."""
    try:
        a = np.asarray(array)
    except Exception as e:
        raise MeshtrimError(f"faces: not an array of numbers: {e}") from None
    if a.ndim != 2 or a.shape[1] != 3:
        raise MeshtrimError(f"faces: expected an array of shape (m, 3), got {a.shape}")
    if a.dtype.kind == "f" and a.size and not np.all(np.mod(a, 1) == 0):
        raise MeshtrimError("faces: expected integer vertex indices")
    if a.dtype.kind not in "iuf" and a.size:
        raise MeshtrimError(f"faces: expected integer vertex indices, got dtype {a.dtype}")
    if a.size:
        low, high = a.min(), a.max()
        if low < 0:
            face = int(np.argwhere(a < 0)[0][0])
            raise MeshtrimError(f"faces: face {face} has a negative vertex index ({int(a[face].min())})")
        if high >= vertices:
            face = int(np.argwhere(a >= vertices)[0][0])
            raise MeshtrimError(
                f"faces: face {face} refers to vertex {int(a[face].max())}, "
                f"but there are {vertices} vertices"
            )
    return np.ascontiguousarray(a, dtype=np.uint32)


def _vector(value: Vector, name: str) -> Optional[tuple]:
    if value is None:
        return None
    try:
        v = tuple(float(c) for c in value)
    except (TypeError, ValueError):
        raise MeshtrimError(f"{name}: expected three numbers x, y, z") from None
    if len(v) != 3:
        raise MeshtrimError(f"{name}: expected three numbers x, y, z, got {len(v)}")
    return v


def _distance(value: Any, name: str) -> float:
    """A positive finite number."""
    try:
        d = float(value)
    except (TypeError, ValueError):
        raise MeshtrimError(f"{name}: {value!r} is not a number") from None
    if not (np.isfinite(d) and d > 0):
        raise MeshtrimError(f"{name}: {d} is not a distance: give a number above zero, in the mesh's units")
    return d


def _k(k: Any) -> int:
    if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or not 0 <= k < 2**31:
        raise MeshtrimError(f"k: expected a whole number, got {k!r}")
    return int(k)


def _options(k, anisotropy, view_along, view_from) -> tuple:
    return (
        _k(k),
        bool(anisotropy),
        _vector(view_along, "view_along"),
        _vector(view_from, "view_from"),
    )


def detect(
    points: Any,
    *,
    k: int = 30,
    anisotropy: bool = True,
    view_along: Vector = None,
    view_from: Vector = None,
) -> Detection:
    """Labels the boundary points of a cloud (``meshtrim detect``).

    ``k`` is the neighbourhood size, the point itself included (the
    paper's 30); ``anisotropy=False`` gives the paper's isotropic tests;
    ``view_along`` (a direction) or ``view_from`` (the scanner's position)
    is the range scanner's line of sight, when known.
    """
    k, anisotropy, along, from_ = _options(k, anisotropy, view_along, view_from)
    pts = _float_rows(points, "points")
    (boundary, beta), summary = _meshtrim.detect(pts, k, anisotropy, along, from_)
    return Detection(boundary, beta, json.loads(summary))


def edges(
    points: Any,
    *,
    k: int = 30,
    anisotropy: bool = True,
    offset: bool = True,
    view_along: Vector = None,
    view_from: Vector = None,
) -> Edges:
    """The cloud's smoothed boundary loops (``meshtrim edges``): a list of
    :class:`Loop`, each with its :class:`Edge` list.

    ``offset=False`` gives the paper's edges through the boundary points
    instead of the estimated physical edge half a row beyond them (for
    clouds whose outermost samples lie on the edge itself). The other
    options are :func:`detect`'s.
    """
    k, anisotropy, along, from_ = _options(k, anisotropy, view_along, view_from)
    pts = _float_rows(points, "points")
    (boundary, beta), raw, summary = _meshtrim.edges(
        pts, k, anisotropy, bool(offset), along, from_
    )
    loops = _loops(raw)
    summary = json.loads(summary)
    return Edges(loops, Detection(boundary, beta, summary), summary)


def _loops(raw: list) -> list:
    """The native module's loop tuples as a list of :class:`Loop`."""
    return [
        Loop(closed, indices, corners, [Edge(c, p) for c, p in pieces])
        for closed, indices, corners, pieces in raw
    ]


def trim(
    vertices: Any,
    faces: Any,
    points: Any,
    *,
    k: int = 30,
    anisotropy: bool = True,
    offset: bool = True,
    view_along: Vector = None,
    view_from: Vector = None,
) -> tuple:
    """Trims a mesh reconstructed from the cloud ``points`` along the
    cloud's smoothed boundary (``meshtrim MESH CLOUD OUT``).

    Returns ``(vertices, faces, report)``: the trimmed mesh and a dict
    with the keys of the CLI's ``--report`` JSON (file names ``None``,
    read and write times 0). Options as :func:`edges`.
    """
    k, anisotropy, along, from_ = _options(k, anisotropy, view_along, view_from)
    v = _float_rows(vertices, "vertices")
    f = _face_rows(faces, len(v))
    pts = _float_rows(points, "points")
    out_v, out_f, report = _meshtrim.trim(v, f, pts, k, anisotropy, bool(offset), along, from_)
    return out_v, out_f, json.loads(report)


def mesh(
    points: Any,
    *,
    k: int = 30,
    anisotropy: bool = True,
    offset: bool = True,
    view_along: Vector = None,
    view_from: Vector = None,
) -> tuple:
    """A Delaunay mesh of the cloud, bounded by its smoothed boundary
    (``meshtrim mesh``). Returns ``(vertices, faces, report)``, the report
    with the keys of the CLI's ``--report`` JSON. Options as :func:`edges`.
    """
    k, anisotropy, along, from_ = _options(k, anisotropy, view_along, view_from)
    pts = _float_rows(points, "points")
    out_v, out_f, report = _meshtrim.mesh(pts, k, anisotropy, bool(offset), along, from_)
    return out_v, out_f, json.loads(report)


def clean(
    vertices: Any,
    faces: Any,
    *,
    k: int = 30,
    anisotropy: bool = True,
    offset: bool = True,
    view_along: Vector = None,
    view_from: Vector = None,
    repair: bool = False,
    max_deviation: Optional[float] = None,
    fill_holes: Optional[float] = None,
) -> tuple:
    """Replaces a triangulated scan's jagged border by its smoothed edge
    (``meshtrim clean``): the mesh's own vertices are the cloud. Returns
    ``(vertices, faces, report)``, the report with the keys of the CLI's
    ``--report`` JSON. Options as :func:`edges`; ``repair`` (the CLI's
    ``--repair``) makes a mesh that is not edge-manifold or consistently
    oriented so first (faces on edges of more than two faces removed,
    smallest first; faces wound against their neighbours turned) rather
    than refusing it. Vertices split along a seam (two border edges
    between the same positions, running opposite ways: a texture chart's
    border, a triangle soup) are stitched first (``seam_edges_stitched``
    in the report), and the mesh returned is the stitched one;
    :func:`write_mesh_carrying` splits it again where the input was split,
    as the CLI writes it. ``max_deviation`` (the CLI's
    ``--max-deviation``) keeps the new border within that distance of the
    old one. ``fill_holes`` (the CLI's ``--fill-holes``) first closes
    the holes no wider than that (the largest distance between two of a
    hole's vertices), with faces over their own vertices; the report's
    ``holes_filled``, ``faces_filling`` and ``holes_not_filled`` say what
    it did. The report's ``input_to_output`` and ``output_to_input``
    say how far the scan moved (see :func:`deviation`).
    """
    k, anisotropy, along, from_ = _options(k, anisotropy, view_along, view_from)
    v = _float_rows(vertices, "vertices")
    f = _face_rows(faces, len(v))
    bound = None if max_deviation is None else _distance(max_deviation, "max_deviation")
    width = None if fill_holes is None else _distance(fill_holes, "fill_holes")
    out_v, out_f, report = _meshtrim.clean(v, f, k, anisotropy, bool(offset), along, from_, bool(repair), bound, width)
    return out_v, out_f, json.loads(report)


def border_edges(vertices: Any, faces: Any, *, k: int = 30, anisotropy: bool = True) -> Edges:
    """The border of the mesh ``vertices``, ``faces`` as a list of
    :class:`Loop`, one per border loop (its ``boundary_points`` index
    ``vertices``), split at its corners, found by the paper's corner test
    at the vertices' local resolution (``k`` and ``anisotropy`` as
    :func:`detect`'s), into edges through the border vertices themselves:
    nothing is smoothed. What ``meshtrim clean --edges`` writes of its output:

    >>> out_v, out_f, _ = meshtrim.clean(v, f)
    >>> meshtrim.write_edges("outline.step", meshtrim.border_edges(out_v, out_f), out_v)
    """
    k, anisotropy, _, _ = _options(k, anisotropy, None, None)
    v = _float_rows(vertices, "vertices")
    f = _face_rows(faces, len(v))
    loops = _loops(_meshtrim.border_edges(v, f, k, anisotropy))
    return Edges(loops, None, {"loops": len(loops), "loops_from": "mesh_border"})


def write_edges(
    path: PathLike,
    edges: Sequence[Loop],
    points: Any,
    *,
    units: str = "mm",
    dxf_splines: bool = False,
) -> None:
    """Writes loops of :func:`edges` as ``meshtrim edges CLOUD -o PATH``
    writes them, byte for byte: the format from the extension (.json,
    .obj, .svg, .dxf, .step or .stp, .igs or .iges), missing parent
    directories created, the file replaced atomically.

    ``edges`` is what :func:`edges` returned for ``points``, or some of its
    loops (a list of :class:`Loop`). ``units`` is the length unit a STEP,
    IGES or DXF-with-splines file declares (mm, m or in); ``dxf_splines``
    also writes each edge as a spline into a DXF file (the CLI's
    ``--dxf-splines``). The SVG picture marks the detection's boundary
    points when ``edges`` carries its detection, otherwise the loops'.
    """
    pts = _float_rows(points, "points")
    detection = getattr(edges, "detection", None)
    labelled = detection is not None and len(detection.boundary) == len(pts)
    if labelled:
        boundary = np.ascontiguousarray(detection.boundary, dtype=bool)
    else:
        boundary = np.zeros(len(pts), dtype=bool)
    loops = []
    for i, loop in enumerate(edges):
        if not isinstance(loop, Loop):
            raise MeshtrimError(f"edges[{i}]: expected a Loop, got {type(loop).__name__}")
        indices = np.asarray(loop.boundary_points)
        if indices.ndim != 1 or (indices.size and indices.dtype.kind not in "iu"):
            raise MeshtrimError(f"edges[{i}].boundary_points: expected a 1-D array of point indices")
        indices = np.ascontiguousarray(indices, dtype=np.int64)
        corners = loop.corners if np.size(loop.corners) else np.empty((0, 3))
        pieces = [
            (bool(e.closed), _float_rows(e.points, f"edges[{i}].edges[{j}].points"))
            for j, e in enumerate(loop.edges)
        ]
        if not labelled:
            boundary[indices[(indices >= 0) & (indices < len(pts))]] = True
        loops.append(
            (
                indices,
                _float_rows(corners, f"edges[{i}].corners"),
                pieces,
            )
        )
    _meshtrim.write_edges(os.fspath(path), pts, boundary, loops, str(units), bool(dxf_splines))


def read_cloud(path: PathLike, *, scan: Optional[int] = None, attributes: bool = False):
    """The points of a cloud file, as every command reads a cloud: PLY,
    PCD, OBJ, LAS/LAZ, E57, XYZ/TXT/CSV/ASC/PTS, or a mesh's vertices (STL,
    glTF/GLB). An E57 file's scans are merged in the file's frame, each in
    its pose; ``scan=N`` reads scan N alone (the CLI's ``--scan``). With
    ``attributes=True``, ``(points, VertexAttributes)``: the normals (PLY,
    PCD, glTF), colours (PLY, OBJ, glTF, PCD ``rgb``/``rgba``, LAS,
    E57) and the file's own values (PLY properties, glTF ``_NAME``, LAS
    ``intensity`` and ``classification``, E57 ``intensity``, PCD's other
    fields) that ``mesh`` carries to its vertices."""
    if scan is not None:
        scan = _k(scan)
    points, normals, colours, alpha, fields = _meshtrim.read_cloud(os.fspath(path), scan)
    if not attributes:
        return points
    return points, _attributes(normals, colours, alpha, fields)


_PLY_TYPES = {
    "char": np.int8,
    "uchar": np.uint8,
    "short": np.int16,
    "ushort": np.uint16,
    "int": np.int32,
    "uint": np.uint32,
    "float": np.float32,
    "double": np.float64,
}
"""The PLY types of a file's own values and the NumPy types that hold
them."""


def _attributes(normals, colours, alpha, fields, texcoords=None, material=None) -> "VertexAttributes":
    """Normals, colours, the file's own values, texture coordinates and
    the OBJ material as :class:`VertexAttributes` (RGB when the file had no
    alpha; each value in the NumPy type of its PLY type)."""
    if colours is not None and not alpha:
        colours = np.ascontiguousarray(colours[:, :3])
    scalars = {name: values.astype(_PLY_TYPES[kind]) for name, kind, values in fields}
    if isinstance(material, tuple):
        libraries, names, faces = material
        material = ObjMaterial(tuple(os.fspath(p) for p in libraries), tuple(names), faces)
    return VertexAttributes(normals, colours, scalars, texcoords, material)


class ObjMaterial(NamedTuple):
    """An OBJ's materials: the ``libraries`` (``mtllib`` files, as paths
    from the current directory), the materials' ``names`` (``usemtl``)
    and, per face, its material as an index into ``names`` (``faces``,
    ``(m,)`` uint32). :func:`write_mesh_carrying` gives each output face
    the material of the input face it lies on, and writes an OBJ's
    library beside it (with copies of its images) when the output is in
    another directory than the libraries."""

    libraries: tuple
    names: tuple
    faces: np.ndarray


class VertexAttributes(NamedTuple):
    """A mesh file's per-vertex attributes: ``normals`` ``(n, 3)``
    float64 and ``colours`` ``(n, 4)`` float64 RGBA in 0..1 (alpha 1 where
    the file has none, and then ``colours[:, :3]`` is what it held), each
    ``None`` when the file has none; ``scalars``, the file's own values
    by name (PLY's other vertex properties, such as MeshLab's ``quality``
    or a scanner's ``confidence``; glTF's ``_NAME`` attributes), each an
    ``(n,)`` array of the NumPy type of its stored type (``uchar``:
    uint8, ``int``: int32, ``float``: float32 …); ``texcoords``, ``(n, 2)``
    float64 texture coordinates (u, v with v up the image, as OBJ stores
    it: an OBJ's ``vt``, glTF's ``TEXCOORD_0`` turned up, PLY's
    ``texture_u``/``texture_v``), and ``material``, an OBJ's
    :class:`ObjMaterial` or a glTF's materials or a PLY's texture images
    as a :class:`FileMaterials` (``kind``, ``names``, ``faces``;
    ``with_faces(faces)`` the same materials on other faces), each
    ``None`` when the file has none.""" 

    normals: Optional[np.ndarray]
    colours: Optional[np.ndarray]
    # Read-only, so that the one default is not shared and changed.
    scalars: Mapping[str, np.ndarray] = MappingProxyType({})
    texcoords: Optional[np.ndarray] = None
    material: Optional[Union[ObjMaterial, "FileMaterials"]] = None


def read_mesh(path: PathLike, *, attributes: bool = False) -> tuple:
    """``(vertices, faces)`` of a mesh file (OBJ, PLY, STL, glTF/GLB),
    polygons split into fans, as ``trim`` and ``clean`` read it; with
    ``attributes=True``, ``(vertices, faces, VertexAttributes)``: the
    vertex normals (PLY, OBJ, glTF), colours (PLY, OBJ, glTF), the file's
    own values (PLY's other vertex properties, glTF ``_NAME``), texture
    coordinates (OBJ, glTF, PLY) and an OBJ's materials, which the CLI
    carries to its outputs. An OBJ vertex read with several texture
    coordinates or normals (at a chart's border, a hard edge) is one
    vertex per pair, the copies after the file's ``v`` lines."""
    vertices, faces, normals, colours, alpha, fields, texcoords, material = _meshtrim.read_mesh(os.fspath(path))
    if not attributes:
        return vertices, faces
    return vertices, faces, _attributes(normals, colours, alpha, fields, texcoords, material)


def write_mesh(
    path: PathLike,
    vertices: Any,
    faces: Any,
    *,
    normals: Any = None,
    colours: Any = None,
    scalars: Optional[dict] = None,
    texcoords: Any = None,
    material: Optional[Union[ObjMaterial, FileMaterials]] = None,
) -> None:
    """Writes a mesh as the CLI writes its outputs: the format from the
    extension (.obj, .ply and .stl binary, .gltf, .glb), missing parent
    directories created, the file replaced atomically. ``normals``
    ``(n, 3)`` and ``colours`` ``(n, 3)`` or ``(n, 4)`` (RGB or RGBA in
    0..1) are written with the vertices by every format but STL, as the
    CLI writes them: PLY ``float nx ny nz`` and ``uchar red green blue
    [alpha]``, OBJ ``v x y z r g b`` and ``vn``, glTF ``NORMAL`` (unit) and
    ``COLOR_0``. ``scalars`` (name: ``(n,)`` array) are values of the
    file's own, written as PLY properties of the array's type (int8 …
    uint32, float32, float64) or glTF ``_NAME`` attributes; OBJ and STL
    hold none. ``texcoords`` ``(n, 2)`` (v up the image) are written as
    OBJ ``vt``, PLY ``texture_u``/``texture_v`` and glTF ``TEXCOORD_0``;
    an OBJ ``material`` (one per face) as ``mtllib`` and ``usemtl``
    lines."""
    v = _float_rows(vertices, "vertices")
    f = _face_rows(faces, len(v))
    arrays = _attribute_arrays(normals, colours, scalars or {}, len(v))
    texture = _texture_arrays(texcoords, material, len(v), len(f))
    _meshtrim.write_mesh(os.fspath(path), v, f, *arrays, *texture)


def write_mesh_carrying(
    path: PathLike, vertices: Any, faces: Any, source_vertices: Any, source_faces: Any, attributes: "VertexAttributes"
) -> tuple:
    """Writes a mesh made from the mesh ``source_vertices``,
    ``source_faces`` (by :func:`trim`, :func:`clean` or :func:`mesh`) as the
    CLI writes its outputs, with the source's ``attributes`` (as
    :func:`read_mesh` gives them) that the format holds carried to it
    (:func:`carry`, per kind). Returns ``(written, not_written)``, the
    attributes' names, as the CLI's report lists them: STL holds none, OBJ
    no values of the file's own.

    >>> v, f, attrs = meshtrim.read_mesh("poisson.ply", attributes=True)
    >>> out_v, out_f, _ = meshtrim.trim(v, f, points)
    >>> meshtrim.write_mesh_carrying("trimmed.ply", out_v, out_f, v, f, attrs)
    """
    v = _float_rows(vertices, "vertices")
    f = _face_rows(faces, len(v))
    sv = _float_rows(source_vertices, "source_vertices")
    sf = _faces_or_none(source_faces, len(sv))
    arrays = _attribute_arrays(attributes.normals, attributes.colours, attributes.scalars, len(sv))
    texture = _texture_arrays(attributes.texcoords, attributes.material, len(sv), len(sf))
    written, not_written = _meshtrim.write_mesh_carrying(os.fspath(path), v, f, sv, sf, *arrays, *texture)
    return written, not_written


def _texture_arrays(texcoords: Any, material: Any, vertices: int, faces: int) -> tuple:
    """Texture coordinates of `vertices` vertices and a material of
    `faces` faces as the native layer takes them, each checked."""
    t = None if texcoords is None else _per_vertex(texcoords, "texcoords", vertices, (2,))
    if material is None:
        return t, None
    if isinstance(material, FileMaterials):
        if len(material.faces) != faces:
            raise MeshtrimError(f"material.faces: expected {faces} faces' materials, got {len(material.faces)}")
        return t, material
    libraries, names, per_face = material
    a = np.asarray(per_face)
    if a.shape != (faces,) or (a.size and (not np.issubdtype(a.dtype, np.integer) or a.min() < 0)):
        raise MeshtrimError(f"material.faces: expected {faces} non-negative integers, got shape {a.shape} of {a.dtype}")
    m = ([os.fspath(p) for p in libraries], [str(n) for n in names], np.ascontiguousarray(a, dtype=np.uint32))
    return t, m


def _attribute_arrays(normals: Any, colours: Any, scalars: Mapping, vertices: int) -> tuple:
    """Normals, colours and the file's own values of `vertices` vertices
    as the native layer takes them, each checked."""
    n = None if normals is None else _per_vertex(normals, "normals", vertices, (3,))
    c = None if colours is None else _per_vertex(colours, "colours", vertices, (3, 4))
    fields = [_field(name, values, vertices) for name, values in scalars.items()]
    return n, c, fields


def _field(name: Any, values: Any, vertices: int) -> tuple:
    """``(name, PLY type, float64 values)`` of one of the file's own
    values."""
    a = np.asarray(values)
    kinds = {np.dtype(t): kind for kind, t in _PLY_TYPES.items()}
    if a.dtype not in kinds:
        known = ", ".join(np.dtype(t).name for t in _PLY_TYPES.values())
        raise MeshtrimError(f"scalars[{name!r}]: {a.dtype} values have no PLY type; give one of {known}")
    if a.shape != (vertices,):
        raise MeshtrimError(f"scalars[{name!r}]: expected an array of shape ({vertices},), got {a.shape}")
    return str(name), kinds[a.dtype], np.ascontiguousarray(a, dtype=np.float64)


def _per_vertex(array: Any, name: str, vertices: int, widths: tuple) -> np.ndarray:
    """A C-order float64 ``(vertices, w)`` array, ``w`` one of ``widths``."""
    a = np.ascontiguousarray(_real_array(array, name), dtype=np.float64)
    if a.ndim != 2 or a.shape[0] != vertices or a.shape[1] not in widths:
        shape = " or ".join(f"({vertices}, {w})" for w in widths)
        raise MeshtrimError(f"{name}: expected an array of shape {shape}, got {a.shape}")
    return a


def carry(
    vertices: Any,
    faces: Any,
    values: Any,
    out_vertices: Any,
    out_faces: Any = None,
    *,
    normals: bool = False,
    nearest: Optional[bool] = None,
) -> np.ndarray:
    """Per-vertex ``values`` of the mesh ``vertices``, ``faces`` (or of a
    cloud: ``faces`` ``None`` or empty) at the vertices of a mesh made
    from it by :func:`trim`, :func:`clean` or :func:`mesh`
    (``out_vertices``, ``out_faces``), as the CLI carries normals and
    colours to its outputs: a vertex at an input vertex's exact position
    takes its row, any other the row blended by the barycentric weights of
    its closest point on the input surface (from a cloud, the nearest
    point's row). Where input vertices share a position (a seam), the
    output faces say which is which: give ``out_faces`` for meshes with
    seams. :func:`clean` stitches seams, so one output vertex stands for
    both sides; :func:`split_seams` splits the output again and carries
    each side its own values (texture coordinates across a chart's
    border). ``values`` is ``(n,)`` or ``(n, k)``: colours, a quality,
    texture coordinates. With ``normals=True`` (``k`` = 3) rows blend as
    normals do: the direction, at the blended length. Integer (and bool)
    values, labels or flags, are not blended: a new vertex takes the row
    of its face's corner of the largest weight, in the values' own type
    (``nearest``, by default whether the values are integers, says which).
    A corner of weight 0 adds nothing to a blend, not even a NaN.

    >>> v, f, attrs = meshtrim.read_mesh("poisson.ply", attributes=True)
    >>> out_v, out_f, _ = meshtrim.trim(v, f, points)
    >>> colours = meshtrim.carry(v, f, attrs.colours, out_v, out_f)
    """
    v = _float_rows(vertices, "vertices")
    f = _faces_or_none(faces, len(v))
    table = _Table(values, len(v), nearest)
    to = _float_rows(out_vertices, "out_vertices")
    out = _meshtrim.carry(v, f, table.rows, to, _faces_or_none(out_faces, len(to)), bool(normals), table.nearest)
    return table.restored(out)


class _Table:
    """Per-vertex values as the native module carries them: float64 rows,
    whether from the nearest corner (by default for integers), and how to
    give the carried rows back in the values' shape and type."""

    def __init__(self, values: Any, vertices: int, nearest: Optional[bool] = None, name: str = "values"):
        self.given = _real_array(values, name, kinds="biuf")
        self.labels = self.given.dtype.kind in "biu"
        self.nearest = self.labels if nearest is None else bool(nearest)
        as_float = self.given.astype(np.float64)
        self.flat = as_float.ndim == 1
        self.rows = np.ascontiguousarray(as_float.reshape(-1, 1) if self.flat else as_float)
        if self.rows.ndim != 2 or self.rows.shape[0] != vertices:
            raise MeshtrimError(
                f"{name}: expected an array of shape ({vertices},) or ({vertices}, k), got {self.given.shape}"
            )

    def restored(self, out: np.ndarray) -> np.ndarray:
        out = out[:, 0] if self.flat else out
        return out.astype(self.given.dtype) if self.labels and self.nearest else out


class SplitMesh(NamedTuple):
    """A mesh split along its input's seams (:func:`split_seams`), with
    the values carried to it."""

    vertices: np.ndarray
    faces: np.ndarray
    values: list
    face_values: list
    normals: Optional[np.ndarray]


def split_seams(
    vertices: Any,
    faces: Any,
    out_vertices: Any,
    out_faces: Any,
    *,
    values: Sequence = (),
    face_values: Sequence = (),
    normals: Any = None,
    fill: Any = 0,
) -> SplitMesh:
    """The mesh ``out_vertices``, ``out_faces``, made from the mesh
    ``vertices``, ``faces`` by :func:`trim`, :func:`clean` or
    :func:`mesh`, with its vertices split where the input's are along a
    seam (a texture chart's border, a crease stored with two normals), as
    the CLI writes its outputs, the copies after the mesh's own vertices
    (the same mesh when none is split); with per-vertex ``values``
    (texture coordinates, colours: each as :func:`carry` takes it),
    ``normals`` and per-face ``face_values`` (as :func:`carry_faces`
    takes them) carried to it as the CLI carries its attributes, each copy
    its own side's. :func:`clean` stitches a mesh's seams (it cleans the
    surface, not its charts): this is how its output keeps a texture.

    >>> out_v, out_f, _ = meshtrim.clean(v, f)
    >>> split = meshtrim.split_seams(v, f, out_v, out_f, values=[texcoords], face_values=[material_ids])
    >>> uv, ids = split.values[0], split.face_values[0]
    """
    v = _float_rows(vertices, "vertices")
    f = _face_rows(faces, len(v))
    to = _float_rows(out_vertices, "out_vertices")
    tables = [_Table(array, len(v), name=f"values[{i}]") for i, array in enumerate(values)]
    if normals is not None:
        tables.append(_Table(normals, len(v), name="normals"))
    faces_given = [_face_table(array, len(f), f"face_values[{i}]") for i, array in enumerate(face_values)]
    native = [(t.rows, t is tables[-1] and normals is not None, t.nearest) for t in tables]
    split_v, split_f, carried, sources = _meshtrim.split_seams(v, f, to, _face_rows(out_faces, len(to)), native)
    carried = [t.restored(out) for t, out in zip(tables, carried)]
    return SplitMesh(
        split_v,
        split_f,
        carried[: len(values)],
        [_by_face(given, sources, fill) for given in faces_given],
        carried[-1] if normals is not None else None,
    )


def _face_table(values: Any, faces: int, name: str) -> np.ndarray:
    """Per-face values, ``(m,)`` or ``(m, k)``, checked."""
    given = np.asarray(values)
    if given.ndim not in (1, 2) or given.shape[0] != faces:
        raise MeshtrimError(f"{name}: expected an array of shape ({faces},) or ({faces}, k), got {given.shape}")
    return given


def _by_face(given: np.ndarray, sources: np.ndarray, fill: Any) -> np.ndarray:
    """The rows of ``given`` of each face's source face, ``fill`` for none."""
    out = given[np.maximum(sources, 0)]
    out[sources < 0] = fill
    return out


def carry_faces(vertices: Any, faces: Any, values: Any, out_vertices: Any, out_faces: Any, *, fill: Any = 0) -> np.ndarray:
    """Per-face ``values`` of the mesh ``vertices``, ``faces`` (material
    or texture numbers, segment labels, face colours: ``(m,)`` or
    ``(m, k)``, any dtype) at the faces of a mesh made from it by
    :func:`trim`, :func:`clean` or :func:`mesh` (``out_vertices``,
    ``out_faces``), as the CLI carries an OBJ's materials: a face kept
    from the input takes its own row, any other the row of the input
    face, among those its corners lie on, nearest its centroid; ``fill``
    where it lies on none. For a mesh with seams, :func:`split_seams`
    carries per-face values to the split output.

    >>> ids = meshtrim.carry_faces(v, f, material_ids, out_v, out_f)
    """
    v = _float_rows(vertices, "vertices")
    f = _face_rows(faces, len(v))
    given = _face_table(values, len(f), "values")
    to = _float_rows(out_vertices, "out_vertices")
    return _by_face(given, _meshtrim.face_sources(v, f, to, _face_rows(out_faces, len(to))), fill)


def deviation(vertices: Any, faces: Any, surface_vertices: Any, surface_faces: Any = None) -> dict:
    """How far the vertices of one mesh (``vertices``, ``faces``) lie from
    the surface of another (``surface_vertices``, ``surface_faces``; a
    cloud without faces: its nearest point), as ``clean``'s report
    measures the scan against the cleaned mesh and back: a vertex at
    exactly a vertex of the surface is on it and not measured; every other
    one takes the distance to its closest point on the surface's faces.
    Returns ``{"vertices": measured, "max": ..., "mean": ..., "at":
    (x, y, z) of the farthest, or None}``; the one-sided Hausdorff
    distance over vertices that MeshLab's Hausdorff filter gives when it
    samples vertices.

    >>> cut_back = meshtrim.deviation(scan_v, scan_f, clean_v, clean_f)["max"]
    """
    v = _float_rows(vertices, "vertices")
    f = _faces_or_none(faces, len(v))
    sv = _float_rows(surface_vertices, "surface_vertices")
    sf = _faces_or_none(surface_faces, len(sv))
    measured = json.loads(_meshtrim.deviation(v, f, sv, sf))
    at = measured.get("at")
    measured["at"] = None if at is None else tuple(at)
    return measured


def _faces_or_none(faces: Any, vertices: int) -> np.ndarray:
    """Face rows, or none for ``None`` or an empty array."""
    if faces is None or np.size(faces) == 0:
        return np.empty((0, 3), dtype=np.uint32)
    return _face_rows(faces, vertices)


class BatchJob(NamedTuple):
    """One mesh of a batch: the mesh, its output, the clouds paired
    with it (none: it is cleaned; one: trimmed with it; several: the
    batch fails it, as the choice would be a guess), and where its edges
    go (``S.edges.EXT`` beside the output ``S.ext``, when asked for)."""

    input: Path
    output: Path
    clouds: tuple
    edges: Optional[Path] = None


def batch_plan(
    inputs: Union[PathLike, Sequence[PathLike]],
    out_dir: PathLike,
    *,
    cloud_dir: Optional[PathLike] = None,
    to: Optional[str] = None,
    edges_to: Optional[str] = None,
) -> list:
    """The work ``meshtrim batch INPUTS --out-dir OUT_DIR [--cloud-dir
    CLOUD_DIR] [--to EXT] [--edges-to EXT]`` would do, decided as it decides it before processing
    anything: ``inputs`` (files, directories walked recursively, glob
    patterns) expanded, sorted and de-duplicated, each mesh paired with
    its clouds by name (``S.cloud.EXT``, or ``S.EXT`` with a cloud-only
    extension such as ``.e57``, ``.laz`` or ``.xyz``), outputs mirrored
    below ``out_dir`` (with the extension ``to``, a mesh format's, when
    given), each output's edges file named when ``edges_to`` (an edges
    format's extension) is given, and all checked (two meshes with one
    output or edges file, or an
    output that is an input, raise :class:`MeshtrimError`). A list of
    :class:`BatchJob`, sorted by input path; nothing is read but
    directory listings and PLY/OBJ headers, nothing written."""
    if isinstance(inputs, (str, os.PathLike)):
        inputs = [inputs]
    args = [os.fspath(p) for p in inputs]
    cloud = None if cloud_dir is None else os.fspath(cloud_dir)
    return [
        BatchJob(Path(i), Path(o), tuple(Path(c) for c in clouds), None if e is None else Path(e))
        for i, o, clouds, e in _meshtrim.batch_plan(args, os.fspath(out_dir), cloud, to, edges_to)
    ]
