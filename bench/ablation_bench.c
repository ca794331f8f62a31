/* bench/ablation_bench.c — the thesis's Table 6.12 (§6.7) on our engine: rtiow-final rendered
 * with the accelerations switched on one after another, each row's median time and its speedup
 * over the first row, measured in the same run on the same machine.
 *
 *   thesis rows  1 importance sampling (the mixture pdf) only: no BVH, one thread, the per-pixel
 *                  megakernel (the thesis's integrator)
 *                2 + BVH (median split, binary, the thesis's own box test: swap, Listing 5.3)
 *                3 + faster ray/box test (Kensler's, the thesis's pick, §6.3.3)
 *                4 + CPU threads (every core, parallel tasks, the thesis's best strategy)
 *                5 + GPU (the thesis's CUDA megakernel: gpu/cuda_megakernel.cu, same BVH and box
 *                  test as row 4; needs a CUDA device)
 *   our rows     6 + our branch-free slab test and the SAH BVH
 *                7 + the 4-wide SSE traversal
 *                8 the stream (wavefront) engine instead of the megakernel: the design that lets
 *                  a CPU and a GPU work on one image (on the CPU alone it pays for its streams)
 *                9 + the GPU beside the CPU (--devices cpu,gpu): needs a CUDA device
 * Every row renders the same scene, spp and seed; rows 2..8 must give the same image bit for bit
 * (row 1 too: brute force finds the same hits as the BVH).
 *
 *   ablation_bench [--quick] [--runs N] [--width N] [--spp N] [--csv FILE] */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_render.h"
#include "machine.h"
#include "scenes/builtin.h"

#define MAX_RUNS 15

typedef struct row {
    const char *label;
    int no_bvh, megakernel, all_threads, gpu;
    rs_bvh_method method;
    uint32_t aabb, bvh_width;
} row;

static const row rows[] = {
    {"1 importance sampling only (no BVH, 1 thread, megakernel)", 1, 1, 0, 0, RS_BVH_MEDIAN,
     RS_ISECT_AABB_SWAP, 2},
    {"2 + BVH (median split, thesis's swap box test)", 0, 1, 0, 0, RS_BVH_MEDIAN,
     RS_ISECT_AABB_SWAP, 2},
    {"3 + faster box test (Kensler)", 0, 1, 0, 0, RS_BVH_MEDIAN, RS_ISECT_AABB_KENSLER, 2},
    {"4 + CPU threads (parallel tasks)", 0, 1, 1, 0, RS_BVH_MEDIAN, RS_ISECT_AABB_KENSLER, 2},
    {"5 + GPU (thesis: CUDA megakernel)", 0, 1, 1, 1, RS_BVH_MEDIAN, RS_ISECT_AABB_KENSLER, 2},
    {"6 + branch-free slab test, SAH BVH", 0, 1, 1, 0, RS_BVH_SAH, RS_ISECT_AABB_SLAB, 2},
    {"7 + 4-wide SSE traversal", 0, 1, 1, 0, RS_BVH_SAH, RS_ISECT_AABB_SLAB, 4},
    /* width 0: the widest the CPU runs (8 with AVX2), leaves sized to its blocks, as the CLI */
    {"8 + 8-wide AVX2 traversal, leaves packed 8 to a block", 0, 1, 1, 0, RS_BVH_SAH,
     RS_ISECT_AABB_SLAB, 0},
    {"9 stream engine instead of megakernel", 0, 0, 1, 0, RS_BVH_SAH, RS_ISECT_AABB_SLAB, 0},
    {"10 + GPU beside the CPU (cpu,gpu)", 0, 0, 1, 1, RS_BVH_SAH, RS_ISECT_AABB_SLAB, 0},
};
#define N_ROWS ((int)(sizeof rows / sizeof rows[0]))

