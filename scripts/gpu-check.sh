#!/bin/sh
# shellcheck disable=SC2086 # the argument lists in variables are meant to split
# scripts/gpu-check.sh — the GPU half of the checks, for a lent GPU machine (the `device` tool's
# `run`), which gets only this checkout: no ../shared, none of our Debian packages, no network.
# It passes only if a GPU ran: every way of not using one (no GPU listed, a driver raystream
# cannot use, a test skipped for want of a device, a render that fell back to the CPU) fails it.
#
#   sh scripts/gpu-check.sh --fetch     here, with network: the .debs the machine lacks (cmocka,
#                                       cJSON, Assimp and its libraries, pkgconf) into .gpu-debs/
#                                       and the living room's meshes and sky (no textures) from
#                                       ../shared/models into .gpu-models/, both git-ignored, for
#                                       the run to carry; Mitsuba 3's wheels for the bench into
#                                       .gpu-peers/ (carry it too)
#   sh scripts/gpu-check.sh [--bench [--quick]] [--no-suite]
#                                       there (carry .gpu-debs and .gpu-models): unpack the .debs
#                                       into a prefix (never into /) that pkgconf reads through
#                                       PKG_CONFIG_SYSROOT_DIR, configure the PFM-only build
#                                       (RS_DEPS=OPTIONAL: no OpenImageIO, the configuration CI
#                                       builds as pfm_only_build) with RS_CUDA=ON, build it all,
#                                       then:
#     1. nvidia-smi must list a GPU and `raystream --version` must see a usable CUDA device (else
#        its reason: no driver, a driver older than the CUDA runtime with both versions, ...);
#     2. gpu_trace_test must run (exit 77, "no CUDA device", fails here) and pass: the CUDA trace
#        kernel, the stream integrator with the host shading, the CUDA wavefront (paths whole on
#        the GPU, alone and beside the CPU) and the megakernel, each bit for bit against the CPU,
#        and core/hdmath.h's functions on the GPU against the host's, argument by argument;
#     3. the CLI on the GPU: builtin:gpucheck with --devices cpu, gpu (the wavefront), gpu
#        --shade-on host, cpu,gpu, and the GPU megakernel, each GPU render with --require-gpu
#        (a GPU it cannot use stops it with exit 1 and the reason; as second guards a "CPU
#        fallback" warning or no cuda:0 in its summary fails it too), every image the --devices
#        cpu image byte for byte (.pfm); then builtin:many-lights with the light BVH and
#        scripts/make-gltf-samples.py's spheres (every glTF material extension; Assimp carried)
#        on cpu, gpu and the GPU megakernel, byte for byte too; --timeline pictures;
#     4. with --bench: bench/gpu_bench.py (the Cornell box 512x512 and the living room's interior,
#        Mitsuba 3 cuda_ad_rgb beside raystream where .gpu-peers is carried;
#        samples/s and time to RMSE 0.01 for the CPU, the GPU wavefront, CPU + GPU, the GPU with
#        host shading and the megakernel; docs/gpu.md);
#     5. compute-sanitizer --tool memcheck over gpu_trace_test's gpucheck tests (the trace kernel,
#        the megakernel and the wavefront's kernels, the film passes' two, pinned DMA batches),
#        where compute-sanitizer exists and supports the device (a refusal, as under gVisor, is reported, not failed; a
#        memory error fails);
#     6. the whole test suite of this build (ctest), unless --no-suite.
# Logs go to gpu-results/ (or, on the lent machine, /tmp/gpu-check, and then into $OUT, which
# brings back at most 8 files: summary.txt, gpu_trace_test.txt, memcheck.txt, gpu_bench.txt and
# logs.tar.gz with everything, renders and timelines included; summary.txt is copied after every
# step, so a run cut short still says how far it came).  Sized for about 7 minutes on a 16-core
# H200 machine with --bench, build included: run it with timeout_s 540.
#
# "GPU or fail" is raystream's --require-gpu: without it `--devices gpu` on a machine where the
# GPU cannot be used warns and runs on the CPU fallback with exit 0; with it create_gpu in
# app/devices.c stops with exit 1 and one line naming the device and why, before the render.
# Step 3 uses it, and still reads the summary and the warning (cheap, and a guard against a
# raystream whose --require-gpu lets a fallback through).
set -eu
# what the lent machine lacks and the check carries, unpacked into a prefix there (never into /):
# cmocka for the tests, cJSON and Assimp for scene files and glTF, and pkgconf to find them.
# OpenImageIO is not carried: the build there is the PFM-only one.
GPU_DEBS="libcmocka0 libcmocka-dev libcjson1 libcjson-dev libassimp5 libassimp-dev libdraco7
libminizip1 pkgconf-bin libpkgconf3"
exclude() {
    if ! git check-ignore -q "$1" 2>/dev/null; then
        info="$(git rev-parse --git-dir)/info"
        mkdir -p "$info"
        echo "/$1/" >>"$info/exclude"
    fi
}
# Mitsuba 3 for the bench's peer rows (issue 38): the wheels of the lent machine's Python 3.12,
# only the cuda_ad_rgb and scalar_rgb variants and the plugins the bench's scenes use, without
# data/srgb.coeff (spectral upsampling, unused by the RGB variants), packed with xz -9 into
# .gpu-peers/mitsuba.tar.xz (about 20 MB), unpacked there onto PYTHONPATH.
MI_PLUGINS="path perspective independent ldsampler hdrfilm box obj twosided diffuse area constant
srgb uniform d65 regular merge"
fetch_mitsuba() {
    rm -rf .gpu-peers
    mkdir -p .gpu-peers/whl .gpu-peers/site
    if ! python3 -m pip download -q --no-deps --only-binary=:all: --python-version 3.12 \
        --platform manylinux_2_28_x86_64 mitsuba==3.9.1 drjit==1.5.0 -d .gpu-peers/whl; then
        echo "gpu-check: the Mitsuba wheels could not be fetched: the bench's Mitsuba rows are left out"
        rm -rf .gpu-peers
        return 0
    fi
    python3 -c 'import glob, sys, zipfile
for w in glob.glob(".gpu-peers/whl/*.whl"):
    zipfile.ZipFile(w).extractall(".gpu-peers/site")'
    (
        cd .gpu-peers/site/mitsuba
        for f in *_ad_*.so scalar_*.so; do
            case $f in cuda_ad_rgb.* | scalar_rgb.*) ;; *) rm -f "$f" ;; esac
        done
        for f in plugins/*.so; do
            keep=
            for p in $MI_PLUGINS; do [ "$f" = "plugins/$p.so" ] && keep=1; done
            [ -n "$keep" ] || rm -f "$f"
        done
        rm -rf data/srgb.coeff include cmake ./*.pyi
    )
    tar -C .gpu-peers -cf - site | xz -9 -T0 >.gpu-peers/mitsuba.tar.xz
    rm -rf .gpu-peers/whl .gpu-peers/site
    exclude .gpu-peers
    echo "gpu-check: .gpu-peers/mitsuba.tar.xz ($(du -h .gpu-peers/mitsuba.tar.xz | cut -f1)) ready: carry \".gpu-peers\" too"
}
if [ "${1:-}" = "--fetch" ]; then
    mkdir -p .gpu-debs
    # shellcheck disable=SC2086 # the list is meant to split
    (cd .gpu-debs && apt-get download $GPU_DEBS)
    exclude .gpu-debs
    models=${RS_MODELS:-../shared/models}
    if [ -d "$models/living-room" ]; then
        rm -rf .gpu-models
        mkdir -p .gpu-models/living-room
        cp -r "$models/living-room/meshes" "$models/living-room/sky.pfm" .gpu-models/living-room/
        # without its textures (PNG: the PFM-only build there reads none), albedo 0.5 instead
        python3 -c 'import json, sys
s = json.load(open(sys.argv[1]))
s.pop("textures", None)
for m in s["materials"].values():
    if "texture" in m:
        del m["texture"]
        m["albedo"] = [0.5, 0.5, 0.5]
json.dump(s, open(sys.argv[2], "w"))' "$models/living-room/living-room.raystream.json" \
            .gpu-models/living-room/living-room.raystream.json
        exclude .gpu-models
        echo "gpu-check: .gpu-debs and .gpu-models ready; run with carry [\".gpu-debs\", \".gpu-models\"]"
    else
        echo "gpu-check: $models/living-room is absent: the bench will render the Cornell box only"
        echo "gpu-check: .gpu-debs ready; run with carry [\".gpu-debs\"]"
    fi
    fetch_mitsuba
    exit 0
fi
bench=
quick=
suite=1
for a in "$@"; do
    case "$a" in
    --bench) bench=1 ;;
    --quick) quick=--quick ;;
    --no-suite) suite= ;;
    *) echo "gpu-check: unknown option $a (--fetch, --bench, --quick, --no-suite)" >&2; exit 2 ;;
    esac
done
out="gpu-results"
[ -n "${OUT:-}" ] && out=/tmp/gpu-check
prefix=/tmp/rs-prefix
rm -rf "$out"
mkdir -p "$out" "$prefix"
# what comes back from the lent machine: a few files and one archive of all the logs
# shellcheck disable=SC2317 # called by the trap and after each step
copy_back() {
    if [ -n "${OUT:-}" ]; then
        for f in summary.txt gpu_trace_test.txt memcheck.txt gpu_bench.txt; do
            if [ -f "$out/$f" ]; then cp "$out/$f" "$OUT/"; fi
        done
    fi
}
# shellcheck disable=SC2317
pack() {
    copy_back
    if [ -n "${OUT:-}" ]; then
        rm -f "$out"/*.pfm
        tar -czf "$OUT/logs.tar.gz" -C "$out" . 2>/dev/null || true
    fi
}
trap pack EXIT
for f in .gpu-debs/*.deb; do [ -f "$f" ] && dpkg -x "$f" "$prefix"; done
export LD_LIBRARY_PATH="$prefix/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
if [ -x "$prefix/usr/bin/pkgconf" ]; then
    # only the prefix's .pc files, their paths rewritten into the prefix
    export PKG_CONFIG="$prefix/usr/bin/pkgconf"
    export PKG_CONFIG_LIBDIR="$prefix/usr/lib/x86_64-linux-gnu/pkgconfig:$prefix/usr/share/pkgconfig"
    export PKG_CONFIG_SYSROOT_DIR="$prefix"
fi
[ -d /usr/local/cuda/bin ] && PATH="$PATH:/usr/local/cuda/bin"
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
gen=
command -v ninja >/dev/null 2>&1 && gen="-G Ninja"
# shellcheck disable=SC2086
cmake -S . -B build-gpu $gen -DCMAKE_BUILD_TYPE=Release -DRS_DEPS=OPTIONAL -DRS_CUDA=ON \
    -DCMOCKA_ROOT="$prefix" >"$out/configure.txt" 2>&1 || { tail -30 "$out/configure.txt"; exit 1; }
say "$(grep 'raystream: OpenImageIO' "$out/configure.txt" | sed 's/^-- //')"
cmake --build build-gpu -j"$jobs" >"$out/build.txt" 2>&1 || { grep -B2 -A8 'error' "$out/build.txt" | head -60; exit 1; }
say "configured and built in $(($(date +%s) - t0)) s"
copy_back

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
0) say "gpu_trace_test passed: $(grep -h '^GPU device: gpu' "$out/gpu_trace_test.txt" | head -1 | cut -c1-120)..." ;;
77) failed "gpu_trace_test skipped with a GPU present: $(grep -h SKIP "$out/gpu_trace_test.txt")" ;;
124) failed "gpu_trace_test ran over 300 s" ;;
*) failed "gpu_trace_test failed (exit $rc): $(grep -h 'FAILED  \]' "$out/gpu_trace_test.txt" | tr '\n' ' ')" ;;
esac
grep -h "differ in any bit\|megakernel cpu vs cuda" "$out/gpu_trace_test.txt" | grep -v " 0 of " | sed 's/^/gpu-check:   /' | head -20 | tee -a "$summary" || true
copy_back

# ---- 3. the CLI on the GPU, no fallback, every image the CPU's ----------------------------------
# render NAME ARGS...: one render with --stats; GPU renders with --require-gpu and a timeline
render() {
    name=$1
    shift
    log="$out/render-$name.txt"
    extra=
    gpu=0
    case "$*" in *"--devices gpu"* | *"--devices cpu,gpu"*) gpu=1 ;; esac
    [ $gpu = 1 ] && extra="--require-gpu --timeline $out/timeline-$name.svg"
    rc=0
    # shellcheck disable=SC2086
    build-gpu/raystream render "$@" --stats -o "$out/render-$name.pfm" $extra >"$log" 2>&1 || rc=$?
    on_gpu=1
    if [ $gpu = 1 ]; then grep -q '^Rendered.*cuda:0' "$log" || on_gpu=0; fi
    if [ $rc != 0 ] && grep -q -- '--require-gpu' "$log"; then
        failed "render $name: the GPU cannot be used: $(grep -h -- '--require-gpu' "$log" | head -1)"
    elif [ $rc != 0 ]; then
        failed "render $name: exit $rc (see $log)"
    elif grep -q 'CPU fallback' "$log"; then
        failed "render $name fell back to the CPU: $(grep -h 'CPU fallback' "$log")"
    elif [ $on_gpu = 0 ]; then
        failed "render $name: its summary names no cuda:0 device (see $log)"
    else
        say "render $name: $(grep -ho 'in [0-9.]* s: [0-9.]* [kMG]*samples/s' "$log" | head -1)"
    fi
}
same() { # same REF NAME...: each image NAME the image REF, byte for byte
    ref=$1
    shift
    for n in "$@"; do
        if cmp -s "$out/render-$ref.pfm" "$out/render-$n.pfm"; then
            say "  $n: the $ref image, byte for byte"
        else
            failed "$n: not the $ref image"
        fi
    done
}
G="builtin:gpucheck --width 384 --height 256 --spp 64"
render cpu $G --devices cpu
render gpu $G --devices gpu
render gpu-host $G --devices gpu --shade-on host
render cpu+gpu $G --devices cpu,gpu
render megakernel-gpu $G --integrator megakernel --devices gpu
same cpu gpu gpu-host cpu+gpu megakernel-gpu
M="builtin:many-lights --light-sampler bvh --width 192 --height 144 --spp 16"
render ml-cpu $M --devices cpu
render ml-gpu $M --devices gpu
render ml-megakernel $M --integrator megakernel --devices gpu
same ml-cpu ml-gpu ml-megakernel
if command -v python3 >/dev/null 2>&1 && python3 scripts/make-gltf-samples.py "$out/gltf" >/dev/null 2>&1; then
    X="$out/gltf/extensions.gltf --background 1 --width 192 --height 144 --spp 16"
    # shellcheck disable=SC2086
    render gltf-cpu $X --devices cpu
    # shellcheck disable=SC2086
    render gltf-gpu $X --devices gpu
    # shellcheck disable=SC2086
    render gltf-megakernel $X --integrator megakernel --devices gpu
    same gltf-cpu gltf-gpu gltf-megakernel
else
    say "python3 or the glTF samples missing: the glTF extension spheres are not rendered on the GPU"
fi
copy_back

# ---- 4. the GPU bench, on request --------------------------------------------------------------
if [ -n "$bench" ]; then
    models=.gpu-models
    [ -d "$models" ] || models=../shared/models
    rc=0
    # shellcheck disable=SC2086
    mi=
    if [ -f .gpu-peers/mitsuba.tar.xz ]; then # Mitsuba 3's wheels, carried (fetch_mitsuba)
        mkdir -p /tmp/gpu-check-mitsuba
        xz -dc .gpu-peers/mitsuba.tar.xz | tar -C /tmp/gpu-check-mitsuba -xf - && mi=/tmp/gpu-check-mitsuba/site
    fi
    # shellcheck disable=SC2086
    PYTHONPATH=${mi:+$mi:}${PYTHONPATH:-} RS_MODELS_DIR=$models \
        python3 bench/gpu_bench.py --raystream build-gpu/raystream --models "$models" \
        --out "$out/bench" $quick >"$out/gpu_bench.txt" 2>&1 || rc=$?
    if [ $rc = 0 ]; then say "gpu_bench: see gpu_bench.txt"; else failed "gpu_bench (exit $rc): $(tail -2 "$out/gpu_bench.txt")"; fi
    copy_back
fi

# ---- 5. memcheck ------------------------------------------------------------------------------
san=$(command -v compute-sanitizer || true)
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
    copy_back
fi

# ---- 6. the whole suite of this build ----------------------------------------------------------
if [ -n "$suite" ]; then
    rc=0
    timeout 400 ctest --test-dir build-gpu -j"$jobs" --output-on-failure -E '^gpu_trace_test$' \
        >"$out/ctest.txt" 2>&1 || rc=$?
    if [ $rc = 0 ]; then
        say "suite: $(grep -h 'tests passed' "$out/ctest.txt")"
    else
        failed "suite: $(grep -h 'tests passed\|tests failed' "$out/ctest.txt") $(grep -h '(Failed)\|(Timeout)' "$out/ctest.txt" | tr -s ' \n' ' ')"
    fi
fi

if [ $status = 0 ]; then say "PASS (in $(($(date +%s) - t0)) s after the start of the build)"; else say "FAILED"; fi
exit $status
