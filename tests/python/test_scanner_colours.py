"""Scanner clouds' colours (E57 written by pye57, LAS and LAZ by laspy)
carried by `meshtrim mesh` to its vertices: each vertex has the colour
the reference reader gives its nearest cloud point, read back from the
output by PyMeshLab."""

from __future__ import annotations

import json

import laspy
import numpy as np
import pye57
import pymeshlab
import pytest
from scipy.spatial import cKDTree

import synthetic
from meshtrim_cli import run_meshtrim
from scanner_files import las_data


def blade():
    """A synthetic blade (mm) and colours that vary along it, as bytes."""
    points = synthetic.blade(2.0, 7).points
    span = np.ptp(points, axis=0)
    rgb = np.column_stack(
        [
            255 * (points[:, 0] - points[:, 0].min()) / span[0],
            255 * (points[:, 1] - points[:, 1].min()) / span[1],
            np.full(len(points), 128.0),
        ]
    )
    return points, np.rint(rgb).astype(np.uint8)


def meshed_colours(cloud, tmp_path):
    """`meshtrim mesh CLOUD` run; the output's vertices and colours
    (bytes), and its report."""
    out, report = tmp_path / "out.ply", tmp_path / "r.json"
    run_meshtrim("mesh", cloud, out, "--report", report)
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(out))
    m = ms.current_mesh()
    assert m.has_vertex_color()
    return m.vertex_matrix(), np.rint(m.vertex_color_matrix()[:, :3] * 255).astype(int), json.loads(report.read_text())


def check_nearest(points, colours, vertices, got, report):
    assert report["vertex_attributes"] == ["colours"]
    _, nearest = cKDTree(points).query(vertices)
    assert np.array_equal(got, colours[nearest].astype(int))


def write_coloured_e57(path):
    """The coloured blade as one E57 scan, written by pye57; its points
    and colours."""
    points, rgb = blade()
    e = pye57.E57(str(path), mode="w")
    data = {"cartesianX": points[:, 0], "cartesianY": points[:, 1], "cartesianZ": points[:, 2]}
    data.update(colorRed=rgb[:, 0], colorGreen=rgb[:, 1], colorBlue=rgb[:, 2])
    e.write_scan_raw(data)
    e.close()
    return points, rgb


def test_e57_colours_reach_the_mesh(tmp_path):
    path = tmp_path / "blade.e57"
    points, rgb = write_coloured_e57(path)
    scan = pye57.E57(str(path)).read_scan(0, colors=True, ignore_missing_fields=True)
    read = np.column_stack([scan["colorRed"], scan["colorGreen"], scan["colorBlue"]])
    assert np.array_equal(read, rgb)
    vertices, got, report = meshed_colours(path, tmp_path)
    check_nearest(points, read, vertices, got, report)


@pytest.mark.parametrize(
    "point_format, version, ext, sixteen_bit",
    [(2, "1.2", "las", False), (3, "1.3", "laz", False), (7, "1.4", "las", True), (8, "1.4", "laz", True)],
)
def test_las_colours_reach_the_mesh(tmp_path, point_format, version, ext, sixteen_bit):
    """8-bit values in the 16-bit fields (what many writers store) read
    as 0-255; full 16-bit values as 0-65535."""
    points, rgb = blade()
    las = las_data(points, point_format, version)
    stored = rgb.astype(np.uint16) * 257 if sixteen_bit else rgb.astype(np.uint16)
    las.red, las.green, las.blue = stored[:, 0], stored[:, 1], stored[:, 2]
    path = tmp_path / f"blade.{ext}"
    las.write(str(path))
    back = laspy.read(str(path))
    read = np.column_stack([back.red, back.green, back.blue])
    assert np.array_equal(read, stored)
    xyz = np.column_stack([back.x, back.y, back.z])
    vertices, got, report = meshed_colours(path, tmp_path)
    check_nearest(xyz, read // 257 if sixteen_bit else read, vertices, got, report)


@pytest.mark.parametrize("point_format, version", [(1, "1.2"), (3, "1.3")])
def test_las_without_colour_gives_none(tmp_path, point_format, version):
    """No colour field (format 1), or colour, intensity and classification
    fields a writer left at 0 (format 3): no attributes, rather than a
    black mesh with columns of zeros."""
    points, _ = blade()
    las = las_data(points, point_format, version)
    path = tmp_path / "plain.las"
    las.write(str(path))
    out, report = tmp_path / "out.ply", tmp_path / "r.json"
    run_meshtrim("mesh", path, out, "--report", report)
    assert "vertex_attributes" not in json.loads(report.read_text())


@pytest.mark.parametrize("ascii_data, compressed", [(True, False), (False, False), (False, True)])
def test_pcd_rgb_as_open3d_writes_it(tmp_path, ascii_data, compressed):
    """Open3D writes colours as PCL's packed float `rgb`; meshtrim reads
    the bytes Open3D reads back, in every DATA encoding."""
    import open3d as o3d

    import meshtrim

    points, rgb = blade()
    pcd = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points))
    pcd.colors = o3d.utility.Vector3dVector(rgb / 255.0)
    path = tmp_path / "blade.pcd"
    assert o3d.io.write_point_cloud(str(path), pcd, write_ascii=ascii_data, compressed=compressed)
    back = o3d.io.read_point_cloud(str(path))
    read, attrs = meshtrim.read_cloud(path, attributes=True)
    assert np.array_equal(read, np.asarray(back.points))
    assert np.array_equal(np.rint(attrs.colours * 255), np.rint(np.asarray(back.colors) * 255))
    assert np.array_equal(np.rint(attrs.colours * 255).astype(np.uint8), rgb)


def test_pcd_rgba_of_a_real_stereo_scan():
    """PCL's textured stereo scan, `rgba` packed in an unsigned integer:
    meshtrim's colours are Open3D's, for the points both keep (meshtrim
    drops the NaN points of the organised cloud)."""
    import open3d as o3d

    import meshtrim
    from meshtrim_cli import ROOT

    path = ROOT / "fixtures" / "scans" / "pcl_test" / "table_scene_mug_stereo_textured.pcd"
    back = o3d.io.read_point_cloud(str(path), remove_nan_points=False)
    finite = np.isfinite(np.asarray(back.points)).all(axis=1)
    read, attrs = meshtrim.read_cloud(path, attributes=True)
    assert len(read) == finite.sum() > 1000
    want = np.rint(np.asarray(back.colors)[finite] * 255)
    assert np.array_equal(np.rint(attrs.colours * 255), want)
    assert len(np.unique(want, axis=0)) > 100, "a textured scan, not one colour"


def test_read_cloud_gives_the_reference_readers_colours(tmp_path):
    import meshtrim

    path = tmp_path / "blade.e57"
    points, rgb = write_coloured_e57(path)
    _, attrs = meshtrim.read_cloud(path, attributes=True)
    assert attrs.normals is None and attrs.colours.shape == (len(points), 3)
    assert np.array_equal(np.rint(attrs.colours * 255).astype(np.uint8), rgb)
