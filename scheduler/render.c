/* scheduler/render.c — see render.h.  The loop is a table of named stages; each slot (a wave in
 * flight) holds the index of the stage it runs next. */
#include "scheduler/render.h"

#include <string.h>
#include <time.h>

#include "core/alloc.h"
#include "core/cores.h"
#include "streams/wave.h"

/* SLOT_IDLE: the slot holds no wave.  Otherwise its `stage` is an rs_stage. */
#define SLOT_IDLE 0xffu

/* One wave in flight and its buffers. */
typedef struct slot {
    rs_wave_buffers b;
    uint8_t stage;  /* next stage to run, or SLOT_IDLE */
    uint64_t wave;  /* index of the wave it holds */
    uint64_t start; /* its first path */
    uint32_t count, alive, bounce, cur;
    uint32_t n_shadow;
    rs_trace_batch batch; /* what `job` traces: must live as long as the job */
    rs_sched_job job;
} slot;

typedef struct render_ctx {
    rs_integrator it;
    rs_stage_exec ex; /* threads granted to the stage running now */
    rs_render_settings st;
    rs_sched *sched;
    const rs_render_hooks *hooks;
    rs_render_stats *stats;
    rs_film *film;
    slot slots[RS_RENDER_MAX_WAVES];
    uint32_t n_slots;
    uint64_t next_path;       /* the first path no wave has started yet */
    uint64_t end_path;        /* paths [next_path, end_path) are still to start: the render's
                                 end, or the end of the pass under way once the time is up */
    uint64_t on_film;         /* the film holds paths [0, on_film) */
    double t_start;           /* when rs_render began (now_s) */
    uint64_t ended;           /* paths ended in waves not yet on the film */
    rs_host_allocator pinned; /* a device's host_alloc for the wave buffers, if one has it */
    int have_pinned;
} render_ctx;

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int cancelled(const rs_render_hooks *h) { return h && h->cancel && atomic_load(h->cancel); }

static void report(const render_ctx *c)
{
    const rs_render_hooks *h = c->hooks;
    if (h && h->progress)
        h->progress(h->user, c->stats->paths_done + c->ended, c->stats->paths_total);
}

/* Hands the slot's rays to the scheduler: extension rays (closest hit) or shadow rays. */
static void submit(render_ctx *c, slot *sl, rs_trace_kind kind)
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
    rs_sched_submit(c->sched, &sl->batch, &sl->job);
}

/* ---- the stages: each runs one step of a slot's wave and returns the slot's next stage ---- */

static uint8_t stage_raygen(render_ctx *c, slot *sl, rs_status *status)
{
    (void)status;
    rs_integrator_raygen(&c->it, &c->ex, sl->start, sl->count, &sl->b.paths, &sl->b.ext[0]);
    submit(c, sl, RS_TRACE_CLOSEST);
    return RS_STAGE_TRACE_CLOSEST;
}

/* Both trace stages wait for the slot's submission; the devices did the work meanwhile. */
static uint8_t stage_trace(render_ctx *c, slot *sl, rs_status *status)
{
    int closest = sl->stage == RS_STAGE_TRACE_CLOSEST;
    *status = rs_sched_wait(c->sched, &sl->job);
    if (*status != RS_OK)
        return SLOT_IDLE;
    return closest ? RS_STAGE_SHADE : RS_STAGE_RESOLVE_SHADOWS;
}

/* Emission, next-event shadow rays and the next extension rays; the shadow rays are packed for
 * the devices here. */
static uint8_t stage_shade(render_ctx *c, slot *sl, rs_status *status)
{
    rs_wave_buffers *b = &sl->b;
    (void)status;
    rs_integrator_shade(&c->it, &c->ex, sl->start, sl->bounce, &b->ext[sl->cur], &b->hits,
                        sl->alive, &b->paths, &b->ext[sl->cur ^ 1], &b->shadow, &b->runs);
    sl->n_shadow = rs_stream_pack_runs(&b->shadow, &b->runs, 1, sl->alive);
    if (sl->n_shadow == 0)
        return RS_STAGE_COMPACT;
    submit(c, sl, RS_TRACE_OCCLUDED);
    return RS_STAGE_TRACE_SHADOW;
}

