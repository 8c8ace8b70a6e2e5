#!/bin/bash
# Build the OpenSubdiv Bfr benchmark (bfr_bench.cpp; a test tool, not part of tessera)
# exactly as build.sh builds osd_oracle, and against the same OpenSubdiv: the installed
# libosd-dev (-losdCPU), OSD_PREFIX=/prefix, or OSD_SRC=/path/to/OpenSubdiv (a source tree
# compiled into out/osd-src-<version>/libosdcpu.a). Its figures in docs/BENCHMARKS.md come
# from an OSD_SRC build of OpenSubdiv 3.6.0.
#
#     tools/osd-oracle/bfr_bench.sh [OUT]        -> tools/osd-oracle/bfr_bench
#     tools/osd-oracle/bfr_bench [--threads T] [--rate N] [--copies K] [--repeat R]
#                                [--float] [--adaptive-rates FILE] CAGE.obj
set -eu
here=$(cd "$(dirname "$0")" && pwd)
SOURCE=bfr_bench.cpp exec "$here/build.sh" "${1:-$here/bfr_bench}"
