"""The C API (crates/capi, libmeshtrim): a C program compiled by the
system's C compiler against include/meshtrim.h and the built library
gives the CLI's arrays, labels and bytes on the fixtures; bad input gives
status 1 and the message, never a crash; the header compiles as C++.
scripts/test.sh builds the library (``cargo build --release -p
meshtrim-capi``); MESHTRIM_CAPI names another build."""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
import trimesh

import meshtrim
from meshtrim_cli import ROOT, results, run_meshtrim

CAPI = ROOT / "crates" / "capi"
LIBRARY = Path(os.environ.get("MESHTRIM_CAPI", ROOT / "target" / "release" / "libmeshtrim.so"))
FIXTURES = ROOT / "fixtures" / "meshes"
CLOUD = FIXTURES / "blade_small.ply"
POISSON = FIXTURES / "blade_small_poisson.ply"
HOLES = FIXTURES / "blade_holes.ply"
JAGGED = FIXTURES / "blade_jagged.stl"
STRICT = ["-Wall", "-Wextra", "-pedantic", "-Werror"]


def compiler(name: str) -> str:
    found = shutil.which(name)
    if found is None:
        pytest.fail(f"no {name} on PATH: the C API is tested with the system's compiler")
    return found


def link_flags() -> list[str]:
    if not LIBRARY.exists():
        pytest.fail(f"{LIBRARY} missing: build with cargo build --release -p meshtrim-capi")
    return [f"-L{LIBRARY.parent}", "-lmeshtrim", f"-Wl,-rpath,{LIBRARY.parent}"]


@pytest.fixture(scope="module")
def arrays_program(tmp_path_factory) -> Path:
    """crates/capi/examples/arrays.c, built as C99 with every warning an
    error."""
    out = tmp_path_factory.mktemp("capi") / "arrays"
    source = CAPI / "examples" / "arrays.c"
    cmd = [compiler("cc"), "-std=c99", *STRICT, f"-I{CAPI / 'include'}", str(source), *link_flags(), "-o", str(out)]
    subprocess.run(cmd, check=True, capture_output=True, text=True)
    return out


def run_c(program: Path, *args, status: int = 0) -> subprocess.CompletedProcess:
    r = subprocess.run([str(program), *map(str, args)], capture_output=True, text=True, timeout=300)
    assert r.returncode == status, (r.returncode, r.stdout, r.stderr)
    return r


def tofile(path: Path, array: np.ndarray, dtype) -> Path:
    np.ascontiguousarray(array, dtype=dtype).tofile(path)
    return path


def mesh_from_c(prefix: Path) -> tuple[np.ndarray, np.ndarray, dict]:
    vertices = np.fromfile(f"{prefix}.vertices", dtype="<f8").reshape(-1, 3)
    faces = np.fromfile(f"{prefix}.faces", dtype="<u4").reshape(-1, 3)
    return vertices, faces, json.loads(Path(f"{prefix}.json").read_text())


