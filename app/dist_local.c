/* app/dist_local.c — the render thread every rank runs beside its messaging (the main thread,
 * the only one that calls MPI): it takes passes from a queue of QUEUE (one under way, one
 * waiting), renders each onto a scratch film, adds it to the rank's film and lists it as done
 * until the messaging takes the list.  RS_MPI_FAULT's slow and die faults act here. */
#include <signal.h>
#include <string.h>

#include "app/dist_internal.h"
#include "core/clock.h"

/* The next pass into *s0 and *n, waiting for one; 0 when the thread is to exit (then marked so). */
static int take_pass(local *l, uint32_t *s0, uint32_t *n)
{
    pthread_mutex_lock(&l->mu);
    while (!l->q_len && !l->stop && !l->abort_)
        pthread_cond_wait(&l->cv, &l->mu);
    if (l->abort_ || (l->stop && !l->q_len)) {
        l->exited = 1;
        pthread_cond_broadcast(&l->cv);
        pthread_mutex_unlock(&l->mu);
        return 0;
    }
    *s0 = l->q_s0[0];
    *n = l->q_n[0];
    memmove(l->q_s0, l->q_s0 + 1, (QUEUE - 1) * sizeof *l->q_s0);
    memmove(l->q_n, l->q_n + 1, (QUEUE - 1) * sizeof *l->q_n);
    l->q_len--;
    l->busy = 1;
    pthread_mutex_unlock(&l->mu);
    return 1;
}

/* The pass rendered (*st), begun at t0: added to the film and listed, or dropped; *st becomes
 * the merge's status.  0 when it failed and the thread is to exit (then marked so). */
static int finish_pass(local *l, uint32_t s0, uint32_t n, rs_status *status,
                       const rs_render_stats *rs, double t0)
{
    rs_status st = *status;
    /* the merge and its report under one lock: a flush sees a film and the list of the passes
     * in it that agree */
    pthread_mutex_lock(&l->mu);
    if (st == RS_OK) {
        if (l->acc_mu)
            pthread_mutex_lock(l->acc_mu);
        st = rs_film_merge(l->acc, l->scratch);
        if (l->acc_mu)
            pthread_mutex_unlock(l->acc_mu);
    }
    *status = st;
    l->busy = 0;
    l->busy_s += rs_now_s() - t0;
    if (st == RS_OK) {
        l->passes++;
        l->paths += rs->paths_done;
        rs_render_stats_add(&l->sum, rs);
        if (l->done_len < DONE_MAX) {
            l->done_s0[l->done_len] = s0;
            l->done_n[l->done_len++] = n;
        }
    } else if (st != RS_ERR_CANCELLED) {
        l->error = st;
        l->exited = 1;
        pthread_cond_broadcast(&l->cv);
        pthread_mutex_unlock(&l->mu);
        return 0;
    } else {
        rs_error_clear();
    }
    pthread_cond_broadcast(&l->cv);
    pthread_mutex_unlock(&l->mu);
    return 1;
}

static void *local_main(void *arg)
{
    local *l = (local *)arg;
    const rs_dist_job *job = l->job;
    for (;;) {
        uint32_t s0, n;
        rs_render_stats rs;
        rs_status st;
        double t0, t1;
        if (!take_pass(l, &s0, &n))
            return NULL;
        rs_film_clear(l->scratch);
        memset(&rs, 0, sizeof rs);
        t0 = rs_now_s();
        st = job->render(job->user, job->plan.pixels, job->plan.n_pixels, s0, n, l->scratch, &l->cancel,
                         &rs);
        t1 = rs_now_s();
        if (st == RS_OK && job->fault.slow_factor > 1 && job->fault.slow_rank == l->rank)
            rs_dist_sleep_s((job->fault.slow_factor - 1) * (t1 - t0));
        if (!finish_pass(l, s0, n, &st, &rs, t0))
            return NULL;
        if (st == RS_OK && job->fault.die_rank == l->rank && l->passes >= job->fault.die_after)
            raise(SIGKILL); /* a test of a rank lost with finished passes it never sent */
    }
}

rs_status local_start(local *l, const rs_dist_job *job, int rank, rs_film *acc,
                      pthread_mutex_t *acc_mu)
{
    memset(l, 0, sizeof *l);
    l->job = job;
    l->rank = rank;
    l->acc = acc;
    l->acc_mu = acc_mu;
    pthread_mutex_init(&l->mu, NULL);
    pthread_cond_init(&l->cv, NULL);
    if (rs_film_create(job->width, job->height, &l->scratch) != RS_OK)
        return RS_ERR_NOMEM;
    if ((job->variance && rs_film_track_variance(l->scratch) != RS_OK) ||
        (job->passes && rs_film_keep_passes(l->scratch) != RS_OK)) {
        rs_film_destroy(l->scratch);
        return RS_ERR_NOMEM;
    }
    if (pthread_create(&l->thread, NULL, local_main, l) != 0) {
        rs_film_destroy(l->scratch);
        return rs_error_set(RS_ERR_NOMEM, "cannot start the render thread");
    }
    l->started = 1;
    return RS_OK;
}

void local_push(local *l, uint32_t s0, uint32_t n)
{
    pthread_mutex_lock(&l->mu);
    if (l->q_len < QUEUE) {
        l->q_s0[l->q_len] = s0;
        l->q_n[l->q_len++] = n;
    }
    pthread_cond_broadcast(&l->cv);
    pthread_mutex_unlock(&l->mu);
}

int local_held(local *l)
{
    int n;
    pthread_mutex_lock(&l->mu);
    n = l->q_len + l->busy;
    pthread_mutex_unlock(&l->mu);
    return n;
}

void local_signal(local *l, int abort_)
{
    pthread_mutex_lock(&l->mu);
    if (abort_) {
        l->abort_ = 1;
        l->q_len = 0;
        atomic_store(&l->cancel, 1);
    } else {
        l->stop = 1;
    }
    pthread_cond_broadcast(&l->cv);
    pthread_mutex_unlock(&l->mu);
}

int local_exited(local *l)
{
    int e;
    pthread_mutex_lock(&l->mu);
    e = l->exited;
    pthread_mutex_unlock(&l->mu);
    return e;
}

int local_idle(local *l)
{
    int idle;
    pthread_mutex_lock(&l->mu);
    idle = l->q_len == 0 && !l->busy && l->done_len == 0;
    pthread_mutex_unlock(&l->mu);
    return idle;
}

int local_take_done(local *l, uint32_t *s0, uint32_t *n)
{
    int k;
    pthread_mutex_lock(&l->mu);
    k = l->done_len;
    memcpy(s0, l->done_s0, (size_t)k * sizeof *s0);
    memcpy(n, l->done_n, (size_t)k * sizeof *n);
    l->done_len = 0;
    pthread_mutex_unlock(&l->mu);
    return k;
}

void local_wait(local *l)
{
    pthread_join(l->thread, NULL);
    l->started = 0;
}

void local_free(local *l)
{
    rs_film_destroy(l->scratch);
    pthread_mutex_destroy(&l->mu);
    pthread_cond_destroy(&l->cv);
}

void local_join(local *l)
{
    if (!l->started)
        return;
    local_signal(l, 1);
    local_wait(l);
    local_free(l);
}
