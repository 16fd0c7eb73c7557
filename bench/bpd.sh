#!/usr/bin/env bash
# BPD benchmark: meshtrim against Open3D on the same seeded clouds, in one run
# (plus meshtrim's edge reconstruction time on the same cloud).
#
#   bash bench/bpd.sh [SIZES...]     (default: 12309 100000 1000000 5000000)
#
# Installs Open3D 0.20 (CPU build) into bench-venv/ on first use; it needs
# Debian's libusb-1.0-0. Prints a markdown table with wall times, meshtrim's
# peak memory and the speed ratio Open3D / meshtrim. Open3D needs a search
# radius; it runs with two (bench/open3d_boundary.py): 3 mean nearest-
# neighbour spacings (the speed target's rule, the headline ratio) and the
# mean distance to the 30th neighbour, which on a line scan is the smallest of
# the two that reaches the next scan line (with the first, Open3D labels
# every point of a line scan boundary). The tools run in
# alternating rounds (BENCH_ROUNDS, default 3 up to 1.5M points, 1 above);
# in each round each tool's process runs the detection BENCH_REPEAT times
# (default 3 up to 1.5M points, 1 above) and each side reports its fastest
# run. Both sides are measured warm: Open3D's script loads its library and
# builds a k-d tree before its timed runs. meshtrim's first, cold run in a
# process (fastest over the rounds) is in a column of its own.
set -euo pipefail
cd "$(dirname "$0")/.."

sizes=("$@")
[ ${#sizes[@]} -gt 0 ] || sizes=(12309 100000 1000000 5000000)

source bench/open3d_env.sh
cargo build --release -q --example bench_bpd
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

field() { python3 -c "import json,sys; print(json.loads(sys.argv[1])[sys.argv[2]])" "$1" "$2"; }

echo "| cloud | points | meshtrim detect ms | meshtrim cold ms | edges ms (loops) | meshtrim peak MB | boundary | Open3D normals+detect ms | Open3D boundary | Open3D / meshtrim detect | Open3D, 30-NN radius: ms | boundary | ratio |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|"
for kind in sheet linescan; do
    for n in "${sizes[@]}"; do
        [ "$kind" = linescan ] && [ "$n" -gt 1000000 ] && continue
        ply="$work/$kind-$n.ply"
        # Rounds alternate the two tools, so that a slow spell of the
        # machine hits both; each side's fastest round is reported. Peak
        # memory, edges and counts are the first round's.
        rounds=${BENCH_ROUNDS:-$([ "$n" -le 1500000 ] && echo 3 || echo 1)}
        repeat=${BENCH_REPEAT:-$([ "$n" -le 1500000 ] && echo 3 || echo 1)}
        ms=inf
        cold=inf
        o3d=inf
        o3d_knn=inf
        for round in $(seq "$rounds"); do
            run=$(BENCH_REPEAT=$repeat ./target/release/examples/bench_bpd "$n" "$kind" \
                "$([ "$round" = 1 ] && echo "$ply")")
            [ "$round" = 1 ] && ours=$run
            theirs_run=$(BENCH_REPEAT=$repeat bench-venv/bin/python bench/open3d_boundary.py "$ply")
            [ "$round" = 1 ] && theirs=$theirs_run
            theirs_knn_run=$(BENCH_REPEAT=$repeat bench-venv/bin/python bench/open3d_boundary.py "$ply" knn30)
            [ "$round" = 1 ] && theirs_knn=$theirs_knn_run
            ms=$(python3 -c "print(min(float('$ms'), $(field "$run" detect_ms)))")
            cold=$(python3 -c "print(min(float('$cold'), $(field "$run" first_ms)))")
            o3d=$(python3 -c "print(min(float('$o3d'), $(field "$theirs_run" total_ms)))")
            o3d_knn=$(python3 -c "print(min(float('$o3d_knn'), $(field "$theirs_knn_run" total_ms)))")
        done
        ratio=$(python3 -c "print(f'{$o3d / $ms:.2f}')")
        ratio_knn=$(python3 -c "print(f'{$o3d_knn / $ms:.2f}')")
        echo "| $kind | $(field "$ours" points) | $ms | $cold | $(field "$ours" edges_ms) ($(field "$ours" loops)) | $(field "$ours" peak_rss_mb) | $(field "$ours" boundary) | $o3d | $(field "$theirs" boundary) | $ratio | $o3d_knn | $(field "$theirs_knn" boundary) | $ratio_knn |"
        rm -f "$ply"
    done
done
