/* bench/adaptive_bench.c — what adaptive sampling (--adaptive) buys: error against a reference
 * for the time spent, uniform against adaptive, on one scene.
 *
 * The reference is the scene at --ref-spp uniform samples (Sobol).  Each row renders the same
 * scene, seed and sampler: uniform at a few spp, adaptive at a few thresholds (up to --max-spp a
 * pixel, 16 first); for each the median wall time of --runs interleaved runs, the samples taken,
 * and the RMSE and the relative RMSE (each pixel's error over max(reference, 0.01)) against the
 * reference.  Efficiency is 1 / (error^2 x time), as a ratio to the first uniform row's: above 1,
 * the row reaches a given error sooner.  Validates first: the reference is finite and not black.
 *
 *   adaptive_bench [--quick] [--scene NAME] [--size N] [--ref-spp N] [--max-spp N] [--runs N]
 *                  [--threads N] */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "machine.h"
#include "render_util.h"

#define MAX_RUNS 9

typedef struct row {
    const char *label;
    uint32_t spp;
    double threshold; /* 0: uniform */
} row;

static void errors(const float *img, const float *ref, size_t n, double *rmse, double *rel)
{
    double s = 0, r = 0;
    size_t i;
    for (i = 0; i < n; ++i) {
        double d = (double)img[i] - ref[i], m = ref[i] > 0.01f ? ref[i] : 0.01;
        s += d * d;
        r += (d / m) * (d / m);
    }
    *rmse = sqrt(s / (double)n);
    *rel = sqrt(r / (double)n);
}

int main(int argc, char **argv)
{
    const char *scene = "cornell";
    uint32_t size = 64, ref_spp = 16384, max_spp = 1024;
    int runs = 3, threads = 1, quick = 0, i, r, k;
    row rows[] = {{"uniform", 64, 0},          {"uniform", 256, 0},
                  {"uniform", 1024, 0},        {"adaptive 0.05", 0, 0.05},
                  {"adaptive 0.02", 0, 0.02}, {"adaptive 0.01", 0, 0.01}};
    const int n_rows = (int)(sizeof rows / sizeof rows[0]);
    double t[8][MAX_RUNS], e_abs[8], e_rel[8], samples[8], base_abs = 0, base_rel = 0, base_t = 0;
    float *ref;
    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--quick") == 0)
            quick = 1;
        else if (i + 1 < argc && strcmp(argv[i], "--scene") == 0)
            scene = argv[++i];
        else if (i + 1 < argc && strcmp(argv[i], "--size") == 0)
            size = (uint32_t)atoi(argv[++i]);
        else if (i + 1 < argc && strcmp(argv[i], "--ref-spp") == 0)
            ref_spp = (uint32_t)atoi(argv[++i]);
        else if (i + 1 < argc && strcmp(argv[i], "--max-spp") == 0)
            max_spp = (uint32_t)atoi(argv[++i]);
        else if (i + 1 < argc && strcmp(argv[i], "--runs") == 0)
            runs = atoi(argv[++i]);
        else if (i + 1 < argc && strcmp(argv[i], "--threads") == 0)
            threads = atoi(argv[++i]);
        else {
            fprintf(stderr, "usage: adaptive_bench [--quick] [--scene NAME] [--size N] "
                            "[--ref-spp N] [--max-spp N] [--runs N] [--threads N]\n");
            return 2;
        }
    }
    if (quick) {
        size = 32, ref_spp = 256, max_spp = 64, runs = 1;
        rows[0].spp = 16, rows[1].spp = 32, rows[2].spp = 64;
    }
    if (size < 8 || ref_spp < 16 || max_spp < 16 || runs < 1 || runs > MAX_RUNS || threads < 1) {
        fprintf(stderr, "adaptive_bench: size >= 8, spp >= 16, runs 1..%d\n", MAX_RUNS);
        return 2;
    }
    {
        rt_args a = rt_defaults(scene, size, ref_spp);
        double sum = 0;
        size_t n = (size_t)size * size * 3, j;
        a.sampler = RS_SAMPLER_SOBOL;
        a.threads = threads;
        a.seed = 99; /* not the rows' seed: its noise is independent of theirs */
        ref = rt_render(&a, NULL);
        if (!ref)
            return 1;
        for (j = 0; j < n; ++j) {
            if (!isfinite(ref[j])) {
                fprintf(stderr, "adaptive_bench: the reference has a non-finite pixel\n");
                return 1;
            }
            sum += ref[j];
        }
        if (!(sum > 0)) {
            fprintf(stderr, "adaptive_bench: the reference is black\n");
            return 1;
        }
    }
    rs_bench_print_machine(stdout);
    printf("settings: %s %ux%u, mis, sobol, %d thread%s, stream engine; reference %u spp (another "
           "seed); adaptive up to %u spp, 16 first; medians of %d interleaved runs\n\n",
           scene, size, size, threads, threads == 1 ? "" : "s", ref_spp, max_spp, runs);
    for (r = 0; r < runs; ++r)
        for (k = 0; k < n_rows; ++k) {
            int m = (r & 1) ? n_rows - 1 - k : k;
            rt_args a = rt_defaults(scene, size, rows[m].threshold > 0 ? max_spp : rows[m].spp);
            rs_adaptive_stats as;
            double t0;
            float *img;
            a.sampler = RS_SAMPLER_SOBOL;
            a.threads = threads;
            a.adaptive.threshold = rows[m].threshold;
            a.adaptive.min_spp = 16;
            a.adaptive_out = &as;
            t0 = rs_now_s();
            img = rt_render(&a, NULL);
            t[m][r] = rs_now_s() - t0;
            if (!img)
                return 1;
            if (r == 0) {
                errors(img, ref, (size_t)size * size * 3, &e_abs[m], &e_rel[m]);
                samples[m] = rows[m].threshold > 0 ? (double)as.samples / ((double)size * size)
                                                   : (double)rows[m].spp;
            }
            free(img);
        }
    printf("%-15s %8s %9s %9s %9s %12s %12s\n", "", "spp avg", "time s", "RMSE", "rel RMSE",
           "eff (RMSE)", "eff (rel)");
    for (k = 0; k < n_rows; ++k) {
        double tm = rs_bench_median(t[k], runs);
        double ea = 1.0 / (e_abs[k] * e_abs[k] * tm), er = 1.0 / (e_rel[k] * e_rel[k] * tm);
        char label[32];
        if (k == 0)
            base_abs = ea, base_rel = er, base_t = tm;
        if (rows[k].threshold > 0)
            snprintf(label, sizeof label, "%s", rows[k].label);
        else
            snprintf(label, sizeof label, "uniform %u", rows[k].spp);
        printf("%-15s %8.1f %9.3f %9.5f %9.5f %12.2f %12.2f\n", label, samples[k], tm, e_abs[k],
               e_rel[k], ea / base_abs, er / base_rel);
    }
    (void)base_t;
    printf("\n(efficiency: 1 / (error^2 x time), relative to the first row)\n");
    free(ref);
    return 0;
}
