/* scheduler/sched.c — dispatch threads and the shared bounded chunk queue.
 *
 * Invariants (all under `lock`):
 *   - a chunk is either in the queue, or held by exactly one dispatch thread;
 *   - a held chunk is answered (its batch's `remaining` drops by one) or requeued, never both;
 *   - `alive` counts dispatch threads whose device has not failed; when it reaches 0 every
 *     waiting caller is woken and the batch fails;
 *   - a failed device's chunk goes to `retry`, never to the bounded queue: the producer may
 *     have filled the queue since the chunk was popped.  Each device fails at most once, so
 *     `retry` needs one slot per device.  Dispatch threads take retries first. */
#include "scheduler/sched.h"

#include <pthread.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "core/alloc.h"

typedef struct batch_rec {
    const rs_trace_batch *batch;
    uint32_t remaining; /* chunks not yet answered */
    uint64_t answered;  /* rays answered */
} batch_rec;

typedef struct chunk {
    batch_rec *rec;
    uint32_t begin, end;
} chunk;

typedef struct worker {
    rs_sched *s;
    rs_device *dev;
    pthread_t thread;
    int started;
    int alive;
} worker;

struct rs_sched {
    pthread_mutex_t lock;
    pthread_cond_t work_cv;  /* queue became non-empty, or stop */
    pthread_cond_t space_cv; /* queue has room */
    pthread_cond_t done_cv;  /* a chunk was answered, or a device died */
    chunk *queue;
    uint32_t q_cap, q_head, q_len;
    chunk *retry;
    uint32_t n_retry;
    uint32_t chunk_size;
    int stop;
    int alive;
    int n_workers;
    worker *workers;
    uint64_t submitted, answered;
    char last_error[512];
};

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void queue_push_back(rs_sched *s, chunk c)
{
    s->queue[(s->q_head + s->q_len) % s->q_cap] = c;
    s->q_len++;
}

static chunk queue_pop(rs_sched *s)
{
    chunk c = s->queue[s->q_head];
    s->q_head = (s->q_head + 1) % s->q_cap;
    s->q_len--;
    return c;
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
            t0 = now_s();
            while (s->q_len == 0 && s->n_retry == 0 && !s->stop)
                pthread_cond_wait(&s->work_cv, &s->lock);
            w->dev->stats.idle_s += now_s() - t0;
        }
        if (s->n_retry > 0) {
            c = s->retry[--s->n_retry];
        } else if (s->q_len > 0) {
            c = queue_pop(s);
            pthread_cond_signal(&s->space_cv);
        } else {
            break; /* stop, and nothing left */
        }
        pthread_mutex_unlock(&s->lock);

        t0 = now_s();
        st = w->dev->ops->trace(w->dev, c.rec->batch, c.begin, c.end);
        t1 = now_s();

        pthread_mutex_lock(&s->lock);
        w->dev->stats.busy_s += t1 - t0;
        if (st == RS_OK) {
            w->dev->stats.rays += c.end - c.begin;
            w->dev->stats.chunks++;
            c.rec->answered += c.end - c.begin;
            s->answered += c.end - c.begin;
            c.rec->remaining--;
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
    s->chunk_size = (cfg && cfg->chunk_size) ? cfg->chunk_size : RS_SCHED_DEFAULT_CHUNK;
    s->q_cap = (cfg && cfg->queue_capacity) ? cfg->queue_capacity : 256;
    s->queue = (chunk *)rs_alloc(s->q_cap, sizeof *s->queue);
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

rs_status rs_sched_trace(rs_sched *s, const rs_trace_batch *batch)
{
    batch_rec rec;
    uint32_t begin = 0, n = batch->count, cs = s->chunk_size;
    rs_status st = RS_OK;
    rec.batch = batch;
    rec.answered = 0;
    rec.remaining = n == 0 ? 0 : (uint32_t)(((uint64_t)n + cs - 1) / cs);
    pthread_mutex_lock(&s->lock);
    s->submitted += n;
    while (begin < n && s->alive > 0) {
        chunk c;
        while (s->q_len == s->q_cap && s->alive > 0)
            pthread_cond_wait(&s->space_cv, &s->lock);
        if (s->alive == 0)
            break;
        c.rec = &rec;
        c.begin = begin;
        c.end = (n - begin > cs) ? begin + cs : n;
        begin = c.end;
        queue_push_back(s, c);
        pthread_cond_signal(&s->work_cv);
    }
    while (rec.remaining > 0 && s->alive > 0)
        pthread_cond_wait(&s->done_cv, &s->lock);
    if (rec.remaining > 0) {
        /* no device left: drop this batch's chunks so nothing refers to `rec` after we return */
        uint32_t k, len = s->q_len;
        chunk *keep = s->queue;
        uint32_t kept = 0;
        for (k = 0; k < len; ++k) {
            chunk c = s->queue[(s->q_head + k) % s->q_cap];
            if (c.rec != &rec)
                keep[(s->q_head + kept++) % s->q_cap] = c;
        }
        s->q_len = kept;
        for (k = kept = 0; k < s->n_retry; ++k)
            if (s->retry[k].rec != &rec)
                s->retry[kept++] = s->retry[k];
        s->n_retry = kept;
        st = rs_error_set(RS_ERR_DEVICE_LOST, "every device failed; last: %s", s->last_error);
    }
    RS_ASSERT(st != RS_OK || rec.answered == n);
    pthread_mutex_unlock(&s->lock);
    return st;
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
