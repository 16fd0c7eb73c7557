"""Soak test of the commands on fresh samplings: every output valid.

    .venv-test/bin/python scripts/soak.py [--first-seed N] [--seeds N] [--stages clean,mesh,trim,crops]

Where the fuzzer (scripts/fuzz_cli.py) feeds meshtrim broken files, this
feeds it good ones it has not seen: the synthetic surfaces of
tests/python/synthetic.py (the paper's blade at 4, 8, 16 and 34 mm, the
notched plate, the curved disc, a cylinder wrapped 110 degrees past both
silhouettes), sampled with seeds the tests do not use, and runs

- `clean` on each sampling's jagged mesh (tests/python/jagged.py), and
  `clean --repair` on it with a tenth of its faces turned and fins stood
  on a hundredth of its edges (each must be taken out),
- `mesh` on each cloud (not the wrapped cylinder, which no plane sees as
  a height field: it is refused, as it should be),
- the main job on the screened-Poisson mesh of the blades at 4 and 8 mm,
  the plate and the disc (PyMeshLab, as tests/python/poisson.py makes it);

and crops of the real range scans (`crops`: a ball, one side of a plane,
or holes punched, tests/python/crops.py; the scans of
test_clean_validation.py, read from the shared data) through all three,
the crop's own vertices as the cloud.

A case **fails** when a command exits with anything but a clear error it
was expected to give, or writes a mesh PyMeshLab finds broken
(non-manifold edges or vertices, faces to re-orient, null or duplicate
faces; for a crop, more non-manifold elements than the crop had). A
crop may be refused with a clear error (exit 1, the file named, nothing
written): `mesh` refuses a crop that folds over its plane. Loops `clean` leaves, new faces under 5 degrees and trimmed
borders farther than half a spacing from the truth on average are printed
as **remarks**: the product's measured limits, not defects of the run.
Exits 1 if any case failed. CI runs a short seeded pass
(scripts/test.sh); docs/tests.md has a long run's counts.
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tests", "python"))

import crops  # noqa: E402
import jagged  # noqa: E402
import numpy as np  # noqa: E402
import poisson  # noqa: E402
import pytest  # noqa: E402
import synthetic  # noqa: E402
from meshtrim_cli import REAL_MESHES, shared_data  # noqa: E402

EXE = os.path.join(ROOT, "target", "release", "meshtrim")

SURFACES = {
    "blade 4 mm": lambda s: synthetic.blade(4.0, s),
    "blade 8 mm": lambda s: synthetic.blade(8.0, s),
    "blade 16 mm": lambda s: synthetic.blade(16.0, s),
    "blade 34 mm": lambda s: synthetic.blade(34.0, s),
    "notched plate": lambda s: synthetic.notched_plate(1.0, s),
    "curved disc": lambda s: synthetic.curved_disc(1.5, s),
    "wrapped cylinder": lambda s: synthetic.wrapped_cylinder(1.5, s),
}
# Surfaces no plane sees as a height field: `mesh` refuses them.
NOT_A_HEIGHT_FIELD = {"wrapped cylinder"}
# Poisson meshes take a second or two each: the main job on four surfaces.
TRIMMED = {"blade 4 mm", "blade 8 mm", "notched plate", "curved disc"}
# The real scans whose crops are soaked.
SCANS = REAL_MESHES
MANIFOLD_KEYS = ["non_manifold_edges", "non_manifold_vertices"]


def broken(vertices, faces, allowed=None):
    """What PyMeshLab finds wrong with a mesh, or None. ``allowed``: the
    input's own counts of non-manifold elements, which are not wrong."""
    pm = poisson.pymeshlab_validity(vertices, faces)
    allowed = allowed or {}
    keys = MANIFOLD_KEYS + ["reoriented", "null_faces", "duplicate_faces"]
    wrong = {k: pm[k] for k in keys if pm[k] > allowed.get(k, 0)}
    return wrong or None


def run(args):
    return subprocess.run([EXE, *map(str, args)], capture_output=True, text=True)


