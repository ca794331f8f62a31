/* bench/light_bench.c — what the light BVH (--light-sampler bvh, shading/light_bvh.h) buys over
 * picking lights by power: the time to a given RMSE on a scene of many lights and on the Cornell
 * box (issue 29: at least 3x sooner on many lights, no loss on the Cornell box beyond noise).
 *
 * For each scene: a reference at --ref-spp (the BVH sampler, seed 7: both samplers are
 * unbiased, so either converges to the same image), then for each spp of the ladder both
 * samplers interleaved (seed 1; --runs timings each, the median), each image's RMSE against the
 * reference over values clamped to [0, 1] (the display range: a visible emitter would otherwise
 * swamp it), less the reference's own noise (estimated from the BVH's RMSE at the ladder's top,
 * scaled by sqrt(spp / ref-spp)).  Monte Carlo error falls as 1/sqrt(time), so each sampler's
 * time to --target is its time at the ladder's top times (RMSE / target)^2; the ratio of the two
 * is the speed-up.  Before timing: every image finite and not black, and the two samplers'
 * images at the top of the ladder agree in mean within 2% (both estimate the same image).
 *
 *   light_bench [--quick] [--size N] [--ref-spp N] [--runs N] [--threads N] [--target R]
 *               [--scenes LIST]
 *
 * Full: builtin:many-lights at 200 px wide and builtin:cornell at 200 x 200, ladder 4 .. 64 spp,
 * reference 4096 spp.  --quick: 64 px, ladder 4 and 16, reference 256 (the suite's smoke run). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_render.h"
#include "core/alloc.h"
#include "machine.h"

#define MAX_RUNS  9
#define MAX_STEPS 8

typedef struct opts {
    uint32_t size, ref_spp, ladder[MAX_STEPS];
    int n_ladder, runs, threads;
    double target;
} opts;

static double clamp01(double v) { return v < 0 ? 0 : v > 1 ? 1 : v; }

static double rmse01(const float *a, const float *b, size_t n)
{
    double s = 0;
    size_t i;
    for (i = 0; i < n; ++i) {
        double d = clamp01(a[i]) - clamp01(b[i]);
        s += d * d;
    }
    return sqrt(s / (double)n);
}

static double mean_of(const float *a, size_t n)
{
    double s = 0;
    size_t i;
    for (i = 0; i < n; ++i)
        s += a[i];
    return s / (double)n;
}

static int finite_all(const float *a, size_t n)
{
    size_t i;
    for (i = 0; i < n; ++i)
        if (!isfinite(a[i]))
            return 0;
    return 1;
}

static int render_one(const rs_scene *s, const rs_geom *g, const rs_bvh *bvh, uint32_t w,
                      uint32_t h, uint32_t spp, uint32_t sampler, uint64_t seed, int threads,
                      float *rgb, double *secs)
{
    br_config c;
    rs_render_stats st;
    memset(&c, 0, sizeof c);
    c.width = w;
    c.height = h;
    c.spp = spp;
    c.sampling = RS_SAMPLING_MIS;
    c.sampler = RS_SAMPLER_SOBOL;
    c.light_sampler = sampler;
    c.seed = seed;
    c.threads = threads;
    if (!br_render("light_bench", s, g, bvh, &c, rgb, &st))
        return 0;
    *secs = st.seconds;
    return 1;
}

/* One scene's table; 1 done, 0 a failed check (printed), -1 an error (printed). */
static int bench_scene(const char *spec, const opts *o)
{
    static const char *const names[2] = {"power", "bvh"};
    rs_scene *s = NULL;
    rs_geom g;
    rs_bvh *bvh = NULL;
    uint32_t w, h, k;
    size_t n;
    float *ref = NULL, *img[2] = {NULL, NULL};
    double t_ref, err[2][MAX_STEPS], tmed[2][MAX_STEPS], ref_noise, to[2], mean[2];
    int rc = -1, loaded, j, r;
    loaded = br_load_scene("light_bench", spec, NULL, 0, &s, &g, &bvh);
    if (loaded <= 0)
        return loaded == 0 ? 1 : -1;
    w = o->size;
    h = s->width && s->height ? (uint32_t)((uint64_t)o->size * s->height / s->width) : o->size;
    if (h < 8)
        h = 8;
    n = (size_t)w * h * 3;
    ref = (float *)rs_alloc(n, sizeof(float));
    img[0] = (float *)rs_alloc(n, sizeof(float));
    img[1] = (float *)rs_alloc(n, sizeof(float));
    if (!ref || !img[0] || !img[1]) {
        fprintf(stderr, "light_bench: out of memory\n");
        goto done;
    }
    printf("scene builtin:%s, %ux%u, %u lights (%u in the light BVH, %u nodes), MIS, sobol, box "
           "filter, depth 50, %d thread%s\n",
           spec, w, h, s->n_lights,
           s->n_light_nodes ? (s->n_light_nodes + 1) / 2 : 0, s->n_light_nodes, o->threads,
           o->threads == 1 ? "" : "s");
    if (!render_one(s, &g, bvh, w, h, o->ref_spp, RS_LIGHT_SAMPLER_BVH, 7, o->threads, ref,
                    &t_ref))
        goto done;
    rc = 0;
    if (!finite_all(ref, n) || !(mean_of(ref, n) > 0)) {
        printf("FAIL: the reference is black or not finite\n");
        goto done;
    }
    printf("reference: %u spp (bvh, seed 7) in %.1f s\n", o->ref_spp, t_ref);
    for (k = 0; k < (uint32_t)o->n_ladder; ++k) {
        double t[2][MAX_RUNS];
        for (r = 0; r < o->runs; ++r)
            for (j = 0; j < 2; ++j) { /* interleaved */
                if (!render_one(s, &g, bvh, w, h, o->ladder[k], (uint32_t)j, 1, o->threads,
                                img[j], &t[j][r])) {
                    rc = -1;
                    goto done;
                }
            }
        for (j = 0; j < 2; ++j) {
            if (!finite_all(img[j], n)) {
                printf("FAIL: the %s image at %u spp is not finite\n", names[j], o->ladder[k]);
                goto done;
            }
            err[j][k] = rmse01(img[j], ref, n);
            tmed[j][k] = rs_bench_median(t[j], o->runs);
            mean[j] = mean_of(img[j], n);
        }
    }
    /* both estimate the same image */
    if (fabs(mean[0] - mean[1]) > 0.02 * fmax(mean[0], mean[1])) {
        printf("FAIL: the samplers' images differ in mean: power %.5f, bvh %.5f\n", mean[0],
               mean[1]);
        goto done;
    }
    k = (uint32_t)o->n_ladder - 1;
    ref_noise = err[1][k] * sqrt((double)o->ladder[k] / o->ref_spp);
    printf("the reference's own RMSE, about %.5f, is taken out of each RMSE below\n", ref_noise);
    printf("  %5s  %-6s %9s %10s %9s\n", "spp", "picks", "median s", "RMSE", "RMSE^2 s");
    for (k = 0; k < (uint32_t)o->n_ladder; ++k)
        for (j = 0; j < 2; ++j) {
            double e = sqrt(fmax(0.0, err[j][k] * err[j][k] - ref_noise * ref_noise));
            err[j][k] = e;
            printf("  %5u  %-6s %9.3f %10.5f %9.2e\n", o->ladder[k], names[j], tmed[j][k], e,
                   e * e * tmed[j][k]);
        }
    k = (uint32_t)o->n_ladder - 1;
    for (j = 0; j < 2; ++j)
        to[j] = tmed[j][k] * (err[j][k] / o->target) * (err[j][k] / o->target);
    printf("time to RMSE %.3g (from %u spp, error^2 x time held): power %.2f s, bvh %.2f s: the "
           "light BVH %.2fx sooner\n\n",
           o->target, o->ladder[k], to[0], to[1], to[1] > 0 ? to[0] / to[1] : 0.0);
    rc = 1;
done:
    rs_free(ref);
    rs_free(img[0]);
    rs_free(img[1]);
    rs_bvh_destroy(bvh);
    rs_scene_destroy(s);
    return rc;
}

