#!/bin/sh
# bench/recorded_rays_test.sh RAYSTREAM TRAVERSAL_BENCH: a render records its rays
# (RS_RECORD_RAYS, cpu/cpu_paths.c) and traversal_bench --rays races the walks on them.
# Fails where the file is not the documented size, where the bench cannot read it or its
# kernels disagree on the recorded rays, or where a file that is not a recording is accepted.
set -u
RS=$1
TB=$2
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
fail() { echo "recorded_rays_test: $*" >&2; exit 1; }

# a Cornell box at 32x32, 2 spp traces some 10,000 rays: the first 5,000 are kept
RS_RECORD_RAYS=$dir/box.rays RS_RECORD_RAYS_MAX=5000 \
    "$RS" render builtin:cornell --width 32 --height 32 --spp 2 -q -o "$dir/box.pfm" ||
    fail "the render failed"
[ -f "$dir/box.rays" ] || fail "no box.rays written"
size=$(wc -c <"$dir/box.rays")
[ "$size" -eq $((8 + 36 * 5000)) ] || fail "box.rays is $size bytes, not 8 + 36 x 5000"
[ "$(head -c 8 "$dir/box.rays")" = RSRAYS01 ] || fail "box.rays does not start with RSRAYS01"

"$TB" --quick --scene builtin:cornell --rays "$dir/box.rays" >"$dir/out.txt" 2>&1 ||
    { cat "$dir/out.txt"; fail "traversal_bench --rays failed"; }
for set in camera bounce shadow; do
    grep -q "^| $set (recorded) | closest" "$dir/out.txt" || {
        cat "$dir/out.txt"
        fail "no $set row"
    }
done

# a file that is not a recording: one line naming it, exit status non-zero
printf 'not rays' >"$dir/bad.rays"
if "$TB" --quick --scene builtin:cornell --rays "$dir/bad.rays" >"$dir/bad.txt" 2>&1; then
    fail "a file that is not a recording was accepted"
fi
grep -q "bad.rays: not a ray recording" "$dir/bad.txt" || { cat "$dir/bad.txt"; fail "no clear message"; }
echo "recorded_rays_test: passed"
