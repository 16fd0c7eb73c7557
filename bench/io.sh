#!/usr/bin/env bash
# Cloud reading speed: meshtrim against Open3D's `read_point_cloud` on the
# same files, in one run.
#
#   bash bench/io.sh [POINTS]      (default 1000000)
#
# Writes the benchmark sheet (`bench_bpd`'s seeded cloud) as binary PLY,
# then with Open3D as ASCII PLY, ASCII, binary and LZF-compressed PCD, XYZ
# and PTS (Open3D's own writers, so its reader gets the files it writes),
# and times both readers on each: the fastest of 5 reads in one process (page cache warm on both
# sides). Installs Open3D into bench-venv/ as bench/bpd.sh does. Prints a
# markdown table with the ratio Open3D / meshtrim.
set -euo pipefail
cd "$(dirname "$0")/.."
n=${1:-1000000}
source bench/open3d_env.sh
cargo build --release -q --example bench_bpd --example bench_read
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
BENCH_REPEAT=1 ./target/release/examples/bench_bpd "$n" sheet "$work/sheet.ply" >/dev/null
bench-venv/bin/python - "$work" <<'PY'
import sys
import open3d as o3d
work = sys.argv[1]
cloud = o3d.io.read_point_cloud(f"{work}/sheet.ply")
o3d.io.write_point_cloud(f"{work}/sheet_ascii.ply", cloud, write_ascii=True)
o3d.io.write_point_cloud(f"{work}/sheet.pcd", cloud, write_ascii=True)
o3d.io.write_point_cloud(f"{work}/sheet_binary.pcd", cloud)
o3d.io.write_point_cloud(f"{work}/sheet_lzf.pcd", cloud, compressed=True)
o3d.io.write_point_cloud(f"{work}/sheet.xyz", cloud)
o3d.io.write_point_cloud(f"{work}/sheet.pts", cloud)
PY
field() { python3 -c "import json,sys; print(json.loads(sys.argv[1])[sys.argv[2]])" "$1" "$2"; }
echo "| file | MB | points | meshtrim read ms | Open3D read ms | Open3D / meshtrim |"
echo "|---|---:|---:|---:|---:|---:|"
for f in sheet.ply sheet_ascii.ply sheet.pcd sheet_binary.pcd sheet_lzf.pcd sheet.xyz sheet.pts; do
    ours=$(./target/release/examples/bench_read "$work/$f" 5)
    theirs=$(bench-venv/bin/python bench/open3d_read.py "$work/$f" 5)
    a=$(field "$ours" read_ms)
    b=$(field "$theirs" read_ms)
    mb=$(python3 -c "import os,sys; print(f'{os.path.getsize(sys.argv[1]) / 1e6:.0f}')" "$work/$f")
    ratio=$(python3 -c "import sys; print(f'{float(sys.argv[2]) / float(sys.argv[1]):.2f}')" "$a" "$b")
    echo "| $f | $mb | $(field "$ours" points) / $(field "$theirs" points) | $a | $b | $ratio |"
done
