"""A file's own per-vertex values (PLY's other vertex properties, glTF's
`_NAME` attributes) carried from the input to the output: MeshLab's
`int flags` and `float quality` on its real range map, screened
Poisson's density, a trimesh glTF's custom attributes. Read back by
reference readers (trimesh's PLY reader, which keeps every property with
its type; trimesh's glTF reader) and checked against an independent
carrying (Open3D's closest point and barycentric coordinates)."""

from __future__ import annotations

import json

import numpy as np
import pymeshlab
import pytest
import trimesh

from carrying import closest_corners_and_weights, expected_at, kept_and_new
from meshtrim_cli import ROOT, run_meshtrim, shared_data

FIXTURES = ROOT / "fixtures" / "meshes"


def ply_vertices(path):
    """The vertex element of a PLY file as trimesh's PLY reader reads it:
    a structured array, every property in its own type."""
    mesh = trimesh.load(str(path), process=False)
    return mesh.vertices, mesh.faces, mesh.metadata["_ply_raw"]["vertex"]["data"]


def check_values(src, out, blended, labels):
    """Kept vertices keep their values bit for bit; new ones have the
    `blended` values of their closest point on the input surface (within
    float32 rounding) and the `labels` of that point's corner of the
    largest weight; every property keeps its type."""
    v_in, f_in, raw_in = ply_vertices(src)
    v_out, _, raw_out = ply_vertices(out)
    for name in blended + labels:
        assert raw_out.dtype[name] == raw_in.dtype[name], name
    out_kept, in_kept, new = kept_and_new(v_in, v_out)
    assert len(new) > 50 and len(out_kept) > 500, (len(new), len(out_kept))
    corners, weights = closest_corners_and_weights(v_in, f_in, v_out[new])
    for name in blended + labels:
        assert np.array_equal(raw_out[name][out_kept], raw_in[name][in_kept]), name
    for name in blended:
        values = raw_in[name].astype(np.float64)
        want = np.einsum("ij,ij->i", weights, values[corners])
        scale = np.abs(values).max()
        gap = np.abs(raw_out[name][new] - want).max()
        assert gap <= 1e-4 * scale, (name, gap, scale)
        # Blends, not copies of a corner: most new values are no input's.
        assert np.isin(raw_out[name][new], values).mean() < 0.5, name
    heaviest = corners[np.arange(len(new)), weights.argmax(axis=1)]
    for name in labels:
        agree = raw_out[name][new] == raw_in[name][heaviest]
        # Open3D's float32 weights may order a near tie the other way.
        assert agree.mean() > 0.99, (name, agree.mean())
        assert np.isin(raw_out[name][new], raw_in[name]).all(), name
    return raw_in, raw_out


def test_clean_carries_meshlab_flags_and_quality(tmp_path):
    """MeshLab's range map `lato000.ply` stores `int flags` and `float
    quality` per vertex (0 and 720 on every vertex): `clean` keeps both,
    in their types."""
    src = shared_data("meshlab_scans/lato000.ply")
    out, report = tmp_path / "out.ply", tmp_path / "r.json"
    run_meshtrim("clean", src, out, "--report", report)
    assert json.loads(report.read_text())["vertex_attributes"] == ["flags", "quality"]
    raw_in, raw_out = check_values(src, out, [], ["flags", "quality"])
    assert raw_in.dtype["flags"] == np.int32 and raw_in.dtype["quality"] == np.float32


def test_clean_blends_measures_and_not_labels(tmp_path):
    """The same scan written by trimesh with values that vary: a float32
    `quality` along the scan and an int32 `flags` bit mask and a uint8
    `label` in bands. New vertices get quality blended at their closest
    point and flags and label from its corner of the largest weight."""
    lato = trimesh.load(str(shared_data("meshlab_scans/lato000.ply")), process=False)
    v = lato.vertices
    x = (v[:, 0] - v[:, 0].min()) / np.ptp(v[:, 0])
    lato.vertex_attributes = {
        "quality": (1000 * x + 50 * np.sin(v[:, 1])).astype(np.float32),
        "flags": np.left_shift(1, (10 * x).astype(np.int32) % 31).astype(np.int32),
        "label": (np.floor(v[:, 1] / 3) % 250).astype(np.uint8),
    }
    src, out = tmp_path / "scan.ply", tmp_path / "out.ply"
    src.write_bytes(trimesh.exchange.ply.export_ply(lato, encoding="binary", vertex_normal=False, include_attributes=True))
    run_meshtrim("clean", src, out)
    check_values(src, out, ["quality"], ["flags", "label"])


