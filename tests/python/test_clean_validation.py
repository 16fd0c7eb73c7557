"""Validation of `meshtrim clean` with independent tools.

Synthetic cases (blade with three holes at 4 and 8 mm, notched plate,
curved disc with a hole): the jittered cloud is triangulated here, with
scipy's Delaunay in its parameter domain (:mod:`jagged`, independent of the
Rust generator), so its border zig-zags through the outermost samples; it
is written as a binary PLY (double coordinates) and cleaned by
`meshtrim clean`. Checked on the output:

- border loops = the true loops, and every loop smoothed;
- border (loop vertices and edge midpoints) -> true boundary: mean <= 0.25
  spacings, largest <= 1.0, and closer than the jagged input's;
- the area closer to the true area than the input's;
- PyMeshLab: no non-manifold edges or vertices, as many holes as true
  loops, one piece, `meshing_re_orient_faces_coherently` turns no face,
  `meshing_remove_duplicate_vertices`, `meshing_remove_null_faces` and
  `meshing_remove_duplicate_faces` remove nothing; directed edges used once
  (numpy); every face facing the true normal;
- new faces: smallest angle (the report's, checked against the faces not in
  the input) above 10 degrees and not below the input's smallest angle;
- every output vertex off the border is an input vertex, bit for bit.

`--no-offset` keeps the border through the border vertices: it stays about
as far from the truth as the jagged input and farther than the default.

Real scans (face000, lato000 from MeshLab's samples, the bunny's bun000
range grid): exit 0, PyMeshLab finds no non-manifold edge, no more
non-manifold vertices than in the input, nothing to merge or remove; the
border loops (split at pinched vertices) do not grow; every outer border
and every loop of 8 vertices or more is replaced; new faces have a floor
on their angles (an expected failure where the product falls short).

Measured (seed 1; spacings; area as a fraction of the true area):

============  ===========  ===========  =============  ============
case          input mean/  output mean/ area in / out  min angle in /
              max          max                         out (new)
============  ===========  ===========  =============  ============
blade 4 mm    0.350/0.913  0.117/0.511  0.9741/0.9985  12.96/22.77
blade 8 mm    0.291/0.702  0.129/0.603  0.9554/1.0060  13.45/17.67
plate         0.408/0.833  0.155/0.537  0.9529/0.9941  13.06/16.11
disc          0.390/1.002  0.123/0.606  0.9706/0.9954  11.45/21.52
============  ===========  ===========  =============  ============

--no-offset on the blade at 4 mm: 0.348/0.825. Seeds 2-5: input mean
0.28-0.40, output mean 0.12-0.18, largest 0.40-0.85, every loop smoothed,
smallest new angle 15.8-24.5 degrees.

Real scans (loops split at pinched vertices, as meshtrim counts them),
measured:

=======  =====  =========  ==================  ==============
scan     loops  smoothed   min angle new       new faces < 5
         in                (degrees)           degrees
=======  =====  =========  ==================  ==============
face000  44     40         1.47                12 of 8117
lato000  19     17         4.49                1 of 3612
bun000   4      4          2.14                10 of 2805
=======  =====  =========  ==================  ==============
"""

from __future__ import annotations

import csv
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial import cKDTree

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import crops  # noqa: E402
import jagged  # noqa: E402
import poisson  # noqa: E402
import synthetic  # noqa: E402
from meshtrim_cli import MESHTRIM, REAL_MESHES, ROOT, run_meshtrim, shared_data  # noqa: E402

CASES = synthetic.VALIDATION_CASES

MIN_ANGLE_SLACK = 1.0
"""The output's smallest angle may be this much (degrees) below the
input's (measured: it is 2.6 to 10 degrees above)."""


def read_mesh(path):
    verts, faces = synthetic.read_ply(path)
    return np.stack([verts["x"], verts["y"], verts["z"]], axis=1), faces


def clean(directory, name, vertices, faces, *flags):
    """Writes the mesh, runs `meshtrim clean` on it; (V, F, report)."""
    src = directory / f"{name}.ply"
    out = directory / f"{name}_clean.ply"
    report = directory / f"{name}_report.json"
    synthetic.write_mesh_ply(src, vertices, faces, double=True)
    run_meshtrim("clean", src, out, "--report", report, *flags)
    v, f = read_mesh(out)
    return v, f, json.loads(report.read_text())


@pytest.fixture(scope="module", params=sorted(CASES))
def case(request, tmp_path_factory):
    cloud = CASES[request.param]()
    d = tmp_path_factory.mktemp(f"clean_{request.param}")
    v, f, source = jagged.jagged_mesh(cloud)
    ov, of, report = clean(d, request.param, v, f)
    truth = poisson.PolylineDistance(cloud.loops)
    c = {
        "name": request.param,
        "cloud": cloud,
        "in": (v, f),
        "source": source,
        "out": (ov, of),
        "report": report,
        "err_in": jagged.border_error(v, f, cloud, truth),
        "err_out": jagged.border_error(ov, of, cloud, truth),
        "area_in": poisson.mesh_area(v, f) / cloud.area,
        "area_out": poisson.mesh_area(ov, of) / cloud.area,
        "angle_in": poisson.min_angle(v, f),
        "angle_out": poisson.min_angle(ov, of),
    }
    print(
        f"\n{c['name']}: border in {c['err_in'][0]:.3f}/{c['err_in'][1]:.3f} out "
        f"{c['err_out'][0]:.3f}/{c['err_out'][1]:.3f} spacings; area in {c['area_in']:.4f} "
        f"out {c['area_out']:.4f}; min angle in {c['angle_in']:.2f} out {c['angle_out']:.2f} "
        f"new {report['min_angle_new']:.2f}"
    )
    return c


def test_jagged_input_is_what_scanners_make(case):
    """The generator's mesh: valid, the true loop count, a jagged border
    inside the truth (the Rust generator: 0.27-0.39 spacings)."""
    v, f = case["in"]
    pm = poisson.pymeshlab_validity(v, f)
    assert pm["non_manifold_edges"] == 0 and pm["non_manifold_vertices"] == 0, pm
    assert pm["holes"] == len(case["cloud"].loops), pm
    assert len(poisson.fan_boundary_loops(f)) == len(case["cloud"].loops)
    assert 0.25 < case["err_in"][0] < 0.6, case["err_in"]
    assert case["area_in"] < 1.0


