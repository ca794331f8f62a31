/* cpu/megakernel.c — see megakernel.h. */
#include "cpu/megakernel.h"

#include <stdio.h>
#include <string.h>
#include <time.h>

#include "accel/bvh4.h"
#include "core/alloc.h"
#include "gpu/gpu_device.h"

typedef struct mk_ctx {
    rs_integrator it; /* threads = 1: unused, the path code runs inline */
    rs_path_tracer tracer;
    uint32_t spp, width, height;
    int by_columns;
    const rs_render_hooks *hooks;
    rs_film *film;
    _Atomic uint64_t rays_closest, rays_shadow, paths_done;
    _Atomic uint32_t max_bounce;
} mk_ctx;

/* Adds one thread's (or one pass's) ray counts to the render's. */
static void add_counts(mk_ctx *c, const rs_path_counts *n)
{
    uint32_t seen = atomic_load(&c->max_bounce);
    atomic_fetch_add(&c->rays_closest, n->closest);
    atomic_fetch_add(&c->rays_shadow, n->shadow);
    while (n->max_bounce > seen &&
           !atomic_compare_exchange_weak(&c->max_bounce, &seen, n->max_bounce)) {
    }
}

/* Rows (or columns) [lo, hi) of the image. */
static void render_lines(void *ctx, uint32_t lo, uint32_t hi)
{
    mk_ctx *c = (mk_ctx *)ctx;
    uint64_t npix = (uint64_t)c->width * c->height;
    uint32_t line, k, s;
    rs_path_counts n = {0, 0, 0};
    for (line = lo; line < hi; ++line) {
        uint32_t len = c->by_columns ? c->height : c->width;
        if (c->hooks && c->hooks->cancel && atomic_load(c->hooks->cancel))
            break;
        for (k = 0; k < len; ++k) {
            uint32_t x = c->by_columns ? line : k, y = c->by_columns ? k : line;
            uint32_t pixel = y * c->width + x;
            /* per pixel: at high spp a row can take seconds, Ctrl-C must not */
            if (c->hooks && c->hooks->cancel && atomic_load(c->hooks->cancel)) {
                atomic_fetch_add(&c->paths_done, (uint64_t)k * c->spp);
                goto out;
            }
            for (s = 0; s < c->spp; ++s) {
                rs_vec3 L = rs_path_radiance(&c->it, &c->tracer, (uint64_t)s * npix + pixel, &n);
                rs_film_add(c->film, pixel, L);
            }
        }
        if (c->hooks && c->hooks->progress) {
            uint64_t done =
                atomic_fetch_add(&c->paths_done, (uint64_t)len * c->spp) + (uint64_t)len * c->spp;
#pragma omp critical(rs_megakernel_progress)
            c->hooks->progress(c->hooks->user, done, npix * c->spp);
        } else {
            atomic_fetch_add(&c->paths_done, (uint64_t)len * c->spp);
        }
    }
out:
    add_counts(c, &n);
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The GPU megakernel's pass on the host (its fallback): pixels [lo, hi) of one sample. */
typedef struct pass_ctx {
    mk_ctx *c;
    uint32_t sample;
    rs_vec3 *radiance;
} pass_ctx;

static void pass_pixels(void *ctx, uint32_t lo, uint32_t hi)
{
    pass_ctx *p = (pass_ctx *)ctx;
    rs_path_counts n = {0, 0, 0};
    uint64_t npix = p->c->it.npix;
    uint32_t pixel;
    for (pixel = lo; pixel < hi; ++pixel)
        p->radiance[pixel] =
            rs_path_radiance(&p->c->it, &p->c->tracer, (uint64_t)p->sample * npix + pixel, &n);
    add_counts(p->c, &n);
}

/* Pixels [lo, hi) of a pass onto the film (one sample each: any split keeps each pixel's
 * samples in sample order). */
static void pass_to_film(void *ctx, uint32_t lo, uint32_t hi)
{
    const pass_ctx *p = (const pass_ctx *)ctx;
    uint32_t i;
    for (i = lo; i < hi; ++i)
        rs_film_add(p->c->film, i, p->radiance[i]);
}

/* The GPU megakernel: one pass per sample over every pixel, on CUDA (gpu != NULL) or on host
 * threads; each pass's radiance added to the film pixel by pixel, so every pixel gets its
 * samples in sample order, as in render_lines. */
static rs_status render_passes(mk_ctx *c, rs_gpu_megakernel *gpu, rs_par_strategy strategy,
                               int threads)
{
    uint32_t npix = c->it.npix, s;
    rs_vec3 *radiance = (rs_vec3 *)rs_alloc(npix, sizeof *radiance);
    rs_status st = RS_OK;
    pass_ctx p;
    if (!radiance)
        return rs_error_set(RS_ERR_NOMEM, "out of memory for a %u-pixel pass", npix);
    p.c = c;
    p.radiance = radiance;
    for (s = 0; s < c->spp && st == RS_OK; ++s) {
        if (c->hooks && c->hooks->cancel && atomic_load(c->hooks->cancel))
            break;
        p.sample = s;
        if (gpu) {
            rs_path_counts n = {0, 0, 0};
            if ((st = rs_gpu_megakernel_pass(gpu, s, radiance, &n)) != RS_OK)
                break;
            add_counts(c, &n);
        } else {
            rs_parallel_range(strategy, threads, 0, npix, 1024, pass_pixels, &p);
        }
        rs_parallel_range(RS_PAR_FOR_DYNAMIC, threads, 0, npix, 16384, pass_to_film, &p);
        atomic_fetch_add(&c->paths_done, npix);
        if (c->hooks && c->hooks->progress)
            c->hooks->progress(c->hooks->user, atomic_load(&c->paths_done),
                               (uint64_t)npix * c->spp);
    }
    rs_free(radiance);
    return st;
}

const char *rs_megakernel_device_name(rs_megakernel_device d)
{
    switch (d) {
    case RS_MK_CPU: return "cpu";
    case RS_MK_CUDA: return "cuda";
    case RS_MK_GPU_FALLBACK: return "gpu-fallback";
    }
    return "?";
}

rs_status rs_render_megakernel(const rs_scene *scene, const rs_geom *g, const rs_bvh *bvh,
                               const rs_render_settings *st, rs_megakernel_opts *opts,
                               const rs_render_hooks *hooks, rs_film *film, rs_render_stats *stats)
{
    mk_ctx *c;
    rs_bvh4 *bvh4 = NULL;
    rs_gpu_megakernel *gpu = NULL;
    rs_status status = RS_OK;
    double t0 = now_s();
    uint64_t npix = (uint64_t)st->width * st->height;
    int threads = st->threads < 1 ? 1 : st->threads;
    rs_megakernel_device where = opts ? opts->device : RS_MK_CPU;
    rs_par_strategy strategy = opts ? opts->strategy : RS_PAR_FOR_DYNAMIC;

    memset(stats, 0, sizeof *stats);
    if (st->width == 0 || st->height == 0 || st->spp == 0 || st->max_depth == 0)
        return rs_error_set(RS_ERR_ARG, "width, height, spp and max depth must be >= 1");
    if (film->width != st->width || film->height != st->height)
        return rs_error_set(RS_ERR_ARG, "film is %ux%u but the render is %ux%u", film->width,
                            film->height, st->width, st->height);
    if (npix > UINT32_MAX)
        return rs_error_set(RS_ERR_ARG, "image too large: %ux%u", st->width, st->height);
    /* the CPU's own loop may take the 4-wide BVH; the GPU's (and its fallback) the binary one */
    if (where == RS_MK_CPU && (!opts || opts->bvh_width != 2) &&
        g->aabb_algo == RS_ISECT_AABB_SLAB && (status = rs_bvh4_build(bvh, g, &bvh4)) != RS_OK)
        return status;
    c = (mk_ctx *)rs_calloc(1, sizeof *c);
    if (!c) {
        rs_bvh4_destroy(bvh4);
        return rs_error_set(RS_ERR_NOMEM, "out of memory for the megakernel");
    }
    c->it.scene = scene;
    c->it.camera = rs_camera_make(scene->camera.from, scene->camera.at, scene->camera.up,
                                  scene->camera.vfov_deg, scene->camera.aperture,
                                  scene->camera.focus_dist, st->width, st->height);
    c->it.seed = st->seed;
    c->it.width = st->width;
    c->it.height = st->height;
    c->it.npix = (uint32_t)npix;
    c->it.max_depth = st->max_depth;
    c->it.rr_depth = st->rr_depth ? st->rr_depth : 3;
    c->it.sampling = st->sampling;
    c->it.threads = 1;
    c->tracer.geom = *g;
    c->tracer.bvh = rs_bvh_view_of(bvh);
    c->tracer.bvh4 = bvh4;
    c->spp = st->spp;
    c->width = st->width;
    c->height = st->height;
    c->by_columns = strategy == RS_PAR_COLUMNS;
    c->hooks = hooks;
    c->film = film;
    stats->paths_total = npix * st->spp;
    if (opts) {
        snprintf(opts->device_name, sizeof opts->device_name, "%s", "cpu");
        opts->bytes_to_device = 0;
    }

    if (where == RS_MK_CUDA) {
        status = rs_gpu_megakernel_create(opts->gpu_index, scene, g, bvh, &c->it, &gpu);
        if (status == RS_OK) {
            snprintf(opts->device_name, sizeof opts->device_name, "%s",
                     rs_gpu_megakernel_name(gpu));
            opts->bytes_to_device = rs_gpu_megakernel_bytes(gpu);
            status = render_passes(c, gpu, strategy, threads);
        }
    } else if (where == RS_MK_GPU_FALLBACK) {
        snprintf(opts->device_name, sizeof opts->device_name, "gpu-fallback:%d", opts->gpu_index);
        status = render_passes(c, NULL, strategy, threads);
    } else {
        rs_parallel_range(strategy, threads, 0, c->by_columns ? st->width : st->height, 1,
                          render_lines, c);
    }

    stats->paths_done = atomic_load(&c->paths_done);
    stats->rays_closest = atomic_load(&c->rays_closest);
    stats->rays_shadow = atomic_load(&c->rays_shadow);
    stats->max_bounce = atomic_load(&c->max_bounce);
    if (status == RS_OK && hooks && hooks->cancel && atomic_load(hooks->cancel))
        status = rs_error_set(RS_ERR_CANCELLED, "render interrupted");
    rs_gpu_megakernel_destroy(gpu);
    rs_free(c);
    rs_bvh4_destroy(bvh4);
    stats->seconds = now_s() - t0;
    return status;
}
