"""The Python package (python/, installed into the test venv by
scripts/test.sh) against the CLI on the same inputs: identical arrays,
labels and bytes, not "close"; the adapters on real PyMeshLab, Open3D and
trimesh objects; bad inputs raising MeshtrimError; the GIL released; the
Dask example on a LocalCluster."""

from __future__ import annotations

import csv
import json
import shutil
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import meshtrim
from meshtrim_cli import MESHTRIM, NOT_RESULTS, ROOT, results, run_meshtrim, shared_data

FIXTURES = ROOT / "fixtures" / "meshes"
CLOUD = FIXTURES / "blade_small.ply"
POISSON = FIXTURES / "blade_small_poisson.ply"
HOLES = FIXTURES / "blade_holes.ply"
JAGGED = FIXTURES / "blade_jagged.stl"

def cli_json(*args) -> dict:
    return json.loads(run_meshtrim(*args, "--json").stdout)


def cli_error(*args) -> str:
    r = subprocess.run([str(MESHTRIM), *map(str, args)], capture_output=True, text=True, timeout=120)
    assert r.returncode == 1, (r.stdout, r.stderr)
    return r.stderr.strip().removeprefix("error: ")


def raises(call, *args, **kwargs) -> str:
    with pytest.raises(meshtrim.MeshtrimError) as caught:
        call(*args, **kwargs)
    return str(caught.value)


# --- the same results as the CLI ---------------------------------------


def test_detect_equals_the_cli(tmp_path):
    out = tmp_path / "labels.csv"
    summary = cli_json("detect", HOLES, "-o", out)
    with open(out) as f:
        rows = list(csv.DictReader(f))
    points = meshtrim.read_cloud(HOLES)
    d = meshtrim.detect(points)
    cli_xyz = np.array([[float(r[c]) for c in "xyz"] for r in rows])
    assert np.array_equal(cli_xyz, points)
    assert np.array_equal(np.array([r["boundary"] == "1" for r in rows]), d.boundary)
    assert np.array_equal(np.array([float(r["beta"]) for r in rows]), d.beta)
    assert d.boundary.dtype == bool and d.beta.dtype == np.float64
    assert set(d.summary) == set(summary)
    assert results(d.summary) == results(summary)
    assert d.boundary_points == summary["boundary_points"] == int(d.boundary.sum())


def test_edges_equal_the_cli_json(tmp_path):
    out = tmp_path / "edges.json"
    summary = cli_json("edges", HOLES, "-o", out)
    cli = json.loads(out.read_text())["loops"]
    loops = meshtrim.edges(meshtrim.read_cloud(HOLES))
    assert len(loops) == len(cli) == summary["loops"] == 4
    for ours, theirs in zip(loops, cli):
        assert ours.closed == theirs["closed"]
        assert ours.boundary_points.tolist() == theirs["boundary_points"]
        assert np.array_equal(ours.corners, np.array(theirs["corners"]).reshape(-1, 3))
        assert len(ours.edges) == len(theirs["edges"])
        for edge, cli_edge in zip(ours.edges, theirs["edges"]):
            assert edge.closed == cli_edge["closed"]
            assert np.array_equal(edge.points, np.array(cli_edge["points"]))
    assert results(loops.summary) == results(summary)
    assert sum(len(l.edges) for l in loops) == summary["edges"]


@pytest.mark.parametrize("ext", ["ply", "obj", "stl", "gltf", "glb"])
def test_trim_writes_the_cli_bytes(tmp_path, ext):
    cli_out, report_file = tmp_path / f"cli.{ext}", tmp_path / "r.json"
    run_meshtrim(POISSON, CLOUD, cli_out, "--report", report_file)
    cli_report = json.loads(report_file.read_text())
    vertices, faces, attributes = meshtrim.read_mesh(POISSON, attributes=True)
    out_v, out_f, report = meshtrim.trim(vertices, faces, meshtrim.read_cloud(CLOUD))
    ours = tmp_path / f"py.{ext}"
    # The fixture's screened Poisson has its density as `float quality`.
    written, not_written = meshtrim.write_mesh_carrying(ours, out_v, out_f, vertices, faces, attributes)
    assert ours.read_bytes() == cli_out.read_bytes()
    assert written == cli_report.get("vertex_attributes", []), written
    assert not_written == cli_report.get("vertex_attributes_not_written", []), not_written
    assert written + not_written == ["quality"]
    assert set(report) == set(cli_report) - NOT_RESULTS | set(report) & NOT_RESULTS
    assert results(report) == results(cli_report)
    assert report["mesh"] is None and report["read_ms"] == 0.0
    assert report["faces_out"] == len(out_f) < report["faces_in"]
    if ext == "ply":  # float64 PLY: the arrays themselves read back
        back_v, back_f = meshtrim.read_mesh(cli_out)
        assert np.array_equal(back_v, out_v) and np.array_equal(back_f, out_f)


