/* bench/denoise_bench.c — what denoising with Intel Open Image Denoise buys (core/denoise.h,
 * --denoise; docs/denoise.md): a low-spp render, denoised, against a converged reference.
 *
 * For each scene: a reference at --ref-spp (Sobol), the beauty at --spp (MIS and the CLI's
 * default pixel filter; the Sobol sampler, the CLI's default, then the independent one, noisier
 * at equal spp) with the albedo and normal
 * AOVs exactly as `--aov albedo,normal` makes them (shading/aov.c), then rs_denoise three ways:
 * beauty only; beauty, albedo and normal with cleanAux on (what --denoise does: our AOVs are
 * first-hit values averaged over up to 16 camera rays, so carry no path-tracing noise); and the
 * same with cleanAux off.  Each row, against the reference: the RMSE of values clamped to [0, 1]
 * (the display range: what a viewer sees), the ratio of the noisy image's to the row's (issue 28
 * asks for >= 4x), the spp a plain render would need for the same error (spp x ratio^2, error
 * falling as 1/sqrt(spp)); the RMSE of the linear values and its ratio; the relative RMSE (each
 * value's error over max(reference, 0.01)); and the median time of --runs denoises.  The linear
 * RMSE is printed but not the criterion: in a scene that sees its light, a few pixels on the
 * emitter's edge (15 against an interior below 1, and moved by +-1..2 by the denoiser) outweigh all
 * the noise elsewhere.  The reference's own error is printed beside it: it bounds how large a ratio
 * can be measured.
 *
 * Validates first: the reference and the renders are finite and not black, the AOVs finite with
 * normals of length <= 1, every denoised image finite, and repeated denoises bit-identical (OIDN
 * gave that on one device and version).  Then the cleanAux row must beat the noisy image by
 * --min-ratio (1.5: a sanity bound, that the denoiser works at all; exit 1 otherwise), and the
 * table says whether it meets issue 28's target of 4x (a finding, not a failure: run-all goes
 * on).  Without OIDN it prints why and exits 0 (sh scripts/install-deps.sh installs it).
 *
 *   denoise_bench [--quick] [--size N] [--spp N] [--ref-spp N] [--runs N] [--threads N]
 *                 [--gpu] [--scenes LIST] [--models DIR] [--min-ratio X] [--dump DIR]
 *
 * --dump DIR writes every image as DIR/SCENE-reference.exr, SCENE-SAMPLER-{noisy,albedo,normal,
 * beauty-only,aux-clean,aux-noisy}.exr.
 *
 * Full: 256x256, 16 spp against 4096, builtin:cornell and builtin:cornell-bunny-teapot (the
 * shared models; skipped with a message when ../shared/models is absent).  --quick: 64x64 against
 * 1024 spp. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_render.h"
#include "core/alloc.h"
#include "core/denoise.h"
#include "core/image_io.h"
#include "machine.h"
#include "shading/aov.h"
#include "shading/filter.h"

#define MAX_RUNS 9

typedef struct scene_ctx {
    rs_scene *scene;
    rs_geom g;
    rs_bvh *bvh;
} scene_ctx;

static void settings_for(uint32_t size, uint32_t spp, rs_sampler sampler, int threads,
                         rs_cores *cores, rs_render_settings *st)
{
    memset(st, 0, sizeof *st);
    st->width = st->height = size;
    st->spp = spp;
    st->max_depth = 50;
    st->seed = 1;
    st->sampling = RS_SAMPLING_MIS;
    st->sampler = sampler;
    rs_filter_default(&st->filter); /* the CLI's pixel filter */
    st->threads = threads;
    rs_cores_init(cores, threads);
    st->cores = cores;
}

/* The stream engine on one CPU device with `threads` threads; rgb receives the image; *seconds
 * the render's time; with `albedo` (then normal and direct too), the film's passes as the
 * devices wrote them (what --aov and --denoise read).  Returns 0 after printing why. */
