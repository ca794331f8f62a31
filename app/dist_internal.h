/* app/dist_internal.h — what the files of distributed.h's MPI build share (built only with MPI;
 * distributed_none.c otherwise):
 *   distributed.c       rs_dist_render (rank 0 coordinates, the others work), faults, results
 *   dist_launch.c       the launcher's environment, MPI's start and end, the sanitizers' lists
 *   dist_wire.c         the messages: tags, the film's header and data, polling without spinning
 *   dist_local.c        the render thread every rank runs beside its messaging
 *   dist_passes.c       rank 0's table of passes (which samples, whose, in what state)
 *   dist_coordinator.c  rank 0: hands out passes, one handler per message tag, adds the films
 *   dist_worker.c       the other ranks: ask, render, report, send the film
 *
 * Messages (MPI_COMM_WORLD, uint64 payloads):
 *   worker -> 0   REQ   (nothing)            wants one more pass
 *                 HB    (nothing)            a heartbeat, each second
 *                 DONE  s0, n                a pass finished (on the worker's film)
 *                 FILM  header, then the data (FILM_SUMS chunks, FILM_COUNTS chunks)
 *   0 -> worker   PASS  s0, n                render it
 *                 STOP  (nothing)            finish the passes you hold, then send the film
 *                 ABORT (nothing)            drop what is under way, send the film now
 *                 FLUSH (nothing)            send what you finished (DONEs, then FILM flagged
 *                                            H_FLUSH), and go on from an empty film
 *                 HB    (nothing)            a heartbeat, each second
 *                 BYE   lost                 the job is over (after your film): call
 *                                            MPI_Finalize unless a rank was lost (it would
 *                                            wait for the dead); between the jobs of a run of
 *                                            several (rs_dist_job_begin), the run is over
 *                 JOB   n                    the next job is over n pixels (then JOB_PIXELS
 *                                            chunks, uint32) or every pixel (n = 0)
 * Before any of these, the start-up agreement (rs_dist_start):
 *   rank -> 0     HB    (nothing)            each second while it sets up
 *                 READY code, description    set up (RS_EXIT_OK) or not (its exit code)
 *   0 -> rank     HB    (nothing)            each second
 *                 GO    worst code, who      every rank is READY (or `who` is dead): go on
 *                                            when the code is 0, else stop
 * A film's data: FILM_SUMS chunks, FILM_COUNTS chunks, and, when its header's H_SQ says so,
 * FILM_SQ chunks (three uint64 a pixel: rs_film_sq), then, when H_PASS_DATA says so,
 * FILM_PASSES chunks: the passes' sums (2 RS_FILM_PASSES uint64 a pixel, low words first), then
 * the hit counts (uint32 a pixel).
 * Messages between two ranks arrive in the order they were sent, so a worker's DONEs precede
 * its film. */
#ifndef RS_APP_DIST_INTERNAL_H
#define RS_APP_DIST_INTERNAL_H

#include <mpi.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>

#include "app/distributed.h"

struct rs_dist {
    int rank, size;
    int any_dead;
    char (*desc)[RS_DIST_DESC]; /* rank 0: every rank's */
    uint8_t *dead;              /* rank 0: ranks found dead in an earlier job (NULL: none) */
};

/* ---- the wire (dist_wire.c) ---------------------------------------------------------------- */

enum {
    T_REQ = 1,
    T_HB,
    T_DONE,
    T_FILM,
    T_FILM_SUMS,
    T_FILM_COUNTS,
    T_PASS,
    T_STOP,
    T_ABORT,
    T_FLUSH,
    T_BYE,
    T_FILM_SQ,
    T_JOB,
    T_JOB_PIXELS,
    T_READY,
    T_GO,
    T_FILM_PASSES,
    T_COUNT /* one past the last tag */
};

