/* app/dist_glue.c — `raystream render` under mpirun (docs/distributed.md): every rank runs the
 * render's setup steps (app/render_run.h), rank 0 hands out passes of samples and gathers the
 * films (app/distributed.h), then writes the outputs as one render would. */
#include "app/dist_glue.h"

#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "app/signals.h"
#include "core/alloc.h"
#include "core/clock.h"

/* Sends stderr to `fd` (flushing first); returns what restores it, or -1 when it could not be
 * moved. */
static int stderr_divert(int fd)
{
    int saved;
    fflush(stderr);
    if ((saved = dup(2)) >= 0)
        dup2(fd, 2);
    return saved;
}

/* Undoes stderr_divert (nothing for -1). */
static void stderr_restore(int saved)
{
    if (saved < 0)
        return;
    fflush(stderr);
    dup2(saved, 2);
    close(saved);
}

int rs_mpi_parse_options(int argc, char **argv, rs_cli_options *o)
{
    int ranks, rank = 0, local, saved = -1, rc;
    if (rs_dist_launched(&ranks, &rank, &local) && rank > 0) {
        int null = open("/dev/null", O_WRONLY);
        if (null >= 0) {
            saved = stderr_divert(null);
            close(null);
        }
    }
    rc = rs_cli_parse(argc, argv, o);
    stderr_restore(saved);
    return rc;
}

/* One pass of an MPI job: samples [s0, s0 + n) of the job's pixels onto `film`, on this rank's
 * devices, from its render thread. */
static rs_status dist_render_pass(void *user, const uint32_t *pixels, uint32_t n_pixels,
                                  uint32_t s0, uint32_t n, rs_film *film,
                                  const atomic_int *cancel, rs_render_stats *stats)
{
    render_run *r = (render_run *)user;
    uint64_t np = pixels ? n_pixels : (uint64_t)r->st.width * r->st.height;
    rs_render_hooks h;
    rs_work_plan plan;
    rs_status st;
    memset(&h, 0, sizeof h);
    h.cancel = cancel;
    if (!rs_work_plan_samples(&plan, np, s0, s0 + n)) {
        st = rs_error_set(RS_ERR_NOMEM, "out of memory");
    } else {
        plan.pixels = pixels;
        plan.n_pixels = pixels ? n_pixels : 0;
        st = rs_engine_run(r->engine, &plan, &h, film, stats);
    }
    rs_work_plan_free(&plan);
    return st;
}

/* "host: cpu (2 threads), gpu0" */
static void dist_describe(const render_run *r, char *out, size_t n)
{
    char host[64] = "?";
    size_t len;
    int i;
    gethostname(host, sizeof host - 1);
    host[sizeof host - 1] = 0;
    len = (size_t)snprintf(out, n, "%s:", host);
    for (i = 0; i < (r->mk ? 1 : r->n_devs) && len < n; ++i) {
        const rs_device *d = r->mk ? r->mk : r->devs[i];
        len += (size_t)snprintf(out + len, n - len, "%s %s", i ? "," : "", d->name);
    }
}

/* RS_MPI_FAULT (the fault a test injects), refused by rank 0 (the others stay quiet) when it
 * does not parse.  Every option an MPI job takes is honoured. */
static int dist_check_options(int rank, rs_dist_fault *fault)
{
    if (rs_dist_fault_parse(getenv("RS_MPI_FAULT"), fault) == RS_OK)
        return RS_EXIT_OK;
    if (rank == 0)
        rs_app_fail(0, NULL);
    rs_error_clear();
    return RS_EXIT_USAGE;
}

/* The setup steps on one rank: scene, settings, BVH, devices; rank 0 also the outputs and the
 * film (with --resume).  Returns an exit code. */
static int dist_setup_steps(const rs_cli_options *o, render_run *r)
{
    int code = rs_run_load_scene(o, r);
    if (code == RS_EXIT_OK) {
        rs_run_settings(o, r);
        if (r->rank == 0) {
            if (o->tev) /* the ranks' samples meet in rank 0's film only as passes end */
                rs_app_print("raystream: warning: --tev: no live preview under mpirun; the render "
                             "goes on without it\n");
            if ((code = rs_run_check_outputs(o, r)) == RS_EXIT_OK)
                code = rs_run_make_film(o, r);
        } else if (rs_run_new_film(r, &r->film) != RS_OK) {
            code = rs_app_fail(RS_EXIT_RUNTIME, "starting the render");
        }
    }
    if (code == RS_EXIT_OK && r->rank == 0)
        code = rs_run_resume_whole_samples(o, r,
                                           "under mpirun a render continues whole samples "
                                           "only (resume it on one process)");
    if (code == RS_EXIT_OK && (code = rs_run_build_bvh(o, r)) == RS_EXIT_OK)
        code = rs_run_start_devices(o, r);
    return code;
}