@pytest.fixture(scope="module")
def poisson_with_density(tmp_path_factory):
    """PyMeshLab's screened Poisson of the blade fixture, saved with its
    density (vertex quality), and the cloud."""
    d = tmp_path_factory.mktemp("density")
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(FIXTURES / "blade_small.ply"))
    ms.generate_surface_reconstruction_screened_poisson(depth=8)
    assert ms.current_mesh().has_vertex_scalar()
    ms.save_current_mesh(str(d / "poisson.ply"), save_vertex_quality=True)
    return d / "poisson.ply", FIXTURES / "blade_small.ply"


def test_trim_carries_poisson_density(poisson_with_density, tmp_path):
    """The density screened Poisson leaves in `quality`, by which users
    cut its envelope, goes with the trimmed mesh (PyMeshLab writes it as
    a double, and so does meshtrim)."""
    poisson, cloud = poisson_with_density
    out = tmp_path / "out.ply"
    run_meshtrim(poisson, cloud, out)
    raw_in, _ = check_values(poisson, out, ["quality"], [])
    assert raw_in.dtype["quality"] == np.float64


def test_gltf_custom_attributes_read_and_written(tmp_path):
    """A glTF with an application-specific attribute (`_confidence`,
    float), written by trimesh, is read (it was refused as malformed
    before) and its cleaned PLY holds it; a PLY's `float quality` and
    `uchar label` go into a cleaned glTF as `_quality` and `_label`, in
    those types, as trimesh's glTF reader reads them. (trimesh pads an
    8-bit scalar attribute it writes to four bytes, a VEC4, which meshtrim
    does not read.)"""
    scan = trimesh.load(str(FIXTURES / "blade_jagged.stl"))
    v, f = scan.vertices, scan.faces
    confidence = (v[:, 0] - v[:, 0].min()).astype(np.float32)
    label = (np.arange(len(v)) % 7).astype(np.uint8)
    glb, out_ply = tmp_path / "scan.glb", tmp_path / "from_glb.ply"
    trimesh.Trimesh(vertices=v, faces=f, vertex_attributes={"_confidence": confidence}, process=False).export(str(glb))
    report = tmp_path / "r.json"
    run_meshtrim("clean", glb, out_ply, "--report", report)
    assert json.loads(report.read_text())["vertex_attributes"] == ["confidence"]
    v_glb = np.asarray(v, dtype=np.float32).astype(np.float64)
    v_out, _, raw_out = ply_vertices(out_ply)
    out_kept, in_kept, new = kept_and_new(v_glb, v_out)
    assert raw_out.dtype["confidence"] == np.float32
    assert np.array_equal(raw_out["confidence"][out_kept], confidence[in_kept])
    want = expected_at(v_glb, np.asarray(f), confidence.astype(np.float64)[:, None], v_out[new])[:, 0]
    assert np.abs(raw_out["confidence"][new] - want).max() <= 1e-4 * confidence.max()

    ply, out_glb = tmp_path / "scan.ply", tmp_path / "out.glb"
    source = trimesh.Trimesh(vertices=v, faces=f, process=False)
    source.vertex_attributes = {"quality": confidence, "label": label}
    ply.write_bytes(trimesh.exchange.ply.export_ply(source, vertex_normal=False, include_attributes=True))
    run_meshtrim("clean", ply, out_glb)
    read = trimesh.load(str(out_glb), process=False, force="mesh")
    got = {k: np.asarray(a).reshape(len(read.vertices)) for k, a in read.vertex_attributes.items()}
    assert got["_label"].dtype == np.uint8 and got["_quality"].dtype == np.float32, got
    out_kept, in_kept, new = kept_and_new(v_glb, np.asarray(read.vertices))
    assert np.array_equal(got["_label"][out_kept], label[in_kept])
    assert np.array_equal(got["_quality"][out_kept], confidence[in_kept])
    assert np.isin(got["_label"][new], label).all()


def test_obj_and_stl_say_what_they_do_not_hold(tmp_path):
    """The Stanford bunny's `confidence` and `intensity` go into PLY; OBJ
    holds neither, and the report says so."""
    src = shared_data("stanford_bunny/bun_zipper.ply")
    out, report = tmp_path / "out.obj", tmp_path / "r.json"
    result = run_meshtrim("clean", src, out, "--report", report)
    r = json.loads(report.read_text())
    assert r["vertex_attributes_not_written"] == ["confidence", "intensity"], r
    assert "vertex_attributes" not in r, r
    assert "confidence, intensity not written" in result.stdout, result.stdout
    run_meshtrim("clean", src, tmp_path / "out.ply", "--report", report)
    assert json.loads(report.read_text())["vertex_attributes"] == ["confidence", "intensity"]


