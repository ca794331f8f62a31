/* scheduler/plan.c — see plan.h. */
#include "scheduler/plan.h"

#include <stdlib.h>
#include <string.h>

int rs_path_ranges_add(rs_path_ranges *s, uint64_t lo, uint64_t hi)
{
    uint32_t i, j;
    if (lo >= hi)
        return 1;
    /* the first range that ends at or after lo: it and the following ones up to hi join */
    for (i = 0; i < s->n && s->r[i][1] < lo; ++i) {
    }
    for (j = i; j < s->n && s->r[j][0] <= hi; ++j) {
        if (s->r[j][0] < lo)
            lo = s->r[j][0];
        if (s->r[j][1] > hi)
            hi = s->r[j][1];
    }
    if (j == i) { /* nothing joined: a new range at i */
        if (s->n >= RS_PATH_RANGES_MAX)
            return 0;
        if (s->n == s->cap) {
            uint32_t cap = s->cap ? 2 * s->cap : 8;
            void *r = realloc(s->r, cap * sizeof *s->r);
            if (!r)
                return 0;
            s->r = (uint64_t(*)[2])r;
            s->cap = cap;
        }
        memmove(s->r + i + 1, s->r + i, (s->n - i) * sizeof *s->r);
        s->n++;
    } else if (j > i + 1) { /* ranges i..j-1 became one */
        memmove(s->r + i + 1, s->r + j, (s->n - j) * sizeof *s->r);
        s->n -= j - i - 1;
    }
    s->r[i][0] = lo;
    s->r[i][1] = hi;
    return 1;
}

int rs_path_ranges_union(rs_path_ranges *a, const rs_path_ranges *b)
{
    uint32_t i;
    for (i = 0; i < b->n; ++i)
        if (!rs_path_ranges_add(a, b->r[i][0], b->r[i][1]))
            return 0;
    return 1;
}

int rs_path_ranges_complement(const rs_path_ranges *s, uint64_t end, rs_path_ranges *out)
{
    uint64_t cur = 0;
    uint32_t i;
    for (i = 0; i <= s->n && cur < end; ++i) {
        uint64_t lo = i < s->n ? s->r[i][0] : end;
        if (!rs_path_ranges_add(out, cur, lo < end ? lo : end))
            return 0;
        if (i < s->n)
            cur = s->r[i][1];
    }
    return 1;
}

uint64_t rs_path_ranges_total(const rs_path_ranges *s)
{
    uint64_t t = 0;
    uint32_t i;
    for (i = 0; i < s->n; ++i)
        t += s->r[i][1] - s->r[i][0];
    return t;
}

int rs_path_ranges_is_prefix(const rs_path_ranges *s)
{
    return s->n == 0 || (s->n == 1 && s->r[0][0] == 0);
}

void rs_path_ranges_free(rs_path_ranges *s)
{
    free(s->r);
    memset(s, 0, sizeof *s);
}

int rs_work_plan_samples(rs_work_plan *p, uint64_t npix, uint32_t s0, uint32_t s1)
{
    memset(p, 0, sizeof *p);
    return rs_path_ranges_add(&p->todo, npix * s0, npix * s1);
}

uint64_t rs_work_plan_time_cut(const rs_work_plan *p, uint64_t npix, double elapsed_s,
                               uint64_t begun, int first_done)
{
    uint64_t n = p->pixels ? p->n_pixels : npix, end;
    if (!(p->time_limit_s > 0) || elapsed_s < p->time_limit_s || n == 0)
        return UINT64_MAX;
    end = (begun + n - 1) / n * n;
    if (!first_done && p->todo.n) { /* the render's first pass is always finished */
        uint64_t first = (p->todo.r[0][0] / n + 1) * n;
        if (end < first)
            end = first;
    }
    return end;
}

void rs_work_plan_free(rs_work_plan *p)
{
    rs_path_ranges_free(&p->todo);
    memset(p, 0, sizeof *p);
}
