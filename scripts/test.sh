#!/usr/bin/env bash
# Runs every test: Rust unit, integration and CLI tests, then the PyMeshLab
# validation of the trimming (tests/python/, in the .venv-test venv, which
# this creates or checks first: about 35 s the first time, 1.5 s after).
set -euo pipefail
cd "$(dirname "$0")/.."
cargo test --workspace --release
bash scripts/python_env.sh
cargo build --release --bin meshtrim
MESHTRIM="$PWD/target/release/meshtrim" .venv-test/bin/python -m pytest -q tests/python
