#!/usr/bin/env bash
# BPD benchmark: meshtrim against Open3D on the same seeded clouds, in one run
# (plus meshtrim's edge reconstruction time on the same cloud).
#
#   bash bench/bpd.sh [SIZES...]     (default: 12309 100000 1000000 5000000)
#
# Installs Open3D 0.20 (CPU build) into bench-venv/ on first use; it needs
# Debian's libusb-1.0-0. Prints a markdown table with wall times, meshtrim's
# peak memory and the speed ratio Open3D / meshtrim. Both sides report the
# fastest of BENCH_REPEAT runs (default 3 up to 1.5M points, 1 above).
set -euo pipefail
cd "$(dirname "$0")/.."

sizes=("$@")
[ ${#sizes[@]} -gt 0 ] || sizes=(12309 100000 1000000 5000000)

if ! dpkg -s libusb-1.0-0 >/dev/null 2>&1; then
    apt-get install -y -q libusb-1.0-0 >/dev/null
fi
if [ ! -x bench-venv/bin/python ] || ! bench-venv/bin/python -c "import open3d" 2>/dev/null; then
    python3 -m venv bench-venv
    bench-venv/bin/pip install -q open3d-cpu==0.20.0
fi
cargo build --release -q -p meshtrim-trim --example bench_bpd
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

field() { python3 -c "import json,sys; print(json.loads(sys.argv[1])[sys.argv[2]])" "$1" "$2"; }

echo "| cloud | points | meshtrim detect ms | edges ms (loops) | meshtrim peak MB | boundary | Open3D normals+detect ms | Open3D boundary | Open3D / meshtrim detect |"
echo "|---|---|---|---|---|---|---|---|---|"
for kind in sheet linescan; do
    for n in "${sizes[@]}"; do
        [ "$kind" = linescan ] && [ "$n" -gt 1000000 ] && continue
        ply="$work/$kind-$n.ply"
        ours=$(./target/release/examples/bench_bpd "$n" "$kind" "$ply")
        theirs=$(bench-venv/bin/python bench/open3d_boundary.py "$ply")
        ms=$(field "$ours" detect_ms)
        o3d=$(field "$theirs" total_ms)
        ratio=$(python3 -c "print(f'{$o3d / $ms:.2f}')")
        echo "| $kind | $(field "$ours" points) | $ms | $(field "$ours" edges_ms) ($(field "$ours" loops)) | $(field "$ours" peak_rss_mb) | $(field "$ours" boundary) | $o3d | $(field "$theirs" boundary) | $ratio |"
        rm -f "$ply"
    done
done
