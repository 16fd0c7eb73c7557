"""Validation of the trimming command against PyMeshLab:
for each synthetic cloud (blade with three holes at 4 and 8 mm, notched
plate, curved disc with a hole) -> screened Poisson (PyMeshLab, normals from
compute_normal_for_point_clouds) -> `meshtrim MESH CLOUD OUT` -> checks on
the output:

- the output's boundary loops match the true loops in number;
- border -> true boundary: mean <= 0.3 spacings, max <= 2 spacings;
- output area within 3 % of the true area;
- no output vertex farther from the cloud than the true surface reaches
  (1 spacing inside; at convex corners the true boundary itself lies up to
  1.18 spacings from the nearest sample, measured on these clouds);
- edge-manifold, no degenerate triangles, orientation consistent, no
  duplicate vertices;
- the border is closer to the truth than the density-trimmed Poisson mesh
  (vertex quality below the 5 % and 10 % quantiles removed) on every case;
- the --report JSON describes the output.

Also the Stanford bunny (../shared/data/stanford_bunny/bun_zipper.ply):
its Poisson envelope closes the open base; trimming must open it again.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pymeshlab
import pytest
from scipy.spatial import cKDTree

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from meshtrim_cli import run_meshtrim, shared_data  # noqa: E402
import crops  # noqa: E402
import poisson  # noqa: E402
import synthetic  # noqa: E402

CASES = synthetic.VALIDATION_CASES


@pytest.fixture(scope="session", params=sorted(CASES))
def case(request, tmp_path_factory):
    """One synthetic case: cloud, its Poisson mesh, and meshtrim's output
    (built once per session; Poisson takes 5-20 s per case)."""
    cloud = CASES[request.param]()
    d = tmp_path_factory.mktemp(request.param)
    cloud_path = d / "cloud.ply"
    mesh_path = d / "poisson.ply"
    out_path = d / "trimmed.ply"
    report_path = d / "report.json"
    synthetic.write_cloud_ply(cloud_path, cloud.points, cloud.normals)
    v, f, q = poisson.reconstruct(cloud.points, depth=8)
    synthetic.write_mesh_ply(mesh_path, v, f, quality=q)
    run_meshtrim(mesh_path, cloud_path, out_path, "--report", report_path)
    verts, faces = synthetic.read_ply(out_path)
    out_v = np.stack([verts["x"], verts["y"], verts["z"]], axis=1)
    return {
        "name": request.param,
        "cloud": cloud,
        "poisson": (v, f, q),
        "out": (out_v, faces),
        "metrics": poisson.border_metrics(out_v, faces, cloud),
        "report": json.loads(report_path.read_text()),
    }


def test_loop_count(case):
    m = case["metrics"]
    assert m["loops"] == m["true_loops"], m


def test_border_distance(case):
    m = case["metrics"]
    assert m["border_mean"] <= 0.3, m
    assert m["border_max"] <= 2.0, m
    # Nothing of the true boundary left without a border near it.
    assert m["truth_to_border_max"] <= 2.0, m


def test_area(case):
    m = case["metrics"]
    assert abs(m["area_ratio"] - 1.0) <= 0.03, m


def truth_to_cloud_max(cloud) -> float:
    """How far the true boundary reaches from the samples, in spacings."""
    tree = poisson.cKDTree(cloud.points)
    d = np.concatenate([tree.query(np.asarray(loop))[0] for loop in cloud.loops])
    return float(d.max()) / cloud.spacing


def test_supported_by_cloud(case):
    limit = max(1.0, truth_to_cloud_max(case["cloud"]))
    assert case["metrics"]["max_vertex_to_cloud"] <= limit, (limit, case["metrics"])


def test_valid_mesh(case):
    v, f = case["out"]
    m = case["metrics"]
    assert m["edge_manifold"], m
    assert m["degenerate"] == 0, m
    assert poisson.orientation_consistent(f)
    # No duplicate vertices.
    assert len(np.unique(v, axis=0)) == len(v)


def test_beats_density_trimming(case):
    v, f, q = case["poisson"]
    cloud = case["cloud"]
    ours = case["metrics"]
    for quant in (0.05, 0.10):
        tv, tf = poisson.density_trim(v, f, q, quant)
        base = poisson.border_metrics(tv, tf, cloud)
        assert ours["border_mean"] < base["border_mean"], (quant, ours, base)
        assert ours["border_max"] < base["border_max"], (quant, ours, base)


def test_report(case):
    rep = case["report"]
    v, f = case["out"]
    assert rep["faces_out"] == len(f), rep
    assert rep["loops"] == case["metrics"]["true_loops"], rep
    assert abs(rep["area_out"] / case["metrics"]["area"] - 1.0) < 1e-6, rep
    assert rep["faces_in"] == len(case["poisson"][1]), rep
    # The output border runs along the smoothed loops it was cut on.
    h = case["cloud"].spacing
    for fit in rep["border_to_edge"]:
        assert fit["vertices"] > 0 and fit["mean"] <= 0.1 * h and fit["max"] <= 1.0 * h, rep


def mesh_area(vertices, faces):
    a = vertices[faces[:, 1]] - vertices[faces[:, 0]]
    b = vertices[faces[:, 2]] - vertices[faces[:, 0]]
    return 0.5 * float(np.linalg.norm(np.cross(a, b), axis=1).sum())


def poisson_trimmed(points, cloud, tmp_path, *options):
    """PyMeshLab's screened-Poisson mesh of ``points`` (depth 8), trimmed
    by meshtrim with ``cloud`` and ``options``: the Poisson faces, and the
    output's vertices and faces."""
    v, f, _ = poisson.reconstruct(points, depth=8)
    mesh_path = tmp_path / "poisson.ply"
    out_path = tmp_path / "trimmed.ply"
    synthetic.write_mesh_ply(mesh_path, v, f)
    run_meshtrim("trim", mesh_path, cloud, out_path, *options)
    ov, of = synthetic.read_ply(out_path)
    return f, np.stack([ov["x"], ov["y"], ov["z"]], axis=1), of


