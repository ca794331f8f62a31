#!/bin/sh
# scripts/check-sanitizers.sh — the test suite under AddressSanitizer + UBSan, the scheduler,
# render, CLI and MPI tests (and the timeline, written from several threads) under
# ThreadSanitizer, and the libFuzzer harnesses (tests/fuzz, scripts/fuzz.sh) for a short bound
# each.  One command; run it before resolving an issue.
#   sh scripts/check-sanitizers.sh [address|thread|fuzz]   (default: all three)
# Builds in build-asan/, build-tsan/ and build-fuzz/ with RS_CUDA=OFF (device code is not
# instrumented).  FUZZ_SECONDS (default 20) bounds each harness.
set -eu
cd "$(dirname "$0")/.."
jobs="$(nproc)"
which="${1:-all}"
case "$which" in
all | address | thread | fuzz) ;;
both) which=all ;; # its name before the fuzzers joined
*)
    echo "check-sanitizers.sh: '$which': use address, thread, fuzz or nothing (all)" >&2
    exit 2
    ;;
esac

if [ "$which" = all ] || [ "$which" = address ]; then
    cmake -S . -B build-asan -DRS_SANITIZE=address -DRS_CUDA=OFF -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
    cmake --build build-asan -j"$jobs"
    # tests/fuzz/lsan.supp: Assimp's own leak on a malformed PLY (scenes_mesh_test reads one)
    ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
        LSAN_OPTIONS="suppressions=$(pwd)/tests/fuzz/lsan.supp" \
        ctest --test-dir build-asan --output-on-failure
fi
if [ "$which" = all ] || [ "$which" = thread ]; then
    cmake -S . -B build-tsan -DRS_SANITIZE=thread -DRS_CUDA=OFF -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
    cmake --build build-tsan -j"$jobs"
    # OpenMP is compiled out of this build (core/parallel.h says why): no suppressions needed.
    # app_mpi_test: the render thread against the messaging loop of every rank; Open MPI's own
    # locks and threads are suppressed by the binary itself (app/distributed.c)
    # OpenImageIO's thread pool synchronises where TSan cannot see (scripts/tsan.supp)
    TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1 suppressions=$(pwd)/scripts/tsan.supp" \
        ctest --test-dir build-tsan --output-on-failure -R "scheduler|render|app_cli|app_mpi|app_timeline|app_tev|api_test"
fi
if [ "$which" = all ] || [ "$which" = fuzz ]; then
    # the scene reader, the mesh import and the option parser: no crash, hang, leak or
    # sanitizer report in FUZZ_SECONDS each (a finding fails the check; fuzz.sh says where)
    FUZZ_JOBS="$jobs" sh scripts/fuzz.sh "${FUZZ_SECONDS:-20}"
fi
