#!/usr/bin/env bash
# End-to-end benchmark of the main job: a seeded ~1M-point blade cloud, its
# screened-Poisson mesh (PyMeshLab, depth 10), then `meshtrim MESH CLOUD OUT`
# with the time of each stage (from --report) and the peak memory
# (/usr/bin/time). Uses the test venv (created by scripts/python_env.sh).
# The peer, in the same run: the usual PyMeshLab recipe for trimming a
# Poisson mesh, its vertices below the 10 % quantile of the Poisson
# density (vertex quality) removed, timed from loading the mesh to writing
# the result, as meshtrim's wall time is. meshtrim does more (boundary
# detection, edges, an exact cut); the ratio says what that costs.
#
#   bash bench/trim.sh [SPACING_MM] [DEPTH]
#
# Defaults: 0.38 mm (about 960k points) and Poisson depth 10 (about 756k
# triangles); depth 11 gives about 2.9M triangles.
set -euo pipefail
cd "$(dirname "$0")/.."
spacing=${1:-0.38}
depth=${2:-10}
bash scripts/python_env.sh >/dev/null
cargo build --release -q --bin meshtrim
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
.venv-test/bin/python - "$work" "$spacing" "$depth" <<'PY'
import sys, time
sys.path.insert(0, "tests/python")
import poisson, synthetic
work, h, depth = sys.argv[1], float(sys.argv[2]), int(sys.argv[3])
c = synthetic.blade(h, 1)
synthetic.write_cloud_ply(f"{work}/cloud.ply", c.points, c.normals)
t = time.time()
v, f, q = poisson.reconstruct(c.points, c.normals, depth=depth)
synthetic.write_mesh_ply(f"{work}/mesh.ply", v, f, quality=q)
print(f"cloud: {len(c.points)} points; Poisson depth {depth}: {len(f)} triangles in {time.time() - t:.0f} s", flush=True)
PY
/usr/bin/time -v ./target/release/meshtrim "$work/mesh.ply" "$work/cloud.ply" "$work/out.ply" \
    --report "$work/report.json" > "$work/stdout" 2> "$work/time"
.venv-test/bin/python - "$work" > "$work/peer" <<'PY'
import sys, time
import numpy as np
import pymeshlab
work = sys.argv[1]
t = time.perf_counter()
ms = pymeshlab.MeshSet()
ms.load_new_mesh(f"{work}/mesh.ply")
q = ms.current_mesh().vertex_scalar_array()
ms.compute_selection_by_condition_per_vertex(condselect=f"(q < {float(np.quantile(q, 0.10))!r})")
ms.meshing_remove_selected_vertices()
ms.meshing_remove_unreferenced_vertices()
ms.save_current_mesh(f"{work}/peer.ply")
print(f"{time.perf_counter() - t:.3f} {ms.current_mesh().face_number()}")
PY
python3 - "$work" <<'PY'
import json, re, sys
work = sys.argv[1]
r = json.load(open(f"{work}/report.json"))
t = open(f"{work}/time").read()
peak = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", t).group(1)) / 1024
wall = re.search(r"Elapsed \(wall clock\) time.*: (.*)", t).group(1)
wall_s = sum(float(x) * 60**i for i, x in enumerate(reversed(wall.split(":"))))
peer_s, peer_faces = open(f"{work}/peer").read().split()
print("| faces in | faces out | loops | read ms | detect ms | edges ms | trim ms | write ms | wall | peak MB | PyMeshLab density trim s (faces out) | meshtrim / PyMeshLab |")
print("|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|")
print(f"| {r['faces_in']} | {r['faces_out']} | {r['loops']} | {r['read_ms']:.0f} | {r['detect_ms']:.0f} "
      f"| {r['edges_ms']:.0f} | {r['trim_ms']:.0f} | {r['write_ms']:.0f} | {wall} | {peak:.0f} "
      f"| {float(peer_s):.2f} ({peer_faces}) | {wall_s / float(peer_s):.2f} |")
PY
