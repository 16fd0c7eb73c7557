"""meshtrim on Open3D geometry: ``TriangleMesh`` and ``PointCloud`` in,
new ``TriangleMesh`` out (the inputs are not changed).

>>> poisson, _ = o3d.geometry.TriangleMesh.create_from_point_cloud_poisson(pcd)
>>> trimmed = meshtrim.open3d.trim(poisson, pcd)

Each mesh function takes :func:`meshtrim.trim`'s options as keywords, and
with ``report=True`` returns ``(mesh, report)``. The input's vertex normals
and colours, when it has them, are carried to the new mesh
(:func:`meshtrim.carry`; from a cloud, each vertex's nearest point's). A
textured mesh keeps its texture: each corner's texture coordinates and
each triangle's material are carried, the vertices split along the
charts' borders as the input's were (:func:`meshtrim.split_seams`), with
its images.
"""

from __future__ import annotations

import numpy as np
import open3d as o3d

import meshtrim

__all__ = ["trim", "clean", "mesh", "detect"]


def _arrays(mesh: o3d.geometry.TriangleMesh) -> tuple:
    return np.asarray(mesh.vertices), np.asarray(mesh.triangles)


def _result(vertices: np.ndarray, faces: np.ndarray, report: dict, with_report: bool, source):
    texture = _split_by_texture(source) if isinstance(source, o3d.geometry.TriangleMesh) else None
    split = None
    if texture is not None:
        # The seams the texture coordinates split stay split, each side
        # with its own coordinates.
        split_v, split_f, uv = texture
        ids = np.asarray(source.triangle_material_ids)
        face_values = [ids] if len(ids) == len(split_f) else []
        split = meshtrim.split_seams(split_v, split_f, vertices, faces, values=[uv], face_values=face_values)
        vertices, faces = split.vertices, split.faces
    out = o3d.geometry.TriangleMesh(
        o3d.utility.Vector3dVector(vertices),
        o3d.utility.Vector3iVector(faces.astype(np.int32)),
    )
    _carry_attributes(source, out)
    if split is not None:
        out.triangle_uvs = o3d.utility.Vector2dVector(split.values[0][faces].reshape(-1, 2))
        out.textures = list(source.textures)
        if split.face_values:
            out.triangle_material_ids = o3d.utility.IntVector(split.face_values[0].astype(np.int32))
    return (out, report) if with_report else out


def _split_by_texture(mesh: o3d.geometry.TriangleMesh):
    """A textured mesh (a texture coordinate per triangle corner) as one
    vertex per (vertex, texture coordinate) pair its corners read:
    ``(vertices, faces, texcoords)``; ``None`` without texture
    coordinates."""
    faces = np.asarray(mesh.triangles)
    uvs = np.asarray(mesh.triangle_uvs)
    if len(faces) == 0 or uvs.shape != (3 * len(faces), 2):
        return None
    keys = np.column_stack([faces.reshape(-1).astype(np.float64), uvs])
    pairs, corners = np.unique(keys, axis=0, return_inverse=True)
    vertices = np.asarray(mesh.vertices)[pairs[:, 0].astype(np.int64)]
    return vertices, corners.reshape(-1, 3), pairs[:, 1:]


def _carry_attributes(source, out: o3d.geometry.TriangleMesh) -> None:
    """The vertex normals and colours of ``source`` (a mesh or a cloud)
    carried to ``out``'s vertices."""
    if isinstance(source, o3d.geometry.TriangleMesh):
        from_v, from_f = _arrays(source)
        normals, colours = source.vertex_normals, source.vertex_colors
    else:
        from_v, from_f = np.asarray(source.points), None
        normals, colours = source.normals, source.colors
    to, to_faces = _arrays(out)
    if len(normals):
        carried = meshtrim.carry(from_v, from_f, np.asarray(normals), to, to_faces, normals=True)
        out.vertex_normals = o3d.utility.Vector3dVector(carried)
    if len(colours):
        carried = meshtrim.carry(from_v, from_f, np.asarray(colours), to, to_faces)
        out.vertex_colors = o3d.utility.Vector3dVector(carried)


def trim(mesh: o3d.geometry.TriangleMesh, cloud: o3d.geometry.PointCloud, *, report: bool = False, **options):
    """``mesh`` (e.g. Open3D's Poisson) cut along the smoothed boundary of
    ``cloud``: a new ``TriangleMesh``."""
    vertices, faces = _arrays(mesh)
    return _result(*meshtrim.trim(vertices, faces, np.asarray(cloud.points), **options), report, mesh)


def clean(mesh: o3d.geometry.TriangleMesh, *, report: bool = False, **options):
    """A scanned ``mesh`` with its jagged border smoothed: a new ``TriangleMesh``."""
    return _result(*meshtrim.clean(*_arrays(mesh), **options), report, mesh)


def mesh(cloud: o3d.geometry.PointCloud, *, report: bool = False, **options):
    """A Delaunay ``TriangleMesh`` of ``cloud`` within its smoothed boundary."""
    return _result(*meshtrim.mesh(np.asarray(cloud.points), **options), report, cloud)


def detect(cloud: o3d.geometry.PointCloud, **options) -> meshtrim.Detection:
    """The boundary points of ``cloud`` (see :func:`meshtrim.detect`);
    ``cloud.select_by_index(np.flatnonzero(d.boundary))`` shows them."""
    return meshtrim.detect(np.asarray(cloud.points), **options)
