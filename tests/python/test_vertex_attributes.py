"""Vertex normals and colours carried from the input to the output, read
back by PyMeshLab and trimesh, and checked against an independent
carrying: Open3D's closest point on the input surface and its
barycentric coordinates there.

The inputs are PyMeshLab's own: a cloud whose colours vary along the
blade, meshed by PyMeshLab's screened Poisson (which gives the mesh
normals and colours of its own), and the jagged blade scan coloured
the same way."""

from __future__ import annotations

import json
import os
import subprocess

import numpy as np
import pymeshlab
import pytest
import trimesh

from carrying import expected_at, kept_and_new
from meshtrim_cli import MESHTRIM, ROOT, run_meshtrim, shared_data

FIXTURES = ROOT / "fixtures" / "meshes"


def colour_by_position(v):
    """RGBA in 0..1: red along x, blue along y, a fixed green."""
    c = np.ones((len(v), 4))
    c[:, 0] = (v[:, 0] - v[:, 0].min()) / np.ptp(v[:, 0])
    c[:, 1] = 0.5
    c[:, 2] = (v[:, 1] - v[:, 1].min()) / np.ptp(v[:, 1])
    return c


@pytest.fixture(scope="module")
def coloured(tmp_path_factory):
    """A coloured cloud and its screened-Poisson mesh (normals and colours
    from PyMeshLab), and the jagged blade scan coloured by position."""
    d = tmp_path_factory.mktemp("coloured")
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(FIXTURES / "blade_small.ply"))
    m = ms.current_mesh()
    v = m.vertex_matrix()
    ms.add_mesh(
        pymeshlab.Mesh(vertex_matrix=v, v_normals_matrix=m.vertex_normal_matrix(), v_color_matrix=colour_by_position(v)),
        "cloud",
    )
    ms.save_current_mesh(str(d / "cloud.ply"), save_vertex_color=True, save_vertex_normal=True)
    ms.generate_surface_reconstruction_screened_poisson(depth=8)
    assert ms.current_mesh().has_vertex_color()
    ms.save_current_mesh(str(d / "poisson.ply"), save_vertex_color=True, save_vertex_normal=True)

    scan = pymeshlab.MeshSet()
    scan.load_new_mesh(str(FIXTURES / "blade_jagged.stl"))
    s = scan.current_mesh()
    sv = s.vertex_matrix()
    scan.add_mesh(pymeshlab.Mesh(vertex_matrix=sv, face_matrix=s.face_matrix(), v_color_matrix=colour_by_position(sv)), "scan")
    scan.compute_normal_per_vertex()
    scan.save_current_mesh(str(d / "scan.ply"), save_vertex_color=True, save_vertex_normal=True)
    return d


def load(path):
    """Vertices, faces, normals and colours (RGBA bytes) as PyMeshLab
    reads them."""
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(path))
    m = ms.current_mesh()
    colours = np.rint(m.vertex_color_matrix() * 255).astype(int) if m.has_vertex_color() else None
    return m.vertex_matrix(), m.face_matrix(), m.vertex_normal_matrix(), colours


def check_carried(src, out):
    """Kept vertices keep their normals (at float32) and colours exactly;
    new ones have the colours and normal directions trimesh's carrying
    gives, within a colour step and 1e-4 radians."""
    v_in, f_in, n_in, c_in = load(src)
    v_out, f_out, n_out, c_out = load(out)
    assert c_out is not None, "the output has no colours"
    out_kept, in_kept, new = kept_and_new(v_in, v_out)
    assert len(new) > 50 and len(out_kept) > 500, (len(new), len(out_kept))
    assert np.array_equal(c_out[out_kept], c_in[in_kept])
    assert np.array_equal(n_out[out_kept], n_in[in_kept].astype(np.float32))

    want = expected_at(v_in, f_in, c_in.astype(float), v_out[new])
    assert np.abs(c_out[new] - want).max() <= 1.0, np.abs(c_out[new] - want).max()
    # Not a copy of the nearest vertex's: most new colours are blends.
    assert (np.abs(c_out[new] - want) <= 0.5 + 1e-9).mean() > 0.95
    want_n = expected_at(v_in, f_in, n_in, v_out[new])
    unit = lambda a: a / np.linalg.norm(a, axis=1, keepdims=True)
    cosines = np.einsum("ij,ij->i", unit(want_n), unit(n_out[new]))
    assert cosines.min() > np.cos(1e-4), cosines.min()
    return v_in, n_in, v_out, n_out, new


