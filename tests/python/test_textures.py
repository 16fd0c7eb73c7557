"""Textured scans: a scan with texture coordinates and a material, written
by PyMeshLab as an OBJ (one `v` per vertex, a `vt` per distinct face
corner, so the vertices along a chart's border are read with two), is
cleaned with its texture: the kept faces keep their corners' texture
coordinates exactly, the new ones read the texture from the input's
surface on their own chart's side, and the material and its image are
found from the output by PyMeshLab and trimesh.

The scan is MeshLab's range map face000, mapped flat onto the image
(u, v from x, y) with the faces right of the middle moved along u (a
second chart, so a seam down the middle)."""

from __future__ import annotations

import hashlib
import json

import numpy as np
import PIL.Image
import pymeshlab
import pytest
import trimesh

from meshtrim_cli import ROOT, run_meshtrim, shared_data

SCALE, SHIFT = 0.7, 0.25
"""The flat map: uv = SCALE * ((x, y) - lowest) / extent, plus SHIFT along
u on the right chart."""


@pytest.fixture(scope="module")
def textured(tmp_path_factory):
    """face000 mapped onto a 256-pixel image, written by PyMeshLab as
    `in/face.obj` (with `face.obj.mtl` and `face_tex.png`); returns the
    directory and the map (lowest corner, extent, middle x)."""
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(shared_data("meshlab_scans/face000.ply")))
    v, f = ms.current_mesh().vertex_matrix(), ms.current_mesh().face_matrix()
    middle = np.median(v[:, 0])
    lowest, extent = v.min(axis=0), np.ptp(v[:, :2], axis=0).max()
    right = v[f].mean(axis=1)[:, 0] > middle
    wedges = flat_map(v[f], lowest, extent, right[:, None]).reshape(-1, 2)
    colours = np.ones((len(v), 4))
    colours[:, 0], colours[:, 2] = 0.5 + 0.4 * np.sin(v[:, 0]), 0.5 + 0.4 * np.cos(v[:, 1])
    out = pymeshlab.MeshSet()
    out.add_mesh(pymeshlab.Mesh(v, f, v_color_matrix=colours, w_tex_coords_matrix=wedges))
    out.compute_texmap_from_color(textname="face_tex.png", textw=256, texth=256)
    directory = tmp_path_factory.mktemp("textured") / "in"
    directory.mkdir()
    out.save_current_mesh(str(directory / "face.obj"), save_vertex_color=False)
    assert {p.name for p in directory.iterdir()} == {"face.obj", "face.obj.mtl", "face_tex.png"}
    return directory, (lowest, extent, middle)


def flat_map(points, lowest, extent, right):
    """The texture coordinates of `points` on the left chart, or the right
    one where `right`."""
    shift = np.array([SHIFT, 0.0]) * np.asarray(right, dtype=float)[..., None]
    return SCALE * ((points[..., :2] - lowest[:2]) / extent + shift)


def wedges(path):
    """PyMeshLab's reading: each face's corner positions and texture
    coordinates, and the names of the mesh's textures."""
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(path))
    m = ms.current_mesh()
    assert m.has_wedge_tex_coord(), path
    corners = m.vertex_matrix()[m.face_matrix()]
    return corners, m.wedge_tex_coord_matrix().reshape(-1, 3, 2), list(m.textures())


def chart_error(corners, uv, the_map):
    """Per face, how far its corners' coordinates are from the flat map of
    the nearer chart (one chart for all three corners)."""
    lowest, extent, _ = the_map
    return np.minimum(
        *[np.abs(uv - flat_map(corners, lowest, extent, side)).max(axis=(1, 2)) for side in (False, True)]
    )


def assert_texture_kept(source, out, the_map):
    """As PyMeshLab reads them: the output names the image copied into its
    folder, and its faces' coordinates are kept (`assert_wedges_kept`)."""
    corners, uv, textures = wedges(out)
    assert textures == ["face_textures/face_tex.png"], textures
    assert_wedges_kept(wedges(source)[:2], (corners, uv), the_map)


