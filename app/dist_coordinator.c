/* app/dist_coordinator.c — rank 0: hands out the passes on request, renders passes of its own
 * on its render thread, adds the films that come, flushes every worker for a checkpoint, and
 * finds the dead.  Each round of its messaging loop looks at the stops (a signal, the time
 * limit), its own render thread, one message (one handler per tag), the requests waiting, the
 * flush under way, the heartbeats and the silent ranks; it ends once every worker's film is in
 * (or it is dead) and every pass below the limit is on the frame. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "app/dist_internal.h"
#include "core/alloc.h"
#include "core/clock.h"

typedef struct coord {
    rs_dist *d;
    const rs_dist_job *job;
    rs_dist_result *res;
    int n;              /* ranks */
    passes pt;
    double timeout_s;
    double grace_s;     /* after a stop signal, how long the films may take */
    double t0, t_signal, last_hb, next_flush;
    int signalled;      /* a stop signal: nothing more is handed out */
    int flush_round;    /* the workers were asked to flush; not all are in yet */
    local l;            /* rank 0's own render thread */
    pthread_mutex_t film_mu;
    rs_film *film;      /* the frame */
    rs_film *tmp;       /* a worker's film as it comes */
    /* per rank */
    double *last_seen;
    int *asked;         /* a request is waiting (no pass was free) */
    int *finished;      /* its film arrived, or it is dead */
    int *stopped;       /* it was sent STOP or ABORT */
    int *flushing;      /* a flush asked of it is not in yet */
} coord;

static void progress(coord *c)
{
    if (!c->job->progress)
        return;
    c->job->progress(c->job->user, passes_paths_done(&c->pt), c->pt.todo_paths);
}

static void mark_dead(coord *c, int r, const char *why)
{
    rs_dist_rank_stats *rk = &c->res->rank[r];
    if (!rk->alive)
        return;
    rk->alive = 0;
    c->finished[r] = 1;
    c->flushing[r] = 0;
    c->d->any_dead = 1;
    c->d->dead[r] = 1; /* and in the run's later jobs */
    c->res->dead++;
    fprintf(stderr, "\nraystream: rank %d (%s) %s; its passes go to the other ranks\n", r,
            c->d->desc ? c->d->desc[r] : "?", why);
    passes_release(&c->pt, r);
}

/* Every rank's finished passes are on the frame: job->saved, while rank 0's render thread
 * cannot add to it (its lock, then the frame's). */
static void call_saved(coord *c)
{
    local *l = &c->l;
    rs_path_ranges done;
    uint32_t samples, i;
    int ok;
    pthread_mutex_lock(&l->mu);
    for (i = 0; i < (uint32_t)l->done_len; ++i) {
        uint32_t q = passes_of(&c->pt, l->done_s0[i]);
        if (q < c->pt.n_passes)
            c->pt.state[q] = P_MERGED;
    }
    l->done_len = 0;
    ok = passes_merged_ranges(&c->pt, &done, &samples);
    pthread_mutex_lock(&c->film_mu);
    if (ok)
        c->job->saved(c->job->user, c->film, &done);
    pthread_mutex_unlock(&c->film_mu);
    pthread_mutex_unlock(&l->mu);
    rs_path_ranges_free(&done);
}

/* ---- set-up and the end ------------------------------------------------------------------- */