def test_mesh_equals_the_cli(tmp_path):
    cli_out, report_file = tmp_path / "cli.ply", tmp_path / "r.json"
    run_meshtrim("mesh", HOLES, cli_out, "--report", report_file)
    out_v, out_f, report = meshtrim.mesh(meshtrim.read_cloud(HOLES))
    back_v, back_f = meshtrim.read_mesh(cli_out)
    assert np.array_equal(back_v, out_v) and np.array_equal(back_f, out_f)
    assert results(report) == results(json.loads(report_file.read_text()))


def test_mesh_of_a_range_scan_in_its_scanner_image_equals_the_cli(tmp_path):
    """bun000 meshed in its scanner's image, where its smoothed loops
    cross and are resolved by winding: the same mesh from Python."""
    scan = shared_data("stanford_bunny/bun000.ply")
    cli_out, report_file = tmp_path / "cli.ply", tmp_path / "r.json"
    run_meshtrim("mesh", scan, cli_out, "--report", report_file, "--view-along", "0,0,1")
    out_v, out_f, report = meshtrim.mesh(meshtrim.read_cloud(scan), view_along=(0, 0, 1))
    back_v, back_f = meshtrim.read_mesh(cli_out)
    assert np.array_equal(back_v, out_v) and np.array_equal(back_f, out_f)
    assert results(report) == results(json.loads(report_file.read_text()))
    assert report["loop_crossings"] > 0 and report["loops_from"] == "scanner_image", report


def test_clean_equals_the_cli(tmp_path):
    cli_out, report_file = tmp_path / "cli.ply", tmp_path / "r.json"
    run_meshtrim("clean", JAGGED, cli_out, "--report", report_file)
    vertices, faces = meshtrim.read_mesh(JAGGED)
    out_v, out_f, report = meshtrim.clean(vertices, faces)
    back_v, back_f = meshtrim.read_mesh(cli_out)
    assert np.array_equal(back_v, out_v) and np.array_equal(back_f, out_f)
    cli_report = json.loads(report_file.read_text())
    assert set(report) == set(cli_report)
    assert results(report) == results(cli_report)
    assert report["loops_smoothed"] > 0


def test_clean_with_repair_equals_the_cli(tmp_path):
    """A mesh with every fifth face wound the wrong way: refused without
    ``repair`` (the message names it, in the library's words), cleaned
    with it to the CLI's ``--repair`` bytes."""
    vertices, faces = meshtrim.read_mesh(JAGGED)
    faces = faces.copy()
    faces[::5] = faces[::5, [0, 2, 1]]
    wrong = tmp_path / "wrong.ply"
    meshtrim.write_mesh(wrong, vertices, faces)
    assert "clean with repair on" in raises(meshtrim.clean, vertices, faces)
    assert "clean with --repair" in cli_error("clean", wrong, tmp_path / "o.ply")
    cli_out, report_file = tmp_path / "cli.ply", tmp_path / "r.json"
    run_meshtrim("clean", wrong, cli_out, "--repair", "--report", report_file)
    out_v, out_f, report = meshtrim.clean(vertices, faces, repair=True)
    back_v, back_f = meshtrim.read_mesh(cli_out)
    assert np.array_equal(back_v, out_v) and np.array_equal(back_f, out_f)
    assert results(report) == results(json.loads(report_file.read_text()))
    assert report["faces_flipped"] == len(faces[::5])
    # Turned back, the faces are the fixture's: so is the output.
    right_v, right_f, _ = meshtrim.clean(vertices, meshtrim.read_mesh(JAGGED)[1])
    assert np.array_equal(right_v, out_v) and np.array_equal(right_f, out_f)


