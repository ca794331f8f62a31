#!/bin/sh
# scripts/make-man.sh RAYSTREAM VERSION OUT.1 — the manual page, made from the command's own help
# (`raystream --help`, `raystream render --help`, `raystream export --help`), so the two never
# disagree.  Run by the build (cmake/install.cmake).
set -eu
bin="$1"
version="$2"
out="$3"
# groff: a leading . or ' starts a request, a backslash escapes: quote them
quote() { sed -e 's/\\/\\e/g' -e "s/^\\([.']\\)/\\\\\\&\\1/"; }
{
    echo ".TH RAYSTREAM 1 \"\" \"raystream $version\" \"User Commands\""
    echo ".SH NAME"
    echo "raystream \\- heterogeneous CPU+GPU streaming path tracer"
    echo ".SH SYNOPSIS"
    echo ".B raystream render"
    echo "[SCENE] [options]"
    echo ".br"
    echo ".B raystream"
    echo "scenes | export | --version | --help"
    echo ".SH DESCRIPTION"
    echo ".nf"
    "$bin" --help | quote
    echo ".fi"
    echo ".SH RENDER"
    echo ".nf"
    "$bin" render --help | quote
    echo ".fi"
    echo ".SH EXPORT"
    echo ".nf"
    "$bin" export --help | quote
    echo ".fi"
    echo ".SH SEE ALSO"
    echo "The C API: raystream.h and docs/api.md; the Python module: import raystream."
} >"$out.tmp"
mv "$out.tmp" "$out"
