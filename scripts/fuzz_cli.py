"""Mutation fuzzing of the meshtrim CLI: no input may make it panic.

    python3 scripts/fuzz_cli.py [--seed N] [--cases N] [--kind bytes|mesh|cloud|all]

Builds nothing: it runs `target/release/meshtrim` (build it first) on
mutated copies of the fixtures and of files it derives from them (every
cloud and mesh format meshtrim reads, and textured OBJ and GLB meshes),
in a temporary directory.

- `bytes`: random byte changes, truncations, insertions (`nan`, `1e400`,
  NUL, blanks) and repeated stretches of the files themselves; read by
  `detect`, `edges`, `clean` and the main job.
- `mesh`: the jagged fixture's geometry changed: spikes (up to 10³ × its
  size), jitter, collapsed and repeated vertices, dropped and reversed
  faces, flattened heights; run through `clean`, the main job, `detect`
  and `mesh`.
- `cloud`: the fixture cloud changed: spikes, thousands of copies,
  quantised coordinates, tiny subsets, straight lines, huge offsets, a flat
  plane, a cluster of near-coincident points; run through `detect`,
  `edges`, `mesh` and the main job.

A run that exits with Rust's panic code (101) or prints "panicked", dies
by a signal (a stack overflow, an abort, the out-of-memory killer) or
outlives --timeout is reported and its input kept (in `fuzz-failures/`);
errors with a message are what bad input should get. Exits 1 if any run
failed so. CI runs a short seeded pass (scripts/test.sh).
"""

import argparse
import os
import random
import shutil
import struct
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EXE = os.path.join(ROOT, "target", "release", "meshtrim")
FIXTURES = os.path.join(ROOT, "fixtures", "meshes")
CLOUD = os.path.join(FIXTURES, "blade_small.ply")
POISSON = os.path.join(FIXTURES, "blade_small_poisson.ply")
JAGGED = os.path.join(FIXTURES, "blade_jagged.stl")


# Seconds a run may take before it counts as a hang.
TIMEOUT = 120


def run(cmd):
    try:
        return subprocess.run([EXE] + cmd, capture_output=True, timeout=TIMEOUT)
    except subprocess.TimeoutExpired:
        return None


def failure(result):
    """What went wrong with a run, or None when it exited on its own with
    a message or success: a hang, a death by signal (stack overflow,
    abort, out of memory), or a panic."""
    if result is None:
        return f"HANG (over {TIMEOUT} s)"
    if result.returncode < 0:
        return f"SIGNAL {-result.returncode}"
    if result.returncode == 101 or b"panicked" in result.stderr:
        return "PANIC"
    return None


def derive_sources(work):
    """The fixtures in every format meshtrim reads."""
    csv = os.path.join(work, "cloud.csv")
    run(["detect", CLOUD, "-o", csv])
    rows = [line.split(",")[:3] for line in open(csv).read().splitlines()[1:]][:4000]
    with open(os.path.join(work, "cloud.xyz"), "w") as f:
        f.write("".join(" ".join(r) + "\n" for r in rows))
    # Leica PTS: each scan after its point count, here two.
    half = len(rows) // 2
    with open(os.path.join(work, "cloud.pts"), "w") as f:
        for block in (rows[:half], rows[half:]):
            f.write(f"{len(block)}\n" + "".join(" ".join(r) + " 0 0 0 0\n" for r in block))
    with open(os.path.join(work, "cloud.obj"), "w") as f:
        f.write("".join("v " + " ".join(r) + "\n" for r in rows))
    header = (
        "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
        f"WIDTH {len(rows)}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {len(rows)}\nDATA "
    )
    with open(os.path.join(work, "cloud_ascii.pcd"), "w") as f:
        f.write(header + "ascii\n" + "".join(" ".join(r) + "\n" for r in rows))
    with open(os.path.join(work, "cloud_binary.pcd"), "wb") as f:
        f.write((header + "binary\n").encode())
        for r in rows:
            f.write(struct.pack("<3f", *map(float, r)))
    write_las_clouds(work, rows)
    for ext in ("stl", "obj", "gltf", "glb", "ply"):
        run(["clean", JAGGED, os.path.join(work, f"mesh.{ext}")])
    write_ascii_meshes(work)
    write_textured_meshes(work)
    clouds = [CLOUD] + [os.path.join(work, n) for n in
                        ("cloud.csv", "cloud.xyz", "cloud.pts", "cloud.obj", "cloud_ascii.pcd",
                         "cloud_binary.pcd", "cloud.las", "cloud.laz", "cloud.e57")]
    meshes = [JAGGED, POISSON] + [os.path.join(work, f"mesh.{e}") for e in ("stl", "obj", "gltf", "glb", "ply")]
    meshes += [os.path.join(work, n) for n in
               ("mesh_ascii.stl", "mesh_ascii.ply", "mesh_textured.obj", "mesh_textured.glb")]
    return clouds, meshes