static rs_status setup(coord *c)
{
    const rs_dist_job *job = c->job;
    rs_dist_result *res = c->res;
    const char *kill_after = getenv("OMPI_MCA_odls_base_sigkill_timeout");
    int r, n = c->n;
    c->pt.npix = job->plan.pixels ? job->plan.n_pixels : job->width * job->height;
    c->pt.pass_spp = job->plan.pass_samples ? job->plan.pass_samples
                                            : passes_auto_spp(job, c->pt.npix, n);
    c->pt.reissued = &res->reissued;
    if (!passes_make(&c->pt, job))
        return rs_error_set(RS_ERR_NOMEM, "out of memory for the MPI coordinator");
    c->next_flush = job->flush_every_s > 0 ? c->t0 + job->flush_every_s : 0;
    res->ranks = n;
    res->pass_spp = c->pt.pass_spp;
    res->passes_total = c->pt.n_passes;
    c->last_seen = (double *)rs_calloc((size_t)n, sizeof *c->last_seen);
    c->asked = (int *)rs_calloc((size_t)n, sizeof *c->asked);
    c->finished = (int *)rs_calloc((size_t)n, sizeof *c->finished);
    c->stopped = (int *)rs_calloc((size_t)n, sizeof *c->stopped);
    c->flushing = (int *)rs_calloc((size_t)n, sizeof *c->flushing);
    res->rank = (rs_dist_rank_stats *)rs_calloc((size_t)n, sizeof *res->rank);
    if (!c->d->dead)
        c->d->dead = (uint8_t *)rs_calloc((size_t)n, 1);
    if (!c->last_seen || !c->asked || !c->finished || !c->stopped || !c->flushing ||
        !res->rank || !c->d->dead || rs_film_create(job->width, job->height, &c->tmp) != RS_OK ||
        (job->variance && rs_film_track_variance(c->tmp) != RS_OK) ||
        (job->passes && rs_film_keep_passes(c->tmp) != RS_OK))
        return rs_error_set(RS_ERR_NOMEM, "out of memory for the MPI coordinator");
    for (r = 0; r < n; ++r) {
        res->rank[r].alive = !c->d->dead[r]; /* found dead in an earlier job: not here */
        c->finished[r] = c->d->dead[r];
        c->last_seen[r] = c->t0;
        if (c->d->desc)
            snprintf(res->rank[r].desc, RS_DIST_DESC, "%s", c->d->desc[r]);
    }
    c->finished[0] = 1; /* rank 0's own thread is tracked apart */
    /* after a stop signal, mpirun kills every rank odls_base_sigkill_timeout (1 s) later */
    c->grace_s = (kill_after && atof(kill_after) > 0 ? atof(kill_after) : 1.0) - 0.3;
    if (c->grace_s < 0.2)
        c->grace_s = 0.2;
    if (c->grace_s > c->timeout_s)
        c->grace_s = c->timeout_s;
    return RS_OK;
}

static void free_coord(coord *c)
{
    rs_film_destroy(c->tmp);
    passes_free(&c->pt);
    rs_free(c->last_seen);
    rs_free(c->asked);
    rs_free(c->finished);
    rs_free(c->stopped);
    rs_free(c->flushing);
}

/* BYE to every rank whose film came, and the result's totals (after the render thread's end) */
static void finish(coord *c)
{
    rs_dist_result *res = c->res;
    local *l = &c->l;
    int r;
    /* the end, to every rank whose film came: finalize only if nobody was lost */
    for (r = 1; r < c->n; ++r)
        if (res->rank[r].alive) {
            uint64_t lost = (uint64_t)c->d->any_dead;
            rs_dist_send_small(&lost, 1, r, T_BYE);
        }
    /* rank 0's row */
    res->rank[0].passes = l->passes;
    res->rank[0].paths = l->paths;
    res->rank[0].busy_s = l->busy_s;
    res->rank[0].wall_s = rs_now_s() - c->t0;
    res->rank[0].comm_cpu_s = rs_dist_thread_cpu_s() - rs_dist_cpu0;
    res->local = l->sum;
    res->rays_closest += l->sum.rays_closest;
    res->rays_shadow += l->sum.rays_shadow;
    if (l->sum.max_bounce > res->max_bounce)
        res->max_bounce = l->sum.max_bounce;
    for (r = 1; r < c->n; ++r) {
        res->rays_closest += res->rank[r].rays_closest;
        res->rays_shadow += res->rank[r].rays_shadow;
    }
    /* which samples the frame holds */
    if (!passes_merged_ranges(&c->pt, &res->done, &res->samples_done))
        fprintf(stderr, "raystream: out of memory listing the passes done\n");
    res->complete = passes_count(&c->pt, P_MERGED, c->pt.n_passes) == c->pt.n_passes;
}

/* ---- one message from a worker: one handler per tag ---------------------------------------- */

static void on_req(coord *c, int r, const uint64_t *v)
{
    (void)v;
    c->asked[r] = 1;
}

static void on_hb(coord *c, int r, const uint64_t *v)
{
    (void)c, (void)r, (void)v; /* it was heard from: nothing more */
}

static void on_done(coord *c, int r, const uint64_t *v)
{
    uint32_t q = passes_of(&c->pt, (uint32_t)v[0]);
    if (q < c->pt.n_passes && c->pt.owner[q] == r && c->pt.state[q] == P_ASSIGNED) {
        c->pt.state[q] = P_DONE;
        progress(c);
    }
}

