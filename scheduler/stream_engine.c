/* scheduler/stream_engine.c — the stream engine's run of a plan (render.h): waves of paths
 * through a table of named stages; each slot (a wave in flight) holds the index of the stage it
 * runs next. */
#include <string.h>

#include "core/alloc.h"
#include "core/clock.h"
#include "core/cores.h"
#include "scheduler/engine_impl.h"

static void report(rs_run *c)
{
    const rs_render_hooks *h = c->hooks;
    rs_run_lock(c);
    if (h && h->progress)
        h->progress(h->user, c->stats->paths_done + c->ended, c->stats->paths_total);
    rs_run_unlock(c);
}

/* rs_run_more under the run's lock (path devices may be taking ranges beside the waves). */
static int more(rs_run *c)
{
    int m;
    rs_run_lock(c);
    m = rs_run_more(c);
    rs_run_unlock(c);
    return m;
}

/* Hands the slot's rays to the scheduler: extension rays (closest hit) or shadow rays. */
static void submit(rs_run *c, rs_slot *sl, rs_trace_kind kind)
{
    rs_wave_buffers *b = &sl->b;
    memset(&sl->batch, 0, sizeof sl->batch);
    sl->batch.kind = kind;
    sl->batch.wave = (uint32_t)sl->wave;
    sl->batch.pinned = (uint32_t)b->pinned;
    if (kind == RS_TRACE_CLOSEST) {
        sl->batch.count = sl->alive;
        sl->batch.rays = b->ext[sl->cur];
        sl->batch.hits = b->hits;
        c->stats->rays_closest += sl->alive;
        if (sl->bounce > c->stats->max_bounce)
            c->stats->max_bounce = sl->bounce;
    } else {
        sl->batch.count = sl->n_shadow;
        sl->batch.rays = b->shadow;
        sl->batch.occluded = b->occluded;
        c->stats->rays_shadow += sl->n_shadow;
    }
    rs_sched_submit(c->e->sched, &sl->batch, &sl->job);
}

/* ---- the stages: each runs one step of a slot's wave and says whether what it made is empty
 * (the table below then picks the stage's `next_if_empty`) ---------------------------------- */

static int stage_raygen(rs_run *c, rs_slot *sl, rs_status *status)
{
    (void)status;
    rs_stage_raygen(&c->e->it, &c->map, &c->ex, sl->start, sl->count, &sl->b.paths, &sl->b.ext[0]);
    submit(c, sl, RS_TRACE_CLOSEST);
    return 0;
}

/* Both trace stages wait for the slot's submission; the devices did the work meanwhile. */
static int stage_wait(rs_run *c, rs_slot *sl, rs_status *status)
{
    *status = rs_sched_wait(c->e->sched, &sl->job);
    return 0;
}

/* Emission, next-event shadow rays and the next extension rays; the shadow rays are packed for
 * the devices here.  Empty: no shadow ray. */
static int stage_shade(rs_run *c, rs_slot *sl, rs_status *status)
{
    rs_wave_buffers *b = &sl->b;
    (void)status;
    rs_stage_shade(&c->e->it, &c->map, &c->ex, sl->start, sl->bounce, &b->ext[sl->cur], &b->hits,
                   sl->alive, &b->paths, &b->ext[sl->cur ^ 1], &b->shadow, &b->runs);
    sl->n_shadow = rs_stream_pack_runs(&b->shadow, &b->runs, 1, sl->alive);
    if (sl->n_shadow == 0)
        return 1;
    submit(c, sl, RS_TRACE_OCCLUDED);
    return 0;
}

static int stage_resolve_shadows(rs_run *c, rs_slot *sl, rs_status *status)
{
    (void)status;
    rs_stage_resolve_shadows(&c->ex, &sl->b.shadow, sl->b.occluded, sl->n_shadow, &sl->b.paths);
    return 0;
}

/* The surviving paths' next rays become the current stream: the shade stage wrote them in runs
 * into the other buffer, packed here in place.  Empty: no path alive. */
static int stage_compact(rs_run *c, rs_slot *sl, rs_status *status)
{
    rs_wave_buffers *b = &sl->b;
    uint32_t before = sl->alive;
    (void)status;
    sl->alive = rs_stream_pack_runs(&b->ext[sl->cur ^ 1], &b->runs, 0, sl->alive);
    sl->cur ^= 1;
    c->ended += before - sl->alive;
    sl->bounce++;
    report(c);
    if (sl->alive == 0)
        return 1;
    submit(c, sl, RS_TRACE_CLOSEST);
    return 0;
}

