/* scheduler/render.c — see render.h.  The loop reads as its list of stages. */
#include "scheduler/render.h"

#include <string.h>
#include <time.h>

#include "core/alloc.h"

/* Every buffer a wave needs, allocated once per render (nothing per chunk or per bounce). */
typedef struct wave_buffers {
    rs_ray_soa ext[2];     /* extension rays: current and next (ping-pong) */
    rs_ray_soa shadow_raw; /* shadow rays by input slot */
    rs_ray_soa shadow;     /* compacted shadow rays */
    rs_hit_soa hits;
    uint8_t *next_valid, *shadow_valid, *occluded;
    rs_paths paths;
} wave_buffers;

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void buffers_free(wave_buffers *b)
{
    rs_ray_soa_free(&b->ext[0]);
    rs_ray_soa_free(&b->ext[1]);
    rs_ray_soa_free(&b->shadow_raw);
    rs_ray_soa_free(&b->shadow);
    rs_hit_soa_free(&b->hits);
    rs_free(b->next_valid);
    rs_free(b->shadow_valid);
    rs_free(b->occluded);
    rs_paths_free(&b->paths);
}

static rs_status buffers_init(wave_buffers *b, uint32_t n)
{
    rs_status st;
    memset(b, 0, sizeof *b);
    if ((st = rs_ray_soa_init(&b->ext[0], n)) != RS_OK ||
        (st = rs_ray_soa_init(&b->ext[1], n)) != RS_OK ||
        (st = rs_ray_soa_init(&b->shadow_raw, n)) != RS_OK ||
        (st = rs_ray_soa_init(&b->shadow, n)) != RS_OK ||
        (st = rs_hit_soa_init(&b->hits, n)) != RS_OK || (st = rs_paths_init(&b->paths, n)) != RS_OK)
        goto fail;
    b->next_valid = (uint8_t *)rs_alloc_aligned(n, 1);
    b->shadow_valid = (uint8_t *)rs_alloc_aligned(n, 1);
    b->occluded = (uint8_t *)rs_alloc_aligned(n, 1);
    if (!b->next_valid || !b->shadow_valid || !b->occluded) {
        st = rs_error_set(RS_ERR_NOMEM, "out of memory for a wave of %u paths", n);
        goto fail;
    }
    return RS_OK;
fail:
    buffers_free(b);
    return st;
}

static int cancelled(const rs_render_hooks *h) { return h && h->cancel && atomic_load(h->cancel); }

static void report(const rs_render_hooks *h, uint64_t done, uint64_t total)
{
    if (h && h->progress)
        h->progress(h->user, done, total);
}

