#!/bin/sh
# scripts/check-pfm-only.sh BUILD_DIR — configures, builds and tests the PFM-only build: the
# configuration a bare GPU machine gets (scripts/gpu-check.sh: RS_DEPS=OPTIONAL, no OpenImageIO,
# cJSON and Assimp carried), made here by leaving OpenImageIO out where it is installed
# (RS_SKIP_DEPS).  CTest's pfm_only_build runs it from the main build, so that CI keeps that
# configuration linking and its suite passing without a GPU.  The CUDA device is built when nvcc
# is found, as there.  Exits non-zero, with the failing step's last lines, if any step fails.
set -eu
dir=${1:?usage: check-pfm-only.sh BUILD_DIR}
src=$(cd "$(dirname "$0")/.." && pwd)
jobs=$(nproc 2>/dev/null || echo 2)
mkdir -p "$dir"
step() {
    name=$1
    shift
    if ! "$@" >"$dir/$name.log" 2>&1; then
        tail -40 "$dir/$name.log"
        echo "check-pfm-only: $name failed (whole log: $dir/$name.log)"
        exit 1
    fi
}
gen=
command -v ninja >/dev/null 2>&1 && gen="-G Ninja"
# shellcheck disable=SC2086 # $gen is empty or two words
step configure cmake -S "$src" -B "$dir/build" $gen -DCMAKE_BUILD_TYPE=Release \
    -DRS_DEPS=OPTIONAL -DRS_SKIP_DEPS=OpenImageIO
grep -q 'OpenImageIO 0' "$dir/configure.log" || {
    echo "check-pfm-only: the build still found OpenImageIO: $(grep 'raystream: OpenImageIO' "$dir/configure.log")"
    exit 1
}
step build cmake --build "$dir/build" -j"$jobs"
step ctest ctest --test-dir "$dir/build" -j"$jobs" --output-on-failure
grep -E 'tests passed|tests failed' "$dir/ctest.log" | sed 's/^/check-pfm-only: /'
grep -A20 'did not run' "$dir/ctest.log" | grep -E '^[[:space:]]+[0-9]+ - ' | sed 's/^ */check-pfm-only: skipped /' || true