typedef struct flush_ctx {
    const rs_slot *sl;
    rs_film *film;
    const rs_path_map *map;
    uint32_t npix; /* paths per pass */
} flush_ctx;

/* Paths k, k + npix, k + 2 npix, ... of the wave all land on one pixel, in sample order; distinct
 * k are distinct pixels, so the lines of k run in parallel and each pixel still sums its samples
 * in path order (the film is the same bit for bit). */
static void flush_range(void *ctx, uint32_t begin, uint32_t end)
{
    const flush_ctx *f = (const flush_ctx *)ctx;
    uint32_t k, i;
    const rs_paths *ps = &f->sl->b.paths;
    for (k = begin; k < end; ++k)
        for (i = k; i < f->sl->count; i += f->npix) {
            uint32_t pixel = rs_path_map_pixel(f->map, f->sl->start + i);
            rs_film_add(f->film, pixel, rs_path_result(ps->radiance[i], ps->flags[i]));
            if (f->film->pass)
                rs_film_add_pass(f->film, pixel, &ps->aux[i]);
        }
}

/* The wave onto the film in path order (run only for the next wave in wave order). */
static int stage_film(rs_run *c, rs_slot *sl, rs_status *status)
{
    flush_ctx f;
    const rs_render_hooks *h = c->hooks;
    f.sl = sl;
    f.film = c->film;
    f.map = &c->map;
    f.npix = c->map.n_active;
    rs_run_lock(c); /* path devices merge their films into the same one */
    rs_parallel_range(RS_PAR_FOR_DYNAMIC, c->ex.threads, 0, sl->count < f.npix ? sl->count : f.npix,
                      4096, flush_range, &f);
    c->stats->paths_done += sl->count;
    c->ended -= sl->count;
    c->stats->waves++;
    if (c->lock) { /* the stream engine's rate, for the share it takes next (wavefront.c) */
        double s = rs_now_s() - c->t0;
        c->host_paths += sl->count;
        if (s > 0)
            c->rate[c->e->n_pdev] = (double)c->host_paths / s;
    }
    if (h && h->progress)
        h->progress(h->user, c->stats->paths_done + c->ended, c->stats->paths_total);
    *status = rs_run_on_film(c, sl->start, sl->start + sl->count);
    rs_run_unlock(c);
    return 0;
}

/* The stage table, in rs_stage order: what runs, whether it takes threads from the core budget
 * (`host`; the others wait for the devices), whether the slot yields to the round robin before
 * it (a wait, or the film, which takes the waves in wave order), and the stage after it. */
static const struct stage_def {
    int (*run)(rs_run *c, rs_slot *sl, rs_status *status);
    uint8_t host, yields, next, next_if_empty;
} stages[RS_STAGE_PASS] = {
    /* RS_STAGE_RAYGEN */ {stage_raygen, 1, 0, RS_STAGE_TRACE_CLOSEST, RS_STAGE_TRACE_CLOSEST},
    /* RS_STAGE_TRACE_CLOSEST */ {stage_wait, 0, 1, RS_STAGE_SHADE, RS_STAGE_SHADE},
    /* RS_STAGE_SHADE */ {stage_shade, 1, 0, RS_STAGE_TRACE_SHADOW, RS_STAGE_COMPACT},
    /* RS_STAGE_TRACE_SHADOW */
    {stage_wait, 0, 1, RS_STAGE_RESOLVE_SHADOWS, RS_STAGE_RESOLVE_SHADOWS},
    /* RS_STAGE_RESOLVE_SHADOWS */
    {stage_resolve_shadows, 1, 0, RS_STAGE_COMPACT, RS_STAGE_COMPACT},
    /* RS_STAGE_COMPACT */ {stage_compact, 1, 0, RS_STAGE_TRACE_CLOSEST, RS_STAGE_FILM},
    /* RS_STAGE_FILM */ {stage_film, 1, 1, SLOT_IDLE, SLOT_IDLE},
};

