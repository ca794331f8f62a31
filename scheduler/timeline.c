/* scheduler/timeline.c — see timeline.h.
 *
 * Invariants: `spans` holds `capacity` entries, allocated once at create; entries 0 .. n - 1 are
 * filled, in the order their rs_timeline_add calls took the lock; n <= capacity; every add past
 * capacity increments `dropped` instead.  `lock` guards n, dropped and the entries, so a reader
 * (rs_timeline_spans) sees only whole spans.  The clock is CLOCK_MONOTONIC, zero at create. */
#include "scheduler/timeline.h"

#include <pthread.h>

#include "core/alloc.h"
#include "core/clock.h"

struct rs_timeline {
    rs_span *spans;
    uint32_t capacity;
    uint32_t n;
    uint64_t dropped;
    double start;         /* rs_now_s at creation */
    pthread_mutex_t lock; /* held only for the few stores of one add (never across a call out) */
};

const char *rs_stage_name(rs_stage s)
{
    switch (s) {
    case RS_STAGE_RAYGEN: return "raygen";
    case RS_STAGE_TRACE_CLOSEST: return "trace-closest";
    case RS_STAGE_SHADE: return "shade";
    case RS_STAGE_TRACE_SHADOW: return "trace-shadow";
    case RS_STAGE_RESOLVE_SHADOWS: return "resolve-shadows";
    case RS_STAGE_COMPACT: return "compact";
    case RS_STAGE_FILM: return "film";
    case RS_STAGE_PASS: return "pass";
    case RS_STAGE_COUNT: break;
    }
    return "unknown";
}

rs_status rs_timeline_create(uint32_t capacity, rs_timeline **out)
{
    rs_timeline *t;
    if (!out)
        return rs_error_set(RS_ERR_ARG, "rs_timeline_create: no out pointer");
    *out = NULL;
    t = (rs_timeline *)rs_calloc(1, sizeof *t);
    if (!t)
        return rs_error_set(RS_ERR_NOMEM, "out of memory for the timeline");
    /* capacity 0 is allowed (every span is dropped); rs_alloc hands out a 1-byte block then */
    t->spans = (rs_span *)rs_alloc(capacity, sizeof *t->spans);
    if (!t->spans) {
        rs_free(t);
        return rs_error_set(RS_ERR_NOMEM, "out of memory for a timeline of %u spans",
                            (unsigned)capacity);
    }
    if (pthread_mutex_init(&t->lock, NULL) != 0) {
        rs_free(t->spans);
        rs_free(t);
        return rs_error_set(RS_ERR_NOMEM, "cannot create the timeline's lock");
    }
    t->capacity = capacity;
    t->start = rs_now_s();
    *out = t;
    return RS_OK;
}

void rs_timeline_destroy(rs_timeline *t)
{
    if (!t)
        return;
    pthread_mutex_destroy(&t->lock);
    rs_free(t->spans);
    rs_free(t);
}

double rs_timeline_now(const rs_timeline *t) { return t ? rs_now_s() - t->start : 0.0; }

void rs_timeline_add(rs_timeline *t, uint16_t lane, rs_stage stage, uint32_t wave, double t0,
                     double t1)
{
    rs_span s;
    if (!t)
        return;
    s.t0 = t0;
    s.t1 = t1 > t0 ? t1 : t0; /* a clock read out of order never makes a negative span */
    s.wave = wave;
    s.lane = lane;
    s.stage = (uint8_t)stage;
    s.unused = 0;
    pthread_mutex_lock(&t->lock);
    if (t->n < t->capacity)
        t->spans[t->n++] = s;
    else
        ++t->dropped;
    pthread_mutex_unlock(&t->lock);
}

const rs_span *rs_timeline_spans(const rs_timeline *t, uint32_t *n, uint64_t *dropped)
{
    /* the lock is not part of the log's value: taking it through a const handle is fine */
    pthread_mutex_t *lock;
    uint32_t count = 0;
    uint64_t lost = 0;
    if (t) {
        lock = (pthread_mutex_t *)&t->lock;
        pthread_mutex_lock(lock);
        count = t->n;
        lost = t->dropped;
        pthread_mutex_unlock(lock);
    }
    if (n)
        *n = count;
    if (dropped)
        *dropped = lost;
    return t ? t->spans : NULL;
}
