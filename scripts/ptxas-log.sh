#!/bin/sh
# scripts/ptxas-log.sh — the CUDA compiler launcher of rs_gpu (top-level CMakeLists.txt): runs the
# compile command it is given and keeps what ptxas reports about each kernel (rs_gpu's .cu files
# are compiled with -Xptxas=-v: registers, stack frame, spill bytes, shared memory) in
# OBJECT.ptxas.txt beside the object named by -o, for scripts/cuda-occupancy.py.
#   sh scripts/ptxas-log.sh COMPILER ARGS...   (CMake calls it so; CUDA_COMPILER_LAUNCHER)
# Everything else the compiler prints (warnings, errors) still reaches stderr, and the exit status
# is the compiler's.  The log is written after the compile, so it is never older than its object.
# A command without -o is run as it is.

out=""
prev=""
for a in "$@"; do
    [ "$prev" = "-o" ] && out="$a"
    prev="$a"
done
[ -n "$out" ] || exec "$@"

tmp="$out.ptxas.tmp"
"$@" > "$tmp" 2>&1
rc=$?
# ptxas -v's lines: "ptxas info    : ..." and the indented "N bytes stack frame, ..." after each
# "Function properties for ..."; warnings ("ptxas warning") and the host compiler's lines pass on
info='^ptxas info|^[[:space:]]+[0-9]+ bytes stack frame'
if [ "$rc" -eq 0 ]; then
    grep -E "$info" "$tmp" > "$out.ptxas.txt"
    grep -vE "$info" "$tmp" >&2
else
    rm -f "$out.ptxas.txt"
    cat "$tmp" >&2
fi
rm -f "$tmp"
exit "$rc"