/* The set-up on a rank's start-up thread (rs_dist_start): an exit code, the description. */
typedef struct setup_ctx {
    const rs_cli_options *o;
    render_run *r;
    int code; /* this rank's */
} setup_ctx;

static int setup_thread(void *user, char *desc, size_t n)
{
    setup_ctx *c = (setup_ctx *)user;
    int code = c->code = dist_setup_steps(c->o, c->r);
    desc[0] = 0;
    if (code == RS_EXIT_OK)
        dist_describe(c->r, desc, n);
    if (c->r->dist_fault.die_start_rank == c->r->rank)
        raise(SIGKILL); /* a test of a rank lost while it starts */
    return code;
}

/* Every rank: the setup steps.  The others' messages are held back until the ranks agree: when
 * rank 0 failed too it has said why, and only a rank that failed alone shows its own.  Returns
 * the job's exit code, the same on every rank. */
static int dist_setup(const rs_cli_options *o, render_run *r)
{
    int code, worst, who = 0, saved = -1;
    FILE *held = NULL;
    setup_ctx c;
    memset(&c, 0, sizeof c);
    if ((code = dist_check_options(r->rank, &r->dist_fault)) != RS_EXIT_OK)
        return code;
    if (r->rank > 0 && (held = tmpfile()) != NULL)
        saved = stderr_divert(fileno(held));
    c.o = o;
    c.r = r;
    worst = rs_dist_start(r->dist, setup_thread, &c, o->mpi_timeout_s, &who);
    stderr_restore(saved);
    if (held) {
        if (worst != RS_EXIT_OK && who == r->rank) { /* rank 0 started: say why this one did not */
            char line[512];
            rewind(held);
            while (fgets(line, sizeof line, held))
                fprintf(stderr, "raystream: rank %d: %s", r->rank,
                        strncmp(line, "raystream: ", 11) == 0 ? line + 11 : line);
        }
        fclose(held);
    }
    if (worst != RS_EXIT_OK && r->rank == 0 && c.code == RS_EXIT_OK && !rs_dist_lost(r->dist))
        fprintf(stderr,
                "raystream: rank %d could not start (its message is above); no rank "
                "renders\n",
                who);
    return worst;
}

static void on_dist_progress(void *user, uint64_t done, uint64_t total)
{
    rs_progress_update(&((render_run *)user)->progress, done, total);
}

/* The film held r->held, plus the job's finished passes `done`. */
static int dist_held(render_run *r, const rs_path_ranges *done, rs_path_ranges *out)
{
    memset(out, 0, sizeof *out);
    return rs_path_ranges_union(out, &r->held) && rs_path_ranges_union(out, done);
}

/* rank 0, after each periodic flush of an MPI job: the --checkpoint */
static void on_dist_saved(void *user, const rs_film *film, const rs_path_ranges *done)
{
    render_run *r = (render_run *)user;
    rs_path_ranges held;
    if (dist_held(r, done, &held))
        (void)rs_checkpoint_write(r->ckpt_out->path, r->ckpt_out->staged, 1, &r->key, film, &held);
    rs_path_ranges_free(&held);
}

/* Rank 0, after the job: its result as one render's statistics, the film's ranges for the
 * final checkpoint.  Returns an exit code. */
static int dist_gathered(render_run *r, rs_status st)
{
    uint64_t npix = (uint64_t)r->st.width * r->st.height;
    rs_path_ranges now;
    r->stats = r->dres.local;
    r->stats.seconds = r->dres.seconds;
    r->stats.paths_total = npix * r->st.spp - r->resumed;
    r->stats.paths_done = npix * r->dres.samples_done;
    r->stats.rays_closest = r->dres.rays_closest;
    r->stats.rays_shadow = r->dres.rays_shadow;
    r->stats.max_bounce = r->dres.max_bounce;
    r->stats.time_limited = r->dres.time_limited;
    if (st != RS_OK)
        return rs_app_fail(RS_EXIT_RUNTIME, "render failed");
    /* what the film holds now, for the final checkpoint (app/checkpoint.h: any ranges) */
    if (!dist_held(r, &r->dres.done, &now)) {
        rs_path_ranges_free(&now);
        return rs_app_fail(RS_EXIT_RUNTIME, "out of memory");
    }
    rs_path_ranges_free(&r->held);
    r->held = now;
    r->done = NULL;
    if (r->dres.stopped) {
        r->interrupted = rs_signals_caught() ? rs_signals_caught() : SIGTERM;
        return RS_EXIT_SIGNALLED(r->interrupted);
    }
    return RS_EXIT_OK;
}

