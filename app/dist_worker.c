/* app/dist_worker.c — a rank other than 0: asks rank 0 for passes while its render thread has
 * room, reports each finished pass (DONE), answers rank 0's messages (one handler per tag), sends
 * a heartbeat each second, and at the end sends its film and waits for rank 0's word on how to
 * end (BYE). */
#include <stdio.h>
#include <string.h>

#include "app/dist_internal.h"
#include "core/alloc.h"
#include "core/clock.h"

typedef struct worker {
    rs_dist *d;
    const rs_dist_job *job;
    double timeout_s;
    local l;
    rs_film *film;  /* the caller's */
    rs_film *spare; /* the other film a flush swaps in (one of the two is `film`) */
    double last_sent, last_heard;
    int asked;      /* a request is waiting for its answer */
    int stopping, aborting;
    int failed;     /* the render thread exited on an error */
} worker;

/* The FILM header's fields from the render thread's totals. */
static void film_header(local *l, uint64_t h[H_COUNT], int failed, int flush)
{
    memset(h, 0, H_COUNT * sizeof *h);
    pthread_mutex_lock(&l->mu);
    h[H_PASSES] = l->passes;
    h[H_PATHS] = l->paths;
    h[H_RAYS_C] = l->sum.rays_closest;
    h[H_RAYS_S] = l->sum.rays_shadow;
    h[H_MAX_BOUNCE] = l->sum.max_bounce;
    h[H_BUSY] = rs_dist_dbits(l->busy_s);
    pthread_mutex_unlock(&l->mu);
    h[H_FAILED] = (uint64_t)failed;
    h[H_FLUSH] = (uint64_t)flush;
}

static void send_dones(const uint32_t *s0, const uint32_t *n, int k)
{
    int i;
    for (i = 0; i < k; ++i) {
        uint64_t v[2] = {s0[i], n[i]};
        rs_dist_send_small(v, 2, 0, T_DONE);
    }
}

/* What the render thread finished, as DONEs.  Their number. */
static int report_done(worker *w)
{
    uint32_t s0[DONE_MAX], n[DONE_MAX];
    int k = local_take_done(&w->l, s0, n);
    send_dones(s0, n, k);
    if (k)
        w->last_sent = rs_now_s();
    return k;
}

/* ---- rank 0's messages: one handler per tag ------------------------------------------------ */

static void on_pass(worker *w, const uint64_t *v)
{
    local_push(&w->l, (uint32_t)v[0], (uint32_t)v[1]);
    w->asked = 0;
}

static void on_stop(worker *w, const uint64_t *v)
{
    (void)v;
    w->stopping = 1;
    w->asked = 0;
    local_signal(&w->l, 0);
}

static void on_abort(worker *w, const uint64_t *v)
{
    (void)v;
    w->aborting = 1;
    local_signal(&w->l, 1);
}

/* A flush: the film so far and its passes to rank 0; the render thread goes on into the spare
 * film (cleared), which becomes the rank's film. */
static void on_flush(worker *w, const uint64_t *v)
{
    local *l = &w->l;
    uint32_t s0[DONE_MAX], n[DONE_MAX];
    uint64_t h[H_COUNT];
    rs_film *sent;
    int k;
    (void)v;
    rs_film_clear(w->spare);
    pthread_mutex_lock(&l->mu);
    sent = l->acc;
    l->acc = w->spare;
    k = l->done_len;
    memcpy(s0, l->done_s0, (size_t)k * sizeof *s0);
    memcpy(n, l->done_n, (size_t)k * sizeof *n);
    l->done_len = 0;
    pthread_mutex_unlock(&l->mu);
    send_dones(s0, n, k);
    film_header(l, h, 0, 1);
    if (!rs_dist_send_film(sent, h, w->timeout_s))
        fprintf(stderr, "raystream: rank %d: could not send its film to rank 0\n", w->d->rank);
    w->spare = sent;
}

typedef void (*worker_handler)(worker *w, const uint64_t *v);

/* by tag; a heartbeat needs nothing more than its arrival */
static const worker_handler on_message[T_COUNT] = {
    [T_PASS] = on_pass,
    [T_STOP] = on_stop,
    [T_ABORT] = on_abort,
    [T_FLUSH] = on_flush,
};

/* ---- the loop ------------------------------------------------------------------------------ */

/* One round: 1 to go on (*active: something happened), 0 when the loop is over (the render
 * thread exited, or MPI failed), -1 when rank 0 has been silent too long. */
static int round_(worker *w, int *active)
{
    uint64_t v[2];
    int flag, tag = 0;
    *active = report_done(w) > 0;
    if (local_exited(&w->l)) {
        w->failed = w->l.error != RS_OK;
        return 0;
    }
    if (w->job->cancel && atomic_load(w->job->cancel) && !w->aborting) {
        local_signal(&w->l, 1); /* our own stop signal: send what is finished, now */
        w->aborting = 1;
    }
    /* ask for a pass while the queue has room */
    if (!w->stopping && !w->aborting && !w->asked && local_held(&w->l) < QUEUE) {
        rs_dist_send_small(NULL, 0, 0, T_REQ);
        w->asked = 1;
        w->last_sent = rs_now_s();
        *active = 1;
    }
    if ((flag = rs_dist_poll_rank0(&tag, v)) < 0)
        return 0;
    if (flag) {
        w->last_heard = rs_now_s();
        if (tag > 0 && tag < T_COUNT && on_message[tag])
            on_message[tag](w, v);
        w->last_sent = rs_now_s();
        *active = 1;
    }
    if (rs_now_s() - w->last_sent > 1.0) {
        rs_dist_send_small(NULL, 0, 0, T_HB);
        w->last_sent = rs_now_s();
    }
    return rs_now_s() - w->last_heard > w->timeout_s ? -1 : 1;
}