def test_trim_carries_poisson_normals_and_colours(coloured, tmp_path):
    out, report = tmp_path / "out.ply", tmp_path / "r.json"
    run_meshtrim(coloured / "poisson.ply", coloured / "cloud.ply", out, "--report", report)
    # PyMeshLab saves screened Poisson's density as the vertex quality.
    assert json.loads(report.read_text())["vertex_attributes"] == ["normals", "colours", "quality"]
    _, n_in, _, n_out, new = check_carried(coloured / "poisson.ply", out)
    # Screened Poisson's normals are not unit; the new ones are of the
    # same kind (their lengths blended), not unit vectors among them.
    lengths_in, lengths_new = np.linalg.norm(n_in, axis=1), np.linalg.norm(n_out[new], axis=1)
    assert lengths_in.min() > 1.5 and lengths_new.min() > 0.8 * lengths_in.min(), (lengths_in.min(), lengths_new.min())


def test_clean_carries_a_scans_normals_and_colours(coloured, tmp_path):
    out = tmp_path / "out.ply"
    run_meshtrim("clean", coloured / "scan.ply", out)
    check_carried(coloured / "scan.ply", out)


def test_clean_carries_a_real_colour_scans_colours(tmp_path):
    """Laurana50k, MeshLab's sample bust scanned in colour (RGBA per
    vertex, no normals): the cleaned base keeps the scan's colours."""
    src, out, report = shared_data("meshlab_scans/Laurana50k.ply"), tmp_path / "out.ply", tmp_path / "r.json"
    run_meshtrim("clean", src, out, "--report", report)
    assert json.loads(report.read_text())["vertex_attributes"] == ["colours"]
    v_in, f_in, _, c_in = load(src)
    v_out, _, _, c_out = load(out)
    out_kept, in_kept, new = kept_and_new(v_in, v_out)
    assert len(new) > 100, len(new)
    assert np.array_equal(c_out[out_kept], c_in[in_kept])
    want = expected_at(v_in, f_in, c_in.astype(float), v_out[new])
    assert np.abs(c_out[new] - want).max() <= 1.0, np.abs(c_out[new] - want).max()


def test_mesh_takes_each_vertexs_from_the_nearest_point(coloured, tmp_path):
    from scipy.spatial import cKDTree

    out = tmp_path / "out.ply"
    run_meshtrim("mesh", coloured / "cloud.ply", out)
    v_in, _, n_in, c_in = load(coloured / "cloud.ply")
    v_out, _, n_out, c_out = load(out)
    _, nearest = cKDTree(v_in).query(v_out)
    assert np.array_equal(c_out, c_in[nearest])
    assert np.array_equal(n_out, n_in[nearest].astype(np.float32))


def load_gltf_with_trimesh(path):
    """Vertices, normals and colours (RGBA bytes) as trimesh's glTF
    reader reads them (its raw output: a `Trimesh` built from it replaces
    some normals by its own)."""
    from trimesh.exchange import gltf

    with open(path, "rb") as f:
        read = gltf.load_glb(f) if path.suffix == ".glb" else gltf.load_gltf(f)
    (geometry,) = read["geometry"].values()
    colours = np.asarray(geometry["vertex_colors"]).astype(int)
    return np.asarray(geometry["vertices"]), np.asarray(geometry["vertex_normals"]), colours


