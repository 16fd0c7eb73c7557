#!/usr/bin/env bash
# Runs every test: Rust unit, integration and CLI tests.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo test --workspace --release
