# Sourced by the benchmarks that run Open3D (bpd.sh, accuracy.sh, io.sh):
# makes sure bench-venv/ holds Open3D 0.20 (CPU build), installing it on
# first use, with the Debian package it needs (libusb-1.0-0).
if ! dpkg -s libusb-1.0-0 >/dev/null 2>&1; then
    apt-get install -y -q libusb-1.0-0 >/dev/null
fi
if [ ! -x bench-venv/bin/python ] || ! bench-venv/bin/python -c "import open3d" 2>/dev/null; then
    python3 -m venv bench-venv
    bench-venv/bin/pip install -q open3d-cpu==0.20.0
fi
