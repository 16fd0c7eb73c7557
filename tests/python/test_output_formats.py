"""Every mesh format meshtrim writes, read back by PyMeshLab (an
independent reader): the same triangles as the PLY output, corner by
corner at single precision (STL and glTF store float32)."""

from __future__ import annotations

import numpy as np
import pymeshlab
import pytest

from meshtrim_cli import ROOT, run_meshtrim

FIXTURES = ROOT / "fixtures" / "meshes"
FORMATS = ["ply", "obj", "stl", "gltf", "glb"]


def triangles(path):
    """The mesh's triangles as rows of nine float32 corner coordinates,
    each triangle started at its smallest corner (turn kept), sorted."""
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(path))
    m = ms.current_mesh()
    corners = m.vertex_matrix().astype(np.float32)[m.face_matrix()]
    rows = []
    for tri in corners:
        keys = [tuple(c) for c in tri]
        k = keys.index(min(keys))
        rows.append(np.concatenate([tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]]))
    rows = np.array(rows)
    return rows[np.lexsort(rows.T[::-1])]


@pytest.mark.parametrize(
    "job",
    [
        ["clean", FIXTURES / "blade_jagged.stl"],
        [FIXTURES / "blade_small_poisson.ply", FIXTURES / "blade_small.ply"],
        ["mesh", FIXTURES / "blade_holes.ply"],
    ],
    ids=["clean", "trim", "mesh"],
)
def test_every_format_reads_back_the_same_triangles(tmp_path, job):
    reference = None
    for ext in FORMATS:
        out = tmp_path / f"out.{ext}"
        run_meshtrim(*job, out)
        tris = triangles(out)
        assert len(tris) > 100, ext
        if reference is None:
            reference = tris
        else:
            assert tris.shape == reference.shape, ext
            assert np.array_equal(tris, reference), ext