/* Runs the slot's current stage, timed under its name; a failed stage leaves the slot idle. */
static rs_status run_stage(rs_run *c, rs_slot *sl)
{
    const struct stage_def *d = &stages[sl->stage];
    const rs_render_settings *st = &c->e->st;
    rs_status status = RS_OK;
    double t0, t1;
    int empty;
    if (d->host)
        c->ex.threads = rs_cores_acquire(st->cores, st->threads);
    t0 = rs_now_s();
    empty = d->run(c, sl, &status);
    t1 = rs_now_s();
    if (d->host) {
        rs_cores_release(st->cores, c->ex.threads);
        c->stats->host_s += t1 - t0;
        /* waits are gaps on the render thread's lane: the devices' lanes show the work */
        if (st->timeline) {
            double e = rs_timeline_now(st->timeline);
            rs_timeline_add(st->timeline, st->timeline_lane, (rs_stage)sl->stage,
                            (uint32_t)sl->wave, e - (t1 - t0), e);
        }
    } else {
        c->stats->wait_s += t1 - t0;
    }
    c->stats->stage_s[sl->stage] += t1 - t0;
    sl->stage = status != RS_OK ? SLOT_IDLE : empty ? d->next_if_empty : d->next;
    return status;
}

/* Starts the next wave: at most wave_paths paths from where the plan stands (rs_run_take: the
 * next ones, or with path devices beside it a share by its rate).  An idle slot stays idle when
 * nothing is left. */
static rs_status slot_start(rs_run *c, rs_slot *sl, uint64_t *wave)
{
    uint64_t lo, n;
    if (!rs_run_take(c, c->e->n_pdev, c->e->st.wave_paths, &lo, &n))
        return RS_OK;
    sl->wave = (*wave)++;
    sl->start = lo;
    sl->count = (uint32_t)n;
    sl->alive = sl->count;
    sl->bounce = 0;
    sl->cur = 0;
    sl->stage = RS_STAGE_RAYGEN;
    return run_stage(c, sl);
}

/* Runs the slot's stages up to the next one it yields before, or its end. */
static rs_status slot_step(rs_run *c, rs_slot *sl)
{
    rs_status status;
    do {
        status = run_stage(c, sl);
    } while (status == RS_OK && sl->stage != SLOT_IDLE && !stages[sl->stage].yields);
    return status;
}

/* Runs the film stage of every finished wave that is next in wave order. */
static rs_status flush_in_order(rs_run *c, uint64_t *next_flush)
{
    rs_engine *e = c->e;
    rs_status status = RS_OK;
    for (;;) {
        uint32_t j;
        for (j = 0; j < e->n_slots; ++j)
            if (e->slots[j].stage == RS_STAGE_FILM && e->slots[j].wave == *next_flush)
                break;
        if (j == e->n_slots)
            return status;
        if ((status = run_stage(c, &e->slots[j])) != RS_OK)
            return status;
        (*next_flush)++;
    }
}

/* Round robin over the slots: each visit runs a slot up to its next wait, so the devices trace
 * the other slots' rays meanwhile; finished waves go to the film in wave order. */
rs_status rs_stream_run(rs_run *c)
{
    rs_engine *e = c->e;
    uint64_t next_wave = 0, next_flush = 0;
    rs_status status = RS_OK;
    uint32_t k, busy;
    c->ex.threads = e->st.threads;
    c->ex.strategy = e->st.strategy;
    c->stats->wave_paths = e->st.wave_paths;
    for (busy = 1; status == RS_OK && busy;) {
        busy = 0;
        for (k = 0; k < e->n_slots && status == RS_OK; ++k) {
            rs_slot *sl = &e->slots[k];
            if (sl->stage == SLOT_IDLE && more(c)) {
                if (rs_run_cancelled(c))
                    break;
                status = slot_start(c, sl, &next_wave);
            } else if (sl->stage != SLOT_IDLE && stages[sl->stage].yields &&
                       sl->stage != RS_STAGE_FILM) {
                if (rs_run_cancelled(c))
                    break;
                status = slot_step(c, sl);
            }
            if (status == RS_OK)
                status = flush_in_order(c, &next_flush);
            busy |= sl->stage != SLOT_IDLE || more(c);
        }
        if (status == RS_OK && rs_run_cancelled(c))
            status = rs_error_set(RS_ERR_CANCELLED, "render interrupted");
    }
    /* on a failure or an interruption, take back what is still with the scheduler: the engine
     * keeps the buffers for its next run */
    for (k = 0; k < e->n_slots; ++k) {
        rs_slot *sl = &e->slots[k];
        if (sl->stage == RS_STAGE_TRACE_CLOSEST || sl->stage == RS_STAGE_TRACE_SHADOW)
            (void)rs_sched_wait(e->sched, &sl->job);
        sl->stage = SLOT_IDLE;
    }
    return status;
}

