"""Scanner files for the tests, written by the formats' reference
writers."""

from __future__ import annotations

import laspy
import numpy as np


def las_data(points, point_format: int, version: str) -> laspy.LasData:
    """A laspy LAS of `points` on a grid of 1e-4 from their minimum, in
    `point_format` and `version`; its other fields are the caller's to
    set."""
    header = laspy.LasHeader(point_format=point_format, version=version)
    header.scales = np.array([1e-4, 1e-4, 1e-4])
    header.offsets = points.min(axis=0)
    las = laspy.LasData(header)
    las.x, las.y, las.z = points[:, 0], points[:, 1], points[:, 2]
    return las