/* Rank r's film (header h) is on the frame: its passes and totals. */
static void film_added(coord *c, int r, const uint64_t *h)
{
    rs_dist_rank_stats *rk = &c->res->rank[r];
    uint32_t p;
    for (p = 0; p < c->pt.n_passes; ++p)
        if (c->pt.owner[p] == r && c->pt.state[p] == P_DONE) {
            c->pt.state[p] = P_MERGED;
            rk->passes++;
            rk->paths += (uint64_t)c->pt.pn[p] * c->pt.npix;
        }
    /* the worker's totals so far (a flush sends them too) */
    rk->busy_s = rs_dist_bitsd(h[H_BUSY]);
    rk->wall_s = c->last_seen[r] - c->t0;
    rk->comm_cpu_s = rs_dist_bitsd(h[H_COMM_CPU]);
    rk->rays_closest = h[H_RAYS_C];
    rk->rays_shadow = h[H_RAYS_S];
    if (h[H_MAX_BOUNCE] > c->res->max_bounce)
        c->res->max_bounce = (uint32_t)h[H_MAX_BOUNCE];
    c->flushing[r] = 0;
    if (!h[H_FLUSH]) { /* its last: after a flush it goes on */
        c->finished[r] = 1;
        if (h[H_FAILED]) {
            rk->failed = 1;
            fprintf(stderr, "\nraystream: rank %d (%s) failed; its passes go to the other ranks\n",
                    r, rk->desc);
        }
        passes_release(&c->pt, r); /* what it held but did not finish */
    }
}

static void on_film(coord *c, int r, const uint64_t *h)
{
    double t_recv = rs_now_s();
    uint64_t bytes = 0;
    int got = rs_dist_recv_film(r, h, c->tmp, c->timeout_s, &bytes), q;
    if (got) {
        pthread_mutex_lock(&c->film_mu);
        rs_film_merge(c->film, c->tmp);
        pthread_mutex_unlock(&c->film_mu);
        c->res->bytes_received += bytes;
        c->res->rank[r].film_bytes += bytes;
    }
    /* the others' silence while this film came does not count */
    for (q = 1; q < c->n; ++q)
        if (q != r)
            c->last_seen[q] += rs_now_s() - t_recv;
    if (got)
        film_added(c, r, h);
    else
        mark_dead(c, r, "sent a broken film");
}

typedef void (*coord_handler)(coord *c, int r, const uint64_t *v);

/* by tag; a film's data outside a film (one given up on) is dropped unread */
static const coord_handler on_message[T_COUNT] = {
    [T_REQ] = on_req,
    [T_HB] = on_hb,
    [T_DONE] = on_done,
    [T_FILM] = on_film,
};

/* One message, if one is there, to its handler.  1 if one came. */
static int poll_message(coord *c)
{
    uint64_t v[H_COUNT];
    int flag = 0, cnt = 0, r, tag;
    MPI_Status ms;
    if (MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &ms) != MPI_SUCCESS ||
        !flag)
        return 0;
    r = ms.MPI_SOURCE;
    tag = ms.MPI_TAG;
    memset(v, 0, sizeof v);
    if (rs_dist_is_film_data(tag)) {
        rs_dist_drop_data(&ms); /* data of a film given up on */
    } else {
        MPI_Get_count(&ms, MPI_UINT64_T, &cnt);
        rs_dist_msgs++;
        rs_dist_msg_bytes += 8u * (uint64_t)cnt;
        MPI_Recv(v, cnt > H_COUNT ? H_COUNT : cnt, MPI_UINT64_T, r, tag, MPI_COMM_WORLD,
                 MPI_STATUS_IGNORE);
    }
    c->last_seen[r] = rs_now_s();
    /* a rank given up on, heard from again: its passes are out already */
    if (c->res->rank[r].alive && tag > 0 && tag < T_COUNT && on_message[tag])
        on_message[tag](c, r, v);
    return 1;
}

/* ---- the rounds of the loop ------------------------------------------------------------- */