def test_loops(case):
    rep, cloud = case["report"], case["cloud"]
    n = len(cloud.loops)
    assert len(poisson.fan_boundary_loops(case["out"][1])) == n
    assert rep["loops_in"] == n and rep["loops_smoothed"] == n, rep
    assert rep["loops_left"] == [] and rep["loops_too_small"] == 0, rep


def test_border_on_the_true_border(case):
    mean_in, max_in = case["err_in"]
    mean_out, max_out = case["err_out"]
    assert mean_out <= 0.25, case["err_out"]
    assert max_out <= 1.0, case["err_out"]
    assert mean_out < mean_in and max_out < max_in, (case["err_in"], case["err_out"])


def test_area_closer_to_the_truth(case):
    assert abs(case["area_out"] - 1.0) < abs(case["area_in"] - 1.0), (case["area_in"], case["area_out"])
    rep = case["report"]
    v, f = case["in"]
    ov, of = case["out"]
    assert rep["area_in"] == pytest.approx(poisson.mesh_area(v, f), rel=1e-9)
    assert rep["area_out"] == pytest.approx(poisson.mesh_area(ov, of), rel=1e-9)
    assert rep["faces_out"] == len(of) and rep["faces_in"] == len(f)
    assert rep["faces_out"] == rep["faces_in"] - rep["faces_removed"] + rep["faces_added"]


def test_valid_by_pymeshlab(case):
    v, f = case["out"]
    pm = poisson.pymeshlab_validity(v, f)
    print(f"\n{case['name']}: {pm}")
    assert pm["non_manifold_edges"] == 0 and pm["non_manifold_vertices"] == 0, pm
    assert pm["holes"] == len(case["cloud"].loops), pm
    assert pm["components"] == 1, pm
    assert pm["reoriented"] == 0, pm
    assert pm["duplicate_vertices"] == 0 and pm["null_faces"] == 0 and pm["duplicate_faces"] == 0, pm
    assert poisson.orientation_consistent(f)
    scale = float(np.linalg.norm(v.max(0) - v.min(0)))
    assert poisson.degenerate_triangles(v, f, scale) == 0


def test_faces_face_the_true_normal(case):
    v, f = case["out"]
    cloud = case["cloud"]
    n = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    _, nearest = poisson.cKDTree(cloud.points).query(v[f].mean(axis=1))
    assert np.all(np.einsum("ij,ij->i", n, cloud.normals[nearest]) > 0)


def pymeshlab_border_smoothing(v, f, steps=3):
    """The peer: what MeshLab offers for a jagged border (as in
    bench/pymeshlab_border.py): select the border and smooth it with the
    1D boundary Laplacian, `steps` times; only border vertices move."""
    ms = poisson.pymeshlab.MeshSet()
    ms.add_mesh(poisson.pymeshlab.Mesh(vertex_matrix=v, face_matrix=f))
    ms.compute_selection_from_mesh_border()
    ms.apply_coord_laplacian_smoothing(
        stepsmoothnum=steps, boundary=True, cotangentweight=False, selected=True
    )
    m = ms.current_mesh()
    return m.vertex_matrix(), m.face_matrix()


def test_closer_to_the_truth_than_meshlabs_border_smoothing(case):
    """meshtrim's border is closer to the true border than MeshLab's border
    Laplacian gives, at 3 steps (the benchmark's peer) and at 10. Measured
    (mean / largest, spacings): blade 4 mm 0.324/1.11 (x3), 0.359/1.62
    (x10) against meshtrim's 0.117; blade 8 mm 0.277/0.88, 0.418/1.44
    against 0.129; plate 0.426/1.20, 0.548/1.70 against 0.155; disc
    0.394/0.82, 0.494/0.73 against 0.123. The Laplacian shrinks the
    border's curves, pulling it further inside the part."""
    truth = poisson.PolylineDistance(case["cloud"].loops)
    v, f = case["in"]
    ours = case["err_out"][0]
    for steps in (3, 10):
        pv, pf = pymeshlab_border_smoothing(v, f, steps)
        theirs = jagged.border_error(pv, pf, case["cloud"], truth)
        print(f"\n{case['name']}: MeshLab border Laplacian x{steps}: {theirs[0]:.3f}/{theirs[1]:.3f}, meshtrim {ours:.3f}")
        assert ours < theirs[0], (steps, ours, theirs)


def new_faces(case):
    """The output faces that are not input faces (compared by coordinates)."""
    v, f = case["in"]
    ov, of = case["out"]
    old = {tuple(sorted(map(tuple, tri))) for tri in v[f]}
    return np.array([tuple(sorted(map(tuple, tri))) not in old for tri in ov[of]])


def test_no_slivers(case):
    rep = case["report"]
    ov, of = case["out"]
    fresh = new_faces(case)
    assert fresh.sum() == rep["faces_added"], (fresh.sum(), rep)
    assert rep["min_angle_new"] == pytest.approx(poisson.min_angle(ov, of[fresh]), abs=1e-6)
    assert rep["min_angle_new"] > 10.0, rep
    assert case["angle_out"] >= case["angle_in"] - MIN_ANGLE_SLACK, (case["angle_in"], case["angle_out"])


def test_interior_vertices_are_input_vertices(case):
    v, _ = case["in"]
    ov, of = case["out"]
    on_border = np.zeros(len(ov), dtype=bool)
    on_border[poisson.boundary_edges(of).ravel()] = True
    inputs = {tuple(p) for p in v}
    off_border = [tuple(p) in inputs for p in ov[~on_border]]
    assert all(off_border), f"{len(off_border) - sum(off_border)} new vertices off the border"
    # New vertices: exactly the report's, all on the border.
    new = np.array([tuple(p) not in inputs for p in ov])
    assert new.sum() == case["report"]["vertices_added"]


