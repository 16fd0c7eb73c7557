"""The smoothed edges as DXF (`meshtrim edges CLOUD -o OUT.dxf`), read
back by ezdxf, the reference Python DXF library: the file passes ezdxf's
audit, each loop is one closed 3-D polyline whose vertices are the JSON
output's edge points to the last bit, loops sit on OUTER or HOLES by
enclosure, corners are POINTs on CORNERS. With `--dxf-splines` the file is
AutoCAD 2000 and also holds each edge as a cubic SPLINE through its
points, with the length unit declared."""

from __future__ import annotations

import json

import ezdxf
import numpy as np
import pytest

import synthetic
from curves import cases, median_spacing, segment_distance
from meshtrim_cli import ROOT, run_meshtrim, shared_data


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


@pytest.mark.parametrize("ext", ["json", "obj", "svg", "dxf", "step", "igs", "dxf --dxf-splines"])
def test_trim_and_mesh_write_the_edges_they_used(tmp_path, ext):
    ext, *flags = ext.split()
    meshes = ROOT / "fixtures" / "meshes"
    cloud, poisson = meshes / "blade_small.ply", meshes / "blade_small_poisson.ply"
    run_meshtrim(poisson, cloud, tmp_path / "trimmed.ply", "--edges", tmp_path / f"trim.{ext}", "--k", 25, *flags)
    run_meshtrim("edges", cloud, "-o", tmp_path / f"edges.{ext}", "--k", 25, *flags)
    assert (tmp_path / f"trim.{ext}").read_bytes() == (tmp_path / f"edges.{ext}").read_bytes()
    holes = meshes / "blade_holes.ply"
    run_meshtrim("mesh", holes, tmp_path / "meshed.ply", "--edges", tmp_path / f"mesh.{ext}", "--no-offset", *flags)
    run_meshtrim("edges", holes, "-o", tmp_path / f"holes.{ext}", "--no-offset", *flags)
    assert (tmp_path / f"mesh.{ext}").read_bytes() == (tmp_path / f"holes.{ext}").read_bytes()
    if flags:
        assert b"SPLINE" in (tmp_path / f"mesh.{ext}").read_bytes()


@pytest.mark.parametrize("name", ["blade_holes", "notched_plate", "bunny"])
def test_dxf_splines_pass_through_the_edge_points(tmp_path, name):
    cloud = cases(tmp_path)[name]
    run_meshtrim("edges", cloud, "-o", tmp_path / "e.json")
    run_meshtrim("edges", cloud, "-o", tmp_path / "r12.dxf")
    run_meshtrim("edges", cloud, "-o", tmp_path / "e.dxf", "--dxf-splines")
    loops = json.loads((tmp_path / "e.json").read_text())["loops"]
    edges = [e for l in loops for e in l["edges"]]
    doc = ezdxf.readfile(tmp_path / "e.dxf")
    auditor = doc.audit()
    assert not auditor.has_errors, [str(e.message) for e in auditor.errors]
    assert doc.dxfversion == "AC1015" and doc.header["$INSUNITS"] == 4
    # The polylines and corners of the R12 file, to the bit.
    r12 = ezdxf.readfile(tmp_path / "r12.dxf").modelspace()
    msp = doc.modelspace()
    for kind in ["POLYLINE", "POINT"]:
        assert [e.dxf.layer for e in msp.query(kind)] == [e.dxf.layer for e in r12.query(kind)]
    vertices = lambda msp: [[list(v.dxf.location) for v in p.vertices] for p in msp.query("POLYLINE")]
    assert vertices(msp) == vertices(r12)
    assert [list(p.dxf.location) for p in msp.query("POINT")] == [list(p.dxf.location) for p in r12.query("POINT")]
    xyz = np.array([list(v.dxf.location) for p in msp.query("POLYLINE") for v in p.vertices])
    scale = np.abs(xyz).max()
    spacing = median_spacing(cloud, tmp_path)
    splines = msp.query("SPLINE")
    assert len(splines) == len(edges) > 0
    for spline, edge in zip(splines, edges):
        assert spline.dxf.layer == "SPLINES" and spline.dxf.degree == 3
        assert not spline.closed, "clamped; a closed loop's curve ends where it starts"
        curve = spline.construction_tool()
        points = np.array(edge["points"])
        through = np.vstack([points, points[:1]]) if edge["closed"] else points
        # Each edge point at its own knot: the knots are the points'
        # parameters, each interior one doubled.
        knots = np.unique(curve.knots())
        assert len(knots) == len(through)
        on = np.array([list(curve.point(k)) for k in knots])
        assert np.abs(on - through).max() <= 1e-9 * scale
        if edge["closed"]:
            assert list(spline.control_points[0]) == list(spline.control_points[-1]) == edge["points"][0]
        # Between points, within a quarter spacing of the polyline.
        samples = np.array([list(p) for p in curve.approximate(4000)])
        assert segment_distance(samples, through).max() <= 0.25 * spacing
    again = tmp_path / "again.dxf"
    run_meshtrim("edges", cloud, "-o", again, "--dxf-splines")
    assert again.read_bytes() == (tmp_path / "e.dxf").read_bytes()


