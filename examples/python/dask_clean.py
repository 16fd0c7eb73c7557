"""Clean or trim every mesh of a folder with meshtrim, one Dask task per
file: on this machine's cores (a ``LocalCluster``), or on a cluster when
given its scheduler's address. The same code runs in both places.

    python examples/python/dask_clean.py SCANS/ OUT/
    python examples/python/dask_clean.py SCANS/ OUT/ --scheduler tcp://host:8786
    python examples/python/dask_clean.py SCANS/ OUT/ --edges-to dxf

The work is ``meshtrim batch``'s own list (:func:`meshtrim.batch_plan`):
the folder walked recursively, each mesh (.stl, .ply, .obj, .gltf, .glb)
paired with its cloud by name (``S.cloud.EXT`` beside ``S.EXT``, or a
scanner's ``S.e57`` / ``S.laz`` / ``S.xyz`` …) and trimmed with it, any
other mesh cleaned, two clouds for one mesh a failure. Each output is
``OUT/`` plus the mesh's path below the folder, the same bytes ``meshtrim
batch SCANS/ --out-dir OUT/`` writes; with ``--edges-to EXT`` each
output's edges too, as ``S.edges.EXT`` beside it (``batch --edges-to``'s
bytes). The workers need the ``meshtrim``
package (``pip install ./python``) and to see the folders (a shared file
system on a cluster).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import meshtrim


def process(job: meshtrim.BatchJob) -> dict:
    """Trims or cleans one mesh and writes its output; runs on a worker.
    Returns a row for the summary (an error does not stop the others)."""
    mode = "clean" if not job.clouds else "trim"
    row = {"input": str(job.input), "output": str(job.output), "mode": mode}
    try:
        if len(job.clouds) > 1:
            names = ", ".join(str(c) for c in job.clouds)
            raise meshtrim.MeshtrimError(f"several clouds match this mesh ({names}): keep one")
        vertices, faces, attributes = meshtrim.read_mesh(job.input, attributes=True)
        if job.clouds:
            points = meshtrim.read_cloud(job.clouds[0])
            out_v, out_f, report = meshtrim.trim(vertices, faces, points)
        else:
            out_v, out_f, report = meshtrim.clean(vertices, faces)
        # Normals, colours and the file's own values go with it, as batch
        # carries them.
        meshtrim.write_mesh_carrying(job.output, out_v, out_f, vertices, faces, attributes)
        if job.edges and job.clouds:
            # The smoothed edges the mesh was cut along.
            meshtrim.write_edges(job.edges, meshtrim.edges(points), points)
        elif job.edges:
            # The cleaned mesh's border.
            meshtrim.write_edges(job.edges, meshtrim.border_edges(out_v, out_f), out_v)
        row.update(status="ok", faces_in=report["faces_in"], faces_out=report["faces_out"])
    except meshtrim.MeshtrimError as e:
        row.update(status="failed", error=str(e))
    return row


def run(folder: str, out_dir: str, client, edges_to: str | None = None) -> list[dict]:
    """Every mesh of ``folder`` through meshtrim on the Dask ``client``'s
    workers, one task per file; the rows in file order."""
    work = meshtrim.batch_plan(folder, out_dir, edges_to=edges_to)
    futures = client.map(process, work, pure=False)
    return client.gather(futures)


def main(argv: list[str]) -> int:
    from dask.distributed import Client, LocalCluster

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folder")
    parser.add_argument("out_dir")
    parser.add_argument("--scheduler", help="a Dask scheduler's address (default: a LocalCluster)")
    parser.add_argument("--edges-to", help="also write each output's edges as S.edges.EXT (json, obj, svg, dxf, step, igs)")
    args = parser.parse_args(argv)
    Path(args.out_dir).mkdir(parents=True, exist_ok=True)
    if args.scheduler:
        client = Client(args.scheduler)
    else:
        # One single-threaded worker per core: meshtrim's own threads are
        # many per call, so the tasks share the cores.
        client = Client(LocalCluster(threads_per_worker=1))
    with client:
        rows = run(args.folder, args.out_dir, client, args.edges_to)
    for row in rows:
        detail = f"{row['faces_in']} -> {row['faces_out']} faces" if row["status"] == "ok" else row["error"]
        print(f"{row['mode']:5} {row['status']:6} {row['input']}: {detail}")
    return 0 if all(r["status"] == "ok" for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