/* FILM header fields (uint64; doubles by their bits) */
enum {
    H_ENC,       /* 0: sums as int64 (they all fit), 1: as int128 (two words, low first) */
    H_PASSES,
    H_PATHS,
    H_RAYS_C,
    H_RAYS_S,
    H_MAX_BOUNCE,
    H_NONFINITE,
    H_BUSY,      /* double */
    H_FAILED,    /* the worker's render failed */
    H_FLUSH,     /* a periodic flush: the worker goes on */
    H_COMM_CPU,  /* double: CPU seconds of its messaging thread so far */
    H_SQ,        /* 1: FILM_SQ chunks follow the counts */
    H_PASS_DATA, /* 1: FILM_PASSES chunks follow (the film's passes, shading/film.h) */
    H_COUNT
};

#define DIST_CHUNK (1u << 24) /* elements per data message (128 MB of int64) */

/* this rank's small messages, sent and received, and their payload bytes */
extern uint64_t rs_dist_msgs, rs_dist_msg_bytes;
/* the messaging thread's CPU seconds when the job began */
extern double rs_dist_cpu0;

void rs_dist_sleep_s(double s);
uint64_t rs_dist_dbits(double v);
double rs_dist_bitsd(uint64_t u);
/* CPU seconds the calling thread has used (the messaging loop's cost: it must not spin) */
double rs_dist_thread_cpu_s(void);
/* Between probes of a messaging loop: after activity `nap` is reset to 0.1 ms; while nothing
 * comes it sleeps and doubles up to 2 ms, so a waiting rank costs no core. */
void rs_dist_idle_nap(double *nap, int active);
/* A small message (n uint64 values; v NULL: none), counted.  1 when MPI took it. */
int rs_dist_send_small(const uint64_t *v, int n, int to, int tag);
/* A message from rank 0, if one is there: 1 with its tag and (up to two) values, 0 if none,
 * -1 on an MPI error. */
int rs_dist_poll_rank0(int *tag, uint64_t v[2]);
/* The film to rank 0: the header h (H_ENC, H_NONFINITE and H_COMM_CPU are filled here), then
 * the sums and counts.  1 once rank 0 took it all. */
int rs_dist_send_film(const rs_film *f, uint64_t h[H_COUNT], double timeout_s);
/* Rank r's film data after its header h, into tmp (cleared first).  The bytes it came as into
 * *bytes.  1 when it all came. */
int rs_dist_recv_film(int r, const uint64_t *h, rs_film *tmp, double timeout_s,
                      uint64_t *bytes);
/* n values of `type` (elem bytes each) to rank `to` as `tag` messages of at most DIST_CHUNK
 * values; 1 when every piece went. */
int rs_dist_send_chunks(const void *data, size_t n, size_t elem, MPI_Datatype type, int to,
                        int tag, double timeout_s);
/* The other side: n values from rank `from` into data.  1 when every piece came. */
int rs_dist_recv_chunks(void *data, size_t n, size_t elem, MPI_Datatype type, int from, int tag,
                        double timeout_s);
/* Whether tag is one of a film's data messages (dropped when they come outside a film). */
int rs_dist_is_film_data(int tag);
/* Drops a data message (of a film given up on) that MPI_Iprobe found. */
void rs_dist_drop_data(const MPI_Status *ms);

/* ---- the render thread (dist_local.c) ------------------------------------------------------ */

#define QUEUE 2   /* passes a rank holds: one under way, one waiting */
#define DONE_MAX 64

typedef struct local {
    const rs_dist_job *job;
    int rank;
    pthread_t thread;
    int started;
    pthread_mutex_t mu;
    pthread_cond_t cv;
    uint32_t q_s0[QUEUE], q_n[QUEUE];
    int q_len;
    int busy;                        /* a pass is under way */
    uint32_t done_s0[DONE_MAX], done_n[DONE_MAX];
    int done_len;                    /* finished passes not yet reported */
    int stop, abort_, exited;
    rs_status error;                 /* a failed render: the thread exits */
    atomic_int cancel;               /* to the render under way */
    rs_film *scratch;
    rs_film *acc;                    /* the rank's finished passes (rank 0: the frame) */
    pthread_mutex_t *acc_mu;         /* rank 0: shared with the merging of received films */
    /* statistics (under mu) */
    uint32_t passes;
    uint64_t paths, rays_c, rays_s;
    uint32_t max_bounce;
    double busy_s;
    rs_render_stats sum;             /* stages, summed */
} local;

