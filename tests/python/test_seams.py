"""Scans stored with their vertices split along a seam, as glTF must store
a texture chart's border or a hard edge and PLY exports often do, written
by PyMeshLab and trimesh: `clean` cleans them as one surface, and each
side keeps its own attributes in the output.

The scan is MeshLab's range map face000, its faces right of the middle
given their own copies of the vertices they share with the left ones."""

from __future__ import annotations

import json

import numpy as np
import pymeshlab
import pytest
import trimesh

from meshtrim_cli import ROOT, run_meshtrim, shared_data

BLUE, RED = [0.0, 0.0, 1.0, 1.0], [1.0, 0.0, 0.0, 1.0]


@pytest.fixture(scope="module")
def scan():
    """face000's vertices and faces, and the same split down the middle:
    (vertices, faces, whether each face is right of the middle)."""
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(shared_data("meshlab_scans/face000.ply")))
    v, f = ms.current_mesh().vertex_matrix(), ms.current_mesh().face_matrix()
    right = v[f].mean(axis=1)[:, 0] > np.median(v[:, 0])
    seam = np.intersect1d(np.unique(f[right]), np.unique(f[~right]))
    assert len(seam) > 300
    copy = np.arange(len(v))
    copy[seam] = len(v) + np.arange(len(seam))
    faces = f.copy()
    faces[right] = copy[f[right]]
    return (v, f), (np.vstack([v, v[seam]]), faces, right)


def save(path, vertices, faces, colours=None):
    """A PLY written by PyMeshLab, vertex colours only if given."""
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertices, faces, v_color_matrix=colours) if colours is not None else pymeshlab.Mesh(vertices, faces))
    ms.save_current_mesh(str(path), save_vertex_color=colours is not None, save_vertex_quality=False, save_vertex_flag=False)


def boundary_edges(path, merge=False):
    """PyMeshLab's count of border edges, after merging the vertices that
    share a position if asked."""
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(path))
    if merge:
        ms.meshing_merge_close_vertices(threshold=pymeshlab.PercentageValue(0))
    return ms.get_topological_measures()["boundary_edges"], ms.current_mesh().vertex_number()


def side_colours(vertices, faces, right):
    colours = np.tile(BLUE, (len(vertices), 1))
    colours[np.unique(faces[right])] = RED
    return colours


def test_a_split_scan_is_cleaned_to_the_whole_scans_bytes(scan, tmp_path):
    """Without stitching the seam was border to the cleanup (46 loops
    instead of 44, 10,043 faces replaced instead of 8,143). Now the split
    scan gives the whole scan's output byte for byte, and the report
    counts the seam's edges as PyMeshLab counts the extra border."""
    (v, f), (vs, fs, _) = scan
    whole, split = tmp_path / "whole.ply", tmp_path / "split.ply"
    save(whole, v, f)
    save(split, vs, fs)
    extra = boundary_edges(split)[0] - boundary_edges(whole)[0]
    assert extra > 600, "PyMeshLab sees the seam as border"
    run_meshtrim("clean", whole, tmp_path / "whole.stl")
    report = json.loads(run_meshtrim("clean", split, tmp_path / "split.stl", "--json").stdout)
    assert (tmp_path / "split.stl").read_bytes() == (tmp_path / "whole.stl").read_bytes()
    assert report["seam_edges_stitched"] * 2 == extra
    text = run_meshtrim("clean", split, tmp_path / "again.stl").stdout
    assert f"seams stitched       {extra // 2} edges" in text


def mixed_faces(vertices, faces, colours_bytes):
    red = colours_bytes[faces][..., 0] == 255
    return ~(red.all(axis=1) | ~red.any(axis=1))


