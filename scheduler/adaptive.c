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
    void *run; /* the adaptive_run it belongs to */
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

rs_status rs_adaptive_state_init(rs_adaptive_state *s, uint32_t npix)
{
    memset(s, 0, sizeof *s);
    s->running = (uint8_t *)rs_alloc(npix ? npix : 1, 1);
    if (!s->running)
        return rs_error_set(RS_ERR_NOMEM, "out of memory for adaptive sampling");
    memset(s->running, 1, npix);
    return RS_OK;
}

void rs_adaptive_state_free(rs_adaptive_state *s)
{
    rs_free(s->running);
    memset(s, 0, sizeof *s);
}

int rs_adaptive_state_fits(const rs_adaptive_state *s, const uint32_t *count, uint32_t npix,
                           uint32_t spp)
{
    uint64_t in_round = 0, running = 0;
    uint32_t p;
    if ((uint64_t)s->n + s->step > spp)
        return 0;
    for (p = 0; p < npix; ++p) {
        if (s->running[p] > 1)
            return 0;
        if (!s->running[p] && count[p] > s->n)
            return 0;
        if (s->running[p] && (count[p] < s->n || count[p] > s->n + s->step))
            return 0;
        in_round += s->running[p] ? count[p] - s->n : 0;
        running += s->running[p];
    }
    return in_round == s->round_done && s->round_done <= running * s->step;
}

/* One adaptive render: the engine, the state and what the rounds share. */
typedef struct adaptive_run {
    rs_plan_runner run; /* runs one plan onto the film */
    void *run_user;
    uint32_t spp;
    const rs_adaptive *a;
    rs_adaptive_state *s;
    const rs_render_hooks *outer;
    rs_render_hooks hooks; /* the outer ones, progress and film_ready seen through the run's */
    progress_ctx pc;
    rs_film *film;
    rs_render_stats *stats;
    uint64_t round_base; /* the round's paths on the film before the run under way */
    uint8_t *need;
    uint32_t *list;
} adaptive_run;

/* The film holds the run's `done` paths of the round: the state says so before the outer hook
 * (a checkpoint) sees the film. */
static void round_film_ready(void *user, const rs_film *film, const rs_path_ranges *done)
{
    adaptive_run *r = (adaptive_run *)((const progress_ctx *)user)->run;
    r->s->round_done = r->round_base + rs_path_ranges_total(done);
    r->outer->film_ready(r->outer->user, film, done);
}

/* Runs the round under way (r->s->step > 0) from where the film stands: its pixels are the
 * running ones, listed; returns the engine's status, *limited when the time limit cut it. */
static rs_status run_round(adaptive_run *r, int *limited)
{
    rs_adaptive_state *s = r->s;
    const uint32_t npix = r->film->width * r->film->height;
    rs_render_stats one;
    rs_work_plan plan;
    rs_status st;
    uint32_t count = 0, p;
    for (p = 0; p < npix; ++p)
        if (s->running[p])
            r->list[count++] = p;
    memset(&plan, 0, sizeof plan);
    plan.time_limit_s = r->a->time_limit_s;
    if (count < npix) { /* every pixel is the image's own numbering */
        plan.pixels = r->list;
        plan.n_pixels = count;
    }
    if (!rs_path_ranges_add(&plan.todo, (uint64_t)count * s->n + s->round_done,
                            (uint64_t)count * (s->n + s->step)))
        return rs_error_set(RS_ERR_NOMEM, "out of memory for adaptive sampling");
    r->round_base = s->round_done;
    memset(&one, 0, sizeof one);
    st = r->run(r->run_user, &plan, &r->hooks, r->film, &one);
    rs_work_plan_free(&plan);
    s->round_done = r->round_base + one.paths_done;
    rs_render_stats_add(r->stats, &one);
    s->stats.samples += one.paths_done;
    r->pc.done_before += one.paths_done;
    *limited = one.time_limited;
    if (st == RS_OK && !one.time_limited) { /* the round is done */
        s->n += s->step;
        s->step = 0;
        s->round_done = 0;
    }
    return st;
}

/* Decides the next round from the film (s->step == 0): its samples, or 0 when every pixel has
 * stopped or has spp samples. */
static uint32_t decide_round(adaptive_run *r)
{
    rs_adaptive_state *s = r->s;
    const uint32_t spp = r->spp;
    uint32_t step;
    if (s->n >= spp)
        return 0;
    if (s->n == 0) /* every pixel, min_spp samples */
        return r->a->min_spp < spp ? r->a->min_spp : spp;
    if (next_round(r->film, r->a->threshold, spp, s->n, s->running, r->need, r->list,
                   &s->stats.stopped, &r->pc.done_before) == 0)
        return 0;
    step = s->n / 4 > 4 ? s->n / 4 : 4;
    return step < spp - s->n ? step : spp - s->n;
}

