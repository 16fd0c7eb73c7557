"""How far one mesh lies from another (`meshtrim.deviation`, and the two
deviations of `clean`'s report), against Open3D's closest points and
SciPy's nearest neighbours on meshes made here."""

from __future__ import annotations

import json

import numpy as np
import pytest

import meshtrim
from meshtrim_cli import ROOT, run_meshtrim
from test_clean_validation import open3d_vertex_deviation

JAGGED = ROOT / "fixtures" / "meshes" / "blade_jagged.stl"


def wavy_sheet(n: int, seed: int):
    """A jittered n x n grid sheet, its height a wave."""
    rng = np.random.default_rng(seed)
    i, j = np.meshgrid(np.arange(n), np.arange(n))
    x = i.ravel() + rng.uniform(-0.3, 0.3, n * n)
    y = j.ravel() + rng.uniform(-0.3, 0.3, n * n)
    vertices = np.column_stack([x, y, np.sin(0.4 * x) + 0.2 * y])
    v = (j[:-1, :-1] * n + i[:-1, :-1]).ravel()
    faces = np.concatenate([np.column_stack([v, v + 1, v + n + 1]), np.column_stack([v, v + n + 1, v + n])])
    return vertices, faces


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_deviation_is_open3ds_closest_distance(seed):
    """A sheet with a fifth of its vertices moved (up to 2 spacings) and
    some faces cut away, measured against the sheet and back: the
    vertices measured, the largest distance, where, and the mean are
    Open3D's (float32: 1e-5)."""
    rng = np.random.default_rng(seed)
    v, f = wavy_sheet(30, seed)
    moved = v.copy()
    pick = rng.random(len(v)) < 0.2
    moved[pick] += rng.uniform(-2.0, 2.0, (pick.sum(), 3))
    kept = f[rng.random(len(f)) < 0.8]
    for a, b in [((moved, kept), (v, f)), ((v, f), (moved, kept))]:
        ours = meshtrim.deviation(*a, *b)
        distances, measured = open3d_vertex_deviation(*a, *b)
        assert ours["vertices"] == len(measured) > 0
        assert abs(ours["max"] - distances.max()) < 1e-5, (ours, distances.max())
        assert abs(ours["mean"] - distances.mean()) < 1e-5, (ours, distances.mean())
        assert np.allclose(ours["at"], a[0][measured[np.argmax(distances)]])


def test_a_surface_without_faces_is_a_cloud():
    """Against a cloud, each vertex's distance is to its nearest point
    (SciPy's k-d tree); a mesh of the same points does not deviate."""
    from scipy.spatial import cKDTree

    v, f = wavy_sheet(12, 4)
    cloud = v[::3] + 0.01
    ours = meshtrim.deviation(v, f, cloud)
    nearest, _ = cKDTree(cloud).query(v)
    assert ours["vertices"] == len(v)
    assert abs(ours["max"] - nearest.max()) < 1e-12 and abs(ours["mean"] - nearest.mean()) < 1e-12
    none = meshtrim.deviation(v, f, v, f)
    assert none == {"vertices": 0, "max": 0.0, "mean": 0.0, "at": None}


def test_cleans_report_is_the_deviation_both_ways():
    """`clean`'s report measures the scan against the cleaned mesh and
    back, as `deviation` does."""
    v, f = meshtrim.read_mesh(JAGGED)
    out_v, out_f, report = meshtrim.clean(v, f)
    report = json.loads(report) if isinstance(report, str) else report
    expected = {
        "input_to_output": meshtrim.deviation(v, f, out_v, out_f),
        "output_to_input": meshtrim.deviation(out_v, out_f, v, f),
    }
    for key, measured in expected.items():
        got = dict(report[key], at=tuple(report[key]["at"]))
        assert got == measured, (key, got, measured)
    # The jagged border's vertices lie on the new surface or near it; the
    # new border runs out past them to the physical edge.
    assert report["input_to_output"]["mean"] < report["output_to_input"]["mean"]


