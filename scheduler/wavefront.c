/* scheduler/wavefront.c — a run of a plan on a device that runs paths whole (render.h:
 * rs_engine_create_paths): the plan's ranges handed to the device's render_paths in calls of
 * about a quarter of a second of its measured rate, with Ctrl-C, the time limit, progress and
 * the film's record checked between calls.  The device runs the stream engine's stages itself
 * over path state in its own memory (gpu/wavefront.h) and adds each call's samples to the film
 * with exact sums, so the image is the CPU stream engine's bit for bit. */
#include <string.h>

#include "core/clock.h"
#include "scheduler/engine_impl.h"

/* The first call's paths (a GPU's wave), the fewest and the most per call. */
#define RS_PATHS_FIRST_CALL (1ull << 21)
#define RS_PATHS_MIN_CALL   (1ull << 16)
#define RS_PATHS_MAX_CALL   (1ull << 28)
/* Seconds of work per call once the device's rate is known. */
#define RS_PATHS_CALL_S 0.25

static int paths_cancelled(void *user) { return rs_run_cancelled((const rs_run *)user); }

rs_status rs_paths_run(rs_run *c)
{
    rs_engine *e = c->e;
    rs_device *d = e->mk;
    const rs_render_hooks *hooks = c->hooks;
    rs_paths_job job;
    rs_path_counts counts = {0, 0, 0};
    rs_status status = RS_OK;
    uint64_t per = RS_PATHS_FIRST_CALL;
    uint32_t calls = 0;

    memset(&job, 0, sizeof job);
    job.it = &e->it;
    job.pixel_of = c->map.pixel_of;
    job.n_active = c->map.n_active;
    job.plan_id = e->plan_id;
    job.film = c->film;
    job.cancelled = paths_cancelled;
    job.user = c;
    while (status == RS_OK && rs_run_more(c)) {
        uint64_t n, done = 0, lo;
        double t0, t1;
        if (rs_run_cancelled(c))
            break;
        (void)rs_run_time_cut(c, c->next_path);
        if (!rs_run_more(c))
            break;
        lo = c->next_path;
        n = c->end_path - lo < per ? c->end_path - lo : per;
        t0 = rs_now_s();
        status = d->ops->render_paths(d, &job, lo, lo + n, &done, &counts);
        t1 = rs_now_s();
        c->stats->stage_s[RS_STAGE_PASS] += t1 - t0;
        if (e->st.timeline) {
            double end = rs_timeline_now(e->st.timeline);
            rs_timeline_add(e->st.timeline, 0, RS_STAGE_PASS, calls, end - (t1 - t0), end);
        }
        calls++;
        c->next_path += n;
        c->stats->paths_done += done;
        if (hooks && hooks->progress)
            hooks->progress(hooks->user, c->stats->paths_done, c->stats->paths_total);
        if (status == RS_OK && done)
            status = rs_run_on_film(c, lo, lo + done);
        if (done < n)
            break; /* cancelled within the call: the finished waves are on the film */
        /* the next call: about RS_PATHS_CALL_S of this device's work */
        if (t1 > t0) {
            double want = (double)n / (t1 - t0) * RS_PATHS_CALL_S;
            per = want < (double)RS_PATHS_MIN_CALL   ? RS_PATHS_MIN_CALL
                  : want > (double)RS_PATHS_MAX_CALL ? RS_PATHS_MAX_CALL
                                                     : (uint64_t)want;
        }
    }
    c->stats->rays_closest = counts.closest;
    c->stats->rays_shadow = counts.shadow;
    c->stats->max_bounce = counts.max_bounce;
    c->stats->waves = calls;
    if (status == RS_OK && rs_run_cancelled(c))
        status = rs_error_set(RS_ERR_CANCELLED, "render interrupted");
    return status;
}