def assert_wedges_kept(source, out, the_map):
    """Of the faces' corners and their texture coordinates (`(corners,
    uv)`, `(m, 3, 3)` and `(m, 3, 2)`), every face kept from the source
    has its corners' exact coordinates; the new ones are on their chart's
    flat map (0.002 at the 99th percentile) but for at most 10 faces that
    read both charts."""
    (corners_in, uv_in), (corners, uv) = source, out
    by_corners = {c.tobytes(): w for c, w in zip(corners_in, uv_in)}
    kept = [i for i, c in enumerate(corners) if c.tobytes() in by_corners]
    assert len(kept) > 0.9 * len(corners)
    assert all(np.array_equal(uv[i], by_corners[corners[i].tobytes()]) for i in kept)
    error = chart_error(corners, uv, the_map)
    assert np.percentile(error, 99) < 2e-3, np.percentile(error, 99)
    assert (error > SCALE * SHIFT / 4).sum() <= 10, (error > SCALE * SHIFT / 4).sum()


def digest(directory):
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in directory.iterdir()}


def test_a_textured_obj_is_cleaned_with_its_texture(textured, tmp_path):
    """Measured: 158,116 faces kept, every one with its corners' exact
    coordinates; 415 seam edges stitched (the seam is one surface, as
    with the whole scan); on the new faces the coordinates are the flat
    map's within 0.0009 at the 99th percentile (a new vertex reads the
    input's surface at its closest point), and 6 of 166,233 faces read
    both charts (laid across the seam where it meets the border; a chart
    is 0.175 away from the other)."""
    directory, the_map = textured
    before = digest(directory)
    out = tmp_path / "out" / "face.obj"
    report = json.loads(run_meshtrim("clean", directory / "face.obj", out, "--json").stdout)
    assert report["seam_edges_stitched"] == 415, report
    assert "texture coordinates" in report["vertex_attributes"], report
    assert "material" in report["vertex_attributes"], report
    assert digest(directory) == before, "the input's files are untouched"
    # The output's own library, beside it, with a copy of the image in
    # the output's own folder.
    assert {p.name for p in out.parent.iterdir()} == {"face.obj", "face.mtl", "face_textures"}
    image = out.parent / "face_textures" / "face_tex.png"
    assert image.read_bytes() == (directory / "face_tex.png").read_bytes()

    assert_texture_kept(directory / "face.obj", out, the_map)

    # trimesh finds the image through the output's library.
    loaded = trimesh.load(str(out), process=False)
    assert loaded.visual.material.image.size == (256, 256)


def test_written_beside_the_input_the_library_is_shared(textured, tmp_path):
    """An output in the input's directory names the input's own library
    and writes no other file but itself."""
    directory, _ = textured
    before = digest(directory)
    out = directory / "cleaned.obj"
    try:
        run_meshtrim("clean", directory / "face.obj", out)
        assert "mtllib face.obj.mtl\n" in out.read_text()
        assert {p.name for p in directory.iterdir()} == set(before) | {"cleaned.obj"}
        assert wedges(out)[2] == ["face_tex.png"]
    finally:
        out.unlink(missing_ok=True)
    assert digest(directory) == before


def test_texture_coordinates_in_ply_and_gltf(textured, tmp_path):
    """PLY (MeshLab's `texture_u`, `texture_v`, read by PyMeshLab) and
    GLB (`TEXCOORD_0`, v down the image; Open3D turns it up) hold the same
    coordinates as the OBJ output, vertex for vertex."""
    import open3d as o3d

    directory, the_map = textured
    for name in ["face.obj", "face.ply", "face.glb"]:
        run_meshtrim("clean", directory / "face.obj", tmp_path / name)
    obj = trimesh.load(str(tmp_path / "face.obj"), process=False)

    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(tmp_path / "face.ply"))
    ply = ms.current_mesh()
    assert ply.has_vertex_tex_coord()
    uv = ply.vertex_tex_coord_matrix()
    corners = ply.vertex_matrix()[ply.face_matrix()]
    assert chart_error(corners, uv[ply.face_matrix()], the_map).max() < 0.2
    # The OBJ's vertices are the PLY's, in order (trimesh keeps them).
    assert np.array_equal(obj.vertices, ply.vertex_matrix())
    assert np.abs(obj.visual.uv - uv).max() < 1e-6

    glb = o3d.io.read_triangle_mesh(str(tmp_path / "face.glb"))
    corner_uv = np.asarray(glb.triangle_uvs).reshape(-1, 3, 2)
    # Open3D renumbers the vertices but keeps the faces' order.
    glb_corners = np.asarray(glb.vertices)[np.asarray(glb.triangles)]
    assert np.abs(glb_corners - corners).max() < 1e-4 * np.abs(corners).max()
    # Open3D turns v up again, as the OBJ and PLY store it.
    assert np.abs(corner_uv - uv[ply.face_matrix()]).max() < 1e-6


