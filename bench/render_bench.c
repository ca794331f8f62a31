/* bench/render_bench.c — end-to-end render throughput of the built-in scenes through the whole
 * stream pipeline (raygen, scheduler, CPU device, shading, film), at 1 and 2.. N threads.
 *
 * Validates first (the render must be finite and non-black, and every thread count must give
 * the same image bit for bit), then prints the machine, the settings, the median of the runs,
 * and the speedup over the 1-thread row measured in the same run.
 *
 *   render_bench [--quick] [--scene NAME] [--size N] [--spp N] [--runs N] [--csv FILE]
 *   --quick: a tiny render, one run (the test suite's smoke test). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "core/alloc.h"
#include "cpu/cpu_device.h"
#include "machine.h"
#include "scenes/builtin.h"
#include "scheduler/render.h"

typedef struct result {
    double seconds;
    uint64_t rays;
} result;

/* One render; returns 0 on failure.  `rgb` (optional) receives the image. */
static int render_once(const rs_scene *scene, const rs_bvh *bvh, uint32_t size, uint32_t spp,
                       int threads, float *rgb, result *res)
{
    rs_geom g = rs_scene_geom(scene);
    rs_device *dev = NULL;
    rs_sched *sched = NULL;
    rs_film *film = NULL;
    rs_render_settings st;
    rs_render_stats stats;
    int ok = 0;
    memset(&st, 0, sizeof st);
    st.width = st.height = size;
    st.spp = spp;
    st.max_depth = 50;
    st.seed = 1;
    st.sampling = RS_SAMPLING_MIS;
    st.threads = threads;
    if (rs_cpu_device_create(threads, "cpu", &dev) == RS_OK &&
        rs_device_upload(dev, &g, bvh) == RS_OK &&
        rs_sched_create(&dev, 1, NULL, &sched) == RS_OK &&
        rs_film_create(size, size, &film) == RS_OK &&
        rs_render(scene, sched, &st, NULL, film, &stats) == RS_OK) {
        res->seconds = stats.seconds;
        res->rays = stats.rays_closest + stats.rays_shadow;
        if (rgb)
            rs_film_resolve(film, rgb);
        ok = 1;
    } else {
        fprintf(stderr, "render_bench: %s\n", rs_error_message());
    }
    rs_sched_destroy(sched);
    rs_device_destroy(dev);
    rs_film_destroy(film);
    return ok;
}

int main(int argc, char **argv)
{
    const char *scene_name = "cornell", *csv = NULL;
    uint32_t size = 600, spp = 64;
    int runs = 5, quick = 0, i, t, max_threads = rs_cpu_count();
    rs_scene *scene;
    rs_bvh *bvh;
    rs_geom g;
    float *ref, *img;
    size_t nf;
    double base = 0.0, mean = 0.0;
    FILE *csv_f = NULL;

    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--quick") == 0) {
            quick = 1;
        } else if (strcmp(argv[i], "--scene") == 0 && i + 1 < argc) {
            scene_name = argv[++i];
        } else if (strcmp(argv[i], "--size") == 0 && i + 1 < argc) {
            size = (uint32_t)atoi(argv[++i]);
        } else if (strcmp(argv[i], "--spp") == 0 && i + 1 < argc) {
            spp = (uint32_t)atoi(argv[++i]);
        } else if (strcmp(argv[i], "--runs") == 0 && i + 1 < argc) {
            runs = atoi(argv[++i]);
        } else if (strcmp(argv[i], "--csv") == 0 && i + 1 < argc) {
            csv = argv[++i];
        } else {
            fprintf(stderr, "usage: render_bench [--quick] [--scene NAME] [--size N] [--spp N] "
                            "[--runs N] [--csv FILE]\n");
            return 2;
        }
    }
    if (quick) {
        size = 48;
        spp = 4;
        runs = 1;
    }
    if (size < 1 || spp < 1 || runs < 1) {
        fprintf(stderr, "render_bench: size, spp and runs must be >= 1\n");
        return 2;
    }
    if (rs_builtin_create(scene_name, &scene) != RS_OK) {
        fprintf(stderr, "render_bench: %s\n", rs_error_message());
        return 2;
    }
    g = rs_scene_geom(scene);
    if (rs_bvh_build(&g, NULL, &bvh) != RS_OK) {
        fprintf(stderr, "render_bench: %s\n", rs_error_message());
        return 1;
    }
    nf = (size_t)size * size * 3;
    ref = (float *)malloc(nf * sizeof *ref);
    img = (float *)malloc(nf * sizeof *img);

    /* validate: a finite, non-black image, identical for every thread count */
    {
        result r;
        if (!render_once(scene, bvh, size, spp, 1, ref, &r))
            return 1;
        for (i = 0; i < (int)nf; ++i) {
            if (!isfinite(ref[i])) {
                fprintf(stderr, "render_bench: non-finite pixel value\n");
                return 1;
            }
            mean += ref[i];
        }
        mean /= (double)nf;
        if (!(mean > 0.0)) {
            fprintf(stderr, "render_bench: black image\n");
            return 1;
        }
    }

    rs_bench_print_machine(stdout);
    printf("scene: builtin:%s, %ux%u, %u spp, mis sampling, max depth 50; median of %d run%s; "
           "image mean %.5f\n\n",
           scene_name, size, size, spp, runs, runs == 1 ? "" : "s", mean);
    printf("| threads | median s | samples/s | Mrays/s | speedup | efficiency |\n");
    printf("|--------:|---------:|----------:|--------:|--------:|-----------:|\n");
    if (csv) {
        csv_f = fopen(csv, "w");
        if (csv_f)
            fprintf(csv_f, "scene,size,spp,threads,median_s,samples_per_s,mrays_per_s,speedup\n");
    }
    for (t = 1; t <= max_threads;
         t = (t < max_threads && t * 2 > max_threads) ? max_threads : t * 2) {
        double secs[64];
        result r = {0, 0};
        int k, n = runs > 64 ? 64 : runs;
        double med, sps;
        for (k = 0; k < n; ++k) {
            if (!render_once(scene, bvh, size, spp, t, img, &r))
                return 1;
            if (memcmp(img, ref, nf * sizeof *img) != 0) {
                fprintf(stderr, "render_bench: %d threads changed the image\n", t);
                return 1;
            }
            secs[k] = r.seconds;
        }
        med = rs_bench_median(secs, n);
        if (t == 1)
            base = med;
        sps = (double)size * size * spp / med;
        printf("| %7d | %8.3f | %9.3g | %7.2f | %6.2fx | %10.2f |\n", t, med, sps,
               (double)r.rays / med / 1e6, base / med, base / med / t);
        if (csv_f)
            fprintf(csv_f, "%s,%u,%u,%d,%.6f,%.1f,%.3f,%.4f\n", scene_name, size, spp, t, med, sps,
                    (double)r.rays / med / 1e6, base / med);
        if (t == max_threads)
            break;
    }
    if (csv_f)
        fclose(csv_f);
    free(ref);
    free(img);
    rs_bvh_destroy(bvh);
    rs_scene_destroy(scene);
    return 0;
}
