"""Clean or trim every mesh of a folder with meshtrim, one Dask task per
file: on this machine's cores (a ``LocalCluster``), or on a cluster when
given its scheduler's address. The same code runs in both places.

    python examples/python/dask_clean.py SCANS/ OUT/
    python examples/python/dask_clean.py SCANS/ OUT/ --scheduler tcp://host:8786

The files pair as ``meshtrim batch`` pairs them: a mesh ``S.EXT`` (.stl,
.ply, .obj, .gltf, .glb) with a cloud ``S.cloud.EXT`` beside it is trimmed
with that cloud; any other mesh is cleaned. Each output is ``OUT/`` plus the
mesh's file name, the same bytes ``meshtrim batch SCANS/ --out-dir OUT/``
writes. The workers need the ``meshtrim`` package (``pip install ./python``)
and to see the folders (a shared file system on a cluster).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import meshtrim

MESH_EXTENSIONS = {".stl", ".ply", ".obj", ".gltf", ".glb"}
CLOUD_EXTENSIONS = [".ply", ".obj", ".pcd", ".xyz", ".txt", ".csv", ".asc", ".pts"]


def jobs(folder: Path) -> list[tuple[str, str | None]]:
    """(mesh, cloud or None) for every mesh directly in ``folder``, sorted."""
    found = []
    for path in sorted(folder.iterdir()):
        is_cloud = path.suffixes[-2:-1] == [".cloud"]
        if path.suffix.lower() not in MESH_EXTENSIONS or is_cloud:
            continue
        stem = path.name[: -len(path.suffix)]
        clouds = [folder / f"{stem}.cloud{ext}" for ext in CLOUD_EXTENSIONS]
        cloud = next((str(c) for c in clouds if c.is_file()), None)
        found.append((str(path), cloud))
    return found


def process(job: tuple[str, str | None], out_dir: str) -> dict:
    """Trims or cleans one mesh and writes its output; runs on a worker.
    Returns a row for the summary (an error does not stop the others)."""
    mesh_path, cloud_path = job
    output = Path(out_dir) / Path(mesh_path).name
    row = {"input": mesh_path, "output": str(output), "mode": "trim" if cloud_path else "clean"}
    try:
        vertices, faces = meshtrim.read_mesh(mesh_path)
        if cloud_path:
            points = meshtrim.read_cloud(cloud_path)
            vertices, faces, report = meshtrim.trim(vertices, faces, points)
        else:
            vertices, faces, report = meshtrim.clean(vertices, faces)
        meshtrim.write_mesh(output, vertices, faces)
        row.update(status="ok", faces_in=report["faces_in"], faces_out=report["faces_out"])
    except meshtrim.MeshtrimError as e:
        row.update(status="failed", error=str(e))
    return row


def run(folder: str, out_dir: str, client) -> list[dict]:
    """Every mesh of ``folder`` through meshtrim on the Dask ``client``'s
    workers, one task per file; the rows in file order."""
    work = jobs(Path(folder))
    futures = client.map(process, work, out_dir=out_dir, pure=False)
    return client.gather(futures)


def main(argv: list[str]) -> int:
    from dask.distributed import Client, LocalCluster

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folder")
    parser.add_argument("out_dir")
    parser.add_argument("--scheduler", help="a Dask scheduler's address (default: a LocalCluster)")
    args = parser.parse_args(argv)
    Path(args.out_dir).mkdir(parents=True, exist_ok=True)
    if args.scheduler:
        client = Client(args.scheduler)
    else:
        # One single-threaded worker per core: meshtrim's own threads are
        # many per call, so the tasks share the cores.
        client = Client(LocalCluster(threads_per_worker=1))
    with client:
        rows = run(args.folder, args.out_dir, client)
    for row in rows:
        detail = f"{row['faces_in']} -> {row['faces_out']} faces" if row["status"] == "ok" else row["error"]
        print(f"{row['mode']:5} {row['status']:6} {row['input']}: {detail}")
    return 0 if all(r["status"] == "ok" for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
