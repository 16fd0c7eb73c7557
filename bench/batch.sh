#!/usr/bin/env bash
# Batch benchmark: `meshtrim batch` cleaning COUNT generated jagged
# meshes of about TRIANGLES triangles, with 1 and 2 jobs, against the same
# batch done the way a shop does it today: a Python loop over PyMeshLab
# (border selection + MeshLab's 1D boundary Laplacian, three steps; see
# bench/pymeshlab_border.py), in one process and in a 2-process pool.
#
#   bash bench/batch.sh [COUNT] [TRIANGLES]     (default: 200 50000)
#
# Inputs go to $BENCH_DIR/in (default target/bench-batch/in) and are reused
# when the stamp says they were made with the same COUNT and TRIANGLES;
# outputs and reports go beside them and are remade every run. Installs
# pymeshlab 2025.7.post1 and numpy 2.2.6 into bench-venv/ on first use.
#
# Prints: files/s of each run and the speed-ups, meshtrim / peer ratios, the
# per-file split of meshtrim's time from its CSV report and the overhead
# (defined below), the start-up of one meshtrim process, the load average
# before and after, and whether every file went through and the 1-job and
# 2-job outputs are byte-identical. Fails (after printing) if any file
# failed or the outputs differ.
set -euo pipefail
cd "$(dirname "$0")/.."

count=${1:-200}
triangles=${2:-50000}
dir=${BENCH_DIR:-target/bench-batch}
bin=${CARGO_TARGET_DIR:-target}/release

echo "load average before: $(cat /proc/loadavg)"
load_before=$(cut -d' ' -f1-3 /proc/loadavg)

if [ ! -x bench-venv/bin/python ] || ! bench-venv/bin/python -c "import pymeshlab, numpy" 2>/dev/null; then
    [ -x bench-venv/bin/python ] || python3 -m venv bench-venv
    bench-venv/bin/pip install -q pymeshlab==2025.7.post1 numpy==2.2.6
fi
cargo build --release -q --bin meshtrim --example make_jagged

mkdir -p "$dir"
stamp="$dir/in.stamp"
if [ "$(cat "$stamp" 2>/dev/null)" != "$count $triangles" ] \
    || [ "$(find "$dir/in" -name 'jagged_*.stl' 2>/dev/null | wc -l)" -ne "$count" ]; then
    rm -rf "$dir/in" "$stamp"
    "$bin/examples/make_jagged" "$dir/in" "$count" "$triangles"
    echo "$count $triangles" > "$stamp"
else
    echo "reusing $count meshes in $dir/in"
