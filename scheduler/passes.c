/* scheduler/passes.c — see passes.h. */
#include "scheduler/passes.h"

#include <string.h>
#include <time.h>

typedef struct pass_ctx {
    const rs_render_hooks *hooks;
    rs_render_stats *stats;
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
    uint32_t s0, per;

    memset(stats, 0, sizeof *stats);
    if ((status = rs_render_constants(scene, st, film, &it)) != RS_OK)
        return status;
    if (!d->ops->render_pass)
        return rs_error_set(RS_ERR_ARG, "device %s cannot run the megakernel", d->name);
    stats->paths_total = (uint64_t)it.npix * st->spp;
    if (d->ops->pass_begin && (status = d->ops->pass_begin(d, scene, &it)) != RS_OK)
        return status;
    p.hooks = hooks;
    p.stats = stats;
    memset(&job, 0, sizeof job);
    job.it = &it;
    job.film = film;
    job.strategy = st->strategy;
    job.cancelled = pass_cancelled;
    job.progress = pass_progress;
    job.user = &p;
    per = d->pass_samples ? d->pass_samples : st->spp;
    for (s0 = 0; s0 < st->spp && status == RS_OK; s0 += per) {
        uint32_t n = st->spp - s0 < per ? st->spp - s0 : per;
        double t0, t1;
        if (pass_cancelled(&p))
            break;
        t0 = now_s();
        status = d->ops->render_pass(d, &job, s0, n, &counts);
        t1 = now_s();
        stats->stage_s[RS_STAGE_PASS] += t1 - t0;
        if (st->timeline) {
            /* the device's lane: one span per call, labelled with its first sample */
            double e = rs_timeline_now(st->timeline);
            rs_timeline_add(st->timeline, 0, RS_STAGE_PASS, s0, e - (t1 - t0), e);
        }
    }
    stats->rays_closest = counts.closest;
    stats->rays_shadow = counts.shadow;
    stats->max_bounce = counts.max_bounce;
    stats->waves = s0 / (per ? per : 1);
    if (status == RS_OK && pass_cancelled(&p))
        status = rs_error_set(RS_ERR_CANCELLED, "render interrupted");
    stats->seconds = now_s() - t_start;
    return status;
}
