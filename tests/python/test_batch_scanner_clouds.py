"""`meshtrim batch` pairs a mesh with the scanner's own file beside it
(`S.e57` written by pye57, `S.laz` and `S.cloud.las` by laspy): each such
mesh is trimmed, the bytes `meshtrim trim MESH CLOUD OUT` writes, and an
E57 file in metres beside a mesh in millimetres fails with the units
named. The package's `batch_plan` is the batch's own list of work."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import laspy
import numpy as np
import pye57
import pymeshlab
import pytest

import meshtrim
from meshtrim_cli import MESHTRIM, run_meshtrim

FIXTURES = Path(__file__).resolve().parents[2] / "fixtures" / "meshes"
CLOUD = FIXTURES / "blade_small.ply"
POISSON = FIXTURES / "blade_small_poisson.ply"
JAGGED = FIXTURES / "blade_jagged.stl"


def cloud_points() -> np.ndarray:
    """The fixture cloud's points, as PyMeshLab reads them."""
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(CLOUD))
    return ms.current_mesh().vertex_matrix()


def write_e57(path: Path, points: np.ndarray) -> None:
    e = pye57.E57(str(path), mode="w")
    e.write_scan_raw({"cartesianX": points[:, 0], "cartesianY": points[:, 1], "cartesianZ": points[:, 2]})
    e.close()


def write_las(path: Path, points: np.ndarray) -> None:
    """LAS or LAZ by the extension (laspy compresses .laz with lazrs)."""
    header = laspy.LasHeader(point_format=0, version="1.4")
    header.offsets = points.min(0)
    header.scales = [1e-4, 1e-4, 1e-4]
    las = laspy.LasData(header)
    las.x, las.y, las.z = points[:, 0], points[:, 1], points[:, 2]
    las.write(str(path))


@pytest.fixture(scope="module")
def scans(tmp_path_factory) -> Path:
    """A folder as a scanning shop keeps it: Poisson meshes beside the
    scanner's clouds, a jagged scan without one, a mesh with two, and a
    mesh in millimetres beside its scan in metres (as E57 holds them)."""
    root = tmp_path_factory.mktemp("shop")
    d = root / "scans"
    (d / "sub").mkdir(parents=True)
    points = cloud_points()
    for mesh in ["a.ply", "b.ply", "e.ply", "m.ply", "sub/c.ply"]:
        (d / mesh).write_bytes(POISSON.read_bytes())
    (d / "d.stl").write_bytes(JAGGED.read_bytes())
    write_e57(d / "a.e57", points)
    write_las(d / "b.laz", points)
    write_las(d / "sub" / "c.cloud.las", points)
    write_e57(d / "e.e57", points)
    np.savetxt(d / "e.xyz", points)
    write_e57(d / "m.e57", points / 1000.0)
    return root


def test_batch_plan_pairs_the_scanners_files(scans):
    d, out = scans / "scans", scans / "out"
    plan = meshtrim.batch_plan(d, out)
    assert plan == [
        meshtrim.BatchJob(d / "a.ply", out / "a.ply", (d / "a.e57",)),
        meshtrim.BatchJob(d / "b.ply", out / "b.ply", (d / "b.laz",)),
        meshtrim.BatchJob(d / "d.stl", out / "d.stl", ()),
        meshtrim.BatchJob(d / "e.ply", out / "e.ply", (d / "e.e57", d / "e.xyz")),
        meshtrim.BatchJob(d / "m.ply", out / "m.ply", (d / "m.e57",)),
        meshtrim.BatchJob(d / "sub" / "c.ply", out / "sub" / "c.ply", (d / "sub" / "c.cloud.las",)),
    ]
    # Every output in one format (--to).
    assert [j.output for j in meshtrim.batch_plan(d, out, to="glb")] == [
        out / "a.glb", out / "b.glb", out / "d.glb", out / "e.glb", out / "m.glb", out / "sub" / "c.glb"
    ]
    # Each output's edges file beside it (--edges-to).
    assert [j.edges for j in meshtrim.batch_plan(d, out, edges_to="step")] == [
        out / "a.edges.step", out / "b.edges.step", out / "d.edges.step", out / "e.edges.step", out / "m.edges.step", out / "sub" / "c.edges.step"
    ]
    assert all(j.edges is None for j in plan)
    # A glob pattern and a file argument, as the CLI takes them.
    assert [j.input for j in meshtrim.batch_plan([str(d / "*.ply"), d / "d.stl"], out)] == [
        d / "a.ply",
        d / "b.ply",
        d / "d.stl",
        d / "e.ply",
        d / "m.ply",
    ]


