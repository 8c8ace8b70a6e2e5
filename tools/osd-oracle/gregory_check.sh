#!/bin/bash
# Build and run the Gregory end-cap oracle (gregory_check.cpp) against a static
# OpenSubdiv 3.6.0 built from source by build.sh (OSD_SRC=... tools/osd-oracle/build.sh),
# and write tessera's fixture. OSD_SRC (default /tmp/osd-src) is the source tree for the
# headers; OSD_LIB the archive (default: this tree's out/, else /work/main's).
#     tools/osd-oracle/gregory_check.sh   -> crates/tessera/tests/fixtures/gregory/osd_gregory.txt
set -eu
here=$(cd "$(dirname "$0")" && pwd)
src=${OSD_SRC:-/tmp/osd-src}
lib=${OSD_LIB:-$here/out/osd-src-v3_6_0/libosdcpu.a}
[ -f "$lib" ] || lib=/work/main/tools/osd-oracle/out/osd-src-v3_6_0/libosdcpu.a
mkdir -p "$here/out"
${CXX:-g++} -std=c++17 -O2 -Wall -Wextra -I"$src" -o "$here/out/gregory_check" "$here/gregory_check.cpp" "$lib"
fixture="$here/../../crates/tessera/tests/fixtures/gregory/osd_gregory.txt"
mkdir -p "$(dirname "$fixture")"
"$here/out/gregory_check" > "$fixture"
echo "wrote $fixture ($(grep -c '^patch' "$fixture") patches)"