def test_a_gltf_scan_keeps_its_texture_coordinates(textured, tmp_path):
    """A GLB written by trimesh with TEXCOORD_0 (v down the image) is
    cleaned to an OBJ whose coordinates trimesh reads as it read the
    input's: the kept vertices' exactly (to f32)."""
    directory, the_map = textured
    scan = trimesh.load(str(directory / "face.obj"), process=False)
    glb = tmp_path / "scan.glb"
    scan.export(str(glb))
    out = tmp_path / "out.obj"
    report = json.loads(run_meshtrim("clean", glb, out, "--json").stdout)
    assert "texture coordinates" in report["vertex_attributes"], report
    cleaned = trimesh.load(str(out), process=False)
    uv_of = {p.astype(np.float32).tobytes(): t for p, t in zip(scan.vertices, scan.visual.uv)}
    kept = [(t, uv_of[p.astype(np.float32).tobytes()]) for p, t in zip(cleaned.vertices, cleaned.visual.uv)
            if p.astype(np.float32).tobytes() in uv_of]
    assert len(kept) > 0.9 * len(cleaned.vertices)
    got, want = np.array(kept).transpose(1, 0, 2)
    # Vertices at the seam have two coordinates; each must be one of them.
    assert np.mean(np.abs(got - want).max(axis=1) < 1e-6) > 0.99


COLOURS = {"left": (200, 30, 30), "right": (30, 30, 200)}
"""The halves' images' colours."""


def halves(material):
    """face000's left and right halves as a trimesh scene of two meshes,
    each with a material `material(name, image)` over an image of its
    colour (16 × 8 pixels); and the middle x."""
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(shared_data("meshlab_scans/face000.ply")))
    v, f = ms.current_mesh().vertex_matrix(), ms.current_mesh().face_matrix()
    middle = np.median(v[:, 0])
    right = v[f].mean(axis=1)[:, 0] > middle
    scene = trimesh.Scene()
    for name, side in [("left", ~right), ("right", right)]:
        half = trimesh.Trimesh(v, f[side], process=False)
        half.remove_unreferenced_vertices()
        image = PIL.Image.new("RGB", (16, 8), COLOURS[name])
        half.visual = trimesh.visual.TextureVisuals(uv=half.vertices[:, :2] / 1000.0, material=material(name, image))
        scene.add_geometry(half, geom_name=name)
    return scene, middle


def halves_as_obj(path):
    """The halves (`halves`) as trimesh exports them in OBJ, with
    `scan.mtl` and an image per material beside `path`; the middle x."""
    scene, middle = halves(lambda name, image: trimesh.visual.material.SimpleMaterial(image=image))
    text, assets = trimesh.exchange.obj.export_obj(scene, include_texture=True, return_texture=True, mtl_name="scan.mtl")
    path.write_text(text)
    for name, data in assets.items():
        (path.parent / name).write_bytes(data)
    return middle


def halves_as_glb(path):
    """The halves as trimesh exports them in GLB, two meshes with a
    PBR material each, the images embedded; the middle x."""
    scene, middle = halves(
        lambda name, image: trimesh.visual.material.PBRMaterial(name=name, baseColorTexture=image)
    )
    scene.export(str(path))
    return middle


def halves_as_ply(path):
    """The halves as PyMeshLab saves trimesh's OBJ of them in PLY: two
    `comment TextureFile`s and a `texnumber` per face; the middle x."""
    middle = halves_as_obj(path.with_suffix(".obj"))
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(path.with_suffix(".obj")))
    ms.save_current_mesh(str(path), save_face_color=False)
    header = path.read_bytes()[:600]
    assert header.count(b"comment TextureFile") == 2 and b"texnumber" in header, header
    return middle


def parts_by_material(path):
    """The mesh in `path` as meshes by material, as trimesh reads them,
    and how to find a part's image from its material: a GLB by trimesh
    itself, an OBJ grouped by material, and a PLY by PyMeshLab (which
    reads MeshLab's texture files) then saved by it as an OBJ."""
    if path.suffix == ".glb":
        return trimesh.load(str(path), process=False).geometry.values(), lambda m: m.baseColorTexture
    if path.suffix == ".ply":
        ms = pymeshlab.MeshSet()
        ms.load_new_mesh(str(path))
        assert len(ms.current_mesh().textures()) == 2, ms.current_mesh().textures()
        path = path.with_name(path.stem + "_by_meshlab.obj")
        ms.save_current_mesh(str(path))
    return trimesh.load(str(path), process=False, group_material=True).geometry.values(), lambda m: m.image


