/* scheduler/wavefront.c — runs of plans on devices that run paths whole (render.h:
 * rs_engine_create_paths): each device's render_paths (a GPU's wavefront, gpu/wavefront.h) takes
 * ranges of the plan in calls of about a quarter of a second of its measured rate; with a
 * scheduler, the stream engine runs beside them on the render thread (stream_engine.c), its waves
 * taken from the same ranges.
 *
 * One device alone runs on the render thread.  Otherwise each device has a thread, and all take
 * their ranges through rs_run_take (run.c) under the run's lock: whoever is free takes the next
 * range, sized by its own rate against everyone's so that near the end of the plan each takes
 * what it finishes about when the others finish (guided self-scheduling: the last ranges shrink,
 * so no device is left with a long tail while another waits).  A device adds each call's samples to a
 * film of its own, which is merged into the run's film under the lock (exact sums: in any order
 * and any split, the one-device image bit for bit) before the range is recorded and the hooks
 * told.  A device that fails gives its range back, and the others (the stream engine first, on
 * the render thread) render it; the run fails only when nobody is left to. */
#include <stdio.h>
#include <string.h>

#include "core/clock.h"
#include "scheduler/engine_impl.h"

/* The first call's paths (a GPU's wave; a host device's: a few waves per thread), the fewest and
 * the most per call. */
#define RS_PATHS_FIRST_CALL (1ull << 21)
#define RS_PATHS_FIRST_HOST_CALL (4ull * RS_RENDER_HOST_WAVE)
#define RS_PATHS_MIN_CALL   (1ull << 16)
#define RS_PATHS_MAX_CALL   (1ull << 28)
/* Seconds of work per call once the device's rate is known. */
#define RS_PATHS_CALL_S 0.25

rs_status rs_paths_setup(rs_engine *e)
{
    rs_status st = RS_OK;
    int k;
    for (k = 0; k < e->n_pdev && st == RS_OK; ++k)
        if (e->pdev[k]->ops->upload_scene) /* a host device reads the host scene in place */
            st = e->pdev[k]->ops->upload_scene(e->pdev[k], e->scene, &e->it);
    if (st == RS_OK && (e->sched || e->n_pdev > 1))
        for (k = 0; k < e->n_pdev && st == RS_OK; ++k)
            st = rs_film_create(e->st.width, e->st.height, &e->pfilm[k]);
    if (st == RS_OK && e->sched)
        st = rs_stream_setup(e);
    return st;
}

static int paths_cancelled(void *user) { return rs_run_cancelled((const rs_run *)user); }

/* One path device's share of the run. */
typedef struct pdev_ctx {
    rs_run *c;
    int k;
    rs_status status;
    rs_path_counts counts;
    double busy_s;
    uint32_t calls;
    pthread_t thread;
    char why[512]; /* its failure's message (rs_error's is per thread) */
} pdev_ctx;

static void pdev_loop(pdev_ctx *p)
{
    rs_run *c = p->c;
    rs_engine *e = c->e;
    rs_device *d = e->pdev[p->k];
    const rs_render_hooks *hooks = c->hooks;
    rs_film *own = c->lock ? e->pfilm[p->k] : c->film;
    rs_paths_job job;
    uint64_t per = rs_device_owns_memory(d) ? RS_PATHS_FIRST_CALL
                                            : RS_PATHS_FIRST_HOST_CALL * (uint64_t)d->threads,
             lo, n;
    double ran_s = 0.0, ran_paths = 0.0;

    memset(&job, 0, sizeof job);
    job.it = &e->it;
    job.pixel_of = c->map.pixel_of;
    job.n_active = c->map.n_active;
    job.plan_id = e->plan_id;
    job.film = own;
    job.cancelled = paths_cancelled;
    job.user = c;
    /* the device's film keeps the variance sums and the passes when the run's does */
    if (own != c->film && c->film->sum_l2 && !own->sum_l2)
        p->status = rs_film_track_variance(own);
    if (p->status == RS_OK && own != c->film && c->film->pass && !own->pass)
        p->status = rs_film_keep_passes(own);
    while (p->status == RS_OK && rs_run_take(c, p->k, per, &lo, &n)) {
        uint64_t done = 0;
        double t0 = rs_now_s(), t1;
        rs_status st = d->ops->render_paths(d, &job, lo, lo + n, &done, &p->counts);
        t1 = rs_now_s();
        p->busy_s += t1 - t0;
        if (e->st.timeline) {
            double end = rs_timeline_now(e->st.timeline);
            rs_timeline_add(e->st.timeline, (uint16_t)p->k, RS_STAGE_PASS, p->calls,
                            end - (t1 - t0), end);
        }
        p->calls++;
        rs_run_lock(c);
        if (own != c->film && done) {
            if (st == RS_OK)
                st = rs_film_merge(c->film, own);
            rs_film_clear(own);
        }
        if (st != RS_OK && c->lock && c->n_redo < RS_ENGINE_MAX_PATH_DEVICES) {
            /* what it did not finish goes back to the others; its film is dropped */
            c->redo[c->n_redo][0] = lo;
            c->redo[c->n_redo][1] = lo + n;
            c->n_redo++;
            done = 0;
        } else {
            c->stats->paths_done += done;
            if (hooks && hooks->progress)
                hooks->progress(hooks->user, c->stats->paths_done, c->stats->paths_total);
            if (st == RS_OK && done)
                st = rs_run_on_film(c, lo, lo + done);
        }
        /* this device's rate, for its next share */
        ran_s += t1 - t0;
        ran_paths += (double)done;
        if (ran_s > 0)
            c->rate[p->k] = ran_paths / ran_s;
        rs_run_unlock(c);
        p->status = st;
        if (st != RS_OK || done < n)
            break; /* failed (its range given back), or cancelled within the call */
        if (t1 > t0) {
            double want = (double)n / (t1 - t0) * RS_PATHS_CALL_S;
            per = want < (double)RS_PATHS_MIN_CALL   ? RS_PATHS_MIN_CALL
                  : want > (double)RS_PATHS_MAX_CALL ? RS_PATHS_MAX_CALL
                                                     : (uint64_t)want;
        }
    }
}