def write_las_clouds(work, rows):
    """The cloud as LAS 1.2 (point format 1) and LAZ 1.4 (point format 6),
    written by laspy, the format's reference library."""
    import laspy
    import numpy as np

    xyz = np.array(rows, dtype=float)
    for name, point_format, version in (("cloud.las", 1, "1.2"), ("cloud.laz", 6, "1.4")):
        header = laspy.LasHeader(point_format=point_format, version=version)
        header.offsets = xyz.min(axis=0)
        header.scales = [1e-5, 1e-5, 1e-5]
        las = laspy.LasData(header)
        las.x, las.y, las.z = xyz[:, 0], xyz[:, 1], xyz[:, 2]
        las.write(os.path.join(work, name))
    write_e57_cloud(work, xyz)


def write_e57_cloud(work, xyz):
    """The cloud as an E57 file of two posed scans, written by pye57
    (libE57Format)."""
    import numpy as np
    import pye57

    e57 = pye57.E57(os.path.join(work, "cloud.e57"), mode="w")
    half = len(xyz) // 2
    for block, translation in ((xyz[:half], [0.0, 0.0, 0.0]), (xyz[half:] - 10.0, [10.0, 10.0, 10.0])):
        data = {"cartesianX": block[:, 0], "cartesianY": block[:, 1], "cartesianZ": block[:, 2]}
        e57.write_scan_raw(data, rotation=np.array([1.0, 0, 0, 0]), translation=np.array(translation))
    e57.close()


