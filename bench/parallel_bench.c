/* bench/parallel_bench.c — the thesis's OpenMP strategies (§5.8, §6.5, Tables 6.7–6.9) on our
 * engine: speedup S(p) = T(1) / T(p) (thesis Eq. 3.1) and efficiency E(p) = S(p) / p (Eq. 3.2)
 * of each strategy at 1, 2, 4, ... up to every core, for the thesis's per-pixel megakernel and
 * for the stream engine, on rtiow-final (the thesis's Fig. 6.9) and the teapot+bunny Cornell box
 * (Figs. 6.2/6.4; needs the shared models).  Medians of --runs renders.  Every render must give
 * the same image bit for bit, whatever the strategy, integrator or thread count.
 *
 *   parallel_bench [--quick] [--runs N] [--spp N] [--scale F] [--max-threads N] [--csv FILE]
 *   --scale multiplies the default image sizes (rtiow-final 400x225, Cornell 200x200). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_render.h"
#include "machine.h"
#include "scenes/builtin.h"

#define MAX_RUNS 15

int main(int argc, char **argv)
{
    static const char *const scenes[] = {"rtiow-final", "cornell-bunny-teapot"};
    static const uint32_t sizes[][2] = {{400, 225}, {200, 200}};
    const char *csv = NULL;
    int runs = 5, quick = 0, max_threads = rs_cpu_count(), i, s, failed = 0;
    uint32_t spp = 16;
    double scale = 1.0;
    FILE *csv_f = NULL;

    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--quick") == 0)
            quick = 1;
        else if (strcmp(argv[i], "--runs") == 0 && i + 1 < argc)
            runs = atoi(argv[++i]);
        else if (strcmp(argv[i], "--spp") == 0 && i + 1 < argc)
            spp = (uint32_t)atoi(argv[++i]);
        else if (strcmp(argv[i], "--scale") == 0 && i + 1 < argc)
            scale = atof(argv[++i]);
        else if (strcmp(argv[i], "--max-threads") == 0 && i + 1 < argc)
            max_threads = atoi(argv[++i]);
        else if (strcmp(argv[i], "--csv") == 0 && i + 1 < argc)
            csv = argv[++i];
        else {
            fprintf(stderr, "usage: parallel_bench [--quick] [--runs N] [--spp N] [--scale F] "
                            "[--max-threads N] [--csv FILE]\n");
            return 2;
        }
    }
    if (quick) {
        runs = 1;
        spp = 1;
        scale = 0.1;
    }
    if (runs < 1 || runs > MAX_RUNS || spp < 1 || scale <= 0.0 || max_threads < 1) {
        fprintf(stderr, "parallel_bench: runs 1..%d, spp >= 1, scale > 0, max-threads >= 1\n",
                MAX_RUNS);
        return 2;
    }
    if (csv && !(csv_f = rs_bench_csv_open("parallel_bench", csv,
                                           "scene,integrator,strategy,threads,median_s,speedup,"
                                           "efficiency\n")))
        return 1;

    rs_bench_print_machine(stdout);
    printf("settings: %u spp, MIS, max depth 50, SAH BVH, the CLI's CPU traversal (8-wide with AVX2); median of %d; "
           "speedup S = T(1)/T(p) (thesis Eq. 3.1), efficiency E = S/p (Eq. 3.2)\n\n",
           spp, runs);

    for (s = 0; s < 2 && !failed; ++s) {
        rs_scene *scene = NULL;
        rs_bvh *bvh = NULL;
        rs_geom g;
        uint32_t w = (uint32_t)(sizes[s][0] * scale + 0.5),
                 h = (uint32_t)(sizes[s][1] * scale + 0.5);
        size_t nf;
        float *ref, *img;
        int mk, st, p;
        if (quick && s == 1)
            break;
        if (w < 1)
            w = 1;
        if (h < 1)
            h = 1;
        int loaded = br_load_scene("parallel_bench", scenes[s], NULL, 0, &scene, &g, &bvh);
        if (loaded < 0)
            return 1;
        if (loaded == 0)
            continue;
        nf = (size_t)w * h * 3;
        ref = (float *)malloc(nf * sizeof *ref);
        img = (float *)malloc(nf * sizeof *img);
        printf("scene %s, %ux%u (%u primitives)\n", scenes[s], w, h, rs_geom_prim_count(&g));
        printf("  %-11s %-12s %8s %10s %9s %11s\n", "integrator", "strategy", "threads", "median s",
               "speedup", "efficiency");
        for (mk = 1; mk >= 0 && !failed; --mk)
            for (st = 0; st < 3 && !failed; ++st) {
                double t1 = 0.0;
                for (p = 1; !failed;
                     p = p * 2 > max_threads && p < max_threads ? max_threads : p * 2) {
                    br_config c;
                    double secs[MAX_RUNS], med, sp;
                    int r;
                    memset(&c, 0, sizeof c);
                    c.width = w;
                    c.height = h;
                    c.spp = spp;
                    c.sampling = RS_SAMPLING_MIS;
                    c.threads = p;
                    c.megakernel = mk;
                    c.strategy = (rs_par_strategy)st;
                    c.bvh_width = 0; /* the widest this CPU runs, as the CLI */
                    for (r = 0; r < runs; ++r) {
                        rs_render_stats rstats;
                        int first = mk == 1 && st == 0 && p == 1 && r == 0;
                        if (!br_render("parallel_bench", scene, &g, bvh, &c,
                                       r == 0 ? (first ? ref : img) : NULL, &rstats)) {
                            failed = 1;
                            break;
                        }
                        secs[r] = rstats.seconds;
                        if (r == 0 && !first && memcmp(img, ref, nf * sizeof *img) != 0) {
                            fprintf(stderr,
                                    "parallel_bench: %s %s %d threads: image differs from the "
                                    "first\n",
                                    mk ? "megakernel" : "stream", rs_par_strategy_name(c.strategy),
                                    p);
                            failed = 1;
                        }
                    }
                    if (failed)
                        break;
                    med = rs_bench_median(secs, runs);
                    if (p == 1)
                        t1 = med;
                    sp = t1 / med;
                    printf("  %-11s %-12s %8d %10.3f %8.2fx %11.2f\n", mk ? "megakernel" : "stream",
                           rs_par_strategy_name(c.strategy), p, med, sp, sp / p);
                    if (csv_f)
                        fprintf(csv_f, "%s,%s,%s,%d,%.4f,%.4f,%.4f\n", scenes[s],
                                mk ? "megakernel" : "stream", rs_par_strategy_name(c.strategy), p,
                                med, sp, sp / p);
                    if (p >= max_threads)
                        break;
                }
            }
        if (!failed)
            printf("  images: bit-identical across integrators, strategies and thread counts\n\n");
        free(ref);
        free(img);
        rs_bvh_destroy(bvh);
        rs_scene_destroy(scene);
    }
    printf("thesis (16 threads, its best strategy): 5.44x, efficiency 0.34; He et al.: 6.33x\n");
    if (csv_f)
        fclose(csv_f);
    return failed ? 1 : 0;
}