def check_sides(out_v, out_f, out_c, src_v, src_f, whole_out):
    """Each side keeps its colour: the output's faces are all red or all
    blue but for a few of the new ones laid along the seam where it meets
    the border (input faces kept keep their side); merged, the output is the whole scan's; split, it has a
    vertex per side at the seam's positions."""
    mixed = mixed_faces(out_v, out_f, out_c)
    corners = lambda v, f: {tuple(sorted(map(tuple, v[face].tolist()))) for face in f}
    input_faces = corners(src_v, src_f)
    new = np.array([tuple(sorted(map(tuple, out_v[face].tolist()))) not in input_faces for face in out_f])
    # Measured: 6 of 166,233, all new faces laid along the seam where it
    # meets the border (one of them joins three of the seam's vertices).
    assert mixed.sum() <= 10 and not (mixed & ~new).any(), (mixed.sum(), (mixed & ~new).sum())
    red = out_c[out_f][..., 0] == 255
    assert red.all(axis=1).sum() > 80_000 and (~red).all(axis=1).sum() > 80_000
    positions, counts = np.unique(out_v, axis=0, return_counts=True)
    assert counts.max() == 2 and (counts == 2).sum() > 400
    assert len(out_f) == len(whole_out[1])
    assert len(positions) == len(np.unique(whole_out[0], axis=0))


def test_each_side_of_the_seam_keeps_its_colour_in_ply(scan, tmp_path):
    (v, f), (vs, fs, right) = scan
    split = tmp_path / "split.ply"
    save(split, vs, fs, side_colours(vs, fs, right))
    save(tmp_path / "whole.ply", v, f)
    run_meshtrim("clean", split, tmp_path / "out.ply")
    run_meshtrim("clean", tmp_path / "whole.ply", tmp_path / "whole_out.ply")
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(tmp_path / "out.ply"))
    m = ms.current_mesh()
    out_c = np.rint(m.vertex_color_matrix() * 255).astype(int)
    whole = pymeshlab.MeshSet()
    whole.load_new_mesh(str(tmp_path / "whole_out.ply"))
    whole_out = (whole.current_mesh().vertex_matrix(), whole.current_mesh().face_matrix())
    check_sides(m.vertex_matrix(), m.face_matrix(), out_c, vs, fs, whole_out)
    assert boundary_edges(tmp_path / "out.ply", merge=True) == boundary_edges(tmp_path / "whole_out.ply")


def test_each_side_of_the_seam_keeps_its_colour_in_gltf(scan, tmp_path):
    """The same scan exported by trimesh to GLB (vertices as given, colours
    as COLOR_0), cleaned to GLB and read back by trimesh's glTF reader."""
    (v, f), (vs, fs, right) = scan
    colours = (side_colours(vs, fs, right) * 255).astype(np.uint8)
    mesh = trimesh.Trimesh(vs, fs, vertex_colors=colours, process=False)
    assert len(mesh.vertices) == len(vs)
    split = tmp_path / "split.glb"
    mesh.export(split)
    save(tmp_path / "whole.ply", v, f)
    run_meshtrim("clean", split, tmp_path / "out.glb")
    run_meshtrim("clean", tmp_path / "whole.ply", tmp_path / "whole_out.glb")
    from trimesh.exchange import gltf

    def read(path):
        with open(path, "rb") as file:
            (g,) = gltf.load_glb(file)["geometry"].values()
        return np.asarray(g["vertices"]), np.asarray(g["faces"]), np.asarray(g.get("vertex_colors", []))

    out_v, out_f, out_c = read(tmp_path / "out.glb")
    whole_v, whole_f, _ = read(tmp_path / "whole_out.glb")
    # glTF stores f32: the input's positions as trimesh wrote them.
    check_sides(out_v, out_f, out_c.astype(int), vs.astype(np.float32).astype(float), fs, (whole_v, whole_f))


def test_a_triangle_soup_is_cleaned_as_the_welded_mesh():
    """trimesh's STL loading with `process=False` gives each triangle its
    own corners, every edge a seam: the package's `clean` stitches them
    and gives the faces it gives the mesh trimesh welds."""
    import meshtrim

    stl = ROOT / "fixtures" / "meshes" / "blade_jagged.stl"
    soup = trimesh.load(str(stl), process=False)
    welded = trimesh.load(str(stl))
    assert len(soup.vertices) == 3 * len(soup.faces) > 5 * len(welded.vertices)
    out_soup = meshtrim.clean(np.asarray(soup.vertices), np.asarray(soup.faces))
    out_welded = meshtrim.clean(np.asarray(welded.vertices), np.asarray(welded.faces))

    def triangles(v, f):
        return {tuple(sorted(map(tuple, v[face].tolist()))) for face in f}

    assert triangles(*out_soup[:2]) == triangles(*out_welded[:2])
    edges = len(trimesh.grouping.group_rows(welded.edges_sorted, require_count=2))
    assert out_soup[2]["seam_edges_stitched"] == edges
