#!/bin/sh
# scripts/check-layering.sh — every quoted `#include "X/..."` in the source folders must follow
# the layering the build links along (top-level CMakeLists.txt, one static library per folder).
#   sh scripts/check-layering.sh [SOURCE_ROOT]   check the tree (default: this script's checkout)
#   sh scripts/check-layering.sh --self-test     check the checker on a small planted fixture
# A violation prints `FILE:LINE: FOLDER may not include X/... (FOLDER may use: ...)` and the
# script exits 1; a clean tree prints one summary line and exits 0.  Includes without a folder
# component ("internal.h", a file's own neighbour) and system includes (<...>) are not checked.
# Run by CTest as layering_check and layering_self_test (tests/CMakeLists.txt).

# The allowed arrows, A=B,C: a file in A/ may include A/ itself and B/, C/.  Keep this table and
# the target_link_libraries of the folder libraries in CMakeLists.txt the same.  cpu and gpu
# never include each other; nothing includes app/ but api/ (the C API over the command's steps)
# and python/, nothing tests/ or bench/.  The public header include/raystream.h is included as
# "raystream.h", without a folder.
RS_LAYERS="core=
streams=core
accel=core,streams
scenes=core
shading=core,streams,accel,scenes
scheduler=core,streams,accel,scenes,shading
cpu=core,streams,accel,scenes,shading,scheduler
gpu=core,streams,accel,scenes,shading,scheduler
app=core,streams,accel,scenes,shading,scheduler,cpu,gpu
api=core,streams,accel,scenes,shading,scheduler,cpu,gpu,app
python=core,streams,accel,scenes,shading,scheduler,cpu,gpu,app"
RS_FOLDERS="core accel streams scenes shading scheduler cpu gpu app api python"

script="$0"

