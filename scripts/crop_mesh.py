"""Crops two meshes to the same window, for close-up pictures in docs/.

    .venv-test/bin/python scripts/crop_mesh.py BEFORE AFTER CX CY HALF

keeps the faces whose centroid lies within HALF (a fraction of BEFORE's
x extent) of the point at fractions CX, CY of each mesh's bounding box, and
writes /tmp/crop_in.ply and /tmp/crop_out.ply (unused vertices dropped).
docs/img/clean_face000_detail.png: face000.ply and its `meshtrim clean`
output, 0.15 0.5 0.12, drawn by `cargo run --release --example
render_mesh -- OUT.png /tmp/crop_in.ply /tmp/crop_out.ply`.
"""

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests" / "python"))
import poisson  # noqa: E402
import synthetic  # noqa: E402


def main():
    before, after = sys.argv[1], sys.argv[2]
    cx, cy, half = (float(a) for a in sys.argv[3:6])
    for path, name in [(before, "/tmp/crop_in.ply"), (after, "/tmp/crop_out.ply")]:
        v, f = poisson.load_mesh(path)
        lo, hi = v.min(0), v.max(0)
        centre = v[f].mean(1)
        x0, y0 = lo[0] + cx * (hi[0] - lo[0]), lo[1] + cy * (hi[1] - lo[1])
        h = half * (hi[0] - lo[0])
        keep = (np.abs(centre[:, 0] - x0) < h) & (np.abs(centre[:, 1] - y0) < h)
        faces = f[keep]
        used = np.unique(faces)
        remap = -np.ones(len(v), int)
        remap[used] = np.arange(len(used))
        synthetic.write_mesh_ply(name, v[used], remap[faces], double=True)
        print(name, len(faces), "faces")


if __name__ == "__main__":
    main()
