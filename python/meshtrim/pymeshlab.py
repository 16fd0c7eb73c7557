"""meshtrim on a PyMeshLab ``MeshSet``: each function reads its layers,
runs meshtrim on their arrays, adds the result as a new layer (which
becomes the current mesh) and returns the report. The new layer's vertex
normals, colours and scalar (quality) are carried from the input layer
(:func:`meshtrim.carry`): screened Poisson's density and colours go with
the trimmed mesh. (PyMeshLab's ``Mesh`` replaces the normals of the
border vertices by its own, computed from the faces.)

>>> ms.generate_surface_reconstruction_screened_poisson(depth=8)
>>> report = meshtrim.pymeshlab.trim(ms, poisson_id, cloud_id)
"""

from __future__ import annotations

import numpy as np
import pymeshlab

import meshtrim

__all__ = ["trim", "clean", "mesh"]


def _add(ms: pymeshlab.MeshSet, vertices: np.ndarray, faces: np.ndarray, name: str, source: pymeshlab.Mesh) -> None:
    """Adds the mesh as a new layer, with the vertex attributes of the
    layer it was made from carried to it."""
    from_v = source.vertex_matrix()
    from_f = source.face_matrix() if source.face_number() else None
    def carried_values(values, **kind):
        return meshtrim.carry(from_v, from_f, values, vertices, faces, **kind)

    carried = dict(v_normals_matrix=carried_values(source.vertex_normal_matrix(), normals=True))
    if source.has_vertex_color():
        carried["v_color_matrix"] = carried_values(source.vertex_color_matrix())
    if source.has_vertex_scalar():
        carried["v_scalar_array"] = carried_values(source.vertex_scalar_array())
    layer = pymeshlab.Mesh(vertex_matrix=vertices, face_matrix=faces.astype(np.int32), **carried)
    ms.add_mesh(layer, mesh_name=name)


def trim(ms: pymeshlab.MeshSet, mesh_id: int, cloud_id: int, **options) -> dict:
    """Trims layer ``mesh_id`` (e.g. screened Poisson's) along the smoothed
    boundary of the cloud in layer ``cloud_id``; adds the trimmed mesh as
    the current layer; returns the report (see :func:`meshtrim.trim`)."""
    mesh, cloud = ms.mesh(mesh_id), ms.mesh(cloud_id)
    vertices, faces, report = meshtrim.trim(
        mesh.vertex_matrix(), mesh.face_matrix(), cloud.vertex_matrix(), **options
    )
    _add(ms, vertices, faces, "trimmed", mesh)
    return report


def clean(ms: pymeshlab.MeshSet, mesh_id: int, **options) -> dict:
    """Smooths the border of the scan in layer ``mesh_id``; adds the
    cleaned mesh as the current layer; returns the report (see
    :func:`meshtrim.clean`)."""
    mesh = ms.mesh(mesh_id)
    vertices, faces, report = meshtrim.clean(mesh.vertex_matrix(), mesh.face_matrix(), **options)
    _add(ms, vertices, faces, "cleaned", mesh)
    return report


def mesh(ms: pymeshlab.MeshSet, cloud_id: int, **options) -> dict:
    """Meshes the cloud in layer ``cloud_id`` within its smoothed boundary
    (the Delaunay path); adds the mesh as the current layer, each vertex
    with the attributes of the nearest cloud point; returns the report
    (see :func:`meshtrim.mesh`)."""
    cloud = ms.mesh(cloud_id)
    vertices, faces, report = meshtrim.mesh(cloud.vertex_matrix(), **options)
    _add(ms, vertices, faces, "meshed", cloud)
    return report