def test_python_carries_values_as_the_cli_does(tmp_path):
    """`read_mesh` gives the values in their NumPy types; `carry` (float
    blended, integers from the nearest corner, in their type) and
    `write_mesh(scalars=…)` give the CLI's bytes."""
    import meshtrim

    src = shared_data("meshlab_scans/lato000.ply")
    cli = tmp_path / "cli.ply"
    run_meshtrim("clean", src, cli)
    v, f, attributes = meshtrim.read_mesh(src, attributes=True)
    assert attributes.scalars["flags"].dtype == np.int32
    assert attributes.scalars["quality"].dtype == np.float32
    out_v, out_f, _ = meshtrim.clean(v, f)
    scalars = {
        name: meshtrim.carry(v, f, values, out_v, out_f).astype(values.dtype)
        for name, values in attributes.scalars.items()
    }
    assert scalars["flags"].dtype == np.int32
    ours = tmp_path / "python.ply"
    meshtrim.write_mesh(ours, out_v, out_f, scalars=scalars)
    assert ours.read_bytes() == cli.read_bytes()


def test_write_mesh_refuses_values_a_format_cannot_hold(tmp_path):
    import meshtrim

    v = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    f = np.array([[0, 1, 2]])
    q = np.array([0.5, 1.0, 2.0], dtype=np.float32)
    with pytest.raises(meshtrim.MeshtrimError, match=r"'quality' cannot be written to OBJ.*write \.ply"):
        meshtrim.write_mesh(tmp_path / "a.obj", v, f, scalars={"quality": q})
    with pytest.raises(meshtrim.MeshtrimError, match="int64 values have no PLY type"):
        meshtrim.write_mesh(tmp_path / "a.ply", v, f, scalars={"label": np.arange(3)})
    with pytest.raises(meshtrim.MeshtrimError, match=r"expected an array of shape \(3,\)"):
        meshtrim.write_mesh(tmp_path / "a.ply", v, f, scalars={"q": q[:2]})
    nan = np.array([0.5, np.nan, 1.0], dtype=np.float32)
    with pytest.raises(meshtrim.MeshtrimError, match="'q' cannot be written to glTF"):
        meshtrim.write_mesh(tmp_path / "a.glb", v, f, scalars={"q": nan})
    big = np.array([0, 1 << 30, 2], dtype=np.uint32)
    with pytest.raises(meshtrim.MeshtrimError, match=r"within ±2\^24"):
        meshtrim.write_mesh(tmp_path / "a.gltf", v, f, scalars={"flags": big})
    assert not any(tmp_path.iterdir()), "nothing is written"
    # PLY holds both, NaN and all.
    meshtrim.write_mesh(tmp_path / "a.ply", v, f, scalars={"q": nan, "flags": big})
    raw = ply_vertices(tmp_path / "a.ply")[2]
    assert raw.dtype["flags"] == np.uint32 and np.array_equal(raw["flags"], big)
    assert np.array_equal(raw["q"], nan, equal_nan=True)


def test_a_name_ply_cannot_hold_is_reported_not_written(tmp_path):
    """glTF names its attributes freely; a PLY header token cannot hold a
    space. Such a value is left out of a PLY (the report names it), the
    others written, and the file reads."""
    scan = trimesh.load(str(FIXTURES / "blade_jagged.stl"))
    v, f = scan.vertices, scan.faces
    values = (v[:, 0] - v[:, 0].min()).astype(np.float32)
    glb = tmp_path / "scan.glb"
    attributes = {"_good": values, "_two words": values}
    trimesh.Trimesh(vertices=v, faces=f, vertex_attributes=attributes, process=False).export(str(glb))
    out, report = tmp_path / "out.ply", tmp_path / "r.json"
    result = run_meshtrim("clean", glb, out, "--report", report)
    r = json.loads(report.read_text())
    assert r["vertex_attributes"] == ["good"] and r["vertex_attributes_not_written"] == ["two words"], r
    assert "good (kept vertices'" in result.stdout and "two words not written" in result.stdout, result.stdout
    assert ply_vertices(out)[2].dtype.names == ("x", "y", "z", "good")