def test_no_offset_keeps_the_inward_bias(tmp_path):
    """The paper's edges run through the border vertices: the border stays
    about where the jagged one was (measured on the blade at 4 mm: 0.348
    against 0.350), farther than with the offset (0.117)."""
    cloud = CASES["blade4"]()
    v, f, _ = jagged.jagged_mesh(cloud)
    truth = poisson.PolylineDistance(cloud.loops)
    before = jagged.border_error(v, f, cloud, truth)
    ov, of, rep = clean(tmp_path, "paper", v, f, "--no-offset")
    dv, df, _ = clean(tmp_path, "default", v, f)
    paper = jagged.border_error(ov, of, cloud, truth)
    default = jagged.border_error(dv, df, cloud, truth)
    print(f"\nblade4: input {before}, --no-offset {paper}, default {default}")
    assert rep["loops_smoothed"] == len(cloud.loops), rep
    assert paper[0] > 0.8 * before[0], (before, paper)
    assert paper[0] > default[0] + 0.1, (paper, default)
    assert len(poisson.fan_boundary_loops(of)) == len(cloud.loops)
    pm = poisson.pymeshlab_validity(ov, of)
    assert pm["non_manifold_edges"] == 0 and pm["non_manifold_vertices"] == 0 and pm["reoriented"] == 0, pm


def test_batch_cleans_a_directory(tmp_path):
    """`meshtrim batch DIR` with two meshes and no clouds: both cleaned."""
    scans = tmp_path / "scans"
    scans.mkdir()
    meshes = {}
    for name, make in (("plate", lambda: synthetic.notched_plate(2.0, 3)), ("blade", lambda: synthetic.blade(8.0, 2))):
        cloud = make()
        v, f, _ = jagged.jagged_mesh(cloud)
        synthetic.write_mesh_ply(scans / f"{name}.ply", v, f, double=True)
        meshes[name] = (cloud, v, f)
    out = tmp_path / "out"
    report = tmp_path / "batch.csv"
    run_meshtrim("batch", scans, "--out-dir", out, "--report", report, "--jobs", "2")
    rows = list(csv.DictReader(report.open()))
    assert len(rows) == 2, rows
    for row in rows:
        assert row["mode"] == "clean" and row["status"] == "ok", row
    for name, (cloud, v, f) in meshes.items():
        path = out / f"{name}.ply"
        assert path.exists(), sorted(out.rglob("*"))
        ov, of = read_mesh(path)
        row = next(r for r in rows if Path(r["input"]).name == f"{name}.ply")
        assert int(row["faces_in"]) == len(f) and int(row["faces_out"]) == len(of), row
        assert int(row["loops"]) == len(cloud.loops), row
        assert jagged.border_error(ov, of, cloud)[0] < jagged.border_error(v, f, cloud)[0]


# --------------------------------------------------------------------------
# Real scans.

# name: path. What must be replaced is asserted as requirements below
# (every outer border; loops of 8 vertices or more), not as shares of
# today's output.
REAL = REAL_MESHES

OUTER_SHRINK = {
    # name: largest output / input length of the outer border. Measured:
    # face000 0.767, lato000 0.822, Laurana50k 0.969, bun000 0.786,
    # bun045 0.750, bun090 0.835, chin 0.840. Laurana50k is a decimated
    # mesh, not a raw range grid: its silhouette is far less jagged (median
    # turning 16.5 degrees per vertex against 34-56 on the range grids), so
    # it has less length to lose; its turning drops 4-fold all the same.
    "Laurana50k": 0.98,
}

BIG_LOOPS_LEFT = {
    # name: loops of 8 or more vertices left, measured. bun090's three
    # (10, 13 and 17 vertices) are small holes at its silhouette whose
    # smoothed loops double back or whose walls cannot close.
    "bun090": 3,
}


_SCANS = {}


def clean_scan(name, tmp_path_factory):
    """Cleans one real scan once per session (the tests below reuse the
    result) and measures input and output."""
    if name in _SCANS:
        return _SCANS[name]
    src = shared_data(REAL[name])
    d = tmp_path_factory.mktemp(f"scan_{name}")
    out = d / f"{name}_clean.ply"
    report = d / "report.json"
    run_meshtrim("clean", src, out, "--report", report)
    # PyMeshLab reads the bunny's range grid as faces, too.
    iv, if_ = poisson.load_mesh(src)
    ov, of = poisson.load_mesh(out)
    rep = json.loads(report.read_text())
    s = {
        "name": name,
        "src": src,
        "out_path": out,
        "in": (iv, if_),
        "out": (ov, of),
        "report": rep,
        "pm_in": poisson.pymeshlab_validity(iv, if_),
        "pm_out": poisson.pymeshlab_validity(ov, of),
        "loops_in": len(poisson.fan_boundary_loops(if_)),
        "loops_out": len(poisson.fan_boundary_loops(of)),
    }
    print(
        f"\n{name}: loops {s['loops_in']} -> {s['loops_out']}, smoothed {rep['loops_smoothed']}, "
        f"left {[len(x['loops']) for x in rep['loops_left']]}, min angle in "
        f"{poisson.min_angle(iv, if_):.2f} new {rep['min_angle_new']:.2f}; in {s['pm_in']}; out {s['pm_out']}"
    )
    _SCANS[name] = s
    return s


@pytest.fixture(scope="module", params=sorted(REAL))
def scan(request, tmp_path_factory):
    return clean_scan(request.param, tmp_path_factory)


