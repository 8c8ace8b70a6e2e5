#!/bin/bash
# Build the OpenSubdiv Bfr benchmark (bfr_bench.cpp; a test tool, not part of tessera)
# the way build.sh builds osd_oracle: g++ -std=c++17 -O2 -Wall -Wextra, plus -pthread.
#
# Which OpenSubdiv, in this order:
#   OSD_SRC=/path/to/OpenSubdiv   a source tree: its sdc/vtr/far/bfr .cpp files are
#                                 compiled (as build.sh does; JOBS, default 2) into
#                                 out/osd-src-<version>/libosdcpu.a, which is linked
#   OSD_PREFIX=/prefix            an install prefix ($OSD_PREFIX/include, /lib, rpath)
#   otherwise, if /tmp/osd-src (v3_6_0) and the archive build.sh made from it,
#   out/osd-src-v3_6_0/libosdcpu.a, are both present: those (-I/tmp/osd-src)
#   otherwise the installed libosd-dev (Debian 12: 3.5.0), -losdCPU
#
#     tools/osd-oracle/bfr_bench.sh [OUT]        -> tools/osd-oracle/bfr_bench
#     tools/osd-oracle/bfr_bench [--threads T] [--rate N] [--copies K] [--repeat R]
#                                [--float] [--adaptive-rates FILE] CAGE.obj
set -eu
here=$(cd "$(dirname "$0")" && pwd)
out=${1:-"$here/bfr_bench"}
CXX=${CXX:-g++}
JOBS=${JOBS:-2}
flags=()
libs=(-losdCPU)
if [ -n "${OSD_SRC:-}" ]; then
    ver=$(sed -n 's/^#define OPENSUBDIV_VERSION \(v[0-9_]*\).*/\1/p' "$OSD_SRC/opensubdiv/version.h")
    bdir="$here/out/osd-src-$ver"
    mkdir -p "$bdir"
    srcs=("$OSD_SRC"/opensubdiv/{sdc,vtr,far,bfr}/*.cpp)
    printf '%s\n' "${srcs[@]}" | xargs -P "$JOBS" -I{} sh -c \
        'o="$1/$(basename "$(dirname "$2")")_$(basename "$2" .cpp).o";
         [ "$o" -nt "$2" ] || '"$CXX"' -std=c++14 -O2 -DNDEBUG -fPIC -I"$3" -c "$2" -o "$o"' \
        _ "$bdir" {} "$OSD_SRC"
    rm -f "$bdir/libosdcpu.a"
    ar rcs "$bdir/libosdcpu.a" "$bdir"/*.o
    flags=(-I"$OSD_SRC")
    libs=("$bdir/libosdcpu.a")
elif [ -n "${OSD_PREFIX:-}" ]; then
    flags=(-I"$OSD_PREFIX/include" -L"$OSD_PREFIX/lib" -Wl,-rpath,"$OSD_PREFIX/lib")
elif [ -f /tmp/osd-src/opensubdiv/version.h ] && [ -f "$here/out/osd-src-v3_6_0/libosdcpu.a" ] &&
     grep -q '^#define OPENSUBDIV_VERSION v3_6_0' /tmp/osd-src/opensubdiv/version.h; then
    flags=(-I/tmp/osd-src)
    libs=("$here/out/osd-src-v3_6_0/libosdcpu.a")
fi
$CXX -std=c++17 -O2 -Wall -Wextra -pthread -o "$out" "$here/bfr_bench.cpp" "${flags[@]}" "${libs[@]}"
echo "built $out (${libs[*]})"
