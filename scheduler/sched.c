/* scheduler/sched.c — dispatch threads, the shared bounded job queue and chunk sizing.
 *
 * Invariants (all under `lock`):
 *   - the queue holds the jobs that still have rays to hand out (next < count), oldest first;
 *     a job leaves it when its last ray is handed out (or when it fails);
 *   - every ray of a job is, at any time, exactly one of: not handed out (>= next), in a chunk
 *     held by one dispatch thread, in a chunk on `retry`, or answered; `remaining` counts all
 *     but the answered ones;
 *   - `alive` counts dispatch threads whose device has not failed; when it reaches 0 every
 *     waiting caller is woken and its job fails;
 *   - a failed device's chunk goes to `retry`.  Each device fails at most once and holds at
 *     most one chunk, so `retry` needs one slot per device.  Dispatch threads take retries
 *     first. */
#include "scheduler/sched.h"

#include <pthread.h>
#include <stdio.h>
#include <string.h>

#include "core/alloc.h"
#include "core/clock.h"
#include "scheduler/timeline.h"

typedef struct chunk {
    rs_sched_job *job;
    uint32_t begin, end;
} chunk;

typedef struct worker {
    rs_sched *s;
    rs_device *dev;
    pthread_t thread;
    int started;
    int alive;
    double rate;    /* measured rays/s, a running mean; 0 until the first chunk */
    uint32_t chunk; /* next chunk size (adaptive mode) */
} worker;

struct rs_sched {
    pthread_mutex_t lock;
    pthread_cond_t work_cv;  /* a job was queued, a chunk was retried, or stop */
    pthread_cond_t space_cv; /* the queue has room */
    pthread_cond_t done_cv;  /* a chunk was answered, or a device died */
    rs_sched_job **queue;
    uint32_t q_cap, q_head, q_len;
    chunk *retry;
    uint32_t n_retry;
    uint32_t fixed_chunk; /* 0: adaptive */
    int stop;
    int alive;
    int n_workers;
    worker *workers;
    uint64_t submitted, answered;
    rs_timeline *timeline; /* chunk spans, one lane per device; NULL: none */
    char last_error[512];
};

static rs_sched_job *queue_at(const rs_sched *s, uint32_t k)
{
    return s->queue[(s->q_head + k) % s->q_cap];
}

/* The size of w's next chunk, given that `left` rays are still to be handed out. */
static uint32_t chunk_size_for(const rs_sched *s, const worker *w, uint64_t left)
{
    double share, rate_sum = 0.0;
    uint64_t size, cap;
    int i, measured = 1, alive = 0;
    if (s->fixed_chunk)
        return s->fixed_chunk;
    size = w->chunk;
    for (i = 0; i < s->n_workers; ++i) {
        if (!s->workers[i].alive)
            continue;
        alive++;
        rate_sum += s->workers[i].rate;
        measured &= s->workers[i].rate > 0.0;
    }
    /* guided: no more than this device's share of what is left */
    share = measured && rate_sum > 0.0 ? w->rate / rate_sum : 1.0 / (alive > 0 ? alive : 1);
    cap = (uint64_t)((double)left * share) + 1;
    if (cap < RS_SCHED_MIN_CHUNK)
        cap = RS_SCHED_MIN_CHUNK;
    return (uint32_t)(size < cap ? size : cap);
}

/* After a chunk of `rays` took `secs`: update the rate and the next chunk size. */
static void adapt(worker *w, uint32_t rays, double secs)
{
    double target = rs_device_owns_memory(w->dev) ? RS_SCHED_TARGET_GPU_S : RS_SCHED_TARGET_HOST_S;
    double r, size;
    if (secs <= 0.0 || rays == 0)
        return;
    r = (double)rays / secs;
    w->rate = w->rate > 0.0 ? 0.5 * w->rate + 0.5 * r : r;
    size = w->rate * target;
    size = size < RS_SCHED_MIN_CHUNK   ? RS_SCHED_MIN_CHUNK
           : size > RS_SCHED_MAX_CHUNK ? RS_SCHED_MAX_CHUNK
                                       : size;
    w->chunk = ((uint32_t)size + 63u) & ~63u;
}

/* Takes w's next chunk under the lock: a retry, else a cut off the oldest queued job.  0 when
 * there is nothing to do. */
