#!/usr/bin/env bash
# Runs every command of a meshtrim binary over the fixtures and the real
# scans and prints one sha256 per output (files, JSON reports with their
# timings removed, and error messages), sorted by name. Two binaries give
# the same list exactly when their outputs are byte-identical, which is how
# a change that must not change behaviour is checked:
#
#   bash scripts/output_checksums.sh target/release/meshtrim > after.txt
#   diff before.txt after.txt
#
# DATA (default ../shared/data or MESHTRIM_SHARED_DATA) holds the real scans.
set -uo pipefail
cd "$(dirname "$0")/.."
bin=$(realpath "${1:-target/release/meshtrim}")
data=${MESHTRIM_SHARED_DATA:-../shared/data}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

# Drops the keys whose values are timings or paths, so reports compare.
strip_timings() {
    python3 -c '
import json, sys
def strip(v):
    if isinstance(v, dict):
        return {k: strip(x) for k, x in v.items()
                if not k.endswith("_ms") and k not in ("file", "input", "output", "cloud", "mesh")}
    if isinstance(v, list):
        return [strip(x) for x in v]
    return v
text = open(sys.argv[1]).read()
try:
    print(json.dumps(strip(json.loads(text)), sort_keys=True))
except ValueError:
    print(text)
' "$1"
}

# run NAME ARGS...: runs the binary; keeps its stderr as NAME.err when it fails.
run() {
    local name=$1
    shift
    if ! "$bin" "$@" >/dev/null 2>"$out/$name.err"; then
        sed "s#$out/##g; s#$data/##g" "$out/$name.err" >"$out/$name.error"
    fi
    rm -f "$out/$name.err"
}

clouds=(fixtures/meshes/blade_holes.ply fixtures/meshes/blade_small.ply
    fixtures/meshes/blade_small_poisson.ply fixtures/meshes/blade_jagged.stl)
meshes=(fixtures/meshes/blade_small_poisson.ply fixtures/meshes/blade_jagged.stl)
while IFS= read -r f; do
    clouds+=("$f")
    case $f in *.ply) meshes+=("$f") ;; esac
done < <(find "$data" -type f \( -name '*.ply' -o -name '*.pcd' -o -name '*.csv' \) | sort)

for f in "${clouds[@]}"; do
    n=$(basename "$f" | tr . _)
    run "detect_$n" detect "$f" -o "$out/detect_$n.csv"
    run "detect_${n}_ply" detect "$f" -o "$out/detect_$n.ply"
    run "detect_${n}_view" detect "$f" --view-along 0,0,1 -o "$out/detect_${n}_view.csv"
    run "detect_${n}_iso" detect "$f" --no-anisotropy -o "$out/detect_${n}_iso.csv"
    run "edges_$n" edges "$f" -o "$out/edges_$n.json"
    run "edges_${n}_obj" edges "$f" -o "$out/edges_$n.obj"
    run "edges_${n}_svg" edges "$f" -o "$out/edges_$n.svg"
    run "edges_${n}_nooff" edges "$f" --no-offset -o "$out/edges_${n}_nooff.json"
    run "mesh_$n" mesh "$f" "$out/mesh_$n.ply" --report "$out/mesh_$n.report.json"
done
for f in "${meshes[@]}"; do
    n=$(basename "$f" | tr . _)
    run "clean_$n" clean "$f" "$out/clean_$n.ply" --report "$out/clean_$n.report.json"
done
fx=fixtures/meshes
for ext in ply obj stl gltf glb; do
    run "trim_$ext" "$fx/blade_small_poisson.ply" "$fx/blade_small.ply" "$out/trim.$ext" \
        --report "$out/trim_$ext.report.json"
done
run trim_nooff trim "$fx/blade_small_poisson.ply" "$fx/blade_small.ply" "$out/trim_nooff.ply" --no-offset
run trim_holes trim "$fx/blade_small_poisson.ply" "$fx/blade_holes.ply" "$out/trim_holes.ply"
run trim_bunny trim "$data/stanford_bunny/bun_zipper_res2.ply" "$data/stanford_bunny/bun000.ply" \
    "$out/trim_bunny.ply" --report "$out/trim_bunny.report.json"
run batch batch "$fx" --out-dir "$out/batch" --report "$out/batch.report.json" --jobs 2

cd "$out"
for r in $(find . -name '*.report.json'); do
    strip_timings "$r" >"$r.tmp" && mv "$r.tmp" "$r"
done
find . -type f | sort | xargs sha256sum
