"""Times Open3D's boundary detection on a PLY cloud; prints one JSON line.

Open3D's `compute_boundary_points` needs normals, so the time reported is
`estimate_normals` (max_nn = 30) plus the detection (max_nn = 30), the
same work meshtrim's `detect` does.

    python open3d_boundary.py CLOUD.ply [spacings|knn30]

The search radius (Open3D has no threshold-free choice) is either
- `spacings` (default, the speed target's rule): 3 mean nearest-neighbour
  spacings;
- `knn30`: the mean distance to the 30th nearest neighbour, the radius in
  which `max_nn = 30` is filled. On an isotropic cloud that is about 3
  grid pitches too; on a line scan, whose nearest neighbours all lie on
  the same scan line, 3 spacings do not reach the next line and Open3D
  labels every point boundary, while this radius spans the lines.
Both are estimated from a sample of about 2,000 points.

Like `bench_bpd`, it runs `BENCH_REPEAT` times (default: 3 up to 1.5M
points, 1 above), each time on a fresh copy of the cloud, and reports the
fastest run, so both sides get the same treatment.
"""

import json
import os
import sys
import time

import numpy as np
import open3d as o3d


def search_radius(legacy: o3d.geometry.PointCloud, points: np.ndarray, rule: str) -> float:
    tree = o3d.geometry.KDTreeFlann(legacy)
    sample = points[:: max(1, len(points) // 2000)]
    if rule == "spacings":
        return 3.0 * float(np.mean([np.sqrt(tree.search_knn_vector_3d(p, 2)[2][1]) for p in sample]))
    if rule == "knn30":
        return float(np.mean([np.sqrt(tree.search_knn_vector_3d(p, 30)[2][29]) for p in sample]))
    sys.exit(f"unknown radius rule {rule!r} (spacings or knn30)")


def main(path: str, rule: str) -> None:
    legacy = o3d.io.read_point_cloud(path)
    points = np.asarray(legacy.points)
    radius = search_radius(legacy, points, rule)
    default_repeat = 3 if len(points) <= 1_500_000 else 1
    repeat = max(1, int(os.environ.get("BENCH_REPEAT", default_repeat)))
    best = None
    for _ in range(repeat):
        cloud = o3d.t.geometry.PointCloud(o3d.core.Tensor(points, o3d.core.float64))
        start = time.perf_counter()
        cloud.estimate_normals(max_nn=30)
        normals_s = time.perf_counter() - start
        _, mask = cloud.compute_boundary_points(radius, 30)
        total_s = time.perf_counter() - start
        if best is None or total_s < best[1]:
            best = (normals_s, total_s, mask)
    normals_s, total_s, mask = best
    print(json.dumps({
        "points": len(points),
        "radius_rule": rule,
        "radius": round(radius, 4),
        "boundary": int(mask.numpy().sum()),
        "normals_ms": round(normals_s * 1e3, 1),
        "total_ms": round(total_s * 1e3, 1),
    }))


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2] if len(sys.argv) > 2 else "spacings")
