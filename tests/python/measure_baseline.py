"""Measures meshtrim's trimming against the density-trimming baseline (a
script, not a test): for each validation cloud, screened Poisson (PyMeshLab,
normals from compute_normal_for_point_clouds), density trimming at the 5 %
and 10 % quantiles of vertex quality, and `meshtrim MESH CLOUD OUT` (binary
from $MESHTRIM, default target/release/meshtrim); prints a markdown table.

    .venv-test/bin/python tests/python/measure_baseline.py [--depth 8] [--seed 1]

Columns: loops found (true); border -> true boundary mean and max, and true
boundary -> border max (a hole left capped shows here), in spacings; area
over the true area; largest distance from an output vertex to the cloud, in
spacings; edge-manifold; Poisson time.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import poisson  # noqa: E402
import synthetic  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--depth", type=int, default=8)
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()

    print(f"Screened Poisson depth {args.depth}, preclean off, seed {args.seed}.\n")
    print("| cloud | points | method | loops (true) | border→truth mean | max | truth→border max "
          "| area / true | max vertex→cloud | manifold | Poisson s |")
    print("|---|---:|---|---:|---:|---:|---:|---:|---:|---|---:|")
    for cloud in synthetic.validation_clouds(args.seed):
        t = time.time()
        normals = poisson.estimate_normals(cloud.points)
        agree = poisson.normal_agreement(normals, cloud.normals)
        v, f, q = poisson.reconstruct(cloud.points, normals, depth=args.depth)
        secs = time.time() - t
        rows = [("Poisson, untrimmed", v, f)]
        for quant in (0.05, 0.10):
            tv, tf = poisson.density_trim(v, f, q, quant)
            rows.append((f"density < {quant:.0%} quantile", tv, tf))
        rows.append(("meshtrim", *run_meshtrim(cloud, v, f, q)))
        for method, mv, mf in rows:
            m = poisson.border_metrics(mv, mf, cloud)
            print(
                f"| {cloud.name} | {cloud.n} | {method} | {m['loops']} ({m['true_loops']}) "
                f"| {m['border_mean']:.2f} | {m['border_max']:.2f} | {m['truth_to_border_max']:.2f} "
                f"| {m['area_ratio']:.3f} | {m['max_vertex_to_cloud']:.2f} "
                f"| {'yes' if m['edge_manifold'] else 'NO'} | {secs:.1f} |"
            )
        if agree not in (0.0, 1.0):
            print(f"<!-- {cloud.name}: estimated normals agree with the truth on {agree:.1%} -->")
        sys.stdout.flush()


def run_meshtrim(cloud, v, f, q):
    """Trims the Poisson mesh with meshtrim; returns its vertices and faces."""
    root = Path(__file__).resolve().parent.parent.parent
    binary = os.environ.get("MESHTRIM", str(root / "target" / "release" / "meshtrim"))
    with tempfile.TemporaryDirectory() as d:
        d = Path(d)
        synthetic.write_cloud_ply(d / "cloud.ply", cloud.points, cloud.normals)
        synthetic.write_mesh_ply(d / "mesh.ply", v, f, quality=q)
        subprocess.run([binary, d / "mesh.ply", d / "cloud.ply", d / "out.ply"], check=True,
                       capture_output=True)
        verts, faces = synthetic.read_ply(d / "out.ply")
    import numpy as np
    return np.stack([verts["x"], verts["y"], verts["z"]], axis=1), faces


if __name__ == "__main__":
    main()
