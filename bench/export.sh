#!/usr/bin/env bash
# Edge export speed: `meshtrim edges` on a ~1M-point cloud (the seeded,
# twisted sheet with three holes of bench/bpd.sh) written as each edges
# format, the write time (for STEP, IGES and DXF splines the B-spline fit included) against the
# detection time of the same run. Median of BENCH_ROUNDS runs (default 3)
# per format; prints a markdown table.
#
#   bash bench/export.sh [POINTS]      (default: 1000000)
set -euo pipefail
cd "$(dirname "$0")/.."
n=${1:-1000000}
rounds=${BENCH_ROUNDS:-3}
cargo build --release -q --bin meshtrim --example bench_bpd
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
BENCH_REPEAT=1 ./target/release/examples/bench_bpd "$n" sheet "$work/sheet.ply" >/dev/null

echo "| output | points | loops | edges | corners | detect ms | edges ms | write ms | write / detect | file MB |"
echo "|---|---|---|---|---|---|---|---|---|---|"
# "dxf+splines" is a .dxf written with --dxf-splines.
for format in json obj svg dxf dxf+splines step igs; do
    flags=()
    [ "$format" = dxf+splines ] && flags=(--dxf-splines)
    out="$work/edges.${format%+splines}"
    runs=()
    for _ in $(seq "$rounds"); do
        runs+=("$(./target/release/meshtrim edges "$work/sheet.ply" -o "$out" "${flags[@]}" --json)")
    done
    python3 - "$format" "$(stat -c %s "$out")" "${runs[@]}" <<'PY'
import json, statistics, sys
fmt, size, runs = sys.argv[1], int(sys.argv[2]), [json.loads(r) for r in sys.argv[3:]]
med = lambda key: statistics.median(r[key] for r in runs)
r = runs[0]
detect, edges, write = med("detect_ms"), med("edges_ms"), med("write_ms")
print(f"| .{fmt} | {r['points']} | {r['loops']} | {r['edges']} | {r['corners']} | "
      f"{detect:.0f} | {edges:.0f} | {write:.1f} | {write / detect:.3f} | {size / 1e6:.2f} |")
PY
done