static int take_chunk(rs_sched *s, const worker *w, chunk *c)
{
    rs_sched_job *j;
    uint64_t left = 0;
    uint32_t k, size;
    if (s->n_retry > 0) {
        *c = s->retry[--s->n_retry];
        return 1;
    }
    if (s->q_len == 0)
        return 0;
    for (k = 0; k < s->q_len; ++k)
        left += queue_at(s, k)->batch->count - queue_at(s, k)->next;
    j = queue_at(s, 0);
    size = chunk_size_for(s, w, left);
    c->job = j;
    c->begin = j->next;
    c->end = j->batch->count - j->next > size ? j->next + size : j->batch->count;
    j->next = c->end;
    if (j->next == j->batch->count) {
        s->q_head = (s->q_head + 1) % s->q_cap;
        s->q_len--;
        pthread_cond_broadcast(&s->space_cv);
    }
    return 1;
}

static void *dispatch_main(void *arg)
{
    worker *w = (worker *)arg;
    rs_sched *s = w->s;
    pthread_mutex_lock(&s->lock);
    for (;;) {
        chunk c;
        double t0, t1;
        rs_status st;
        if (s->q_len == 0 && s->n_retry == 0 && !s->stop) {
            t0 = rs_now_s();
            while (s->q_len == 0 && s->n_retry == 0 && !s->stop)
                pthread_cond_wait(&s->work_cv, &s->lock);
            w->dev->stats.idle_s += rs_now_s() - t0;
        }
        if (!take_chunk(s, w, &c))
            break; /* stop, and nothing left */
        pthread_mutex_unlock(&s->lock);

        t0 = rs_now_s();
        st = w->dev->ops->trace(w->dev, c.job->batch, c.begin, c.end);
        t1 = rs_now_s();
        if (s->timeline && st == RS_OK) {
            /* the timeline's clock: the span ends now and lasted t1 - t0 */
            double e = rs_timeline_now(s->timeline);
            rs_timeline_add(s->timeline, (uint16_t)(w - s->workers),
                            c.job->batch->kind == RS_TRACE_CLOSEST ? RS_STAGE_TRACE_CLOSEST
                                                                   : RS_STAGE_TRACE_SHADOW,
                            c.job->batch->wave, e - (t1 - t0), e);
        }

        pthread_mutex_lock(&s->lock);
        w->dev->stats.busy_s += t1 - t0;
        if (st == RS_OK) {
            w->dev->stats.rays += c.end - c.begin;
            w->dev->stats.chunks++;
            adapt(w, c.end - c.begin, t1 - t0);
            s->answered += c.end - c.begin;
            c.job->remaining -= c.end - c.begin;
            if (c.job->remaining == 0)
                pthread_cond_broadcast(&s->done_cv);
            continue;
        }
        /* The device failed: give its chunk back and retire it. */
        w->dev->stats.failures++;
        snprintf(s->last_error, sizeof s->last_error, "device %s failed: %s", w->dev->name,
                 rs_error_message()[0] ? rs_error_message() : rs_status_name(st));
        rs_error_clear();
        s->retry[s->n_retry++] = c;
        pthread_cond_signal(&s->work_cv);
        w->alive = 0;
        s->alive--;
        pthread_cond_broadcast(&s->done_cv);
        pthread_cond_broadcast(&s->space_cv);
        break;
    }
    pthread_mutex_unlock(&s->lock);
    return NULL;
}

rs_status rs_sched_create(rs_device *const *devices, int n_devices, const rs_sched_config *cfg,
                          rs_sched **out)
{
    rs_sched *s;
    int i;
    *out = NULL;
    if (n_devices <= 0)
        return rs_error_set(RS_ERR_ARG, "the scheduler needs at least one device");
    s = (rs_sched *)rs_calloc(1, sizeof *s);
    if (!s)
        return rs_error_set(RS_ERR_NOMEM, "out of memory creating the scheduler");
    s->fixed_chunk = cfg ? cfg->chunk_size : 0;
    s->timeline = cfg ? cfg->timeline : NULL;
    s->q_cap = (cfg && cfg->queue_capacity) ? cfg->queue_capacity : 8;
    s->queue = (rs_sched_job **)rs_alloc(s->q_cap, sizeof *s->queue);
    s->workers = (worker *)rs_calloc((size_t)n_devices, sizeof *s->workers);
    s->retry = (chunk *)rs_alloc((size_t)n_devices, sizeof *s->retry);
    if (!s->queue || !s->workers || !s->retry) {
        rs_free(s->queue);
        rs_free(s->retry);
        rs_free(s->workers);
        rs_free(s);
        return rs_error_set(RS_ERR_NOMEM, "out of memory creating the scheduler");
    }
    pthread_mutex_init(&s->lock, NULL);
    pthread_cond_init(&s->work_cv, NULL);
    pthread_cond_init(&s->space_cv, NULL);
    pthread_cond_init(&s->done_cv, NULL);
    s->n_workers = n_devices;
    for (i = 0; i < n_devices; ++i) {
        worker *w = &s->workers[i];
        w->s = s;
        w->dev = devices[i];
        w->alive = 1;
        w->chunk = rs_device_owns_memory(devices[i]) ? RS_SCHED_FIRST_GPU : RS_SCHED_FIRST_HOST;
    }
    pthread_mutex_lock(&s->lock);
    for (i = 0; i < n_devices; ++i) {
        worker *w = &s->workers[i];
        if (pthread_create(&w->thread, NULL, dispatch_main, w) != 0) {
            w->alive = 0;
            continue;
        }
        w->started = 1;
        s->alive++;
    }
    pthread_mutex_unlock(&s->lock);
    if (s->alive == 0) {
        rs_sched_destroy(s);
        return rs_error_set(RS_ERR_NOMEM, "could not start any dispatch thread");
    }
    *out = s;
    return RS_OK;
}

