"""Times Open3D's boundary detection on a PLY cloud; prints one JSON line.

Open3D's `compute_boundary_points` needs normals, so the time reported is
`estimate_normals` (max_nn = 30) plus the detection (max_nn = 30, radius
about 3 mean spacings), the same work meshtrim's `detect` does.

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


def main(path: str) -> None:
    legacy = o3d.io.read_point_cloud(path)
    points = np.asarray(legacy.points)
    # Mean nearest-neighbour spacing from a sample, for the search radius.
    tree = o3d.geometry.KDTreeFlann(legacy)
    sample = points[:: max(1, len(points) // 2000)]
    spacing = np.mean([np.sqrt(tree.search_knn_vector_3d(p, 2)[2][1]) for p in sample])
    radius = 3.0 * spacing
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
        "boundary": int(mask.numpy().sum()),
        "normals_ms": round(normals_s * 1e3, 1),
        "total_ms": round(total_s * 1e3, 1),
    }))


if __name__ == "__main__":
    main(sys.argv[1])