def read_ply(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """A float64 PLY as trimesh reads it, vertices in file order."""
    mesh = trimesh.load(path, process=False)
    return np.asarray(mesh.vertices), np.asarray(mesh.faces)


def test_clean_gives_the_cli_mesh(arrays_program, tmp_path):
    vertices, faces = meshtrim.read_mesh(JAGGED)
    v_file, f_file = tofile(tmp_path / "v", vertices, "<f8"), tofile(tmp_path / "f", faces, "<u4")
    for bound in [None, 0.5]:
        extra = [] if bound is None else ["--max-deviation", bound]
        cli_out, report_file = tmp_path / "cli.ply", tmp_path / "r.json"
        run_meshtrim("clean", JAGGED, cli_out, "--report", report_file, *extra)
        run_c(arrays_program, "clean", v_file, f_file, tmp_path / "c", *([] if bound is None else [bound]))
        out_v, out_f, report = mesh_from_c(tmp_path / "c")
        cli_v, cli_f = read_ply(cli_out)
        assert np.array_equal(out_v, cli_v) and np.array_equal(out_f, cli_f)
        cli_report = json.loads(report_file.read_text())
        assert results(report) == results(cli_report)
        assert report["loops_smoothed"] > 0 and report.get("max_deviation") == bound
        if bound is not None:
            assert report["vertices_held"] > 0 and report["input_to_output"]["max"] <= bound * (1 + 1e-9)


@pytest.mark.parametrize("name, units", [("border.step", "in"), ("border.dxf", None), ("border.json", None)])
def test_border_edges_are_clean_edges_bytes(arrays_program, tmp_path, name, units):
    """The C-cleaned mesh's border, written by meshtrim_border_edges: the
    bytes ``meshtrim clean IN OUT --edges FILE`` writes."""
    vertices, faces = meshtrim.read_mesh(JAGGED)
    v_file, f_file = tofile(tmp_path / "v", vertices, "<f8"), tofile(tmp_path / "f", faces, "<u4")
    run_c(arrays_program, "clean", v_file, f_file, tmp_path / "c")
    units_args = [units] if units else []
    run_c(arrays_program, "border", f"{tmp_path / 'c'}.vertices", f"{tmp_path / 'c'}.faces", tmp_path / name, *units_args)
    cli_file = tmp_path / f"cli_{name}"
    run_meshtrim("clean", JAGGED, tmp_path / "cli.ply", "--edges", cli_file, *(["--units", units] if units else []))
    assert (tmp_path / name).read_bytes() == cli_file.read_bytes()


def test_results_do_not_depend_on_threads(arrays_program, tmp_path):
    """One worker thread or all of them, and four callers at once on
    their own threads (ctypes releases the GIL): the same arrays."""
    vertices, faces = meshtrim.read_mesh(JAGGED)
    v_file, f_file = tofile(tmp_path / "v", vertices, "<f8"), tofile(tmp_path / "f", faces, "<u4")
    run_c(arrays_program, "clean", v_file, f_file, tmp_path / "all")
    env = {**os.environ, "RAYON_NUM_THREADS": "1"}
    subprocess.run([str(arrays_program), "clean", v_file, f_file, tmp_path / "one"], env=env, check=True, capture_output=True)
    for suffix in [".vertices", ".faces"]:
        assert Path(f"{tmp_path / 'all'}{suffix}").read_bytes() == Path(f"{tmp_path / 'one'}{suffix}").read_bytes()
    script = tmp_path / "callers.py"
    script.write_text(CALLERS)
    r = subprocess.run([sys.executable, str(script), str(LIBRARY), str(v_file), str(f_file)], capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, (r.stdout, r.stderr[-4000:])
    expected = hashlib.sha256(Path(f"{tmp_path / 'all'}.vertices").read_bytes()).hexdigest()
    assert r.stdout.split() == [expected] * 4, r.stdout


CALLERS = """
import ctypes, hashlib, sys, threading
import numpy as np

lib = ctypes.CDLL(sys.argv[1])
P, S = ctypes.c_void_p, ctypes.c_size_t
class Mesh(ctypes.Structure):
    _fields_ = [("vertices", P), ("vertex_count", S), ("faces", P), ("face_count", S), ("report_json", P)]
lib.meshtrim_clean.argtypes = [P, S, P, S, P, P, P]
lib.meshtrim_mesh_free.argtypes = [P]
v = np.fromfile(sys.argv[2], dtype="<f8")
f = np.fromfile(sys.argv[3], dtype="<u4")
digests = [None] * 4

def clean(i):
    out = Mesh()
    assert lib.meshtrim_clean(v.ctypes.data, len(v) // 3, f.ctypes.data, len(f) // 3, None, ctypes.byref(out), None) == 0
    digests[i] = hashlib.sha256(ctypes.string_at(out.vertices, out.vertex_count * 24)).hexdigest()
    lib.meshtrim_mesh_free(ctypes.byref(out))

threads = [threading.Thread(target=clean, args=(i,)) for i in range(4)]
for t in threads:
    t.start()
for t in threads:
    t.join()
print(*digests)
"""


def test_trim_and_mesh_give_the_cli_meshes(arrays_program, tmp_path):
    vertices, faces = meshtrim.read_mesh(POISSON)
    v_file, f_file = tofile(tmp_path / "v", vertices, "<f8"), tofile(tmp_path / "f", faces, "<u4")
    p_file = tofile(tmp_path / "p", meshtrim.read_cloud(CLOUD), "<f8")
    cli_out, report_file = tmp_path / "cli.ply", tmp_path / "r.json"
    run_meshtrim(POISSON, CLOUD, cli_out, "--report", report_file)
    printed = run_c(arrays_program, "trim", v_file, f_file, p_file, tmp_path / "c").stdout
    out_v, out_f, report = mesh_from_c(tmp_path / "c")
    cli_v, cli_f = read_ply(cli_out)
    assert np.array_equal(out_v, cli_v) and np.array_equal(out_f, cli_f)
    assert results(report) == results(json.loads(report_file.read_text()))
    assert printed == f"{len(out_v)} vertices, {len(out_f)} faces\n"

    h_file = tofile(tmp_path / "h", meshtrim.read_cloud(HOLES), "<f8")
    run_meshtrim("mesh", HOLES, cli_out, "--report", report_file)
    run_c(arrays_program, "mesh", h_file, tmp_path / "m")
    out_v, out_f, report = mesh_from_c(tmp_path / "m")
    cli_v, cli_f = read_ply(cli_out)
    assert np.array_equal(out_v, cli_v) and np.array_equal(out_f, cli_f)
    assert results(report) == results(json.loads(report_file.read_text()))


def test_detect_gives_the_cli_labels(arrays_program, tmp_path):
    points = meshtrim.read_cloud(HOLES)
    run_c(arrays_program, "detect", tofile(tmp_path / "p", points, "<f8"), tmp_path / "d")
    boundary = np.fromfile(tmp_path / "d.boundary", dtype=np.uint8)
    beta = np.fromfile(tmp_path / "d.beta", dtype="<f8")
    cli_csv = tmp_path / "labels.csv"
    run_meshtrim("detect", HOLES, "-o", cli_csv)
    rows = np.genfromtxt(cli_csv, delimiter=",", names=True)
    assert np.array_equal(boundary, rows["boundary"].astype(np.uint8))
    assert np.array_equal(beta, rows["beta"])
    report = json.loads((tmp_path / "d.json").read_text())
    assert report["boundary_points"] == int(boundary.sum()) > 0


@pytest.mark.parametrize("name, units", [("edges.step", "in"), ("edges.dxf", None), ("edges.json", None)])
def test_edges_files_are_the_clis_bytes(arrays_program, tmp_path, name, units):
    p_file = tofile(tmp_path / "p", meshtrim.read_cloud(HOLES), "<f8")
    run_c(arrays_program, "edges", p_file, tmp_path / name, *([units] if units else []))
    cli_file = tmp_path / f"cli_{name}"
    run_meshtrim("edges", HOLES, "-o", cli_file, *(["--units", units] if units else []))
    assert (tmp_path / name).read_bytes() == cli_file.read_bytes()


def test_bad_input_is_status_1_with_the_message(arrays_program, tmp_path):
    vertices, faces = meshtrim.read_mesh(JAGGED)
    v_file = tofile(tmp_path / "v", vertices, "<f8")
    bad = faces.copy()
    bad[7, 2] = len(vertices) + 3
    r = run_c(arrays_program, "clean", v_file, tofile(tmp_path / "f", bad, "<u4"), tmp_path / "c", status=1)
    assert r.stderr == f"error: faces: face 7 refers to vertex {len(vertices) + 3}, but there are {len(vertices)} vertices\n"
    r = run_c(arrays_program, "clean", v_file, tofile(tmp_path / "f", faces, "<u4"), tmp_path / "c", "-2", status=1)
    assert r.stderr.startswith("error: max_deviation: -2 is not a distance"), r.stderr
    line = np.array([[i, 2.0 * i, 0.0] for i in range(50)])
    r = run_c(arrays_program, "detect", tofile(tmp_path / "line", line, "<f8"), tmp_path / "d", status=1)
    assert r.stderr.startswith("error: points: the cloud is degenerate: all 50 distinct points lie on one line"), r.stderr
    r = run_c(arrays_program, "edges", tofile(tmp_path / "p", meshtrim.read_cloud(HOLES), "<f8"), tmp_path / "e.txt", status=1)
    assert "e.txt" in r.stderr, r.stderr
    assert not (tmp_path / "c.vertices").exists() and not (tmp_path / "e.txt").exists()


def test_the_header_compiles_as_cpp(tmp_path):
    source = tmp_path / "use.cpp"
    source.write_text(textwrap.dedent("""\
        #include "meshtrim.h"
        #include <cstddef>
        #include <cstdio>
        // The layouts crates/capi/src/tests.rs::layouts_are_the_headers asserts.
        static_assert(offsetof(MeshtrimOptions, k) == 0 && offsetof(MeshtrimOptions, anisotropy) == 4, "");
        static_assert(offsetof(MeshtrimOptions, offset) == 8 && offsetof(MeshtrimOptions, view_kind) == 12, "");
        static_assert(offsetof(MeshtrimOptions, view) == 16 && offsetof(MeshtrimOptions, repair) == 40, "");
        static_assert(offsetof(MeshtrimOptions, max_deviation) == 48 && offsetof(MeshtrimOptions, fill_holes) == 56, "");
        static_assert(sizeof(MeshtrimOptions) == 64, "");
        static_assert(offsetof(MeshtrimMesh, vertices) == 0 && offsetof(MeshtrimMesh, vertex_count) == 8, "");
        static_assert(offsetof(MeshtrimMesh, faces) == 16 && offsetof(MeshtrimMesh, face_count) == 24, "");
        static_assert(offsetof(MeshtrimMesh, report_json) == 32 && sizeof(MeshtrimMesh) == 40, "");
        int main() {
            MeshtrimOptions options = meshtrim_default_options();
            MeshtrimMesh mesh;
            char *error = nullptr;
            const double points[3] = {0.0, 0.0, 0.0};
            int status = meshtrim_mesh(points, 1, &options, &mesh, &error);
            std::printf("%s %d %s\\n", meshtrim_version(), status, error);
            meshtrim_string_free(error);
            meshtrim_mesh_free(&mesh);
            return status == MESHTRIM_ERROR ? 0 : 1;
        }
        """))
    out = tmp_path / "use"
    cmd = [compiler("c++"), "-std=c++11", *STRICT, f"-I{CAPI / 'include'}", str(source), *link_flags(), "-o", str(out)]
    subprocess.run(cmd, check=True, capture_output=True, text=True)
    printed = run_c(out).stdout
    assert printed.startswith("0.1.0 1 "), printed


def test_installed_library_builds_through_pkg_config(tmp_path):
    """scripts/install_capi.sh under a prefix: the header, the library
    without its debug information, and a pkg-config file whose flags
    build a program that runs against the installed copy."""
    prefix = tmp_path / "prefix"
    subprocess.run(["bash", str(ROOT / "scripts" / "install_capi.sh"), str(prefix)], check=True, capture_output=True, text=True)
    installed = prefix / "lib" / "libmeshtrim.so"
    assert (prefix / "include" / "meshtrim.h").read_bytes() == (CAPI / "include" / "meshtrim.h").read_bytes()
    assert installed.stat().st_size < LIBRARY.stat().st_size
    env = {**os.environ, "PKG_CONFIG_PATH": str(prefix / "lib" / "pkgconfig")}

    def pkg_config(*args):
        return subprocess.run(["pkg-config", *args, "meshtrim"], env=env, check=True, capture_output=True, text=True).stdout.split()

    source = tmp_path / "version.c"
    source.write_text('#include <stdio.h>\n#include "meshtrim.h"\nint main(void) { puts(meshtrim_version()); return 0; }\n')
    libdir = pkg_config("--variable=libdir")[0]
    program = tmp_path / "version"
    cmd = [compiler("cc"), "-std=c99", *STRICT, str(source), *pkg_config("--cflags", "--libs"), f"-Wl,-rpath,{libdir}", "-o", str(program)]
    subprocess.run(cmd, check=True, capture_output=True, text=True)
    version = run_c(program).stdout.strip()
    assert [version] == pkg_config("--modversion") and version == "0.1.0"
    linked = subprocess.run(["ldd", str(program)], check=True, capture_output=True, text=True).stdout
    assert str(installed) in linked, linked


FUZZ = """
import ctypes, sys
import numpy as np

lib = ctypes.CDLL(sys.argv[1])
P, S, I = ctypes.c_void_p, ctypes.c_size_t, ctypes.c_int
class Mesh(ctypes.Structure):
    _fields_ = [("vertices", P), ("vertex_count", S), ("faces", P), ("face_count", S), ("report_json", ctypes.c_char_p)]
class Options(ctypes.Structure):
    _fields_ = [("k", ctypes.c_uint32), ("anisotropy", I), ("offset", I), ("view_kind", I),
                ("view", ctypes.c_double * 3), ("repair", I), ("max_deviation", ctypes.c_double),
                ("fill_holes", ctypes.c_double)]
lib.meshtrim_default_options.restype = Options
lib.meshtrim_clean.argtypes = [P, S, P, S, P, P, P]
lib.meshtrim_detect.argtypes = [P, S, P, P, P, P, P]
lib.meshtrim_border_edges.argtypes = [P, S, P, S, P, ctypes.c_char_p, ctypes.c_char_p, I, P]
lib.meshtrim_string_free.argtypes = [P]
lib.meshtrim_mesh_free.argtypes = [P]
rng = np.random.default_rng(int(sys.argv[2]))
statuses = {(call, s): 0 for call in ["clean", "detect", "border"] for s in (0, 1)}
border_file = (sys.argv[4] + "/border.json").encode()
for case in range(int(sys.argv[3])):
    if rng.random() < 0.5:  # a random blob and random faces
        n = int(rng.integers(0, 60))
        v = rng.normal(size=(n, 3)) * 10.0 ** rng.integers(-3, 4)
        f = rng.integers(0, max(n, 1), size=(int(rng.integers(0, 90)), 3))
    else:  # a jittered grid with faces missing along and inside its border
        g = int(rng.integers(2, 14))
        x, y = np.meshgrid(np.arange(g), np.arange(g))
        v = np.column_stack([x.ravel(), y.ravel(), np.zeros(g * g)]) + rng.normal(size=(g * g, 3)) * 0.1
        c = (x[:-1, :-1] + g * y[:-1, :-1]).ravel()
        f = np.concatenate([np.column_stack([c, c + 1, c + g + 1]), np.column_stack([c, c + g + 1, c + g])])
        f = f[rng.random(len(f)) > rng.random() * 0.3]
        n = len(v)
    if n and rng.random() < 0.3:
        v.flat[rng.integers(0, v.size)] = rng.choice([np.nan, np.inf, 1e300, -0.0])
    if len(f) and rng.random() < 0.2:
        f[rng.integers(0, len(f)), rng.integers(0, 3)] = n + int(rng.integers(0, 3))
    if len(f) and rng.random() < 0.2:
        f = np.concatenate([f, f[:1, ::-1]])
    f = np.ascontiguousarray(f, dtype=np.uint32)
    m = len(f)
    o = lib.meshtrim_default_options()
    o.k = int(rng.choice([30, 30, 4, 3, 0, 5000]))
    o.view_kind = int(rng.choice([0, 0, 1, 2, 9]))
    o.view[:] = rng.normal(size=3) * rng.integers(0, 2)
    o.repair = int(rng.integers(0, 2))
    o.max_deviation = float(rng.choice([0.0, 0.5, -1.0, np.nan]))
    o.fill_holes = float(rng.choice([0.0, 0.0, 3.0, 1e9, -2.0]))
    v = np.ascontiguousarray(v, dtype=np.float64)
    out, err = Mesh(), ctypes.c_void_p()
    s = lib.meshtrim_clean(v.ctypes.data, n, f.ctypes.data, m, ctypes.byref(o), ctypes.byref(out), ctypes.byref(err))
    assert s in (0, 1), (case, s, ctypes.string_at(err.value))
    assert (s == 1) == bool(err.value), case
    if s == 1:
        assert ctypes.string_at(err.value), case
    lib.meshtrim_string_free(err)
    lib.meshtrim_mesh_free(ctypes.byref(out))
    boundary = np.zeros(max(n, 1), dtype=np.uint8)
    err = ctypes.c_void_p()
    s2 = lib.meshtrim_detect(v.ctypes.data, n, ctypes.byref(o), boundary.ctypes.data, None, None, ctypes.byref(err))
    assert s2 in (0, 1), (case, s2, ctypes.string_at(err.value))
    lib.meshtrim_string_free(err)
    err = ctypes.c_void_p()
    s3 = lib.meshtrim_border_edges(v.ctypes.data, n, f.ctypes.data, m, ctypes.byref(o), border_file, None, 0, ctypes.byref(err))
    assert s3 in (0, 1), (case, s3, ctypes.string_at(err.value))
    lib.meshtrim_string_free(err)
    statuses["clean", s] += 1
    statuses["detect", s2] += 1
    statuses["border", s3] += 1
print(*statuses.values())
"""


def test_random_input_never_crashes_the_caller(tmp_path):
    """Random clouds and meshes (NaN, infinities, huge values, indices out
    of range, bad options) through ctypes in a child process: every call
    returns 0 or 1, a 1 with its message; the process ends normally."""
    link_flags()
    script = tmp_path / "fuzz.py"
    script.write_text(FUZZ)
    r = subprocess.run([sys.executable, str(script), str(LIBRARY), "7", "300", str(tmp_path)], capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, (r.returncode, r.stdout[-2000:], r.stderr[-4000:])
    # Cleaned, refused; detected, refused; border written, refused: each
    # way taken.
    assert all(int(count) > 0 for count in r.stdout.split()), r.stdout
