/* scheduler/passes.c — the megakernel's run of a plan (render.h): the plan's samples handed to
 * one device's render_pass in calls of d->pass_samples samples (all of a range for the CPU
 * device, whose pixel loop adds each pixel's samples one after the other; a few per call for a
 * GPU, which runs one pass over every pixel per sample), with Ctrl-C, the time limit and
 * progress checked between calls.  Each pixel gets its samples in sample order, so the image is
 * the stream engine's bit for bit.
 *
 * With a time limit or a film_ready hook the film must end every call on whole samples: the CPU
 * device then gets one sample per call and is not told of a cancel (it would stop within a
 * sample), which the loop checks between calls instead. */
#include <string.h>

#include "core/clock.h"
#include "scheduler/engine_impl.h"

typedef struct pass_ctx {
    rs_run *c;
    uint64_t call_paths; /* the paths the call under way has put on the film */
    int whole_calls;     /* the device is not told of a cancel: each call ends on whole samples */
} pass_ctx;

static int pass_cancelled(void *user) { return rs_run_cancelled(((const pass_ctx *)user)->c); }

static int device_cancelled(void *user)
{
    const pass_ctx *p = (const pass_ctx *)user;
    return !p->whole_calls && pass_cancelled(user);
}

/* The device calls this from one thread at a time. */
static void pass_progress(void *user, uint64_t paths)
{
    pass_ctx *p = (pass_ctx *)user;
    rs_run *c = p->c;
    p->call_paths += paths;
    c->stats->paths_done += paths;
    if (c->hooks && c->hooks->progress)
        c->hooks->progress(c->hooks->user, c->stats->paths_done, c->stats->paths_total);
}

rs_status rs_passes_setup(rs_engine *e)
{
    rs_device *d = e->mk;
    return d->ops->upload_scene ? d->ops->upload_scene(d, e->scene, &e->it) : RS_OK;
}

rs_status rs_passes_run(rs_run *c)
{
    rs_engine *e = c->e;
    rs_device *d = e->mk;
    const rs_render_hooks *hooks = c->hooks;
    const uint64_t npix = c->e->it.npix;
    rs_pass_job job;
    rs_path_counts counts = {0, 0, 0};
    pass_ctx p;
    rs_status status = RS_OK;
    uint32_t per, calls = 0;
    /* a time limit or a reader of the film needs the film on whole samples between calls */
    int consistent = c->plan->time_limit_s > 0 || (hooks && hooks->film_ready);

    p.c = c;
    /* the CPU's per-pixel loop (pass_samples 0) stops within a sample on a cancel: with
     * `consistent` it gets one sample per call and runs each call to its end instead (the same
     * image: each pixel still sums its samples in sample order); the GPU devices stop between
     * samples anyway */
    p.whole_calls = consistent && d->pass_samples == 0;
    memset(&job, 0, sizeof job);
    job.it = &e->it;
    job.film = c->film;
    job.strategy = e->st.strategy;
    job.cancelled = device_cancelled;
    job.progress = pass_progress;
    job.user = &p;
    per = d->pass_samples ? d->pass_samples : (consistent ? 1 : e->st.spp);
    while (status == RS_OK && rs_run_more(c)) {
        /* samples [s0, s0 + n) of every pixel: paths s0 * npix + pixel */
        uint32_t s0 = (uint32_t)(c->next_path / npix), left;
        uint32_t n;
        double t0, t1;
        if (pass_cancelled(&p))
            break;
        (void)rs_run_time_cut(c, c->next_path);
        if (!rs_run_more(c))
            break;
        left = (uint32_t)((c->end_path - c->next_path) / npix);
        n = left < per ? left : per;
        p.call_paths = 0;
        t0 = rs_now_s();
        status = d->ops->render_pass(d, &job, s0, n, &counts);
        t1 = rs_now_s();
        c->stats->stage_s[RS_STAGE_PASS] += t1 - t0;
        if (e->st.timeline) {
            /* the device's lane: one span per call, labelled with its first sample */
            double end = rs_timeline_now(e->st.timeline);
            rs_timeline_add(e->st.timeline, 0, RS_STAGE_PASS, s0, end - (t1 - t0), end);
        }
        calls++;
        c->next_path += (uint64_t)n * npix;
        /* the devices count whole samples only (a cancelled pass is left out of the film) */
        if (status == RS_OK && p.call_paths)
            status = rs_run_on_film(c, (uint64_t)s0 * npix, (uint64_t)s0 * npix + p.call_paths);
    }
    c->stats->rays_closest = counts.closest;
    c->stats->rays_shadow = counts.shadow;
    c->stats->max_bounce = counts.max_bounce;
    c->stats->waves = calls;
    if (status == RS_OK && pass_cancelled(&p))
        status = rs_error_set(RS_ERR_CANCELLED, "render interrupted");
    return status;
}
