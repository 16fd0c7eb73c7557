"""meshtrim on a PyMeshLab ``MeshSet``: each function reads its layers,
runs meshtrim on their arrays, adds the result as a new layer (which
becomes the current mesh) and returns the report.

>>> ms.generate_surface_reconstruction_screened_poisson(depth=8)
>>> report = meshtrim.pymeshlab.trim(ms, poisson_id, cloud_id)
"""

from __future__ import annotations

import numpy as np
import pymeshlab

import meshtrim

__all__ = ["trim", "clean", "mesh"]


def _add(ms: pymeshlab.MeshSet, vertices: np.ndarray, faces: np.ndarray, name: str) -> None:
    layer = pymeshlab.Mesh(vertex_matrix=vertices, face_matrix=faces.astype(np.int32))
    ms.add_mesh(layer, mesh_name=name)


def trim(ms: pymeshlab.MeshSet, mesh_id: int, cloud_id: int, **options) -> dict:
    """Trims layer ``mesh_id`` (e.g. screened Poisson's) along the smoothed
    boundary of the cloud in layer ``cloud_id``; adds the trimmed mesh as
    the current layer; returns the report (see :func:`meshtrim.trim`)."""
    mesh, cloud = ms.mesh(mesh_id), ms.mesh(cloud_id)
    vertices, faces, report = meshtrim.trim(
        mesh.vertex_matrix(), mesh.face_matrix(), cloud.vertex_matrix(), **options
    )
    _add(ms, vertices, faces, "trimmed")
    return report


def clean(ms: pymeshlab.MeshSet, mesh_id: int, **options) -> dict:
    """Smooths the border of the scan in layer ``mesh_id``; adds the
    cleaned mesh as the current layer; returns the report (see
    :func:`meshtrim.clean`)."""
    mesh = ms.mesh(mesh_id)
    vertices, faces, report = meshtrim.clean(mesh.vertex_matrix(), mesh.face_matrix(), **options)
    _add(ms, vertices, faces, "cleaned")
    return report


def mesh(ms: pymeshlab.MeshSet, cloud_id: int, **options) -> dict:
    """Meshes the cloud in layer ``cloud_id`` within its smoothed boundary
    (the Delaunay path); adds the mesh as the current layer; returns the
    report (see :func:`meshtrim.mesh`)."""
    vertices, faces, report = meshtrim.mesh(ms.mesh(cloud_id).vertex_matrix(), **options)
    _add(ms, vertices, faces, "meshed")
    return report
