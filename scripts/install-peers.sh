#!/bin/sh
# scripts/install-peers.sh — the other renderers that bench/peers_bench races, in a Python virtual
# environment of their own (benchmark only; the renderer and its tests never need them).
#   sh scripts/install-peers.sh [DIR]     (default: build/peers-venv)
#   sh scripts/install-peers.sh --find-python313   the Python 3.13 it would use, or "none"
# Installs Debian's python3, python3-venv and libllvm19 (Mitsuba's llvm_ad_rgb variant JIT-compiles
# with it; peers_bench points DRJIT_LIBLLVM_PATH at it) where they are missing, then Mitsuba 3
# and LuxCoreRender (pyluxcore) from PyPI into DIR, and Blender's Cycles (bpy) into DIR-cycles:
# bpy 5.2 is built for Python 3.13 only, so that venv is made where a python3.13 is found (on
# PATH, or pyenv's under ~/.pyenv/versions/3.13.*), and skipped with a message otherwise.
# Idempotent: a venv that already imports its peers is left as it is.
set -eu

DIR=${1:-build/peers-venv}
MITSUBA=mitsuba==3.9.1
LUXCORE=pyluxcore==2.11.2
BPY=bpy==5.2.3

# PY313: a Python 3.13 that runs.  Each candidate is run before it is taken: pyenv's python3.13
# shim is on PATH even where 3.13 is not the active version, and then it only says "pyenv:
# python3.13: command not found".
find_python313() {
    PY313=
    for p in "$(command -v python3.13 2>/dev/null || true)" \
        "$HOME"/.pyenv/versions/3.13*/bin/python3.13; do
        if [ -n "$p" ] && [ -x "$p" ] &&
            "$p" -c 'import sys; assert sys.version_info[:2] == (3, 13)' >/dev/null 2>&1; then
            PY313=$p
            return 0
        fi
    done
}

cycles_venv() {
    CY="$DIR-cycles"
    if [ -x "$CY/bin/python" ] && "$CY/bin/python" -c "import bpy, numpy" 2>/dev/null; then
        return 0
    fi
    find_python313
    if [ -z "$PY313" ]; then
        echo "install-peers.sh: no python3.13 found: Cycles (bpy 5.2 needs Python 3.13) is skipped" >&2
        return 0
    fi
    echo "install-peers.sh: making $CY with $BPY ($PY313)" >&2
    [ -x "$CY/bin/python" ] || "$PY313" -m venv "$CY"
    "$CY/bin/pip" install -q "$BPY" numpy
    "$CY/bin/python" -c "import bpy; print('install-peers.sh: Blender', bpy.app.version_string, 'in $CY')" 2>/dev/null | tail -1
}

if [ "${1:-}" = "--find-python313" ]; then # which Python 3.13 the Cycles venv would be made with
    find_python313
    echo "${PY313:-none}"
    exit 0
fi

# one import per process: mitsuba and pyluxcore in one process abort (their TBBs clash)
if [ -x "$DIR/bin/python" ] && "$DIR/bin/python" -c "import mitsuba, numpy" 2>/dev/null &&
    "$DIR/bin/python" -c "import pyluxcore" >/dev/null 2>&1; then
    cycles_venv
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
cycles_venv
