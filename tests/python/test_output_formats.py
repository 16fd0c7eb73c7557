"""Every mesh format meshtrim writes, read back by PyMeshLab (an
independent reader): the same triangles as the PLY output, corner by
corner at single precision (STL and glTF store float32)."""

from __future__ import annotations

import subprocess

import numpy as np
import pymeshlab
import pytest

from meshtrim_cli import MESHTRIM, ROOT, run_meshtrim

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


UTM = np.array([512345.0, 4123456.0, 250.0])


def test_far_from_the_origin_gltf_keeps_its_precision_and_stl_is_refused(tmp_path):
    """The fixture trimmed after moving mesh and cloud to UTM-like
    coordinates, where float32 steps by 0.25: the GLB, read by trimesh and
    by PyMeshLab (which keep the node's translation, PyMeshLab as the
    layer's matrix), is the PLY trim moved, to 1e-4 (the mesh is 930
    across; written plain it was off by 0.125); the STL is refused, with
    nothing written, and so is `meshtrim.write_mesh` to STL."""
    import meshtrim
    import trimesh

    v, f = meshtrim.read_mesh(FIXTURES / "blade_small_poisson.ply")
    meshtrim.write_mesh(tmp_path / "mesh.ply", v + UTM, f)
    cloud = meshtrim.read_cloud(FIXTURES / "blade_small.ply") + UTM
    np.savetxt(tmp_path / "cloud.xyz", cloud, fmt="%.17g")
    run_meshtrim(FIXTURES / "blade_small_poisson.ply", FIXTURES / "blade_small.ply", tmp_path / "here.ply")
    here, here_faces = meshtrim.read_mesh(tmp_path / "here.ply")
    run_meshtrim(tmp_path / "mesh.ply", tmp_path / "cloud.xyz", tmp_path / "far.glb")
    read = trimesh.load(str(tmp_path / "far.glb"), force="mesh", process=False)
    assert np.array_equal(read.faces, here_faces)
    assert np.abs(read.vertices - UTM - here).max() < 1e-4
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(tmp_path / "far.glb"))
    ms.apply_matrix_freeze()
    assert np.array_equal(ms.current_mesh().face_matrix(), here_faces)
    assert np.abs(ms.current_mesh().vertex_matrix() - UTM - here).max() < 1e-4
    refused = subprocess.run(
        [str(MESHTRIM), tmp_path / "mesh.ply", tmp_path / "cloud.xyz", tmp_path / "far.stl"],
        capture_output=True,
        text=True,
    )
    assert refused.returncode == 1 and "STL stores coordinates as f32" in refused.stderr, refused.stderr
    assert not (tmp_path / "far.stl").exists()
    with pytest.raises(meshtrim.MeshtrimError, match="rounding merges vertex"):
        meshtrim.write_mesh(tmp_path / "here.stl", here + UTM, here_faces)
    assert not (tmp_path / "here.stl").exists()
