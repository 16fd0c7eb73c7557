#!/usr/bin/env bash
# The Python package's binding overhead: meshtrim.detect on a ~1M-point
# cloud and meshtrim.trim of its ~2.9M-triangle screened-Poisson mesh, each
# timed from Python (the call, arrays in and out) against the library's own
# time for the same work in the same call (the report's detect_ms, edges_ms,
# trim_ms, measured inside Rust around the library). The difference is
# what the binding costs: checks, conversions and copies. Median of 3 runs.
# Uses the test venv (scripts/python_env.sh) with the package installed as
# scripts/test.sh installs it.
#
#   bash bench/python.sh [SPACING_MM] [DEPTH]
#
# Defaults: 0.37 mm (about 1.0M points) and Poisson depth 11.
set -euo pipefail
cd "$(dirname "$0")/.."
spacing=${1:-0.37}
depth=${2:-11}
bash scripts/python_env.sh >/dev/null
PATH="$PWD/.venv-test/bin:$PATH" .venv-test/bin/python -m pip install --quiet \
    --disable-pip-version-check --no-build-isolation --no-deps --force-reinstall ./python
.venv-test/bin/python - "$spacing" "$depth" <<'PY'
import statistics, sys, time
sys.path.insert(0, "tests/python")
import numpy as np
import meshtrim
import poisson, synthetic

h, depth = float(sys.argv[1]), int(sys.argv[2])
c = synthetic.blade(h, 1)
points = np.ascontiguousarray(c.points, dtype=np.float64)
vertices, faces, _ = poisson.reconstruct(c.points, c.normals, depth=depth)
vertices = np.ascontiguousarray(vertices, dtype=np.float64)
faces = np.ascontiguousarray(faces, dtype=np.int64)
print(f"cloud {len(points)} points; Poisson mesh {len(faces)} triangles, {len(vertices)} vertices")


def timed(call, library_ms):
    rows = []
    for _ in range(3):
        t = time.perf_counter()
        result = call()
        wall = (time.perf_counter() - t) * 1e3
        rows.append((wall, library_ms(result)))
    wall, lib = statistics.median(r[0] for r in rows), statistics.median(r[1] for r in rows)
    return wall, lib


detect = timed(lambda: meshtrim.detect(points), lambda d: d.summary["detect_ms"])
trim = timed(
    lambda: meshtrim.trim(vertices, faces, points),
    lambda r: r[2]["detect_ms"] + r[2]["edges_ms"] + r[2]["trim_ms"],
)
print(f"{'call':<16}{'from Python':>14}{'library':>12}{'overhead':>12}{'share':>9}")
for name, (wall, lib) in [("meshtrim.detect", detect), ("meshtrim.trim", trim)]:
    print(f"{name:<16}{wall:>11.1f} ms{lib:>9.1f} ms{wall - lib:>9.1f} ms{100 * (wall - lib) / lib:>8.1f}%")
PY