static int render(const scene_ctx *s, uint32_t size, uint32_t spp, rs_sampler sampler, int threads,
                  float *rgb, double *seconds, float *albedo, float *normal, float *direct)
{
    rs_device *dev = NULL;
    rs_sched *sched = NULL;
    rs_film *film = NULL;
    rs_render_settings st;
    rs_render_stats stats;
    rs_cpu_device_opts co;
    rs_cores cores;
    int ok = 0;
    settings_for(size, spp, sampler, threads, &cores, &st);
    st.passes = albedo != NULL;
    memset(&co, 0, sizeof co);
    co.threads = threads;
    co.cores = &cores;
    if (rs_cpu_device_create_opts(&co, &dev) == RS_OK &&
        rs_device_upload(dev, &s->g, s->bvh) == RS_OK &&
        rs_sched_create(&dev, 1, NULL, &sched) == RS_OK &&
        rs_film_create(size, size, &film) == RS_OK &&
        (!albedo || rs_film_keep_passes(film) == RS_OK) &&
        rs_render(s->scene, sched, &st, NULL, film, &stats) == RS_OK) {
        rs_film_resolve(film, rgb);
        if (albedo)
            rs_film_resolve_passes(film, albedo, normal, direct, NULL);
        *seconds = stats.seconds;
        ok = 1;
    } else {
        fprintf(stderr, "denoise_bench: %s\n", rs_error_message());
    }
    rs_sched_destroy(sched);
    rs_device_destroy(dev);
    rs_film_destroy(film);
    return ok;
}

/* The direct emission refined on its edges, as app/render_outputs.c's --denoise does. */
static int refine(const scene_ctx *s, uint32_t size, uint32_t spp, rs_sampler sampler, int threads,
                  const float *direct, float *direct_fine, size_t *refined, double *seconds)
{
    double t0;
    rs_render_settings st;
    rs_render_consts it;
    rs_cores cores;
    rs_bvh_view v = rs_bvh_view_of(s->bvh);
    uint32_t *count = (uint32_t *)malloc((size_t)size * size * sizeof *count);
    size_t i;
    if (!count)
        return 0;
    for (i = 0; i < (size_t)size * size; ++i)
        count[i] = spp;
    settings_for(size, spp, sampler, threads, &cores, &st);
    if (rs_render_constants(s->scene, &st, &it) != RS_OK) {
        fprintf(stderr, "denoise_bench: %s\n", rs_error_message());
        free(count);
        return 0;
    }
    t0 = rs_now_s();
    *refined = rs_aov_refine(&it, &v, &s->g, count, threads, direct, direct_fine);
    *seconds = rs_now_s() - t0;
    free(count);
    return 1;
}

static int all_finite(const float *v, size_t n)
{
    size_t i;
    for (i = 0; i < n; ++i)
        if (!isfinite(v[i]))
            return 0;
    return 1;
}

static double mean(const float *v, size_t n)
{
    double s = 0;
    size_t i;
    for (i = 0; i < n; ++i)
        s += v[i];
    return s / (double)n;
}

typedef struct errs {
    double clamped, linear, rel;
} errs;

static double clamp01(double v) { return v < 0 ? 0 : v > 1 ? 1 : v; }

static errs errors(const float *img, const float *ref, size_t n)
{
    double c = 0, s = 0, r = 0;
    size_t i;
    errs e;
    for (i = 0; i < n; ++i) {
        double d = (double)img[i] - ref[i], m = ref[i] > 0.01f ? ref[i] : 0.01;
        double dc = clamp01(img[i]) - clamp01(ref[i]);
        c += dc * dc;
        s += d * d;
        r += (d / m) * (d / m);
    }
    e.clamped = sqrt(c / (double)n);
    e.linear = sqrt(s / (double)n);
    e.rel = sqrt(r / (double)n);
    return e;
}

typedef struct opts {
    uint32_t size, spp, ref_spp;
    int runs, threads, gpu;
    double min_ratio;
    const char *models;
    const char *dump; /* --dump DIR (see the top) */
} opts;

static void dump(const opts *o, const char *spec, const char *what, const float *rgb)
{
    char path[4096];
    if (!o->dump)
        return;
    snprintf(path, sizeof path, "%s/%s-%s.exr", o->dump, spec, what);
    if (rs_image_write(path, o->size, o->size, rgb) != RS_OK) {
        fprintf(stderr, "denoise_bench: %s\n", rs_error_message());
        rs_error_clear();
    }
}