def loop_shapes(vertices, faces):
    """Each border loop's vertex count, centroid and length."""
    shapes = []
    for lp in poisson.boundary_loops(faces):
        p = vertices[lp]
        shapes.append((len(lp), p.mean(axis=0), float(np.linalg.norm(p - np.roll(p, -1, axis=0), axis=1).sum())))
    return shapes


def test_bunny_base_holes(tmp_path):
    bunny = shared_data("stanford_bunny/bun_zipper.ply")
    verts, scan_faces = synthetic.read_ply(bunny)
    pts = np.stack([verts["x"], verts["y"], verts["z"]], axis=1)
    f, out_v, of = poisson_trimmed(pts, bunny, tmp_path)
    # The five holes of the base (80, 42, 40, 39 and 22 border vertices,
    # SOURCES.md) are each back as a loop of the output: its centroid
    # within 5 mm of the hole's (the bunny is 155 mm across, the holes 10-36
    # mm wide) and its length 0.6-1.2 of the hole's jagged border (smoothed,
    # it is shorter: measured 0.69-0.90, and 1.11 where the smoothed loop
    # takes in a sparse spot beside the hole); each by a different loop.
    holes = loop_shapes(pts, np.asarray(scan_faces))
    assert sorted(n for n, _, _ in holes) == [22, 39, 40, 42, 80]
    out = loop_shapes(out_v, np.asarray(of))
    matched = set()
    for n, centre, length in holes:
        near = [i for i, (_, c, l) in enumerate(out) if np.linalg.norm(c - centre) <= 0.005 and 0.6 <= l / length <= 1.2]
        assert len(near) == 1, (n, [(out[i][0], out[i][2] / length) for i in near])
        matched.add(near[0])
    assert len(matched) == 5
    # Within 1.5 local spacings of the cloud (measured 1.24): no envelope
    # is left. The bound is local because the base is sampled about twice
    # as sparsely as the median; in median spacings the cut through a base
    # gap lies 1.95-2.13 away (docs/edges.md, "Limits").
    assert poisson.max_distance_in_local_spacings(out_v, pts) <= 1.5
    assert poisson.is_edge_manifold(of)
    # The rest of the scanned surface stays: the zippered mesh's own area
    # (holes and all). Removing every piece beyond the walls of the small
    # loops round sparse spots would cut away about 30 % of it (area ratio
    # 0.69); the support test keeps what the cloud covers.
    kept = mesh_area(out_v, np.asarray(of)) / mesh_area(pts, np.asarray(scan_faces))
    assert 0.97 <= kept <= 1.03, kept