def soak_clean(cloud, work):
    """(failures, remarks) of `clean` on the sampling's jagged mesh."""
    v, f, _ = jagged.jagged_mesh(cloud)
    repair = soak_repair(v, f, len(f), work)
    src, out, rep = work / "jagged.ply", work / "clean.ply", work / "clean.json"
    synthetic.write_mesh_ply(src, v, f, double=True)
    r = run(["clean", src, out, "--report", rep])
    if r.returncode:
        return [f"clean exited {r.returncode}: {r.stderr.strip()[-300:]}"], []
    wrong = broken(*poisson.load_mesh(out))
    failures = [f"clean wrote a broken mesh: {wrong}"] if wrong else []
    report = json.loads(rep.read_text())
    remarks = [f"clean left {x['vertices']}: {x['reason']}" for x in report["loops_left"]]
    if report["faces_added"] and report["min_angle_new"] < 5.0:
        remarks.append(f"clean's smallest new angle {report['min_angle_new']:.2f}°")
    return failures + repair[0], remarks


def damaged(v, f, seed):
    """The mesh with a tenth of its faces wound the wrong way and fins (a
    thin face standing on an edge) on a hundredth of its interior edges
    whose faces are both larger than the fin: what `clean --repair` takes
    out; (vertices, faces, fins, turned)."""
    rng = np.random.default_rng(seed)
    edges = {}
    for i, face in enumerate(f):
        for k in range(3):
            a, b = sorted((face[k], face[(k + 1) % 3]))
            edges.setdefault((a, b), []).append(i)
    area = poisson.triangle_areas(v, f)
    new_v, fins = [v], []
    for (a, b), faces in sorted(edges.items()):
        length = np.linalg.norm(v[a] - v[b])
        fin_area = 0.5 * length * 0.05 * length
        if len(faces) == 2 and area[faces].min() > 2 * fin_area and rng.random() < 0.01:
            normal = np.cross(v[f[faces[0]][1]] - v[f[faces[0]][0]], v[f[faces[0]][2]] - v[f[faces[0]][0]])
            tip = (v[a] + v[b]) / 2 + 0.05 * length * normal / np.linalg.norm(normal)
            new_v.append(tip[None])
            fins.append([a, b, len(v) + len(fins)])
    turn = rng.random(len(f)) < 0.1
    out_f = f.copy()
    out_f[turn] = out_f[turn][:, [0, 2, 1]]
    return np.vstack(new_v), np.vstack([out_f, np.array(fins, dtype=f.dtype).reshape(-1, 3)]), len(fins), int(turn.sum())


def soak_repair(v, f, seed, work):
    """(failures, remarks) of `clean --repair` on the jagged mesh damaged
    (see `damaged`): it must write a valid mesh, taking out each fin and
    turning back each face turned."""
    dv, df, fins, turned = damaged(v, f, seed)
    src, out, rep = work / "damaged.ply", work / "repaired.ply", work / "repaired.json"
    synthetic.write_mesh_ply(src, dv, df, double=True)
    r = run(["clean", src, out, "--repair", "--report", rep])
    if r.returncode:
        return [f"clean --repair exited {r.returncode}: {r.stderr.strip()[-300:]}"], []
    wrong = broken(*poisson.load_mesh(out))
    failures = [f"clean --repair wrote a broken mesh: {wrong}"] if wrong else []
    report = json.loads(rep.read_text())
    got = (report["crowded_faces_removed"], report["faces_flipped"], report["one_sided_faces_removed"])
    if got != (fins, turned, 0):
        failures.append(f"clean --repair took out {got} (fins, turned, one-sided), not {(fins, turned, 0)}")
    return failures, []


def soak_mesh(name, cloud, work):
    cloud_path, out = work / "cloud.ply", work / "mesh.ply"
    synthetic.write_cloud_ply(cloud_path, cloud.points)
    r = run(["mesh", cloud_path, out])
    if name in NOT_A_HEIGHT_FIELD:
        if r.returncode == 1 and "folds over the best-fit plane" in r.stderr:
            return [], []
        return [f"mesh should refuse it (exit 1, the surface folds): exited {r.returncode}: {r.stderr.strip()[-300:]}"], []
    if r.returncode:
        return [f"mesh exited {r.returncode}: {r.stderr.strip()[-300:]}"], []
    wrong = broken(*poisson.load_mesh(out))
    return ([f"mesh wrote a broken mesh: {wrong}"] if wrong else []), []


def soak_trim(cloud, work):
    v, f, _ = poisson.reconstruct(cloud.points, cloud.normals, threads=1)
    mesh_path, cloud_path, out = work / "poisson.ply", work / "cloud.ply", work / "trimmed.ply"
    poisson.save_mesh(mesh_path, v, f)
    synthetic.write_cloud_ply(cloud_path, cloud.points)
    r = run([mesh_path, cloud_path, out])
    if r.returncode:
        return [f"trim exited {r.returncode}: {r.stderr.strip()[-300:]}"], []
    ov, of = poisson.load_mesh(out)
    wrong = broken(ov, of)
    failures = [f"trim wrote a broken mesh: {wrong}"] if wrong else []
    m = poisson.border_metrics(ov, of, cloud)
    remarks = []
    if m["loops"] != m["true_loops"] or m["border_mean"] > 0.5:
        remarks.append(f"trim: {m['loops']} loops for {m['true_loops']}, border {m['border_mean']:.3f} spacings from the truth")
    return failures, remarks