@pytest.mark.parametrize("ext", ["obj", "glb", "gltf"])
def test_other_formats_hold_the_same_attributes(coloured, tmp_path, ext):
    """OBJ (`v x y z r g b`, `vn`) read by PyMeshLab, glTF (COLOR_0,
    NORMAL) by trimesh: the PLY output's colours, and its normals'
    directions (glTF holds unit normals)."""
    ply, other = tmp_path / "out.ply", tmp_path / f"out.{ext}"
    for out in (ply, other):
        run_meshtrim(coloured / "poisson.ply", coloured / "cloud.ply", out)
    v_ply, _, n_ply, c_ply = load(ply)
    if ext == "obj":
        vertices, _, normals, colours = load(other)
    else:
        vertices, normals, colours = load_gltf_with_trimesh(other)
    assert len(vertices) == len(v_ply)
    assert np.allclose(vertices, v_ply, rtol=0, atol=1e-4)
    assert np.abs(colours[:, :3] - c_ply[:, :3]).max() <= 1, np.abs(colours[:, :3] - c_ply[:, :3]).max()
    unit = lambda a: a / np.linalg.norm(a, axis=1, keepdims=True)
    assert np.einsum("ij,ij->i", unit(normals), unit(n_ply)).min() > 1 - 1e-6


def test_stl_output_says_what_it_could_not_hold(coloured, tmp_path):
    out, report = tmp_path / "out.stl", tmp_path / "r.json"
    result = run_meshtrim(coloured / "poisson.ply", coloured / "cloud.ply", out, "--report", report)
    assert "normals, colours, quality not written" in result.stdout, result.stdout
    r = json.loads(report.read_text())
    assert r["vertex_attributes_not_written"] == ["normals", "colours", "quality"] and "vertex_attributes" not in r


def test_carried_attributes_do_not_depend_on_threads(coloured, tmp_path):
    outputs = []
    for threads in ["1", "2"]:
        out = tmp_path / f"out{threads}.ply"
        env = dict(os.environ, RAYON_NUM_THREADS=threads)
        subprocess.run(
            [str(MESHTRIM), "clean", str(coloured / "scan.ply"), str(out)], check=True, env=env, capture_output=True
        )
        outputs.append(out.read_bytes())
    assert outputs[0] == outputs[1]


# --------------------------------------------------------------------------
# The Python package: the same carrying, and the adapters.


def test_python_carry_and_write_give_the_clis_bytes(coloured, tmp_path):
    import meshtrim

    for job in ("trim", "clean"):
        src = coloured / ("poisson.ply" if job == "trim" else "scan.ply")
        cli = tmp_path / f"{job}_cli.ply"
        if job == "trim":
            run_meshtrim(src, coloured / "cloud.ply", cli)
        else:
            run_meshtrim("clean", src, cli)
        v, f, attrs = meshtrim.read_mesh(src, attributes=True)
        assert attrs.normals is not None and attrs.colours.shape == (len(v), 4)
        if job == "trim":
            out_v, out_f, _ = meshtrim.trim(v, f, meshtrim.read_cloud(coloured / "cloud.ply"))
        else:
            out_v, out_f, _ = meshtrim.clean(v, f)
        py = tmp_path / f"{job}_py.ply"
        meshtrim.write_mesh(
            py,
            out_v,
            out_f,
            normals=meshtrim.carry(v, f, attrs.normals, out_v, out_f, normals=True),
            colours=meshtrim.carry(v, f, attrs.colours, out_v, out_f),
            scalars={k: meshtrim.carry(v, f, a, out_v, out_f).astype(a.dtype) for k, a in attrs.scalars.items()},
        )
        assert py.read_bytes() == cli.read_bytes(), job
        # The same in one call.
        one = tmp_path / f"{job}_one.ply"
        meshtrim.write_mesh_carrying(one, out_v, out_f, v, f, attrs)
        assert one.read_bytes() == cli.read_bytes(), job