def test_scan_valid(scan):
    pm_in, pm = scan["pm_in"], scan["pm_out"]
    assert pm["non_manifold_edges"] == 0, pm
    # Pinched border vertices of the scan itself stay (face000: 6 in, 4
    # out; bun000: 4 and 4); cleaning adds none: every pinched vertex of
    # the output is one of the input's (within float32 rounding: PyMeshLab
    # reads the ASCII scans in single precision, meshtrim in double).
    assert pm["non_manifold_vertices"] <= pm_in["non_manifold_vertices"], (pm_in, pm)
    (vi, fi), (v, f) = scan["in"], scan["out"]
    pinched_in = sorted(crops.pinched_vertices(fi))
    pinched_out = sorted(crops.pinched_vertices(f))
    if pinched_out:
        assert pinched_in, pinched_out
        gap, _ = cKDTree(vi[pinched_in]).query(v[pinched_out])
        scale = np.linalg.norm(vi.max(0) - vi.min(0))
        assert gap.max() <= 1e-6 * scale, (gap, scale)
    assert pm["reoriented"] == 0 and poisson.orientation_consistent(scan["out"][1]), pm
    assert pm["duplicate_vertices"] == 0 and pm["null_faces"] == 0 and pm["duplicate_faces"] == 0, pm
    v, f = scan["out"]
    assert poisson.degenerate_triangles(v, f, float(np.linalg.norm(v.max(0) - v.min(0)))) == 0


def test_scan_loops(scan):
    rep = scan["report"]
    # meshtrim chains a pinched vertex's border edges in index order, so it
    # may split a loop the fan order keeps whole (bun045: 8 against 6).
    assert rep["loops_in"] >= scan["loops_in"], rep
    assert scan["loops_out"] <= scan["loops_in"]
    left = sum(len(x["loops"]) for x in rep["loops_left"])
    assert rep["loops_smoothed"] + rep["loops_too_small"] + left == rep["loops_in"], rep
    assert all(x["reason"] for x in rep["loops_left"]), rep
    assert rep["faces_out"] == len(scan["out"][1]), rep


def loop_length(v, loop):
    p = v[loop]
    return float(np.linalg.norm(p - np.roll(p, -1, axis=0), axis=1).sum())


def outer_border(v, f):
    """The longest border loop: a single-view scan's silhouette."""
    return max(poisson.fan_boundary_loops(f), key=lambda lp: loop_length(v, lp))


def test_scan_outer_border_replaced_and_shorter(scan):
    """The outer border (the silhouette, wrapping round the object) is
    replaced: none of its input vertices is on the output's border, the
    smoothed border is shorter than the jagged one (by 5 % at least, but on
    Laurana50k, whose border is far less jagged), and it turns at most a
    third as much from one segment to the next (every scan)."""
    (iv, if_), (ov, of) = scan["in"], scan["out"]
    outer_in = outer_border(iv, if_)
    on_border = {tuple(x) for x in ov[poisson.boundary_edges(of).ravel()].astype(np.float32)}
    still = sum(tuple(x) in on_border for x in iv[outer_in].astype(np.float32))
    assert still == 0, (scan["name"], still, len(outer_in))
    outer_out = outer_border(ov, of)
    ratio = loop_length(ov, outer_out) / loop_length(iv, outer_in)
    assert ratio <= OUTER_SHRINK.get(scan["name"], 0.95), (scan["name"], ratio)
    turn_in, turn_out = median_turning(iv, outer_in), median_turning(ov, outer_out)
    assert turn_out <= 0.35 * turn_in, (scan["name"], turn_in, turn_out)


def median_turning(v, loop):
    """Median angle (degrees) between consecutive segments of a loop: a
    sawtooth border turns by tens of degrees at every vertex, a smooth one
    by a few. Measured on the outer borders, in -> out: face000 33.9 -> 9.5,
    lato000 36.7 -> 8.7, Laurana50k 16.5 -> 4.2, bun000 55.6 -> 10.5,
    bun045 50.1 -> 10.1, bun090 51.8 -> 11.7, chin 48.8 -> 10.1."""
    p = v[loop]
    a = np.roll(p, -1, axis=0) - p
    b = np.roll(a, -1, axis=0)
    cos = (a * b).sum(1) / (np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1))
    return float(np.median(np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))))


def test_scan_big_loops_replaced(scan):
    """Every loop of 8 vertices or more is replaced (bun090: as measured),
    and a loop left says why."""
    rep = scan["report"]
    left = [n for x in rep["loops_left"] for n in x["vertices"]]
    assert len(left) == sum(len(x["loops"]) for x in rep["loops_left"]), rep
    assert sum(n >= 8 for n in left) <= BIG_LOOPS_LEFT.get(scan["name"], 0), rep["loops_left"]


def test_big_loops_replaced_over_all_scans(tmp_path_factory):
    """At least 90 % of the loops of 8 vertices or more, over the seven
    real scans (measured: 62 of 65)."""
    big = left = 0
    for name in REAL:
        s = clean_scan(name, tmp_path_factory)
        big += sum(len(lp) >= 8 for lp in poisson.fan_boundary_loops(s["in"][1]))
        left += sum(n >= 8 for x in s["report"]["loops_left"] for n in x["vertices"])
    assert big - left >= 0.9 * big, (big, left)


def new_face_angles(scan):
    """Smallest angle (degrees) of each output face with a vertex that is
    not an input vertex: faces the cleanup made. (Faces of input vertices
    only are not compared with the input's faces: PyMeshLab triangulates
    the bunny's range grid differently from meshtrim.) Coordinates are
    compared in single precision: PyMeshLab reads ASCII PLY as floats,
    meshtrim as doubles."""
    (iv, _), (ov, of) = scan["in"], scan["out"]
    old = {tuple(v) for v in iv.astype(np.float32)}
    fresh = np.array([tuple(v) not in old for v in ov.astype(np.float32)])
    p = ov[of[fresh[of].any(1)]]
    angles = []
    for k in range(3):
        a, b = p[:, (k + 1) % 3] - p[:, k], p[:, (k + 2) % 3] - p[:, k]
        c = (a * b).sum(1) / np.linalg.norm(a, axis=1) / np.linalg.norm(b, axis=1)
        angles.append(np.degrees(np.arccos(np.clip(c, -1, 1))))
    return np.min(angles, 0)


SILHOUETTE_STRIPS = {"bun000", "bun045", "bun090", "chin"}
"""The bunny's range scans, whose outer borders are replaced by strips
along a silhouette where the range grid zig-zags in depth."""


# Meshes round whole objects, open at their base; the others are range
# scans seen from one side.
WRAPS_ROUND = {"Laurana50k"}


