#!/usr/bin/env bash
# Reading speed of the scanner formats against their reference readers, in
# the same run: a 10M-point LAZ (and the same as LAS) against laspy with the
# lazrs backend (parallel), and a 4-scan, 10M-point E57 with poses against
# pye57 (libE57Format). Each side reads the file into an (n, 3) float64
# array: meshtrim through its Python package (meshtrim.read_cloud, the
# CLI's reader), laspy as x, y, z columns, pye57 scan by scan posed
# (read_scan(transform=True)) and stacked. Best of 3; the files are made
# by laspy and pye57 first (not timed). Uses the test venv.
#
#   bash bench/formats.sh [MILLIONS_OF_POINTS]
set -euo pipefail
cd "$(dirname "$0")/.."
millions=${1:-10}
bash scripts/python_env.sh >/dev/null
PATH="$PWD/.venv-test/bin:$PATH" .venv-test/bin/python -m pip install --quiet \
    --disable-pip-version-check --no-build-isolation --no-deps --force-reinstall ./python
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
.venv-test/bin/python - "$work" "$millions" <<'PY'
import sys, time
import laspy
import numpy as np
import pye57
import meshtrim

work, n = sys.argv[1], int(float(sys.argv[2]) * 1e6)
rng = np.random.default_rng(1)
side = int(np.sqrt(n))
u, v = np.meshgrid(np.arange(side) * 1e-3, np.arange(n // side + 1) * 1e-3)
xyz = np.column_stack([u.ravel()[:n], v.ravel()[:n], 0.01 * np.sin(u.ravel()[:n] * 7)])
xyz += rng.normal(0, 1e-4, xyz.shape) + [612_345.0, 6_012_345.0, 100.0]
for ext in ("las", "laz"):
    header = laspy.LasHeader(point_format=1, version="1.2")
    header.offsets, header.scales = xyz.min(axis=0), [1e-5] * 3
    las = laspy.LasData(header)
    las.x, las.y, las.z = xyz[:, 0], xyz[:, 1], xyz[:, 2]
    las.write(f"{work}/cloud.{ext}")
e57 = pye57.E57(f"{work}/scans.e57", mode="w")
for block in np.array_split(xyz - xyz.mean(axis=0), 4):
    data = {"cartesianX": block[:, 0], "cartesianY": block[:, 1], "cartesianZ": block[:, 2]}
    e57.write_scan_raw(data, rotation=np.array([0.9238795, 0, 0, 0.3826834]), translation=np.array([10.0, 20.0, 0.0]))
e57.close()


def best(read):
    times, out = [], None
    for _ in range(3):
        t = time.perf_counter()
        out = read()
        times.append(time.perf_counter() - t)
    return min(times), out


def laspy_read(path):
    las = laspy.read(path)
    return np.column_stack([np.asarray(las.x), np.asarray(las.y), np.asarray(las.z)])


def pye57_read(path):
    f = pye57.E57(path)
    scans = [f.read_scan(i, ignore_missing_fields=True, transform=True) for i in range(f.scan_count)]
    return np.vstack([np.column_stack([s["cartesianX"], s["cartesianY"], s["cartesianZ"]]) for s in scans])


print(f"{len(xyz)} points")
print(f"{'file':<12}{'meshtrim':>11}{'peer':>22}{'ratio':>8}  same points")
for name, peer_name, peer in [("cloud.las", "laspy", laspy_read), ("cloud.laz", "laspy+lazrs", laspy_read), ("scans.e57", "pye57", pye57_read)]:
    path = f"{work}/{name}"
    ours_s, ours = best(lambda: meshtrim.read_cloud(path))
    peer_s, theirs = best(lambda: peer(path))
    same = "exact" if np.array_equal(ours, theirs) else f"max diff {np.abs(ours - theirs).max():.1e}"
    print(f"{name:<12}{ours_s:>9.2f} s{peer_name:>14}{peer_s:>6.2f} s{peer_s / ours_s:>7.2f}x  {same}")
PY
