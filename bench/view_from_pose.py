"""Does an E57 scan's pose give detection a useful line of sight?

Each Stanford bunny range scan is written into a one-scan E57 file with its
pose from bun.conf (pye57), read back by meshtrim posed into the common
frame, and detected three ways: the paper's projection (no view), the pose
translation as the scanner's position (`--view-from`), and the scan's own z
axis, rotated by the pose, as the line of sight (`--view-along`: the
Cyberware scanner looked along its frame's z). Each is scored against the
scan's range-grid border as tests/python/test_detect_real_truth.py scores
detection (precision and recall within 1.5 median edges).

    .venv-test/bin/python bench/view_from_pose.py   # needs ../shared/data
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pye57
from scipy.spatial import cKDTree

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests" / "python"))
from meshtrim_cli import MESHTRIM, shared_data  # noqa: E402
from test_detect_real_truth import TOLERANCE, border_truth  # noqa: E402

SCANS = ["bun000", "bun045", "bun090", "chin"]


def poses(conf: Path) -> dict:
    """bun.conf: `bmesh FILE tx ty tz qi qj qk qr` (quaternion last-real)."""
    out = {}
    for line in conf.read_text().splitlines():
        parts = line.split()
        if parts and parts[0] == "bmesh":
            t = np.array([float(c) for c in parts[2:5]])
            qi, qj, qk, qr = (float(c) for c in parts[5:9])
            out[parts[1].removesuffix(".ply")] = (np.array([qr, qi, qj, qk]), t)
    return out


def rotate(q, v):
    w, x, y, z = q / np.linalg.norm(q)
    r = np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )
    return r @ v


def score(labels, v, used, plausible, clear, h):
    detected = labels & used
    near = lambda points, to: cKDTree(v[to]).query(v[points])[0] <= TOLERANCE * h
    return near(detected, plausible).mean(), near(clear, detected).mean()


def main():
    conf = poses(shared_data("stanford_bunny/bun.conf"))
    print(f"{'scan':<8}{'view':<34}{'precision':>10}{'recall':>8}")
    with tempfile.TemporaryDirectory() as work:
        for name in SCANS:
            v, used, plausible, clear, h = border_truth(shared_data(f"stanford_bunny/{name}.ply"))
            rotation, translation = conf[name]
            path = Path(work) / f"{name}.e57"
            e57 = pye57.E57(str(path), mode="w")
            e57.write_scan_raw(
                {"cartesianX": v[:, 0], "cartesianY": v[:, 1], "cartesianZ": v[:, 2]},
                rotation=rotation,
                translation=translation,
            )
            e57.close()
            axis = rotate(rotation, np.array([0.0, 0.0, 1.0]))
            views = {
                "none (the paper's projection)": [],
                "--view-from the pose translation": ["--view-from", ",".join(repr(float(c)) for c in translation)],
                "--view-along the pose's z axis": ["--view-along", ",".join(repr(float(c)) for c in axis)],
            }
            for label, extra in views.items():
                out = Path(work) / "labels.csv"
                subprocess.run([str(MESHTRIM), "detect", str(path), "-o", str(out), *extra], check=True, capture_output=True)
                labels = np.loadtxt(out, delimiter=",", skiprows=1)[:, 3].astype(bool)
                precision, recall = score(labels, v, used, plausible, clear, h)
                print(f"{name:<8}{label:<34}{precision:>10.3f}{recall:>8.3f}")


if __name__ == "__main__":
    main()
