#!/usr/bin/env bash
# Runs every test: Rust unit, integration and CLI tests, then the PyMeshLab
# validation of the trimming (tests/python/, in the .venv-test venv, which
# this creates or checks first: about 35 s the first time, 1.5 s after).
set -euo pipefail
cd "$(dirname "$0")/.."
# Libraries, binaries and tests; the examples are compiled (and linted) by
# `cargo clippy --all-targets` in CI, so they are not built again here.
cargo test --workspace --release --lib --bins --tests
bash scripts/python_env.sh
cargo build --release --bin meshtrim
MESHTRIM="$PWD/target/release/meshtrim" .venv-test/bin/python -m pytest -q tests/python
