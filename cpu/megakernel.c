/* cpu/megakernel.c — see megakernel.h. */
#include "cpu/megakernel.h"

#include <string.h>
#include <time.h>

#include "accel/bvh4.h"
#include "core/alloc.h"

typedef struct mk_ctx {
    rs_integrator it; /* threads = 1: every stage runs inline on the calling thread */
    const rs_geom *g;
    rs_bvh_view bvh;
    const rs_bvh4 *bvh4; /* NULL: the binary kernel */
    uint32_t spp, width, height;
    int by_columns;
    const rs_render_hooks *hooks;
    rs_film *film;
    _Atomic uint64_t rays_closest, rays_shadow, paths_done;
    _Atomic uint32_t max_bounce;
    _Atomic int failed;
} mk_ctx;

/* One thread's streams of one path. */
typedef struct scratch {
    rs_ray_soa ext[2], shadow;
    rs_hit_soa hits;
    rs_paths paths;
    uint8_t next_valid, shadow_valid, occluded;
} scratch;

static void scratch_free(scratch *w)
{
    rs_ray_soa_free(&w->ext[0]);
    rs_ray_soa_free(&w->ext[1]);
    rs_ray_soa_free(&w->shadow);
    rs_hit_soa_free(&w->hits);
    rs_paths_free(&w->paths);
}

static int scratch_init(scratch *w)
{
    memset(w, 0, sizeof *w);
    if (rs_ray_soa_init(&w->ext[0], 1) != RS_OK || rs_ray_soa_init(&w->ext[1], 1) != RS_OK ||
        rs_ray_soa_init(&w->shadow, 1) != RS_OK || rs_hit_soa_init(&w->hits, 1) != RS_OK ||
        rs_paths_init(&w->paths, 1) != RS_OK) {
        scratch_free(w);
        return 0;
    }
    return 1;
}

static void trace(const mk_ctx *c, const rs_trace_batch *b)
{
    if (c->bvh4)
        rs_bvh4_trace_one(c->bvh4, c->g, b, 0);
    else
        rs_trace_one(&c->bvh, c->g, b, 0);
}

/* Path g (sample g / npix of pixel g % npix) from the camera to its end; returns its radiance. */
static rs_vec3 trace_path(mk_ctx *c, scratch *w, uint64_t g, uint64_t *n_closest,
                          uint64_t *n_shadow, uint32_t *max_bounce)
{
    rs_trace_batch b;
    uint32_t bounce, cur = 0;
    rs_integrator_raygen(&c->it, g, 1, &w->paths, &w->ext[0]);
    for (bounce = 0;; ++bounce) {
        memset(&b, 0, sizeof b);
        b.kind = RS_TRACE_CLOSEST;
        b.count = 1;
        b.rays = w->ext[cur];
        b.hits = w->hits;
        trace(c, &b);
        ++*n_closest;
        if (bounce > *max_bounce)
            *max_bounce = bounce;
        rs_integrator_shade(&c->it, g, bounce, &w->ext[cur], &w->hits, 1, &w->paths,
                            &w->ext[cur ^ 1], &w->next_valid, &w->shadow, &w->shadow_valid);
        if (w->shadow_valid) {
            memset(&b, 0, sizeof b);
            b.kind = RS_TRACE_OCCLUDED;
            b.count = 1;
            b.rays = w->shadow;
            b.occluded = &w->occluded;
            trace(c, &b);
            ++*n_shadow;
            rs_integrator_resolve_shadows(&c->it, &w->shadow, &w->occluded, 1, &w->paths);
        }
        if (!w->next_valid)
            break;
        cur ^= 1;
    }
    return w->paths.radiance[0];
}