/* The settings of a job every rank shares: the samples (rank 0) and the pixels are the
 * caller's. */
static void dist_job_init(const rs_cli_options *o, render_run *r, rs_dist_job *job)
{
    memset(job, 0, sizeof *job);
    job->fault = r->dist_fault;
    job->width = r->st.width;
    job->height = r->st.height;
    job->spp = r->st.spp;
    job->variance = r->img.adaptive > 0;
    job->passes = r->st.passes != 0;
    job->plan.pass_samples = o->mpi_pass_spp;
    job->plan.time_limit_s = o->time_limit_s;
    job->t_start = rs_now_s();
    job->timeout_s = o->mpi_timeout_s > 0 ? o->mpi_timeout_s : 60.0;
    job->cancel = rs_signals_cancel();
    job->render = dist_render_pass;
    job->user = r;
}

/* ---- --adaptive under mpirun ---------------------------------------------------------------
 * Rank 0 runs the rounds of scheduler/adaptive.h and decides each one from the frame, as one
 * process does; each round is one job over the ranks (rs_dist_job_begin tells them its pixels).
 * The film's sums, the squared-luminance ones included, are exact integers, so the frame after
 * a round, every decision and the image are the one process's bit for bit.  Checkpoints are
 * written between rounds. */

typedef struct dist_rounds {
    render_run *r;
    rs_dist_job job;              /* the settings every round shares */
    const rs_render_hooks *hooks; /* the adaptive run's, while a round runs */
    double t0;
    int uneven;                   /* a stop left gaps in the round under way */
} dist_rounds;

static rs_status round_pass(void *user, const uint32_t *pixels, uint32_t n_pixels, uint32_t s0,
                            uint32_t n, rs_film *film, const atomic_int *cancel,
                            rs_render_stats *stats)
{
    return dist_render_pass(((dist_rounds *)user)->r, pixels, n_pixels, s0, n, film, cancel,
                            stats);
}

static void round_progress(void *user, uint64_t done, uint64_t total)
{
    const rs_render_hooks *h = ((const dist_rounds *)user)->hooks;
    if (h && h->progress)
        h->progress(h->user, done, total);
}

/* The job's result as the round's statistics (rank 0's stages, every rank's rays). */
static void round_stats(const rs_dist_result *res, uint64_t np, rs_render_stats *stats)
{
    *stats = res->local;
    stats->paths_done = (uint64_t)res->samples_done * np;
    stats->rays_closest = res->rays_closest;
    stats->rays_shadow = res->rays_shadow;
    stats->max_bounce = res->max_bounce;
    stats->time_limited = res->time_limited;
    stats->seconds = res->seconds;
}

/* rs_plan_runner on rank 0: a round, or what a checkpoint left of it, as one job. */
static rs_status dist_round(void *user, const rs_work_plan *plan, const rs_render_hooks *hooks,
                            rs_film *film, rs_render_stats *stats)
{
    dist_rounds *dr = (dist_rounds *)user;
    render_run *r = dr->r;
    uint64_t np = plan->pixels ? plan->n_pixels : (uint64_t)r->st.width * r->st.height;
    uint64_t lo = plan->todo.n ? plan->todo.r[0][0] : 0, hi = plan->todo.n ? plan->todo.r[0][1] : 0;
    rs_dist_job job = dr->job;
    rs_dist_result res;
    rs_status st;
    if (plan->todo.n > 1 || lo % np || hi % np)
        return rs_error_set(RS_ERR_ARG, "under mpirun an adaptive render continues whole "
                                        "samples of its round only (resume it on one process)");
    if (lo == hi)
        return RS_OK;
    job.plan.todo = plan->todo; /* the round's plan: its budget counts from dr->t0 */
    job.plan.pixels = plan->pixels;
    job.plan.n_pixels = plan->n_pixels;
    job.plan.time_limit_s = plan->time_limit_s;
    job.t_start = dr->t0;
    if (!rs_dist_job_begin(r->dist, plan->pixels, plan->n_pixels, job.timeout_s))
        return rs_error_set(RS_ERR_NOMEM, "out of memory");
    dr->hooks = hooks;
    st = rs_dist_render(r->dist, &job, film, &res);
    dr->hooks = NULL;
    round_stats(&res, np, stats);
    stats->paths_total = hi - lo;
    if (st == RS_OK && !rs_dist_result_add(&r->dres, &res))
        st = rs_error_set(RS_ERR_NOMEM, "out of memory");
    if (st == RS_OK && res.stopped) {
        /* resumable only if what the round finished is its first samples */
        dr->uneven = !(res.done.n == 0 || (res.done.n == 1 && res.done.r[0][0] == lo));
        st = rs_error_set(RS_ERR_CANCELLED, "stopped");
    } else if (st == RS_OK && res.complete && hooks && hooks->film_ready) {
        rs_path_ranges done;
        memset(&done, 0, sizeof done);
        if (rs_path_ranges_add(&done, lo, hi))
            hooks->film_ready(hooks->user, film, &done);
        rs_path_ranges_free(&done);
    }
    rs_dist_result_free(&res);
    return st;
}