static int scene_cb(const char *name, const void *ctx)
{
    return bench_scene(name, (const opts *)ctx);
}

int main(int argc, char **argv)
{
    opts o;
    const char *scenes = "many-lights,cornell";
    int i;
    static const uint32_t full[] = {4, 8, 16, 32, 64}, quick[] = {4, 16};
    memset(&o, 0, sizeof o);
    o.size = 200;
    o.ref_spp = 4096;
    o.runs = 3;
    o.threads = rs_cpu_count();
    o.target = 0.01;
    memcpy(o.ladder, full, sizeof full);
    o.n_ladder = 5;
    for (i = 1; i < argc; ++i)
        if (strcmp(argv[i], "--quick") == 0) {
            o.size = 64;
            o.ref_spp = 256;
            o.runs = 1;
            memcpy(o.ladder, quick, sizeof quick);
            o.n_ladder = 2;
        }
    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--quick") == 0)
            continue;
        else if (i + 1 < argc && strcmp(argv[i], "--size") == 0)
            o.size = (uint32_t)atoi(argv[++i]);
        else if (i + 1 < argc && strcmp(argv[i], "--ref-spp") == 0)
            o.ref_spp = (uint32_t)atoi(argv[++i]);
        else if (i + 1 < argc && strcmp(argv[i], "--runs") == 0)
            o.runs = atoi(argv[++i]);
        else if (i + 1 < argc && strcmp(argv[i], "--threads") == 0)
            o.threads = atoi(argv[++i]);
        else if (i + 1 < argc && strcmp(argv[i], "--target") == 0)
            o.target = atof(argv[++i]);
        else if (i + 1 < argc && strcmp(argv[i], "--scenes") == 0)
            scenes = argv[++i];
        else {
            fprintf(stderr, "usage: light_bench [--quick] [--size N] [--ref-spp N] [--runs N] "
                            "[--threads N] [--target R] [--scenes LIST]\n");
            return 2;
        }
    }
    if (o.size < 8 || o.size > 4096 || o.runs < 1 || o.runs > MAX_RUNS || o.threads < 1 ||
        o.ref_spp <= o.ladder[o.n_ladder - 1] || !(o.target > 0)) {
        fprintf(stderr, "light_bench: bad settings (size 8..4096, runs 1..%d, ref-spp above the "
                        "ladder's %u, target > 0)\n",
                MAX_RUNS, o.ladder[o.n_ladder - 1]);
        return 2;
    }
    rs_bench_print_machine(stdout);
    return br_each_name(scenes, scene_cb, &o) == 1 ? 0 : 1;
}
