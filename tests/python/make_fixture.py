"""Writes the trimming fixture: a small blade cloud and its screened-Poisson
mesh (see fixtures/meshes/README.md).

    bash scripts/python_env.sh
    .venv-test/bin/python tests/python/make_fixture.py [OUT_DIR]

OUT_DIR defaults to fixtures/meshes. Writes
- blade_small.ply: the blade of synthetic.blade at 7 mm pitch, seed 7;
  binary little-endian PLY, double x y z + float nx ny nz (the true normals);
- blade_small_poisson.ply: screened Poisson (PyMeshLab, depth 8, preclean
  off, one thread so the file is reproducible) of the points alone, normals estimated by
  compute_normal_for_point_clouds (poisson.reconstruct); binary
  little-endian PLY, float x y z + float quality (the Poisson density), faces
  as list uchar int.
"""

from __future__ import annotations

import hashlib
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import poisson  # noqa: E402
import synthetic  # noqa: E402

SPACING = 7.0
SEED = 7
DEPTH = 8


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(HERE, "..", "..", "fixtures", "meshes")
    os.makedirs(out, exist_ok=True)
    cloud = synthetic.blade(SPACING, SEED)
    cloud_path = os.path.join(out, "blade_small.ply")
    mesh_path = os.path.join(out, "blade_small_poisson.ply")
    synthetic.write_cloud_ply(cloud_path, cloud.points, cloud.normals)
    v, f, q = poisson.reconstruct(cloud.points, depth=DEPTH, threads=1)
    synthetic.write_mesh_ply(mesh_path, v, f, quality=q)
    for path in (cloud_path, mesh_path):
        data = open(path, "rb").read()
        print(f"{os.path.relpath(path)}: {len(data)} bytes, sha256 {hashlib.sha256(data).hexdigest()}")
    m = poisson.border_metrics(v, f, cloud)
    print(f"cloud: {cloud.n} points, true area {cloud.area:.1f} mm², "
          f"hole radii {[synthetic.blade_hole_radius(r, SPACING) for _, r in synthetic.BLADE_HOLES]}")
    print(f"mesh: {len(v)} vertices, {len(f)} faces, area {m['area']:.1f} mm² "
          f"({m['area_ratio']:.2f}× true), {m['loops']} boundary loop(s)")


if __name__ == "__main__":
    main()
