#!/usr/bin/env bash
# Accuracy against a peer: meshtrim's BPD and Open3D's boundary detection
# on the synthetic clouds with ground truth of docs/results.md's accuracy
# table, both scored by trim::evaluate (precision: detected points within
# one intended spacing of the true boundary; recall: the share of the true
# boundary's length with a detected point that close).
#
#   bash bench/accuracy.sh
#
# Installs Open3D 0.20 (CPU build) into bench-venv/ on first use, as
# bench/bpd.sh does. Open3D needs a search radius; both of bench/bpd.sh's
# rules are scored (3 mean nearest-neighbour spacings, and the mean
# distance to the 30th neighbour). Prints a markdown table.
set -euo pipefail
cd "$(dirname "$0")/.."

if ! dpkg -s libusb-1.0-0 >/dev/null 2>&1; then
    apt-get install -y -q libusb-1.0-0 >/dev/null
fi
if [ ! -x bench-venv/bin/python ] || ! bench-venv/bin/python -c "import open3d" 2>/dev/null; then
    python3 -m venv bench-venv
    bench-venv/bin/pip install -q open3d-cpu==0.20.0
fi
cargo build --release -q --example accuracy_peer
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

./target/release/examples/accuracy_peer write "$work"
bench-venv/bin/python bench/open3d_labels.py "$work"
./target/release/examples/accuracy_peer score "$work" spacings knn30