def test_options_reach_the_library():
    points = meshtrim.read_cloud(HOLES)
    cli = cli_json("detect", HOLES, "--k", 20, "--no-anisotropy", "--view-along", "0,0.2,1")
    d = meshtrim.detect(points, k=20, anisotropy=False, view_along=(0, 0.2, 1))
    assert results(d.summary) == results(cli)
    plain = meshtrim.detect(points)
    assert d.summary["k"] == 20 and not np.array_equal(d.beta, plain.beta)
    no_offset = meshtrim.edges(points, offset=False)
    assert no_offset.summary["offset"] is False
    assert not np.array_equal(no_offset[0].edges[0].points, meshtrim.edges(points)[0].edges[0].points)


def test_any_layout_and_dtype_gives_the_same_result():
    vertices, faces = meshtrim.read_mesh(POISSON)
    points = meshtrim.read_cloud(CLOUD)
    reference = meshtrim.trim(vertices, faces, points)
    variants = [
        (np.asfortranarray(vertices), faces.astype(np.int32), np.asfortranarray(points)),
        (vertices.tolist(), faces.astype(np.uint32)[:, :], points[::1].copy(order="F")),
        (np.hstack([vertices, vertices])[:, :3], np.hstack([faces, faces])[:, 3:], np.ascontiguousarray(points)),
    ]
    for v, f, p in variants:
        out_v, out_f, _ = meshtrim.trim(v, f, p)
        assert np.array_equal(out_v, reference[0]) and np.array_equal(out_f, reference[1])
    # float32 input is widened exactly: the same as the widened array.
    p32 = points.astype(np.float32)
    assert np.array_equal(meshtrim.detect(p32).beta, meshtrim.detect(p32.astype(np.float64)).beta)


def test_results_do_not_depend_on_the_thread_count():
    code = (
        "import sys, meshtrim; d = meshtrim.detect(meshtrim.read_cloud(sys.argv[1]));"
        "sys.stdout.buffer.write(d.boundary.tobytes() + d.beta.tobytes())"
    )
    outputs = set()
    for threads in ["1", "2", "3"]:
        env = {"RAYON_NUM_THREADS": threads, "PATH": "/usr/bin:/bin"}
        r = subprocess.run([sys.executable, "-c", code, str(HOLES)], capture_output=True, env=env, timeout=120, check=True)
        outputs.add(r.stdout)
    d = meshtrim.detect(meshtrim.read_cloud(HOLES))
    assert outputs == {d.boundary.tobytes() + d.beta.tobytes()}


# --- bad inputs raise MeshtrimError --------------------------------------


def test_error_is_a_value_error():
    assert issubclass(meshtrim.MeshtrimError, ValueError)
    assert meshtrim.MeshtrimError.__module__ == "meshtrim"


@pytest.mark.parametrize(
    "points, words",
    [
        (np.zeros((0, 3)), "no points"),
        (np.zeros((10, 3)), "on one point"),
        (np.zeros((10, 2)), "shape (n, 3)"),
        (np.zeros(30), "shape (n, 3)"),
        (np.zeros((4, 3, 1)), "shape (n, 3)"),
        (np.array([["a", "b", "c"]]), "real numbers"),
        ([[1, 2, 3], [4, 5]], "not an array of numbers"),
        (None, "real numbers"),
        (np.array([[0.0, 0.0, np.nan]] * 40), "non-finite"),
        (np.array([[0.0, np.inf, 0.0]] * 40), "non-finite"),
        (np.c_[np.arange(500.0), np.zeros(500), np.zeros(500)].astype(np.float32), "line"),
        (np.random.default_rng(1).random((12, 3)), "lower k"),
    ],
)
def test_bad_points_raise(points, words):
    for call in (meshtrim.detect, meshtrim.edges, meshtrim.mesh):
        message = raises(call, points)
        assert words in message, message
        assert message.startswith("points") or words in ("no points",), message


