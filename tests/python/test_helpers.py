"""Fast checks of the validation helpers (no meshtrim needed)."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

import poisson  # noqa: E402
import synthetic  # noqa: E402


def grid_mesh(n=4):
    """An n x n square of unit cells, two triangles each, CCW from +z."""
    xs, ys = np.meshgrid(np.arange(n + 1.0), np.arange(n + 1.0), indexing="ij")
    v = np.stack([xs.ravel(), ys.ravel(), np.zeros(xs.size)], 1)
    idx = lambda i, j: i * (n + 1) + j  # noqa: E731
    f = []
    for i in range(n):
        for j in range(n):
            a, b, c, d = idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)
            f += [(a, b, c), (a, c, d)]
    return v, np.array(f)


def test_generators_deterministic_and_sized():
    a, b = synthetic.blade(8.0, 3), synthetic.blade(8.0, 3)
    assert np.array_equal(a.points, b.points)
    assert not np.array_equal(a.points, synthetic.blade(8.0, 4).points)
    assert len(a.loops) == 4
    assert np.allclose(np.linalg.norm(a.normals, axis=1), 1.0)
    for c in synthetic.validation_clouds():
        for lp in c.loops:
            gaps = np.linalg.norm(np.roll(lp, -1, 0) - lp, axis=1)
            assert gaps.max() <= c.spacing * c.stretch_max / synthetic.BOUNDARY_OVERSAMPLING * 1.01


def test_true_area_exact_on_the_plate():
    p = synthetic.notched_plate(1.0)
    assert abs(p.area - (60 * 40 - 15 * 15 - math.pi * 25)) < 1e-3


def test_ply_round_trip(tmp_path):
    c = synthetic.notched_plate(2.0)
    synthetic.write_cloud_ply(tmp_path / "c.ply", c.points, c.normals)
    verts, faces = synthetic.read_ply(tmp_path / "c.ply")
    assert faces is None
    assert np.array_equal(np.stack([verts["x"], verts["y"], verts["z"]], 1), c.points)
    v, f = grid_mesh(3)
    synthetic.write_mesh_ply(tmp_path / "m.ply", v, f, quality=np.arange(len(v)))
    verts, faces = synthetic.read_ply(tmp_path / "m.ply")
    assert np.array_equal(faces, f) and np.array_equal(verts["quality"], np.arange(len(v)))
    lv, lf = poisson.load_mesh(tmp_path / "m.ply")
    assert lv.shape == v.shape and lf.shape == f.shape


def test_mesh_metrics_on_a_grid():
    v, f = grid_mesh(4)
    assert poisson.is_edge_manifold(f) and poisson.orientation_consistent(f)
    assert len(poisson.boundary_loops(f)) == 1
    assert len(poisson.boundary_loops(f)[0]) == 16
    assert abs(poisson.mesh_area(v, f) - 16.0) < 1e-12
    assert poisson.degenerate_triangles(v, f, 4.0) == 0
    # Removing the centre vertex opens a hole: two loops.
    centre = 2 * 5 + 2
    rv, rf = poisson.density_trim(v, f, (np.arange(len(v)) != centre).astype(float), 0.01)
    assert len(poisson.boundary_loops(rf)) == 2
    # A third face on an edge breaks manifoldness; a flipped face orientation.
    assert not poisson.is_edge_manifold(np.vstack([f, [[0, 6, 24]]]))
    assert not poisson.orientation_consistent(np.vstack([f[:-1], f[-1:, ::-1]]))
    # Border distance to a square of known side.
    truth = [np.array([[0, 0, 0], [4, 0, 0], [4, 4, 0], [0, 4, 0]], float)]
    d = poisson.PolylineDistance(truth)(np.array([[1.0, 0.5, 0.0], [2.0, 2.0, 1.0]]))
    assert np.allclose(d, [0.5, math.sqrt(5.0)])


def test_poisson_and_density_trim_agree_with_pymeshlab():
    c = synthetic.notched_plate(2.0)
    n = poisson.estimate_normals(c.points)
    assert poisson.normal_agreement(n, c.normals) == 1.0
    v, f, q = poisson.reconstruct(c.points, n, depth=6)
    assert len(f) > 100 and poisson.is_edge_manifold(f)
    a = poisson.density_trim(v, f, q, 0.10)
    b = poisson.density_trim_pymeshlab(v, f, q, 0.10)
    assert len(a[1]) == len(b[1])
    assert abs(poisson.mesh_area(*a) - poisson.mesh_area(*b)) < 1e-6 * poisson.mesh_area(*a)
