"""Running the meshtrim binary and finding the real test data (shared by
the validation suites)."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
MESHTRIM = Path(os.environ.get("MESHTRIM", ROOT / "target" / "release" / "meshtrim"))

# The real scans that are meshes (range maps, range grids, a decimated
# bust), by name: their paths under the shared data.
REAL_MESHES = {
    "face000": "meshlab_scans/face000.ply",
    "lato000": "meshlab_scans/lato000.ply",
    "Laurana50k": "meshlab_scans/Laurana50k.ply",
    "bun000": "stanford_bunny/bun000.ply",
    "bun045": "stanford_bunny/bun045.ply",
    "bun090": "stanford_bunny/bun090.ply",
    "chin": "stanford_bunny/chin.ply",
}

# What differs between a CLI report and one from the Python package or the
# C API: file names and the times (none of which is a result).
NOT_RESULTS = {"mesh", "cloud", "output", "input", "file"}
# What the CLI did with the input's vertex attributes while writing; from
# Python, write_mesh_carrying says it.
NOT_RESULTS |= {"vertex_attributes", "vertex_attributes_not_written"}


def results(report: dict) -> dict:
    """A report's results: without NOT_RESULTS and the times."""
    return {k: v for k, v in report.items() if k not in NOT_RESULTS and not k.endswith("_ms")}



def shared_data(rel: str) -> Path:
    """A real scan by its path under the shared data directory: the PCL
    scans are shipped in fixtures/scans/pcl_test; the others are where
    MESHTRIM_SHARED_DATA points when it is set, else beside the repository
    or at /work/shared/data. Without
    them the test is skipped with the reason (not counted as passed),
    unless MESHTRIM_REQUIRE_DATA is set (as in CI): then it fails."""
    if rel.startswith("pcl_test/"):
        return ROOT / "fixtures" / "scans" / rel
    override = os.environ.get("MESHTRIM_SHARED_DATA")
    candidates = [Path(override)] if override else [ROOT.parent / "shared" / "data", Path("/work/shared/data")]
    for c in candidates:
        if c.is_dir():
            return c / rel
    message = f"the real scans are missing ({rel}): looked in {[str(c) for c in candidates]}"
    if os.environ.get("MESHTRIM_REQUIRE_DATA"):
        pytest.fail(message)
    pytest.skip(f"not run: {message}")


def run_meshtrim(*args):
    """Runs meshtrim; a non-zero exit fails the test with its output."""
    if not MESHTRIM.exists():
        pytest.fail(f"{MESHTRIM} missing: build with cargo build --release")
    r = subprocess.run([str(MESHTRIM), *map(str, args)], capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, f"meshtrim {args} failed:\n{r.stdout}\n{r.stderr}"
    return r
