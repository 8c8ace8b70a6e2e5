#!/bin/bash
# Build and run the Loop Gregory-triangle end-cap oracle (loop_gregory_check.cpp) against
# OpenSubdiv 3.6.0 built from source, and write tessera's fixture.
#
# OSD_SRC (default /tmp/osd-src) is the source tree. OSD_LIB may name an archive that
# build.sh made (OSD_SRC=... tools/osd-oracle/build.sh -> out/osd-src-<ver>/libosdcpu.a);
# if it is unset and that archive is absent, the sdc/vtr/far .cpp files (Bfr is not needed)
# are compiled here with g++ into out/osd-far-<ver>/libosdfar.a, JOBS (default 2) at a time.
#     tools/osd-oracle/loop_gregory_check.sh
#         -> crates/tessera/tests/fixtures/gregory/osd_gregory_triangle.txt
set -eu
here=$(cd "$(dirname "$0")" && pwd)
src=${OSD_SRC:-/tmp/osd-src}
CXX=${CXX:-g++}
JOBS=${JOBS:-2}
ver=$(sed -n 's/^#define OPENSUBDIV_VERSION \(v[0-9_]*\).*/\1/p' "$src/opensubdiv/version.h")
lib=${OSD_LIB:-$here/out/osd-src-$ver/libosdcpu.a}
if [ ! -f "$lib" ]; then
    bdir="$here/out/osd-far-$ver"
    mkdir -p "$bdir"
    printf '%s\n' "$src"/opensubdiv/{sdc,vtr,far}/*.cpp | xargs -P "$JOBS" -I{} sh -c \
        'o="$1/$(basename "$(dirname "$2")")_$(basename "$2" .cpp).o";
         [ "$o" -nt "$2" ] || '"$CXX"' -std=c++17 -O2 -DNDEBUG -fPIC -I"$3" -c "$2" -o "$o"' \
        _ "$bdir" {} "$src"
    lib="$bdir/libosdfar.a"
    rm -f "$lib"
    ar rcs "$lib" "$bdir"/*.o
fi
mkdir -p "$here/out"
$CXX -std=c++17 -O2 -Wall -Wextra -I"$src" -o "$here/out/loop_gregory_check" "$here/loop_gregory_check.cpp" "$lib"
fixture="$here/../../crates/tessera/tests/fixtures/gregory/osd_gregory_triangle.txt"
mkdir -p "$(dirname "$fixture")"
"$here/out/loop_gregory_check" > "$fixture"
echo "wrote $fixture ($(grep -c '^patch' "$fixture") patches)"