/* Rows (or columns) [lo, hi) of the image. */
static void render_lines(void *ctx, uint32_t lo, uint32_t hi)
{
    mk_ctx *c = (mk_ctx *)ctx;
    uint64_t npix = (uint64_t)c->width * c->height, n_closest = 0, n_shadow = 0, paths = 0;
    uint32_t line, k, s, max_bounce = 0, seen;
    scratch w;
    if (!scratch_init(&w)) {
        atomic_store(&c->failed, 1);
        return;
    }
    for (line = lo; line < hi; ++line) {
        uint32_t n = c->by_columns ? c->height : c->width;
        if (c->hooks && c->hooks->cancel && atomic_load(c->hooks->cancel))
            break;
        for (k = 0; k < n; ++k) {
            uint32_t x = c->by_columns ? line : k, y = c->by_columns ? k : line;
            uint32_t pixel = y * c->width + x;
            for (s = 0; s < c->spp; ++s) {
                rs_vec3 L = trace_path(c, &w, (uint64_t)s * npix + pixel, &n_closest, &n_shadow,
                                       &max_bounce);
                rs_film_add(c->film, pixel, L);
            }
        }
        paths += (uint64_t)n * c->spp;
        if (c->hooks && c->hooks->progress) {
            uint64_t done =
                atomic_fetch_add(&c->paths_done, (uint64_t)n * c->spp) + (uint64_t)n * c->spp;
#pragma omp critical(rs_megakernel_progress)
            c->hooks->progress(c->hooks->user, done, npix * c->spp);
        } else {
            atomic_fetch_add(&c->paths_done, (uint64_t)n * c->spp);
        }
    }
    (void)paths;
    atomic_fetch_add(&c->rays_closest, n_closest);
    atomic_fetch_add(&c->rays_shadow, n_shadow);
    seen = atomic_load(&c->max_bounce);
    while (max_bounce > seen && !atomic_compare_exchange_weak(&c->max_bounce, &seen, max_bounce)) {
    }
    scratch_free(&w);
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

rs_status rs_render_megakernel(const rs_scene *scene, const rs_geom *g, const rs_bvh *bvh,
                               const rs_render_settings *st, const rs_megakernel_opts *opts,
                               const rs_render_hooks *hooks, rs_film *film, rs_render_stats *stats)
{
    mk_ctx *c;
    rs_bvh4 *bvh4 = NULL;
    rs_status status = RS_OK;
    double t0 = now_s();
    uint64_t npix = (uint64_t)st->width * st->height;
    int threads = st->threads < 1 ? 1 : st->threads;

    memset(stats, 0, sizeof *stats);
    if (st->width == 0 || st->height == 0 || st->spp == 0 || st->max_depth == 0)
        return rs_error_set(RS_ERR_ARG, "width, height, spp and max depth must be >= 1");
    if (film->width != st->width || film->height != st->height)
        return rs_error_set(RS_ERR_ARG, "film is %ux%u but the render is %ux%u", film->width,
                            film->height, st->width, st->height);
    if (npix > UINT32_MAX)
        return rs_error_set(RS_ERR_ARG, "image too large: %ux%u", st->width, st->height);
    if ((!opts || opts->bvh_width != 2) && g->aabb_algo == RS_ISECT_AABB_SLAB &&
        (status = rs_bvh4_build(bvh, g, &bvh4)) != RS_OK)
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
    c->g = g;
    c->bvh = rs_bvh_view_of(bvh);
    c->bvh4 = bvh4;
    c->spp = st->spp;
    c->width = st->width;
    c->height = st->height;
    c->by_columns = opts && opts->strategy == RS_PAR_COLUMNS;
    c->hooks = hooks;
    c->film = film;
    stats->paths_total = npix * st->spp;

    rs_parallel_range(opts ? opts->strategy : RS_PAR_FOR_DYNAMIC, threads, 0,
                      c->by_columns ? st->width : st->height, 1, render_lines, c);

    stats->paths_done = atomic_load(&c->paths_done);
    stats->rays_closest = atomic_load(&c->rays_closest);
    stats->rays_shadow = atomic_load(&c->rays_shadow);
    stats->max_bounce = atomic_load(&c->max_bounce);
    if (atomic_load(&c->failed))
        status = rs_error_set(RS_ERR_NOMEM, "out of memory for the megakernel's paths");
    else if (hooks && hooks->cancel && atomic_load(hooks->cancel))
        status = rs_error_set(RS_ERR_CANCELLED, "render interrupted");
    rs_free(c);
    rs_bvh4_destroy(bvh4);
    stats->seconds = now_s() - t0;
    return status;
}
