"""The smoothed edges as STEP and IGES B-spline curves (`meshtrim edges
CLOUD -o OUT.step|OUT.igs`), read back by OpenCASCADE through gmsh: one B-spline curve per
JSON edge, every edge point on its curve within 0.01 beta, the curve within
a quarter spacing of the edge polyline between points (no overshoot),
consecutive edges meeting at their corners, closed loops closed, the unit
declared."""

from __future__ import annotations

import csv
import json

import gmsh
import numpy as np
import pytest
from scipy.spatial import cKDTree

from curves import cases, segment_distance
from meshtrim_cli import ROOT, run_meshtrim


def read_step(path, target_unit="MM"):
    """The curves OpenCASCADE reads from `path` (STEP or IGES), in file
    order: a function evaluating each at parameters, and its closest-point
    query. STEP is converted to `target_unit`; OpenCASCADE's IGES reader
    converts to millimetres itself (gmsh cannot set its target unit)."""
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    if path.suffix != ".igs":
        gmsh.option.setString("Geometry.OCCTargetUnit", target_unit)
    try:
        gmsh.model.occ.importShapes(str(path))
        gmsh.model.occ.synchronize()
        curves = []
        for dim, tag in gmsh.model.getEntities(1):
            assert gmsh.model.getType(dim, tag) == "BSpline"
            lo, hi = gmsh.model.getParametrizationBounds(dim, tag)
            u = np.linspace(lo[0], hi[0], 4001)
            samples = np.array(gmsh.model.getValue(dim, tag, u)).reshape(-1, 3)
            curves.append({"tag": tag, "samples": samples})
        closest = lambda tag, pts: np.array(gmsh.model.getClosestPoint(1, tag, pts.ravel())[0]).reshape(-1, 3)
        for c in curves:
            c["closest"] = closest
        return curves, closest
    except Exception:
        gmsh.finalize()
        raise


@pytest.mark.parametrize("suffix", [".step", ".igs"])
@pytest.mark.parametrize("name", ["blade_holes", "notched_plate", "bunny"])
def test_curves_fit_the_json_edges(tmp_path, name, suffix):
    cloud = cases(tmp_path)[name]
    run_meshtrim("edges", cloud, "-o", tmp_path / "e.json")
    run_meshtrim("edges", cloud, "-o", (tmp_path / "e").with_suffix(suffix))
    run_meshtrim("detect", cloud, "-o", tmp_path / "labels.csv")
    with open(tmp_path / "labels.csv") as f:
        rows = list(csv.DictReader(f))
    xyz = np.array([[float(r[c]) for c in "xyz"] for r in rows])
    beta = np.array([float(r["beta"]) for r in rows])
    spacing = float(np.median(cKDTree(xyz).query(xyz, k=2)[0][:, 1]))
    loops = json.loads((tmp_path / "e.json").read_text())["loops"]
    edges = [e for l in loops for e in l["edges"]]
    curves, closest = read_step((tmp_path / "e").with_suffix(suffix))
    try:
        assert len(curves) == len(edges) > 0
        for curve, edge in zip(curves, edges):
            points = np.array(edge["points"])
            # Every edge point on its curve, within 0.01 beta (of the
            # nearest cloud point: the local resolution there).
            local_beta = beta[cKDTree(xyz).query(points)[1]]
            off = np.linalg.norm(closest(curve["tag"], points) - points, axis=1)
            assert np.all(off <= 0.01 * local_beta), off.max()
            # Between points, within a quarter spacing of the polyline.
            polyline = np.vstack([points, points[:1]]) if edge["closed"] else points
            assert segment_distance(curve["samples"], polyline).max() <= 0.25 * spacing
            ends = curve["samples"][[0, -1]]
            if edge["closed"]:
                assert np.linalg.norm(ends[0] - ends[1]) < 1e-9 * np.abs(points).max()
            else:
                assert np.allclose(ends, points[[0, -1]], rtol=0, atol=1e-9 * np.abs(points).max())
        # Consecutive edges of a loop meet at their corners.
        for l in loops:
            open_edges = [e for e in l["edges"] if not e["closed"]]
            for a, b in zip(open_edges, open_edges[1:] + open_edges[:1]):
                assert a["points"][-1] == b["points"][0]
    finally:
        gmsh.finalize()