def trimmed_scan(cloud, tmp_path, view):
    """A real scan's points and β (from `meshtrim detect`, with `view`),
    its PyMeshLab Poisson envelope's vertices, and the trimmed output."""
    points_path = tmp_path / "points.ply"
    run_meshtrim("detect", cloud, "-o", points_path, *view)
    verts, _ = synthetic.read_ply(points_path)
    pts = np.stack([verts["x"], verts["y"], verts["z"]], axis=1)
    beta = np.asarray(verts["beta"], dtype=float)
    v, f, _ = poisson.reconstruct(pts, depth=8)
    mesh_path, out_path = tmp_path / "poisson.ply", tmp_path / "trimmed.ply"
    synthetic.write_mesh_ply(mesh_path, v, f)
    run_meshtrim("trim", mesh_path, cloud, out_path, *view)
    ov, of = synthetic.read_ply(out_path)
    return pts, beta, v, np.stack([ov["x"], ov["y"], ov["z"]], axis=1), np.asarray(of)


def assert_within_reach_and_covering(pts, beta, envelope, out_v, uncovered=0.001):
    """The trim's contract on a scan whose border may not close: the kept
    surface ends at the cloud's reach, 2 β from the nearest point (the
    trim's `reach`), but for the smoothed cut half a row beyond it (at
    most 0.1 % of the vertices beyond 2.5 β) and spots under a disc of
    radius β that the cloud does not resolve (none beyond 4 β); and the
    scanned surface stays: every cloud point that the envelope covers (an
    envelope vertex within 2 local spacings) is covered by the output as
    well, but a share `uncovered` (0.1 %)."""
    tree = cKDTree(pts)
    d, nearest = tree.query(out_v)
    r = d / beta[nearest]
    assert (r > 2.5).mean() <= 0.001 and r.max() <= 4.0, ((r > 2.5).mean(), r.max())
    spacing = tree.query(pts, k=7)[0][:, 1:].mean(axis=1)
    by_envelope = cKDTree(envelope).query(pts)[0] <= 2.0 * spacing
    by_output = cKDTree(out_v).query(pts)[0] <= 2.0 * spacing
    assert (by_envelope & ~by_output).mean() <= uncovered, (by_envelope & ~by_output).mean()


def test_range_scan_trimmed_along_the_line_of_sight(tmp_path):
    """milk.pcd is a Kinect cloud in its camera's frame. Its Poisson mesh
    trimmed with the camera's view (--view-from 0,0,0) keeps the carton's
    scanned faces and nothing beyond the cloud's reach (measured: largest
    distance 2.11 β, 0.01 % of the vertices beyond 2 β). With the view its
    border is traced in the camera's image plane (docs/edges.md); by
    default, in its own best-fit plane, where it closes as well (largest
    distance 2.08 β, no point uncovered)."""
    milk = shared_data("pcl_test/milk.pcd")
    pts, beta, envelope, out_v, of = trimmed_scan(milk, tmp_path, ["--view-from", "0,0,0"])
    assert_within_reach_and_covering(pts, beta, envelope, out_v)
    assert poisson.is_edge_manifold(of)


def test_single_view_scan_trimmed_in_its_own_plane(tmp_path):
    """milk.pcd without a view: its ragged border, which BPD's links leave
    open, is traced in its own best-fit plane and closes, so the default
    trim keeps the carton's faces within the cloud's reach as the camera's
    view does (measured: largest distance 2.08 β, farthest vertex 2.0 local
    spacings, no point uncovered, 6 border loops)."""
    milk = shared_data("pcl_test/milk.pcd")
    pts, beta, envelope, out_v, of = trimmed_scan(milk, tmp_path, [])
    assert_within_reach_and_covering(pts, beta, envelope, out_v)
    assert poisson.is_edge_manifold(of)
    assert len(poisson.fan_boundary_loops(of)) <= 10