def faces_on_the_other_side(parts, middle, image_of):
    """How many faces of `parts` (meshes by material) lie on the other
    side of the middle than their material's image says, and how many
    faces there are."""
    wrong, faces = 0, 0
    for part in parts:
        image = image_of(part.visual.material)
        assert image.size == (16, 8)
        is_right = image.getpixel((0, 0))[:3] == COLOURS["right"]
        on_right = part.triangles_center[:, 0] > middle
        wrong += int((on_right != is_right).sum())
        faces += len(part.faces)
    return wrong, faces


def test_each_face_keeps_its_material(tmp_path):
    """Two materials, each with its own image (the scan's left and right
    halves, exported by trimesh as two objects, so the vertices along the
    middle are stored twice): every face of the output takes the
    material of the input face it lies on. Measured: 6 of 165,989 faces
    take the material of the other side of the middle, new faces laid
    across it where it meets the border."""
    middle = halves_as_obj(tmp_path / "scan.obj")

    out = tmp_path / "out" / "scan.obj"
    report = json.loads(run_meshtrim("clean", tmp_path / "scan.obj", out, "--json").stdout)
    assert report["seam_edges_stitched"] == 415, report
    by_material = trimesh.load(str(out), process=False, group_material=True).geometry
    assert len(by_material) == 2
    wrong, faces = faces_on_the_other_side(by_material.values(), middle, lambda m: m.image)
    assert faces == report["faces_out"]
    assert wrong <= 10, wrong


def test_the_python_package_carries_the_texture_as_the_cli_does(textured, tmp_path):
    """read_mesh gives the split vertices, their texture coordinates and
    the material; clean then write_mesh_carrying write the CLI's bytes
    (the OBJ, its library and the image)."""
    import meshtrim

    directory, _ = textured
    v, f, attributes = meshtrim.read_mesh(directory / "face.obj", attributes=True)
    assert attributes.texcoords.shape == (len(v), 2)
    assert attributes.material.names == ("material_0",)
    assert attributes.material.faces.shape == (len(f),)
    assert attributes.material.libraries[0].endswith("face.obj.mtl")
    out_v, out_f, _ = meshtrim.clean(v, f)
    written, not_written = meshtrim.write_mesh_carrying(tmp_path / "py" / "face.obj", out_v, out_f, v, f, attributes)
    assert written == ["normals", "texture coordinates", "material"] and not_written == [], (written, not_written)
    run_meshtrim("clean", directory / "face.obj", tmp_path / "cli" / "face.obj")
    for name in ["face.obj", "face.mtl", "face_textures/face_tex.png"]:
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes(), name
    # A material of the wrong length is refused, naming it.
    wrong = attributes._replace(material=attributes.material._replace(faces=attributes.material.faces[1:]))
    with pytest.raises(meshtrim.MeshtrimError, match="material.faces: expected"):
        meshtrim.write_mesh_carrying(tmp_path / "bad.obj", out_v, out_f, v, f, wrong)
    assert not (tmp_path / "bad.obj").exists()


def test_a_gltf_scan_keeps_its_materials_and_images(tmp_path):
    """A GLB by trimesh, the scan's halves two meshes of two materials
    with their own images: cleaned to GLB, each face keeps its half's
    material, and the materials and images are the input's (trimesh reads
    the same pixels). Measured: 6 of 165,989 faces take the other half's
    material, as with the OBJ."""
    scene, middle = halves(
        lambda name, image: trimesh.visual.material.PBRMaterial(name=name, baseColorTexture=image)
    )
    glb = tmp_path / "scan.glb"
    scene.export(str(glb))
    out = tmp_path / "out.glb"
    report = json.loads(run_meshtrim("clean", glb, out, "--json").stdout)
    assert "material" in report["vertex_attributes"], report
    cleaned = trimesh.load(str(out), process=False)
    assert len(cleaned.geometry) == 2, list(cleaned.geometry)
    parts = cleaned.geometry.values()
    wrong, faces = faces_on_the_other_side(parts, middle, lambda m: m.baseColorTexture)
    assert faces == report["faces_out"]
    assert wrong <= 10, wrong


