/* scheduler/run.c — one run of a plan, as every part of the engine sees it (engine_impl.h's
 * rs_run_*): whether it is cancelled, where the time limit cuts it, the next range, a share for
 * one participant (guided self-scheduling), and the record of the paths on the film.  Apart from
 * engine.c, which starts runs, so that the parts that carry them out (stream_engine.c, passes.c,
 * wavefront.c) call down into this file and never back up into the engine's. */
#include <string.h>

#include "core/clock.h"
#include "scheduler/engine_impl.h"

/* The fewest paths a guided share falls to. */
#define RS_PATHS_MIN_SHARE 4096ull

int rs_run_cancelled(const rs_run *c)
{
    return c->hooks && c->hooks->cancel && atomic_load(c->hooks->cancel);
}

uint64_t rs_run_time_cut(rs_run *c, uint64_t next)
{
    const rs_engine *e = c->e;
    uint64_t n = c->map.n_active, end;
    uint32_t k;
    end = rs_work_plan_time_cut(c->plan, e->it.npix, rs_now_s() - e->t_start, next, e->any_done);
    if (end == UINT64_MAX)
        return end;
    /* The paths between the plan's ranges are on the film already (a checkpoint's, which has
     * gaps where devices finished ranges out of order): where such paths lie past `end`, the
     * passes they are in are finished too, so that every pixel ends with the same samples.
     * Scanning the later ranges in order: one that starts past `end` after a gap moves `end` to
     * the end of its start's pass, which may take in the next. */
    for (k = c->range + 1; k < c->n_ranges; ++k) {
        uint64_t lo = c->plan->todo.r[k][0];
        if (lo > end && lo > c->plan->todo.r[k - 1][1])
            end = (lo + n - 1) / n * n;
    }
    if (end < c->end_path || c->range + 1 < c->n_ranges) {
        int dropped = end < c->end_path;
        if (end < c->end_path)
            c->end_path = end > c->next_path ? end : c->next_path;
        /* later ranges: those that start before `end` stay, the last cut there (rs_run_more) */
        for (k = c->range + 1; k < c->n_ranges && c->plan->todo.r[k][0] < end; ++k)
            dropped |= c->plan->todo.r[k][1] > end;
        dropped |= k < c->n_ranges;
        c->n_ranges = k;
        c->cut = end;
        if (dropped)
            c->stats->time_limited = 1;
    }
    return end;
}

int rs_run_more(rs_run *c)
{
    if (c->n_redo)
        return 1;
    while (c->next_path >= c->end_path && c->range + 1 < c->n_ranges) {
        c->range++;
        c->next_path = c->plan->todo.r[c->range][0];
        c->end_path = c->plan->todo.r[c->range][1];
        if (c->end_path > c->cut) /* the time limit's cut (rs_run_time_cut) */
            c->end_path = c->cut > c->next_path ? c->cut : c->next_path;
    }
    return c->next_path < c->end_path;
}

rs_status rs_run_on_film(rs_run *c, uint64_t lo, uint64_t hi)
{
    if (!rs_path_ranges_add(&c->e->done, lo, hi))
        return rs_error_set(RS_ERR_NOMEM, "out of memory for the render's record of its paths");
    if (c->hooks && c->hooks->film_ready)
        c->hooks->film_ready(c->hooks->user, c->film, &c->e->done);
    return RS_OK;
}

/* Paths left in the plan from the run's position. */
static uint64_t paths_left(const rs_run *c)
{
    uint64_t left = c->end_path > c->next_path ? c->end_path - c->next_path : 0;
    uint32_t r;
    for (r = c->range + 1; r < c->n_ranges; ++r)
        left += c->plan->todo.r[r][1] - c->plan->todo.r[r][0];
    return left;
}

int rs_run_take(rs_run *c, int who, uint64_t most, uint64_t *lo, uint64_t *n)
{
    int got = 0;
    rs_run_lock(c);
    if (c->n_redo) {
        uint64_t *r = c->redo[c->n_redo - 1];
        *lo = r[0];
        *n = r[1] - r[0] < most ? r[1] - r[0] : most;
        r[0] += *n;
        if (r[0] == r[1])
            c->n_redo--;
        got = 1;
    } else if (!rs_run_cancelled(c)) {
        (void)rs_run_time_cut(c, c->next_path);
        if (rs_run_more(c)) {
            uint64_t left = c->end_path - c->next_path, want = most;
            if (c->lock && c->rate[who] <= 0) {
                /* its first take, rate unknown: at most a quarter of an even share, and the
                 * stream engine (far slower than a GPU) a small wave per thread */
                uint64_t even = paths_left(c) / (4u * (uint64_t)(c->e->n_pdev + 1));
                if (who == c->e->n_pdev && want > (uint64_t)RS_RENDER_HOST_WAVE * c->e->st.threads)
                    want = (uint64_t)RS_RENDER_HOST_WAVE * c->e->st.threads;
                if (want > even)
                    want = even > RS_PATHS_MIN_SHARE ? even : RS_PATHS_MIN_SHARE;
            } else if (c->lock) {
                /* a share of what is left, in proportion to this one's rate, about a quarter
                 * of the time everyone together still needs (and never over `most`) */
                double total = 0.0, t;
                int k;
                for (k = 0; k <= c->e->n_pdev; ++k)
                    total += c->rate[k];
                t = (double)paths_left(c) / total / 4.0;
                t = c->rate[who] * t;
                want = t < (double)RS_PATHS_MIN_SHARE ? RS_PATHS_MIN_SHARE
                       : t < (double)most             ? (uint64_t)t
                                                      : most;
            }
            if (want > most) /* never past what the taker can hold (a wave's buffers) */
                want = most;
            *lo = c->next_path;
            *n = left < want ? left : want;
            c->next_path += *n;
            got = 1;
        }
    }
    rs_run_unlock(c);
    return got;
}

