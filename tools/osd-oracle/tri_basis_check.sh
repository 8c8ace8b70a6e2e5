#!/bin/bash
# Build tools/osd-oracle/tri_basis_check.cpp against an OpenSubdiv source tree and write its
# output, OpenSubdiv's own LOOP and GREGORY_TRIANGLE basis weights at a table of (u, v)
# points, as the fixture of tessera's surface::quartic_triangle and
# surface::gregory_triangle tests.
#
#   OSD_SRC=/path/to/OpenSubdiv tools/osd-oracle/tri_basis_check.sh [FIXTURE]
#
# OSD_SRC defaults to /tmp/osd-src (a checkout or tarball of tag v3_6_0). Only
# far/patchBasis.cpp is compiled (it needs nothing but headers); no CMake, no archive.
# FIXTURE defaults to crates/tessera/tests/fixtures/loop/tri_basis.txt.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
OSD_SRC=${OSD_SRC:-/tmp/osd-src}
CXX=${CXX:-g++}
fixture=${1:-"$root/crates/tessera/tests/fixtures/loop/tri_basis.txt"}
ver=$(sed -n 's/^#define OPENSUBDIV_VERSION \(v[0-9_]*\).*/\1/p' "$OSD_SRC/opensubdiv/version.h")
mkdir -p "$here/out"
# The weights' float arithmetic must be OpenSubdiv's as written: no fast-math, and x86-64's
# default SSE evaluation (no FMA contraction without -march).
$CXX -std=c++17 -O2 -Wall -Wextra -I"$OSD_SRC" -o "$here/out/tri_basis_check" \
    "$here/tri_basis_check.cpp" "$OSD_SRC/opensubdiv/far/patchBasis.cpp"
mkdir -p "$(dirname "$fixture")"
"$here/out/tri_basis_check" > "$fixture"
echo "wrote $fixture ($(grep -c '^loop' "$fixture") LOOP and $(grep -c '^gregory' "$fixture") GREGORY_TRIANGLE evaluations, OpenSubdiv $ver)"