def soak_crop(vertices, faces, work):
    """(failures, remarks) of clean, mesh and the main job on one crop."""
    src, cloud = work / "crop.ply", work / "crop_cloud.ply"
    synthetic.write_mesh_ply(src, vertices, faces, double=True)
    synthetic.write_cloud_ply(cloud, vertices)
    pm_in = poisson.pymeshlab_validity(vertices, faces)
    allowed = {k: pm_in[k] for k in MANIFOLD_KEYS}
    failures, remarks = [], []
    for command, args in [("clean", ["clean", src]), ("mesh", ["mesh", cloud]), ("trim", [src, cloud])]:
        out, rep = work / f"{command}.ply", work / f"{command}.json"
        for path in (out, rep):
            path.unlink(missing_ok=True)
        r = run([*args, out, "--report", rep])
        if r.returncode == 1 and r.stderr.startswith("error: ") and not out.exists():
            remarks.append(f"{command} refused: {r.stderr.strip().splitlines()[0][:160]}")
            continue
        if r.returncode:
            failures.append(f"{command} exited {r.returncode}: {r.stderr.strip()[-300:]}")
            continue
        wrong = broken(*poisson.load_mesh(out), allowed)
        if wrong:
            failures.append(f"{command} wrote a broken mesh: {wrong} (the crop had {allowed})")
        if command == "clean":
            left = [n for x in json.loads(rep.read_text())["loops_left"] for n in x["vertices"] if n >= 8]
            if left:
                remarks.append(f"clean left loops of {left} vertices")
    return failures, remarks


def soak_crops(first_seed, seeds, work):
    """Yields (case name, failures, remarks) for each crop."""
    for index, (name, rel) in enumerate(SCANS.items()):
        try:
            path = shared_data(rel)
        except pytest.skip.Exception as missing:
            print(f"{name}: crops {missing}", flush=True)
            continue
        except pytest.fail.Exception as missing:
            yield f"{name} crops", [str(missing)], []
            continue
        vertices, faces = poisson.load_mesh(path)
        for seed in range(first_seed, first_seed + seeds):
            kind, (v, f) = crops.crop(vertices, faces, np.random.default_rng([seed, index]))
            yield f"{name} crop {seed} ({kind}, {len(f)} faces)", *soak_crop(v, f, work)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--first-seed", type=int, default=100)
    ap.add_argument("--seeds", type=int, default=10, help="samplings per surface, crops per scan")
    ap.add_argument("--stages", default="clean,mesh,trim,crops")
    args = ap.parse_args()
    stages = set(args.stages.split(","))
    if not os.path.exists(EXE):
        sys.exit(f"{EXE} not found: build it first (cargo build --release)")
    counts = []
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        for name, make in SURFACES.items():
            for seed in range(args.first_seed, args.first_seed + args.seeds):
                cloud = make(seed)
                results = []
                if "clean" in stages:
                    results.append(soak_clean(cloud, work))
                if "mesh" in stages:
                    results.append(soak_mesh(name, cloud, work))
                if "trim" in stages and name in TRIMMED:
                    results.append(soak_trim(cloud, work))
                failures = [x for fs, _ in results for x in fs]
                remarks = [x for _, rs in results for x in rs]
                if results:
                    counts.append(tell(f"{name}, seed {seed}", failures, remarks))
        if "crops" in stages:
            for case, failures, remarks in soak_crops(args.first_seed, args.seeds, work):
                counts.append(tell(case, failures, remarks))
    failed = sum(c == "failed" for c in counts)
    remarked = sum(c == "remarked" for c in counts)
    print(f"{len(counts)} cases, {failed} failed, {remarked} with remarks only")
    sys.exit(1 if failed else 0)


def tell(case, failures, remarks):
    """Prints a case's failures and remarks; returns its outcome."""
    for line in [f"FAIL {x}" for x in failures] + [f"remark: {x}" for x in remarks]:
        print(f"{case}: {line}", flush=True)
    return "failed" if failures else "remarked" if remarks else "passed"


if __name__ == "__main__":
    main()