def test_a_meshlab_ply_keeps_its_texture(textured, tmp_path):
    """The textured scan as PyMeshLab writes it in PLY: a `texcoord` list
    per face and `comment TextureFile`. Read by meshtrim as the OBJ is
    (a vertex split where its corners read two coordinates), cleaned to a
    PLY elsewhere: PyMeshLab finds the copied image and reads the same
    per-corner coordinates on every kept face (f32, as both files store
    them), and the seam is stitched as in the OBJ."""
    directory, the_map = textured
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(directory / "face.obj"))
    source = tmp_path / "in" / "face.ply"
    source.parent.mkdir()
    ms.save_current_mesh(str(source), save_vertex_color=False, save_face_color=False)
    (source.parent / "face_tex.png").write_bytes((directory / "face_tex.png").read_bytes())
    assert b"comment TextureFile face_tex.png" in source.read_bytes()[:400]
    out = tmp_path / "out" / "face.ply"
    report = json.loads(run_meshtrim("clean", source, out, "--json").stdout)
    assert report["seam_edges_stitched"] == 415, report
    assert {p.name for p in out.parent.iterdir()} == {"face.ply", "face_textures"}

    assert_texture_kept(source, out, the_map)


def test_a_meshlab_ply_with_two_textures_keeps_each_faces(tmp_path):
    """The two-material halves as PyMeshLab saves them in PLY (two
    `TextureFile`s and a `texnumber` per face): cleaned to PLY, each face
    keeps its half's image. Read back by PyMeshLab and saved by it as an
    OBJ, which trimesh groups by material: 6 of 165,989 faces are on the
    other half's image, as with the OBJ input."""
    middle = halves_as_obj(tmp_path / "scan.obj")
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(tmp_path / "scan.obj"))
    source = tmp_path / "scan.ply"
    ms.save_current_mesh(str(source), save_face_color=False)
    header = source.read_bytes()[:600]
    assert header.count(b"comment TextureFile") == 2 and b"texnumber" in header, header

    out = tmp_path / "out" / "scan.ply"
    report = json.loads(run_meshtrim("clean", source, out, "--json").stdout)
    assert "material" in report["vertex_attributes"], report
    back = pymeshlab.MeshSet()
    back.load_new_mesh(str(out))
    assert len(back.current_mesh().textures()) == 2
    back.save_current_mesh(str(tmp_path / "out" / "back.obj"))
    by_material = trimesh.load(str(tmp_path / "out" / "back.obj"), process=False, group_material=True).geometry
    wrong, faces = faces_on_the_other_side(by_material.values(), middle, lambda m: m.image)
    assert faces == report["faces_out"]
    assert wrong <= 10, wrong


WRITERS = {"obj": halves_as_obj, "glb": halves_as_glb, "ply": halves_as_ply}


@pytest.mark.parametrize(
    "source, target", [("obj", "glb"), ("obj", "ply"), ("glb", "obj"), ("glb", "ply"), ("ply", "obj"), ("ply", "glb")]
)
def test_materials_are_carried_to_another_format(source, target, tmp_path):
    """The two-material halves, written by trimesh (OBJ, GLB) or
    PyMeshLab (PLY), cleaned to another format: the materials are made the
    output's kind (MTL with the images in the output's folder, glTF's
    materials with the images embedded, MeshLab's texture files), and read
    back by trimesh and PyMeshLab each face is on its half's image but
    for the new faces laid across the middle. Measured: 6 of 165,989
    faces, for every pair of formats, as without a change of format."""
    middle = WRITERS[source](tmp_path / f"scan.{source}")
    out = tmp_path / "out" / f"scan.{target}"
    report = json.loads(run_meshtrim("clean", tmp_path / f"scan.{source}", out, "--json").stdout)
    assert report["vertex_attributes"] == ["texture coordinates", "material"], report
    parts, image_of = parts_by_material(out)
    assert len(parts) == 2, parts
    wrong, faces = faces_on_the_other_side(parts, middle, image_of)
    assert faces == report["faces_out"]
    assert wrong <= 10, wrong
    # OBJ and PLY name their images, copied or written into the output's
    # folder; glTF embeds them.
    folder = out.parent / "scan_textures"
    assert len(list(folder.iterdir()) if folder.exists() else []) == (0 if target == "glb" else 2)