/* A stop signal (every worker aborted), the films' grace after it, the time limit. */
static void check_stops(coord *c, double now)
{
    int r;
    if (!c->signalled && c->job->cancel && atomic_load(c->job->cancel)) {
        c->signalled = 1;
        c->res->stopped = 1;
        c->pt.limit = 0;
        for (r = 1; r < c->n; ++r)
            if (!c->finished[r]) {
                rs_dist_send_small(NULL, 0, r, T_ABORT);
                c->stopped[r] = 1;
            }
        local_signal(&c->l, 1);
        /* what is under way is dropped (a worker's film says which it finished) and nothing is
         * handed out again; the films must come before mpirun's SIGKILL */
        c->t_signal = now;
    }
    if (c->signalled && now - c->t_signal > c->grace_s)
        for (r = 1; r < c->n; ++r)
            if (!c->finished[r]) {
                c->finished[r] = 1;
                c->res->rank[r].alive = 0;
                c->d->any_dead = 1;
                fprintf(stderr, "\nraystream: rank %d (%s) sent no film within %.1f s of the "
                                "stop (it may be dead); its passes are left out\n",
                        r, c->res->rank[r].desc, c->grace_s);
            }
    /* past the budget no new pass: those begun (or handed out again later) still finish */
    if (!c->signalled && !c->res->time_limited && c->job->plan.time_limit_s > 0) {
        double t0 = c->job->t_start > 0 ? c->job->t_start : c->t0;
        uint64_t end = rs_work_plan_time_cut(&c->job->plan,
                                             (uint64_t)c->job->width * c->job->height, now - t0,
                                             passes_begun_end(&c->pt), 0);
        if (end != UINT64_MAX && passes_limit_to(&c->pt, end))
            c->res->time_limited = 1;
    }
}

/* Rank 0's own passes: the finished ones are on the frame, and one more when it has room.
 * 1 if something happened; 0 into *failed unless its render failed. */
static int serve_self(coord *c, int *failed)
{
    uint32_t s0[DONE_MAX], nn[DONE_MAX], p;
    int k = local_take_done(&c->l, s0, nn), i, active = 0;
    for (i = 0; i < k; ++i)
        c->pt.state[passes_of(&c->pt, s0[i])] = P_MERGED;
    if (k) {
        progress(c);
        active = 1;
    }
    *failed = local_exited(&c->l) && c->l.error != RS_OK;
    if (*failed)
        return active;
    if (!c->signalled && local_held(&c->l) < QUEUE && (p = passes_next_free(&c->pt)) <
                                                          c->pt.n_passes) {
        passes_assign(&c->pt, p, 0);
        local_push(&c->l, c->pt.ps0[p], c->pt.pn[p]);
        active = 1;
    }
    return active;
}

/* A pass to each worker waiting for one, or STOP once nothing is left to hand out. */
static void answer_requests(coord *c)
{
    uint32_t p;
    int r;
    for (r = 1; r < c->n; ++r) {
        if (!c->asked[r] || c->finished[r] || c->stopped[r])
            continue;
        if ((p = passes_next_free(&c->pt)) < c->pt.n_passes) {
            uint64_t v[2];
            passes_assign(&c->pt, p, r);
            v[0] = c->pt.ps0[p];
            v[1] = c->pt.pn[p];
            c->asked[r] = 0;
            if (!rs_dist_send_small(v, 2, r, T_PASS))
                mark_dead(c, r, "cannot be reached");
        } else if (passes_count(&c->pt, P_ASSIGNED, c->pt.limit) +
                       passes_count(&c->pt, P_FREE, c->pt.limit) ==
                   0) {
            /* nothing left to hand out (a death could free some: rank 0 then takes them) */
            c->asked[r] = 0;
            c->stopped[r] = 1;
            if (!rs_dist_send_small(NULL, 0, r, T_STOP))
                mark_dead(c, r, "cannot be reached");
        }
    }
}

/* Periodic flushes: every worker sends what it finished; once all are in, the frame holds every
 * finished pass, and job->saved writes it.  1 when a flush completed. */
static int flush_step(coord *c)
{
    double now = rs_now_s();
    int r, waiting = 0;
    if (c->next_flush > 0 && !c->signalled && !c->flush_round && now >= c->next_flush) {
        for (r = 1; r < c->n; ++r)
            if (!c->finished[r]) {
                c->flushing[r] = 1;
                if (!rs_dist_send_small(NULL, 0, r, T_FLUSH))
                    mark_dead(c, r, "cannot be reached");
            }
        c->flush_round = 1;
    }
    if (!c->flush_round)
        return 0;
    for (r = 1; r < c->n; ++r)
        waiting |= c->flushing[r] && !c->finished[r];
    if (waiting)
        return 0;
    if (c->job->saved)
        call_saved(c);
    c->res->flushes++;
    c->flush_round = 0;
    c->next_flush = rs_now_s() + c->job->flush_every_s;
    return 1;
}