/* Every other rank: the rounds' jobs, until rank 0 says the run is over. */
static rs_status dist_rounds_work(render_run *r, const rs_dist_job *base)
{
    for (;;) {
        rs_dist_job job = *base;
        rs_dist_result res;
        uint32_t *pixels, n_pixels;
        rs_status st;
        int go = rs_dist_job_wait(r->dist, &pixels, &n_pixels, base->timeout_s);
        if (go <= 0)
            return go == 0 ? RS_OK : rs_error_set(RS_ERR_IO, "rank 0 is gone");
        job.plan.pixels = pixels;
        job.plan.n_pixels = n_pixels;
        st = rs_dist_render(r->dist, &job, r->film, &res);
        rs_free(pixels);
        if (st != RS_OK)
            return st;
    }
}

/* Rank 0: the adaptive rounds over the ranks.  Returns an exit code. */
static int dist_run_adaptive(const rs_cli_options *o, render_run *r, const rs_dist_job *base)
{
    dist_rounds dr;
    rs_adaptive a;
    rs_render_hooks hooks;
    rs_status st;
    memset(&dr, 0, sizeof dr);
    dr.r = r;
    dr.job = *base;
    dr.job.render = round_pass;
    dr.job.user = &dr;
    dr.job.progress = round_progress;
    dr.t0 = rs_now_s();
    a.threshold = r->img.adaptive;
    a.min_spp = r->img.adaptive_min_spp;
    a.time_limit_s = base->plan.time_limit_s;
    memset(&hooks, 0, sizeof hooks);
    hooks.progress = on_dist_progress;
    hooks.user = r;
    hooks.cancel = base->cancel;
    r->ckpt_every_s = o->ckpt_every_s;
    r->last_ckpt = rs_now_s();
    if (r->ckpt_out) {
        hooks.film_ready = rs_run_on_film_ready;
        rs_outputs_track(r->ckpt_out->staged); /* a second signal during a write */
    }
    rs_progress_begin(&r->progress, !o->quiet);
    st = rs_adaptive_run_plans(dist_round, &dr, r->st.spp, &a, &r->ad, &hooks, r->film,
                               &r->stats);
    rs_progress_end(&r->progress);
    rs_dist_jobs_end(r->dist);
    r->adaptive = r->ad.stats;
    r->done = NULL;
    if (dr.uneven && r->ckpt_out) {
        fprintf(stderr, "raystream: --checkpoint %s: not updated: the stop left gaps in the "
                        "adaptive round under way; the last one written stays\n",
                r->ckpt_out->path);
        r->ckpt_out->dropped = 1; /* not renamed over the last one written */
        r->ckpt_out = NULL;
    }
    if (st == RS_ERR_CANCELLED) {
        rs_error_clear();
        r->interrupted = rs_signals_caught() ? rs_signals_caught() : SIGTERM;
        return RS_EXIT_SIGNALLED(r->interrupted);
    }
    return st == RS_OK ? RS_EXIT_OK : rs_app_fail(RS_EXIT_RUNTIME, "render failed");
}

/* The job: rank 0 hands out the passes and gathers the films, every rank renders.  Rank 0 then
 * has the frame and the statistics in r.  Returns an exit code. */
