#!/bin/sh
# tests/install_test.sh BUILD SOURCE — `cmake --install BUILD --prefix TMP`, then the example
# program (examples/render.c) compiled as an outside program would be, against the installed tree
# only: with pkg-config (the shared library, and libraystream.a with --static) and with CMake
# (find_package(raystream)); each renders builtin:cornell without LD_LIBRARY_PATH (the .pc file
# carries an rpath), and the three images are the installed command's bit for bit.  The manual page and the header are where users look.
set -eu
build="$1"
src="$2"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
prefix="$tmp/prefix"
fail() {
    echo "install_test: $*" >&2
    exit 1
}
cmake --install "$build" --prefix "$prefix" >"$tmp/install.log" 2>&1 ||
    fail "cmake --install failed: $(tail -n 3 "$tmp/install.log")"
for f in bin/raystream include/raystream.h share/man/man1/raystream.1 share/doc/raystream/api.md; do
    [ -e "$prefix/$f" ] || fail "$f is not installed"
done
pcdir=$(dirname "$(find "$prefix" -name raystream.pc | head -n 1)")
[ -f "$pcdir/raystream.pc" ] || fail "raystream.pc is not installed"
libdir=$(dirname "$pcdir")
[ -f "$libdir/libraystream.a" ] && [ -e "$libdir/libraystream.so" ] ||
    fail "libraystream.a and libraystream.so are not both in $libdir"
grep -q '^\.SH RENDER' "$prefix/share/man/man1/raystream.1" &&
    grep -q -- '--spp' "$prefix/share/man/man1/raystream.1" ||
    fail "the manual page lacks the render options"

export PKG_CONFIG_PATH="$pcdir"
cc=${CC:-cc}
cp "$src/examples/render.c" "$tmp/example.c"
cd "$tmp"
# shellcheck disable=SC2046 # pkg-config's words are the flags
"$cc" example.c $(pkg-config --cflags --libs raystream) -o ex-shared ||
    fail "cc example.c \$(pkg-config --cflags --libs raystream) failed"
# shellcheck disable=SC2046
"$cc" example.c $(pkg-config --cflags raystream) "$libdir/libraystream.a" \
    $(pkg-config --static --libs raystream | sed 's/-lraystream//') -o ex-static ||
    fail "the static link (pkg-config --static) failed"
nm ex-static | grep -q ' T raystream_render$' || fail "ex-static does not hold the library"

mkdir proj
cat >proj/CMakeLists.txt <<'CM'
cmake_minimum_required(VERSION 3.16)
project(example C)
find_package(raystream 0.2 REQUIRED)
add_executable(ex-cmake ../example.c)
target_link_libraries(ex-cmake PRIVATE raystream::raystream)
CM
cmake -S proj -B proj/b -DCMAKE_PREFIX_PATH="$prefix" >cmake.log 2>&1 &&
    cmake --build proj/b >>cmake.log 2>&1 ||
    fail "find_package(raystream) project failed: $(tail -n 5 cmake.log)"

"$prefix/bin/raystream" render builtin:cornell --width 64 --spp 2 -q -o cli.pfm ||
    fail "the installed command failed"
# no LD_LIBRARY_PATH: raystream.pc's rpath and CMake's find the library where it was installed
for ex in ./ex-shared ./ex-static ./proj/b/ex-cmake; do
    "$ex" builtin:cornell out.pfm spp=2 width=64 >run.log 2>&1 ||
        fail "$ex failed: $(tail -n 2 run.log)"
    cmp -s out.pfm cli.pfm || fail "$ex's image differs from the installed command's"
done
echo "install_test: installed into a prefix; pkg-config (shared, static) and find_package" \
    "programs render the command's image"
