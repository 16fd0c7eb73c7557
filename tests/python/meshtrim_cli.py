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


def shared_data(rel: str) -> Path:
    """The real scans: beside the repository, via MESHTRIM_SHARED_DATA, or
    at /work/shared/data. Missing data is a failure, not a skip."""
    candidates = [Path(p) for p in [os.environ.get("MESHTRIM_SHARED_DATA")] if p]
    candidates += [ROOT.parent / "shared" / "data", Path("/work/shared/data")]
    for c in candidates:
        if c.is_dir():
            return c / rel
    pytest.fail(f"the real test data is missing: looked in {candidates}")


def run_meshtrim(*args):
    """Runs meshtrim; a non-zero exit fails the test with its output."""
    if not MESHTRIM.exists():
        pytest.fail(f"{MESHTRIM} missing: build with cargo build --release")
    r = subprocess.run([str(MESHTRIM), *map(str, args)], capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, f"meshtrim {args} failed:\n{r.stdout}\n{r.stderr}"
    return r