@pytest.mark.parametrize("scan", ["BladeScan1.csv", "BladeScan2.csv"])
@pytest.mark.parametrize("view", [[], ["--view-along", "0,0,1"]], ids=["default", "view"])
def test_kinect_blade_trim_stays_within_the_clouds_reach(tmp_path, scan, view):
    """The real Kinect scans of the blade-shaped panel, whose ragged
    borders BPD's links do not close. Traced in the image plane, their
    own best-fit plane's by default and the camera's along z, the borders
    close and the cut follows the smoothed outer loop (measured by default:
    largest distance 2.7 and 3.1 β, 0.004 % and 0.010 % of the vertices
    beyond 2.5 β; along z 2.3 and 3.1 β). Without the cut along the
    cloud's reach (2 β), the envelope beyond a border that stays open would
    stay, as it did by the links, up to 85 local spacings from the cloud
    (BladeScan2). The smoothed border passes inside the ragged band's
    farthest points: 0.10 % and 0.03 % of the points uncovered by default
    (42 and 13), 0.10 % and 0.01 % along z (42 and 5, border points 3.2
    spacings apart or more), held to 0.15 %."""
    cloud = shared_data(f"blade_scan_kinect/{scan}")
    pts, beta, envelope, out_v, of = trimmed_scan(cloud, tmp_path, view)
    assert_within_reach_and_covering(pts, beta, envelope, out_v, uncovered=0.0015)
    assert poisson.is_edge_manifold(of)


@pytest.fixture(scope="session", params=sorted(CASES))
def delaunay_case(request, tmp_path_factory):
    """One synthetic case meshed by the Delaunay path, `meshtrim mesh`."""
    cloud = CASES[request.param]()
    d = tmp_path_factory.mktemp(f"delaunay_{request.param}")
    cloud_path = d / "cloud.ply"
    out_path = d / "delaunay.ply"
    synthetic.write_cloud_ply(cloud_path, cloud.points, cloud.normals)
    run_meshtrim("mesh", cloud_path, out_path)
    verts, faces = synthetic.read_ply(out_path)
    out_v = np.stack([verts["x"], verts["y"], verts["z"]], axis=1)
    return {"cloud": cloud, "out": (out_v, faces), "metrics": poisson.border_metrics(out_v, faces, cloud)}


def test_delaunay_path(delaunay_case):
    m = delaunay_case["metrics"]
    v, f = delaunay_case["out"]
    assert m["loops"] == m["true_loops"], m
    assert m["border_mean"] <= 0.3 and m["border_max"] <= 2.0, m
    assert m["truth_to_border_max"] <= 2.0, m
    assert abs(m["area_ratio"] - 1.0) <= 0.03, m
    assert m["max_vertex_to_cloud"] <= max(1.0, truth_to_cloud_max(delaunay_case["cloud"])), m
    assert m["edge_manifold"] and m["degenerate"] == 0, m
    assert poisson.orientation_consistent(f)
    assert len(np.unique(v, axis=0)) == len(v)
    # No sliver: smallest angles measured 11.0, 10.5, 11.4 and 9.9° (4.4-5.7°
    # before the loops were evened out and points kept 0.3 β from them).
    assert smallest_angles(v, f).min() >= 8.0, smallest_angles(v, f).min()


def smallest_angles(v, f):
    """Each face's smallest angle, in degrees."""
    p = v[f]
    angles = []
    for k in range(3):
        a, b = p[:, (k + 1) % 3] - p[:, k], p[:, (k + 2) % 3] - p[:, k]
        cos = (a * b).sum(axis=1) / np.linalg.norm(a, axis=1) / np.linalg.norm(b, axis=1)
        angles.append(np.degrees(np.arccos(np.clip(cos, -1.0, 1.0))))
    return np.min(angles, axis=0)


REAL_DELAUNAY = {
    # name: (path, view options)
    "face000": ("meshlab_scans/face000.ply", []),
    "lato000": ("meshlab_scans/lato000.ply", []),
    "bun000": ("stanford_bunny/bun000.ply", ["--view-along", "0,0,1"]),
    "bun045": ("stanford_bunny/bun045.ply", ["--view-along", "0,0,1"]),
    "bun090": ("stanford_bunny/bun090.ply", ["--view-along", "0,0,1"]),
    "chin": ("stanford_bunny/chin.ply", ["--view-along", "0,0,1"]),
    # Through the border points themselves, loops touch at shared points.
    "face000 no offset": ("meshlab_scans/face000.ply", ["--no-offset"]),
    "bun000 no offset": ("stanford_bunny/bun000.ply", ["--view-along", "0,0,1", "--no-offset"]),
}


