#!/bin/sh
# tests/install_peers_test.sh — which Python 3.13 scripts/install-peers.sh makes the Cycles venv
# with (issue 39, item 10): a python3.13 on PATH that does not run (pyenv's shim where 3.13 is not
# the active version: "pyenv: python3.13: command not found", exit 127) is passed over for
# ~/.pyenv/versions/3.13.*; one that runs is taken; with neither, "none".
set -eu
src=$(cd "$(dirname "$0")/.." && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$tmp/shims" "$tmp/good" "$tmp/home/.pyenv/versions/3.13.7/bin" "$tmp/empty"
printf '#!/bin/sh\necho "pyenv: python3.13: command not found" >&2\nexit 127\n' >"$tmp/shims/python3.13"
printf '#!/bin/sh\nexit 0\n' >"$tmp/good/python3.13"
cp "$tmp/good/python3.13" "$tmp/home/.pyenv/versions/3.13.7/bin/python3.13"
chmod +x "$tmp/shims/python3.13" "$tmp/good/python3.13" "$tmp/home/.pyenv/versions/3.13.7/bin/python3.13"
fail=0
expect() { # expect WANT HOME PATH
    got=$(HOME=$2 PATH=$3 sh "$src/scripts/install-peers.sh" --find-python313)
    if [ "$got" = "$1" ]; then echo "ok - $got"; else echo "FAIL - want $1, got $got"; fail=1; fi
}
expect "$tmp/home/.pyenv/versions/3.13.7/bin/python3.13" "$tmp/home" "$tmp/shims:/usr/bin:/bin"
expect "$tmp/good/python3.13" "$tmp/home" "$tmp/good:/usr/bin:/bin"
expect none "$tmp/empty" "$tmp/shims:/usr/bin:/bin"
exit $fail
