/* app/distributed.h — one frame rendered by the ranks of an MPI job (`mpirun -n N raystream
 * render SCENE ...`, built when CMake finds MPI: RS_MPI=AUTO|ON|OFF).  docs/distributed.md.
 *
 * Every rank loads the scene and starts its own devices.  The frame is cut into passes of
 * `pass_spp` samples of every pixel; rank 0 hands them out on request, lowest first, so a slower
 * rank asks less often and gets fewer.  Each rank renders a pass onto a scratch film and adds it
 * to its own film when the pass is whole; at the end each rank sends its film to rank 0, which
 * adds them.  Since film sums are exact integers (shading/film.h), the result is the one-process
 * image of the same samples bit for bit, whatever the ranks, the split and the order.
 *
 * Threads: MPI is only ever called from the thread that initialised it (MPI_THREAD_FUNNELED),
 * the main thread, which runs the messaging loop: it probes without blocking and sleeps between
 * probes (0.1 to 2 ms), since Open MPI's blocking calls spin a core.  Each rank renders on a
 * second thread, which takes passes from a queue of two (one under way, one waiting).
 *
 * Stopping: the time limit on rank 0 hands out no new pass; the passes under way finish, so the
 * film holds samples [0, k) of every pixel.  A stop signal on rank 0 (or mpirun's SIGTERM on
 * every rank, which Open MPI follows with SIGKILL after odls_base_sigkill_timeout, 1 s by
 * default) drops the passes under way, and every rank sends what it finished at once.
 *
 * A rank is dead when MPI reports an error talking to it or it has been silent for `timeout_s`
 * (every rank sends a heartbeat each second).  Its passes, under way or finished but not yet
 * sent, are handed to the others again: Open MPI lets the job go on when mpirun runs with
 * --enable-recovery; without it mpirun ends the whole job, and rank 0 writes what it has in the
 * second it is given. */
#ifndef RS_APP_DISTRIBUTED_H
#define RS_APP_DISTRIBUTED_H

#include <stdatomic.h>
#include <stdint.h>

#include "core/status.h"
#include "scheduler/render.h"
#include "shading/film.h"

#define RS_DIST_DESC 96 /* one rank's description: "host: devices" */

/* Whether an MPI launcher started this process (its environment; MPI is not touched), with the
 * job's size, this process's rank and the ranks on this machine (1 where unknown). */
int rs_dist_launched(int *ranks, int *rank, int *local_ranks);
/* Whether this binary was built with MPI. */
int rs_dist_built(void);

typedef struct rs_dist rs_dist;

/* MPI_Init_thread(FUNNELED), errors returned rather than fatal.  RS_ERR_* with a message. */
rs_status rs_dist_init(int *argc, char ***argv, rs_dist **out);
int rs_dist_rank(const rs_dist *d);
int rs_dist_size(const rs_dist *d);
/* Every rank, once: runs setup(user, desc, n) (the rank's set-up: loading the scene, building
 * the BVH, starting the devices; an exit code, and the rank's description into desc) on a
 * thread of its own while this thread, MPI's, keeps in touch with rank 0, then agrees with the
 * others: returns the worst exit code over the ranks (0: all started), *who the lowest rank
 * with it; rank 0 keeps each rank's description for the statistics.  Nothing blocks for ever:
 * a rank silent for timeout_s while starting (dead) ends the start-up on every rank with
 * RS_EXIT_RUNTIME (rank 0 says which rank), and no rank calls MPI_Finalize. */
int rs_dist_start(rs_dist *d, int (*setup)(void *user, char *desc, size_t n), void *user,
                  double timeout_s, int *who);
/* Whether a rank was found dead (or rank 0 is gone). */
int rs_dist_lost(const rs_dist *d);
/* MPI_Finalize when every rank is known to be alive; otherwise nothing (a finalize would wait
 * for the dead).  Frees d. */
void rs_dist_finish(rs_dist *d);

/* Test faults (RS_MPI_FAULT): "slow:R:F" makes rank R take F times as long per pass (it sleeps
 * after each); "die:R:K" makes rank R kill itself (SIGKILL) after finishing K passes, before it
 * sends them; "die-start:R" kills rank R at the end of its set-up (having loaded the scene),
 * "die-init:R" just before it starts MPI.  Several, comma-separated. */
typedef struct rs_dist_fault {
    int slow_rank;
    double slow_factor; /* 0: none */
    int die_rank;       /* -1: none */
    uint32_t die_after;
    int die_start_rank; /* -1: none */
    int die_init_rank;  /* -1: none */
} rs_dist_fault;
rs_status rs_dist_fault_parse(const char *spec, rs_dist_fault *out);

/* Renders samples [s0, s0 + n) of the job's pixels (`pixels`, n_pixels of them; NULL: every
 * pixel) onto `film` (empty, the frame's size); stops early with RS_ERR_CANCELLED when *cancel
 * is set.  `stats` as rs_render's. */
typedef rs_status (*rs_dist_render_fn)(void *user, const uint32_t *pixels, uint32_t n_pixels,
                                       uint32_t s0, uint32_t n, rs_film *film,
                                       const atomic_int *cancel, rs_render_stats *stats);

