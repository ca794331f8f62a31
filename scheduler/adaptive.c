/* scheduler/adaptive.c — see adaptive.h. */
#include "scheduler/adaptive.h"

#include <string.h>
#include <time.h>

#include "core/alloc.h"

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* A round's progress as the whole render's: the samples of earlier rounds and of stopped
 * pixels (as if they had run to spp) are done. */
typedef struct progress_ctx {
    const rs_render_hooks *outer;
    uint64_t done_before, total;
} progress_ctx;

static void round_progress(void *user, uint64_t done, uint64_t total)
{
    const progress_ctx *p = (const progress_ctx *)user;
    (void)total;
    p->outer->progress(p->outer->user, p->done_before + done, p->total);
}


rs_status rs_render_adaptive(const rs_scene *scene, rs_sched *sched,
                             const rs_render_settings *settings, const rs_adaptive *a,
                             const rs_render_hooks *hooks, rs_film *film, rs_render_stats *stats,
                             rs_adaptive_stats *as)
{
    const uint32_t w = settings->width, h = settings->height, spp = settings->spp;
    const size_t npix = (size_t)w * h;
    rs_render_settings r = *settings;
    rs_render_hooks rh;
    progress_ctx pc;
    rs_render_stats one;
    uint8_t *running = NULL, *need = NULL;
    uint32_t *list = NULL, n;
    double t0 = now_s();
    rs_status st = RS_OK;
    memset(stats, 0, sizeof *stats);
    memset(as, 0, sizeof *as);
    if (!(a->threshold > 0) || a->min_spp < 2)
        return rs_error_set(RS_ERR_ARG, "adaptive sampling needs a threshold > 0 and at least 2 "
                                        "samples before any pixel stops");
    if (settings->path_begin || settings->pixels || settings->sample_base)
        return rs_error_set(RS_ERR_ARG, "adaptive sampling starts from an empty film");
    if (hooks && hooks->film_ready)
        return rs_error_set(RS_ERR_ARG, "adaptive sampling cannot be checkpointed yet");
    if ((st = rs_film_track_variance(film)) != RS_OK)
        return st;
    running = (uint8_t *)rs_alloc(npix ? npix : 1, 1);
    need = (uint8_t *)rs_alloc(npix ? npix : 1, 1);
    list = (uint32_t *)rs_alloc(npix ? npix : 1, sizeof *list);
    if (!running || !need || !list) {
        st = rs_error_set(RS_ERR_NOMEM, "out of memory for adaptive sampling");
        goto out;
    }
    memset(running, 1, npix);
    if (hooks)
        rh = *hooks;
    else
        memset(&rh, 0, sizeof rh);
    pc.outer = hooks;
    pc.total = (uint64_t)npix * spp;
    pc.done_before = 0;
    if (hooks && hooks->progress) {
        rh.progress = round_progress;
        rh.user = &pc;
    }
    r.spp_total = spp;
    for (n = 0; n < spp;) {
        uint32_t step, count = 0;
        size_t p;
        if (n == 0) {
            step = a->min_spp < spp ? a->min_spp : spp; /* every pixel */
            r.pixels = NULL;
            r.n_pixels = 0;
        } else {
            int x, y;
            /* who goes on: the noisy pixels still running, and their running neighbours */
            for (p = 0; p < npix; ++p)
                need[p] = running[p] && rs_film_rel_error(film, (uint32_t)p) > a->threshold;
            for (y = 0; y < (int)h; ++y)
                for (x = 0; x < (int)w; ++x) {
                    int dx, dy, go = 0;
                    p = (size_t)y * w + (size_t)x;
                    if (!running[p])
                        continue;
                    for (dy = -1; dy <= 1 && !go; ++dy)
                        for (dx = -1; dx <= 1 && !go; ++dx) {
                            int xx = x + dx, yy = y + dy;
                            go = xx >= 0 && yy >= 0 && xx < (int)w && yy < (int)h &&
                                 need[(size_t)yy * w + (size_t)xx];
                        }
                    if (go)
                        list[count++] = (uint32_t)p;
                    else {
                        running[p] = 0;
                        as->stopped++;
                        pc.done_before += spp - n; /* counted as done */
                    }
                }
            if (count == 0)
                break;
            step = n / 4 > 4 ? n / 4 : 4;
            step = step < spp - n ? step : spp - n;
            r.pixels = list;
            r.n_pixels = count;
        }
        r.sample_base = n;
        r.spp = step;
        if (hooks && hooks->time_limit_s > 0) {
            double left = hooks->time_limit_s - (now_s() - t0);
            if (n > 0 && left <= 0) {
                stats->time_limited = 1;
                break;
            }
            rh.time_limit_s = left > 1e-6 ? left : 1e-6;
        }
        st = rs_render(scene, sched, &r, &rh, film, &one);
        rs_render_stats_add(stats, &one);
        as->rounds++;
        as->samples += one.paths_done;
        pc.done_before += one.paths_done;
        if (st != RS_OK || one.time_limited)
            break;
        n += step;
    }
out:
    rs_free(running);
    rs_free(need);
    rs_free(list);
    stats->seconds = now_s() - t0;
    return st;
}