fi
rm -rf "$dir/out1" "$dir/out2" "$dir/peer1" "$dir/peer2" "$dir"/r*.csv "$dir"/*.log "$dir"/*.json \
    "$dir"/*.time "$dir/clean_one.stl"

# Wall clock and CPU of one command: "wall_s user_s sys_s" into $dir/$1.time.
timed() {
    local name=$1
    shift
    /usr/bin/time -f "%e %U %S" -o "$dir/$name.time" "$@"
}

status=0
echo "meshtrim batch, 1 job ..."
timed m1 "$bin/meshtrim" batch "$dir/in" --out-dir "$dir/out1" --jobs 1 --report "$dir/r1.csv" \
    > "$dir/m1.log" 2>&1 || status=1
echo "meshtrim batch, 2 jobs ..."
timed m2 "$bin/meshtrim" batch "$dir/in" --out-dir "$dir/out2" --jobs 2 --report "$dir/r2.csv" \
    > "$dir/m2.log" 2>&1 || status=1
tail -n 1 "$dir/m1.log" "$dir/m2.log"
echo "PyMeshLab loop, 1 process ..."
timed p1 bench-venv/bin/python bench/pymeshlab_border.py "$dir/in" "$dir/peer1" 1 > "$dir/p1.json"
echo "PyMeshLab loop, 2 processes ..."
timed p2 bench-venv/bin/python bench/pymeshlab_border.py "$dir/in" "$dir/peer2" 2 > "$dir/p2.json"

# Start-up: a meshtrim process that does nothing (20 runs), and Python with
# pymeshlab imported (5 runs), wall clock each.
startup() {
    local runs=$1
    shift
    python3 - "$runs" "$@" <<'PY'
import subprocess, sys, time
runs, cmd = int(sys.argv[1]), sys.argv[2:]
t = []
for _ in range(runs):
    s = time.perf_counter()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    t.append(time.perf_counter() - s)
print(f"{sum(t) / len(t) * 1e3:.2f}")
PY
}
startup_ms=$(startup 20 "$bin/meshtrim" --version)
# The algorithm's own split (boundary detection on all vertices, then the
# border replacement) on the first file, from `meshtrim clean --report`,
# on one thread like `batch --jobs 1`.
first=$(find "$dir/in" -name 'jagged_*.stl' | sort | sed -n 1p)  # sed reads all: no SIGPIPE under pipefail
RAYON_NUM_THREADS=1 "$bin/meshtrim" clean "$first" "$dir/clean_one.stl" --report "$dir/clean_one.json" > /dev/null
py_startup_ms=$(startup 5 bench-venv/bin/python -c "import pymeshlab")

identical=yes
diff -rq "$dir/out1" "$dir/out2" > "$dir/diff.log" 2>&1 || identical=no

echo "load average after: $(cat /proc/loadavg)"
load_after=$(cut -d' ' -f1-3 /proc/loadavg)

python3 - "$dir" "$count" "$identical" "$startup_ms" "$py_startup_ms" "$load_before" "$load_after" "$(nproc)" <<'PY' || status=1
import csv, json, os, sys
d, count, identical, startup_ms, py_startup_ms, load_before, load_after, cores = sys.argv[1:]
startup_ms, py_startup_ms = float(startup_ms), float(py_startup_ms)

def times(name):
    wall, user, sys_ = map(float, open(f"{d}/{name}.time").read().split()[-3:])
    return wall, user + sys_

bad = False
runs = {}
for name, jobs in (("m1", 1), ("m2", 2)):
    rows = list(csv.DictReader(open(f"{d}/r{jobs}.csv")))
    wall, cpu = times(name)
    ok = [r for r in rows if r["status"] == "ok"]
    for r in rows:
        if r["status"] != "ok":
            bad = True
            print(f"FAILED ({jobs} job{'s' if jobs > 1 else ''}): {r['input']}: {r['error']}")
    if len(rows) != int(count):
        bad = True
        print(f"FAILED: the {jobs}-job report has {len(rows)} rows for {count} inputs")
    n = len(ok)
    mean = lambda k: sum(float(r[k]) for r in ok) / n
    read, alg, write, total = mean("read_ms"), mean("algorithm_ms"), mean("write_ms"), mean("total_ms")
    # Worker time = wall x jobs. Per file, it splits into the algorithm
    # (algorithm_ms) and the overhead: reading, writing, the rest of the
    # file's own time (total_ms - read - algorithm - write: output checks,
    # the rename, the printed line), and the worker time outside any file
    # (process start-up, input expansion and planning, the report, and with
    # 2 jobs the idle worker at the end), spread over the files.
    outside = (wall * 1e3 * jobs - sum(float(r["total_ms"]) for r in rows)) / len(rows)
    overhead = wall * 1e3 * jobs / len(rows) - alg
    runs[jobs] = dict(wall=wall, cpu=cpu, files=len(rows), ok=n, fps=n / wall, read=read, alg=alg,
                      write=write, rest=total - read - alg - write, outside=outside, overhead=overhead,
                      faces=mean("faces_in"))

peer = {}
for name, jobs in (("p1", 1), ("p2", 2)):
    r = json.load(open(f"{d}/{name}.json"))
    wall, cpu = times(name)
    for f in r["failed"]:
        print(f"PEER FAILED ({jobs} process{'es' if jobs > 1 else ''}): {f['file']}: {f['error']}")
    peer[jobs] = dict(wall=wall, cpu=cpu, ok=r["ok"], fps=r["ok"] / wall, load=r["load_ms"],
                      smooth=r["smooth_ms"], save=r["save_ms"])

m1, m2, p1, p2 = runs[1], runs[2], peer[1], peer[2]
print()
print(f"{count} meshes, {m1['faces']:.0f} triangles on average; {cores} cores; "
      f"load average {load_before} before, {load_after} after")
print()
# cores used = CPU s / wall s: below the jobs asked for when other
# processes share the machine (then the speed-up is the machine's, not ours).
print("| run | files ok | wall s | CPU s | cores used | CPU ms / file | files/s | speed-up 1→2 | meshtrim / PyMeshLab files/s |")
print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
print(f"| meshtrim batch --jobs 1 | {m1['ok']}/{m1['files']} | {m1['wall']:.1f} | {m1['cpu']:.1f} | {m1['cpu'] / m1['wall']:.2f} | {m1['cpu'] * 1e3 / m1['files']:.0f} | {m1['fps']:.2f} | | {m1['fps'] / p1['fps']:.2f} |")
print(f"| meshtrim batch --jobs 2 | {m2['ok']}/{m2['files']} | {m2['wall']:.1f} | {m2['cpu']:.1f} | {m2['cpu'] / m2['wall']:.2f} | {m2['cpu'] * 1e3 / m2['files']:.0f} | {m2['fps']:.2f} | {m2['fps'] / m1['fps']:.2f} | {m2['fps'] / p2['fps']:.2f} |")
print(f"| PyMeshLab loop, 1 process | {p1['ok']}/{count} | {p1['wall']:.1f} | {p1['cpu']:.1f} | {p1['cpu'] / p1['wall']:.2f} | {p1['cpu'] * 1e3 / int(count):.0f} | {p1['fps']:.2f} | | |")
print(f"| PyMeshLab pool, 2 processes | {p2['ok']}/{count} | {p2['wall']:.1f} | {p2['cpu']:.1f} | {p2['cpu'] / p2['wall']:.2f} | {p2['cpu'] * 1e3 / int(count):.0f} | {p2['fps']:.2f} | {p2['fps'] / p1['fps']:.2f} | |")
print()
print("Per file, mean ms (meshtrim from its CSV report; PyMeshLab timed in the loop):")
print()
print("| run | read | algorithm | write | rest of the file | outside files | overhead | overhead / algorithm |")
print("|---|---:|---:|---:|---:|---:|---:|---:|")
for jobs, m in runs.items():
    print(f"| meshtrim, {jobs} job{'s' if jobs > 1 else ''} | {m['read']:.1f} | {m['alg']:.1f} | {m['write']:.1f} "
          f"| {m['rest']:.1f} | {m['outside']:.1f} | {m['overhead']:.1f} | {m['overhead'] / m['alg']:.1%} |")
for jobs, p in peer.items():
    print(f"| PyMeshLab, {jobs} process{'es' if jobs > 1 else ''} | {p['load']:.1f} | {p['smooth']:.1f} (select + smooth) "
          f"| {p['save']:.1f} | | | | |")
print()
print(f"start-up: `meshtrim --version` {startup_ms:.2f} ms (mean of 20); "
      f"`python -c 'import pymeshlab'` {py_startup_ms:.0f} ms (mean of 5)")
c = json.load(open(f"{d}/clean_one.json"))
print(f"algorithm split, `meshtrim clean` on one thread, on {os.path.basename(c['input'])}: local resolution {c['resolution_ms']:.1f} ms, "
      f"border replacement {c['clean_ms']:.1f} ms (read {c['read_ms']:.1f}, write {c['write_ms']:.1f})")
print(f"outputs of 1 and 2 jobs byte-identical: {identical}")
print()
print("overhead per file = wall x jobs / files - mean algorithm_ms = read + write + rest of the file")
print("+ outside files; outside files = (wall x jobs - sum of total_ms) / files: start-up,")
print("input expansion, the report and, with 2 jobs, a worker idle at the end.")
if identical != "yes":
    print(f"1-job and 2-job outputs differ: see {d}/diff.log")
    bad = True
sys.exit(1 if bad else 0)
PY
exit $status