/* Host memory for the wave buffers from a device's host_alloc (the first device that has one:
 * a GPU's page-locked memory, which every CUDA device can copy by DMA). */
static void *pinned_alloc(void *user, size_t bytes)
{
    rs_device *d = (rs_device *)user;
    return d->ops->host_alloc(d, bytes);
}

static void pinned_release(void *user, void *p)
{
    rs_device *d = (rs_device *)user;
    d->ops->host_free(d, p);
}

/* The allocator of the first device with host_alloc; 0 when none has one. */
static int device_host_memory(rs_sched *sched, rs_host_allocator *a)
{
    int i;
    for (i = 0; i < rs_sched_device_count(sched); ++i) {
        rs_device *d = rs_sched_device(sched, i);
        if (d->ops->host_alloc && d->ops->host_free) {
            a->alloc = pinned_alloc;
            a->release = pinned_release;
            a->user = d;
            return 1;
        }
    }
    return 0;
}

/* The settings with the automatic choices made: the wave size, waves in flight, the wave size
 * per slot, for a render of `total` paths. */
static void resolve_settings(rs_render_settings *st, const rs_sched *sched, uint64_t total)
{
    int i, gpu = 0, n_dev = rs_sched_device_count(sched);
    for (i = 0; i < n_dev; ++i)
        gpu |= rs_device_owns_memory(rs_sched_device(sched, i));
    if (st->threads < 1)
        st->threads = 1;
    if (st->wave_paths == 0) {
        /* One CPU device: waves the caches hold when the render thread and the device's
         * dispatch thread share one core (RS_RENDER_HOST_WAVE per thread), bigger ones when the
         * dispatch thread has a core of its own to trace on while the stages run
         * (RS_RENDER_HOST_WAVE_FREE).  Several devices need the big wave to share out. */
        uint64_t host =
            (uint64_t)(rs_cores_allowed() > 1 ? RS_RENDER_HOST_WAVE_FREE : RS_RENDER_HOST_WAVE) *
            (uint32_t)st->threads;
        st->wave_paths = gpu || n_dev > 1 || host > RS_RENDER_DEFAULT_WAVE ? RS_RENDER_DEFAULT_WAVE
                                                                           : (uint32_t)host;
    }
    if (st->waves_in_flight == 0)
        st->waves_in_flight = gpu ? 2 : 1;
    /* the paths in flight are shared among the waves in flight */
    st->wave_paths = (st->wave_paths + st->waves_in_flight - 1) / st->waves_in_flight;
    if ((uint64_t)st->wave_paths > total)
        st->wave_paths = (uint32_t)total;
}

rs_status rs_stream_setup(rs_engine *e)
{
    uint64_t total = (uint64_t)e->it.npix * e->st.spp, n_waves;
    rs_host_allocator pinned;
    int have_pinned = device_host_memory(e->sched, &pinned);
    rs_status status = RS_OK;
    uint32_t k;
    resolve_settings(&e->st, e->sched, total);
    n_waves = (total + e->st.wave_paths - 1) / e->st.wave_paths;
    e->n_slots = n_waves < e->st.waves_in_flight ? (uint32_t)n_waves : e->st.waves_in_flight;
    for (k = 0; k < RS_RENDER_MAX_WAVES; ++k)
        e->slots[k].stage = SLOT_IDLE;
    for (k = 0; k < e->n_slots && status == RS_OK; ++k) {
        status =
            rs_wave_buffers_create(e->st.wave_paths, have_pinned ? &pinned : NULL, &e->slots[k].b);
        if (status == RS_ERR_NOMEM && have_pinned) {
            /* page-locked memory is scarcer than memory: the device then stages its chunks */
            rs_error_clear();
            status = rs_wave_buffers_create(e->st.wave_paths, NULL, &e->slots[k].b);
        }
    }
    return status;
}

void rs_stream_release(rs_engine *e)
{
    uint32_t k;
    for (k = 0; k < e->n_slots; ++k)
        rs_wave_buffers_destroy(&e->slots[k].b);
}
