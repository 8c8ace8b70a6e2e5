#!/bin/bash
# Build tools/osd-oracle/loop_sdc_check.cpp against an OpenSubdiv source tree and write its
# output, OpenSubdiv's own Sdc Loop refinement and limit masks for a seeded table of
# neighbourhoods, as the fixture tessera's `subdivision::loop_sdc` tests compare against.
#
#   OSD_SRC=/path/to/OpenSubdiv tools/osd-oracle/loop_sdc_check.sh [FIXTURE]
#
# OSD_SRC defaults to /tmp/osd-src (a checkout or tarball of tag v3_6_0). Sdc is headers
# plus sdc/crease.cpp: the archive that build.sh makes (out/osd-src-<version>/libosdcpu.a,
# here or in OSD_LIB_DIR) is linked when present, otherwise crease.cpp and typeTraits.cpp
# are compiled here. FIXTURE defaults to
# crates/tessera/tests/fixtures/sdc/loop_masks.txt.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
OSD_SRC=${OSD_SRC:-/tmp/osd-src}
CXX=${CXX:-g++}
fixture=${1:-"$root/crates/tessera/tests/fixtures/sdc/loop_masks.txt"}
ver=$(sed -n 's/^#define OPENSUBDIV_VERSION \(v[0-9_]*\).*/\1/p' "$OSD_SRC/opensubdiv/version.h")
lib="${OSD_LIB_DIR:-$here/out/osd-src-$ver}/libosdcpu.a"
mkdir -p "$here/out"
if [ -f "$lib" ]; then
    srcs=("$lib")
else
    srcs=("$OSD_SRC/opensubdiv/sdc/crease.cpp" "$OSD_SRC/opensubdiv/sdc/typeTraits.cpp")
fi
# The order of operations in Sdc's float and double arithmetic must survive: no fast-math,
# and x86-64's default SSE evaluation (no FMA contraction without -march). The masks' cos
# and sin are the C library's, as Rust's f64::cos/sin are on the same platform.
$CXX -std=c++17 -O2 -Wall -Wextra -I"$OSD_SRC" -o "$here/out/loop_sdc_check" "$here/loop_sdc_check.cpp" "${srcs[@]}"
mkdir -p "$(dirname "$fixture")"
"$here/out/loop_sdc_check" > "$fixture"
echo "wrote $fixture ($(grep -vc '^#' "$fixture") cases, OpenSubdiv $ver)"