def write_textured_meshes(work):
    """The OBJ written by `clean` with texture coordinates and normals per
    corner (a chart border down the middle, where corners read two), two
    materials and their library and image; and as a GLB with two
    materials and an embedded image, written by trimesh."""
    import trimesh
    from PIL import Image

    vertices, faces = read_obj(os.path.join(work, "mesh.obj"))
    middle = sorted(v[0] for v in vertices)[len(vertices) // 2]
    Image.new("RGB", (8, 8), (200, 30, 30)).save(os.path.join(work, "texture.png"))
    with open(os.path.join(work, "mesh_textured.mtl"), "w") as f:
        f.write("newmtl left\nmap_Kd texture.png\nnewmtl right\nKd 0 0 1\n")
    lines = ["mtllib mesh_textured.mtl"]
    lines += ["v %r %r %r" % tuple(v) for v in vertices]
    lines += ["vt %r %r" % (v[0] / 100, v[1] / 100) for v in vertices]
    lines += ["vt %r %r" % (v[0] / 100 + 0.5, v[1] / 100) for v in vertices]
    lines += ["vn 0 0 1", "vn 0 0.6 0.8"]
    n = len(vertices)
    for face in faces:
        corners = [int(c.split("/")[0]) for c in face]
        right = sum(vertices[c - 1][0] for c in corners) > 3 * middle
        lines.append("usemtl " + ("right" if right else "left"))
        shift, normal = (n, 2) if right else (0, 1)
        lines.append("f " + " ".join(f"{c}/{c + shift}/{normal}" for c in corners))
    with open(os.path.join(work, "mesh_textured.obj"), "w") as f:
        f.write("\n".join(lines) + "\n")
    scene = trimesh.load(os.path.join(work, "mesh_textured.obj"), process=False, group_material=True)
    scene.export(os.path.join(work, "mesh_textured.glb"))


def write_ascii_meshes(work):
    """The binary STL written by `clean` as ASCII STL and ASCII PLY."""
    data = open(os.path.join(work, "mesh.stl"), "rb").read()
    (n,) = struct.unpack_from("<I", data, 80)
    triangles = [struct.unpack_from("<12f", data, 84 + 50 * t)[3:] for t in range(n)]
    with open(os.path.join(work, "mesh_ascii.stl"), "w") as f:
        f.write("solid fuzz\n")
        for t in triangles:
            f.write("facet normal 0 0 0\n outer loop\n")
            for k in range(3):
                f.write("  vertex %r %r %r\n" % t[3 * k:3 * k + 3])
            f.write(" endloop\nendfacet\n")
        f.write("endsolid fuzz\n")
    corners = [t[3 * k:3 * k + 3] for t in triangles for k in range(3)]
    with open(os.path.join(work, "mesh_ascii.ply"), "w") as f:
        f.write(f"ply\nformat ascii 1.0\nelement vertex {len(corners)}\nproperty float x\n"
                f"property float y\nproperty float z\nelement face {n}\n"
                "property list uchar int vertex_indices\nend_header\n")
        f.write("".join("%r %r %r\n" % c for c in corners))
        f.write("".join(f"3 {3 * t} {3 * t + 1} {3 * t + 2}\n" for t in range(n)))


def commands(path, is_mesh, work):
    out = lambda name: os.path.join(work, name)
    if is_mesh:
        return [["clean", path, out("clean.ply"), "--edges", out("border.step")],
                ["clean", path, out("repaired.glb"), "--repair", "--max-deviation", "0.5", "--fill-holes", "60"],
                [path, CLOUD, out("trim.ply")],
                ["detect", path, "-o", out("d.csv")], ["mesh", path, out("m.ply")]]
    # A LAS or LAZ input's labels go to LAS, which reads its records again.
    labels = "d.laz" if path.endswith((".las", ".laz")) else "d.csv"
    return [["detect", path, "-o", out(labels)], ["edges", path, "-o", out("e.json")],
            ["mesh", path, out("m.ply")], [POISSON, path, out("trim.ply")]]


def mutate_bytes(rng, data):
    op = rng.choice(["flip", "truncate", "insert", "repeat"])
    if op == "flip":
        for _ in range(rng.randint(1, 20)):
            data[rng.randrange(len(data))] = rng.randrange(256)
    elif op == "truncate":
        del data[rng.randrange(len(data)):]
    elif op == "insert":
        i = rng.randrange(len(data))
        data[i:i] = rng.choice([b" ", b"\n", b"-", b"nan", b"1e400", b"\x00", b"0"]) * rng.randint(1, 3)
    else:
        i = rng.randrange(len(data))
        j = min(len(data), i + rng.randint(1, 200))
        data[j:j] = data[i:j]
    return op


def read_obj(path):
    lines = open(path).read().splitlines()
    vertices = [list(map(float, l.split()[1:4])) for l in lines if l.startswith("v ")]
    faces = [l.split()[1:] for l in lines if l.startswith("f ")]
    return vertices, faces


def mutate_mesh(rng, vertices, faces, size):
    op = rng.choice(["spike", "jitter", "collapse", "drop faces", "reverse faces", "repeat vertices", "flatten"])
    k = rng.randint(1, 30)
    if op == "spike":
        for _ in range(k):
            rng.choice(vertices)[rng.randrange(3)] += rng.choice([-1, 1]) * size * rng.choice([0.01, 0.1, 1, 10, 1e3])
    elif op == "jitter":
        s = size * rng.choice([1e-4, 1e-3, 1e-2, 0.05])
        for v in vertices:
            for i in range(3):
                v[i] += rng.uniform(-s, s)
    elif op == "collapse":
        for _ in range(k):
            vertices[rng.randrange(len(vertices))] = list(rng.choice(vertices))
    elif op == "drop faces":
        for _ in range(5 * k):
            if faces:
                faces.pop(rng.randrange(len(faces)))
    elif op == "reverse faces":
        for _ in range(k):
            rng.choice(faces).reverse()
    elif op == "repeat vertices":
        for _ in range(k):
            f = rng.choice(faces)
            j = rng.randrange(3)
            vertices.append(list(vertices[int(f[j].split("/")[0]) - 1]))
            f[j] = str(len(vertices))
    else:
        for v in vertices:
            v[2] = round(v[2])
    return op


def mutate_cloud(rng, points):
    op = rng.choice(["spike", "copies", "quantise", "subset", "line", "far", "flat", "cluster"])
    if op == "spike":
        for _ in range(rng.randint(1, 50)):
            rng.choice(points)[rng.randrange(3)] += rng.choice([-1, 1]) * rng.choice([10, 100, 1e4, 1e8])
    elif op == "copies":
        points += [list(rng.choice(points)) for _ in range(rng.randint(1, 2000))]
    elif op == "quantise":
        step = rng.choice([0.01, 0.5, 2, 5, 20])
        points[:] = [[round(c / step) * step for c in q] for q in points]
    elif op == "subset":
        points[:] = rng.sample(points, rng.randint(1, 200))
    elif op == "line":
        a = rng.choice(points)
        points += [[a[0] + 0.3 * t, a[1], a[2]] for t in range(rng.randint(1, 500))]
    elif op == "far":
        offset = rng.choice([1e5, 1e8, 1e12, -1e15])
        points[:] = [[c + offset for c in q] for q in points]
    elif op == "flat":
        points[:] = [[q[0], q[1], 0.0] for q in points]
    else:
        a = rng.choice(points)
        points += [[a[0] + rng.gauss(0, 1e-6), a[1] + rng.gauss(0, 1e-6), a[2]]
                   for _ in range(rng.randint(30, 3000))]
    rng.shuffle(points)
    return op


def main():
    global TIMEOUT
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--cases", type=int, default=100, help="mutated inputs per kind")
    parser.add_argument("--kind", choices=["bytes", "mesh", "cloud", "all"], default="all")
    parser.add_argument("--timeout", type=float, default=TIMEOUT, help="seconds before a run counts as a hang")
    args = parser.parse_args()
    TIMEOUT = args.timeout
    if not os.access(EXE, os.X_OK):
        sys.exit(f"{EXE} not found: run `cargo build --release` first")
    rng = random.Random(args.seed)
    failures = os.path.join(ROOT, "fuzz-failures")
    runs = panics = 0
    with tempfile.TemporaryDirectory() as work:
        clouds, meshes = derive_sources(work)

        def check(path, is_mesh, what):
            nonlocal runs, panics
            for cmd in commands(path, is_mesh, work):
                runs += 1
                result = run(cmd)
                wrong = failure(result)
                if wrong:
                    panics += 1
                    os.makedirs(failures, exist_ok=True)
                    kept = os.path.join(failures, f"seed{args.seed}-{panics}{os.path.splitext(path)[1]}")
                    shutil.copy(path, kept)
                    print(f"{wrong}: {what}: meshtrim {' '.join(cmd)} (input kept in {kept})")
                    if result is not None:
                        print(result.stderr.decode(errors="replace")[:400])
                    return

        kinds = ["bytes", "mesh", "cloud"] if args.kind == "all" else [args.kind]
        if "bytes" in kinds:
            for _ in range(args.cases):
                source = rng.choice(clouds + meshes)
                data = bytearray(open(source, "rb").read())
                op = mutate_bytes(rng, data)
                path = os.path.join(work, "case" + os.path.splitext(source)[1])
                open(path, "wb").write(data)
                check(path, source in meshes, f"{os.path.basename(source)}, bytes {op}")
        if "mesh" in kinds:
            vertices, faces = read_obj(os.path.join(work, "mesh.obj"))
            size = max(max(v[i] for v in vertices) - min(v[i] for v in vertices) for i in range(3))
            for _ in range(args.cases):
                vs, fs = [list(v) for v in vertices], [list(f) for f in faces]
                op = mutate_mesh(rng, vs, fs, size)
                path = os.path.join(work, "case.obj")
                with open(path, "w") as f:
                    f.write("".join("v %r %r %r\n" % tuple(v) for v in vs))
                    f.write("".join("f " + " ".join(face) + "\n" for face in fs))
                check(path, True, f"mesh {op}")
        if "cloud" in kinds:
            points = [list(map(float, l.split())) for l in open(os.path.join(work, "cloud.xyz"))]
            for _ in range(args.cases):
                ps = [list(p) for p in points]
                op = mutate_cloud(rng, ps)
                path = os.path.join(work, "case.xyz")
                open(path, "w").write("".join("%r %r %r\n" % tuple(p) for p in ps))
                check(path, False, f"cloud {op}")
    print(f"{runs} runs, {panics} failed (panic, signal or hang)")
    sys.exit(1 if panics else 0)


if __name__ == "__main__":
    main()
