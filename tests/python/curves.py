"""Helpers of the tests of the exported edge curves (STEP, IGES, DXF
splines): the clouds they run on and the distance to an edge polyline."""

from __future__ import annotations

import csv

import numpy as np
from scipy.spatial import cKDTree

import synthetic
from meshtrim_cli import ROOT, run_meshtrim, shared_data


def segment_distance(points, polyline):
    """Each point's distance to the polyline."""
    a, b = polyline[:-1], polyline[1:]
    ab = b - a
    t = np.einsum("pkj,kj->pk", points[:, None, :] - a[None], ab) / np.maximum(np.einsum("kj,kj->k", ab, ab), 1e-300)
    t = np.clip(t, 0, 1)
    nearest = a[None] + t[..., None] * ab[None]
    return np.linalg.norm(points[:, None, :] - nearest, axis=2).min(axis=1)


def cases(tmp_path):
    """The clouds the curve tests run on, by name: the blade with holes
    (corners and holes), the notched plate (8 corners, written to
    `tmp_path`) and the bunny (small, sharply turning loops)."""
    plate = tmp_path / "plate.ply"
    synthetic.write_cloud_ply(plate, synthetic.notched_plate(1.0, 2).points)
    return {
        "blade_holes": ROOT / "fixtures" / "meshes" / "blade_holes.ply",
        "notched_plate": plate,
        "bunny": shared_data("stanford_bunny/bun_zipper.ply"),
    }


def median_spacing(cloud, tmp_path):
    """The median nearest-neighbour distance of the cloud's points, as
    `meshtrim detect` reads them."""
    labels = tmp_path / "spacing_labels.csv"
    run_meshtrim("detect", cloud, "-o", labels)
    with open(labels) as f:
        xyz = np.array([[float(r[c]) for c in "xyz"] for r in csv.DictReader(f)])
    return float(np.median(cKDTree(xyz).query(xyz, k=2)[0][:, 1]))