rs_status rs_render(const rs_scene *scene, rs_sched *sched, const rs_render_settings *st_in,
                    const rs_render_hooks *hooks, rs_film *film, rs_render_stats *stats)
{
    rs_render_settings st = *st_in;
    rs_integrator it;
    wave_buffers b;
    uint64_t npix, total, wave_start;
    double t_start = now_s(), t0;
    rs_status status = RS_OK;

    memset(stats, 0, sizeof *stats);
    if (st.width == 0 || st.height == 0 || st.spp == 0 || st.max_depth == 0)
        return rs_error_set(RS_ERR_ARG, "width, height, spp and max depth must be >= 1");
    if (film->width != st.width || film->height != st.height)
        return rs_error_set(RS_ERR_ARG, "film is %ux%u but the render is %ux%u", film->width,
                            film->height, st.width, st.height);
    npix = (uint64_t)st.width * st.height;
    /* npix and spp are both < 2^32, so npix * spp cannot overflow 64 bits */
    if (npix > UINT32_MAX)
        return rs_error_set(RS_ERR_ARG, "image too large: %ux%u at %u spp", st.width, st.height,
                            st.spp);
    total = npix * st.spp;
    if (st.wave_paths == 0)
        st.wave_paths = RS_RENDER_DEFAULT_WAVE;
    if ((uint64_t)st.wave_paths > total)
        st.wave_paths = (uint32_t)total;
    if (st.rr_depth == 0)
        st.rr_depth = 3;
    if (st.threads < 1)
        st.threads = 1;

    memset(&it, 0, sizeof it);
    it.scene = scene;
    it.camera = rs_camera_make(scene->camera.from, scene->camera.at, scene->camera.up,
                               scene->camera.vfov_deg, scene->camera.aperture,
                               scene->camera.focus_dist, st.width, st.height);
    it.seed = st.seed;
    it.width = st.width;
    it.height = st.height;
    it.npix = (uint32_t)npix;
    it.max_depth = st.max_depth;
    it.rr_depth = st.rr_depth;
    it.sampling = st.sampling;
    it.threads = st.threads;

    if ((status = buffers_init(&b, st.wave_paths)) != RS_OK)
        return status;
    stats->paths_total = total;

    for (wave_start = 0; wave_start < total && status == RS_OK; wave_start += st.wave_paths) {
        uint32_t count =
            (uint32_t)((total - wave_start < st.wave_paths) ? total - wave_start : st.wave_paths);
        uint32_t alive, bounce, cur = 0, i;

        t0 = now_s();
        rs_integrator_raygen(&it, wave_start, count, &b.paths, &b.ext[cur]);
        stats->shade_s += now_s() - t0;
        alive = count;

        for (bounce = 0; alive > 0; ++bounce) {
            rs_trace_batch batch;
            uint32_t n_shadow;
            if (cancelled(hooks)) {
                status = rs_error_set(RS_ERR_CANCELLED, "render interrupted");
                break;
            }
            /* trace closest hits of the extension rays */
            memset(&batch, 0, sizeof batch);
            batch.kind = RS_TRACE_CLOSEST;
            batch.count = alive;
            batch.rays = b.ext[cur];
            batch.hits = b.hits;
            t0 = now_s();
            if ((status = rs_sched_trace(sched, &batch)) != RS_OK)
                break;
            stats->trace_s += now_s() - t0;
            stats->rays_closest += alive;
            if (bounce > stats->max_bounce)
                stats->max_bounce = bounce;

            /* shade: emission, next-event shadow rays, the next extension rays */
            t0 = now_s();
            rs_integrator_shade(&it, wave_start, bounce, &b.ext[cur], &b.hits, alive, &b.paths,
                                &b.ext[cur ^ 1], b.next_valid, &b.shadow_raw, b.shadow_valid);
            n_shadow =
                rs_stream_compact(&b.shadow_raw, b.shadow_valid, alive, &b.shadow, st.threads);
            stats->shade_s += now_s() - t0;

            /* trace the shadow rays, then credit the unoccluded ones */
            if (n_shadow > 0) {
                memset(&batch, 0, sizeof batch);
                batch.kind = RS_TRACE_OCCLUDED;
                batch.count = n_shadow;
                batch.rays = b.shadow;
                batch.occluded = b.occluded;
                t0 = now_s();
                if ((status = rs_sched_trace(sched, &batch)) != RS_OK)
                    break;
                stats->trace_s += now_s() - t0;
                stats->rays_shadow += n_shadow;
                t0 = now_s();
                rs_integrator_resolve_shadows(&it, &b.shadow, b.occluded, n_shadow, &b.paths);
                stats->shade_s += now_s() - t0;
            }

            /* the surviving paths' next rays, in slot order, become the current stream; they
             * were written in place of the current rays' slots in the other buffer */
            t0 = now_s();
            alive =
                rs_stream_compact(&b.ext[cur ^ 1], b.next_valid, alive, &b.ext[cur], st.threads);
            stats->shade_s += now_s() - t0;
            report(hooks, stats->paths_done + (count - alive), total);
        }
        if (status != RS_OK)
            break;

        /* the wave is complete: add its samples to the film in path order */
        for (i = 0; i < count; ++i)
            rs_film_add(film, (uint32_t)((wave_start + i) % npix), b.paths.radiance[i]);
        stats->paths_done += count;
        stats->waves++;
        report(hooks, stats->paths_done, total);
    }

    buffers_free(&b);
    stats->seconds = now_s() - t_start;
    return status;
}