@pytest.mark.parametrize("scan", sorted(REAL_DELAUNAY))
def test_delaunay_path_on_real_range_scans(tmp_path, scan):
    """Real range scans meshed by the Delaunay path: the MeshLab range
    maps in their own best-fit plane, the bunny's scans in their scanner's
    image (along z; over their best-fit plane they fold). Some of their
    smoothed loops cross (small holes across the outer border, holes
    across each other; not on bun045 and bun090), or with `--no-offset`
    touch where they pass through the same border point: split there, the
    surface is kept by winding. In the image, the loops run along the
    occlusions without the half-row offset, and the faces that still span
    a depth jump where a nearer surface occludes a farther one are dropped.
    PyMeshLab finds each mesh valid (no non-manifold edge or vertex, no
    null, duplicate or misoriented face); every vertex lies within reach
    of the cloud (measured at most 1.79, 1.32, 1.33, 1.19, 1.14, 1.29 β for
    face000, lato000, bun000, bun045, bun090, chin: loop vertices half a
    row beyond the border points); and the mesh covers the cloud but for
    points beyond the loops (measured 0.21, 0.17, 0.21, 0.00, 0.37, 0.22 %
    farther than two spacings from every vertex; without the offset 4 and
    2 contacts, the same bounds). All eight were refused before the loops
    could cross, and bun090 until the faces across its occlusions went
    (1.1 % of its triangles stood on edge)."""
    rel, view = REAL_DELAUNAY[scan]
    cloud = shared_data(rel)
    points_path, out_path, report_path = tmp_path / "points.ply", tmp_path / "mesh.ply", tmp_path / "r.json"
    run_meshtrim("detect", cloud, "-o", points_path, *[a for a in view if a != "--no-offset"])
    verts, _ = synthetic.read_ply(points_path)
    pts = np.stack([verts["x"], verts["y"], verts["z"]], axis=1)
    beta = np.asarray(verts["beta"], dtype=float)
    run_meshtrim("mesh", cloud, out_path, "--report", report_path, *view)
    report = json.loads(report_path.read_text())
    if scan not in ("bun045", "bun090"):
        assert report["loop_crossings"] > 0, report
    assert report["loops_from"] == ("scanner_image" if "--view-along" in view else "own_plane"), report
    v, f = poisson.load_mesh(out_path)
    pm = poisson.pymeshlab_validity(v, f)
    assert pm["non_manifold_edges"] == 0 and pm["non_manifold_vertices"] == 0, pm
    assert pm["null_faces"] == 0 and pm["duplicate_faces"] == 0 and pm["reoriented"] == 0, pm
    assert pm["duplicate_vertices"] == 0, pm
    tree = cKDTree(pts)
    d, nearest = tree.query(v)
    assert (d / beta[nearest]).max() <= 4.0, (d / beta[nearest]).max()
    spacing = tree.query(pts, k=7)[0][:, 1:].mean(axis=1)
    uncovered = (cKDTree(v).query(pts)[0] > 2.0 * spacing).mean()
    assert uncovered <= 0.005, uncovered
    # Few slivers: faces under 5° are at most 0.046 % of the faces (0.04 to
    # 0.19 % before the loops were evened out and points kept 0.3 β from
    # them); the one under 1° (chin) lies where loops cross.
    assert (smallest_angles(v, f) < 5.0).mean() <= 0.001, (smallest_angles(v, f) < 5.0).mean()
    if "--view-along" in view:
        # Where a nearer surface occludes a farther one, no face spans the
        # depth jump: faces with an edge over 10 times the median hold
        # 0.00-0.03 % of the area (4.6, 5.3 and 6.7 % on bun000, bun045
        # and chin when those faces were kept; the files' own range grids
        # 6.9, 11.8 and 14.9 %).
        assert report["occlusion_faces_dropped"] > 0, report
        assert long_face_area_share(v, f, 10.0) <= 0.001, long_face_area_share(v, f, 10.0)


def long_face_area_share(v, f, times):
    """Share of the area in faces with an edge longer than `times` the
    median of the faces' longest edges."""
    p = v[f]
    longest = np.stack([np.linalg.norm(p[:, (k + 1) % 3] - p[:, k], axis=1) for k in range(3)], axis=1).max(axis=1)
    area = 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)
    return area[longest > times * np.median(longest)].sum() / area.sum()


# Samplings whose screened-Poisson mesh has zero-area triangles (tiny faces
# where marching cubes cuts a cell at a corner): 2 on blade4 seed 2, 2 on
# disc seed 3, 3 on blade4 seed 4.
DEGENERATE_POISSON = [("blade4", 2), ("disc", 3), ("blade4", 4)]


