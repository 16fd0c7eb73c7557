"""Scanner clouds' per-point fields besides colour (LAS and LAZ intensity
and classification written by laspy, E57 intensity written by pye57, PCD
fields written by Open3D) read as the reference readers read them and
carried by `meshtrim mesh` to its vertices: each vertex has its nearest
cloud point's value, in the field's type, read back by trimesh's PLY
reader."""

from __future__ import annotations

import json

import laspy
import numpy as np
import pye57
import pytest
import trimesh
from scipy.spatial import cKDTree

import synthetic
from meshtrim_cli import run_meshtrim
from scanner_files import las_data


def blade():
    """A synthetic blade (mm), an intensity that varies along it and a
    classification in bands across it."""
    points = synthetic.blade(2.0, 7).points
    x = (points[:, 0] - points[:, 0].min()) / np.ptp(points[:, 0])
    intensity = np.rint(1000 + 60000 * x).astype(np.uint16)
    classification = (2 + (points[:, 1] // 20) % 5).astype(np.uint8)
    return points, intensity, classification


def meshed_fields(cloud, tmp_path):
    """`meshtrim mesh CLOUD` run: the output's vertices and vertex
    properties (as trimesh's PLY reader reads them), and its report."""
    out, report = tmp_path / "out.ply", tmp_path / "r.json"
    run_meshtrim("mesh", cloud, out, "--report", report)
    mesh = trimesh.load(str(out), process=False)
    return mesh.vertices, mesh.metadata["_ply_raw"]["vertex"]["data"], json.loads(report.read_text())


def nearest(points, vertices):
    """Each vertex's nearest cloud point."""
    return cKDTree(points).query(vertices)[1]


@pytest.mark.parametrize("point_format, version, ext", [(1, "1.2", "las"), (3, "1.3", "laz"), (6, "1.4", "las")])
def test_las_intensity_and_classification_reach_the_mesh(tmp_path, point_format, version, ext):
    """Legacy formats store the classification in five bits, the extended
    ones (6-10) in a byte of its own; meshtrim reads both as laspy does."""
    points, intensity, classification = blade()
    las = las_data(points, point_format, version)
    las.intensity = intensity
    las.classification = classification
    path = tmp_path / f"blade.{ext}"
    las.write(str(path))
    back = laspy.read(str(path))
    assert np.array_equal(back.intensity, intensity)
    assert np.array_equal(np.asarray(back.classification), classification)
    xyz = np.column_stack([back.x, back.y, back.z])
    vertices, raw, report = meshed_fields(path, tmp_path)
    assert report["vertex_attributes"] == ["intensity", "classification"], report
    assert raw.dtype["intensity"] == np.uint16 and raw.dtype["classification"] == np.uint8
    at = nearest(xyz, vertices)
    assert np.array_equal(raw["intensity"], intensity[at])
    assert np.array_equal(raw["classification"], classification[at])


def test_e57_intensity_reaches_the_mesh(tmp_path):
    """Intensity as stored (pye57 writes it as floats), not rescaled."""
    points, intensity, _ = blade()
    values = intensity.astype(np.float64) / 7.0
    path = tmp_path / "blade.e57"
    e = pye57.E57(str(path), mode="w")
    e.write_scan_raw(
        {"cartesianX": points[:, 0], "cartesianY": points[:, 1], "cartesianZ": points[:, 2], "intensity": values}
    )
    e.close()
    read = pye57.E57(str(path)).read_scan(0, intensity=True, ignore_missing_fields=True)["intensity"]
    vertices, raw, report = meshed_fields(path, tmp_path)
    assert report["vertex_attributes"] == ["intensity"], report
    assert raw.dtype["intensity"] == np.float32
    assert np.array_equal(raw["intensity"], read[nearest(points, vertices)].astype(np.float32))


@pytest.mark.parametrize("encoding", ["ascii", "binary", "binary_compressed"])
def test_pcd_fields_reach_the_mesh(tmp_path, encoding):
    """Open3D's tensor point cloud writes its attributes as PCD fields
    (`intensity` float, `label` 32-bit integer); `read_cloud` gives them
    in those types and `mesh` carries them."""
    import open3d as o3d

    import meshtrim

    points, intensity, classification = blade()
    pcd = o3d.t.geometry.PointCloud(o3d.core.Tensor(points))
    pcd.point["intensity"] = o3d.core.Tensor(intensity.astype(np.float32)[:, None] / 3)
    pcd.point["label"] = o3d.core.Tensor(classification.astype(np.int32)[:, None])
    path = tmp_path / "blade.pcd"
    assert o3d.t.io.write_point_cloud(
        str(path), pcd, write_ascii=encoding == "ascii", compressed=encoding == "binary_compressed"
    )
    back = o3d.t.io.read_point_cloud(str(path))
    want_i = back.point["intensity"].numpy()[:, 0]
    want_l = back.point["label"].numpy()[:, 0]
    read, attrs = meshtrim.read_cloud(path, attributes=True)
    assert np.array_equal(read, back.point["positions"].numpy())
    assert attrs.scalars["intensity"].dtype == np.float32 and attrs.scalars["label"].dtype == np.int32
    assert np.array_equal(attrs.scalars["intensity"], want_i)
    assert np.array_equal(attrs.scalars["label"], want_l)
    vertices, raw, report = meshed_fields(path, tmp_path)
    assert sorted(report["vertex_attributes"]) == ["intensity", "label"], report  # in file order
    at = nearest(read, vertices)
    assert np.array_equal(raw["intensity"], want_i[at]) and np.array_equal(raw["label"], want_l[at])
