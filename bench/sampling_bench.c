/* bench/sampling_bench.c — what importance sampling buys (the thesis's §6.2 claim, measured):
 * RMSE against a 4096-spp reference as a function of spp for each sampling strategy, the time
 * one sample per pixel costs with each, and the time each needs to reach a fixed RMSE.
 *
 * Validates first: the reference is finite and not black, and at the highest spp every
 * strategy's image mean agrees with the reference's within 3%.  Then prints, per scene, the
 * machine, the settings, the RMSE table, and time-to-RMSE with the ratio to the BSDF-only
 * baseline measured in the same run.  RMSE falls as spp^(-1/2): each strategy's constant
 * C = RMSE sqrt(spp) is the geometric mean over the levels from 4 spp up (robust to one
 * firefly-struck level), and the spp it needs for the target RMSE is (C / target)^2.
 * The reference's own noise (1/16 of the 256-spp variance) is included in the RMSE.
 *
 *   sampling_bench [--quick] [--ref-spp N] [--max-spp N] [--runs N] [--target RMSE] [--out DIR]
 *   --out DIR writes DIR/sampling_<scene>.dat (for scripts/plot-sampling.sh) and .csv. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/parallel.h"
#include "machine.h"
#include "render_util.h"

typedef struct scene_cfg {
    const char *name;
    uint32_t width, height;
} scene_cfg;

#define MAX_LEVELS   16
#define N_STRATEGIES 4

static double rmse(const float *a, const float *b, size_t n)
{
    double s = 0.0;
    size_t i;
    for (i = 0; i < n; ++i)
        s += ((double)a[i] - b[i]) * ((double)a[i] - b[i]);
    return sqrt(s / (double)n);
}

static double image_mean(const float *a, size_t n)
{
    double s = 0.0;
    size_t i;
    for (i = 0; i < n; ++i)
        s += a[i];
    return s / (double)n;
}

static float *render(const scene_cfg *sc, rs_sampling sampling, uint32_t spp, uint64_t seed,
                     double *seconds)
{
    rt_args a = rt_defaults(sc->name, sc->width, spp);
    rs_render_stats st;
    float *img;
    a.height = sc->height;
    a.sampling = sampling;
    a.seed = seed;
    a.threads = rs_cpu_count();
    img = rt_render(&a, &st);
    if (img && seconds)
        *seconds = st.seconds;
    return img;
}

static int bench_scene(const scene_cfg *sc, uint32_t ref_spp, uint32_t max_spp, int runs,
                       double target, const char *out_dir)
{
    size_t nf = (size_t)sc->width * sc->height * 3;
    double ref_s, ref_mean, err[N_STRATEGIES][MAX_LEVELS], per_spp[N_STRATEGIES], cst[N_STRATEGIES];
    uint32_t levels[MAX_LEVELS], n_levels = 0, spp;
    float *ref;
    int k, l;
    FILE *dat = NULL, *csv = NULL;

    ref = render(sc, RS_SAMPLING_MIS, ref_spp, 4242, &ref_s);
    if (!ref)
        return 1;
    ref_mean = image_mean(ref, nf);
    for (size_t i = 0; i < nf; ++i)
        if (!isfinite(ref[i])) {
            fprintf(stderr, "sampling_bench: non-finite reference pixel\n");
            return 1;
        }
    if (!(ref_mean > 0.0)) {
        fprintf(stderr, "sampling_bench: black reference\n");
        return 1;
    }
    for (spp = 1; spp <= max_spp && n_levels < MAX_LEVELS; spp *= 4)
        levels[n_levels++] = spp;

    for (k = 0; k < N_STRATEGIES; ++k) {
        double secs[32];
        int r, n = runs > 32 ? 32 : runs;
        for (l = 0; l < (int)n_levels; ++l) {
            float *img = render(sc, (rs_sampling)k, levels[l], 1 + (uint64_t)l, NULL);
            if (!img)
                return 1;
            err[k][l] = rmse(img, ref, nf);
            /* the means must agree within 3% plus 5 standard errors of the image mean (the
             * pixels' errors are independent, so that error is about rmse / sqrt(n)) */
            if (l + 1 == (int)n_levels &&
                fabs(image_mean(img, nf) - ref_mean) >
                    0.03 * ref_mean + 5.0 * err[k][l] / sqrt((double)nf)) {
                fprintf(stderr,
                        "sampling_bench: %s: %s mean %.5f differs from the reference's "
                        "%.5f\n",
                        sc->name, rs_sampling_name((rs_sampling)k), image_mean(img, nf), ref_mean);
                return 1;
            }
            free(img);
        }
        /* the cost of one sample per pixel: median over runs of a 4-spp render */
        for (r = 0; r < n; ++r) {
            float *img = render(sc, (rs_sampling)k, 4, 100 + (uint64_t)r, &secs[r]);
            if (!img)
                return 1;
            free(img);
        }
        per_spp[k] = rs_bench_median(secs, n) / 4.0;
    }
    for (k = 0; k < N_STRATEGIES; ++k) {
        double acc = 0.0;
        int m = 0;
        for (l = 0; l < (int)n_levels; ++l)
            if (levels[l] >= 4 || n_levels == 1) {
                acc += log(err[k][l] * sqrt((double)levels[l]));
                m++;
            }
        if (m == 0)
            acc = log(err[k][0]), m = 1;
        cst[k] = exp(acc / m);
    }

    printf("\n### builtin:%s, %ux%u; reference %u spp MIS (%.1f s, mean %.5f)\n\n", sc->name,
           sc->width, sc->height, ref_spp, ref_s, ref_mean);
    printf("| strategy |");
    for (l = 0; l < (int)n_levels; ++l)
        printf(" RMSE %u spp |", levels[l]);
    printf(" s per spp | spp for RMSE %.3g | time for it | vs bsdf |\n|---|", target);
    for (l = 0; l < (int)n_levels; ++l)
        printf("---:|");
    printf("---:|---:|---:|---:|\n");
    {
        double base_time = (cst[RS_SAMPLING_BSDF] / target) * (cst[RS_SAMPLING_BSDF] / target) *
                           per_spp[RS_SAMPLING_BSDF];
        for (k = 0; k < N_STRATEGIES; ++k) {
            double need = (cst[k] / target) * (cst[k] / target);
            double t = need * per_spp[k];
            printf("| %s |", rs_sampling_name((rs_sampling)k));
            for (l = 0; l < (int)n_levels; ++l)
                printf(" %.5f |", err[k][l]);
            printf(" %.4f | %.0f | %.2f s | %.2fx |\n", per_spp[k], need, t, base_time / t);
        }
    }
    if (out_dir) {
        char path[512];
        snprintf(path, sizeof path, "%s/sampling_%s.dat", out_dir, sc->name);
        dat = fopen(path, "w");
        snprintf(path, sizeof path, "%s/sampling_%s.csv", out_dir, sc->name);
        csv = fopen(path, "w");
        if (!dat || !csv) {
            fprintf(stderr, "sampling_bench: cannot write into %s\n", out_dir);
            return 1;
        }
        fprintf(dat, "# spp mis mixture bsdf uniform (RMSE vs %u-spp reference)\n", ref_spp);
        fprintf(csv, "scene,strategy,spp,rmse,seconds_per_spp\n");
        for (l = 0; l < (int)n_levels; ++l) {
            fprintf(dat, "%u", levels[l]);
            for (k = 0; k < N_STRATEGIES; ++k) {
                fprintf(dat, " %.6f", err[k][l]);
                fprintf(csv, "%s,%s,%u,%.6f,%.6f\n", sc->name, rs_sampling_name((rs_sampling)k),
                        levels[l], err[k][l], per_spp[k]);
            }
            fprintf(dat, "\n");
        }
        fclose(dat);
        fclose(csv);
    }
    free(ref);
    return 0;
}

