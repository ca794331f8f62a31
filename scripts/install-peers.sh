#!/bin/sh
# scripts/install-peers.sh — the other renderers that bench/peers_bench races, in a Python virtual
# environment of their own (benchmark only; the renderer and its tests never need them).
#   sh scripts/install-peers.sh [DIR]     (default: build/peers-venv)
# Installs Debian's python3, python3-venv and libllvm19 (Mitsuba's llvm_ad_rgb variant JIT-compiles
# with it; peers_bench points DRJIT_LIBLLVM_PATH at it) where they are missing, then Mitsuba 3
# and LuxCoreRender (pyluxcore) from PyPI into DIR.  Idempotent: a DIR that already imports both
# is left as it is.
set -eu

DIR=${1:-build/peers-venv}
MITSUBA=mitsuba==3.9.1
LUXCORE=pyluxcore==2.11.2

if [ -x "$DIR/bin/python" ] && "$DIR/bin/python" -c "import mitsuba, pyluxcore, numpy" 2>/dev/null; then
    exit 0
fi

missing=""
for p in python3 python3-venv libllvm19; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
        missing="$missing $p"
    fi
done
if [ -n "$missing" ]; then
    if [ "$(id -u)" -ne 0 ]; then
        if command -v sudo >/dev/null 2>&1; then SUDO=sudo; else
            echo "install-peers.sh: missing packages:$missing; run this script as root" >&2
            exit 1
        fi
    else
        SUDO=
    fi
    echo "install-peers.sh: installing$missing" >&2
    export DEBIAN_FRONTEND=noninteractive
    $SUDO apt-get update -qq
    # shellcheck disable=SC2086
    $SUDO apt-get install -y -qq --no-install-recommends $missing >/dev/null
fi

echo "install-peers.sh: making $DIR with $MITSUBA $LUXCORE" >&2
[ -x "$DIR/bin/python" ] || /usr/bin/python3 -m venv "$DIR"
# numpy: bench/peers/mitsuba_peer.py hands Mitsuba's image over as a numpy array (without it
# every Mitsuba row of peers_bench was dropped)
"$DIR/bin/pip" install -q "$MITSUBA" "$LUXCORE" numpy
"$DIR/bin/python" -c "import mitsuba; print('install-peers.sh: Mitsuba', mitsuba.__version__, 'in $DIR')"
"$DIR/bin/python" -c "import pyluxcore; print('install-peers.sh: LuxCoreRender', pyluxcore.Version())" | tail -1