static int dist_run(const rs_cli_options *o, render_run *r)
{
    rs_dist_job job;
    rs_status st;
    rs_path_ranges todo;
    rs_signals_install();
    memset(&todo, 0, sizeof todo);
    dist_job_init(o, r, &job);
    if (r->img.adaptive > 0 && r->rank > 0)
        return dist_rounds_work(r, &job) == RS_OK ? RS_EXIT_OK
                                                  : rs_app_fail(RS_EXIT_RUNTIME, NULL);
    if (r->img.adaptive > 0)
        return dist_run_adaptive(o, r, &job);
    /* rank 0: the paths the film lacks (all of them, or the gaps of a --resume, which start and
     * end on whole samples: checked at --resume) */
    if (r->rank == 0 &&
        !rs_path_ranges_complement(&r->held, (uint64_t)r->st.width * r->st.height * r->st.spp,
                                   &todo)) {
        rs_path_ranges_free(&todo);
        return rs_app_fail(RS_EXIT_RUNTIME, "out of memory");
    }
    job.plan.todo = todo;
    if (r->ckpt_out) {
        job.flush_every_s = o->ckpt_every_s;
        job.saved = on_dist_saved;
    }
    if (r->rank == 0)
        job.progress = on_dist_progress;
    if (r->rank == 0)
        rs_progress_begin(&r->progress, !o->quiet);
    st = rs_dist_render(r->dist, &job, r->film, &r->dres);
    rs_path_ranges_free(&todo);
    if (r->rank == 0)
        rs_progress_end(&r->progress);
    if (r->rank > 0)
        return st == RS_OK ? RS_EXIT_OK : rs_app_fail(RS_EXIT_RUNTIME, NULL);
    return dist_gathered(r, st);
}

static int cmd_render_dist(const rs_cli_options *o, render_run *r)
{
    int code = dist_setup(o, r);
    if (code != RS_EXIT_OK)
        return code;
    code = dist_run(o, r);
    if (r->rank == 0 && (code == RS_EXIT_OK || r->interrupted))
        code = rs_run_write_outputs(o, r, code);
    rs_dist_result_free(&r->dres);
    return code;
}

typedef struct init_ctx {
    int *argc;
    char ***argv;
    rs_dist **d;
} init_ctx;

static int init_mpi(void *arg)
{
    init_ctx *c = (init_ctx *)arg;
    return rs_dist_init(c->argc, c->argv, c->d) == RS_OK;
}

/* MPI_Init, bounded: with mpirun --enable-recovery a rank that died before it leaves the others
 * waiting in it for ever.  At least 10 s (a loaded machine), else --mpi-timeout.  1 if it
 * started. */
static int start_mpi(const rs_cli_options *o, int *argc, char ***argv, int rank, rs_dist **d)
{
    double limit = o->mpi_timeout_s > 10 ? o->mpi_timeout_s : 10;
    rs_dist_fault f;
    init_ctx c;
    char line[256];
    if (rs_dist_fault_parse(getenv("RS_MPI_FAULT"), &f) == RS_OK && f.die_init_rank == rank)
        raise(SIGKILL); /* a test of a rank lost before MPI starts */
    rs_error_clear(); /* a bad spec is reported after the start */
    c.argc = argc;
    c.argv = argv;
    c.d = d;
    snprintf(line, sizeof line,
             "raystream: rank %d: MPI did not start within %.0f s (a rank may have died while "
             "starting); stopping\n",
             rank, limit);
    return rs_watch_run(limit, line, init_mpi, &c);
}

/* Whether an MPI launcher started this process: then r->dist (and 1), or an exit code. */
static int start_dist(const rs_cli_options *o, int *argc, char ***argv, render_run *r, int *code)
{
    int ranks = 1, rank = 0, local = 1;
    *code = RS_EXIT_OK;
    if (!rs_dist_launched(&ranks, &rank, &local))
        return 0;
    if (!rs_dist_built()) {
        if (ranks <= 1)
            return 0;
        if (rank == 0)
            fprintf(stderr,
                    "raystream: started by mpirun as %d ranks, but this raystream was "
                    "built without MPI (install libopenmpi-dev and rebuild; "
                    "RS_MPI=AUTO finds it): every rank would render the whole frame\n",
                    ranks);
        *code = RS_EXIT_USAGE;
        return 1;
    }
    if (!start_mpi(o, argc, argv, rank, &r->dist)) {
        *code = rs_app_fail(RS_EXIT_RUNTIME, "starting MPI");
        return 1;
    }
    r->rank = rs_dist_rank(r->dist);
    r->local_ranks = local;
    return 1;
}

int rs_mpi_render(const rs_cli_options *o, int *argc, char ***argv, render_run *r, int *code)
{
    rs_cli_options wo = *o;
    if (!start_dist(o, argc, argv, r, code))
        return 0;
    if (!r->dist)
        return 1;
    if (r->rank > 0)
        wo.quiet = 1; /* rank 0 shows the progress and the summary */
    if (rs_fault_parse(getenv("RS_FAULT"), &r->fault) != RS_OK)
        *code = rs_app_fail(RS_EXIT_USAGE, NULL);
    else
        *code = cmd_render_dist(&wo, r);
    rs_run_release(r);
    rs_dist_finish(r->dist);
    return 1;
}
