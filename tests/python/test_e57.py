"""E57 files written by pye57 (libE57Format, the format's reference
implementation) read by meshtrim: several scans with their poses merged in
the file's frame, one scan alone (--scan), invalid points dropped and
counted, spherical coordinates converted, labels identical to the same
points given as a double PLY, broken files refused."""

from __future__ import annotations

import csv
import json
import math
import subprocess

import numpy as np
import pye57
import pytest
from pye57 import libe57

import synthetic
from meshtrim_cli import MESHTRIM, run_meshtrim


def quaternion(axis, degrees):
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    half = math.radians(degrees) / 2
    return np.array([math.cos(half), *(math.sin(half) * axis)])


def halves():
    """A synthetic blade (mm) cut in two overlapping scans."""
    p = synthetic.blade(2.0, 5).points
    order = np.argsort(p[:, 0])
    return p[order[: 2 * len(p) // 3]], p[order[len(p) // 3 :]]


# Two scans, each in its own frame: the poses put them back in the file's.
POSES = [(quaternion([0, 0, 1], 30), np.array([1000.0, -200.0, 50.0])), (quaternion([1, 1, 0], -70), np.array([0.0, 0.0, 0.0]))]


def write_scans(path, scans, poses, states=None, grids=None):
    """Writes the scans with pye57; `states[i]` their invalid states,
    `grids[i]` (rows, columns) their image indices, where not None."""
    e = pye57.E57(str(path), mode="w")
    for i, (points, (rotation, translation)) in enumerate(zip(scans, poses)):
        data = {"cartesianX": points[:, 0], "cartesianY": points[:, 1], "cartesianZ": points[:, 2]}
        if states is not None:
            data["cartesianInvalidState"] = states[i]
        if grids is not None and grids[i] is not None:
            data["rowIndex"], data["columnIndex"] = grids[i]
        e.write_scan_raw(data, rotation=rotation, translation=translation)
    e.close()


def local(points, pose):
    """Points given in the file's frame, in the scan's own frame."""
    rotation, translation = pose
    w, x, y, z = rotation
    r = np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )
    return (points - translation) @ r


def pye57_points(path, index):
    scan = pye57.E57(str(path)).read_scan(index, ignore_missing_fields=True, transform=True)
    return np.column_stack([scan["cartesianX"], scan["cartesianY"], scan["cartesianZ"]])


def labels(path, *extra):
    out = path.with_suffix(".labels.csv")
    summary = json.loads(run_meshtrim("detect", path, "-o", out, "--json", *extra).stdout)
    with open(out) as f:
        rows = list(csv.DictReader(f))
    xyz = np.array([[float(r[c]) for c in "xyz"] for r in rows])
    return xyz, np.array([r["boundary"] == "1" for r in rows]), np.array([float(r["beta"]) for r in rows]), summary


def test_scans_merge_in_the_files_frame(tmp_path):
    a, b = halves()
    path = tmp_path / "two.e57"
    write_scans(path, [local(a, POSES[0]), local(b, POSES[1])], POSES)
    xyz, boundary, beta, summary = labels(path)
    expected = np.vstack([pye57_points(path, 0), pye57_points(path, 1)])
    assert len(xyz) == len(expected) == len(a) + len(b)
    # pye57 poses with a rotation matrix product, the e57 crate with its
    # own: the same to rounding, a few ulps of the coordinates.
    assert np.allclose(xyz, expected, rtol=0, atol=1e-9 * np.abs(expected).max())
    # and, up to pye57's float32 storage, the blade itself back together.
    assert np.allclose(xyz, np.vstack([a, b]), atol=1e-3)
    ply = tmp_path / "same.ply"
    synthetic.write_cloud_ply(ply, xyz)
    ply_xyz, ply_boundary, ply_beta, _ = labels(ply)
    assert np.array_equal(ply_xyz, xyz)
    assert np.array_equal(boundary, ply_boundary) and np.array_equal(beta, ply_beta)
    assert summary["dropped_non_finite"] == 0


def test_one_scan_alone(tmp_path):
    a, b = halves()
    path = tmp_path / "two.e57"
    write_scans(path, [local(a, POSES[0]), local(b, POSES[1])], POSES)
    xyz, _, _, _ = labels(path, "--scan", "1")
    assert np.allclose(xyz, pye57_points(path, 1), rtol=0, atol=1e-9 * np.abs(xyz).max())
    assert len(xyz) == len(b)
    r = subprocess.run([str(MESHTRIM), "detect", str(path), "--scan", "2"], capture_output=True, text=True)
    assert r.returncode == 1
    assert r.stderr.strip() == f"error: {path}: there is no scan 2: the file has 2 scan(s), numbered from 0 to 1"
    r = subprocess.run([str(MESHTRIM), "detect", str(tmp_path / "x.ply"), "--scan", "0"], capture_output=True, text=True)
    assert r.returncode == 1
    # The Python package reads the same points (the same reader).
    import meshtrim

    assert np.array_equal(meshtrim.read_cloud(path, scan=1), xyz)
    assert np.array_equal(meshtrim.read_cloud(path), labels(path)[0])
    with pytest.raises(meshtrim.MeshtrimError, match="there is no scan 2"):
        meshtrim.read_cloud(path, scan=2)


def test_a_rounded_quaternion_is_normalised(tmp_path):
    # 45 degrees about z, as files store it: seven digits, a norm of
    # 0.99999996. Unnormalised, it would shrink the scan by 8e-8 of its size.
    rotation = np.array([0.9238795, 0.0, 0.0, 0.3826834])
    a, _ = halves()
    far = a + [5e4, 0.0, 0.0]  # 50 m away: a shrink would show as 4 micrometres
    path = tmp_path / "rounded.e57"
    write_scans(path, [far], [(rotation, np.zeros(3))])
    xyz, _, _, _ = labels(path)
    expected = pye57_points(path, 0)  # pye57 normalises (pyquaternion)
    assert np.allclose(xyz, expected, rtol=0, atol=1e-9)
    stored = pye57.E57(str(path)).read_scan_raw(0)
    radius = np.hypot(stored["cartesianX"], stored["cartesianY"])
    assert np.allclose(np.hypot(xyz[:, 0], xyz[:, 1]), radius, rtol=1e-12)


def test_an_identity_pose_reads_pye57s_values_exactly(tmp_path):
    a, _ = halves()
    path = tmp_path / "one.e57"
    write_scans(path, [a], [(np.array([1.0, 0, 0, 0]), np.zeros(3))])
    xyz, _, _, _ = labels(path)
    assert np.array_equal(xyz, pye57_points(path, 0))


def test_invalid_points_are_dropped_and_counted(tmp_path):
    a, _ = halves()
    states = np.zeros(len(a), dtype=np.int8)
    states[::7] = 2  # no coordinates
    states[3::11] = 1  # a direction only
    path = tmp_path / "invalid.e57"
    write_scans(path, [a], [(np.array([1.0, 0, 0, 0]), np.zeros(3))], states=[states])
    xyz, _, _, summary = labels(path)
    dropped = int(np.count_nonzero(states))
    assert summary["dropped_non_finite"] == dropped
    assert summary["points"] == len(a) - dropped
    assert np.array_equal(xyz, a[states == 0].astype(np.float32).astype(np.float64))


def test_row_and_column_indices_are_kept_beside_the_labels(tmp_path):
    """A structured scan's rowIndex and columnIndex, with some points
    invalid, and a second scan without them: detect's CSV and PLY give each
    written point its scan, row and column (-1 where the scan has none),
    as pye57 reads them; the labels are those of the same file without
    indices."""
    a, b = halves()
    rows = (np.arange(len(a)) // 97).astype(np.uint16)
    columns = (np.arange(len(a)) % 97).astype(np.uint16)
    states = [np.zeros(len(a), dtype=np.int8), np.zeros(len(b), dtype=np.int8)]
    states[0][5::13] = 2
    path = tmp_path / "grid.e57"
    write_scans(path, [a, b], POSES, states=states, grids=[(rows, columns), None])
    plain = tmp_path / "plain.e57"
    write_scans(plain, [a, b], POSES, states=states)
    read = pye57.E57(str(path)).read_scan_raw(0)
    valid = read["cartesianInvalidState"] == 0
    expected = np.concatenate(
        [
            np.column_stack([np.zeros(valid.sum()), read["rowIndex"][valid], read["columnIndex"][valid]]),
            np.column_stack([np.ones(len(b)), -np.ones(len(b)), -np.ones(len(b))]),
        ]
    ).astype(np.int64)
    out = tmp_path / "labels.csv"
    run_meshtrim("detect", path, "-o", out)
    with open(out) as f:
        table = list(csv.DictReader(f))
    assert list(table[0]) == ["x", "y", "z", "boundary", "beta", "scan", "row", "column"]
    got = np.array([[int(r["scan"]), int(r["row"]), int(r["column"])] for r in table])
    assert np.array_equal(got, expected)
    xyz, boundary, beta, _ = labels(plain)
    assert np.array_equal(np.array([[float(r[c]) for c in "xyz"] for r in table]), xyz)
    assert np.array_equal(np.array([r["boundary"] == "1" for r in table]), boundary)
    # The PLY, read by trimesh's PLY parser.
    import trimesh

    ply = tmp_path / "labels.ply"
    run_meshtrim("detect", path, "-o", ply)
    vertex = trimesh.load(ply, process=False).metadata["_ply_raw"]["vertex"]["data"]
    assert np.array_equal(np.column_stack([vertex["scan"], vertex["row"], vertex["column"]]), expected)
    assert np.array_equal(vertex["boundary"] == 1, boundary)
    # One scan alone: its own index as its scan; a scan without indices
    # alone writes no grid columns.
    alone = tmp_path / "alone.csv"
    run_meshtrim("detect", path, "-o", alone, "--scan", "0")
    with open(alone) as f:
        got = np.array([[int(r["scan"]), int(r["row"]), int(r["column"])] for r in csv.DictReader(f)])
    assert np.array_equal(got, expected[: valid.sum()])
    run_meshtrim("detect", path, "-o", alone, "--scan", "1")
    with open(alone) as f:
        assert next(csv.reader(f)) == ["x", "y", "z", "boundary", "beta"]


def write_spherical(path, r, azimuth, elevation, state):
    """One scan in spherical coordinates (range, azimuth, elevation),
    written through libE57Format's own node API (pye57's writer writes
    Cartesian scans only)."""
    e = pye57.E57(str(path), mode="w")
    f = e.image_file
    scan = libe57.StructureNode(f)
    scan.set("guid", libe57.StringNode(f, "{00000000-0000-0000-0000-0000000000e5}"))
    proto = libe57.StructureNode(f)
    proto.set("sphericalRange", libe57.FloatNode(f, 0.0, libe57.E57_DOUBLE, 0.0, 1e4))
    proto.set("sphericalAzimuth", libe57.FloatNode(f, 0.0, libe57.E57_DOUBLE, -math.pi, math.pi))
    proto.set("sphericalElevation", libe57.FloatNode(f, 0.0, libe57.E57_DOUBLE, -math.pi / 2, math.pi / 2))
    proto.set("sphericalInvalidState", libe57.IntegerNode(f, 0, 0, 2))
    fields = ["sphericalRange", "sphericalAzimuth", "sphericalElevation", "sphericalInvalidState"]
    points = libe57.CompressedVectorNode(f, proto, libe57.VectorNode(f, True))
    scan.set("points", points)
    e.data3d.append(scan)
    arrays, buffers = e.make_buffers(fields, len(r))
    for name, values in zip(fields, [r, azimuth, elevation, state]):
        arrays[name][:] = values
    writer = points.writer(buffers)
    writer.write(len(r))
    writer.close()
    e.close()


def test_spherical_coordinates_are_converted(tmp_path):
    rng = np.random.default_rng(4)
    az, el = np.meshgrid(np.linspace(-0.6, 0.6, 80), np.linspace(-0.4, 0.4, 60))
    az, el = az.ravel() + rng.uniform(-2e-3, 2e-3, az.size), el.ravel()
    r = 2000.0 + 5 * np.sin(3 * az)
    state = np.zeros(r.size, dtype=np.int8)
    state[::13] = 2
    path = tmp_path / "spherical.e57"
    write_spherical(path, r, az, el, state)
    xyz, boundary, _, summary = labels(path)
    keep = state == 0
    expected = np.column_stack(
        [r * np.cos(el) * np.cos(az), r * np.cos(el) * np.sin(az), r * np.sin(el)]
    )[keep]
    assert summary["dropped_non_finite"] == int((~keep).sum())
    assert np.allclose(xyz, expected, rtol=0, atol=1e-9)
    assert 0.02 < boundary.mean() < 0.3


def test_broken_e57_files_are_refused(tmp_path):
    a, b = halves()
    good = tmp_path / "good.e57"
    write_scans(good, [a, b], POSES)
    data = good.read_bytes()
    flipped = bytearray(data)
    flipped[len(data) // 2] ^= 0x40
    empty = tmp_path / "empty.e57"
    pye57.E57(str(empty), mode="w").close()
    cases = {
        "short.e57": data[: len(data) // 3],
        "bad_crc.e57": bytes(flipped),
        "header_only.e57": data[:48],
    }
    for name, content in cases.items():
        (tmp_path / name).write_bytes(content)
    for name in [*cases, "empty.e57"]:
        path, out = tmp_path / name, tmp_path / f"{name}.csv"
        r = subprocess.run([str(MESHTRIM), "detect", str(path), "-o", str(out)], capture_output=True, text=True, timeout=60)
        assert r.returncode == 1, (name, r.stderr)
        assert r.stderr.startswith(f"error: {path}:") and "panicked" not in r.stderr, r.stderr
        assert not out.exists()
    r = subprocess.run([str(MESHTRIM), "detect", str(empty)], capture_output=True, text=True)
    assert "no scans" in r.stderr, r.stderr