/* rank 0, every `flush_every_s`: the film holds the samples it held before plus `done`
 * (path ranges, as job->plan.todo numbers them); it may be read, not written */
typedef void (*rs_dist_saved_fn)(void *user, const rs_film *film, const rs_path_ranges *done);

typedef struct rs_dist_job {
    uint32_t width, height, spp;
    /* The job's plan (scheduler/plan.h; not owned: its ranges are the caller's).  Every rank:
     * plan.pixels, increasing (rank 0 tells the others with rs_dist_job_begin; NULL: every
     * pixel), and plan.n_pixels.  Rank 0: plan.todo, the paths to render in the plan's
     * numbering over the job's pixels, each range whole samples (what the film does not hold;
     * the passes are cut from it, dist_passes.c); plan.pass_samples, samples per pass (0: auto,
     * about 8 passes per rank, at most about 2^21 paths a pass); plan.time_limit_s, the
     * render's budget from t_start (the one rule: rs_work_plan_time_cut, as the engine's). */
    rs_work_plan plan;
    double t_start;             /* rank 0: when the render began (rs_now_s); 0: the job's start */
    int variance;               /* every rank: films keep squared-luminance sums (--adaptive) */
    int passes;                 /* every rank: films keep the passes (--aov, --denoise) */
    double flush_every_s;       /* rank 0: > 0, every rank sends what it finished this often
                                   (then `saved` is called); 0: only at the end */
    rs_dist_saved_fn saved;
    double timeout_s;           /* a rank silent this long is dead; 0: 60 */
    const atomic_int *cancel;   /* rank 0 and every rank: a stop signal */
    rs_dist_render_fn render;
    void (*progress)(void *user, uint64_t paths_done, uint64_t paths_total); /* rank 0; NULL */
    void *user;
    rs_dist_fault fault;
} rs_dist_job;

typedef struct rs_dist_rank_stats {
    char desc[RS_DIST_DESC];
    uint32_t passes;    /* passes this rank finished and rank 0 added */
    uint64_t paths;     /* their samples */
    double busy_s;      /* seconds its render thread spent rendering */
    double wall_s;      /* from the first request to its film's arrival */
    uint64_t film_bytes; /* the films it sent */
    uint64_t rays_closest, rays_shadow;
    double comm_cpu_s;  /* CPU seconds of its messaging thread (which sleeps between probes) */
    int alive;          /* 0: found dead (its passes were handed out again) */
    int failed;         /* its render failed (its passes were handed out again) */
} rs_dist_rank_stats;

typedef struct rs_dist_result {
    int ranks;
    uint32_t pass_spp, passes_total;
    uint32_t samples_done;     /* samples of every pixel this job added to the film */
    rs_path_ranges done;       /* which: path ranges, as job->todo numbers them */
    int complete;              /* every sample of `todo` is on the film */
    uint32_t flushes;          /* times every rank sent what it had finished */
    int time_limited, stopped; /* the time limit / a stop signal ended it early */
    int dead;                  /* ranks found dead */
    uint32_t reissued;         /* passes handed out again */
    uint64_t bytes_received;   /* film data received by rank 0 */
    uint64_t messages, message_bytes; /* rank 0's control messages (requests, passes, heartbeats)
                                         sent and received, and their payload */
    double seconds;
    rs_render_stats local;     /* rank 0's own passes, summed (rays, stages) */
    uint64_t rays_closest, rays_shadow; /* every rank's */
    uint32_t max_bounce;
    rs_dist_rank_stats *rank;  /* [ranks], rank 0 only; freed by rs_dist_result_free */
} rs_dist_result;

/* Collective: renders `job` over every rank into `film` (rank 0: the frame, which may already
 * hold the paths outside job->todo; other ranks: scratch of the frame's size).  Rank 0 fills
 * *res.  RS_OK also when stopped early (res says so); an error when rank 0's own render failed
 * or every rank was lost. */
rs_status rs_dist_render(rs_dist *d, const rs_dist_job *job, rs_film *film, rs_dist_result *res);
void rs_dist_result_free(rs_dist_result *res);
/* Adds one job's result to a run's (rank 0; `total` zeroed before the first): the counts
 * summed, the rank table row by row, `done` left out.  0 when out of memory. */
int rs_dist_result_add(rs_dist_result *total, const rs_dist_result *job);

/* Several jobs in one MPI run, each over pixels rank 0 decides from the frame the jobs before
 * left (the rounds of --adaptive).  Rank 0, before each job: rs_dist_job_begin tells every live
 * rank the job's pixels (NULL: all; 0 when no rank is left to tell); after the last job:
 * rs_dist_jobs_end.  Every other rank, before each job: rs_dist_job_wait, 1 with the next job's
 * pixels (*pixels rs_alloc'd, NULL for all), 0 after the last job, -1 when rank 0 has been
 * silent for `timeout_s`.  A rank found dead in one job takes no part in the later ones. */
int rs_dist_job_begin(rs_dist *d, const uint32_t *pixels, uint32_t n_pixels, double timeout_s);
void rs_dist_jobs_end(rs_dist *d);
int rs_dist_job_wait(rs_dist *d, uint32_t **pixels, uint32_t *n_pixels, double timeout_s);

#endif