def two_colour_obj(path):
    """The jagged blade fixture as an OBJ of two colour materials (`Kd`,
    and `d` on one, no texture coordinates), as CAD systems export parts:
    `red` left of the middle, `blue` (half opaque) right of it. Returns
    the middle x."""
    mesh = trimesh.load(str(ROOT / "fixtures" / "meshes" / "blade_jagged.stl"), process=True)
    middle = np.median(mesh.vertices[:, 0])
    right = mesh.triangles_center[:, 0] > middle
    lines = ["mtllib colours.mtl"] + [f"v {x!r} {y!r} {z!r}" for x, y, z in mesh.vertices.tolist()]
    for name, side in [("red", ~right), ("blue", right)]:
        lines.append(f"usemtl {name}")
        lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in mesh.faces[side]]
    path.write_text("\n".join(lines) + "\n")
    (path.parent / "colours.mtl").write_text("newmtl red\nKd 1 0 0\n\nnewmtl blue\nKd 0 0 1\nd 0.5\n")
    return middle


def test_colour_materials_are_carried_to_gltf(tmp_path):
    """Colour materials cleaned to GLB: trimesh reads each material's base
    colour and opacity (the MTL's `Kd` and `d`) and each face on its
    side's (measured: none across). PLY holds texture images only: the
    report says the material is not written. From Python, write_mesh
    makes the same materials of read_mesh's `material` for a GLB."""
    import meshtrim

    middle = two_colour_obj(tmp_path / "parts.obj")
    colours = {(255, 0, 0, 255): "red", (0, 0, 255, 128): "blue"}

    def colour_sides(path):
        wrong = 0
        for part in trimesh.load(str(path), process=False).geometry.values():
            name = colours[tuple(part.visual.material.baseColorFactor)]
            wrong += int(((part.triangles_center[:, 0] > middle) != (name == "blue")).sum())
        return wrong

    report = json.loads(run_meshtrim("clean", tmp_path / "parts.obj", tmp_path / "parts.glb", "--json").stdout)
    assert report["vertex_attributes"] == ["material"], report
    assert colour_sides(tmp_path / "parts.glb") <= 4
    report = json.loads(run_meshtrim("clean", tmp_path / "parts.obj", tmp_path / "parts.ply", "--json").stdout)
    assert report["vertex_attributes_not_written"] == ["material"], report

    v, f, attributes = meshtrim.read_mesh(tmp_path / "parts.obj", attributes=True)
    meshtrim.write_mesh(tmp_path / "direct.glb", v, f, material=attributes.material)
    assert colour_sides(tmp_path / "direct.glb") == 0


def test_split_seams_gives_what_the_cli_writes(tmp_path):
    """From Python, clean then split_seams (texture coordinates, the
    materials per face) make the mesh write_mesh_carrying writes, as the
    CLI does: the same vertices, faces, coordinates and materials, bit
    for bit, read back from its OBJ. carry_faces carries per-face values
    of any shape and type to an output without seams."""
    import meshtrim

    halves_as_obj(tmp_path / "scan.obj")
    v, f, attributes = meshtrim.read_mesh(tmp_path / "scan.obj", attributes=True)
    out_v, out_f, _ = meshtrim.clean(v, f)
    split = meshtrim.split_seams(
        v, f, out_v, out_f, values=[attributes.texcoords], face_values=[attributes.material.faces]
    )
    assert len(split.vertices) > len(out_v) and len(split.faces) == len(out_f)

    meshtrim.write_mesh_carrying(tmp_path / "out" / "scan.obj", out_v, out_f, v, f, attributes._replace(normals=None))
    written_v, written_f, written = meshtrim.read_mesh(tmp_path / "out" / "scan.obj", attributes=True)
    assert np.array_equal(written_v, split.vertices) and np.array_equal(written_f, split.faces)
    assert np.array_equal(written.texcoords, split.values[0])
    names = np.array(attributes.material.names)
    assert np.array_equal(np.array(written.material.names)[written.material.faces], names[split.face_values[0]])

    rows = np.stack([np.arange(len(f)), -np.arange(len(f))], axis=1).astype(np.int16)
    carried = meshtrim.carry_faces(v, f, rows, out_v, out_f)
    assert carried.dtype == np.int16 and carried.shape == (len(out_f), 2)
    assert np.array_equal(carried[:, 0], -carried[:, 1])
    with pytest.raises(meshtrim.MeshtrimError, match="values: expected an array of shape"):
        meshtrim.carry_faces(v, f, rows[1:], out_v, out_f)
    with pytest.raises(meshtrim.MeshtrimError, match=r"values\[0\]: expected an array of shape"):
        meshtrim.split_seams(v, f, out_v, out_f, values=[attributes.texcoords[1:]])