void rs_sched_submit(rs_sched *s, const rs_trace_batch *batch, rs_sched_job *job)
{
    job->batch = batch;
    job->next = 0;
    job->remaining = batch->count;
    job->failed = 0;
    pthread_mutex_lock(&s->lock);
    s->submitted += batch->count;
    if (batch->count > 0) {
        while (s->q_len == s->q_cap && s->alive > 0)
            pthread_cond_wait(&s->space_cv, &s->lock);
        if (s->alive > 0) {
            s->queue[(s->q_head + s->q_len) % s->q_cap] = job;
            s->q_len++;
            pthread_cond_broadcast(&s->work_cv);
        } else {
            job->failed = 1;
        }
    }
    pthread_mutex_unlock(&s->lock);
}

/* Removes every trace of `job` from the queue and the retry list (no device is left). */
static void withdraw(rs_sched *s, const rs_sched_job *job)
{
    uint32_t k, kept = 0, len = s->q_len;
    for (k = 0; k < len; ++k) {
        rs_sched_job *j = queue_at(s, k);
        if (j != job)
            s->queue[(s->q_head + kept++) % s->q_cap] = j;
    }
    s->q_len = kept;
    for (k = kept = 0; k < s->n_retry; ++k)
        if (s->retry[k].job != job)
            s->retry[kept++] = s->retry[k];
    s->n_retry = kept;
}

rs_status rs_sched_wait(rs_sched *s, rs_sched_job *job)
{
    rs_status st = RS_OK;
    pthread_mutex_lock(&s->lock);
    while (job->remaining > 0 && s->alive > 0)
        pthread_cond_wait(&s->done_cv, &s->lock);
    if (job->remaining > 0 || job->failed) {
        /* no device left, so no chunk of the job is held by a dispatch thread */
        withdraw(s, job);
        job->failed = 1;
        st = rs_error_set(RS_ERR_DEVICE_LOST, "every device failed; last: %s", s->last_error);
    }
    pthread_mutex_unlock(&s->lock);
    return st;
}

rs_status rs_sched_trace(rs_sched *s, const rs_trace_batch *batch)
{
    rs_sched_job job;
    rs_sched_submit(s, batch, &job);
    return rs_sched_wait(s, &job);
}

void rs_sched_destroy(rs_sched *s)
{
    int i;
    if (!s)
        return;
    pthread_mutex_lock(&s->lock);
    s->stop = 1;
    pthread_cond_broadcast(&s->work_cv);
    pthread_mutex_unlock(&s->lock);
    for (i = 0; i < s->n_workers; ++i)
        if (s->workers[i].started)
            pthread_join(s->workers[i].thread, NULL);
    pthread_mutex_destroy(&s->lock);
    pthread_cond_destroy(&s->work_cv);
    pthread_cond_destroy(&s->space_cv);
    pthread_cond_destroy(&s->done_cv);
    rs_free(s->queue);
    rs_free(s->retry);
    rs_free(s->workers);
    rs_free(s);
}

int rs_sched_device_count(const rs_sched *s) { return s->n_workers; }

rs_device *rs_sched_device(const rs_sched *s, int i) { return s->workers[i].dev; }

void rs_sched_device_stats(rs_sched *s, int i, rs_device_stats *out, int *alive)
{
    pthread_mutex_lock(&s->lock);
    *out = s->workers[i].dev->stats;
    if (alive)
        *alive = s->workers[i].alive;
    pthread_mutex_unlock(&s->lock);
}

void rs_sched_totals(rs_sched *s, uint64_t *submitted, uint64_t *answered)
{
    pthread_mutex_lock(&s->lock);
    *submitted = s->submitted;
    *answered = s->answered;
    pthread_mutex_unlock(&s->lock);
}