@pytest.mark.parametrize("name,seed", DEGENERATE_POISSON)
def test_no_zero_area_or_duplicate_face_out(tmp_path, name, seed):
    """The trimmed mesh has no zero-area and no duplicate face by
    PyMeshLab's own measures, whatever the Poisson mesh had, stays
    two-manifold and coherently oriented, and the report counts the
    repairs."""
    make = {"blade4": lambda s: synthetic.blade(4.0, s), "disc": lambda s: synthetic.curved_disc(1.5, s)}
    cloud = make[name](seed)
    cloud_path, mesh_path = tmp_path / "cloud.ply", tmp_path / "poisson.ply"
    out_path, report_path = tmp_path / "trimmed.ply", tmp_path / "report.json"
    synthetic.write_cloud_ply(cloud_path, cloud.points, cloud.normals)
    v, f, q = poisson.reconstruct(cloud.points, depth=8)
    scale = np.linalg.norm(v.max(0) - v.min(0))
    degenerate_in = poisson.degenerate_triangles(v, f, scale)
    assert degenerate_in > 0, "the case must exercise the repair"
    synthetic.write_mesh_ply(mesh_path, v, f, quality=q)
    run_meshtrim(mesh_path, cloud_path, out_path, "--report", report_path)
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(out_path))
    m = ms.current_mesh()
    ov, of = m.vertex_matrix(), m.face_matrix()
    area = 0.5 * np.linalg.norm(np.cross(ov[of[:, 1]] - ov[of[:, 0]], ov[of[:, 2]] - ov[of[:, 0]]), axis=1)
    diag = np.linalg.norm(ov.max(0) - ov.min(0))
    assert int(np.sum(area < 1e-12 * diag * diag)) == 0
    pm = poisson.pymeshlab_validity(ov, of)
    assert pm["null_faces"] == 0 and pm["duplicate_faces"] == 0, pm
    assert pm["non_manifold_edges"] == 0 and pm["reoriented"] == 0, pm
    report = json.loads(report_path.read_text())
    assert report["faces_repaired"] >= 1 and report["zero_area_faces_left"] == 0, report


# Ball crops of the bunny's range scans (crops.crop, ball, these seeds)
# whose trim with their own vertices as the cloud cuts the surface down to
# kept pieces that touch at one vertex: the range grid's slits and skirts
# leave pieces the support test drops between kept ones.
PINCHING_CROPS = [("bun090", 0), ("bun090", 2), ("chin", 0), ("chin", 3)]


@pytest.mark.parametrize("name,seed", PINCHING_CROPS)
def test_trim_leaves_no_vertex_pinched_that_the_input_was_not(tmp_path, name, seed):
    """Where kept pieces would touch at one vertex, the smaller piece's
    faces there go: the output has no pinched vertex (faces round it in
    more than one fan, counted by crops.pinched_vertices) but where the
    input had one, PyMeshLab counts no more non-manifold vertices than in
    the input, and the report counts the faces dropped. Without the step
    the four crops' trims had 3, 1, 3 and 1 new pinched vertices
    (PyMeshLab: non-manifold vertices 1 -> 4, 0 -> 1, 0 -> 3, 0 -> 1)."""
    v0, f0 = poisson.load_mesh(shared_data(f"stanford_bunny/{name}.ply"))
    _, (v, f) = crops.crop(v0, f0, np.random.default_rng(seed), "ball")
    mesh_path, cloud_path = tmp_path / "crop.ply", tmp_path / "cloud.ply"
    out_path, report_path = tmp_path / "trimmed.ply", tmp_path / "report.json"
    synthetic.write_mesh_ply(mesh_path, v, f, double=True)
    synthetic.write_cloud_ply(cloud_path, v)
    run_meshtrim(mesh_path, cloud_path, out_path, "--report", report_path)
    report = json.loads(report_path.read_text())
    assert report["pinch_faces_dropped"] > 0, "the case must exercise the step"
    ov, of = poisson.load_mesh(out_path)
    pinched_in = {tuple(v[i]) for i in crops.pinched_vertices(f)}
    new = [tuple(ov[i]) for i in crops.pinched_vertices(of) if tuple(ov[i]) not in pinched_in]
    assert not new, new
    pm_in, pm = poisson.pymeshlab_validity(v, f), poisson.pymeshlab_validity(ov, of)
    assert pm["non_manifold_vertices"] <= pm_in["non_manifold_vertices"], (pm_in, pm)
    assert pm["non_manifold_edges"] == 0 and pm["reoriented"] == 0, pm
    assert pm["null_faces"] == 0 and pm["duplicate_faces"] == 0, pm