/* The rows for one noisy image against `ref`: noisy, then the three denoises.  Returns 1, 0
 * after a failed check (printed), -1 after an error (printed). */
static int denoise_rows(const char *spec, const char *tag, const opts *o, const float *ref,
                        const float *noisy, const float *albedo, const float *normal,
                        const float *direct, const float *direct_fine, float *out, float *again)
{
    static const char *const labels[5] = {"beauty only", "+ albedo, normal, cleanAux on",
                                          "+ albedo, normal, cleanAux off",
                                          "cleanAux, direct kept out",
                                          "cleanAux, direct out, refined"};
    static const char *const files[5] = {"beauty-only", "aux-clean", "aux-noisy", "split",
                                         "split-fine"};
    size_t n = (size_t)o->size * o->size * 3;
    double clean_ratio = 0;
    char used[512] = "", what[64];
    errs e0 = errors(noisy, ref, n);
    int r, row;
    printf("  %-31s %9s %7s %9s %10s %7s %9s %9s\n", "image", "RMSE", "ratio", "~spp same",
           "RMSE lin", "ratio", "rel RMSE", "denoise s");
    printf("  %-31s %9.5f %6.2fx %9u %10.5f %6.2fx %9.4f %9s\n", "noisy", e0.clamped, 1.0, o->spp,
           e0.linear, 1.0, e0.rel, "-");
    for (row = 0; row < 5; ++row) {
        const float *a = row == 0 ? NULL : albedo, *nm = row == 0 ? NULL : normal;
        const float *d = row >= 3 ? direct : NULL, *df = row == 4 ? direct_fine : direct;
        double t[MAX_RUNS], ratio;
        errs e;
        for (r = 0; r < o->runs; ++r) {
            double t0 = rs_now_s();
            rs_error_clear();
            if (rs_denoise_split(noisy, d, df, a, nm, o->size, o->size, row != 2, o->gpu,
                                 r ? again : out, used, sizeof used) != RS_OK) {
                fprintf(stderr, "denoise_bench: %s\n", rs_error_message());
                return -1;
            }
            t[r] = rs_now_s() - t0;
            if (r && memcmp(again, out, n * sizeof(float)) != 0) {
                printf("FAIL: two denoises of the same image differ (%s)\n", used);
                return 0;
            }
        }
        if (!all_finite(out, n)) {
            printf("FAIL: the denoised image (%s) is not finite\n", labels[row]);
            return 0;
        }
        snprintf(what, sizeof what, "%s-%s", tag, files[row]);
        dump(o, spec, what, out);
        e = errors(out, ref, n);
        ratio = e0.clamped / e.clamped;
        printf("  %-31s %9.5f %6.2fx %9.0f %10.5f %6.2fx %9.4f %9.3f\n", labels[row], e.clamped,
               ratio, o->spp * ratio * ratio, e.linear, e0.linear / e.linear, e.rel,
               rs_bench_median(t, o->runs));
        if (row == 4)
            clean_ratio = ratio;
    }
    printf("  denoised on: %s\n", used);
    printf("  issue 28's target, RMSE in [0,1] >= 4x lower with the AOVs and cleanAux: %s "
           "(%.2fx)\n\n",
           clean_ratio >= 4.0 ? "met" : "not met", clean_ratio);
    if (clean_ratio < o->min_ratio) {
        printf("FAIL: denoised with clean AOVs only %.2fx below the noisy RMSE in [0,1] (want >= "
               "%.1fx)\n",
               clean_ratio, o->min_ratio);
        return 0;
    }
    return 1;
}

/* One scene's tables (the default Sobol sampler, then the independent one, noisier at the same
 * spp, against one Sobol reference); returns 1 (done or skipped), 0 on a failed check, -1 on an
 * error. */