static uint8_t stage_resolve_shadows(render_ctx *c, slot *sl, rs_status *status)
{
    (void)status;
    rs_integrator_resolve_shadows(&c->ex, &sl->b.shadow, sl->b.occluded, sl->n_shadow,
                                  &sl->b.paths);
    return RS_STAGE_COMPACT;
}

/* The surviving paths' next rays, in slot order, become the current stream: the shade stage
 * wrote them in runs into the other buffer, packed here in place. */
static uint8_t stage_compact(render_ctx *c, slot *sl, rs_status *status)
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
        return RS_STAGE_FILM;
    submit(c, sl, RS_TRACE_CLOSEST);
    return RS_STAGE_TRACE_CLOSEST;
}

typedef struct flush_ctx {
    const slot *sl;
    rs_film *film;
    const rs_integrator *it;
    uint32_t npix; /* paths per pass */
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
            rs_film_add(f->film, rs_path_pixel(f->it, f->sl->start + i),
                        f->sl->b.paths.radiance[i]);
}

/* The wave onto the film in path order (run only for the next wave in wave order). */
static uint8_t stage_film(render_ctx *c, slot *sl, rs_status *status)
{
    flush_ctx f;
    (void)status;
    f.sl = sl;
    f.film = c->film;
    f.it = &c->it;
    f.npix = c->it.n_active;
    rs_parallel_range(RS_PAR_FOR_DYNAMIC, c->ex.threads, 0, sl->count < f.npix ? sl->count : f.npix,
                      4096, flush_range, &f);
    c->stats->paths_done += sl->count;
    c->ended -= sl->count;
    c->stats->waves++;
    c->on_film = sl->start + sl->count;
    report(c);
    if (c->hooks && c->hooks->film_ready)
        c->hooks->film_ready(c->hooks->user, c->film, c->on_film);
    return SLOT_IDLE;
}

typedef uint8_t (*stage_fn)(render_ctx *c, slot *sl, rs_status *status);

/* The stage table, in rs_stage order; `host` stages take threads from the core budget. */
static const struct {
    stage_fn run;
    int host;
} stages[RS_STAGE_PASS] = {
    {stage_raygen, 1},          {stage_trace, 0},   {stage_shade, 1}, {stage_trace, 0},
    {stage_resolve_shadows, 1}, {stage_compact, 1}, {stage_film, 1},
};

/* Runs the slot's current stage, timed under its name. */
static rs_status run_stage(render_ctx *c, slot *sl)
{
    uint8_t s = sl->stage;
    rs_status status = RS_OK;
    double t0, t1;
    if (stages[s].host)
        c->ex.threads = rs_cores_acquire(c->st.cores, c->st.threads);
    t0 = now_s();
    sl->stage = stages[s].run(c, sl, &status);
    t1 = now_s();
    if (stages[s].host) {
        rs_cores_release(c->st.cores, c->ex.threads);
        c->stats->shade_s += t1 - t0;
        /* waits are gaps on the render thread's lane: the devices' lanes show the work */
        if (c->st.timeline) {
            double e = rs_timeline_now(c->st.timeline);
            rs_timeline_add(c->st.timeline, c->st.timeline_lane, (rs_stage)s, (uint32_t)sl->wave,
                            e - (t1 - t0), e);
        }
    } else {
        c->stats->trace_s += t1 - t0;
    }
    c->stats->stage_s[s] += t1 - t0;
    return status;
}

/* Starts the next wave: paths [next_path, next_path + wave_paths), cut at end_path. */
static rs_status slot_start(render_ctx *c, slot *sl, uint64_t wave)
{
    uint64_t left = c->end_path - c->next_path, per = c->st.wave_paths;
    sl->wave = wave;
    sl->start = c->next_path;
    sl->count = (uint32_t)(left < per ? left : per);
    c->next_path += sl->count;
    sl->alive = sl->count;
    sl->bounce = 0;
    sl->cur = 0;
    sl->stage = RS_STAGE_RAYGEN;
    return run_stage(c, sl);
}

