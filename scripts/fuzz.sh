#!/bin/sh
# scripts/fuzz.sh — builds the libFuzzer harnesses (tests/fuzz) with clang, ASan and UBSan in
# build-fuzz/, and runs each for a bounded time.  One command; check-sanitizers.sh runs it short.
#   sh scripts/fuzz.sh [SECONDS] [HARNESS...]   (default: 60 s each, every harness)
# HARNESS: scene_json, mesh, cli_options.  Each harness starts from its corpus in
# build-fuzz/corpus/HARNESS (kept between runs, so later runs go deeper), seeded from the inputs
# already in the repository: tests/data (meshes; gltf_*.gltf: every material extension and
# texture transform we read), scenes/examples and tests/fuzz/seeds (scenes, command lines);
# nothing is copied into the repository.  An input that crashes, hangs (over
# -timeout=10 s), leaks or trips a sanitizer is saved as build-fuzz/findings/HARNESS-*; give it a
# regression test (tests/data or a case in the module's cmocka test) and a fix.
# Exit status: 0 when no harness found anything, 1 otherwise (every harness still runs).
# Environment: CC/CXX (default clang/clang++), FUZZ_JOBS (build jobs, default nproc),
# FUZZ_NICE (a prefix such as "nice -n 19" for the build and the runs).
set -eu
cd "$(dirname "$0")/.."
root="$(pwd)"
seconds="${1:-60}"
[ $# -gt 0 ] && shift
harnesses="${*:-scene_json mesh cli_options}"
case "$seconds" in
'' | *[!0-9]*)
    echo "fuzz.sh: SECONDS must be a whole number, not '$seconds'" >&2
    exit 2
    ;;
esac
cc="${CC:-clang}"
cxx="${CXX:-clang++}"
nice="${FUZZ_NICE:-}"
if ! command -v "$cc" >/dev/null 2>&1 || ! command -v "$cxx" >/dev/null 2>&1; then
    echo "fuzz.sh: $cc/$cxx not found (sh scripts/install-deps.sh installs clang)" >&2
    exit 2
fi

build="$root/build-fuzz"
mkdir -p "$build"
cmake -S . -B "$build" -DRS_FUZZ=ON -DRS_CUDA=OFF -DRS_BUILD_TESTS=OFF -DRS_BUILD_BENCH=OFF \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_C_COMPILER="$cc" -DCMAKE_CXX_COMPILER="$cxx" \
    >"$build/configure.log" 2>&1 || {
    cat "$build/configure.log" >&2
    exit 2
}
$nice cmake --build "$build" -j"${FUZZ_JOBS:-$(nproc)}" --target fuzzers

mkdir -p "$build/findings"
found=0
for h in $harnesses; do
    case "$h" in
    scene_json) seeds="scenes/examples tests/fuzz/seeds/scene_json"; max_len=65536 ;;
    mesh) seeds="tests/data"; max_len=16384 ;;
    cli_options) seeds="tests/fuzz/seeds/cli_options"; max_len=1024 ;;
    *)
        echo "fuzz.sh: unknown harness '$h' (scene_json, mesh, cli_options)" >&2
        exit 2
        ;;
    esac
    corpus="$build/corpus/$h"
    mkdir -p "$corpus"
    log="$build/fuzz-$h.log"
    t0="$(date +%s)"
    # shellcheck disable=SC2086
    if ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:allocator_may_return_null=1:${ASAN_OPTIONS:-}" \
        LSAN_OPTIONS="suppressions=$root/tests/fuzz/lsan.supp:print_suppressions=0:${LSAN_OPTIONS:-}" \
        UBSAN_OPTIONS="print_stacktrace=1:${UBSAN_OPTIONS:-}" \
        $nice "$build/tests/fuzz/fuzz_$h" -max_total_time="$seconds" -max_len="$max_len" \
        -timeout=10 -rss_limit_mb=2048 -close_fd_mask=3 -print_final_stats=1 \
        -dict="tests/fuzz/$h.dict" -artifact_prefix="$build/findings/$h-" \
        "$corpus" $seeds >"$log" 2>&1; then
        status="no findings"
    else
        status="FINDING (see $log and $build/findings/)"
        found=1
    fi
    took=$(($(date +%s) - t0))
    execs="$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)"
    rate="$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)"
    echo "fuzz $h: ${execs:-?} executions in ${took} s (${rate:-?}/s), corpus $(ls "$corpus" | wc -l) inputs: $status"
done
exit "$found"