/* What adaptive sampling needs before it begins or continues; the progress context. */
static rs_status adaptive_begin(adaptive_run *r, const rs_render_hooks *hooks)
{
    const uint32_t npix = r->film->width * r->film->height, spp = r->spp;
    rs_adaptive_state *s = r->s;
    uint32_t p;
    rs_status st;
    if (!(r->a->threshold > 0) || r->a->min_spp < 2)
        return rs_error_set(RS_ERR_ARG, "adaptive sampling needs a threshold > 0 and at least 2 "
                                        "samples before any pixel stops");
    if (!s->running) {
        if (rs_film_samples(r->film))
            return rs_error_set(RS_ERR_ARG, "adaptive sampling starts from an empty film");
        if ((st = rs_film_track_variance(r->film)) != RS_OK ||
            (st = rs_adaptive_state_init(s, npix)) != RS_OK)
            return st;
    } else if (!r->film->sum_l2 || !rs_adaptive_state_fits(s, r->film->count, npix, spp)) {
        return rs_error_set(RS_ERR_ARG, "adaptive sampling continues a film of its own only");
    }
    r->need = (uint8_t *)rs_alloc(npix ? npix : 1, 1);
    r->list = (uint32_t *)rs_alloc(npix ? npix : 1, sizeof *r->list);
    if (!r->need || !r->list)
        return rs_error_set(RS_ERR_NOMEM, "out of memory for adaptive sampling");
    /* done so far: the film's samples, and the samples stopped pixels will never take */
    r->pc.outer = hooks;
    r->pc.total = (uint64_t)npix * spp;
    r->pc.done_before = 0;
    r->pc.run = r;
    for (p = 0; p < npix; ++p)
        r->pc.done_before += s->running[p] ? r->film->count[p] : spp;
    if (hooks)
        r->hooks = *hooks;
    else
        memset(&r->hooks, 0, sizeof r->hooks);
    r->hooks.user = &r->pc;
    r->hooks.progress = hooks && hooks->progress ? round_progress : NULL;
    r->hooks.film_ready = hooks && hooks->film_ready ? round_film_ready : NULL;
    r->outer = hooks;
    return RS_OK;
}

rs_status rs_adaptive_run_plans(rs_plan_runner run, void *user, uint32_t spp,
                                const rs_adaptive *a, rs_adaptive_state *state,
                                const rs_render_hooks *hooks, rs_film *film,
                                rs_render_stats *stats)
{
    adaptive_run r;
    double t0 = rs_now_s();
    rs_status st;
    int limited = 0;
    memset(stats, 0, sizeof *stats);
    memset(&r, 0, sizeof r);
    r.run = run;
    r.run_user = user;
    r.spp = spp;
    r.a = a;
    r.s = state;
    r.film = film;
    r.stats = stats;
    st = adaptive_begin(&r, hooks);
    while (st == RS_OK && !limited) {
        if (state->step == 0) {
            if ((state->step = decide_round(&r)) == 0)
                break;
            state->stats.rounds++;
        }
        st = run_round(&r, &limited);
    }
    rs_free(r.need);
    rs_free(r.list);
    stats->seconds = rs_now_s() - t0;
    return st;
}

static rs_status engine_plan(void *user, const rs_work_plan *plan, const rs_render_hooks *hooks,
                             rs_film *film, rs_render_stats *stats)
{
    return rs_engine_run((rs_engine *)user, plan, hooks, film, stats);
}

rs_status rs_adaptive_run(rs_engine *e, const rs_adaptive *a, rs_adaptive_state *state,
                          const rs_render_hooks *hooks, rs_film *film, rs_render_stats *stats)
{
    if (rs_engine_settings(e)->path_begin) {
        memset(stats, 0, sizeof *stats);
        return rs_error_set(RS_ERR_ARG, "adaptive sampling starts from an empty film");
    }
    return rs_adaptive_run_plans(engine_plan, e, rs_engine_settings(e)->spp, a, state, hooks,
                                 film, stats);
}

rs_status rs_render_adaptive(rs_engine *e, const rs_adaptive *a, const rs_render_hooks *hooks,
                             rs_film *film, rs_render_stats *stats, rs_adaptive_stats *astats)
{
    rs_adaptive_state s;
    rs_status st;
    memset(&s, 0, sizeof s);
    st = rs_adaptive_run(e, a, &s, hooks, film, stats);
    *astats = s.stats;
    rs_adaptive_state_free(&s);
    return st;
}
