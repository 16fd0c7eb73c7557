"""Type stubs of meshtrim's native module (python/src/lib.rs).

The public API is in ``meshtrim/__init__.py``, which checks shapes and
converts dtypes before calling these: points and vertices arrive here as
C-order float64 ``(n, 3)`` arrays, faces as C-order uint32 ``(m, 3)``.
Reports and summaries are JSON text.
"""

from os import PathLike
from typing import Optional, Tuple

import numpy as np
import numpy.typing as npt

Points = npt.NDArray[np.float64]
Faces = npt.NDArray[np.int64]
Vector = Optional[Tuple[float, float, float]]
Labels = Tuple[npt.NDArray[np.bool_], npt.NDArray[np.float64]]
LoopTuple = Tuple[bool, npt.NDArray[np.int64], Points, list[Tuple[bool, Points]]]

class MeshtrimError(ValueError): ...

class FileMaterials:
    @property
    def kind(self) -> str: ...
    @property
    def names(self) -> list[str]: ...
    @property
    def faces(self) -> npt.NDArray[np.uint32]: ...
    def with_faces(self, faces: npt.NDArray[np.uint32]) -> FileMaterials: ...

def detect(
    points: Points, k: int, anisotropy: bool, view_along: Vector, view_from: Vector
) -> Tuple[Labels, str]: ...
def edges(
    points: Points, k: int, anisotropy: bool, offset: bool, view_along: Vector, view_from: Vector
) -> Tuple[Labels, list[LoopTuple], str]: ...
def border_edges(
    vertices: Points, faces: npt.NDArray[np.uint32], k: int, anisotropy: bool
) -> list[LoopTuple]: ...
def trim(
    vertices: Points,
    faces: npt.NDArray[np.uint32],
    points: Points,
    k: int,
    anisotropy: bool,
    offset: bool,
    view_along: Vector,
    view_from: Vector,
) -> Tuple[Points, Faces, str]: ...
def mesh(
    points: Points, k: int, anisotropy: bool, offset: bool, view_along: Vector, view_from: Vector
) -> Tuple[Points, Faces, str]: ...
def clean(
    vertices: Points,
    faces: npt.NDArray[np.uint32],
    k: int,
    anisotropy: bool,
    offset: bool,
    view_along: Vector,
    view_from: Vector,
    repair: bool,
    max_deviation: float | None,
    fill_holes: float | None,
) -> Tuple[Points, Faces, str]: ...
Fields = list[Tuple[str, str, npt.NDArray[np.float64]]]

def read_cloud(
    path: str | PathLike[str], scan: Optional[int] = None
) -> Tuple[Points, Optional[Points], Optional[npt.NDArray[np.float64]], bool, Fields]: ...
Material = Tuple[list[str], list[str], npt.NDArray[np.uint32]] | FileMaterials

def read_mesh(
    path: str | PathLike[str],
) -> Tuple[
    Points,
    Faces,
    Optional[Points],
    Optional[npt.NDArray[np.float64]],
    bool,
    Fields,
    Optional[npt.NDArray[np.float64]],
    Optional[Material],
]: ...
def write_mesh(
    path: str | PathLike[str],
    vertices: Points,
    faces: npt.NDArray[np.uint32],
    normals: Optional[Points],
    colours: Optional[npt.NDArray[np.float64]],
    scalars: Fields,
    texcoords: Optional[npt.NDArray[np.float64]],
    material: Optional[Material],
) -> None: ...
def write_mesh_carrying(
    path: str | PathLike[str],
    vertices: Points,
    faces: npt.NDArray[np.uint32],
    from_vertices: Points,
    from_faces: npt.NDArray[np.uint32],
    normals: Optional[Points],
    colours: Optional[npt.NDArray[np.float64]],
    scalars: Fields,
    texcoords: Optional[npt.NDArray[np.float64]],
    material: Optional[Material],
) -> Tuple[list[str], list[str]]: ...
def carry(
    vertices: Points,
    faces: npt.NDArray[np.uint32],
    values: npt.NDArray[np.float64],
    to: Points,
    to_faces: npt.NDArray[np.uint32],
    normals: bool,
    nearest: bool,
) -> npt.NDArray[np.float64]: ...
def split_seams(
    vertices: Points,
    faces: npt.NDArray[np.uint32],
    to: Points,
    to_faces: npt.NDArray[np.uint32],
    tables: list[Tuple[npt.NDArray[np.float64], bool, bool]],
) -> Tuple[Points, npt.NDArray[np.int64], list[npt.NDArray[np.float64]], npt.NDArray[np.int64]]: ...
def face_sources(
    vertices: Points,
    faces: npt.NDArray[np.uint32],
    to: Points,
    to_faces: npt.NDArray[np.uint32],
) -> npt.NDArray[np.int64]: ...
def deviation(
    vertices: Points,
    faces: npt.NDArray[np.uint32],
    surface: Points,
    surface_faces: npt.NDArray[np.uint32],
) -> str: ...
def write_edges(
    path: str | PathLike[str],
    points: Points,
    boundary: npt.NDArray[np.bool_],
    loops: list[Tuple[npt.NDArray[np.int64], Points, list[Tuple[bool, Points]]]],
    units: str,
    dxf_splines: bool,
) -> None: ...
def batch_plan(
    inputs: list[str],
    out_dir: str,
    cloud_dir: Optional[str] = None,
    to: Optional[str] = None,
    edges_to: Optional[str] = None,
) -> list[Tuple[PathLike[str], PathLike[str], list[PathLike[str]], Optional[PathLike[str]]]]: ...
