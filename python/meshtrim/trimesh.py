"""meshtrim on trimesh objects: a new ``trimesh.Trimesh`` out, built with
``process=False`` so that its arrays are meshtrim's exactly; the report is
in ``result.metadata["meshtrim"]``. Vertex colours, when the input has
them, and its ``vertex_attributes`` (glTF's ``_NAME`` attributes, say) are
carried to the new mesh (:func:`meshtrim.carry`: integer ones from the
nearest corner, in their own type); trimesh computes normals from the
faces. A textured mesh keeps its texture: its texture coordinates are
carried, the vertices split along the charts' borders as the input's
(:func:`meshtrim.split_seams`), and its material is the input's.

>>> cleaned = meshtrim.trimesh.clean(trimesh.load("scan.stl", process=False))
"""

from __future__ import annotations

import numpy as np
import trimesh

import meshtrim

__all__ = ["trim", "clean"]


def _result(vertices: np.ndarray, faces: np.ndarray, report: dict, source: trimesh.Trimesh) -> trimesh.Trimesh:
    texture = _texture(source)
    visual = None
    if texture is not None:
        # The seams the texture coordinates split stay split, each side
        # with its own coordinates.
        uv, material = texture
        split = meshtrim.split_seams(source.vertices, source.faces, vertices, faces, values=[uv])
        vertices, faces = split.vertices, split.faces
        visual = trimesh.visual.TextureVisuals(uv=split.values[0], material=material)

    def carried(values):
        return meshtrim.carry(source.vertices, source.faces, values, vertices, faces)

    colours = None
    if source.visual.kind == "vertex":
        rgba = carried(np.asarray(source.visual.vertex_colors, dtype=np.float64))
        colours = np.clip(np.rint(rgba), 0, 255).astype(np.uint8)
    attributes = {
        name: carried(values).astype(values.dtype)
        for name, values in source.vertex_attributes.items()
        if np.ndim(values) in (1, 2) and len(values) == len(source.vertices)
    }
    out = trimesh.Trimesh(
        vertices=vertices,
        faces=faces,
        vertex_colors=colours,
        vertex_attributes=attributes,
        visual=visual,
        process=False,
    )
    out.metadata["meshtrim"] = report
    return out


def _texture(mesh: trimesh.Trimesh):
    """A textured mesh's texture coordinates (one row per vertex) and
    material, or ``None``."""
    visual = mesh.visual
    if visual.kind != "texture" or visual.uv is None:
        return None
    uv = np.asarray(visual.uv, dtype=np.float64)
    if uv.shape != (len(mesh.vertices), 2):
        return None
    return uv, visual.material


def trim(mesh: trimesh.Trimesh, points, **options) -> trimesh.Trimesh:
    """``mesh`` cut along the smoothed boundary of the cloud ``points`` (an
    ``(n, 3)`` array or a ``trimesh.PointCloud``)."""
    if isinstance(points, trimesh.PointCloud):
        points = points.vertices
    return _result(*meshtrim.trim(mesh.vertices, mesh.faces, points, **options), mesh)


def clean(mesh: trimesh.Trimesh, **options) -> trimesh.Trimesh:
    """A scanned ``mesh`` with its jagged border smoothed."""
    return _result(*meshtrim.clean(mesh.vertices, mesh.faces, **options), mesh)
