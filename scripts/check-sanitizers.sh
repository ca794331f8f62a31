#!/bin/sh
# scripts/check-sanitizers.sh — the test suite under AddressSanitizer + UBSan, and the scheduler
# and render tests (and the timeline, written from several threads) under ThreadSanitizer.  One
# command; run it before resolving an issue.
#   sh scripts/check-sanitizers.sh [address|thread]   (default: both)
# Builds in build-asan/ and build-tsan/ with RS_CUDA=OFF (device code is not instrumented).
set -eu
cd "$(dirname "$0")/.."
jobs="$(nproc)"
which="${1:-both}"

if [ "$which" = both ] || [ "$which" = address ]; then
    cmake -S . -B build-asan -DRS_SANITIZE=address -DRS_CUDA=OFF -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
    cmake --build build-asan -j"$jobs"
    ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
        ctest --test-dir build-asan --output-on-failure
fi
if [ "$which" = both ] || [ "$which" = thread ]; then
    cmake -S . -B build-tsan -DRS_SANITIZE=thread -DRS_CUDA=OFF -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
    cmake --build build-tsan -j"$jobs"
    # OpenMP is compiled out of this build (core/parallel.h says why): no suppressions needed.
    TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1" \
        ctest --test-dir build-tsan --output-on-failure -R "scheduler|render|app_cli|app_timeline"
fi