/* A heartbeat to the workers, so that one waiting for an answer knows rank 0 lives; the silent
 * ones are dead. */
static void heartbeats(coord *c)
{
    double now = rs_now_s();
    int r;
    if (now - c->last_hb > 1.0) {
        for (r = 1; r < c->n; ++r)
            if (!c->finished[r])
                rs_dist_send_small(NULL, 0, r, T_HB);
        c->last_hb = now;
    }
    for (r = 1; r < c->n; ++r)
        if (!c->finished[r] && now - c->last_seen[r] > c->timeout_s) {
            char why[64];
            snprintf(why, sizeof why, "has been silent for %.0f s", c->timeout_s);
            mark_dead(c, r, why);
        }
}

/* The end: every worker's film is in (or it is dead), rank 0 holds nothing, and no pass below
 * the limit is left (after a stop signal: whatever is left is lost). */
static int is_over(coord *c)
{
    int r, all_finished = 1;
    for (r = 1; r < c->n; ++r)
        all_finished &= c->finished[r];
    return all_finished && local_idle(&c->l) &&
           (c->signalled || passes_count(&c->pt, P_MERGED, c->pt.limit) == c->pt.limit);
}

/* The messaging loop, until the end or rank 0's own render fails (its error). */
static rs_status loop(coord *c)
{
    double nap = 1e-4;
    for (;;) {
        int active, failed = 0;
        check_stops(c, rs_now_s());
        active = serve_self(c, &failed);
        if (failed)
            return c->l.error;
        active |= poll_message(c);
        answer_requests(c);
        active |= flush_step(c);
        heartbeats(c);
        if (is_over(c))
            return RS_OK;
        rs_dist_idle_nap(&nap, active);
    }
}

rs_status rs_dist_run_coordinator(rs_dist *d, const rs_dist_job *job, rs_film *film,
                                  rs_dist_result *res, double timeout_s)
{
    coord c;
    rs_status st;
    int r;
    memset(&c, 0, sizeof c);
    c.d = d;
    c.job = job;
    c.res = res;
    c.n = d->size;
    c.film = film;
    c.timeout_s = timeout_s;
    c.t0 = c.last_hb = rs_now_s();
    pthread_mutex_init(&c.film_mu, NULL);
    if ((st = setup(&c)) == RS_OK && (st = local_start(&c.l, job, 0, film, &c.film_mu)) == RS_OK) {
        if ((st = loop(&c)) != RS_OK) {
            /* rank 0 failed: the others are told, and it does not wait for them (no
             * MPI_Finalize, which would wait for films nobody receives: mpirun ends them) */
            d->any_dead = 1;
            for (r = 1; r < c.n; ++r)
                if (!c.finished[r])
                    rs_dist_send_small(NULL, 0, r, T_ABORT);
        }
        local_join(&c.l);
        finish(&c);
    }
    res->seconds = rs_now_s() - c.t0;
    res->messages = rs_dist_msgs;
    res->message_bytes = rs_dist_msg_bytes;
    free_coord(&c);
    return st;
}

int rs_dist_job_begin(rs_dist *d, const uint32_t *pixels, uint32_t n_pixels, double timeout_s)
{
    int r;
    if (!d->dead && !(d->dead = (uint8_t *)rs_calloc((size_t)d->size, 1)))
        return 0;
    for (r = 1; r < d->size; ++r) {
        uint64_t n = pixels ? n_pixels : 0;
        if (d->dead[r])
            continue;
        if (rs_dist_send_small(&n, 1, r, T_JOB) &&
            (!pixels || rs_dist_send_chunks(pixels, n_pixels, sizeof *pixels, MPI_UINT32_T, r,
                                            T_JOB_PIXELS, timeout_s)))
            continue;
        {
            d->dead[r] = 1;
            d->any_dead = 1;
            fprintf(stderr, "\nraystream: rank %d cannot be reached; the next rounds go on "
                            "without it\n", r);
        }
    }
    return 1; /* rank 0 renders on alone if it must */
}

void rs_dist_jobs_end(rs_dist *d)
{
    int r;
    for (r = 1; r < d->size; ++r)
        if (!d->dead || !d->dead[r]) {
            uint64_t lost = (uint64_t)d->any_dead;
            rs_dist_send_small(&lost, 1, r, T_BYE);
        }
}
