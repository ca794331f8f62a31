#!/bin/sh
# scripts/gpu-check.sh — the GPU half of the checks, for a lent GPU machine (the `device` tool's
# `run`), which gets only this checkout: no ../shared, none of our Debian packages, no network.
# It passes only if a GPU ran: every way of not using one (no GPU listed, a driver raystream
# cannot use, a test skipped for want of a device, a render that fell back to the CPU) fails it.
#
#   sh scripts/gpu-check.sh --fetch     here, with network: put the cmocka .debs in .gpu-debs/
#                                       (git-ignored) for the run to carry
#   sh scripts/gpu-check.sh [--bench [--quick]]
#                                       there (carry .gpu-debs): unpack cmocka into a prefix (never
#                                       into /), configure with RS_DEPS=OPTIONAL (no OpenImageIO,
#                                       cJSON, Assimp: images .pfm only) and RS_CUDA=ON, build only
#                                       what the check runs, then:
#     1. nvidia-smi must list a GPU and `raystream --version` must see a usable CUDA device (else
#        its reason: no driver, a driver older than the CUDA runtime with both versions, ...);
#     2. gpu_trace_test must run (exit 77, "no CUDA device", fails here) and pass: the CUDA trace
#        kernel, the stream integrator and the megakernel bit for bit against the CPU;
#     3. compute-sanitizer --tool memcheck over gpu_trace_test's gpucheck tests (both kernels,
#        pinned DMA batches), where compute-sanitizer exists and supports the device (a refusal,
#        as under gVisor, is reported, not failed; a memory error fails);
#     4. the host tests that compare the GPU's fallback and devices (render_gpucheck_test,
#        scheduler_stream_test, render_determinism_test, scenes_mirror_test);
#     5. builtin:gpucheck rendered by the CLI with --devices cpu, gpu, cpu,gpu (stream) and the
#        GPU megakernel: each GPU render runs with --require-gpu, so a GPU it cannot use stops it
#        with exit 1 and the reason; as second guards a "runs on the CPU fallback" warning, or no
#        cuda:0 in its summary, fails it too; the three stream images must be one, byte for byte
#        (.pfm); --timeline pictures of the GPU renders;
#     with --bench, the GPU benchmarks as well (scheduler, parallel, ablation; --quick: shorter).
# Logs go to gpu-results/ (or, on the lent machine, /tmp/gpu-check, and then into $OUT, which
# brings back at most 8 files: summary.txt, gpu_trace_test.txt, memcheck.txt and logs.tar.gz
# with everything, renders and timelines included); a summary is printed.  Sized for about 5
# minutes on a 16-core H200 machine, build included: run it with timeout_s 540.
#
# "GPU or fail" is raystream's --require-gpu: without it `--devices gpu` on a machine where the
# GPU cannot be used warns and runs on the CPU fallback with exit 0; with it create_gpu in
# app/devices.c stops with exit 1 and one line naming the device and why, before the render.
# Step 5 uses it, and still reads the summary and the warning (cheap, and a guard against a
# raystream whose --require-gpu lets a fallback through).
set -eu
if [ "${1:-}" = "--fetch" ]; then
    mkdir -p .gpu-debs
    (cd .gpu-debs && apt-get download libcmocka0 libcmocka-dev)
    if ! git check-ignore -q .gpu-debs 2>/dev/null; then
        info="$(git rev-parse --git-dir)/info"
        mkdir -p "$info"
        echo '/.gpu-debs/' >>"$info/exclude"
    fi
    echo "gpu-check: .gpu-debs ready; run with carry [\".gpu-debs\"]"
    exit 0
fi
bench=
quick=
for a in "$@"; do
    case "$a" in
    --bench) bench=1 ;;
    --quick) quick=--quick ;;
    *) echo "gpu-check: unknown option $a (--fetch, --bench, --quick)" >&2; exit 2 ;;
    esac