def test_scan_wrapping_round_is_told_from_one_side(scan):
    """`clean` warns that a mesh wraps round an object (it may be an
    envelope cut open, to be trimmed with its cloud instead) when no
    direction sees 85 % of its area. Measured: the range scans 0.944
    (bun090, whose silhouette's faces turn past 90 degrees) to 1.0,
    Laurana50k 0.758, the zippered bunny 0.545."""
    share = scan["report"]["area_facing_one_way"]
    if scan["name"] in WRAPS_ROUND:
        assert share < 0.85, share
    else:
        assert share >= 0.85, share


def pymeshlab_vertex_hausdorff(sampled, target):
    """PyMeshLab's Hausdorff distance from every vertex of the faces of
    the mesh in file `sampled` to the surface of the mesh in file `target` (vertex
    sampling only, no distance limit): (max, mean over all vertices,
    vertices sampled, the target's bounding diagonal)."""
    import pymeshlab

    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(sampled))
    # A vertex in no face is no part of the surface (meshtrim does not
    # measure it): Laurana50k has 2,735.
    ms.meshing_remove_unreferenced_vertices()
    ms.load_new_mesh(str(target))
    r = ms.get_hausdorff_distance(
        sampledmesh=0,
        targetmesh=1,
        samplevert=True,
        sampleedge=False,
        sampleface=False,
        samplenum=ms.mesh(0).vertex_number(),
        maxdist=pymeshlab.PercentageValue(100),
    )
    return r["max"], r["mean"], r["n_samples"], r["diag_mesh_1"]


def open3d_vertex_deviation(vertices, faces, surface_vertices, surface_faces):
    """Open3D's exact distances (its ray-casting scene's closest point)
    from the vertices of `faces` that are not at a vertex of the surface
    to the surface's faces: (distances, their vertices)."""
    import open3d as o3d

    used = np.zeros(len(vertices), bool)
    used[np.asarray(faces).ravel()] = True
    on_surface = set(map(tuple, np.asarray(surface_vertices)))
    measured = np.array([i for i in np.flatnonzero(used) if tuple(vertices[i]) not in on_surface])
    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(
        o3d.core.Tensor(np.asarray(surface_vertices, dtype=np.float32)),
        o3d.core.Tensor(np.asarray(surface_faces, dtype=np.uint32)),
    )
    query = o3d.core.Tensor(np.asarray(vertices, dtype=np.float32)[measured])
    return scene.compute_distance(query).numpy().astype(np.float64), measured


def test_scan_deviations_are_open3ds_and_pymeshlabs(scan):
    """The report's two deviations (the scan's removed vertices against
    the cleaned surface, the cleaned mesh's new vertices against the
    scan), both ways, against two other implementations:

    - Open3D's closest-point distances of the same vertices (those of
      faces, not at a vertex of the other mesh; found here with NumPy):
      the same count, largest distance, its vertex and mean, to the
      float32 Open3D works in (1e-6 of the diagonal).
    - PyMeshLab's Hausdorff filter sampling every vertex (its mean taken
      over all of them, the vertices on the other surface at 0): within
      2 %. MeshLab's closest-point search can miss the closest face: on
      bun045 it puts a removed vertex 0.0015434 from the output, where
      Open3D and meshtrim find a face 0.0015158 away.

    Measured: face000 removes vertices up to 12.64 mm from the output and
    puts new ones up to 13.08 mm off the scan (the smoothed border cuts
    off a notch's corner and bridges another); the bunny's scans move by
    at most 2-5.6 mm."""
    import meshtrim

    rep = scan["report"]
    src, out = scan["src"], scan["out_path"]
    # As meshtrim read them: PyMeshLab reads the bunny's ASCII floats
    # rounded to float32, so that no input vertex would be an output one.
    (iv, if_), (ov, of) = meshtrim.read_mesh(src), meshtrim.read_mesh(out)
    directions = [
        ("input_to_output", (iv, if_, ov, of), (src, out)),
        ("output_to_input", (ov, of, iv, if_), (out, src)),
    ]
    for key, meshes, files in directions:
        ours = rep[key]
        distances, measured = open3d_vertex_deviation(*meshes)
        diagonal = np.linalg.norm(np.ptp(meshes[2], axis=0))
        tolerance = 1e-6 * diagonal
        assert ours["vertices"] == len(measured) > 0, (scan["name"], key, ours, len(measured))
        assert abs(ours["max"] - distances.max()) <= tolerance, (scan["name"], key, ours, distances.max())
        assert abs(ours["mean"] - distances.mean()) <= tolerance, (scan["name"], key, ours, distances.mean())
        farthest = meshes[0][measured[np.argmax(distances)]]
        assert np.allclose(ours["at"], farthest, rtol=0, atol=tolerance), (ours["at"], farthest)
        pm_max, pm_mean, samples, _ = pymeshlab_vertex_hausdorff(*files)
        assert abs(pm_max - ours["max"]) <= 0.02 * ours["max"] + tolerance, (scan["name"], key, ours, pm_max)
        pm_mean_measured = pm_mean * samples / ours["vertices"]
        assert abs(pm_mean_measured - ours["mean"]) <= 0.02 * ours["mean"] + tolerance, (key, ours, pm_mean)
        print(f"\n{scan['name']} {key}: max {ours['max']:.5g}, mean {ours['mean']:.5g} over {ours['vertices']}; PyMeshLab max {pm_max:.5g}")


# The bound given to `clean --max-deviation` on the real scans: 1 mm on
# the MeshLab scans (in mm), 1 mm on the bunny's (in metres).
HELD_TO = {"face000": 1.0, "lato000": 1.0, "Laurana50k": 1.0, "bun000": 0.001, "bun045": 0.001, "bun090": 0.001, "chin": 0.001}


