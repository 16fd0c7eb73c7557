#!/usr/bin/env bash
# Accuracy against a peer: meshtrim's BPD and Open3D's boundary detection
# on the synthetic clouds with ground truth of docs/results.md's accuracy
# table, both scored by the test kit's evaluation (precision: detected
# points within one intended spacing of the true boundary; recall: the
# share of the true boundary's length with a detected point that close).
#
#   bash bench/accuracy.sh
#
# Installs Open3D 0.20 (CPU build) into bench-venv/ on first use, as
# bench/bpd.sh does. Open3D needs a search radius; both of bench/bpd.sh's
# rules are scored (3 mean nearest-neighbour spacings, and the mean
# distance to the 30th neighbour). Prints a markdown table.
set -euo pipefail
cd "$(dirname "$0")/.."

source bench/open3d_env.sh
cargo build --release -q --example accuracy_peer
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

./target/release/examples/accuracy_peer write "$work"
bench-venv/bin/python bench/open3d_labels.py "$work"
./target/release/examples/accuracy_peer score "$work" spacings knn30