done
if [ -n "${OUT:-}" ]; then out=/tmp/gpu-check; else out=gpu-results; fi
prefix=/tmp/rs-prefix
rm -rf "$out"
mkdir -p "$out" "$prefix"
# what comes back from the lent machine: a few files and one archive of all the logs
# shellcheck disable=SC2317 # called by the trap
pack() {
    if [ -n "${OUT:-}" ]; then
        for f in summary.txt gpu_trace_test.txt memcheck.txt; do
            if [ -f "$out/$f" ]; then cp "$out/$f" "$OUT/"; fi
        done
        tar -czf "$OUT/logs.tar.gz" -C "$out" . 2>/dev/null || true
    fi
}
trap pack EXIT
for f in .gpu-debs/*.deb; do [ -f "$f" ] && dpkg -x "$f" "$prefix"; done
export LD_LIBRARY_PATH="$prefix/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
jobs=$(nproc)
status=0
summary="$out/summary.txt"
: >"$summary"
say() { echo "gpu-check: $*" | tee -a "$summary"; }
failed() { say "FAIL: $*"; status=1; }

# ---- 1. a GPU, and raystream able to use it ------------------------------------------------------
{
    nvidia-smi || true
    nvidia-smi -L || true
    echo "cores: $jobs"
} >"$out/machine.txt" 2>&1
gpus=$(nvidia-smi -L 2>/dev/null | grep -c '^GPU ' || true)
driver=$(nvidia-smi --query-gpu=driver_version --format=csv,noheader 2>/dev/null | head -1 || true)
if [ "${gpus:-0}" -eq 0 ]; then
    say "FAIL: nvidia-smi lists no GPU: this check needs a GPU machine (see $out/machine.txt)"
    exit 1
fi
say "nvidia-smi lists $gpus GPU(s), driver ${driver:-?}"

t0=$(date +%s)
cmake -S . -B build-gpu -DCMAKE_BUILD_TYPE=Release -DRS_DEPS=OPTIONAL -DRS_CUDA=ON \
    -DCMOCKA_ROOT="$prefix" >"$out/configure.txt" 2>&1 || { tail -30 "$out/configure.txt"; exit 1; }
targets="raystream gpu_trace_test render_gpucheck_test scheduler_stream_test render_determinism_test scenes_mirror_test"
[ -n "$bench" ] && targets="$targets scheduler_bench parallel_bench ablation_bench"
# shellcheck disable=SC2086 # the list is meant to split
cmake --build build-gpu -j"$jobs" --target $targets >"$out/build.txt" 2>&1 ||
    { tail -50 "$out/build.txt"; exit 1; }
say "configured and built in $(($(date +%s) - t0)) s"

build-gpu/raystream --version >"$out/version.txt" 2>&1 || true
if ! grep -Eq 'CUDA: +yes \([0-9]+ device' "$out/version.txt"; then
    failed "nvidia-smi lists a GPU (driver ${driver:-?}) but raystream cannot use it: $(grep 'CUDA:' "$out/version.txt" | sed 's/^ *//')"
    exit 1
fi
say "$(grep 'CUDA:' "$out/version.txt" | sed 's/^ *//')"

# ---- 2. the GPU test: it must run, not skip -------------------------------------------------------
rc=0
timeout 300 build-gpu/tests/gpu_trace_test >"$out/gpu_trace_test.txt" 2>&1 || rc=$?
case $rc in
0) say "gpu_trace_test passed: $(grep -h '^GPU device: gpu' "$out/gpu_trace_test.txt" | head -1)" ;;
77) failed "gpu_trace_test skipped with a GPU present: $(grep -h SKIP "$out/gpu_trace_test.txt")" ;;
124) failed "gpu_trace_test ran over 300 s" ;;
*) failed "gpu_trace_test failed (exit $rc): see $out/gpu_trace_test.txt" ;;
esac

# ---- 3. memcheck ------------------------------------------------------------------------------
san=$(command -v compute-sanitizer || true)
[ -z "$san" ] && [ -x /usr/local/cuda/bin/compute-sanitizer ] && san=/usr/local/cuda/bin/compute-sanitizer
if [ -z "$san" ]; then
    say "compute-sanitizer not found: memcheck not run"
else
    rc=0
    timeout 240 "$san" --tool memcheck --error-exitcode 86 --print-limit 20 \
        build-gpu/tests/gpu_trace_test 'test_gpucheck*' >"$out/memcheck.txt" 2>&1 || rc=$?
    case $rc in
    0) say "memcheck: $(grep -h 'ERROR SUMMARY' "$out/memcheck.txt" | tail -1)" ;;
    86) failed "memcheck found errors: $(grep -h 'ERROR SUMMARY' "$out/memcheck.txt" | tail -1); see $out/memcheck.txt" ;;
    124) failed "memcheck ran over 240 s: see $out/memcheck.txt" ;;
    *)
        if grep -qi 'device not supported\|not supported on this\|unable to \(initialize\|attach\)' "$out/memcheck.txt"; then
            say "memcheck could not run on this machine (compute-sanitizer refused it: $(grep -hi 'not supported\|unable to' "$out/memcheck.txt" | head -1)); not counted"
        else
            failed "gpu_trace_test under memcheck failed (exit $rc): see $out/memcheck.txt"
        fi
        ;;
    esac
fi

# ---- 4. the host tests around the GPU device --------------------------------------------------
ctest --test-dir build-gpu --output-on-failure -j"$jobs" \
    -R 'render_gpucheck|scheduler_stream|render_determinism|scenes_mirror' >"$out/ctest.txt" 2>&1 ||
    failed "host tests: $(tail -3 "$out/ctest.txt" | tr '\n' ' ')"
say "host tests: $(grep -h 'tests passed' "$out/ctest.txt" || echo '?')"

