#!/usr/bin/env bash
# Creates (idempotently) the Python test venv at .venv-test/ with the pinned
# packages of the PyMeshLab validation suite (tests/python/).
#
#   bash scripts/python_env.sh            # create or check the venv
#   .venv-test/bin/python -m pytest tests/python
#
# - Fast when the venv is already complete: a stamp file records the pinned
#   requirements; if they are unchanged and the imports work, nothing is done.
# - Online: installs from PyPI and also keeps the wheels in a local wheelhouse
#   ($MESHTRIM_WHEELHOUSE, default ~/.cache/meshtrim/wheels).
# - Offline: if PyPI cannot be reached, installs from that wheelhouse
#   (pip --no-index), so a machine that has run this once can rebuild the venv.
# - Headless: pymeshlab's manylinux wheel bundles Qt and MeshLab; no Debian
#   package is needed. The final check builds a MeshSet and runs screened
#   Poisson on a small cloud.
# Needs python3 >= 3.10 with the venv module (PYTHON overrides the interpreter).
set -euo pipefail
cd "$(dirname "$0")/.."

VENV=.venv-test
PYTHON=${PYTHON:-python3}
WHEELHOUSE=${MESHTRIM_WHEELHOUSE:-$HOME/.cache/meshtrim/wheels}

# The pins. numpy: pymeshlab 2025.7.post1 declares plain "numpy" and converts
# arrays through pybind11 at run time, so numpy 2.x works (checked below).
# scipy: cKDTree for nearest-point distances. The last three are pytest's
# dependencies, pinned so the venv is the same everywhere.
REQUIREMENTS='pymeshlab==2025.7.post1
numpy==2.2.6
scipy==1.15.3
pytest==8.3.5
iniconfig==2.3.1
packaging==26.3
pluggy==1.7.0'

STAMP="$VENV/.meshtrim-requirements"
log() { echo "python_env: $*" >&2; }

check() {
    "$VENV/bin/python" - <<'EOF'
import numpy as np
import pymeshlab
import scipy.spatial
import pytest  # noqa: F401

# A small cap of a sphere: screened Poisson must produce faces.
rng = np.random.default_rng(1)
p = rng.normal(size=(2000, 3))
p /= np.linalg.norm(p, axis=1, keepdims=True)
p = p[p[:, 2] > 0.0]
ms = pymeshlab.MeshSet()
ms.add_mesh(pymeshlab.Mesh(vertex_matrix=p, v_normals_matrix=p.copy()))
ms.generate_surface_reconstruction_screened_poisson(depth=6)
m = ms.current_mesh()
assert m.face_number() > 100, m.face_number()
assert m.vertex_scalar_array().shape[0] == m.vertex_number()
EOF
}

if [[ -f "$STAMP" && "$(cat "$STAMP")" == "$REQUIREMENTS" && -x "$VENV/bin/python" ]]; then
    if check 2>/dev/null; then
        log "$VENV is up to date"
        exit 0
    fi
    log "$VENV is stamped but the check failed; reinstalling"
fi

start=$(date +%s)
if [[ ! -x "$VENV/bin/python" ]]; then
    log "creating $VENV with $("$PYTHON" --version 2>&1)"
    "$PYTHON" -m venv "$VENV"
fi
rm -f "$STAMP"
REQ_FILE=$(mktemp)
trap 'rm -f "$REQ_FILE"' EXIT
printf '%s\n' "$REQUIREMENTS" >"$REQ_FILE"
PIP=("$VENV/bin/python" -m pip --disable-pip-version-check --no-input)

if "${PIP[@]}" install --timeout 30 --retries 2 -r "$REQ_FILE"; then
    # Keep the wheels for offline rebuilds (from pip's cache when present).
    mkdir -p "$WHEELHOUSE"
    "${PIP[@]}" download --quiet --timeout 30 -d "$WHEELHOUSE" -r "$REQ_FILE" ||
        log "could not fill the wheelhouse $WHEELHOUSE (ignored)"
else
    log "online install failed; trying the wheelhouse $WHEELHOUSE"
    "${PIP[@]}" install --no-index --find-links "$WHEELHOUSE" -r "$REQ_FILE"
fi

check
printf '%s' "$REQUIREMENTS" >"$STAMP"
log "$VENV ready in $(( $(date +%s) - start )) s"
