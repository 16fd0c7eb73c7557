"""Labels the points of every DIR/NAME.xyz with Open3D's boundary detection,
for `bench/accuracy.sh`: writes DIR/NAME.RULE.labels (one 0 or 1 per point)
for each search-radius rule of `open3d_boundary.py` (`spacings`: 3 mean
nearest-neighbour spacings; `knn30`: the mean distance to the 30th
neighbour). As in the speed benchmark: `estimate_normals(max_nn=30)`, then
`compute_boundary_points(radius, max_nn=30)` with Open3D's default angle
threshold (90°).

    python open3d_labels.py DIR
"""

import pathlib
import sys

import numpy as np
import open3d as o3d

from open3d_boundary import search_radius

RULES = ("spacings", "knn30")


def main(directory: str) -> None:
    for path in sorted(pathlib.Path(directory).glob("*.xyz")):
        points = np.loadtxt(path, dtype=np.float64).reshape(-1, 3)
        legacy = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points))
        for rule in RULES:
            radius = search_radius(legacy, points, rule)
            cloud = o3d.t.geometry.PointCloud(o3d.core.Tensor(points, o3d.core.float64))
            cloud.estimate_normals(max_nn=30)
            _, mask = cloud.compute_boundary_points(radius, 30)
            labels = mask.numpy().astype(np.uint8)
            path.with_suffix(f".{rule}.labels").write_text(
                "".join(f"{v}\n" for v in labels))


if __name__ == "__main__":
    main(sys.argv[1])