static int bench_scene(const char *spec, const opts *o)
{
    static const rs_sampler samplers[2] = {RS_SAMPLER_SOBOL, RS_SAMPLER_INDEPENDENT};
    static const char *const sampler_names[2] = {"sobol", "independent"};
    scene_ctx s;
    size_t n = (size_t)o->size * o->size * 3, k;
    float *ref = NULL, *noisy = NULL, *albedo = NULL, *normal = NULL, *out = NULL, *again = NULL;
    float *direct = NULL, *direct_fine = NULL;
    double t_ref = 0, t_noisy = 0, t_aov = 0;
    size_t refined = 0;
    int rc = -1, loaded, j;
    char what[64];
    memset(&s, 0, sizeof s);
    loaded = br_load_scene("denoise_bench", spec, o->models, 0, &s.scene, &s.g, &s.bvh);
    if (loaded <= 0)
        return loaded == 0 ? 1 : -1;
    rs_bvh_attach(s.bvh, &s.g);
    ref = (float *)rs_alloc(n, sizeof(float));
    noisy = (float *)rs_alloc(n, sizeof(float));
    albedo = (float *)rs_alloc(n, sizeof(float));
    normal = (float *)rs_alloc(n, sizeof(float));
    out = (float *)rs_alloc(n, sizeof(float));
    again = (float *)rs_alloc(n, sizeof(float));
    direct = (float *)rs_alloc(n, sizeof(float));
    direct_fine = (float *)rs_alloc(n, sizeof(float));
    if (!ref || !noisy || !albedo || !normal || !out || !again || !direct || !direct_fine) {
        fprintf(stderr, "denoise_bench: out of memory\n");
        goto done;
    }
    {
        rs_filter f;
        char fd[128];
        rs_filter_default(&f);
        rs_filter_describe(&f, fd, sizeof fd);
        printf("scene builtin:%s, %ux%u, %u spp against a %u-spp reference (sobol, MIS, depth 50, "
               "pixel filter %s), %d thread%s\n",
               spec, o->size, o->size, o->spp, o->ref_spp, fd, o->threads,
               o->threads == 1 ? "" : "s");
    }
    if (!render(&s, o->size, o->ref_spp, RS_SAMPLER_SOBOL, o->threads, ref, &t_ref, NULL, NULL,
                NULL))
        goto done;
    rc = 0;
    if (!all_finite(ref, n) || mean(ref, n) <= 0) {
        printf("FAIL: the reference is black or not finite\n");
        goto done;
    }
    dump(o, spec, "reference", ref);
    printf("reference: %.2f s\n", t_ref);
    for (j = 0; j < 2; ++j) {
        double floor;
        rc = -1;
        if (!render(&s, o->size, o->spp, samplers[j], o->threads, noisy, &t_noisy, albedo, normal,
                    direct) ||
            !refine(&s, o->size, o->spp, samplers[j], o->threads, direct, direct_fine, &refined,
                    &t_aov))
            goto done;
        /* validate the inputs */
        rc = 0;
        if (!all_finite(noisy, n) || mean(noisy, n) <= 0) {
            printf("FAIL: the %u-spp render is black or not finite\n", o->spp);
            goto done;
        }
        if (!all_finite(albedo, n) || !all_finite(normal, n)) {
            printf("FAIL: the AOVs are not finite\n");
            goto done;
        }
        for (k = 0; k < n; k += 3)
            if (normal[k] * normal[k] + normal[k + 1] * normal[k + 1] +
                    normal[k + 2] * normal[k + 2] >
                1.001f) {
                printf("FAIL: a normal longer than 1 at pixel %zu\n", k / 3);
                goto done;
            }
        snprintf(what, sizeof what, "%s-noisy", sampler_names[j]);
        dump(o, spec, what, noisy);
        snprintf(what, sizeof what, "%s-albedo", sampler_names[j]);
        dump(o, spec, what, albedo);
        snprintf(what, sizeof what, "%s-normal", sampler_names[j]);
        dump(o, spec, what, normal);
        /* the reference's own error: a Sobol render's at ref_spp, from this one's at spp */
        floor = errors(noisy, ref, n).clamped * sqrt((double)o->spp / o->ref_spp);
        printf("%s sampler%s: %u spp in %.2f s", sampler_names[j], j == 0 ? " (the default)" : "",
               o->spp, t_noisy);
        if (j == 0)
            printf("; the reference's own RMSE is about %.5f (this RMSE x sqrt(%u/%u))", floor,
                   o->spp, o->ref_spp);
        printf("\n");
        printf("  AOVs and direct emission as passes of the render; its edges refined in %.2f s, "
               "%zu pixels (%.1f%%) with %u samples\n",
               t_aov, refined, 100.0 * (double)refined / ((double)o->size * o->size),
               RS_AOV_EMISSION_SPP);
        rc = denoise_rows(spec, sampler_names[j], o, ref, noisy, albedo, normal, direct,
                          direct_fine, out, again);
        if (rc <= 0)
            goto done;
    }
    rc = 1;
done:
    rs_free(ref);
    rs_free(noisy);
    rs_free(albedo);
    rs_free(normal);
    rs_free(out);
    rs_free(again);
    rs_free(direct);
    rs_free(direct_fine);
    rs_bvh_destroy(s.bvh);
    rs_scene_destroy(s.scene);
    return rc;
}