@pytest.mark.parametrize(
    "args, message",
    [
        (([[np.nan, 0.0, 0.0]], None, [[0.0, 0.0, 0.0]]), "vertices: vertex 0 has a coordinate that is not finite"),
        (([[0.0, 0.0, 0.0]], None, [[0.0, 0.0, np.inf]]), "surface_vertices: vertex 0 has a coordinate that is not finite"),
        (([[0.0, 0.0]], None, [[0.0, 0.0, 0.0]]), "vertices: expected an array of shape (n, 3)"),
        (([[0.0, 0.0, 0.0]], None, [[0.0, 0.0, 0.0]], [[0, 1, 2]]), "refers to vertex"),
    ],
)
def test_bad_input_is_a_clear_error(args, message):
    with pytest.raises(meshtrim.MeshtrimError, match=message.replace("(", r"\(").replace(")", r"\)")):
        meshtrim.deviation(*args)


def test_clean_holds_the_border_to_max_deviation(tmp_path):
    """`clean(..., max_deviation=)` is `clean --max-deviation`: the same
    arrays and report, the new vertices within the bound; a bound that is
    no positive number is refused."""
    import subprocess

    from meshtrim_cli import MESHTRIM

    v, f = meshtrim.read_mesh(JAGGED)
    out_v, out_f, report = meshtrim.clean(v, f, max_deviation=1.5)
    assert report["max_deviation"] == 1.5 and report["vertices_held"] > 0, report
    assert report["output_to_input"]["max"] <= 1.5 + 1e-9, report
    out = tmp_path / "held.ply"
    cli = subprocess.run([str(MESHTRIM), "clean", str(JAGGED), str(out), "--max-deviation", "1.5", "--json"], capture_output=True, text=True)
    assert cli.returncode == 0, cli.stderr
    cli_report = json.loads(cli.stdout)
    for key in ("input_to_output", "output_to_input", "vertices_held", "faces_out"):
        assert cli_report[key] == report[key], key
    assert np.array_equal(meshtrim.read_mesh(out)[0], out_v)
    for bad in (0, -1.0, float("nan"), "wide"):
        with pytest.raises(meshtrim.MeshtrimError, match="max_deviation"):
            meshtrim.clean(v, f, max_deviation=bad)


def test_trims_report_is_the_clouds_distance_from_the_output(tmp_path):
    """`meshtrim MESH CLOUD OUT` reports how far the cloud's points lie
    from the trimmed surface: Open3D's closest-point distances of the
    same points give the same count, largest distance, its point and
    mean (float32: 1e-6 of the diagonal); `meshtrim.trim` reports the
    same, and it is `meshtrim.deviation` of the cloud against the
    output."""
    mesh = ROOT / "fixtures" / "meshes" / "blade_small_poisson.ply"
    cloud = ROOT / "fixtures" / "meshes" / "blade_small.ply"
    out, report_path = tmp_path / "trimmed.ply", tmp_path / "report.json"
    run_meshtrim(mesh, cloud, out, "--report", report_path)
    reported = json.loads(report_path.read_text())["cloud_to_output"]
    points = meshtrim.read_cloud(cloud)
    out_v, out_f = meshtrim.read_mesh(out)
    distances, measured = open3d_vertex_deviation(points, np.arange(len(points)), out_v, out_f)
    tolerance = 1e-6 * np.linalg.norm(points.max(0) - points.min(0))
    assert reported["vertices"] == len(measured) == len(points), (reported, len(points))
    assert abs(reported["max"] - distances.max()) < tolerance, (reported, distances.max())
    assert abs(reported["mean"] - distances.mean()) < tolerance, (reported, distances.mean())
    assert np.allclose(reported["at"], points[measured[np.argmax(distances)]])
    # The fit of a screened-Poisson envelope to its scan: small, not zero.
    assert 0.0 < reported["mean"] < reported["max"]
    _, _, in_python = meshtrim.trim(*meshtrim.read_mesh(mesh), points)
    in_python = json.loads(in_python) if isinstance(in_python, str) else in_python
    assert in_python["cloud_to_output"] == reported
    assert dict(reported, at=tuple(reported["at"])) == meshtrim.deviation(points, np.empty((0, 3), np.uint32), out_v, out_f)