def test_bad_options_raise():
    points = meshtrim.read_cloud(CLOUD)
    assert "k = 3" in raises(meshtrim.detect, points, k=3)
    assert "whole number" in raises(meshtrim.detect, points, k=-1)
    assert "whole number" in raises(meshtrim.detect, points, k=2.5)
    assert "not both" in raises(meshtrim.detect, points, view_along=(0, 0, 1), view_from=(0, 0, 5))
    assert "zero" in raises(meshtrim.detect, points, view_along=(0, 0, 0))
    assert "three numbers" in raises(meshtrim.detect, points, view_from=(1, 2))
    assert "not finite" in raises(meshtrim.detect, points, view_from=(1, 2, np.nan))


def test_bad_meshes_raise(tmp_path):
    vertices, faces = meshtrim.read_mesh(POISSON)
    points = meshtrim.read_cloud(CLOUD)
    bad = faces.copy()
    bad[7, 1] = -2
    assert raises(meshtrim.trim, vertices, bad, points).startswith("faces: face 7 has a negative vertex index")
    bad[7, 1] = len(vertices)
    assert "face 7 refers to vertex" in raises(meshtrim.clean, vertices, bad)
    assert "integer" in raises(meshtrim.clean, vertices, faces + 0.5)
    assert "no faces" in raises(meshtrim.clean, vertices, np.zeros((0, 3), int))
    assert "shape (m, 3)" in raises(meshtrim.trim, vertices, faces[:, :2], points)
    nan = vertices.copy()
    nan[3, 0] = np.nan
    assert "vertex 3 has a non-finite coordinate" in raises(meshtrim.trim, nan, faces, points)
    assert "vertex 3" in raises(meshtrim.write_mesh, tmp_path / "x.ply", nan, faces)
    assert "extension" in raises(meshtrim.write_mesh, tmp_path / "x.txt", vertices, faces)
    assert not (tmp_path / "x.ply").exists() and not (tmp_path / "x.txt").exists()


def test_values_that_are_not_real_numbers_raise(tmp_path):
    """Complex values would lose their imaginary part in the conversion
    to float64, text would not convert: both are refused by name, as
    coordinates are."""
    vertices, faces = meshtrim.read_mesh(POISSON)
    for bad in (vertices[:, 0] * 1j, vertices[:, 0].astype(str)):
        message = raises(meshtrim.carry, vertices, faces, bad, vertices, faces)
        assert message == f"values: expected real numbers, got dtype {bad.dtype}", message
        message = raises(meshtrim.write_mesh, tmp_path / "x.ply", vertices, faces, colours=np.c_[bad, bad, bad])
        assert message == f"colours: expected real numbers, got dtype {bad.dtype}", message
    message = raises(meshtrim.carry, vertices, faces, [[1.0, 2.0], [3.0]], vertices, faces)
    assert message.startswith("values: not an array of numbers"), message
    assert not (tmp_path / "x.ply").exists()


def test_file_errors_carry_the_cli_message(tmp_path):
    broken = tmp_path / "broken.ply"
    broken.write_bytes(POISSON.read_bytes()[:2000])
    missing = tmp_path / "missing.ply"
    for path in (broken, missing):
        assert raises(meshtrim.read_cloud, path) == cli_error("detect", path)
    assert raises(meshtrim.read_mesh, broken) == cli_error("clean", broken, tmp_path / "o.ply")
    # A cloud has no faces: read_mesh says so and what to do.
    assert "no faces: read it with read_cloud" in raises(meshtrim.read_mesh, CLOUD)


def test_library_messages_are_the_cli_messages_in_parameter_words(tmp_path):
    few = np.random.default_rng(3).random((12, 3))
    path = tmp_path / "few.xyz"
    np.savetxt(path, few, fmt="%.17g")
    cli = cli_error("detect", path)
    ours = raises(meshtrim.detect, meshtrim.read_cloud(path))
    assert ours == cli.replace(str(path), "points").replace("--k", "k")


# --- the GIL ---------------------------------------------------------------