/* Runs the slot's stages up to its next submission (a trace stage, waited for on its next
 * visit) or the end of its paths. */
static rs_status slot_step(render_ctx *c, slot *sl)
{
    rs_status status;
    do {
        status = run_stage(c, sl);
    } while (status == RS_OK && sl->stage != RS_STAGE_TRACE_CLOSEST &&
             sl->stage != RS_STAGE_TRACE_SHADOW && sl->stage != RS_STAGE_FILM &&
             sl->stage != SLOT_IDLE);
    return status;
}

/* Runs the film stage of every finished wave that is next in wave order. */
static rs_status flush_in_order(render_ctx *c, uint64_t *next_flush)
{
    rs_status status = RS_OK;
    for (;;) {
        uint32_t j;
        for (j = 0; j < c->n_slots; ++j)
            if (c->slots[j].stage == RS_STAGE_FILM && c->slots[j].wave == *next_flush)
                break;
        if (j == c->n_slots)
            return status;
        if ((status = run_stage(c, &c->slots[j])) != RS_OK)
            return status;
        (*next_flush)++;
    }
}

void rs_render_stats_add(rs_render_stats *sum, const rs_render_stats *r)
{
    int k;
    for (k = 0; k < RS_STAGE_COUNT; ++k)
        sum->stage_s[k] += r->stage_s[k];
    sum->trace_s += r->trace_s;
    sum->shade_s += r->shade_s;
    sum->paths_total += r->paths_total;
    sum->paths_done += r->paths_done;
    sum->rays_closest += r->rays_closest;
    sum->rays_shadow += r->rays_shadow;
    sum->waves += r->waves;
    if (r->max_bounce > sum->max_bounce)
        sum->max_bounce = r->max_bounce;
    sum->time_limited |= r->time_limited;
}