int main(int argc, char **argv)
{
    scene_cfg scenes[2] = {{"cornell", 96, 96}, {"materials", 128, 72}};
    uint32_t ref_spp = 4096, max_spp = 256;
    double target = 0.05;
    int runs = 3, n_scenes = 2, i;
    const char *out_dir = NULL;
    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--quick") == 0) {
            scenes[0].width = scenes[0].height = 24;
            ref_spp = 64;
            max_spp = 4;
            runs = 1;
            n_scenes = 1;
        } else if (strcmp(argv[i], "--ref-spp") == 0 && i + 1 < argc) {
            ref_spp = (uint32_t)atoi(argv[++i]);
        } else if (strcmp(argv[i], "--max-spp") == 0 && i + 1 < argc) {
            max_spp = (uint32_t)atoi(argv[++i]);
        } else if (strcmp(argv[i], "--runs") == 0 && i + 1 < argc) {
            runs = atoi(argv[++i]);
        } else if (strcmp(argv[i], "--target") == 0 && i + 1 < argc) {
            target = atof(argv[++i]);
        } else if (strcmp(argv[i], "--out") == 0 && i + 1 < argc) {
            out_dir = argv[++i];
        } else {
            fprintf(stderr, "usage: sampling_bench [--quick] [--ref-spp N] [--max-spp N] "
                            "[--runs N] [--target RMSE] [--out DIR]\n");
            return 2;
        }
    }
    if (ref_spp < 1 || max_spp < 1 || runs < 1 || !(target > 0.0)) {
        fprintf(stderr, "sampling_bench: spp and runs must be >= 1\n");
        return 2;
    }
    rs_bench_print_machine(stdout);
    printf("settings: max depth 50, %d threads; RMSE over linear RGB; time per spp = median of %d "
           "4-spp renders / 4\n",
           rs_cpu_count(), runs);
    for (i = 0; i < n_scenes; ++i)
        if (bench_scene(&scenes[i], ref_spp, max_spp, runs, target, out_dir) != 0)
            return 1;
    return 0;
}
