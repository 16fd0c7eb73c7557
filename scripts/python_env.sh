#!/usr/bin/env bash
# Creates (idempotently) the Python test venv at .venv-test/ with the pinned
# packages of the Python tests (tests/python/requirements.txt): the PyMeshLab
# validation suite and the meshtrim package's tests.
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
# - Headless: pymeshlab's manylinux wheel bundles Qt and MeshLab; Open3D's
#   needs one Debian package, libusb-1.0-0, installed here when missing (as
#   root; otherwise the script says what to install). The final check
#   imports every package, builds a MeshSet and runs screened Poisson on a
#   small cloud.
# Needs python3 >= 3.10 with the venv module (PYTHON overrides the interpreter).
set -euo pipefail
cd "$(dirname "$0")/.."

VENV=.venv-test
PYTHON=${PYTHON:-python3}
WHEELHOUSE=${MESHTRIM_WHEELHOUSE:-$HOME/.cache/meshtrim/wheels}

# The pins, with why each package is there.
REQUIREMENTS_FILE=tests/python/requirements.txt
REQUIREMENTS=$(cat "$REQUIREMENTS_FILE")

STAMP="$VENV/.meshtrim-requirements"
log() { echo "python_env: $*" >&2; }

check() {
    "$VENV/bin/python" - <<'EOF'
import numpy as np
import pymeshlab
import scipy.spatial
import pytest  # noqa: F401
import open3d  # noqa: F401  (fails without libusb-1.0)
import trimesh  # noqa: F401
import dask.bag  # noqa: F401
import distributed  # noqa: F401
import laspy  # noqa: F401
import lazrs  # noqa: F401
import pye57  # noqa: F401
import ezdxf  # noqa: F401
import gmsh  # noqa: F401
import PIL  # noqa: F401

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

# Open3D's wheel links libusb-1.0, which Debian ships apart.
if ! ldconfig -p 2>/dev/null | grep -q 'libusb-1.0.so.0'; then
    if [[ $(id -u) == 0 ]] && command -v apt-get >/dev/null; then
        log "installing libusb-1.0-0 (Debian) for open3d"
        apt-get install -y -q libusb-1.0-0 >/dev/null ||
            { apt-get update -q >/dev/null && apt-get install -y -q libusb-1.0-0 >/dev/null; }
    else
        log "open3d needs libusb-1.0: install it (sudo apt-get install libusb-1.0-0) and run again"
        exit 1
    fi
fi

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
REQ_FILE=$REQUIREMENTS_FILE
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
