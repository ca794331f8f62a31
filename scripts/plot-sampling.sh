#!/bin/sh
# scripts/plot-sampling.sh DIR OUT.png — plots RMSE against spp (log-log) for every
# DIR/sampling_<scene>.dat that bench/sampling_bench --out DIR wrote, one panel per scene.
set -eu
dir="$1"
out="$2"
command -v gnuplot >/dev/null 2>&1 || { echo "plot-sampling.sh: gnuplot is not installed (scripts/install-deps.sh installs it)" >&2; exit 1; }
files=$(ls "$dir"/sampling_*.dat 2>/dev/null) || { echo "plot-sampling.sh: no $dir/sampling_*.dat" >&2; exit 1; }
n=$(echo "$files" | wc -l)
# pngcairo where gnuplot has cairo; gnuplot-nox has the plain (libgd) png terminal
if gnuplot -e "set terminal pngcairo" >/dev/null 2>&1; then term=pngcairo; else term=png; fi
{
    echo "set terminal $term size $((520 * n)),420"
    echo "set output '$out'"
    echo "set multiplot layout 1,$n"
    echo "set logscale xy; set grid; set key top right"
    echo "set xlabel 'samples per pixel'; set ylabel 'RMSE vs 4096-spp reference'"
    for f in $files; do
        scene=$(basename "$f" .dat | sed 's/^sampling_//')
        echo "set title 'builtin:$scene'"
        echo "plot '$f' u 1:2 w lp lw 2 t 'mis', '' u 1:3 w lp lw 2 t 'mixture', '' u 1:4 w lp lw 2 t 'bsdf', '' u 1:5 w lp lw 2 t 'uniform'"
    done
    echo "unset multiplot"
} > "$dir/plot-sampling.gp"
gnuplot "$dir/plot-sampling.gp"
echo "wrote $out"