def test_trimesh_and_open3d_keep_a_texture(textured):
    """The adapters keep a textured mesh's texture: trimesh's (a vertex
    per (v, vt) pair, `TextureVisuals`) and Open3D's (a texture coordinate
    per triangle corner, its images and material ids) cleaned, every face
    kept has its corners' exact coordinates, the new ones are on their
    chart's map, and the material and image are the input's."""
    import open3d as o3d

    import meshtrim

    directory, the_map = textured
    loaded = trimesh.load(str(directory / "face.obj"), process=False)
    cleaned = meshtrim.trimesh.clean(loaded)
    assert cleaned.visual.kind == "texture" and cleaned.visual.material is loaded.visual.material
    assert_wedges_kept(
        (loaded.vertices[loaded.faces], loaded.visual.uv[loaded.faces]),
        (cleaned.vertices[cleaned.faces], cleaned.visual.uv[cleaned.faces]),
        the_map,
    )

    mesh = o3d.io.read_triangle_mesh(str(directory / "face.obj"))
    # Open3D reads the image after an empty one (material 0, none).
    assert mesh.has_triangle_uvs() and [np.asarray(t).shape for t in mesh.textures] == [(), (256, 256, 4)]
    out = meshtrim.open3d.clean(mesh)

    def corners_and_uv(m):
        faces = np.asarray(m.triangles)
        return np.asarray(m.vertices)[faces], np.asarray(m.triangle_uvs).reshape(-1, 3, 2)

    assert_wedges_kept(corners_and_uv(mesh), corners_and_uv(out), the_map)
    assert len(out.textures) == 2 and np.array_equal(np.asarray(out.textures[1]), np.asarray(mesh.textures[1]))
    assert set(np.asarray(out.triangle_material_ids)) == set(np.asarray(mesh.triangle_material_ids)) == {1}


@pytest.mark.parametrize("ext", ["glb", "ply"])
def test_python_carries_a_gltfs_and_a_plys_materials(ext, tmp_path):
    """read_mesh gives a GLB's materials (trimesh's halves) and a MeshLab
    PLY's texture images as FileMaterials; write_mesh_carrying writes the
    CLI's bytes with them, and from memory split_seams carries each
    face's material, which with_faces gives write_mesh: trimesh reads each
    face on its half's image (measured 6 of 165,989 across)."""
    import meshtrim

    middle = WRITERS[ext](tmp_path / f"scan.{ext}")
    v, f, attributes = meshtrim.read_mesh(tmp_path / f"scan.{ext}", attributes=True)
    material = attributes.material
    assert isinstance(material, meshtrim.FileMaterials) and material.kind == {"glb": "gltf", "ply": "ply"}[ext]
    assert len(material.names) == 2 and material.faces.shape == (len(f),)
    out_v, out_f, _ = meshtrim.clean(v, f)

    meshtrim.write_mesh_carrying(tmp_path / "py" / f"scan.{ext}", out_v, out_f, v, f, attributes)
    run_meshtrim("clean", tmp_path / f"scan.{ext}", tmp_path / "cli" / f"scan.{ext}")
    for written in (tmp_path / "cli").rglob("*"):
        if written.is_file():
            twin = tmp_path / "py" / written.relative_to(tmp_path / "cli")
            assert twin.read_bytes() == written.read_bytes(), written

    split = meshtrim.split_seams(v, f, out_v, out_f, values=[attributes.texcoords], face_values=[material.faces])
    memory = tmp_path / "memory" / f"scan.{ext}"
    meshtrim.write_mesh(
        memory, split.vertices, split.faces, texcoords=split.values[0], material=material.with_faces(split.face_values[0])
    )
    parts, image_of = parts_by_material(memory)
    wrong, faces = faces_on_the_other_side(parts, middle, image_of)
    assert faces == len(out_f) and wrong <= 10, (wrong, faces)
    with pytest.raises(meshtrim.MeshtrimError, match="material.faces: expected"):
        meshtrim.write_mesh(tmp_path / "bad.glb", split.vertices, split.faces, material=material)
