/* app/dist_passes.c — rank 0's table of passes: job->plan.todo (path ranges over the job's pixels, whole
 * samples) cut into passes of pass_spp samples of
 * every pixel, each free, handed out to a rank, done there (not yet on the frame) or merged
 * into the frame.  Handed out lowest first; a rank lost frees its passes for the others. */
#include <string.h>

#include "app/dist_internal.h"
#include "core/alloc.h"

uint32_t passes_auto_spp(const rs_dist_job *job, uint32_t npix, int ranks)
{
    /* about 8 passes a rank, so that a slow one costs little at the end, and at most about
     * 2^21 paths (1-2 s on one core), so that a stop, which drops the passes under way, loses
     * little */
    uint32_t left = (uint32_t)(rs_path_ranges_total(&job->plan.todo) / npix), most = (1u << 21) / npix;
    uint32_t spp = left / (8u * (uint32_t)ranks);
    if (spp > most)
        spp = most;
    if (spp < 1)
        spp = 1;
    return spp;
}

/* Range k of job->plan.todo as samples: [*s0, *end) of every pixel of the job. */
static void todo_samples(const passes *t, const rs_dist_job *job, uint32_t k, uint32_t *s0,
                         uint32_t *end)
{
    *s0 = (uint32_t)(job->plan.todo.r[k][0] / t->npix);
    *end = (uint32_t)(job->plan.todo.r[k][1] / t->npix);
}

int passes_make(passes *t, const rs_dist_job *job)
{
    uint32_t i, n = 0, s0, end;
    for (i = 0; i < job->plan.todo.n; ++i) {
        todo_samples(t, job, i, &s0, &end);
        n += (end - s0 + t->pass_spp - 1) / t->pass_spp;
    }
    t->n_passes = n;
    t->limit = n;
    t->todo_paths = rs_path_ranges_total(&job->plan.todo);
    t->ps0 = (uint32_t *)rs_calloc(n ? n : 1, sizeof *t->ps0);
    t->pn = (uint32_t *)rs_calloc(n ? n : 1, sizeof *t->pn);
    if (!t->ps0 || !t->pn)
        return 0;
    for (i = 0, n = 0; i < job->plan.todo.n; ++i) {
        todo_samples(t, job, i, &s0, &end);
        for (; s0 < end; s0 += t->pass_spp, ++n) {
            t->ps0[n] = s0;
            t->pn[n] = end - s0 < t->pass_spp ? end - s0 : t->pass_spp;
        }
    }
    t->state = (uint8_t *)rs_calloc(t->n_passes ? t->n_passes : 1, 1);
    t->owner = (int *)rs_calloc(t->n_passes ? t->n_passes : 1, sizeof *t->owner);
    if (!t->state || !t->owner)
        return 0;
    for (i = 0; i < t->n_passes; ++i)
        t->owner[i] = -1;
    return 1;
}

void passes_free(passes *t)
{
    rs_free(t->state);
    rs_free(t->owner);
    rs_free(t->ps0);
    rs_free(t->pn);
}

uint32_t passes_of(const passes *t, uint32_t s0)
{
    uint32_t lo = 0, hi = t->n_passes;
    while (lo < hi) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (t->ps0[mid] < s0)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo < t->n_passes && t->ps0[lo] == s0 ? lo : t->n_passes;
}

uint32_t passes_next_free(const passes *t)
{
    uint32_t p;
    for (p = 0; p < t->limit; ++p)
        if (t->state[p] == P_FREE)
            return p;
    return t->n_passes;
}

uint32_t passes_count(const passes *t, int state, uint32_t below)
{
    uint32_t p, k = 0;
    for (p = 0; p < below; ++p)
        k += t->state[p] == state;
    return k;
}

void passes_assign(passes *t, uint32_t p, int r)
{
    if (t->state[p] == P_FREE && t->owner[p] != -1)
        (*t->reissued)++;
    t->state[p] = P_ASSIGNED;
    t->owner[p] = r;
}

void passes_release(passes *t, int r)
{
    uint32_t p;
    for (p = 0; p < t->n_passes; ++p)
        if (t->owner[p] == r && (t->state[p] == P_ASSIGNED || t->state[p] == P_DONE)) {
            t->state[p] = P_FREE; /* owner kept: passes_assign counts it as reissued */
        }
}

uint64_t passes_paths_done(const passes *t)
{
    uint64_t done = 0;
    uint32_t p;
    for (p = 0; p < t->n_passes; ++p)
        if (t->state[p] == P_DONE || t->state[p] == P_MERGED)
            done += (uint64_t)t->pn[p] * t->npix;
    return done;
}

int passes_merged_ranges(const passes *t, rs_path_ranges *out, uint32_t *samples)
{
    uint32_t p;
    memset(out, 0, sizeof *out);
    *samples = 0;
    for (p = 0; p < t->n_passes; ++p) {
        if (t->state[p] != P_MERGED)
            continue;
        *samples += t->pn[p];
        if (!rs_path_ranges_add(out, (uint64_t)t->ps0[p] * t->npix,
                                ((uint64_t)t->ps0[p] + t->pn[p]) * t->npix))
            return 0;
    }
    return 1;
}

uint64_t passes_begun_end(const passes *t)
{
    /* handed out lowest first: those below the last begun were all begun (or handed out again
     * after a rank was lost) */
    uint32_t p;
    for (p = t->n_passes; p > 0; --p)
        if (t->state[p - 1] != P_FREE || t->owner[p - 1] != -1)
            return ((uint64_t)t->ps0[p - 1] + t->pn[p - 1]) * t->npix;
    return 0;
}

int passes_limit_to(passes *t, uint64_t end)
{
    uint32_t lim = 0;
    while (lim < t->n_passes && (uint64_t)t->ps0[lim] * t->npix < end)
        ++lim;
    if (lim < t->limit) {
        t->limit = lim;
        return 1;
    }
    return 0;
}