int main(int argc, char **argv)
{
    const char *csv = NULL, *why = "";
    int runs = 3, quick = 0, i, k, failed = 0, threads = rs_cpu_count(), have_gpu;
    uint32_t width = 320, spp = 8, height;
    rs_scene *scene;
    float *ref, *img;
    size_t nf;
    double first = 0.0, med[N_ROWS];
    FILE *csv_f = NULL;

    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--quick") == 0)
            quick = 1;
        else if (strcmp(argv[i], "--runs") == 0 && i + 1 < argc)
            runs = atoi(argv[++i]);
        else if (strcmp(argv[i], "--width") == 0 && i + 1 < argc)
            width = (uint32_t)atoi(argv[++i]);
        else if (strcmp(argv[i], "--spp") == 0 && i + 1 < argc)
            spp = (uint32_t)atoi(argv[++i]);
        else if (strcmp(argv[i], "--csv") == 0 && i + 1 < argc)
            csv = argv[++i];
        else {
            fprintf(stderr, "usage: ablation_bench [--quick] [--runs N] [--width N] [--spp N] "
                            "[--csv FILE]\n");
            return 2;
        }
    }
    if (quick) {
        runs = 1;
        width = 32;
        spp = 1;
    }
    if (runs < 1 || runs > MAX_RUNS || width < 16 || spp < 1) {
        fprintf(stderr, "ablation_bench: runs 1..%d, width >= 16, spp >= 1\n", MAX_RUNS);
        return 2;
    }
    height = width * 9 / 16;
    have_gpu = rs_gpu_count(&why) > 0;
    if (rs_builtin_create("rtiow-final", &scene) != RS_OK) {
        fprintf(stderr, "ablation_bench: %s\n", rs_error_message());
        return 1;
    }
    if (csv && !(csv_f = rs_bench_csv_open("ablation_bench", csv,
                                           "row,label,median_s,speedup,mrays_per_s\n")))
        return 1;
    nf = (size_t)width * height * 3;
    ref = (float *)malloc(nf * sizeof *ref);
    img = (float *)malloc(nf * sizeof *img);

    rs_bench_print_machine(stdout);
    printf("settings: builtin:rtiow-final (486 primitives), %ux%u, %u spp, mixture pdf (the "
           "thesis's importance sampling), max depth 50, seed 1; median of %d; 'all threads' = "
           "%d\n\n",
           width, height, spp, runs, threads);
    printf("| row | median s | speedup over row 1 | Mrays/s |\n| --- | ---: | ---: | ---: |\n");
    for (k = 0; k < N_ROWS && !failed; ++k) {
        const row *rw = &rows[k];
        rs_geom g = rs_scene_geom(scene);
        rs_bvh_build_opts bo;
        rs_bvh *bvh = NULL;
        br_config c;
        double secs[MAX_RUNS], mrays = 0.0;
        int r;
        med[k] = 0.0;
        if (rw->gpu && !have_gpu) {
            printf("| %s | no GPU | | |\n", rw->label);
            if (csv_f)
                fprintf(csv_f, "%d,%s,,,\n", k + 1, rw->label);
            continue;
        }
        g.aabb_algo = rw->aabb;
        memset(&bo, 0, sizeof bo);
        bo.builder.method = rw->method;
        bo.max_leaf = rw->no_bvh ? UINT32_MAX : 0;
        if (rw->bvh_width == 0) /* as the CLI builds it for the CPU's widest tree */
            bo.leaf_block = bo.max_leaf = rs_bvh_wide_leaf_size(0, &g);
        if (rs_bvh_build(&g, &bo, &bvh) != RS_OK) {
            fprintf(stderr, "ablation_bench: %s\n", rs_error_message());
            failed = 1;
            break;
        }
        memset(&c, 0, sizeof c);
        c.width = width;
        c.height = height;
        c.spp = spp;
        c.sampling = RS_SAMPLING_MIXTURE;
        c.threads = rw->all_threads ? threads : 1;
        c.megakernel = rw->megakernel;
        c.strategy = RS_PAR_TASKS;
        c.bvh_width = rw->bvh_width;
        c.with_gpu = rw->gpu;
        for (r = 0; r < runs; ++r) {
            rs_render_stats st;
            if (!br_render("ablation_bench", scene, &g, bvh, &c, r == 0 ? (k ? img : ref) : NULL,
                           &st)) {
                failed = 1;
                break;
            }
            secs[r] = st.seconds;
            mrays = 1e-6 * (double)(st.rays_closest + st.rays_shadow);
        }
        rs_bvh_destroy(bvh);
        if (failed)
            break;
        /* a GPU's hits may differ by float rounding; every CPU row must match row 1 exactly */
        if (k > 0 && !rw->gpu && memcmp(img, ref, nf * sizeof *img) != 0) {
            fprintf(stderr, "ablation_bench: row %d's image differs from row 1's\n", k + 1);
            failed = 1;
            break;
        }
        med[k] = rs_bench_median(secs, runs);
        if (k == 0)
            first = med[k];
        printf("| %s | %.3f | %.1fx | %.2f |\n", rw->label, med[k], first / med[k], mrays / med[k]);
        if (csv_f)
            fprintf(csv_f, "%d,%s,%.4f,%.4f,%.4f\n", k + 1, rw->label, med[k], first / med[k],
                    mrays / med[k]);
    }
    if (!failed) {
        int best = 0;
        for (k = 1; k < N_ROWS; ++k)
            if (!rows[k].gpu && med[k] > 0.0 && med[k] < med[best])
                best = k;
        printf("\nfull CPU stack (the fastest CPU row, %d): %.1fx over row 1 (the issue's target: "
               "100x)\n",
               best + 1, first / med[best]);
        printf("images: every CPU row bit-identical to row 1. thesis (Table 6.12): 1738.75 s "
               "-> 22.25 s with CPU threads (~78x), 3.39 s with the GPU (~513x)\n");
    }
    if (csv_f)
        fclose(csv_f);
    free(ref);
    free(img);
    rs_scene_destroy(scene);
    return failed ? 1 : 0;
}
