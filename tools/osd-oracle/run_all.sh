#!/bin/bash
# Run osd_oracle on every cage of a folder at rates 1, 2 and 8 and print a
# markdown table: boundary interpolation, faces, faces Bfr evaluates as one
# regular patch, faces without a limit surface, points per rate,
# wall time per rate (ms, output written to OUT), warnings and exit status.
#   usage: run_all.sh [CAGE_DIR] [OUT]
# CAGE_DIR defaults to ${TESSERA_DATA:-../shared/data}/subdivision relative
# to the repository root; OUT defaults to tools/osd-oracle/out (git-ignored).
# ORACLE selects the binary (default tools/osd-oracle/osd_oracle).
set -u
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
dir=${1:-"${TESSERA_DATA:-$root/../shared/data}/subdivision"}
out=${2:-"$here/out"}
bin=${ORACLE:-"$here/osd_oracle"}
[ -x "$bin" ] || { echo "no $bin: run build.sh first" >&2; exit 1; }
mkdir -p "$out"
echo "| cage | boundary | faces | regular | no limit | points r1 | points r2 | points r8 | ms r1 | ms r2 | ms r8 | warnings | rc |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|"
for f in "$dir"/*.obj; do
    name=$(basename "$f" .obj)
    pts=(); ms=(); rcs=""
    for r in 1 2 8; do
        t0=$(date +%s%N)
        "$bin" "$f" "$r" >"$out/$name.r$r.txt" 2>"$out/$name.r$r.err"
        rc=$?
        t1=$(date +%s%N)
        ms+=("$(( (t1 - t0) / 1000000 ))")
        rcs="$rcs$rc"
        end=$(tail -n 1 "$out/$name.r$r.txt")
        pts+=("$(echo "$end" | awk '{print $6}')")
    done
    faces=$(echo "$end" | awk '{print $4}')
    nolimit=$(echo "$end" | awk '{print $8}')
    warns=$(echo "$end" | awk '{print $12}')
    regular=$(echo "$end" | awk '{print $14}')
    bnd=$(head -n 1 "$out/$name.r1.txt" | awk '{print $8}')
    [ "$rcs" = "000" ] && rcs=0
    echo "| $name | ${bnd:-?} | ${faces:-?} | ${regular:-?} | ${nolimit:-?} | ${pts[0]:-?} | ${pts[1]:-?} | ${pts[2]:-?} | ${ms[0]} | ${ms[1]} | ${ms[2]} | ${warns:-?} | $rcs |"
done
