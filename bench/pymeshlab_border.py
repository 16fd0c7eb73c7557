"""The batch peer of `meshtrim batch`: smooths the border of every STL mesh
of a directory with PyMeshLab, the way a shop scripts it today.

    python bench/pymeshlab_border.py IN_DIR OUT_DIR [JOBS]

Per file: load the STL (MeshLab merges its duplicated vertices), select the
border (`compute_selection_from_mesh_border`), smooth the selected vertices
with MeshLab's Laplacian in its 1D boundary mode (`boundary=True`: a border
vertex is averaged with its two border neighbours only, so the border curve
is smoothed along itself; `selected=True`: nothing else moves), three steps,
uniform weights, and save as binary STL. That is the closest border-only
smoothing MeshLab has; it moves the border vertices and keeps the
triangulation, where meshtrim replaces the border band by re-triangulated
faces along an FFT-smoothed boundary after its own boundary detection.

JOBS > 1 spreads the files over a multiprocessing pool (fork). Prints one
JSON line: counts, failures with their errors, and the mean load, select +
smooth and save times per file (ms).
"""

import json
import multiprocessing
import os
import sys
import time

import pymeshlab

STEPS = 3


def one(args):
    src, dst = args
    try:
        t0 = time.perf_counter()
        ms = pymeshlab.MeshSet()
        ms.load_new_mesh(src)
        t1 = time.perf_counter()
        ms.compute_selection_from_mesh_border()
        ms.apply_coord_laplacian_smoothing(
            stepsmoothnum=STEPS, boundary=True, cotangentweight=False, selected=True
        )
        t2 = time.perf_counter()
        ms.save_current_mesh(dst, binary=True)
        t3 = time.perf_counter()
        return {"file": src, "ok": True, "load_ms": (t1 - t0) * 1e3,
                "smooth_ms": (t2 - t1) * 1e3, "save_ms": (t3 - t2) * 1e3}
    except Exception as e:  # one bad file never stops the batch
        return {"file": src, "ok": False, "error": f"{type(e).__name__}: {e}"}


def main(src_dir: str, dst_dir: str, jobs: int) -> None:
    os.makedirs(dst_dir, exist_ok=True)
    names = sorted(n for n in os.listdir(src_dir) if n.lower().endswith(".stl"))
    work = [(os.path.join(src_dir, n), os.path.join(dst_dir, n)) for n in names]
    if jobs > 1:
        with multiprocessing.get_context("fork").Pool(jobs) as pool:
            rows = pool.map(one, work, chunksize=1)
    else:
        rows = [one(w) for w in work]
    ok = [r for r in rows if r["ok"]]
    mean = lambda key: round(sum(r[key] for r in ok) / max(1, len(ok)), 2)
    print(json.dumps({
        "files": len(rows),
        "ok": len(ok),
        "failed": [{"file": r["file"], "error": r["error"]} for r in rows if not r["ok"]],
        "load_ms": mean("load_ms"),
        "smooth_ms": mean("smooth_ms"),
        "save_ms": mean("save_ms"),
    }))


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], int(sys.argv[3]) if len(sys.argv) > 3 else 1)
