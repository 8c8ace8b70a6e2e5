#!/bin/bash
# Build the OpenSubdiv Bfr oracle (a test tool, not part of tessera).
#
# Two ways:
#
# 1. Against an installed OpenSubdiv >= 3.5 (the first release with Bfr).
#    On Debian 12 / Ubuntu:  apt-get install -y g++ libosd-dev   (3.5.0)
#      headers:  /usr/include/opensubdiv/{bfr,far,sdc,vtr}/...  (default path)
#      library:  /usr/lib/x86_64-linux-gnu/libosdCPU.so         (-losdCPU)
#    Bfr, Far, Sdc and Vtr all live in libosdCPU; libosdGPU is not needed.
#    For another install prefix set OSD_PREFIX (uses $OSD_PREFIX/include and
#    $OSD_PREFIX/lib, with an rpath).
#        tools/osd-oracle/build.sh                 -> tools/osd-oracle/osd_oracle
#
# 2. From an OpenSubdiv source tree (no CMake): set OSD_SRC to a checkout
#    (e.g. tag v3_6_0). Its 42 sdc/vtr/far/bfr .cpp files are compiled with
#    g++ into a static archive under out/osd-src-<version>/ and linked in.
#    Needed because Debian's 3.5.0 has a Bfr bug (fixed in 3.5.1/3.6.0,
#    OpenSubdiv commit 51eb6a04) that reads uninitialised memory and may
#    crash on catmark_val2_interior; see README.md.
#        OSD_SRC=/path/to/OpenSubdiv tools/osd-oracle/build.sh
#                                                  -> tools/osd-oracle/osd_oracle
#
# An explicit output path may be given as $1. JOBS (default 2) sets the
# parallel compile count for way 2. SOURCE (default osd_oracle.cpp) names the
# program to build: bfr_bench.sh builds bfr_bench.cpp through this script.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
out=${1:-"$here/osd_oracle"}
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
fi
SOURCE=${SOURCE:-osd_oracle.cpp}
$CXX -std=c++17 -O2 -Wall -Wextra -pthread -o "$out" "$here/$SOURCE" "${flags[@]}" "${libs[@]}"
echo "built $out (${libs[*]})"
