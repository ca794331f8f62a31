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
    memset(b, 0, sizeof *b);
}

static rs_status buffers_init(wave_buffers *b, uint32_t n)
{
    rs_status st;
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

typedef enum slot_state {
    SLOT_IDLE,   /* no wave */
    SLOT_EXT,    /* its extension rays are with the scheduler */
    SLOT_SHADOW, /* its shadow rays are with the scheduler */
    SLOT_DONE    /* every path ended; waits to be added to the film in wave order */
} slot_state;

/* One wave in flight and its buffers. */
typedef struct slot {
    wave_buffers b;
    slot_state state;
    uint64_t wave;  /* index of the wave it holds */
    uint64_t start; /* its first path */
    uint32_t count, alive, bounce, cur;
    uint32_t n_shadow;
    rs_trace_batch batch; /* what `job` traces: must live as long as the job */
    rs_sched_job job;
} slot;

typedef struct render_ctx {
    rs_integrator it;
    rs_render_settings st;
    rs_sched *sched;
    const rs_render_hooks *hooks;
    rs_render_stats *stats;
    slot slots[RS_RENDER_MAX_WAVES];
    uint32_t n_slots;
    uint64_t ended; /* paths ended in waves not yet on the film */
} render_ctx;

/* The shading stages run with as many threads as the core budget grants. */
static double stage_begin(render_ctx *c)
{
    c->it.threads = rs_cores_acquire(c->st.cores, c->st.threads);
    return now_s();
}

static void stage_end(render_ctx *c, double t0)
{
    rs_cores_release(c->st.cores, c->it.threads);
    c->stats->shade_s += now_s() - t0;
}

static void report(const render_ctx *c)
{
    const rs_render_hooks *h = c->hooks;
    if (h && h->progress)
        h->progress(h->user, c->stats->paths_done + c->ended, c->stats->paths_total);
}

static void submit_extension(render_ctx *c, slot *sl)
{
    memset(&sl->batch, 0, sizeof sl->batch);
    sl->batch.kind = RS_TRACE_CLOSEST;
    sl->batch.count = sl->alive;
    sl->batch.rays = sl->b.ext[sl->cur];
    sl->batch.hits = sl->b.hits;
    rs_sched_submit(c->sched, &sl->batch, &sl->job);
    sl->state = SLOT_EXT;
    c->stats->rays_closest += sl->alive;
    if (sl->bounce > c->stats->max_bounce)
        c->stats->max_bounce = sl->bounce;
}

static void slot_start(render_ctx *c, slot *sl, uint64_t wave)
{
    uint64_t total = c->stats->paths_total, per = c->st.wave_paths;
    double t0 = stage_begin(c);
    sl->wave = wave;
    sl->start = wave * per;
    sl->count = (uint32_t)(total - sl->start < per ? total - sl->start : per);
    sl->alive = sl->count;
    sl->bounce = 0;
    sl->cur = 0;
    rs_integrator_raygen(&c->it, sl->start, sl->count, &sl->b.paths, &sl->b.ext[0]);
    stage_end(c, t0);
    submit_extension(c, sl);
}

/* Waits for the slot's traced rays and runs the CPU stages that follow, up to its next
 * submission (or the end of its paths). */
static rs_status slot_step(render_ctx *c, slot *sl)
{
    wave_buffers *b = &sl->b;
    double t0 = now_s();
    rs_status status = rs_sched_wait(c->sched, &sl->job);
    c->stats->trace_s += now_s() - t0;
    if (status != RS_OK) {
        sl->state = SLOT_IDLE;
        return status;
    }
    if (sl->state == SLOT_EXT) {
        /* shade: emission, next-event shadow rays, the next extension rays */
        t0 = stage_begin(c);
        rs_integrator_shade(&c->it, sl->start, sl->bounce, &b->ext[sl->cur], &b->hits, sl->alive,
                            &b->paths, &b->ext[sl->cur ^ 1], b->next_valid, &b->shadow_raw,
                            b->shadow_valid);
        sl->n_shadow = rs_stream_compact(&b->shadow_raw, b->shadow_valid, sl->alive, &b->shadow,
                                         c->it.threads);
        stage_end(c, t0);
        if (sl->n_shadow > 0) {
            memset(&sl->batch, 0, sizeof sl->batch);
            sl->batch.kind = RS_TRACE_OCCLUDED;
            sl->batch.count = sl->n_shadow;
            sl->batch.rays = b->shadow;
            sl->batch.occluded = b->occluded;
            rs_sched_submit(c->sched, &sl->batch, &sl->job);
            sl->state = SLOT_SHADOW;
            c->stats->rays_shadow += sl->n_shadow;
            return RS_OK;
        }
    } else {
        /* credit the unoccluded shadow rays */
        t0 = stage_begin(c);
        rs_integrator_resolve_shadows(&c->it, &b->shadow, b->occluded, sl->n_shadow, &b->paths);
        stage_end(c, t0);
    }
    /* the surviving paths' next rays, in slot order, become the current stream; they were
     * written in place of the current rays' slots in the other buffer */
    {
        uint32_t before = sl->alive;
        t0 = stage_begin(c);
        sl->alive = rs_stream_compact(&b->ext[sl->cur ^ 1], b->next_valid, sl->alive,
                                      &b->ext[sl->cur], c->it.threads);
        stage_end(c, t0);
        c->ended += before - sl->alive;
    }
    sl->bounce++;
    report(c);
    if (sl->alive > 0)
        submit_extension(c, sl);
    else
        sl->state = SLOT_DONE;
    return RS_OK;
}

typedef struct flush_ctx {
    const slot *sl;
    rs_film *film;
    uint32_t npix;
} flush_ctx;

/* Paths k, k + npix, k + 2 npix, ... of the wave all land on one pixel, in sample order; distinct
 * k are distinct pixels, so the lines of k run in parallel and each pixel still sums its samples
 * in path order (the film is the same bit for bit). */
static void flush_range(void *ctx, uint32_t begin, uint32_t end)
{
    const flush_ctx *f = (const flush_ctx *)ctx;
    uint32_t k, i;
    for (k = begin; k < end; ++k)
        for (i = k; i < f->sl->count; i += f->npix)
            rs_film_add(f->film, (uint32_t)((f->sl->start + i) % f->npix),
                        f->sl->b.paths.radiance[i]);
}

/* Adds the slot's wave to the film in path order. */
static void slot_flush(render_ctx *c, slot *sl, rs_film *film)
{
    flush_ctx f;
    double t0 = stage_begin(c);
    f.sl = sl;
    f.film = film;
    f.npix = c->it.npix;
    rs_parallel_range(RS_PAR_FOR_DYNAMIC, c->it.threads, 0, sl->count < f.npix ? sl->count : f.npix,
                      4096, flush_range, &f);
    stage_end(c, t0);
    c->stats->paths_done += sl->count;
    c->ended -= sl->count;
    c->stats->waves++;
    sl->state = SLOT_IDLE;
    report(c);
}

rs_status rs_render(const rs_scene *scene, rs_sched *sched, const rs_render_settings *st_in,
                    const rs_render_hooks *hooks, rs_film *film, rs_render_stats *stats)
{
    render_ctx *c;
    rs_render_settings st = *st_in;
    uint64_t npix, total, n_waves, next_wave = 0, next_flush = 0;
    uint32_t k, busy;
    double t_start = now_s();
    rs_status status = RS_OK;

    memset(stats, 0, sizeof *stats);
    if (st.width == 0 || st.height == 0 || st.spp == 0 || st.max_depth == 0)
        return rs_error_set(RS_ERR_ARG, "width, height, spp and max depth must be >= 1");
    if (film->width != st.width || film->height != st.height)
        return rs_error_set(RS_ERR_ARG, "film is %ux%u but the render is %ux%u", film->width,
                            film->height, st.width, st.height);
    if (st.waves_in_flight > RS_RENDER_MAX_WAVES)
        return rs_error_set(RS_ERR_ARG, "%u waves in flight: at most %u", st.waves_in_flight,
                            RS_RENDER_MAX_WAVES);
    npix = (uint64_t)st.width * st.height;
    /* npix and spp are both < 2^32, so npix * spp cannot overflow 64 bits */
    if (npix > UINT32_MAX)
        return rs_error_set(RS_ERR_ARG, "image too large: %ux%u at %u spp", st.width, st.height,
                            st.spp);
    total = npix * st.spp;
    if (st.wave_paths == 0)
        st.wave_paths = RS_RENDER_DEFAULT_WAVE;
    if (st.waves_in_flight == 0) {
        int i;
        st.waves_in_flight = 1;
        for (i = 0; i < rs_sched_device_count(sched); ++i)
            if (rs_sched_device(sched, i)->threads == 0)
                st.waves_in_flight = 2; /* a GPU */
    }
    /* the paths in flight are shared among the waves in flight */
    st.wave_paths = (st.wave_paths + st.waves_in_flight - 1) / st.waves_in_flight;
    if ((uint64_t)st.wave_paths > total)
        st.wave_paths = (uint32_t)total;
    n_waves = (total + st.wave_paths - 1) / st.wave_paths;
    if (st.rr_depth == 0)
        st.rr_depth = 3;
    if (st.threads < 1)
        st.threads = 1;

    c = (render_ctx *)rs_calloc(1, sizeof *c);
    if (!c)
        return rs_error_set(RS_ERR_NOMEM, "out of memory for the render loop");
    c->st = st;
    c->sched = sched;
    c->hooks = hooks;
    c->stats = stats;
    c->it.scene = scene;
    c->it.camera = rs_camera_make(scene->camera.from, scene->camera.at, scene->camera.up,
                                  scene->camera.vfov_deg, scene->camera.aperture,
                                  scene->camera.focus_dist, st.width, st.height);
    c->it.seed = st.seed;
    c->it.width = st.width;
    c->it.height = st.height;
    c->it.npix = (uint32_t)npix;
    c->it.max_depth = st.max_depth;
    c->it.rr_depth = st.rr_depth;
    c->it.sampling = st.sampling;
    c->it.threads = st.threads;
    c->it.strategy = st.strategy;
    c->n_slots = n_waves < st.waves_in_flight ? (uint32_t)n_waves : st.waves_in_flight;
    stats->paths_total = total;

    for (k = 0; k < c->n_slots && status == RS_OK; ++k)
        status = buffers_init(&c->slots[k].b, st.wave_paths);

    /* Round robin over the slots: each step waits for the oldest submission, so the devices
     * trace the other slots' rays meanwhile. */
    for (busy = 1; status == RS_OK && busy;) {
        busy = 0;
        for (k = 0; k < c->n_slots && status == RS_OK; ++k) {
            slot *sl = &c->slots[k];
            if (sl->state == SLOT_IDLE && next_wave < n_waves) {
                if (cancelled(hooks))
                    break;
                slot_start(c, sl, next_wave++);
            } else if (sl->state == SLOT_EXT || sl->state == SLOT_SHADOW) {
                if (cancelled(hooks))
                    break;
                status = slot_step(c, sl);
            }
            /* waves go to the film in wave order: flush every finished one that is next */
            for (;;) {
                uint32_t j;
                for (j = 0; j < c->n_slots; ++j)
                    if (c->slots[j].state == SLOT_DONE && c->slots[j].wave == next_flush)
                        break;
                if (j == c->n_slots)
                    break;
                slot_flush(c, &c->slots[j], film);
                next_flush++;
            }
            busy |= sl->state != SLOT_IDLE || next_wave < n_waves;
        }
        if (status == RS_OK && cancelled(hooks))
            status = rs_error_set(RS_ERR_CANCELLED, "render interrupted");
    }
    /* on a failure or an interruption, take back what is still with the scheduler before the
     * buffers go: the render thread owns them */
    for (k = 0; k < c->n_slots; ++k) {
        slot *sl = &c->slots[k];
        if (sl->state == SLOT_EXT || sl->state == SLOT_SHADOW)
            (void)rs_sched_wait(sched, &sl->job);
        buffers_free(&sl->b);
    }
    rs_free(c);
    stats->seconds = now_s() - t_start;
    return status;
}