@pytest.mark.parametrize("name", sorted(REAL))
def test_scan_max_deviation_holds_the_new_border(name, tmp_path, tmp_path_factory):
    """With --max-deviation D, every new vertex lies within D of the
    scan's surface (Open3D's closest points), the new border's and the
    points the silhouettes' strips add when they refine thin faces alike,
    the output is as valid as without it, and at most one more loop is
    left (chin: a 4-vertex hole). Measured at D = 1 mm (face000's new
    border up to 13.08 mm off the scan without it): the new vertices at
    1 mm at most (the strips' points up to 4.8 mm off before they were
    held too); removed vertices up to 2.30 (face000: a one-face spike the
    edge reconstruction steps over), 1.00, 1.15 mm on the MeshLab
    scans."""
    import meshtrim

    free = clean_scan(name, tmp_path_factory)
    bound = HELD_TO[name]
    src, out, report = shared_data(REAL[name]), tmp_path / "held.ply", tmp_path / "r.json"
    run_meshtrim("clean", src, out, "--max-deviation", bound, "--report", report)
    rep = json.loads(report.read_text())
    assert rep["max_deviation"] == bound and rep["vertices_held"] > 0, rep
    assert rep["loops_smoothed"] >= free["report"]["loops_smoothed"] - 1, (rep["loops_smoothed"], free["report"]["loops_smoothed"])
    (iv, if_), (ov, of) = meshtrim.read_mesh(src), meshtrim.read_mesh(out)
    edges = np.sort(np.concatenate([of[:, [0, 1]], of[:, [1, 2]], of[:, [2, 0]]]), axis=1)
    unique, count = np.unique(edges, axis=0, return_counts=True)
    border = np.unique(unique[count == 1])
    in_input = set(map(tuple, iv))
    new = np.array([v for v in range(len(ov)) if tuple(ov[v]) not in in_input])
    new_border = np.intersect1d(new, border)
    assert len(new_border) > 0 and len(new) > len(new_border)
    # The new vertices against the scan: the vertices of a one-vertex
    # "mesh" each, so that all are measured.
    distances, _ = open3d_vertex_deviation(ov[new], np.arange(len(new))[:, None].repeat(3, 1), iv, if_)
    diagonal = np.linalg.norm(np.ptp(iv, axis=0))
    assert distances.max() <= bound + 1e-6 * diagonal, (name, distances.max(), bound)
    assert rep["output_to_input"]["max"] <= bound + 1e-6 * diagonal, rep
    pm = poisson.pymeshlab_validity(ov, of)
    assert pm["non_manifold_edges"] == 0 and pm["reoriented"] == 0, pm
    assert pm["null_faces"] == 0 and pm["duplicate_faces"] == 0, pm
    print(f"\n{name} held to {bound}: new vertices max {distances.max():.5g}, report {rep['input_to_output']['max']:.5g} / {rep['output_to_input']['max']:.5g}")


SELF_CROSSINGS_ADDED = {
    # name: faces PyMeshLab finds self-intersecting in the output beyond
    # those of the input, measured: bun045 2 -> 8, two faces on consecutive
    # segments of the smoothed loop, which itself folds in depth there (no
    # wall vertex is in them), and four where the strip still folds after
    # its last remaking.
    # With the strips not made again where they fold over themselves: 4,
    # 18 and 11 on bun000, bun045 and chin; with the kept faces they pass
    # through not taken in either: 36, 167, 5 and 99 on bun000, bun045,
    # bun090, chin.
    "bun045": 6,
}


def test_scan_cleanup_adds_few_self_crossings(scan):
    """The cleaned scan intersects itself (PyMeshLab's "Select
    Self-Intersecting Faces") in no more faces than the scan did, beyond
    the measured remainder on the bunny's silhouettes above: a strip from
    the smoothed loop to a wall several spacings behind it, across the
    range grid's skirts, passed through the kept surface or folded over
    itself; the kept faces it passes through, and the wall's vertices at
    its folds, go with the cut, and the strip is made again."""
    import pymeshlab

    counts = []
    for path in [scan["src"], scan["out_path"]]:
        ms = pymeshlab.MeshSet()
        ms.load_new_mesh(str(path))
        ms.compute_selection_by_self_intersections_per_face()
        counts.append(ms.current_mesh().selected_face_number())
    added = counts[1] - counts[0]
    assert added <= SELF_CROSSINGS_ADDED.get(scan["name"], 0), (scan["name"], counts)


def test_zippered_bunny_is_warned_about(tmp_path):
    src = shared_data("stanford_bunny/bun_zipper.ply")
    out = run_meshtrim("clean", src, tmp_path / "out.ply").stdout
    assert "warning              the surface wraps round an object" in out, out
    assert "trim it with its cloud instead" in out, out


def test_scan_new_faces_are_rarely_thin(scan):
    """At most 0.5 % of the new faces (or 2) below 5 degrees, 2 % (or 4)
    below 10. Measured below 5 / 10 degrees: face000 12 / 76 of 7569,
    lato000 1 / 12 of 3349, Laurana50k 0 / 3 of 594 (where a smoothed
    border runs close along itself or another, the strip between them is
    thin whatever the triangulation); the synthetic cases have none below
    10.

    The bunny's silhouettes: the strip meets the range grid's own thin
    faces there (1.5-4.2 % of the input's faces are below 10 degrees, far
    more along the silhouette), where the kept mesh's new border lies
    several spacings behind the smoothed loop; the strip is refined in its
    unfolded plane, and about a third of what stays thin lies where the
    strip folds and cannot be refined: bun000 9 / 46 of 2585, bun045
    23 / 58 of 2487, bun090 39 / 86 of 2360, chin 29 / 78 of 2557 (96 /
    289, 168 / 332, 116 / 291, 180 / 351 unrefined). Bounds: 4 % below 5,
    8 % below 10."""
    angles = new_face_angles(scan)
    rep = scan["report"]
    # The report's smallest angle covers every new face.
    assert angles.min() >= rep["min_angle_new"] - 1e-6, (angles.min(), rep["min_angle_new"])
    assert len(angles) > 0, scan["name"]
    thin, very_thin = (angles < 10.0).sum(), (angles < 5.0).sum()
    if scan["name"] in SILHOUETTE_STRIPS:
        most_very_thin, most_thin = 0.04 * len(angles), 0.08 * len(angles)
    else:
        most_very_thin, most_thin = max(2, 0.005 * len(angles)), max(4, 0.02 * len(angles))
    assert very_thin <= most_very_thin and thin <= most_thin, (scan["name"], very_thin, thin, len(angles))