@pytest.mark.parametrize("unit, code", [("mm", 4), ("m", 6), ("in", 1)])
def test_dxf_splines_declare_the_unit(tmp_path, unit, code):
    cloud = ROOT / "fixtures" / "meshes" / "blade_holes.ply"
    run_meshtrim("edges", cloud, "-o", tmp_path / "e.dxf", "--dxf-splines", "--units", unit)
    assert ezdxf.readfile(tmp_path / "e.dxf").header["$INSUNITS"] == code


def test_dxf_splines_need_a_dxf_output(tmp_path):
    import subprocess

    from meshtrim_cli import MESHTRIM

    meshes = ROOT / "fixtures" / "meshes"
    runs = [
        (["edges", meshes / "blade_holes.ply", "-o", tmp_path / "e.json"], tmp_path / "e.json", "e.json: --dxf-splines writes splines into a .dxf file, and this is not one"),
        ([meshes / "blade_small_poisson.ply", meshes / "blade_small.ply", tmp_path / "t.ply"], tmp_path / "t.ply", "--dxf-splines needs an edges output: --edges FILE.dxf"),
        (["mesh", meshes / "blade_holes.ply", tmp_path / "m.ply", "--edges", tmp_path / "m.step"], tmp_path / "m.ply", "m.step: --dxf-splines writes splines into a .dxf file"),
    ]
    for args, output, message in runs:
        r = subprocess.run([str(MESHTRIM), *map(str, args), "--dxf-splines"], capture_output=True, text=True)
        assert r.returncode == 1 and message in r.stderr, (r.returncode, r.stderr)
        assert not output.exists()


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


def border_of(path):
    """The border of the mesh in `path` as trimesh reads it: the edges of
    one face (as vertex position pairs, either way round) and how many
    loops they form."""
    import trimesh

    mesh = trimesh.load(path, process=False)
    edges = np.sort(mesh.edges, axis=1)
    unique, count = np.unique(edges, axis=0, return_counts=True)
    border = unique[count == 1]
    positions = {tuple(map(float, p)) for p in mesh.vertices[np.unique(border)]}
    pairs = {frozenset((tuple(map(float, mesh.vertices[a])), tuple(map(float, mesh.vertices[b])))) for a, b in border}
    parent = {v: v for v in np.unique(border)}

    def root(v):
        while parent[v] != v:
            parent[v] = parent[parent[v]]
            v = parent[v]
        return v

    for a, b in border:
        parent[root(a)] = root(b)
    return pairs, positions, len({root(v) for v in parent})


@pytest.mark.parametrize("scan", ["fixture", "bun000"])
def test_clean_writes_the_cleaned_border(tmp_path, scan):
    """`clean --edges OUT.dxf`: one closed 3-D polyline per border loop of
    the cleaned mesh as trimesh reads it, running along its border edges
    through every border vertex, to the last bit; the corners are POINTs
    at polyline vertices (the fixture's outer border has its four)."""
    src = ROOT / "fixtures" / "meshes" / "blade_jagged.stl" if scan == "fixture" else shared_data("stanford_bunny/bun000.ply")
    out = tmp_path / "clean.ply"
    run_meshtrim("clean", src, out, "--edges", tmp_path / "e.dxf")
    doc = ezdxf.readfile(tmp_path / "e.dxf")
    auditor = doc.audit()
    assert not auditor.has_errors, [str(e.message) for e in auditor.errors]
    pairs, positions, loops = border_of(out)
    polylines = doc.modelspace().query("POLYLINE")
    assert len(polylines) == loops > 0
    seen = set()
    for polyline in polylines:
        assert polyline.is_3d_polyline and polyline.is_closed
        vertices = [tuple(map(float, v.dxf.location)) for v in polyline.vertices]
        steps = {frozenset(pair) for pair in zip(vertices, vertices[1:] + vertices[:1])}
        assert steps <= pairs, "every step of the polyline is a border edge"
        seen.update(vertices)
    assert seen == positions, "every border vertex, on one polyline or another"
    corners = [tuple(map(float, c.dxf.location)) for c in doc.modelspace().query("POINT")]
    assert set(corners) <= positions
    if scan == "fixture":
        assert len(corners) == 4