def test_python_carry_shapes_and_errors(coloured):
    import meshtrim

    v, f, attrs = meshtrim.read_mesh(coloured / "poisson.ply", attributes=True)
    quality = v[:, 0] * 2.0
    out = meshtrim.carry(v, f, quality, v[:10] + 1e-3)
    assert out.shape == (10,)
    # The value is linear in position, so blending reproduces it closely.
    assert np.allclose(out, (v[:10, 0] + 1e-3) * 2.0, atol=0.05)
    assert np.array_equal(meshtrim.carry(v, None, quality, v[:5]), quality[:5]), "a cloud: the point's own"
    with pytest.raises(meshtrim.MeshtrimError, match="values"):
        meshtrim.carry(v, f, quality[:-1], v)
    with pytest.raises(meshtrim.MeshtrimError, match="normals have 3 columns"):
        meshtrim.carry(v, f, attrs.colours, v, normals=True)
    with pytest.raises(meshtrim.MeshtrimError, match="colours"):
        meshtrim.write_mesh("/tmp/never.ply", v, f, colours=np.zeros((len(v), 2)))
    with pytest.raises(meshtrim.MeshtrimError, match="STL holds no vertex normals, colours or texture coordinates"):
        meshtrim.write_mesh("/tmp/never.stl", v, f, colours=attrs.colours)
    huge = attrs.normals.copy()
    huge[7] = [1e300, 0, 0]
    with pytest.raises(meshtrim.MeshtrimError, match="vertex 7's normal .* is not finite in PLY"):
        meshtrim.write_mesh("/tmp/never.ply", v, f, normals=huge)
    nan = attrs.colours.copy()
    nan[3, 1] = np.nan
    with pytest.raises(meshtrim.MeshtrimError, match="vertex 3 has a non-finite colour"):
        meshtrim.write_mesh("/tmp/never.ply", v, f, colours=nan)
    _, _, plain = meshtrim.read_mesh(FIXTURES / "blade_jagged.stl", attributes=True)
    assert plain == meshtrim.VertexAttributes(None, None)


def test_pymeshlab_adapter_carries_colours_normals_and_quality(coloured, tmp_path):
    import meshtrim.pymeshlab

    cli = tmp_path / "cli.ply"
    run_meshtrim(coloured / "poisson.ply", coloured / "cloud.ply", cli)
    _, _, n_cli, c_cli = load(cli)
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(coloured / "poisson.ply"))
    ms.load_new_mesh(str(coloured / "cloud.ply"))
    assert ms.mesh(0).has_vertex_scalar()
    meshtrim.pymeshlab.trim(ms, 0, 1)
    out = ms.current_mesh()
    assert out.has_vertex_color() and out.has_vertex_scalar()
    assert np.abs(np.rint(out.vertex_color_matrix() * 255) - c_cli).max() <= 1
    # PyMeshLab's Mesh() replaces the normals of border vertices by its
    # own (measured: exactly the 880 border vertices here); the others
    # are meshtrim's.
    faces = out.face_matrix()
    edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    unique, counts = np.unique(edges, axis=0, return_counts=True)
    inner = np.ones(out.vertex_number(), dtype=bool)
    inner[unique[counts == 1].ravel()] = False
    assert inner.sum() > 0.8 * len(inner)
    assert np.allclose(out.vertex_normal_matrix()[inner], n_cli[inner], atol=1e-5)
    # Poisson's density, carried: between the input's extremes.
    q_in, q_out = ms.mesh(0).vertex_scalar_array(), out.vertex_scalar_array()
    assert q_in.min() - 1e-9 <= q_out.min() and q_out.max() <= q_in.max() + 1e-9 and np.ptp(q_out) > 0


def test_open3d_and_trimesh_adapters_carry_colours(coloured):
    import open3d as o3d
    import meshtrim.open3d
    import meshtrim.trimesh

    scan = o3d.io.read_triangle_mesh(str(coloured / "scan.ply"))
    assert scan.has_vertex_colors() and scan.has_vertex_normals()
    cleaned = meshtrim.open3d.clean(scan)
    assert cleaned.has_vertex_colors() and cleaned.has_vertex_normals()
    v, f, attrs = meshtrim.read_mesh(coloured / "scan.ply", attributes=True)
    out_v, out_f = np.asarray(cleaned.vertices), np.asarray(cleaned.triangles)
    want = meshtrim.carry(v, f, attrs.colours[:, :3], out_v, out_f)
    assert np.abs(np.asarray(cleaned.vertex_colors) - want).max() < 1e-6

    tm = trimesh.load(coloured / "scan.ply", process=False)
    assert tm.visual.kind == "vertex"
    out = meshtrim.trimesh.clean(tm)
    assert out.visual.kind == "vertex"
    got = np.asarray(out.visual.vertex_colors, dtype=float)[:, :3]
    assert np.abs(got - want * 255).max() <= 1.0


