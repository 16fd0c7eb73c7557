"""`meshtrim.write_edges`: the loops of `meshtrim.edges`, written to a
file, are the bytes `meshtrim edges CLOUD -o FILE` writes, in every format
and option; a selection of the loops writes just those; loops that do not
fit the cloud raise `MeshtrimError` naming the part, and nothing is
written."""

from __future__ import annotations

import json
from dataclasses import replace

import ezdxf
import numpy as np
import pytest

import meshtrim
from meshtrim_cli import ROOT, run_meshtrim

CLOUD = ROOT / "fixtures" / "meshes" / "blade_holes.ply"


@pytest.fixture(scope="module")
def found():
    points = meshtrim.read_cloud(CLOUD)
    return points, meshtrim.edges(points)


@pytest.mark.parametrize(
    "name, flags",
    [
        ("e.json", []),
        ("e.obj", []),
        ("e.svg", []),
        ("e.dxf", []),
        ("splines.dxf", ["--dxf-splines"]),
        ("e.step", []),
        ("e.stp", ["--units", "in"]),
        ("e.igs", ["--units", "m"]),
    ],
)
def test_files_are_the_cli_bytes(tmp_path, found, name, flags):
    points, loops = found
    units = flags[flags.index("--units") + 1] if "--units" in flags else "mm"
    python = tmp_path / "python" / name
    meshtrim.write_edges(python, loops, points, units=units, dxf_splines="--dxf-splines" in flags)
    run_meshtrim("edges", CLOUD, "-o", tmp_path / name, *flags)
    assert python.read_bytes() == (tmp_path / name).read_bytes()


def test_a_selection_of_loops_writes_those(tmp_path, found):
    points, loops = found
    outer = max(loops, key=lambda l: len(l.boundary_points))
    meshtrim.write_edges(tmp_path / "outer.json", [outer], points)
    meshtrim.write_edges(tmp_path / "outer.dxf", [outer], points)
    written = json.loads((tmp_path / "outer.json").read_text())["loops"]
    assert len(written) == 1 and len(loops) == 4
    assert written[0]["boundary_points"] == outer.boundary_points.tolist()
    assert np.array_equal(np.array(written[0]["corners"]).reshape(-1, 3), outer.corners)
    polylines = ezdxf.readfile(tmp_path / "outer.dxf").modelspace().query("POLYLINE")
    assert len(polylines) == 1
    joined = np.vstack([e.points if e.closed else e.points[:-1] for e in outer.edges])
    assert np.array_equal([list(v.dxf.location) for v in polylines[0].vertices], joined)


def test_loops_that_do_not_fit_are_refused(tmp_path, found):
    points, loops = found
    first = loops[0]
    corner_loop = next(l for l in loops if len(l.corners))
    bad_points = first.edges[0].points.copy()
    bad_points[1, 2] = np.nan
    cases = [
        ("e.json", [replace(first, boundary_points=first.boundary_points + len(points))], {},
         f"edges[0].boundary_points[0]: {first.boundary_points[0] + len(points)} is not a point of the cloud ({len(points)} points)"),
        ("e.json", [replace(corner_loop, corners=corner_loop.corners + 1.0)], {},
         "edges[0].corners[0]: not one of the loop's boundary points"),
        ("e.dxf", [replace(first, edges=[replace(first.edges[0], points=bad_points)])], {},
         "edges[0].edges[0].points: a coordinate is not finite"),
        ("e.step", loops, {"units": "ft"}, 'units: "ft" is not a length unit: mm, m or in'),
        ("e.json", loops, {"dxf_splines": True}, "dxf_splines writes splines into a .dxf file, and this is not one"),
        ("e.txt", loops, {}, "unsupported output format: use .json, .obj, .svg, .dxf, .step or .igs"),
        ("e.json", [first, "loop"], {}, "edges[1]: expected a Loop, got str"),
    ]
    for name, selection, options, message in cases:
        with pytest.raises(meshtrim.MeshtrimError) as raised:
            meshtrim.write_edges(tmp_path / name, selection, points, **options)
        assert message in str(raised.value), (message, str(raised.value))
        assert not (tmp_path / name).exists()


def test_a_loop_without_points_draws_nothing(tmp_path, found):
    points, loops = found
    empty = meshtrim.Loop(True, [], [], [])
    meshtrim.write_edges(tmp_path / "e.json", [loops[0], empty], points)
    written = json.loads((tmp_path / "e.json").read_text())["loops"]
    assert len(written) == 2 and written[1] == {"closed": True, "boundary_points": [], "corners": [], "edges": []}
    meshtrim.write_edges(tmp_path / "e.dxf", [loops[0], empty], points, dxf_splines=True)
    doc = ezdxf.readfile(tmp_path / "e.dxf")
    assert len(doc.modelspace().query("POLYLINE")) == 1 and not doc.audit().has_errors
