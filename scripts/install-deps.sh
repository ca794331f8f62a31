#!/bin/sh
# scripts/install-deps.sh — installs everything raystream needs to build and test, with apt-get
# (Debian bookworm).  Idempotent: prints nothing and changes nothing when all is installed.
# Run as root (or through sudo).  The CUDA toolkit is optional and not installed here: without
# nvcc the build simply leaves the CUDA device out.
# Also Intel Open Image Denoise 2.x for --denoise (core/denoise.h, docs/denoise.md): Debian has
# no package, so its shared libraries come from PyPI's pyoidn wheel (fetched with pip, checked
# against the sha256 below) into /opt/raystream/oidn/lib.  Optional: raystream builds and runs
# without it, so a failure there is one warning line, never a failed script.
#   --bench   also Intel Embree 3 (libembree-dev), which bench/traversal_bench races when CMake
#             finds it.  Benchmark only; the renderer and its tests never need it.
set -eu

# python3-pip: fetches the OIDN wheel (below); python3-dev, -venv, -numpy, -pytest: the Python
# module (python/) and its tests, including `pip install .` in a fresh venv
# clang, its libFuzzer/sanitizer runtimes (libclang-rt-14-dev: bookworm's clang does not pull it
# in) and its OpenMP (libomp-14-dev): scripts/fuzz.sh, which check-sanitizers.sh runs
PACKAGES="gcc g++ make cmake pkg-config libc6-dev
libopenimageio-dev libassimp-dev libcjson-dev libcmocka-dev gnuplot-nox
clang libclang-rt-14-dev libomp-14-dev
libopenmpi-dev openmpi-bin
python3-pip python3-dev python3-venv python3-numpy python3-pytest"

for arg in "$@"; do
    case "$arg" in
    --bench) PACKAGES="$PACKAGES libembree-dev" ;;
    *)
        echo "install-deps.sh: unknown option '$arg' (use --bench)" >&2
        exit 2
        ;;
    esac
done

# OIDN: pyoidn 2.5.1.0's manylinux wheel (a zip) holds libOpenImageDenoise.so.2 and beside it
# (found through its RPATH $ORIGIN/../lib, i.e. its own folder) the core library, the CPU and
# CUDA device libraries and TBB.  Only those are unpacked; OIDN skips the device libraries it
# does not find (SYCL, HIP), so they are left out.
OIDN_DIR=/opt/raystream/oidn
OIDN_WHEEL=pyoidn-2.5.1.0-py3-none-manylinux2014_x86_64.whl
OIDN_SHA256=32ad13368f8de1ef63001942ad05b02a00cd732d1206d97f352d3a3f606d823e
OIDN_LIBS="libOpenImageDenoise.so.2.5.1 libOpenImageDenoise_core.so.2.5.1
libOpenImageDenoise_device_cpu.so.2.5.1 libOpenImageDenoise_device_cuda.so.2.5.1 libtbb.so.12"

# The one line a failed OIDN install prints (never a failure of the script).
oidn_warn() {
    echo "install-deps.sh: warning: Open Image Denoise not installed ($1);" \
        "raystream works without it, but not --denoise" >&2
}

oidn_installed() {
    [ "$(cat "$OIDN_DIR/WHEEL-SHA256" 2>/dev/null)" = "$OIDN_SHA256" ] || return 1
    for f in $OIDN_LIBS; do
        [ -f "$OIDN_DIR/lib/$f" ] || return 1
    done
    [ -e "$OIDN_DIR/lib/libOpenImageDenoise.so.2" ]
}

# Fetches, checks and unpacks the wheel; returns 1 after printing why on one line.
oidn_install() {
    tmp=$(mktemp -d) || { oidn_warn "no temporary folder"; return 1; }
    why=
    if ! command -v python3 >/dev/null 2>&1; then
        why="python3 is missing"
    elif ! python3 -m pip download --no-deps --only-binary=:all: --disable-pip-version-check \
        -q -d "$tmp" "pyoidn==2.5.1.0" >"$tmp/pip.log" 2>&1; then
        why="pip download pyoidn==2.5.1.0 failed: $(tail -n 1 "$tmp/pip.log")"
    elif [ ! -f "$tmp/$OIDN_WHEEL" ]; then
        why="pip fetched no $OIDN_WHEEL"
    elif [ "$(sha256sum "$tmp/$OIDN_WHEEL" | cut -d' ' -f1)" != "$OIDN_SHA256" ]; then
        why="$OIDN_WHEEL: sha256 is not $OIDN_SHA256"
    elif ! python3 - "$tmp/$OIDN_WHEEL" "$tmp/lib" $OIDN_LIBS <<'PY' >"$tmp/unzip.log" 2>&1; then
import os, sys, zipfile
wheel, dest, names = sys.argv[1], sys.argv[2], sys.argv[3:]
os.makedirs(dest)
with zipfile.ZipFile(wheel) as z:
    for name in names:
        with z.open("pyoidn/oidn/lib/" + name) as src, open(os.path.join(dest, name), "wb") as dst:
            dst.write(src.read())
        os.chmod(os.path.join(dest, name), 0o755)
    with z.open("pyoidn-2.5.1.0.dist-info/licenses/LICENSE") as src:
        open(os.path.join(dest, "..", "LICENSE"), "wb").write(src.read())
PY
        why="cannot unpack $OIDN_WHEEL: $(tail -n 1 "$tmp/unzip.log")"
    else
        ln -s libOpenImageDenoise.so.2.5.1 "$tmp/lib/libOpenImageDenoise.so.2"
        echo "$OIDN_SHA256" >"$tmp/WHEEL-SHA256"
        # swap the whole folder in, so a half-copied install is never left behind
        if ! { $SUDO mkdir -p "$OIDN_DIR.new" && $SUDO cp -R "$tmp/lib" "$tmp/LICENSE" \
            "$tmp/WHEEL-SHA256" "$OIDN_DIR.new/" && $SUDO chmod -R a+rX "$OIDN_DIR.new" &&
            $SUDO rm -rf "$OIDN_DIR" && $SUDO mv "$OIDN_DIR.new" "$OIDN_DIR"; } 2>"$tmp/cp.log"; then
            why="cannot write $OIDN_DIR: $(tail -n 1 "$tmp/cp.log")"
            $SUDO rm -rf "$OIDN_DIR.new" 2>/dev/null || true
        fi
    fi
    rm -rf "$tmp"
    if [ -n "$why" ]; then
        oidn_warn "$why"
        return 1
    fi
    echo "install-deps.sh: installed Open Image Denoise 2.5.1 in $OIDN_DIR/lib" >&2
}

missing=""
for p in $PACKAGES; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
        missing="$missing $p"
    fi
done
oidn_missing=0
oidn_installed || oidn_missing=1
[ -z "$missing" ] && [ "$oidn_missing" = 0 ] && exit 0

if [ "$(id -u)" -ne 0 ]; then
    if command -v sudo >/dev/null 2>&1; then
        SUDO=sudo
    elif [ -n "$missing" ]; then
        echo "install-deps.sh: missing packages:$missing; run this script as root" >&2
        exit 1
    else
        oidn_warn "$OIDN_DIR needs root: run this script as root"
        exit 0
    fi
else
    SUDO=
fi

if [ -n "$missing" ]; then
    echo "install-deps.sh: installing$missing" >&2
    export DEBIAN_FRONTEND=noninteractive
    $SUDO apt-get update -qq
    # shellcheck disable=SC2086
    $SUDO apt-get install -y -qq --no-install-recommends $missing >/dev/null
fi
if [ "$oidn_missing" = 1 ]; then
    oidn_install || true
fi
