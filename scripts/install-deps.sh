#!/bin/sh
# scripts/install-deps.sh — installs everything raystream needs to build and test, with apt-get
# (Debian bookworm).  Idempotent: prints nothing and changes nothing when all is installed.
# Run as root (or through sudo).  The CUDA toolkit is optional and not installed here: without
# nvcc the build simply leaves the CUDA device out.
#   --bench   also Intel Embree 3 (libembree-dev), which bench/traversal_bench races when CMake
#             finds it.  Benchmark only; the renderer and its tests never need it.
set -eu

# clang, its libFuzzer/sanitizer runtimes (libclang-rt-14-dev: bookworm's clang does not pull it
# in) and its OpenMP (libomp-14-dev): scripts/fuzz.sh, which check-sanitizers.sh runs
PACKAGES="gcc g++ make cmake pkg-config libc6-dev
libopenimageio-dev libassimp-dev libcjson-dev libcmocka-dev gnuplot-nox
clang libclang-rt-14-dev libomp-14-dev
libopenmpi-dev openmpi-bin"

for arg in "$@"; do
    case "$arg" in
    --bench) PACKAGES="$PACKAGES libembree-dev" ;;
    *)
        echo "install-deps.sh: unknown option '$arg' (use --bench)" >&2
        exit 2
        ;;
    esac
done

missing=""
for p in $PACKAGES; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
        missing="$missing $p"
    fi
done
[ -z "$missing" ] && exit 0

if [ "$(id -u)" -ne 0 ]; then
    if command -v sudo >/dev/null 2>&1; then
        SUDO=sudo
    else
        echo "install-deps.sh: missing packages:$missing; run this script as root" >&2
        exit 1
    fi
else
    SUDO=
fi

echo "install-deps.sh: installing$missing" >&2
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
# shellcheck disable=SC2086
$SUDO apt-get install -y -qq --no-install-recommends $missing >/dev/null