MIN_NEW_ANGLE = 1.0
"""The floor on the new faces' smallest angle, in degrees: below it a
face's normal is at the mercy of its vertices' rounding."""

SHORT_OF_THE_FLOOR = {
    # name: smallest new angle measured (degrees). Along the bunny's
    # silhouettes the range grid's skirts across depth jumps, and the slits
    # between them, have input edges 50-115 spacings long, which the new
    # faces beside them share or span: no triangulation keeping the input's
    # vertices avoids the needles there.
    "bun045": 0.46,
    "bun090": 0.44,
    "chin": 0.95,
}


@pytest.mark.parametrize("name", sorted(REAL))
def test_scan_new_faces_have_a_floor(name, tmp_path_factory, request):
    """No new face below MIN_NEW_ANGLE. The product falls short of it on
    three of the bunny's scans: those are strict expected failures, so the
    suite says so, and turns red the day one of them passes (then the
    entry goes). face000's one face under it (0.29 degrees, where a hole's
    smoothed loop came within 0.017 spacings of the outer border's) went
    when loops that nearly touch were moved apart (now 1.47 degrees)."""
    if name in SHORT_OF_THE_FLOOR:
        request.applymarker(
            pytest.mark.xfail(strict=True, reason=f"smallest new angle {SHORT_OF_THE_FLOOR[name]} degrees")
        )
    scan = clean_scan(name, tmp_path_factory)
    assert new_face_angles(scan).min() >= MIN_NEW_ANGLE


# --------------------------------------------------------------------------
# A border that wraps round the object.


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_wrapped_cylinder_border_on_the_truth(seed, tmp_path):
    """A cylinder seen from the side, its part wrapping 110 degrees round
    each way (past both silhouettes), with a hole beside one silhouette:
    the jagged outer border is no height field over any plane. Both loops
    are replaced, the border lies within 0.25 spacings of the analytic rim
    on average (measured 0.120-0.137, from 0.297-0.378), the output is
    valid and its new faces are not thin (measured: smallest 16-26
    degrees)."""
    cloud = synthetic.wrapped_cylinder(1.5, seed)
    v, f, _ = jagged.jagged_mesh(cloud)
    ov, of, report = clean(tmp_path, "cylinder", v, f)
    assert report["loops_in"] == 2 and report["loops_smoothed"] == 2, report
    before, after = jagged.border_error(v, f, cloud), jagged.border_error(ov, of, cloud)
    assert after[0] <= 0.25 and after[0] < before[0], (before, after)
    pm = poisson.pymeshlab_validity(ov, of)
    assert pm["non_manifold_edges"] == 0 and pm["non_manifold_vertices"] == 0, pm
    assert pm["holes"] == 2 and pm["components"] == 1 and pm["reoriented"] == 0, pm
    assert pm["null_faces"] == 0 and pm["duplicate_faces"] == 0, pm
    assert report["min_angle_new"] >= 10.0, report


def pymeshlab_repair(path):
    """What PyMeshLab's "Remove Duplicate Faces" then "Repair non Manifold
    Edges" (by removing faces) remove from the mesh in `path`: (faces
    repeating another's corners, in either turn; faces taken off edges of
    three or more faces)."""
    import pymeshlab

    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(path))
    counts = [ms.current_mesh().face_number()]
    ms.meshing_remove_duplicate_faces()
    counts.append(ms.current_mesh().face_number())
    ms.meshing_repair_non_manifold_edges(method=0)
    counts.append(ms.current_mesh().face_number())
    return counts[0] - counts[1], counts[1] - counts[2]


@pytest.mark.parametrize("name", ["bun_zipper_res2", "bun_zipper_res3"])
def test_repair_removes_the_faces_pymeshlab_removes(name, tmp_path):
    """The zippered bunny's decimations have 150 and 140 edges of three or
    more faces once their repeated faces are dropped (the Stanford README
    warns that their topology is not kept): `clean` refuses them, naming
    `--repair`; with it the faces repeated in either turn (87 and 83: 6 and
    14 in the same turn, dropped by `clean` anyway, and 81 and 69 the other
    way) and then those on crowded edges (92 and 73, smallest first) go,
    face for face as many as PyMeshLab's "Remove Duplicate Faces" and
    "Repair non Manifold Edges" remove, and PyMeshLab finds the cleaned
    mesh manifold and oriented."""
    src = shared_data(f"stanford_bunny/{name}.ply")
    out, report = tmp_path / "out.ply", tmp_path / "r.json"
    refused = subprocess.run([str(MESHTRIM), "clean", str(src), str(out)], capture_output=True, text=True)
    assert refused.returncode == 1 and "clean with --repair" in refused.stderr, refused.stderr
    run_meshtrim("clean", src, out, "--repair", "--report", report)
    rep = json.loads(report.read_text())
    repeats = rep["repeated_faces_dropped"] + rep["double_sided_faces_removed"]
    assert rep["crowded_faces_removed"] > 50 and (repeats, rep["crowded_faces_removed"]) == pymeshlab_repair(src), rep
    v, f = read_mesh(out)
    pm = poisson.pymeshlab_validity(v, f)
    assert pm["non_manifold_edges"] == 0 and pm["reoriented"] == 0, pm
    assert pm["null_faces"] == 0 and pm["duplicate_faces"] == 0, pm
    assert rep["loops_smoothed"] > 0, rep


def test_a_double_sided_scan_keeps_one_side(tmp_path):
    """The fixture with every face written again the other way (a
    double-sided export): with `--repair` one copy of each goes and the
    scan is cleaned to the bytes of the fixture's own cleanup."""
    v, f = poisson.load_mesh(ROOT / "fixtures" / "meshes" / "blade_jagged.stl")
    double = tmp_path / "double.ply"
    synthetic.write_mesh_ply(double, v, np.vstack([f, f[:, [0, 2, 1]]]), double=True)
    single = tmp_path / "single.ply"
    synthetic.write_mesh_ply(single, v, f, double=True)
    outs = [tmp_path / "double_out.ply", tmp_path / "single_out.ply"]
    run_meshtrim("clean", double, outs[0], "--repair", "--report", tmp_path / "r.json")
    run_meshtrim("clean", single, outs[1])
    assert outs[0].read_bytes() == outs[1].read_bytes()
    rep = json.loads((tmp_path / "r.json").read_text())
    assert rep["double_sided_faces_removed"] == len(f) and rep["crowded_faces_removed"] == 0, rep