@pytest.mark.parametrize("suffix", [".step", ".igs"])
def test_the_unit_is_declared(tmp_path, suffix):
    cloud = ROOT / "fixtures" / "meshes" / "blade_holes.ply"
    first = {}
    for unit, scale in [("mm", 1.0), ("m", 1000.0), ("in", 25.4)]:
        out = tmp_path / f"e_{unit}{suffix}"
        run_meshtrim("edges", cloud, "-o", out, "--units", unit)
        curves, _ = read_step(out, "MM")
        try:
            first[unit] = curves[0]["samples"][0] / scale
        finally:
            gmsh.finalize()
    assert np.allclose(first["m"], first["mm"]) and np.allclose(first["in"], first["mm"])
    again = tmp_path / f"again{suffix}"
    run_meshtrim("edges", cloud, "-o", again, "--units", "in")
    assert again.read_bytes() == (tmp_path / f"e_in{suffix}").read_bytes()


def test_iges_records_and_corners(tmp_path):
    """The IGES file's fixed records: 80 columns, sections in order with
    their own sequence numbers, the Terminate record's counts; one point
    entity (116) per corner and one curve (126) per JSON edge."""
    cloud = ROOT / "fixtures" / "meshes" / "blade_holes.ply"
    run_meshtrim("edges", cloud, "-o", tmp_path / "e.igs")
    run_meshtrim("edges", cloud, "-o", tmp_path / "e.json")
    lines = (tmp_path / "e.igs").read_text().splitlines()
    assert all(len(l) == 80 for l in lines)
    sections = [l[72] for l in lines]
    assert "".join(dict.fromkeys(sections)) == "SGDPT"
    counts = {s: sections.count(s) for s in "SGDP"}
    for s in "SGDP":
        numbers = [int(l[73:]) for l in lines if l[72] == s]
        assert numbers == list(range(1, counts[s] + 1))
    assert lines[-1][:32] == "".join(f"{s}{counts[s]:>7}" for s in "SGDP")
    kinds = [int(l[:8]) for l in lines if l[72] == "D"][::2]
    loops = json.loads((tmp_path / "e.json").read_text())["loops"]
    assert kinds.count(116) == sum(len(l["corners"]) for l in loops) == 4
    assert kinds.count(126) == sum(len(l["edges"]) for l in loops)


@pytest.mark.parametrize("suffix", [".step", ".igs"])
def test_clean_writes_the_cleaned_border_as_curves(tmp_path, suffix):
    """`clean --edges OUT.step|OUT.igs`: one B-spline curve per edge of the
    JSON it writes, through every one of its border vertices (within 1e-6
    of the part's size), ending at its corners."""
    src = ROOT / "fixtures" / "meshes" / "blade_jagged.stl"
    run_meshtrim("clean", src, tmp_path / "a.ply", "--edges", tmp_path / "e.json")
    run_meshtrim("clean", src, tmp_path / "b.ply", "--edges", (tmp_path / "e").with_suffix(suffix))
    loops = json.loads((tmp_path / "e.json").read_text())["loops"]
    edges = [e for l in loops for e in l["edges"]]
    curves, closest = read_step((tmp_path / "e").with_suffix(suffix))
    try:
        assert len(curves) == len(edges) == 7
        size = max(np.abs(np.array(e["points"])).max() for e in edges)
        for curve, edge in zip(curves, edges):
            points = np.array(edge["points"])
            off = np.linalg.norm(closest(curve["tag"], points) - points, axis=1)
            assert off.max() <= 1e-6 * size, off.max()
            if not edge["closed"]:
                assert np.allclose(curve["samples"][[0, -1]], points[[0, -1]], rtol=0, atol=1e-9 * size)
    finally:
        gmsh.finalize()
