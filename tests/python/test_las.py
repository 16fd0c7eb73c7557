"""LAS and LAZ clouds written by laspy (with the lazrs codec), the
format's reference library, read by meshtrim: coordinates exactly as
laspy reads them, labels identical to the same points given as a double
PLY; labels written as LAS/LAZ read back by laspy as scalar fields, a
LAS input's point records and coordinate system kept; bad files refused
with a clear error and nothing written."""

from __future__ import annotations

import csv
import subprocess

import laspy
import numpy as np
import pytest

import synthetic
from meshtrim_cli import MESHTRIM, run_meshtrim

# A survey-sized offset (UTM northing about 6e6 m) on a 0.1 mm grid: the
# coordinates need all of f64's precision.
OFFSET = np.array([612_345.0, 6_012_345.0, 120.0])
SCALE = np.array([1e-4, 1e-4, 1e-4])


def blade_points() -> np.ndarray:
    """A synthetic blade (mm), moved to the survey offset, in metres."""
    c = synthetic.blade(2.0, 3)
    return OFFSET + c.points / 1000.0


def write_las(path, points, point_format=0, version="1.2"):
    header = laspy.LasHeader(point_format=point_format, version=version)
    header.offsets = OFFSET
    header.scales = SCALE
    las = laspy.LasData(header)
    las.x, las.y, las.z = points[:, 0], points[:, 1], points[:, 2]
    las.write(str(path))
    back = laspy.read(str(path))
    return np.column_stack([np.asarray(back.x), np.asarray(back.y), np.asarray(back.z)])