# check ROOT: prints violations and the summary; exit status 0 clean, 1 violations, 2 misuse
check() {
    root="$1"
    if [ ! -d "$root" ]; then
        echo "check-layering: $root: not a directory" >&2
        return 2
    fi
    (
        cd "$root" || exit 2
        dirs=""
        for d in $RS_FOLDERS; do
            [ -d "$d" ] && dirs="$dirs $d"
        done
        if [ -z "$dirs" ]; then
            echo "check-layering: $root: none of $RS_FOLDERS is there" >&2
            exit 2
        fi
        # shellcheck disable=SC2086 # $dirs is a list of plain folder names
        find $dirs -type f \( -name '*.c' -o -name '*.h' -o -name '*.cu' -o -name '*.cpp' \) \
            -exec awk -v table="$RS_LAYERS" '
            BEGIN {
                nrow = split(table, rows, "\n")
                for (i = 1; i <= nrow; i++) {
                    eq = index(rows[i], "=")
                    f = substr(rows[i], 1, eq - 1)
                    uses[f] = substr(rows[i], eq + 1)
                    known[f] = 1
                }
                known["tests"] = 1; known["bench"] = 1
                nfiles = ARGC - 1; nincs = 0
            }
            FNR == 1 { slash = index(FILENAME, "/"); folder = substr(FILENAME, 1, slash - 1) }
            /^[ \t]*#[ \t]*include[ \t]*"/ {
                path = $0
                sub(/^[^"]*"/, "", path); sub(/".*$/, "", path)
                slash = index(path, "/")
                if (slash == 0) next
                top = substr(path, 1, slash - 1)
                if (!(top in known)) next
                nincs++
                if (top == folder) next
                if (index("," uses[folder] ",", "," top ",") > 0) next
                may = uses[folder]; gsub(/,/, ", ", may)
                if (may == "") may = "nothing"
                printf "V\t%s:%d: %s may not include %s (%s may use: %s)\n", \
                       FILENAME, FNR, folder, path, folder, may
            }
            END { printf "C\t%d\t%d\n", nfiles, nincs }
            ' {} + |
            LC_ALL=C sort -t: -k1,1 -k2,2n |
            awk -F'\t' '
            $1 == "C" { files += $2; incs += $3; next }
            $1 == "V" { print $2; bad++ }
            END {
                printf "layering: %d files, %d includes, %d violations\n", files, incs, bad
                exit (bad > 0)
            }'
    )
}

# ---- self-test -------------------------------------------------------------------------------
# A tiny tree that obeys the graph, then copies of it with one forbidden include planted each.
fixture() {
    mkdir -p "$1/core" "$1/cpu" "$1/gpu" "$1/scheduler" "$1/app"
    printf '%s\n' '#pragma once' '#include <stddef.h>' > "$1/core/alloc.h"
    printf '%s\n' '#include "core/alloc.h"' '' '#include <stdlib.h>' 'int rs_alloc_x;' \
        > "$1/core/alloc.c"
    printf '%s\n' '#pragma once' '#include "core/alloc.h"' > "$1/scheduler/device.h"
    printf '%s\n' '#include "scheduler/device.h"' '#include "sched.h"' > "$1/scheduler/sched.c"
    printf '%s\n' '#pragma once' '#include "scheduler/device.h"' > "$1/cpu/cpu_device.h"
    printf '%s\n' '/* the CPU device */' '#include "cpu/cpu_device.h"' '' \
        '#include "core/alloc.h"' 'int rs_cpu_x;' > "$1/cpu/cpu_device.c"
    printf '%s\n' '#pragma once' '#include "scheduler/device.h"' > "$1/gpu/gpu_device.h"
    printf '%s\n' '#include "gpu/gpu_device.h"' '#include "core/alloc.h"' > "$1/gpu/gpu_none.c"
    printf '%s\n' '#include "gpu/gpu_device.h"' '__global__ void k(void) {}' > "$1/gpu/k.cu"
    printf '%s\n' '#include "app/options.h"' '#include "cpu/cpu_device.h"' \
        '#include "gpu/gpu_device.h"' '#  include "scheduler/device.h"' \
        '#include "core/alloc.h"' 'int main(void) { return 0; }' > "$1/app/main.c"
    printf '%s\n' '#pragma once' > "$1/app/options.h"
}

self_test() {
    tmp="$(mktemp -d "${TMPDIR:-/tmp}/check-layering.XXXXXX")" || exit 2
    trap 'rm -rf "$tmp"' EXIT
    trap 'exit 130' INT TERM
    passed=0
    failed=0
    ok() { echo "ok - $1"; passed=$((passed + 1)); }
    fail() { echo "FAIL - $1"; failed=$((failed + 1)); }

    fixture "$tmp/clean"
    out="$(sh "$script" "$tmp/clean" 2>&1)"; rc=$?
    if [ "$rc" -eq 0 ] && [ "$out" = "layering: 11 files, 15 includes, 0 violations" ]; then
        ok "a tree that obeys the graph passes"
    else
        fail "the clean fixture: exit $rc, output: $out"
    fi

    # planted: TREE FILE TEXT EXPECTED-LINE — TEXT appended to FILE must give exactly EXPECTED
    planted() {
        fixture "$tmp/$1"
        printf '%s\n' "$3" >> "$tmp/$1/$2"
        out="$(sh "$script" "$tmp/$1" 2>&1)"; rc=$?
        nviol="$(printf '%s\n' "$out" | grep -c 'may not include')"
        if [ "$rc" -eq 1 ] && [ "$nviol" -eq 1 ] && printf '%s\n' "$out" | grep -qxF "$4" &&
            printf '%s\n' "$out" | grep -qx 'layering: .*, 1 violations'; then
            ok "$1: $2 including ${3#*include } is refused"
        else
            fail "$1: expected exit 1 and '$4'; got exit $rc, output: $out"
        fi
    }
    planted cpu_gpu cpu/cpu_device.c '#include "gpu/gpu_device.h"' \
        'cpu/cpu_device.c:6: cpu may not include gpu/gpu_device.h (cpu may use: core, streams, accel, scenes, shading, scheduler)'
    planted core_scheduler core/alloc.c '#include "scheduler/device.h"' \
        'core/alloc.c:5: core may not include scheduler/device.h (core may use: nothing)'
    planted gpu_cpu gpu/gpu_device.h '#include "cpu/cpu_device.h"' \
        'gpu/gpu_device.h:3: gpu may not include cpu/cpu_device.h (gpu may use: core, streams, accel, scenes, shading, scheduler)'
    planted scheduler_app scheduler/sched.c '#include "app/options.h"' \
        'scheduler/sched.c:3: scheduler may not include app/options.h (scheduler may use: core, streams, accel, scenes, shading)'

    echo "$passed passed, $failed failed"
    [ "$failed" -eq 0 ]
}

case "${1:-}" in
    --self-test) self_test; exit $? ;;
    -h | --help) sed -n '2,9p' "$script"; exit 0 ;;
    -*) echo "usage: sh $script [SOURCE_ROOT | --self-test]" >&2; exit 2 ;;
    "") check "$(cd "$(dirname "$script")/.." && pwd)"; exit $? ;;
    *) check "$1"; exit $? ;;
esac