static void *pdev_main(void *arg)
{
    pdev_ctx *p = (pdev_ctx *)arg;
    pdev_loop(p);
    if (p->status != RS_OK)
        snprintf(p->why, sizeof p->why, "%s: %s", p->c->e->pdev[p->k]->name, rs_error_message());
    return NULL;
}

rs_status rs_paths_run(rs_run *c)
{
    rs_engine *e = c->e;
    pdev_ctx p[RS_ENGINE_MAX_PATH_DEVICES];
    pthread_mutex_t lock;
    rs_status status = RS_OK;
    int k, started = 0, shared = e->sched || e->n_pdev > 1;
    memset(p, 0, sizeof p);
    for (k = 0; k < e->n_pdev; ++k) {
        p[k].c = c;
        p[k].k = k;
    }
    if (!shared) {
        pdev_loop(&p[0]); /* one device: on the render thread, onto the run's film */
    } else {
        pthread_mutex_init(&lock, NULL);
        c->lock = &lock;
        c->t0 = rs_now_s();
        for (k = 0; k < e->n_pdev; ++k)
            if (pthread_create(&p[k].thread, NULL, pdev_main, &p[k]) == 0)
                started |= 1 << k;
            else
                p[k].status = rs_error_set(RS_ERR_NOMEM, "cannot start a thread for %s",
                                           e->pdev[k]->name);
        if (e->sched)
            status = rs_stream_run(c);
        for (k = 0; k < e->n_pdev; ++k)
            if (started & (1 << k))
                pthread_join(p[k].thread, NULL);
        /* a device that failed late gave back a range nobody took: the CPU's, if any */
        if (status == RS_OK && e->sched && c->n_redo)
            status = rs_stream_run(c);
        c->lock = NULL;
        pthread_mutex_destroy(&lock);
    }
    for (k = 0; k < e->n_pdev; ++k) {
        c->stats->rays_closest += p[k].counts.closest;
        c->stats->rays_shadow += p[k].counts.shadow;
        if (p[k].counts.max_bounce > c->stats->max_bounce)
            c->stats->max_bounce = p[k].counts.max_bounce;
        c->stats->waves += p[k].calls;
        c->stats->stage_s[RS_STAGE_PASS] += p[k].busy_s;
        e->pdev[k]->stats.busy_s += p[k].busy_s;
        e->pdev[k]->stats.chunks += p[k].calls;
        e->pdev[k]->stats.rays += p[k].counts.closest + p[k].counts.shadow;
        e->pdev[k]->stats.failures += p[k].status != RS_OK && shared;
    }
    /* a device's failure is the run's only when its range was left undone */
    for (k = 0; k < e->n_pdev && status == RS_OK; ++k)
        if (p[k].status != RS_OK && (!shared || c->n_redo))
            status = shared ? rs_error_set(p[k].status, "%s", p[k].why) : p[k].status;
    if (status == RS_OK && shared && c->n_redo)
        status = rs_error_set(RS_ERR_DEVICE_LOST, "every device that could render failed");
    if (status == RS_OK && rs_run_cancelled(c))
        status = rs_error_set(RS_ERR_CANCELLED, "render interrupted");
    return status;
}