def test_fan_boundary_loops_split_pinched_vertices():
    """Two triangles touching at one vertex: two loops, whatever the order;
    a flipped face and a duplicated vertex are caught by the checks."""
    f = np.array([[0, 1, 2], [0, 3, 4]])
    assert len(poisson.fan_boundary_loops(f)) == 2
    assert len(poisson.fan_boundary_loops(f[::-1])) == 2
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0], [2, 0, 0]], float)
    v2 = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
    quad = np.array([[0, 1, 2], [0, 2, 3]])
    assert poisson.pymeshlab_validity(v2, quad)["reoriented"] == 0
    assert poisson.pymeshlab_validity(v2, np.array([[0, 1, 2], [0, 3, 2]]))["reoriented"] == 1
    dup = np.vstack([v2, v2[:1]])
    assert poisson.pymeshlab_validity(dup, np.array([[0, 1, 2], [4, 2, 3]]))["duplicate_vertices"] == 1
    assert poisson.pymeshlab_validity(v, np.array([[0, 1, 4], [0, 1, 2]]))["null_faces"] == 1


# Crops (scripts/soak.py's: crops.crop with the generator seeded
# [seed, the scan's place in REAL_MESHES]) whose outer border was once left.
# face000 100 and 106: a hole's strip took the place of the planar patch
# replacing the outer border with its neighbouring holes; face000 104 and
# 107: that patch lay on kept faces beside another hole (the projection
# folds there) and the safety net dropped it whole; face000 127, Laurana50k
# 123, bun000 107 (the strip's wall "does not close") and face000 102, chin
# 111 ("doubles back"): the wall's vertices, placed along the smoothed loop
# by following the nearest segment, lost it where the crop's cut runs
# across a bay of the loop; bun090 105: the outer border's cut ran into a
# hole the planar way had replaced, and its wall did not close.
CROPS_OUTER_BORDER = [
    ("face000", 100),
    ("face000", 104),
    ("face000", 106),
    ("face000", 107),
    ("face000", 102),
    ("face000", 127),
    ("Laurana50k", 123),
    ("bun000", 107),
    ("chin", 111),
    ("bun090", 105),
]


def cropped_scan(name, seed):
    """soak.py's crop ``seed`` of the real scan ``name``."""
    v0, f0 = poisson.load_mesh(shared_data(REAL[name]))
    _, (v, f) = crops.crop(v0, f0, np.random.default_rng([seed, list(REAL).index(name)]))
    return v, f


@pytest.mark.parametrize("name,seed", CROPS_OUTER_BORDER)
def test_a_cropped_scan_keeps_its_outer_border_replaced(tmp_path, name, seed):
    """The outer border of a cropped scan is replaced: a strip takes the
    place of a planar patch only for a border at least as long as the
    patch's, a planar group whose patch breaks the manifold is replaced
    again without the loops where it breaks, the wall is aligned with the
    smoothed loop as a whole, and a cut reaching a hole another patch
    replaces lets that patch give way. Measured before: every one of these
    outer borders (458 to 2,545 vertices) left."""
    v, f = cropped_scan(name, seed)
    src, out, report_path = tmp_path / "crop.ply", tmp_path / "clean.ply", tmp_path / "report.json"
    synthetic.write_mesh_ply(src, v, f, double=True)
    run_meshtrim("clean", src, out, "--report", report_path)
    report = json.loads(report_path.read_text())
    longest_in = max(len(lp) for lp in poisson.fan_boundary_loops(f))
    left = [n for x in report["loops_left"] for n in x["vertices"]]
    assert longest_in > 400, longest_in
    assert all(n < 100 for n in left), (longest_in, left)
    pm_in, pm = poisson.pymeshlab_validity(v, f), poisson.pymeshlab_validity(*poisson.load_mesh(out))
    assert pm["non_manifold_edges"] == 0 and pm["reoriented"] == 0, pm
    assert pm["non_manifold_vertices"] <= pm_in["non_manifold_vertices"], (pm_in, pm)


# Punched crops whose holes lie a few faces from the outer border: the
# outer border's strip goes round them, and their own patches, which would
# touch the strip's faces, were left ("its new faces would reach those of
# another border": 27 and 20 vertices on bun000 114, 28 and 32 on chin 118,
# 50 and 42 on Laurana50k 101).
CROPS_HOLES_BESIDE_THE_STRIP = [("bun000", 114), ("chin", 118), ("Laurana50k", 101)]


@pytest.mark.parametrize("name,seed", CROPS_HOLES_BESIDE_THE_STRIP)
def test_holes_beside_a_strip_are_replaced_once_it_is_in(tmp_path, name, seed):
    """A loop blocked by another border's new faces is tried again on the
    mesh with those faces in: no loop of 8 or more vertices is left, and
    the output is valid."""
    v, f = cropped_scan(name, seed)
    src, out, report_path = tmp_path / "crop.ply", tmp_path / "clean.ply", tmp_path / "report.json"
    synthetic.write_mesh_ply(src, v, f, double=True)
    run_meshtrim("clean", src, out, "--report", report_path)
    report = json.loads(report_path.read_text())
    left = [(n, x["reason"]) for x in report["loops_left"] for n in x["vertices"] if n >= 8]
    assert not left, left
    pm_in, pm = poisson.pymeshlab_validity(v, f), poisson.pymeshlab_validity(*poisson.load_mesh(out))
    assert pm["non_manifold_edges"] == 0 and pm["reoriented"] == 0, pm
    assert pm["non_manifold_vertices"] <= pm_in["non_manifold_vertices"], (pm_in, pm)
    assert pm["null_faces"] == 0 and pm["duplicate_faces"] == 0, pm