static int scene_cb(const char *name, const void *ctx)
{
    return bench_scene(name, (const opts *)ctx);
}

int main(int argc, char **argv)
{
    opts o;
    const char *scenes = "cornell,cornell-bunny-teapot";
    char why[512];
    int i;
    memset(&o, 0, sizeof o);
    o.size = 256;
    o.spp = 16;
    o.ref_spp = 4096;
    o.runs = 3;
    o.min_ratio = 1.5;
    o.threads = rs_cpu_count();
    for (i = 1; i < argc; ++i)
        if (strcmp(argv[i], "--quick") == 0) {
            /* the quick sizes first, so that explicit options override them */
            o.size = 64;
            o.ref_spp = 1024;
            o.runs = 2;
        }
    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--quick") == 0)
            continue;
        else if (strcmp(argv[i], "--gpu") == 0)
            o.gpu = 1;
        else if (i + 1 < argc && strcmp(argv[i], "--size") == 0)
            o.size = (uint32_t)atoi(argv[++i]);
        else if (i + 1 < argc && strcmp(argv[i], "--spp") == 0)
            o.spp = (uint32_t)atoi(argv[++i]);
        else if (i + 1 < argc && strcmp(argv[i], "--ref-spp") == 0)
            o.ref_spp = (uint32_t)atoi(argv[++i]);
        else if (i + 1 < argc && strcmp(argv[i], "--runs") == 0)
            o.runs = atoi(argv[++i]);
        else if (i + 1 < argc && strcmp(argv[i], "--threads") == 0)
            o.threads = atoi(argv[++i]);
        else if (i + 1 < argc && strcmp(argv[i], "--scenes") == 0)
            scenes = argv[++i];
        else if (i + 1 < argc && strcmp(argv[i], "--dump") == 0)
            o.dump = argv[++i];
        else if (i + 1 < argc && strcmp(argv[i], "--models") == 0)
            o.models = argv[++i];
        else if (i + 1 < argc && strcmp(argv[i], "--min-ratio") == 0) {
            o.min_ratio = atof(argv[++i]);
        } else {
            fprintf(stderr, "usage: denoise_bench [--quick] [--size N] [--spp N] [--ref-spp N] "
                            "[--runs N] [--threads N] [--gpu] [--scenes LIST] [--models DIR] "
                            "[--min-ratio X] [--dump DIR]\n");
            return 2;
        }
    }
    if (o.size < 8 || o.size > 8192 || o.spp < 1 || o.ref_spp <= o.spp || o.runs < 1 ||
        o.runs > MAX_RUNS || o.threads < 1) {
        fprintf(stderr, "denoise_bench: bad settings (size 8..8192, ref-spp > spp, runs 1..%d)\n",
                MAX_RUNS);
        return 2;
    }
    rs_bench_print_machine(stdout);
    if (!rs_denoise_available(why, sizeof why)) {
        printf("denoise_bench: skipped: %s\n", why);
        return 0;
    }
    printf("denoiser: Open Image Denoise, RT filter, hdr; %s device requested; %d run%s per row "
           "(median)\n\n",
           o.gpu ? "CUDA" : "CPU", o.runs, o.runs == 1 ? "" : "s");
    return br_each_name(scenes, scene_cb, &o) == 1 ? 0 : 1;
}
