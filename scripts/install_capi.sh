#!/usr/bin/env bash
# Builds and installs meshtrim's C API (crates/capi) under a prefix:
#
#   bash scripts/install_capi.sh [PREFIX]      (default /usr/local)
#
#   PREFIX/include/meshtrim.h
#   PREFIX/lib/libmeshtrim.so             (debug information stripped)
#   PREFIX/lib/pkgconfig/meshtrim.pc      (cc $(pkg-config --cflags --libs meshtrim) ...)
#
# Linux; on other systems copy target/release's library and the header by
# hand.
set -euo pipefail
cd "$(dirname "$0")/.."

prefix=${1:-/usr/local}
cargo build --release -q -p meshtrim-capi
version=$(sed -n 's/^version = "\(.*\)"$/\1/p' crates/capi/Cargo.toml | head -1)

install -d "$prefix/include" "$prefix/lib/pkgconfig"
install -m 644 crates/capi/include/meshtrim.h "$prefix/include/meshtrim.h"
# Written to a temporary name and renamed, so that a program running with
# the old library keeps its copy.
install -m 755 target/release/libmeshtrim.so "$prefix/lib/.libmeshtrim.so.tmp"
strip --strip-debug "$prefix/lib/.libmeshtrim.so.tmp"
mv -f "$prefix/lib/.libmeshtrim.so.tmp" "$prefix/lib/libmeshtrim.so"
cat > "$prefix/lib/pkgconfig/meshtrim.pc" <<EOF
prefix=$prefix
includedir=\${prefix}/include
libdir=\${prefix}/lib

Name: meshtrim
Description: Boundary detection, smoothed edges, trimming and border cleanup of meshes from 3D scans
Version: $version
Cflags: -I\${includedir}
Libs: -L\${libdir} -lmeshtrim
EOF
echo "installed meshtrim $version under $prefix"