def labels_csv(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    xyz = np.array([[float(r[c]) for c in "xyz"] for r in rows])
    boundary = np.array([r["boundary"] == "1" for r in rows])
    beta = np.array([float(r["beta"]) for r in rows])
    return xyz, boundary, beta


@pytest.mark.parametrize(
    "point_format, version, ext",
    [(0, "1.1", "las"), (0, "1.2", "las"), (1, "1.2", "las"), (3, "1.3", "laz"), (6, "1.4", "las"), (7, "1.4", "laz"), (10, "1.4", "laz")],
)
def test_coordinates_are_laspys_and_labels_the_plys(tmp_path, point_format, version, ext):
    cloud = tmp_path / f"blade.{ext}"
    expected = write_las(cloud, blade_points(), point_format, version)
    run_meshtrim("detect", cloud, "-o", tmp_path / "las.csv")
    xyz, boundary, beta = labels_csv(tmp_path / "las.csv")
    assert np.array_equal(xyz, expected), "every coordinate as laspy reads it, bit for bit"
    ply = tmp_path / "same.ply"
    synthetic.write_cloud_ply(ply, expected)
    run_meshtrim("detect", ply, "-o", tmp_path / "ply.csv")
    _, ply_boundary, ply_beta = labels_csv(tmp_path / "ply.csv")
    assert np.array_equal(boundary, ply_boundary) and np.array_equal(beta, ply_beta)
    assert 0.02 < boundary.mean() < 0.3


@pytest.mark.parametrize("ext", ["las", "laz"])
def test_labels_written_as_las_read_back_by_laspy(tmp_path, ext):
    cloud = tmp_path / "blade.laz"
    expected = write_las(cloud, blade_points(), 1, "1.2")
    out = tmp_path / f"labels.{ext}"
    run_meshtrim("detect", cloud, "-o", out)
    run_meshtrim("detect", cloud, "-o", tmp_path / "labels.csv")
    _, boundary, beta = labels_csv(tmp_path / "labels.csv")
    las = laspy.read(str(out))
    assert np.array_equal(las.header.offsets, OFFSET) and np.array_equal(las.header.scales, SCALE)
    got = np.column_stack([np.asarray(las.x), np.asarray(las.y), np.asarray(las.z)])
    assert np.array_equal(got, expected), "the same points on the same grid"
    assert list(las.point_format.extra_dimension_names) == ["boundary", "beta"]
    assert np.array_equal(np.asarray(las.boundary) == 1, boundary)
    assert np.array_equal(np.asarray(las.beta), beta)
    # Deterministic: the same bytes again.
    again = tmp_path / f"again.{ext}"
    run_meshtrim("detect", cloud, "-o", again)
    assert again.read_bytes() == out.read_bytes()


def survey_las(path, point_format, version):
    """The blade as a survey's LAS or LAZ by laspy: every field of its
    point format filled (intensity, returns, classification, GPS time,
    colour where the format has them), an extra-bytes dimension of its
    own (`reflectance`) and its coordinate system as a WKT VLR."""
    points = blade_points()
    n = len(points)
    rng = np.random.default_rng(point_format)
    header = laspy.LasHeader(point_format=point_format, version=version)
    header.offsets, header.scales = OFFSET, SCALE
    header.add_extra_dim(laspy.ExtraBytesParams(name="reflectance", type=np.float32))
    header.vlrs.append(laspy.VLR("LASF_Projection", 2112, "OGC WKT", b'PROJCS["UTM 32N"]\0'))
    las = laspy.LasData(header)
    las.x, las.y, las.z = points[:, 0], points[:, 1], points[:, 2]
    las.intensity = rng.integers(0, 65536, n)
    las.number_of_returns = np.full(n, 3)
    las.return_number = rng.integers(1, 4, n)
    las.classification = rng.integers(0, 32, n)
    las.point_source_id = rng.integers(0, 65536, n)
    if "gps_time" in las.point_format.dimension_names:
        las.gps_time = rng.random(n) * 1e5
    if "red" in las.point_format.dimension_names:
        for channel in ("red", "green", "blue"):
            las[channel] = rng.integers(0, 65536, n)
    las.reflectance = rng.random(n).astype(np.float32)
    las.write(str(path))


@pytest.mark.parametrize("point_format, version, ext", [(3, "1.2", "laz"), (1, "1.3", "las"), (7, "1.4", "laz"), (8, "1.4", "las")])
def test_a_survey_keeps_its_point_records(tmp_path, point_format, version, ext):
    """Labels written as LAS or LAZ from a LAS or LAZ input keep each
    point's record as it was (every field of the point format and the
    file's own extra bytes, as laspy reads them), its scale and offset and
    its coordinate system VLR, with `boundary` and `beta` added after its
    own extra dimensions: LAS 1.4, the input's point format."""
    cloud = tmp_path / f"survey.{'laz' if ext == 'las' else 'las'}"
    survey_las(cloud, point_format, version)
    out = tmp_path / f"labels.{ext}"
    run_meshtrim("detect", cloud, "-o", out)
    run_meshtrim("detect", cloud, "-o", tmp_path / "labels.csv")
    _, boundary, beta = labels_csv(tmp_path / "labels.csv")
    source, las = laspy.read(str(cloud)), laspy.read(str(out))
    assert (las.header.version.major, las.header.version.minor) == (1, 4)
    assert las.point_format.id == point_format
    assert np.array_equal(las.header.offsets, OFFSET) and np.array_equal(las.header.scales, SCALE)
    for name in source.point_format.dimension_names:
        assert np.array_equal(np.asarray(las[name]), np.asarray(source[name])), name
    assert list(las.point_format.extra_dimension_names) == ["reflectance", "boundary", "beta"]
    assert np.array_equal(np.asarray(las.boundary) == 1, boundary)
    assert np.array_equal(np.asarray(las.beta), beta)
    wkt = [vlr for vlr in las.header.vlrs if vlr.record_id == 2112]
    assert len(wkt) == 1 and wkt[0].record_data_bytes().startswith(b'PROJCS["UTM 32N"]'), las.header.vlrs


def test_labels_of_another_format_on_a_fine_grid(tmp_path):
    points = blade_points()
    ply = tmp_path / "blade.ply"
    synthetic.write_cloud_ply(ply, points)
    run_meshtrim("detect", ply, "-o", tmp_path / "labels.las")
    run_meshtrim("detect", ply, "-o", tmp_path / "labels.csv")
    _, boundary, _ = labels_csv(tmp_path / "labels.csv")
    las = laspy.read(str(tmp_path / "labels.las"))
    got = np.column_stack([np.asarray(las.x), np.asarray(las.y), np.asarray(las.z)])
    # The grid is the finest power of ten spanning the range in 2^30 steps
    # and at least two f64 epsilons of the coordinates: here 1e-9 m in x
    # (6e5 m), 1e-8 m in y (6e6 m), 1e-10 m in z (the range's bound).
    assert np.array_equal(las.header.scales, [1e-9, 1e-8, 1e-10])
    rounding = las.header.scales / 2 + np.spacing(np.abs(points))
    assert np.all(np.abs(got - points) <= rounding)
    assert np.array_equal(np.asarray(las.boundary) == 1, boundary)


def test_bad_las_files_are_refused(tmp_path):
    good = tmp_path / "good.laz"
    write_las(good, blade_points(), 1, "1.2")
    plain = tmp_path / "good.las"
    write_las(plain, blade_points(), 1, "1.2")
    data, plain_data = good.read_bytes(), plain.read_bytes()
    cases = {
        "short_header.las": plain_data[:100],
        "short_points.las": plain_data[: len(plain_data) - 1000],
        "broken_chunk.laz": data[: len(data) // 2] + bytes(len(data) - len(data) // 2),
        "no_points.laz": data[:400],
    }
    for name, content in cases.items():
        path = tmp_path / name
        path.write_bytes(content)
        out = tmp_path / f"{name}.csv"
        r = subprocess.run([str(MESHTRIM), "detect", str(path), "-o", str(out)], capture_output=True, text=True, timeout=60)
        assert r.returncode == 1, (name, r.stderr)
        assert r.stderr.startswith(f"error: {path}:"), r.stderr
        assert "panicked" not in r.stderr and not out.exists(), name
