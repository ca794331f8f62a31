#!/bin/sh
# scripts/gpu-check.sh — the GPU half of the checks, for a lent GPU machine (the `device` tool's
# `run`), which gets only this checkout: no ../shared, none of our Debian packages, no network.
#
#   sh scripts/gpu-check.sh --fetch     here, with network: put the cmocka .debs in .gpu-debs/
#                                       (git-ignored) for the run to carry
#   sh scripts/gpu-check.sh [--quick]   there (carry .gpu-debs): unpack cmocka into a prefix (never
#                                       into /), build with RS_DEPS=OPTIONAL (no OpenImageIO,
#                                       cJSON, Assimp: images .pfm only) and RS_CUDA=ON, then run
#                                       the CUDA tests, the scheduler and determinism tests and the
#                                       GPU benchmarks; every log goes to $OUT (else gpu-results/).
set -eu
if [ "${1:-}" = "--fetch" ]; then
    mkdir -p .gpu-debs
    (cd .gpu-debs && apt-get download libcmocka0 libcmocka-dev)
    grep -qx '/.gpu-debs/' .git/info/exclude 2>/dev/null || echo '/.gpu-debs/' >>.git/info/exclude
    echo "gpu-check: .gpu-debs ready; run with carry [\".gpu-debs\"]"
    exit 0
fi
quick=
[ "${1:-}" = "--quick" ] && quick=--quick
out=${OUT:-gpu-results}
prefix=/tmp/rs-prefix
mkdir -p "$out" "$prefix"
for f in .gpu-debs/*.deb; do [ -f "$f" ] && dpkg -x "$f" "$prefix"; done
export LD_LIBRARY_PATH="$prefix/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
jobs=$(nproc)
{
    nvidia-smi || true
    echo "cores: $jobs"
} >"$out/machine.txt" 2>&1
cmake -S . -B build-gpu -DCMAKE_BUILD_TYPE=Release -DRS_DEPS=OPTIONAL -DRS_CUDA=ON \
    -DCMOCKA_ROOT="$prefix" >"$out/configure.txt" 2>&1 || { cat "$out/configure.txt"; exit 1; }
cmake --build build-gpu -j"$jobs" >"$out/build.txt" 2>&1 || { tail -50 "$out/build.txt"; exit 1; }
status=0
ctest --test-dir build-gpu --output-on-failure -R 'gpu_trace|scheduler_stream|render_determinism|scenes_mirror' \
    >"$out/ctest.txt" 2>&1 || status=1
rc=0
build-gpu/tests/gpu_trace_test >"$out/gpu_trace_test.txt" 2>&1 || rc=$?
[ "$rc" = 0 ] || [ "$rc" = 77 ] || status=1 # 77: skipped (no CUDA device)
build-gpu/bench/scheduler_bench $quick --csv "$out/scheduler_bench.csv" >"$out/scheduler_bench.txt" 2>&1 || status=1
build-gpu/bench/parallel_bench $quick --max-threads "$jobs" --csv "$out/parallel_bench.csv" \
    >"$out/parallel_bench.txt" 2>&1 || status=1
build-gpu/bench/ablation_bench $quick --csv "$out/ablation_bench.csv" >"$out/ablation_bench.txt" 2>&1 || status=1
# the CUDA megakernel and the stream engine on the CPU and GPU together, end to end, each with
# its --timeline picture (the README's wants one from a real cpu,gpu render)
# (.pfm without OpenImageIO, the lent machine's case; .exr with it)
ext=pfm
build-gpu/raystream --version | grep -q "OpenImageIO: *[0-9]" && ext=exr
for args in "--integrator megakernel --devices gpu" "--devices cpu,gpu" "--devices cpu"; do
    name=$(echo "$args" | tr -c 'a-z0-9\n' '_')
    build-gpu/raystream render builtin:rtiow-final --width 1280 --height 720 --spp 64 --stats \
        $args -o "$out/render-$name.$ext" --timeline "$out/timeline-$name.svg" \
        >>"$out/render.txt" 2>&1 || status=1
done
tail -5 "$out/ctest.txt"
grep -h "mismatch\|diff\|GPU device\|SKIP" "$out/gpu_trace_test.txt" || true
grep -h "efficiency" "$out/scheduler_bench.txt" || true
grep -h "Rendered" "$out/render.txt" || true
exit $status