def test_batch_plan_refuses_what_the_batch_refuses(scans):
    d = scans / "scans"
    with pytest.raises(meshtrim.MeshtrimError, match="matches no mesh"):
        meshtrim.batch_plan(d / "nothing*.stl", scans / "out")
    with pytest.raises(meshtrim.MeshtrimError, match="not a mesh input"):
        meshtrim.batch_plan(d / "a.e57", scans / "out")
    # Outputs into the inputs' own folder would overwrite them.
    with pytest.raises(meshtrim.MeshtrimError, match="overwrite"):
        meshtrim.batch_plan(d, d)
    with pytest.raises(meshtrim.MeshtrimError, match="cannot write meshes as '.xyz'"):
        meshtrim.batch_plan(d, scans / "out", to="xyz")
    with pytest.raises(meshtrim.MeshtrimError, match="cannot write edges as '.stl'"):
        meshtrim.batch_plan(d, scans / "out", edges_to="stl")


def test_batch_trims_with_the_scanners_files(scans, tmp_path):
    d, out, report = scans / "scans", tmp_path / "out", tmp_path / "report.json"
    r = subprocess.run(
        [str(MESHTRIM), "batch", str(d), "--out-dir", str(out), "--report", str(report)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert r.returncode == 1, r.stderr  # e.ply has two clouds, m.ply's is in metres
    rows = {Path(row["input"]).relative_to(d).as_posix(): row for row in json.loads(report.read_text())["files"]}
    assert {k: (v["mode"], v["status"]) for k, v in rows.items()} == {
        "a.ply": ("trim", "ok"),
        "b.ply": ("trim", "ok"),
        "d.stl": ("clean", "ok"),
        "e.ply": ("trim", "failed"),
        "m.ply": ("trim", "failed"),
        "sub/c.ply": ("trim", "ok"),
    }
    assert "several clouds match this mesh" in rows["e.ply"]["error"], rows["e.ply"]
    # The report names the cloud each mesh was trimmed with.
    assert [rows[m]["cloud"] for m in ("a.ply", "b.ply", "d.stl", "e.ply", "sub/c.ply")] == [
        str(d / "a.e57"),
        str(d / "b.laz"),
        None,
        None,
        str(d / "sub" / "c.cloud.las"),
    ]
    units = "the cloud looks to be in metres and the mesh in millimetres"
    assert units in rows["m.ply"]["error"], rows["m.ply"]
    assert rows["m.ply"]["error"].endswith("scale the cloud with --cloud-scale 1000"), rows["m.ply"]
    assert not (out / "m.ply").exists()
    for mesh, cloud in [("a.ply", "a.e57"), ("b.ply", "b.laz"), ("sub/c.ply", "sub/c.cloud.las")]:
        alone = tmp_path / "alone.ply"
        run_meshtrim("trim", d / mesh, d / cloud, alone)
        assert (out / mesh).read_bytes() == alone.read_bytes(), mesh
        assert rows[mesh]["faces_out"] < rows[mesh]["faces_in"], rows[mesh]


def test_batch_scales_clouds_in_metres(scans, tmp_path):
    """`--cloud-scale 1000`, as the error advises: the E57 file in metres
    trims its mesh in millimetres, the bytes `meshtrim trim` writes with
    the same flag, and the report says the factor."""
    d = scans / "scans"
    folder = tmp_path / "m"
    folder.mkdir()
    for name in ("m.ply", "m.e57"):
        (folder / name).write_bytes((d / name).read_bytes())
    out = tmp_path / "out"
    run_meshtrim("batch", folder, "--out-dir", out, "--cloud-scale", "1000")
    alone, report = tmp_path / "alone.ply", tmp_path / "report.json"
    run_meshtrim("trim", folder / "m.ply", folder / "m.e57", alone, "--cloud-scale", "1000", "--report", report)
    assert (out / "m.ply").read_bytes() == alone.read_bytes()
    rep = json.loads(report.read_text())
    assert rep["cloud_scale"] == 1000.0 and rep["faces_out"] < rep["faces_in"], rep