rs_status local_start(local *l, const rs_dist_job *job, int rank, rs_film *acc,
                      pthread_mutex_t *acc_mu);
void local_push(local *l, uint32_t s0, uint32_t n);
/* passes it holds (waiting or under way) */
int local_held(local *l);
/* abort_: drop what is queued and cancel the pass under way; else finish the queue, then exit */
void local_signal(local *l, int abort_);
int local_exited(local *l);
/* nothing waiting, under way or finished unreported */
int local_idle(local *l);
/* Takes the finished passes not yet reported into s0[]/n[] (at most DONE_MAX). */
int local_take_done(local *l, uint32_t *s0, uint32_t *n);
/* Waits for the thread to exit by itself (no signal). */
void local_wait(local *l);
/* Frees the scratch film and the lock (after the thread is gone). */
void local_free(local *l);
/* Aborts the thread, waits for it and frees it; nothing if it never started. */
void local_join(local *l);

/* ---- rank 0's passes (dist_passes.c) ------------------------------------------------------- */

enum { P_FREE, P_ASSIGNED, P_DONE, P_MERGED };

typedef struct passes {
    uint32_t n_passes, pass_spp, limit; /* passes at or above `limit` are not handed out */
    uint32_t *ps0, *pn; /* pass p: samples [ps0[p], ps0[p] + pn[p]), ps0 increasing */
    uint8_t *state;
    int *owner;         /* -1: never handed out */
    uint64_t todo_paths;
    uint32_t npix;
    uint32_t *reissued; /* counts passes handed out again */
} passes;

/* Samples per pass when the job leaves it to us (job->pass_spp 0). */
uint32_t passes_auto_spp(const rs_dist_job *job, uint32_t npix, int ranks);
/* The passes: each range of job->todo (whole samples) cut into pieces of t->pass_spp samples (state and owner
 * allocated, owners -1).  0 when out of memory. */
int passes_make(passes *t, const rs_dist_job *job);
void passes_free(passes *t);
/* the pass that starts at sample s0, or n_passes */
uint32_t passes_of(const passes *t, uint32_t s0);
/* the lowest free pass below the limit, or n_passes */
uint32_t passes_next_free(const passes *t);
uint32_t passes_count(const passes *t, int state, uint32_t below);
void passes_assign(passes *t, uint32_t p, int r);
/* Rank r's passes, under way or finished but not added, are free again (it died or failed). */
void passes_release(passes *t, int r);
/* paths of the passes done or merged */
uint64_t passes_paths_done(const passes *t);
/* The merged passes as path ranges (as job->plan.todo numbers them) into *out (emptied first; free
 * with rs_path_ranges_free), their samples of every pixel into *samples.  0 when out of
 * memory. */
int passes_merged_ranges(const passes *t, rs_path_ranges *out, uint32_t *samples);
/* Where the passes begun so far end (the last begun's end, in paths; 0: none begun): for the
 * time limit's rule, scheduler/plan.h rs_work_plan_time_cut. */
uint64_t passes_begun_end(const passes *t);
/* No pass that starts at or past path `end` is handed out.  1 when that lowered the limit. */
int passes_limit_to(passes *t, uint64_t end);

/* ---- the roles --------------------------------------------------------------------------- */

rs_status rs_dist_run_coordinator(rs_dist *d, const rs_dist_job *job, rs_film *film,
                                  rs_dist_result *res, double timeout_s);
rs_status rs_dist_run_worker(rs_dist *d, const rs_dist_job *job, rs_film *film,
                             double timeout_s);

#endif