def test_each_side_of_a_seam_keeps_its_colour(coloured, tmp_path):
    """The Poisson mesh split down the middle into two colour charts, as
    a textured or hard-edged mesh is: the faces right of the middle get
    their own copies of the vertices they share with the left ones, and
    the right side is red. Trimmed, every output face is a piece of one
    input face, so its three corners are of one side: all red or none,
    kept and new vertices alike (position alone would give the seam's
    right copies the left colours, and the right faces along the seam
    mixed corners)."""
    v, f, n_in, c_in = load(coloured / "poisson.ply")
    middle = np.median(v[:, 0])
    right = v[f].mean(axis=1)[:, 0] > middle
    seam = np.intersect1d(np.unique(f[right]), np.unique(f[~right]))
    assert len(seam) > 50
    copy = np.arange(len(v))
    copy[seam] = len(v) + np.arange(len(seam))
    vertices = np.vstack([v, v[seam]])
    colours = np.vstack([c_in, c_in[seam]]) / 255.0
    normals = np.vstack([n_in, n_in[seam]])
    faces = f.copy()
    faces[right] = copy[f[right]]
    colours[np.unique(faces[right])] = [1.0, 0.0, 0.0, 1.0]
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertices, faces, v_normals_matrix=normals, v_color_matrix=colours))
    split = tmp_path / "split.ply"
    ms.save_current_mesh(str(split), save_vertex_color=True, save_vertex_normal=True)
    assert len(load(split)[0]) == len(vertices), "PyMeshLab kept the seam's copies"
    out = tmp_path / "out.ply"
    run_meshtrim(split, coloured / "cloud.ply", out)
    _, f_out, _, c_out = load(out)
    red = c_out[f_out][..., 1] == 0
    all_red, none_red = red.all(axis=1), ~red.any(axis=1)
    assert all_red.sum() > 1000 and none_red.sum() > 1000, (all_red.sum(), none_red.sum())
    mixed = ~(all_red | none_red)
    assert not mixed.any(), mixed.sum()


def test_a_nan_normal_in_the_input_does_not_stop_the_job(coloured, tmp_path):
    """A PLY whose normals include NaN (written here by hand: PyMeshLab
    replaces a NaN normal by one of its own): cleaned all the same, the
    NaN carried as a zero normal."""
    v, f, n, _ = load(coloured / "scan.ply")
    plain = tmp_path / "plain.ply"
    run_meshtrim("clean", coloured / "scan.ply", plain)
    kept = {tuple(p) for p in load(plain)[0].tolist()}
    inner = next(i for i, p in enumerate(v.tolist()) if tuple(p) in kept)
    n = n.copy()
    n[inner] = np.nan
    src = tmp_path / "nan.ply"
    header = (
        f"ply\nformat ascii 1.0\nelement vertex {len(v)}\n"
        "property double x\nproperty double y\nproperty double z\n"
        "property float nx\nproperty float ny\nproperty float nz\n"
        f"element face {len(f)}\nproperty list uchar int vertex_indices\nend_header\n"
    )
    rows = [" ".join(map(repr, [*p, *q])) for p, q in zip(v.tolist(), n.tolist())]
    faces = [f"3 {a} {b} {c}" for a, b, c in f.tolist()]
    src.write_text(header + "\n".join(rows + faces) + "\n")
    out = tmp_path / "out.ply"
    run_meshtrim("clean", src, out)
    v_out, _, n_out, _ = load(out)
    assert np.isfinite(n_out).all()
    at = np.flatnonzero((v_out == v[inner]).all(axis=1))
    assert len(at) == 1 and (n_out[at[0]] == 0).all(), n_out[at]