def test_the_gil_is_released_while_the_library_works():
    rng = np.random.default_rng(7)
    side = 400
    u, v = np.meshgrid(np.arange(side, dtype=float), np.arange(side, dtype=float))
    points = np.c_[u.ravel(), v.ravel(), np.zeros(side * side)] + rng.uniform(-0.2, 0.2, (side * side, 3)) * [1, 1, 0]
    ticks = []
    stop = threading.Event()

    def count():
        while not stop.is_set():
            ticks.append(time.perf_counter())

    started = time.perf_counter()
    counter = threading.Thread(target=count)
    counter.start()
    try:
        d = meshtrim.detect(points)
    finally:
        stop.set()
        counter.join()
    finished = time.perf_counter()
    assert d.summary["points"] == side * side
    # The other thread ran all along: at least one tick in every tenth of
    # the call (holding the GIL would leave one gap as long as the call).
    inside = [t for t in ticks if started <= t <= finished]
    gaps = np.diff([started, *inside, finished])
    assert finished - started > 0.1, "the call is too short to tell"
    assert gaps.max() < 0.1 * (finished - started), gaps.max()


# --- the adapters ----------------------------------------------------------


def test_pymeshlab_adapter_adds_the_trimmed_layer():
    import pymeshlab

    import meshtrim.pymeshlab

    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(CLOUD))
    cloud_id = ms.current_mesh_id()
    ms.load_new_mesh(str(POISSON))
    mesh_id = ms.current_mesh_id()
    report = meshtrim.pymeshlab.trim(ms, mesh_id, cloud_id)
    assert ms.mesh_number() == 3 and ms.current_mesh_id() not in (mesh_id, cloud_id)
    m = ms.current_mesh()
    vertices, faces = meshtrim.read_mesh(POISSON)
    out_v, out_f, expected = meshtrim.trim(vertices, faces, meshtrim.read_cloud(CLOUD))
    # PyMeshLab reads the PLY itself: its arrays are the file's, so the
    # trim is the same, vertex for vertex.
    assert np.array_equal(m.vertex_matrix(), out_v) and np.array_equal(m.face_matrix(), out_f)
    assert results(report) == results(expected)
    ms.load_new_mesh(str(JAGGED))
    clean_report = meshtrim.pymeshlab.clean(ms, ms.current_mesh_id())
    assert clean_report["faces_out"] == ms.current_mesh().face_number()
    mesh_report = meshtrim.pymeshlab.mesh(ms, cloud_id)
    assert mesh_report["faces"] == ms.current_mesh().face_number() and ms.mesh_number() == 6


def test_open3d_adapter_returns_triangle_meshes():
    import open3d as o3d

    import meshtrim.open3d

    vertices, faces = meshtrim.read_mesh(POISSON)
    points = meshtrim.read_cloud(CLOUD)
    poisson = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(vertices), o3d.utility.Vector3iVector(faces))
    pcd = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points))
    trimmed, report = meshtrim.open3d.trim(poisson, pcd, report=True)
    out_v, out_f, _ = meshtrim.trim(vertices, faces, points)
    assert isinstance(trimmed, o3d.geometry.TriangleMesh)
    assert np.array_equal(np.asarray(trimmed.vertices), out_v)
    assert np.array_equal(np.asarray(trimmed.triangles), out_f)
    assert report["faces_out"] == len(out_f)
    assert len(np.asarray(poisson.triangles)) == len(faces), "the input is unchanged"
    jagged = meshtrim.read_mesh(JAGGED)
    scan = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(jagged[0]), o3d.utility.Vector3iVector(jagged[1]))
    assert np.array_equal(np.asarray(meshtrim.open3d.clean(scan).triangles), meshtrim.clean(*jagged)[1])
    assert len(meshtrim.open3d.mesh(o3d.io.read_point_cloud(str(HOLES))).triangles) > 0
    d = meshtrim.open3d.detect(o3d.io.read_point_cloud(str(HOLES)))
    assert np.array_equal(d.boundary, meshtrim.detect(meshtrim.read_cloud(HOLES)).boundary)


def test_trimesh_adapter_returns_trimeshes():
    import trimesh

    import meshtrim.trimesh

    # trimesh welds an STL's corners into vertices on loading, as
    # meshtrim's reader does (in another order).
    scan = trimesh.load(str(JAGGED))
    cleaned = meshtrim.trimesh.clean(scan)
    out_v, out_f, report = meshtrim.clean(scan.vertices, scan.faces)
    assert report["loops_smoothed"] == meshtrim.clean(*meshtrim.read_mesh(JAGGED))[2]["loops_smoothed"] > 0
    assert isinstance(cleaned, trimesh.Trimesh)
    assert np.array_equal(cleaned.vertices, out_v) and np.array_equal(cleaned.faces, out_f)
    assert results(cleaned.metadata["meshtrim"]) == results(report)
    poisson = trimesh.load(str(POISSON), process=False)
    cloud = trimesh.PointCloud(meshtrim.read_cloud(CLOUD))
    trimmed = meshtrim.trimesh.trim(poisson, cloud)
    assert np.array_equal(trimmed.faces, meshtrim.trim(*meshtrim.read_mesh(POISSON), cloud.vertices)[1])


