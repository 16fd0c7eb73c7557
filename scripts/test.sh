#!/usr/bin/env bash
# Runs every test: Rust unit, integration and CLI tests, then the Python
# tests (tests/python/: the PyMeshLab validation of the commands and the
# meshtrim package's tests, in the .venv-test venv, which this creates or
# checks first: about 1.5 min the first time, 3 s after; the package is
# built and installed into it),
# then a short seeded fuzzing pass of the CLI (scripts/fuzz_cli.py) and a
# short soak of the commands on fresh samplings (scripts/soak.py).
#
# The PCL scans the tests read are shipped in fixtures/scans; the other
# real scans (the Stanford bunny's, MeshLab's, the Kinect blade) are read
# from ../shared/data (or MESHTRIM_SHARED_DATA). Without them the tests
# that need them are not run: each is listed on its own line, and none is
# counted as passed. With MESHTRIM_REQUIRE_DATA set (CI sets it), missing
# data fails the run.
set -euo pipefail
cd "$(dirname "$0")/.."

# The tests' own rule (tests/common/mod.rs): MESHTRIM_SHARED_DATA when it
# is set, else beside the repository or at /work/shared/data.
data_found() {
    if [ -n "${MESHTRIM_SHARED_DATA:-}" ]; then
        [ -d "$MESHTRIM_SHARED_DATA" ]
    else
        [ -d ../shared/data ] || [ -d /work/shared/data ]
    fi
}

# Libraries, binaries and tests; the examples are compiled (and linted) by
# `cargo clippy --all-targets` in CI, so they are not built again here.
# The Python package's native module is tested from Python (below).
rust_tests=(cargo test --workspace --exclude meshtrim-python --release --lib --bins --tests)
if data_found; then
    "${rust_tests[@]}"
elif [ -n "${MESHTRIM_REQUIRE_DATA:-}" ]; then
    echo "error: the real scans are missing (../shared/data, or set MESHTRIM_SHARED_DATA), and MESHTRIM_REQUIRE_DATA is set" >&2
    exit 1
else
    "${rust_tests[@]}" -- --skip shared_data::
    echo
    echo "Rust tests not run (they need the real scans of ../shared/data; set MESHTRIM_SHARED_DATA):"
    "${rust_tests[@]}" -q -- --list --format terse 2>/dev/null | grep 'shared_data::' \
        | sed 's/: test$//; s/^/  not run: /' || true
fi
# The library's documented example (crates/trim/src/lib.rs), run as a test.
cargo test --workspace --exclude meshtrim-python --release --doc
bash scripts/python_env.sh
cargo build --release --bin meshtrim
# The C API's library (crates/capi), which tests/python/test_c_api.py
# compiles a C program against.
cargo build --release -p meshtrim-capi
# The Python package (python/), built by maturin in release into the shared
# target/ (so the CLI's compiled dependencies are reused) and installed into
# the venv, replacing any earlier build.
PATH="$PWD/.venv-test/bin:$PATH" .venv-test/bin/python -m pip install --quiet \
    --disable-pip-version-check --no-build-isolation --no-deps --force-reinstall ./python
MESHTRIM="$PWD/target/release/meshtrim" .venv-test/bin/python -m pytest -q -rsx tests/python
# A short seeded fuzzing pass of the CLI (about 40 s): no mutated input may
# make it panic, die by a signal or hang.
.venv-test/bin/python scripts/fuzz_cli.py --seed 2026 --cases 150 --timeout 60
# A short soak of the commands on samplings and crops of real scans no
# test uses (about 25 s): every output valid by PyMeshLab.
.venv-test/bin/python scripts/soak.py --first-seed 2026 --seeds 2
