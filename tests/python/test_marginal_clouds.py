"""Clouds at the edge of what meshtrim accepts, in single precision as
scanners' PLY files often are (written by numpy, read back by PyMeshLab to
check the file): points along a line or a curve have no surface, and every
command that detects a boundary refuses them with a clear error (exit 1,
the file named, nothing written), while a narrow strip of surface is
still read."""

from __future__ import annotations

import subprocess

import numpy as np
import pymeshlab
import pytest

from meshtrim_cli import MESHTRIM, run_meshtrim
from synthetic import write_cloud_ply


def write_float32_ply(path, points):
    """A float32 binary PLY of `points`; returns the coordinates as stored
    (PyMeshLab's reading of the file)."""
    write_cloud_ply(path, points, single=True)
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(path))
    stored = ms.current_mesh().vertex_matrix()
    assert np.array_equal(stored, np.asarray(points, dtype=np.float32).astype(np.float64))
    return stored


def collinear(n=500):
    """Points on a slanted line in 3-D, not exactly collinear once rounded
    to float32."""
    t = np.linspace(0.0, 1.0, n)[:, None]
    return np.array([12.3, -4.56, 7.89]) + t * np.array([310.7, 123.45, -98.76])


def line_profile(seed, spacing=0.5, noise=0.2):
    """A laser line profile: a curve across a part (a bump on a plate),
    sampled every `spacing` along x with noise of `noise` spacings across
    it, in y and z."""
    rng = np.random.default_rng(seed)
    x = np.arange(0.0, 200.0, spacing)
    z = 8.0 * np.exp(-(((x - 100.0) / 25.0) ** 2)) + 0.02 * x
    p = np.stack([x, np.zeros_like(x), z], axis=1)
    return p + rng.normal(scale=noise * spacing, size=p.shape) * np.array([0.0, 1.0, 1.0])


def strip(rows, spacing=1.0, length=200.0):
    """`rows` rows of points a spacing apart: a narrow strip of surface."""
    x = np.arange(0.0, length, spacing)
    return np.concatenate([np.stack([x, np.full_like(x, r * spacing), np.zeros_like(x)], 1) for r in range(rows)])


def refused(tmp_path, cloud, command):
    """Runs `command` on `cloud`; asserts exit 1, the file named, the reason
    given, and nothing written. Returns the error line."""
    out = tmp_path / "out"
    out.mkdir()
    args = {
        "detect": ["detect", cloud, "-o", out / "labels.csv"],
        "edges": ["edges", cloud, "-o", out / "edges.json"],
        "mesh": ["mesh", cloud, out / "mesh.ply"],
    }[command]
    r = subprocess.run([str(MESHTRIM), *map(str, args)], capture_output=True, text=True, timeout=120)
    assert r.returncode == 1, (r.returncode, r.stderr)
    assert r.stderr.startswith(f"error: {cloud}: "), r.stderr
    assert "no surface" in r.stderr and "line" in r.stderr, r.stderr
    assert "panicked" not in r.stderr
    assert list(out.iterdir()) == [], r.stderr
    return r.stderr


@pytest.mark.parametrize("command", ["detect", "edges", "mesh"])
def test_float32_line_is_refused(tmp_path, command):
    cloud = tmp_path / "line.ply"
    p = write_float32_ply(cloud, collinear())
    # Rounding made it not exactly straight: the global test (relative
    # 1e-10) alone lets it through.
    d = p[-1] - p[0]
    off = np.linalg.norm(np.cross(p - p[0], d), axis=1) / np.linalg.norm(d)
    assert off.max() > 1e-10 * np.linalg.norm(d)
    refused(tmp_path, cloud, command)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_noisy_line_profile_is_refused(tmp_path, seed):
    cloud = tmp_path / "profile.ply"
    write_float32_ply(cloud, line_profile(seed))
    refused(tmp_path, cloud, "detect")


@pytest.mark.parametrize("rows", [3, 4])
def test_narrow_strip_of_surface_is_accepted(tmp_path, rows):
    """Three or four rows of points are a surface: detection runs and
    finds the two outer rows boundary. (Two rows are accepted too, but are
    as thin as a line profile with noise of a whole spacing across it, so
    the test does not hold the threshold to them.)"""
    cloud = tmp_path / "strip.ply"
    points = write_float32_ply(cloud, strip(rows))
    labels = tmp_path / "labels.csv"
    run_meshtrim("detect", cloud, "-o", labels)
    boundary = np.loadtxt(labels, delimiter=",", skiprows=1, usecols=3).astype(bool)
    outer = (points[:, 1] == 0.0) | (points[:, 1] == rows - 1.0)
    assert boundary[outer].mean() > 0.95
