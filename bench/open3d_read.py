"""Times Open3D's `read_point_cloud` on one file; prints one JSON line.

    python open3d_read.py FILE [REPEAT]

The fastest of REPEAT reads (default 5) in one process, as meshtrim's
`bench_read` example reports its own.
"""

import json
import sys
import time

import open3d as o3d

path = sys.argv[1]
repeat = int(sys.argv[2]) if len(sys.argv) > 2 else 5
best = float("inf")
points = 0
for _ in range(max(repeat, 1)):
    start = time.perf_counter()
    cloud = o3d.io.read_point_cloud(path)
    best = min(best, (time.perf_counter() - start) * 1e3)
    points = len(cloud.points)
print(json.dumps({"points": points, "read_ms": round(best, 1)}))
