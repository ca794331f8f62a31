/* scheduler/passes.c — see passes.h. */
#include "scheduler/passes.h"

#include <string.h>
#include <time.h>

typedef struct pass_ctx {
    const rs_render_hooks *hooks;
    rs_render_stats *stats;
    int whole_calls; /* the device is not told of a cancel: each call ends on whole samples */
} pass_ctx;

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int pass_cancelled(void *user)
{
    const pass_ctx *p = (const pass_ctx *)user;
    return p->hooks && p->hooks->cancel && atomic_load(p->hooks->cancel);
}

static int device_cancelled(void *user)
{
    const pass_ctx *p = (const pass_ctx *)user;
    return !p->whole_calls && pass_cancelled(user);
}

/* The device calls this from one thread at a time. */
static void pass_progress(void *user, uint64_t paths)
{
    pass_ctx *p = (pass_ctx *)user;
    p->stats->paths_done += paths;
    if (p->hooks && p->hooks->progress)
        p->hooks->progress(p->hooks->user, p->stats->paths_done, p->stats->paths_total);
}

rs_status rs_render_passes(const rs_scene *scene, rs_device *d, const rs_render_settings *st,
                           const rs_render_hooks *hooks, rs_film *film, rs_render_stats *stats)
{
    rs_integrator it;
    rs_pass_job job;
    rs_path_counts counts = {0, 0, 0};
    pass_ctx p;
    rs_status status;
    double t_start = now_s();
    uint32_t s0, s_begin, s_end, per;
    /* a time limit or a reader of the film needs the film on whole samples between calls */
    int consistent = hooks && (hooks->time_limit_s > 0 || hooks->film_ready);

    memset(stats, 0, sizeof *stats);
    if ((status = rs_render_constants(scene, st, film, &it)) != RS_OK)
        return status;
    if (!d->ops->render_pass)
        return rs_error_set(RS_ERR_ARG, "device %s cannot run the megakernel", d->name);
    if (st->pixels)
        return rs_error_set(RS_ERR_ARG, "the megakernel renders whole images only: adaptive "
                                        "sampling needs --integrator stream");
    if (st->path_begin % it.npix != 0)
        return rs_error_set(RS_ERR_ARG,
                            "the megakernel continues from whole passes only, and the film holds "
                            "%llu samples of %u pixels (use --integrator stream)",
                            (unsigned long long)st->path_begin, it.npix);
    /* samples [sample_base + path_begin / npix, sample_base + spp) (a pass of an MPI job starts
     * at a later sample) */
    s_begin = st->sample_base + (uint32_t)(st->path_begin / it.npix);
    s_end = st->sample_base + st->spp;
    it.sample_base = 0; /* the devices number paths by their absolute sample, s * npix + pixel */
    stats->paths_total = (uint64_t)it.npix * st->spp - st->path_begin;
    if (d->ops->pass_begin && (status = d->ops->pass_begin(d, scene, &it)) != RS_OK)
        return status;
    p.hooks = hooks;
    p.stats = stats;
    /* the CPU's per-pixel loop (pass_samples 0) stops within a sample on a cancel: with
     * `consistent` it gets one sample per call and runs each call to its end instead (the same
     * image: each pixel still sums its samples in sample order); the GPU devices stop between
     * samples anyway */
    p.whole_calls = consistent && d->pass_samples == 0;
    memset(&job, 0, sizeof job);
    job.it = &it;
    job.film = film;
    job.strategy = st->strategy;
    job.cancelled = device_cancelled;
    job.progress = pass_progress;
    job.user = &p;
    per = d->pass_samples ? d->pass_samples : (consistent ? 1 : st->spp);
    for (s0 = s_begin; s0 < s_end && status == RS_OK; s0 += per) {
        uint32_t n = s_end - s0 < per ? s_end - s0 : per;
        double t0, t1;
        if (pass_cancelled(&p))
            break;
        if (hooks && hooks->time_limit_s > 0 && s0 > s_begin &&
            now_s() - t_start >= hooks->time_limit_s) {
            stats->time_limited = 1;
            break;
        }
        t0 = now_s();
        status = d->ops->render_pass(d, &job, s0, n, &counts);
        t1 = now_s();
        stats->stage_s[RS_STAGE_PASS] += t1 - t0;
        if (st->timeline) {
            /* the device's lane: one span per call, labelled with its first sample */
            double e = rs_timeline_now(st->timeline);
            rs_timeline_add(st->timeline, 0, RS_STAGE_PASS, s0, e - (t1 - t0), e);
        }
        /* the devices count whole samples only (a cancelled pass is left out of the film) */
        if (status == RS_OK && hooks && hooks->film_ready)
            hooks->film_ready(hooks->user, film, st->path_begin + stats->paths_done);
    }
    stats->rays_closest = counts.closest;
    stats->rays_shadow = counts.shadow;
    stats->max_bounce = counts.max_bounce;
    stats->waves = (s0 - s_begin) / (per ? per : 1);
    if (status == RS_OK && pass_cancelled(&p))
        status = rs_error_set(RS_ERR_CANCELLED, "render interrupted");
    stats->seconds = now_s() - t_start;
    return status;
}