/* Rank 0's word on how to end (MPI_Finalize waits for every rank, the dead too). */
static void wait_bye(worker *w)
{
    double t_bye = rs_now_s(), nap = 1e-4;
    int got = 0;
    while (!got && rs_now_s() - t_bye < w->timeout_s) {
        uint64_t v[2];
        int tag = 0, flag = rs_dist_poll_rank0(&tag, v);
        if (flag < 0)
            break;
        if (flag) {
            if (tag == T_BYE) {
                got = 1;
                if (v[0])
                    w->d->any_dead = 1;
            }
            continue;
        }
        rs_dist_idle_nap(&nap, 0);
    }
    if (!got)
        w->d->any_dead = 1; /* rank 0 is gone: do not wait for it */
}

/* After the loop: the DONEs of the last passes, then the film, then BYE. */
static void end(worker *w)
{
    int failed = w->failed;
    uint64_t h[H_COUNT];
    rs_film *acc;
    local_wait(&w->l);
    report_done(w);
    if (failed)
        fprintf(stderr, "raystream: rank %d: %s; its passes go to the other ranks\n", w->d->rank,
                rs_error_message());
    pthread_mutex_lock(&w->l.mu);
    acc = w->l.acc;
    pthread_mutex_unlock(&w->l.mu);
    film_header(&w->l, h, failed, 0);
    if (!rs_dist_send_film(acc, h, w->timeout_s)) {
        w->d->any_dead = 1;
        fprintf(stderr, "raystream: rank %d: could not send its film to rank 0\n", w->d->rank);
    } else {
        wait_bye(w);
    }
    rs_film_destroy(w->spare == w->film ? acc : w->spare); /* the one of the two not `film` */
    local_free(&w->l);
}

rs_status rs_dist_run_worker(rs_dist *d, const rs_dist_job *job, rs_film *film,
                             double timeout_s)
{
    worker w;
    double nap = 1e-4;
    rs_status st;
    memset(&w, 0, sizeof w);
    w.d = d;
    w.job = job;
    w.timeout_s = timeout_s;
    w.film = film;
    w.last_sent = w.last_heard = rs_now_s();
    rs_film_clear(film);
    if (rs_film_create(film->width, film->height, &w.spare) != RS_OK)
        return RS_ERR_NOMEM;
    if ((job->variance &&
         (rs_film_track_variance(film) != RS_OK || rs_film_track_variance(w.spare) != RS_OK)) ||
        (job->passes &&
         (rs_film_keep_passes(film) != RS_OK || rs_film_keep_passes(w.spare) != RS_OK))) {
        rs_film_destroy(w.spare);
        return RS_ERR_NOMEM;
    }
    if ((st = local_start(&w.l, job, d->rank, film, NULL)) != RS_OK) {
        rs_film_destroy(w.spare);
        return st;
    }
    for (;;) {
        int active = 0, go = round_(&w, &active);
        if (go == 0)
            break;
        if (go < 0) {
            fprintf(stderr, "raystream: rank %d: rank 0 has been silent for %.0f s; stopping\n",
                    d->rank, timeout_s);
            d->any_dead = 1;
            local_join(&w.l);
            /* after a flush `spare` may be the caller's film: free the other one */
            rs_film_destroy(w.spare == film ? w.l.acc : w.spare);
            return rs_error_set(RS_ERR_IO, "rank 0 is gone");
        }
        rs_dist_idle_nap(&nap, active);
    }
    end(&w);
    return RS_OK;
}

int rs_dist_job_wait(rs_dist *d, uint32_t **pixels, uint32_t *n_pixels, double timeout_s)
{
    double t0 = rs_now_s(), nap = 1e-4;
    *pixels = NULL;
    *n_pixels = 0;
    while (rs_now_s() - t0 < timeout_s) {
        uint64_t v[2];
        int tag = 0, flag = rs_dist_poll_rank0(&tag, v);
        if (flag < 0)
            break;
        if (!flag) {
            rs_dist_idle_nap(&nap, 0);
            continue;
        }
        if (tag == T_BYE) { /* the run is over */
            if (v[0])
                d->any_dead = 1;
            return 0;
        }
        if (tag != T_JOB) /* a heartbeat of the job before */
            continue;
        if (v[0] == 0)
            return 1;
        *pixels = (uint32_t *)rs_alloc((size_t)v[0], sizeof **pixels);
        if (*pixels && rs_dist_recv_chunks(*pixels, (size_t)v[0], sizeof **pixels, MPI_UINT32_T,
                                           0, T_JOB_PIXELS, timeout_s)) {
            *n_pixels = (uint32_t)v[0];
            return 1;
        }
        rs_free(*pixels);
        *pixels = NULL;
        break;
    }
    d->any_dead = 1; /* rank 0 is gone: do not wait for it */
    return -1;
}