def test_adapters_are_imported_on_demand():
    code = "import sys, meshtrim; assert 'open3d' not in sys.modules and 'trimesh' not in sys.modules; meshtrim.trimesh; assert 'trimesh' in sys.modules"
    subprocess.run([sys.executable, "-c", code], check=True, timeout=120)


# --- the Dask example ----------------------------------------------------------


def test_dask_example_matches_meshtrim_batch(tmp_path):
    """The example runs `meshtrim batch`'s own list of work: a cloud beside
    its mesh or under a cloud-only extension (`sub/part.xyz`) trims it,
    sub-directories are mirrored, two clouds for one mesh fail it, and each
    output, and with `--edges-to` each edges file, is the batch's bytes."""
    scans = tmp_path / "scans"
    (scans / "sub").mkdir(parents=True)
    shutil.copy(JAGGED, scans / "jagged.stl")
    shutil.copy(POISSON, scans / "blade.ply")
    shutil.copy(CLOUD, scans / "blade.cloud.ply")
    shutil.copy(POISSON, scans / "sub" / "part.ply")
    np.savetxt(scans / "sub" / "part.xyz", meshtrim.read_cloud(CLOUD))
    shutil.copy(POISSON, scans / "two.ply")
    shutil.copy(CLOUD, scans / "two.cloud.ply")
    shutil.copy(scans / "sub" / "part.xyz", scans / "two.xyz")
    (scans / "empty.stl").write_bytes(b"solid empty\nendsolid empty\n")
    dask_out, batch_out = tmp_path / "dask", tmp_path / "batch"
    # As a user runs it: a LocalCluster of worker processes.
    example = ROOT / "examples" / "python" / "dask_clean.py"
    r = subprocess.run(
        [sys.executable, str(example), str(scans), str(dask_out), "--edges-to", "dxf"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert r.returncode == 1, r.stderr  # the empty file and two.ply fail, the others not
    lines = [line.split(maxsplit=3) for line in r.stdout.splitlines()]
    assert [(mode, status, Path(name.rstrip(":")).relative_to(scans).as_posix()) for mode, status, name, _ in lines] == [
        ("trim", "ok", "blade.ply"),
        ("clean", "failed", "empty.stl"),
        ("clean", "ok", "jagged.stl"),
        ("trim", "ok", "sub/part.ply"),
        ("trim", "failed", "two.ply"),
    ], r.stdout
    assert "several clouds match this mesh" in lines[-1][3], r.stdout
    batch = subprocess.run(
        [str(MESHTRIM), "batch", str(scans), "--out-dir", str(batch_out), "--edges-to", "dxf"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert batch.returncode == 1, batch.stderr
    for name in ("blade.ply", "jagged.stl", "sub/part.ply", "blade.edges.dxf", "jagged.edges.dxf", "sub/part.edges.dxf"):
        assert (dask_out / name).read_bytes() == (batch_out / name).read_bytes(), name


@pytest.mark.parametrize("ext", ["json", "dxf", "step", "svg"])
def test_border_edges_write_what_clean_edges_writes(tmp_path, ext):
    """`border_edges` of `clean`'s output, written by `write_edges`, is
    the file `meshtrim clean --edges` writes."""
    cli = tmp_path / f"cli.{ext}"
    run_meshtrim("clean", JAGGED, tmp_path / "out.ply", "--edges", cli)
    v, f = meshtrim.read_mesh(JAGGED)
    out_v, out_f, _ = meshtrim.clean(v, f)
    loops = meshtrim.border_edges(out_v, out_f)
    assert len(loops) == 4 and loops.summary["loops_from"] == "mesh_border"
    ours = tmp_path / f"ours.{ext}"
    meshtrim.write_edges(ours, loops, out_v)
    assert ours.read_bytes() == cli.read_bytes()
