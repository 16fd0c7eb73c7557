"""The smoothed edges as DXF (`meshtrim edges CLOUD -o OUT.dxf`), read
back by ezdxf, the reference Python DXF library: the file passes ezdxf's
audit, each loop is one closed 3-D polyline whose vertices are the JSON
output's edge points to the last bit, loops sit on OUTER or HOLES by
enclosure, corners are POINTs on CORNERS."""

from __future__ import annotations

import json

import ezdxf
import numpy as np
import pytest

import synthetic
from meshtrim_cli import ROOT, run_meshtrim


def closed_polyline(loop):
    """The JSON loop's edges joined, each corner once."""
    points = []
    for edge in loop["edges"]:
        points.extend(edge["points"] if edge["closed"] else edge["points"][:-1])
    return np.array(points)


def clouds(tmp_path):
    plate = tmp_path / "plate.ply"
    synthetic.write_cloud_ply(plate, synthetic.notched_plate(1.0, 2).points)
    # (file, outer loops, holes)
    return [(ROOT / "fixtures" / "meshes" / "blade_holes.ply", 1, 3), (plate, 1, 1)]


@pytest.mark.parametrize("case", [0, 1])
def test_dxf_polylines_are_the_json_edges(tmp_path, case):
    cloud, outer, holes = clouds(tmp_path)[case]
    run_meshtrim("edges", cloud, "-o", tmp_path / "e.json")
    run_meshtrim("edges", cloud, "-o", tmp_path / "e.dxf")
    loops = json.loads((tmp_path / "e.json").read_text())["loops"]
    doc = ezdxf.readfile(tmp_path / "e.dxf")
    auditor = doc.audit()
    assert not auditor.has_errors, [str(e.message) for e in auditor.errors]
    polylines = doc.modelspace().query("POLYLINE")
    assert len(polylines) == len(loops)
    for polyline, loop in zip(polylines, loops):
        assert polyline.is_3d_polyline and polyline.is_closed
        vertices = np.array([list(v.dxf.location) for v in polyline.vertices])
        assert np.array_equal(vertices, closed_polyline(loop)), "the JSON points, to the last bit"
    layers = [p.dxf.layer for p in polylines]
    assert layers.count("OUTER") == outer and layers.count("HOLES") == holes, layers
    corners = doc.modelspace().query("POINT")
    assert all(c.dxf.layer == "CORNERS" for c in corners)
    starts = [e["points"][0] for l in loops for e in l["edges"] if not e["closed"]]
    assert len(corners) == len(starts) == sum(len(l["corners"]) for l in loops)
    assert np.array_equal(np.array([list(c.dxf.location) for c in corners]).reshape(-1, 3), np.array(starts).reshape(-1, 3))
    again = tmp_path / "again.dxf"
    run_meshtrim("edges", cloud, "-o", again)
    assert again.read_bytes() == (tmp_path / "e.dxf").read_bytes()


def test_the_notched_plate_has_corners(tmp_path):
    cloud = clouds(tmp_path)[1][0]
    run_meshtrim("edges", cloud, "-o", tmp_path / "e.dxf")
    corners = ezdxf.readfile(tmp_path / "e.dxf").modelspace().query("POINT")
    assert len(corners) == 8  # the outline of the plate with its notch


@pytest.mark.parametrize("ext", ["json", "obj", "svg", "dxf", "step", "igs"])
def test_trim_and_mesh_write_the_edges_they_used(tmp_path, ext):
    meshes = ROOT / "fixtures" / "meshes"
    cloud, poisson = meshes / "blade_small.ply", meshes / "blade_small_poisson.ply"
    run_meshtrim(poisson, cloud, tmp_path / "trimmed.ply", "--edges", tmp_path / f"trim.{ext}", "--k", 25)
    run_meshtrim("edges", cloud, "-o", tmp_path / f"edges.{ext}", "--k", 25)
    assert (tmp_path / f"trim.{ext}").read_bytes() == (tmp_path / f"edges.{ext}").read_bytes()
    holes = meshes / "blade_holes.ply"
    run_meshtrim("mesh", holes, tmp_path / "meshed.ply", "--edges", tmp_path / f"mesh.{ext}", "--no-offset")
    run_meshtrim("edges", holes, "-o", tmp_path / f"holes.{ext}", "--no-offset")
    assert (tmp_path / f"mesh.{ext}").read_bytes() == (tmp_path / f"holes.{ext}").read_bytes()


def test_a_bad_edges_output_is_refused_before_any_work(tmp_path):
    import subprocess

    from meshtrim_cli import MESHTRIM

    meshes = ROOT / "fixtures" / "meshes"
    out = tmp_path / "trimmed.ply"
    r = subprocess.run(
        [str(MESHTRIM), meshes / "blade_small_poisson.ply", meshes / "blade_small.ply", out, "--edges", tmp_path / "e.txt"],
        capture_output=True,
        text=True,
    )
    assert r.returncode == 1 and "e.txt: unsupported output format: use .json, .obj, .svg, .dxf, .step or .igs" in r.stderr
    assert not out.exists()
