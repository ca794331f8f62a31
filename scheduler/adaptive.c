/* scheduler/adaptive.c — see adaptive.h. */
#include "scheduler/adaptive.h"

#include <string.h>

#include "core/alloc.h"
#include "core/clock.h"

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

/* Which pixels go on after n samples: the noisy pixels still running, and their running
 * neighbours, listed in `list` (returns how many); the other running pixels stop, each counted
 * in *stopped and its samples up to spp in *skipped. */
static uint32_t next_round(const rs_film *film, double threshold, uint32_t spp, uint32_t n,
                           uint8_t *running, uint8_t *need, uint32_t *list, uint32_t *stopped,
                           uint64_t *skipped)
{
    const uint32_t w = film->width, h = film->height;
    const size_t npix = (size_t)w * h;
    uint32_t count = 0;
    size_t p;
    int x, y;
    for (p = 0; p < npix; ++p)
        need[p] = running[p] && rs_film_rel_error(film, (uint32_t)p) > threshold;
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
            if (go) {
                list[count++] = (uint32_t)p;
            } else {
                running[p] = 0;
                (*stopped)++;
                *skipped += spp - n;
            }
        }
    return count;
}

rs_status rs_render_adaptive(rs_engine *e, const rs_adaptive *a, const rs_render_hooks *hooks,
                             rs_film *film, rs_render_stats *stats, rs_adaptive_stats *as)
{
    const rs_render_settings *set = rs_engine_settings(e);
    const uint32_t spp = set->spp;
    const size_t npix = (size_t)set->width * set->height;
    rs_render_hooks rh;
    progress_ctx pc;
    rs_render_stats one;
    rs_work_plan plan;
    uint8_t *running = NULL, *need = NULL;
    uint32_t *list = NULL, n;
    double t0 = rs_now_s();
    rs_status st = RS_OK;
    memset(stats, 0, sizeof *stats);
    memset(as, 0, sizeof *as);
    memset(&plan, 0, sizeof plan);
    if (!(a->threshold > 0) || a->min_spp < 2)
        return rs_error_set(RS_ERR_ARG, "adaptive sampling needs a threshold > 0 and at least 2 "
                                        "samples before any pixel stops");
    if (set->path_begin)
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
    for (n = 0; n < spp;) {
        uint32_t step, count;
        if (n == 0) { /* every pixel */
            step = a->min_spp < spp ? a->min_spp : spp;
            plan.pixels = NULL;
            count = (uint32_t)npix;
        } else {
            count = next_round(film, a->threshold, spp, n, running, need, list, &as->stopped,
                               &pc.done_before);
            if (count == 0)
                break;
            step = n / 4 > 4 ? n / 4 : 4;
            step = step < spp - n ? step : spp - n;
            plan.pixels = list;
        }
        /* samples [n, n + step) of the round's pixels */
        plan.n_pixels = count;
        plan.todo.n = 0;
        if (!rs_path_ranges_add(&plan.todo, (uint64_t)count * n, (uint64_t)count * (n + step))) {
            st = rs_error_set(RS_ERR_NOMEM, "out of memory for adaptive sampling");
            break;
        }
        st = rs_engine_run(e, &plan, &rh, film, &one);
        rs_render_stats_add(stats, &one);
        as->rounds++;
        as->samples += one.paths_done;
        pc.done_before += one.paths_done;
        if (st != RS_OK || one.time_limited)
            break;
        n += step;
    }
out:
    rs_path_ranges_free(&plan.todo);
    rs_free(running);
    rs_free(need);
    rs_free(list);
    stats->seconds = rs_now_s() - t0;
    return st;
}