rs_status rs_render_constants(const rs_scene *scene, const rs_render_settings *st,
                              const rs_film *film, rs_integrator *it)
{
    uint64_t npix;
    if (st->width == 0 || st->height == 0 || st->spp == 0 || st->max_depth == 0)
        return rs_error_set(RS_ERR_ARG, "width, height, spp and max depth must be >= 1");
    if (film->width != st->width || film->height != st->height)
        return rs_error_set(RS_ERR_ARG, "film is %ux%u but the render is %ux%u", film->width,
                            film->height, st->width, st->height);
    npix = (uint64_t)st->width * st->height;
    /* npix and spp are both < 2^32, so npix * spp cannot overflow 64 bits */
    if (npix > UINT32_MAX)
        return rs_error_set(RS_ERR_ARG, "image too large: %ux%u at %u spp", st->width, st->height,
                            st->spp);
    if (st->path_begin > npix * st->spp)
        return rs_error_set(RS_ERR_ARG,
                            "the film already holds %llu samples, more than %ux%u at %u spp",
                            (unsigned long long)st->path_begin, st->width, st->height, st->spp);
    if (st->pixels && (st->n_pixels == 0 || st->n_pixels > npix))
        return rs_error_set(RS_ERR_ARG, "a pass over %u of %llu pixels", st->n_pixels,
                            (unsigned long long)npix);
    if ((uint64_t)st->sample_base + st->spp > (st->spp_total ? st->spp_total : st->spp) ||
        (st->spp_total && st->spp_total < st->spp))
        return rs_error_set(RS_ERR_ARG, "samples %u..%u of a %u spp render", st->sample_base,
                            st->sample_base + st->spp, st->spp_total);
    memset(it, 0, sizeof *it);
    it->scene = scene;
    it->camera = rs_camera_make(scene->camera.from, scene->camera.at, scene->camera.up,
                                scene->camera.vfov_deg, scene->camera.aperture,
                                scene->camera.focus_dist, st->width, st->height);
    it->seed = st->seed;
    it->width = st->width;
    it->height = st->height;
    it->npix = (uint32_t)npix;
    it->spp = st->spp_total ? st->spp_total : st->spp;
    it->pixel_of = st->pixels;
    it->n_active = st->pixels ? st->n_pixels : (uint32_t)npix;
    it->sample_base = st->sample_base;
    it->max_depth = st->max_depth;
    it->rr_depth = st->rr_depth ? st->rr_depth : 3;
    it->sampling = (uint32_t)st->sampling;
    it->sampler = (uint32_t)st->sampler;
    return RS_OK;
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

static void choose_host_memory(render_ctx *c)
{
    int i;
    for (i = 0; i < rs_sched_device_count(c->sched); ++i) {
        rs_device *d = rs_sched_device(c->sched, i);
        if (d->ops->host_alloc && d->ops->host_free) {
            c->pinned.alloc = pinned_alloc;
            c->pinned.release = pinned_release;
            c->pinned.user = d;
            c->have_pinned = 1;
            return;
        }
    }
}

/* The settings with the automatic choices made: the wave size, waves in flight, the wave size
 * per slot. */
static void resolve_settings(rs_render_settings *st, const rs_sched *sched, uint64_t total)
{
    int i, gpu = 0, n_dev = rs_sched_device_count(sched);
    for (i = 0; i < n_dev; ++i)
        gpu |= rs_device_is_gpu(rs_sched_device(sched, i));
    if (st->threads < 1)
        st->threads = 1;
    if (st->wave_paths == 0) {
        /* One CPU device: waves the caches hold when the render thread and the device's
         * dispatch thread share one core (RS_RENDER_HOST_WAVE per thread), bigger ones when the
         * dispatch thread has a core of its own to trace on while the stages run
         * (RS_RENDER_HOST_WAVE_FREE: 16384 was 16-27% slower there, docs/performance.md).
         * Several devices need the big wave to share out (with 16384-path waves cpu:1 + the
         * fallback lost 10-30% of its load balance). */
        uint64_t host = (uint64_t)(rs_cores_allowed() > 1 ? RS_RENDER_HOST_WAVE_FREE
                                                          : RS_RENDER_HOST_WAVE) *
                        (uint32_t)st->threads;
        st->wave_paths = gpu || n_dev > 1 || host > RS_RENDER_DEFAULT_WAVE
                             ? RS_RENDER_DEFAULT_WAVE
                             : (uint32_t)host;
    }
    if (st->waves_in_flight == 0)
        st->waves_in_flight = gpu ? 2 : 1;
    /* the paths in flight are shared among the waves in flight */
    st->wave_paths = (st->wave_paths + st->waves_in_flight - 1) / st->waves_in_flight;
    if ((uint64_t)st->wave_paths > total)
        st->wave_paths = (uint32_t)total;
}

/* Once the time limit is reached: no path past the end of the pass that holds the last path
 * started (at least the first pass this call adds to), so the film ends on a whole pass. */
static void apply_time_limit(render_ctx *c)
{
    uint64_t npix = c->it.n_active, end, first_pass_end; /* paths per pass */
    const rs_render_hooks *h = c->hooks;
    if (!h || h->time_limit_s <= 0 || c->stats->time_limited ||
        now_s() - c->t_start < h->time_limit_s)
        return;
    end = (c->next_path + npix - 1) / npix * npix;
    first_pass_end = (c->st.path_begin / npix + 1) * npix;
    if (end < first_pass_end)
        end = first_pass_end;
    if (end < c->end_path) {
        c->end_path = end;
        c->stats->time_limited = 1;
    }
}

/* Round robin over the slots: each visit runs a slot up to its next submission, so the devices
 * trace the other slots' rays meanwhile; finished waves go to the film in wave order. */
static rs_status run_waves(render_ctx *c)
{
    uint64_t next_wave = 0, next_flush = 0;
    rs_status status = RS_OK;
    uint32_t k, busy;
    for (busy = 1; status == RS_OK && busy;) {
        busy = 0;
        for (k = 0; k < c->n_slots && status == RS_OK; ++k) {
            slot *sl = &c->slots[k];
            if (sl->stage == SLOT_IDLE && c->next_path < c->end_path) {
                if (cancelled(c->hooks))
                    break;
                apply_time_limit(c);
                if (c->next_path < c->end_path)
                    status = slot_start(c, sl, next_wave++);
            } else if (sl->stage == RS_STAGE_TRACE_CLOSEST || sl->stage == RS_STAGE_TRACE_SHADOW) {
                if (cancelled(c->hooks))
                    break;
                status = slot_step(c, sl);
            }
            if (status == RS_OK)
                status = flush_in_order(c, &next_flush);
            busy |= sl->stage != SLOT_IDLE || c->next_path < c->end_path;
        }
        if (status == RS_OK && cancelled(c->hooks))
            status = rs_error_set(RS_ERR_CANCELLED, "render interrupted");
    }
    return status;
}

rs_status rs_render(const rs_scene *scene, rs_sched *sched, const rs_render_settings *st_in,
                    const rs_render_hooks *hooks, rs_film *film, rs_render_stats *stats)
{
    render_ctx *c;
    rs_integrator it;
    uint64_t total, n_waves;
    uint32_t k;
    double t_start = now_s();
    rs_status status;

    memset(stats, 0, sizeof *stats);
    if ((status = rs_render_constants(scene, st_in, film, &it)) != RS_OK)
        return status;
    if (st_in->waves_in_flight > RS_RENDER_MAX_WAVES)
        return rs_error_set(RS_ERR_ARG, "%u waves in flight: at most %u", st_in->waves_in_flight,
                            RS_RENDER_MAX_WAVES);
    c = (render_ctx *)rs_calloc(1, sizeof *c);
    if (!c)
        return rs_error_set(RS_ERR_NOMEM, "out of memory for the render loop");
    total = (uint64_t)it.n_active * st_in->spp - st_in->path_begin; /* this call's paths */
    c->it = it;
    c->st = *st_in;
    c->sched = sched;
    c->hooks = hooks;
    c->stats = stats;
    c->film = film;
    c->next_path = c->on_film = st_in->path_begin;
    c->end_path = st_in->path_begin + total;
    c->t_start = t_start;
    resolve_settings(&c->st, sched, total);
    c->ex.threads = c->st.threads;
    c->ex.strategy = c->st.strategy;
    n_waves = total ? (total + c->st.wave_paths - 1) / c->st.wave_paths : 0;
    c->n_slots = n_waves < c->st.waves_in_flight ? (uint32_t)n_waves : c->st.waves_in_flight;
    stats->paths_total = total;
    choose_host_memory(c);
    for (k = 0; k < c->n_slots; ++k)
        c->slots[k].stage = SLOT_IDLE;
    for (k = 0; k < c->n_slots && status == RS_OK; ++k) {
        status = rs_wave_buffers_create(c->st.wave_paths, c->have_pinned ? &c->pinned : NULL,
                                        &c->slots[k].b);
        if (status == RS_ERR_NOMEM && c->have_pinned) {
            /* page-locked memory is scarcer than memory: the device then stages its chunks */
            rs_error_clear();
            status = rs_wave_buffers_create(c->st.wave_paths, NULL, &c->slots[k].b);
        }
    }
    if (status == RS_OK && total > 0)
        status = run_waves(c);
    /* on a failure or an interruption, take back what is still with the scheduler before the
     * buffers go: the render thread owns them */
    for (k = 0; k < c->n_slots; ++k) {
        slot *sl = &c->slots[k];
        if (sl->stage == RS_STAGE_TRACE_CLOSEST || sl->stage == RS_STAGE_TRACE_SHADOW)
            (void)rs_sched_wait(sched, &sl->job);
        rs_wave_buffers_destroy(&sl->b);
    }
    rs_free(c);
    stats->seconds = now_s() - t_start;
    return status;
}