# ---- 5. the CLI on the GPU, no fallback -------------------------------------------------------
ext=pfm
grep -q "OpenImageIO: *[0-9]" "$out/version.txt" && ext=exr
for args in "--devices cpu" "--devices gpu" "--devices cpu,gpu" "--integrator megakernel --devices gpu"; do
    name=$(echo "$args" | sed 's/--devices //; s/--integrator //; s/ /-/g; s/,/+/g')
    log="$out/render-$name.txt"
    extra=
    case "$args" in *gpu*) extra="--require-gpu --timeline $out/timeline-$name.svg" ;; esac
    rc=0
    # shellcheck disable=SC2086
    build-gpu/raystream render builtin:gpucheck --width 384 --height 256 --spp 64 --stats \
        $args -o "$out/render-$name.$ext" $extra >"$log" 2>&1 || rc=$?
    on_gpu=1
    case "$args" in *gpu*) grep -q '^Rendered.*cuda:0' "$log" || on_gpu=0 ;; esac
    if [ $rc != 0 ] && grep -q -- '--require-gpu' "$log"; then
        failed "render $args: the GPU cannot be used: $(grep -h -- '--require-gpu' "$log" | head -1)"
    elif [ $rc != 0 ]; then
        failed "render $args: exit $rc (see $log)"
    elif grep -q 'CPU fallback' "$log"; then
        failed "render $args fell back to the CPU: $(grep -h 'CPU fallback' "$log")"
    elif [ $on_gpu = 0 ]; then
        failed "render $args: its summary names no cuda:0 device (see $log)"
    else
        say "render $args: $(grep -ho 'in [0-9.]* s: [0-9.]* [kMG]*samples/s' "$log" | head -1)"
    fi
done
if [ "$ext" = pfm ]; then
    for b in gpu cpu+gpu; do
        if cmp -s "$out/render-cpu.pfm" "$out/render-$b.pfm"; then
            say "render --devices $b: the --devices cpu image, byte for byte"
        else
            failed "render --devices $b: not the --devices cpu image"
        fi
    done
fi

# ---- 5b. issue 29's code on the GPU: the light BVH and glTF's layered materials ---------------
# builtin:many-lights with --light-sampler bvh, and scripts/make-gltf-samples.py's spheres (every
# material extension; needs python3), on the CPU, the GPU and the GPU megakernel: the same image
scenes="builtin:many-lights --light-sampler bvh"
if command -v python3 >/dev/null 2>&1 &&
    python3 scripts/make-gltf-samples.py "$out/gltf" >/dev/null 2>&1; then
    scenes="$scenes|$out/gltf/extensions.gltf --background 1"
else
    say "python3 missing: the glTF extension spheres are not rendered on the GPU"
fi
k=0
echo "$scenes" | tr '|' '\n' >"$out/scenes29.txt"
while read -r spec; do
    k=$((k + 1))
    for args in "--devices cpu" "--devices gpu" "--integrator megakernel --devices gpu"; do
        name=s29-$k-$(echo "$args" | sed 's/--devices //; s/--integrator //; s/ /-/g')
        rc=0
        # shellcheck disable=SC2086
        build-gpu/raystream render $spec --width 192 --height 144 --spp 16 $args \
            -o "$out/$name.$ext" >"$out/$name.txt" 2>&1 || rc=$?
        [ $rc = 0 ] || failed "render $spec $args: exit $rc (see $out/$name.txt)"
    done
    if [ "$ext" = pfm ]; then
        for b in gpu megakernel-gpu; do
            if cmp -s "$out/s29-$k-cpu.pfm" "$out/s29-$k-$b.pfm"; then
                say "render $spec on $b: the CPU image, byte for byte"
            else
                failed "render $spec on $b: not the CPU image"
            fi
        done
    else
        say "render $spec: rendered on cpu, gpu and the GPU megakernel (EXR: not compared here)"
    fi
done <"$out/scenes29.txt"

# ---- benchmarks, on request -------------------------------------------------------------------
if [ -n "$bench" ]; then
    build-gpu/bench/scheduler_bench $quick --csv "$out/scheduler_bench.csv" >"$out/scheduler_bench.txt" 2>&1 || failed "scheduler_bench"
    build-gpu/bench/parallel_bench $quick --max-threads "$jobs" --csv "$out/parallel_bench.csv" \
        >"$out/parallel_bench.txt" 2>&1 || failed "parallel_bench"
    build-gpu/bench/ablation_bench $quick --csv "$out/ablation_bench.csv" >"$out/ablation_bench.txt" 2>&1 || failed "ablation_bench"
    grep -h "efficiency" "$out/scheduler_bench.txt" || true
fi

grep -h "differ in any bit\|megakernel cpu vs cuda\|GPU device:" "$out/gpu_trace_test.txt" | head -30 || true
if [ $status = 0 ]; then say "PASS (in $(($(date +%s) - t0)) s after the start of the build)"; else say "FAILED"; fi
exit $status
