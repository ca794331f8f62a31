/* app/distributed.c — see distributed.h.  Built only with MPI (distributed_none.c otherwise).
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
 *                 BYE   lost                 the job is over (after your film): call
 *                                            MPI_Finalize unless a rank was lost (it would
 *                                            wait for the dead)
 * Messages between two ranks arrive in the order they were sent, so a worker's DONEs precede
 * its film. */
#include "app/distributed.h"

#include <errno.h>
#include <mpi.h>
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "core/alloc.h"
#include "core/clock.h"

/* which sanitizer this is built with (gcc's macros, clang's __has_feature) */
#if defined(__SANITIZE_ADDRESS__)
#  define RS_ASAN 1
#elif defined(__SANITIZE_THREAD__)
#  define RS_TSAN 1
#elif defined(__has_feature)
#  if __has_feature(address_sanitizer)
#    define RS_ASAN 1
#  elif __has_feature(thread_sanitizer)
#    define RS_TSAN 1
#  endif
#endif

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
    T_BYE
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
    H_COUNT
};

#define CHUNK (1u << 24) /* elements per data message (128 MB of int64) */

struct rs_dist {
    int rank, size;
    int any_dead;
    char (*desc)[RS_DIST_DESC]; /* rank 0: every rank's */
};

static void sleep_s(double s)
{
    struct timespec t;
    t.tv_sec = (time_t)s;
    t.tv_nsec = (long)((s - (double)t.tv_sec) * 1e9);
    while (nanosleep(&t, &t) != 0 && errno == EINTR) {
    }
}

static uint64_t dbits(double v)
{
    uint64_t u;
    memcpy(&u, &v, sizeof u);
    return u;
}

/* CPU seconds the calling thread has used (the messaging loop's cost: it must not spin) */
static double thread_cpu_s(void)
{
    struct timespec t;
    if (clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t) != 0)
        return 0.0;
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static double bitsd(uint64_t u)
{
    double v;
    memcpy(&v, &u, sizeof v);
    return v;
}

int rs_dist_built(void)
{
    return 1;
}

int rs_dist_launched(int *ranks, int *rank, int *local_ranks)
{
    static const char *const size_vars[] = {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE",
                                            "MPI_LOCALNRANKS", "SLURM_NTASKS"};
    const char *v = NULL, *r, *l;
    size_t i;
    for (i = 0; i < sizeof size_vars / sizeof size_vars[0] && !v; ++i)
        v = getenv(size_vars[i]);
    if (!v && !getenv("PMIX_RANK"))
        return 0;
    r = getenv("OMPI_COMM_WORLD_RANK");
    if (!r)
        r = getenv("PMI_RANK");
    if (!r)
        r = getenv("PMIX_RANK");
    l = getenv("OMPI_COMM_WORLD_LOCAL_SIZE");
    if (!l)
        l = getenv("MPI_LOCALNRANKS");
    *ranks = v ? atoi(v) : 1;
    *rank = r ? atoi(r) : 0;
    *local_ranks = l && atoi(l) > 0 ? atoi(l) : 1;
    return 1;
}

/* Under AddressSanitizer (RS_SANITIZE=address): Open MPI and the libraries below it keep some
 * memory to the end on purpose.  LeakSanitizer is told so by library.  For a leak to be traced
 * to one, their plug-ins stay loaded (below), and whoever runs the ranks under ASan sets
 * ASAN_OPTIONS=fast_unwind_on_malloc=0 (the libraries have no frame pointers; app_mpi_test and
 * mpi_bench do).  Nothing of raystream's own is suppressed. */
#ifdef RS_ASAN
const char *__lsan_default_suppressions(void);
const char *__lsan_default_suppressions(void)
{
    return "leak:libmpi.so\nleak:libopen-pal.so\nleak:libopen-rte.so\nleak:libpmix.so\n"
           "leak:libhwloc.so\nleak:libevent\nleak:mca_\n";
}
#endif

/* Under ThreadSanitizer (RS_SANITIZE=thread): Open MPI's own locks and threads (its TCP
 * transport takes two of its mutexes in both orders, its progress and PMIx threads share its
 * state) are not raystream's; reports inside them are suppressed, by library.  Our threads and
 * their locks (the render thread against the messaging loop) are checked in full. */
#ifdef RS_TSAN
const char *__tsan_default_suppressions(void);
const char *__tsan_default_suppressions(void)
{
    return "deadlock:libmpi.so\ndeadlock:libopen-pal.so\ndeadlock:libopen-rte.so\n"
           "deadlock:mca_\ndeadlock:libpmix.so\n"
           "race:libmpi.so\nrace:libopen-pal.so\nrace:libopen-rte.so\nrace:mca_\n"
           "race:libpmix.so\nrace:libevent\nrace:libhwloc.so\n"
           "thread:libopen-pal.so\nthread:libpmix.so\nthread:libevent\n";
}
#endif

rs_status rs_dist_init(int *argc, char ***argv, rs_dist **out)
{
    int provided = 0;
    rs_dist *d;
    *out = NULL;
#ifdef RS_ASAN
    setenv("OMPI_MCA_mca_base_component_disable_dlclose", "1", 0);
    setenv("PMIX_MCA_mca_base_component_disable_dlclose", "1", 0);
#endif
    if (MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS)
        return rs_error_set(RS_ERR_IO, "MPI_Init failed");
    if (provided < MPI_THREAD_FUNNELED)
        return rs_error_set(RS_ERR_IO, "this MPI offers no threads beside MPI's (level %d)",
                            provided);
    MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
    d = (rs_dist *)rs_calloc(1, sizeof *d);
    if (!d)
        return rs_error_set(RS_ERR_NOMEM, "out of memory");
    MPI_Comm_rank(MPI_COMM_WORLD, &d->rank);
    MPI_Comm_size(MPI_COMM_WORLD, &d->size);
    *out = d;
    return RS_OK;
}

int rs_dist_rank(const rs_dist *d)
{
    return d->rank;
}

int rs_dist_size(const rs_dist *d)
{
    return d->size;
}

int rs_dist_agree(rs_dist *d, int code, int *who, const char *desc)
{
    int mine[2], worst[2];
    char buf[RS_DIST_DESC];
    mine[0] = code;
    mine[1] = -d->rank; /* MAXLOC-like: the highest code, then the lowest rank */
    /* two reductions keep it to standard types: the worst code, then the lowest rank with it */
    MPI_Allreduce(&mine[0], &worst[0], 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    mine[1] = code == worst[0] ? d->rank : d->size;
    MPI_Allreduce(&mine[1], &worst[1], 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    *who = worst[1];
    memset(buf, 0, sizeof buf);
    snprintf(buf, sizeof buf, "%s", desc ? desc : "");
    if (d->rank == 0 && !d->desc)
        d->desc = rs_calloc((size_t)d->size, sizeof *d->desc);
    MPI_Gather(buf, RS_DIST_DESC, MPI_CHAR, d->desc ? (void *)d->desc : NULL, RS_DIST_DESC,
               MPI_CHAR, 0, MPI_COMM_WORLD);
    return worst[0];
}

void rs_dist_finish(rs_dist *d)
{
    if (!d)
        return;
    if (!d->any_dead)
        MPI_Finalize();
    rs_free(d->desc);
    rs_free(d);
}

rs_status rs_dist_fault_parse(const char *spec, rs_dist_fault *f)
{
    const char *p = spec;
    memset(f, 0, sizeof *f);
    f->slow_rank = f->die_rank = -1;
    if (!spec || !*spec)
        return RS_OK;
    while (*p) {
        int rank, n = 0;
        double x;
        if (sscanf(p, "slow:%d:%lf%n", &rank, &x, &n) == 2 && n > 0 && rank >= 0 && x >= 1) {
            f->slow_rank = rank;
            f->slow_factor = x;
        } else if (sscanf(p, "die:%d:%lf%n", &rank, &x, &n) == 2 && n > 0 && rank > 0 &&
                   x >= 0 && x < 1e9 && x == (uint32_t)x) {
            f->die_rank = rank;
            f->die_after = (uint32_t)x;
        } else {
            return rs_error_set(RS_ERR_ARG,
                                "RS_MPI_FAULT: cannot read '%s' (slow:RANK:FACTOR or "
                                "die:RANK:PASSES, comma-separated)",
                                p);
        }
        p += n;
        if (*p == ',')
            ++p;
        else if (*p)
            return rs_error_set(RS_ERR_ARG, "RS_MPI_FAULT: junk after '%.*s'", (int)(p - spec),
                                spec);
    }
    return RS_OK;
}

/* ---- the render thread of every rank ----------------------------------------------------- */

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


static void *local_main(void *arg)
{
    local *l = (local *)arg;
    const rs_dist_job *job = l->job;
    for (;;) {
        uint32_t s0, n;
        rs_render_stats rs;
        rs_status st;
        double t0, t1;
        pthread_mutex_lock(&l->mu);
        while (!l->q_len && !l->stop && !l->abort_)
            pthread_cond_wait(&l->cv, &l->mu);
        if (l->abort_ || (l->stop && !l->q_len)) {
            l->exited = 1;
            pthread_cond_broadcast(&l->cv);
            pthread_mutex_unlock(&l->mu);
            return NULL;
        }
        s0 = l->q_s0[0];
        n = l->q_n[0];
        memmove(l->q_s0, l->q_s0 + 1, (QUEUE - 1) * sizeof *l->q_s0);
        memmove(l->q_n, l->q_n + 1, (QUEUE - 1) * sizeof *l->q_n);
        l->q_len--;
        l->busy = 1;
        pthread_mutex_unlock(&l->mu);

        rs_film_clear(l->scratch);
        memset(&rs, 0, sizeof rs);
        t0 = rs_now_s();
        st = job->render(job->user, s0, n, l->scratch, &l->cancel, &rs);
        t1 = rs_now_s();
        if (st == RS_OK && job->fault.slow_factor > 1 && job->fault.slow_rank == l->rank)
            sleep_s((job->fault.slow_factor - 1) * (t1 - t0));
        /* the merge and its report under one lock: a flush sees a film and the list of the
         * passes in it that agree */
        pthread_mutex_lock(&l->mu);
        if (st == RS_OK) {
            if (l->acc_mu)
                pthread_mutex_lock(l->acc_mu);
            st = rs_film_merge(l->acc, l->scratch);
            if (l->acc_mu)
                pthread_mutex_unlock(l->acc_mu);
        }
        l->busy = 0;
        l->busy_s += rs_now_s() - t0;
        if (st == RS_OK) {
            l->passes++;
            l->paths += rs.paths_done;
            rs_render_stats_add(&l->sum, &rs);
            if (l->done_len < DONE_MAX) {
                l->done_s0[l->done_len] = s0;
                l->done_n[l->done_len++] = n;
            }
        } else if (st != RS_ERR_CANCELLED) {
            l->error = st;
            l->exited = 1;
            pthread_cond_broadcast(&l->cv);
            pthread_mutex_unlock(&l->mu);
            return NULL;
        } else {
            rs_error_clear();
        }
        pthread_cond_broadcast(&l->cv);
        pthread_mutex_unlock(&l->mu);
        if (st == RS_OK && job->fault.die_rank == l->rank && l->passes >= job->fault.die_after)
            raise(SIGKILL); /* a test of a rank lost with finished passes it never sent */
    }
}

static rs_status local_start(local *l, const rs_dist_job *job, int rank, rs_film *acc,
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
    if (pthread_create(&l->thread, NULL, local_main, l) != 0) {
        rs_film_destroy(l->scratch);
        return rs_error_set(RS_ERR_NOMEM, "cannot start the render thread");
    }
    l->started = 1;
    return RS_OK;
}

static void local_push(local *l, uint32_t s0, uint32_t n)
{
    pthread_mutex_lock(&l->mu);
    if (l->q_len < QUEUE) {
        l->q_s0[l->q_len] = s0;
        l->q_n[l->q_len++] = n;
    }
    pthread_cond_broadcast(&l->cv);
    pthread_mutex_unlock(&l->mu);
}

/* passes it holds (waiting or under way) */
static int local_held(local *l)
{
    int n;
    pthread_mutex_lock(&l->mu);
    n = l->q_len + l->busy;
    pthread_mutex_unlock(&l->mu);
    return n;
}

static void local_signal(local *l, int abort_)
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

static int local_exited(local *l)
{
    int e;
    pthread_mutex_lock(&l->mu);
    e = l->exited;
    pthread_mutex_unlock(&l->mu);
    return e;
}

/* nothing waiting, under way or finished unreported */
static int local_idle(local *l)
{
    int idle;
    pthread_mutex_lock(&l->mu);
    idle = l->q_len == 0 && !l->busy && l->done_len == 0;
    pthread_mutex_unlock(&l->mu);
    return idle;
}

/* Takes the finished passes not yet reported into s0[]/n[] (at most DONE_MAX). */
static int local_take_done(local *l, uint32_t *s0, uint32_t *n)
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

static void local_join(local *l)
{
    if (!l->started)
        return;
    local_signal(l, 1);
    pthread_join(l->thread, NULL);
    l->started = 0;
    rs_film_destroy(l->scratch);
    pthread_mutex_destroy(&l->mu);
    pthread_cond_destroy(&l->cv);
}

/* ---- messaging helpers -------------------------------------------------------------------- */

/* Between probes of a messaging loop: after activity `nap` is reset to 0.1 ms; while nothing
 * comes it sleeps and doubles up to 2 ms, so a waiting rank costs no core. */
static void idle_nap(double *nap, int active)
{
    if (active) {
        *nap = 1e-4;
        return;
    }
    sleep_s(*nap);
    if (*nap < 2e-3)
        *nap *= 2;
}

/* Waits for `req` without spinning a core; gives up (cancelling it) after timeout_s. */
static int wait_req(MPI_Request *req, double timeout_s)
{
    double t0 = rs_now_s(), nap = 1e-4;
    for (;;) {
        int flag = 0;
        if (MPI_Test(req, &flag, MPI_STATUS_IGNORE) != MPI_SUCCESS)
            return 0;
        if (flag)
            return 1;
        if (rs_now_s() - t0 > timeout_s) {
            MPI_Cancel(req);
            MPI_Request_free(req);
            return 0;
        }
        idle_nap(&nap, 0);
    }
}

static uint64_t g_msgs, g_msg_bytes; /* this rank's small messages, sent and received */
static double g_cpu0;                 /* the messaging thread's CPU seconds when the job began */

static int send_small(const uint64_t *v, int n, int to, int tag)
{
    uint64_t none = 0;
    g_msgs++;
    g_msg_bytes += 8u * (uint64_t)n;
    return MPI_Send(v ? (void *)v : (void *)&none, n, MPI_UINT64_T, to, tag, MPI_COMM_WORLD) ==
           MPI_SUCCESS;
}

/* ---- a worker (rank > 0) ----------------------------------------------------------------- */

/* A message from rank 0, if one is there: 1 with its tag and (up to two) values, 0 if none,
 * -1 on an MPI error. */
static int poll_rank0(int *tag, uint64_t v[2])
{
    int flag = 0, cnt = 0;
    MPI_Status ms;
    if (MPI_Iprobe(0, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &ms) != MPI_SUCCESS)
        return -1;
    if (!flag)
        return 0;
    v[0] = v[1] = 0;
    MPI_Get_count(&ms, MPI_UINT64_T, &cnt);
    MPI_Recv(v, cnt > 2 ? 2 : cnt, MPI_UINT64_T, 0, ms.MPI_TAG, MPI_COMM_WORLD,
             MPI_STATUS_IGNORE);
    *tag = ms.MPI_TAG;
    return 1;
}

static int sums_fit_int64(const rs_film *f)
{
    size_t i, n = (size_t)f->width * f->height * 3;
    for (i = 0; i < n; ++i)
        if (f->sum[i] != (rs_film_sum)(int64_t)f->sum[i])
            return 0;
    return 1;
}

/* The film to rank 0: header, sums, counts.  Returns 1 once rank 0 took it all. */
static int send_film(local *l, const rs_film *f, int failed, int flush, double timeout_s)
{
    size_t npix = (size_t)f->width * f->height, n_sum, i, off;
    uint64_t h[H_COUNT];
    int enc = sums_fit_int64(f) ? 0 : 1;
    int64_t *wide = NULL;
    const void *sums;
    int ok = 1;
    memset(h, 0, sizeof h);
    pthread_mutex_lock(&l->mu);
    h[H_ENC] = (uint64_t)enc;
    h[H_PASSES] = l->passes;
    h[H_PATHS] = l->paths;
    h[H_RAYS_C] = l->sum.rays_closest;
    h[H_RAYS_S] = l->sum.rays_shadow;
    h[H_MAX_BOUNCE] = l->sum.max_bounce;
    h[H_BUSY] = dbits(l->busy_s);
    pthread_mutex_unlock(&l->mu);
    h[H_NONFINITE] = f->nonfinite;
    h[H_FAILED] = (uint64_t)failed;
    h[H_FLUSH] = (uint64_t)flush;
    h[H_COMM_CPU] = dbits(thread_cpu_s() - g_cpu0); /* send_film runs on the messaging thread */
    if (!send_small(h, H_COUNT, 0, T_FILM))
        return 0;
    n_sum = npix * 3 * (enc ? 2 : 1);
    if (enc) {
        sums = f->sum; /* two little-endian words each, low first */
    } else {
        wide = (int64_t *)rs_alloc(npix * 3, sizeof *wide);
        if (!wide)
            return 0;
        for (i = 0; i < npix * 3; ++i)
            wide[i] = (int64_t)f->sum[i];
        sums = wide;
    }
    for (off = 0; ok && off < n_sum; off += CHUNK) {
        MPI_Request rq;
        int k = (int)(n_sum - off < CHUNK ? n_sum - off : CHUNK);
        ok = MPI_Isend((const int64_t *)sums + off, k, MPI_INT64_T, 0, T_FILM_SUMS,
                       MPI_COMM_WORLD, &rq) == MPI_SUCCESS &&
             wait_req(&rq, timeout_s);
    }
    for (off = 0; ok && off < npix; off += CHUNK) {
        MPI_Request rq;
        int k = (int)(npix - off < CHUNK ? npix - off : CHUNK);
        ok = MPI_Isend(f->count + off, k, MPI_UINT32_T, 0, T_FILM_COUNTS, MPI_COMM_WORLD, &rq) ==
                 MPI_SUCCESS &&
             wait_req(&rq, timeout_s);
    }
    rs_free(wide);
    return ok;
}

/* A flush: the film so far and its passes to rank 0; the render thread goes on into `spare`
 * (cleared), which becomes the rank's film. */
static int worker_flush(local *l, rs_film **spare, double timeout_s)
{
    uint32_t s0[DONE_MAX], n[DONE_MAX];
    rs_film *sent;
    int k, i, ok;
    rs_film_clear(*spare);
    pthread_mutex_lock(&l->mu);
    sent = l->acc;
    l->acc = *spare;
    k = l->done_len;
    memcpy(s0, l->done_s0, (size_t)k * sizeof *s0);
    memcpy(n, l->done_n, (size_t)k * sizeof *n);
    l->done_len = 0;
    pthread_mutex_unlock(&l->mu);
    for (i = 0; i < k; ++i) {
        uint64_t v[2] = {s0[i], n[i]};
        send_small(v, 2, 0, T_DONE);
    }
    ok = send_film(l, sent, 0, 1, timeout_s);
    *spare = sent;
    return ok;
}

static rs_status run_worker(rs_dist *d, const rs_dist_job *job, rs_film *film, double timeout_s)
{
    local l;
    rs_film *spare = NULL, *acc;
    double last_sent = rs_now_s(), last_heard = rs_now_s(), nap = 1e-4;
    int asked = 0, stopping = 0, aborting = 0, failed = 0;
    rs_status st;
    rs_film_clear(film);
    if (rs_film_create(film->width, film->height, &spare) != RS_OK)
        return RS_ERR_NOMEM;
    if ((st = local_start(&l, job, d->rank, film, NULL)) != RS_OK) {
        rs_film_destroy(spare);
        return st;
    }
    for (;;) {
        int flag = 0, active = 0, tag = 0;
        uint64_t v[2];
        uint32_t s0[DONE_MAX], n[DONE_MAX];
        int k, i;
        /* what the render thread finished */
        k = local_take_done(&l, s0, n);
        for (i = 0; i < k; ++i) {
            uint64_t v[2] = {s0[i], n[i]};
            send_small(v, 2, 0, T_DONE);
            last_sent = rs_now_s();
            active = 1;
        }
        if (local_exited(&l)) {
            failed = l.error != RS_OK;
            break;
        }
        if (job->cancel && atomic_load(job->cancel) && !aborting) {
            local_signal(&l, 1); /* our own stop signal: send what is finished, now */
            aborting = 1;
        }
        /* ask for a pass while the queue has room */
        if (!stopping && !aborting && !asked && local_held(&l) < QUEUE) {
            send_small(NULL, 0, 0, T_REQ);
            asked = 1;
            last_sent = rs_now_s();
            active = 1;
        }
        if ((flag = poll_rank0(&tag, v)) < 0)
            break;
        if (flag) {
            last_heard = rs_now_s();
            if (tag == T_PASS) {
                local_push(&l, (uint32_t)v[0], (uint32_t)v[1]);
                asked = 0;
            } else if (tag == T_STOP) {
                stopping = 1;
                asked = 0;
                local_signal(&l, 0);
            } else if (tag == T_ABORT) {
                aborting = 1;
                local_signal(&l, 1);
            } else if (tag == T_FLUSH && !worker_flush(&l, &spare, timeout_s)) {
                fprintf(stderr, "raystream: rank %d: could not send its film to rank 0\n",
                        d->rank);
            }
            last_sent = rs_now_s();
            active = 1;
        }
        if (rs_now_s() - last_sent > 1.0) {
            send_small(NULL, 0, 0, T_HB);
            last_sent = rs_now_s();
        }
        if (rs_now_s() - last_heard > timeout_s) {
            fprintf(stderr, "raystream: rank %d: rank 0 has been silent for %.0f s; stopping\n",
                    d->rank, timeout_s);
            d->any_dead = 1;
            local_join(&l);
            rs_film_destroy(spare);
            return rs_error_set(RS_ERR_IO, "rank 0 is gone");
        }
        idle_nap(&nap, active);
    }
    pthread_join(l.thread, NULL);
    l.started = 0;
    /* the DONEs of the last passes, then the film */
    {
        uint32_t s0[DONE_MAX], n[DONE_MAX];
        int k = local_take_done(&l, s0, n), i;
        for (i = 0; i < k; ++i) {
            uint64_t v[2] = {s0[i], n[i]};
            send_small(v, 2, 0, T_DONE);
        }
    }
    if (failed)
        fprintf(stderr, "raystream: rank %d: %s; its passes go to the other ranks\n", d->rank,
                rs_error_message());
    pthread_mutex_lock(&l.mu);
    acc = l.acc;
    pthread_mutex_unlock(&l.mu);
    if (!send_film(&l, acc, failed, 0, timeout_s)) {
        d->any_dead = 1;
        fprintf(stderr, "raystream: rank %d: could not send its film to rank 0\n", d->rank);
    } else {
        /* rank 0's word on how to end: MPI_Finalize waits for every rank, the dead too */
        double t_bye = rs_now_s(), nap = 1e-4;
        int got = 0;
        while (!got && rs_now_s() - t_bye < timeout_s) {
            uint64_t v[2];
            int tag = 0, flag = poll_rank0(&tag, v);
            if (flag < 0)
                break;
            if (flag) {
                if (tag == T_BYE) {
                    got = 1;
                    if (v[0])
                        d->any_dead = 1;
                }
                continue;
            }
            idle_nap(&nap, 0);
        }
        if (!got)
            d->any_dead = 1; /* rank 0 is gone: do not wait for it */
    }
    rs_film_destroy(spare == film ? acc : spare); /* the one of the two that is not `film` */
    rs_film_destroy(l.scratch);
    pthread_mutex_destroy(&l.mu);
    pthread_cond_destroy(&l.cv);
    return RS_OK;
}

/* ---- rank 0 ------------------------------------------------------------------------------ */

enum { P_FREE, P_ASSIGNED, P_DONE, P_MERGED };

typedef struct coord {
    rs_dist *d;
    const rs_dist_job *job;
    uint32_t n_passes, pass_spp, limit;
    uint32_t *ps0, *pn; /* pass p: samples [ps0[p], ps0[p] + pn[p]), ps0 increasing */
    uint8_t *state;
    int *owner;
    uint64_t todo_paths;
    int *flushing; /* a flush asked of it is not in yet */
    uint32_t npix;
    /* per rank */
    double *last_seen;
    int *asked;    /* a request is waiting (no pass was free) */
    int *finished; /* its film arrived, or it is dead */
    int *stopped;  /* it was sent STOP or ABORT */
    rs_dist_result *res;
} coord;

static uint32_t pass_s0(const coord *c, uint32_t p)
{
    return c->ps0[p];
}

static uint32_t pass_n(const coord *c, uint32_t p)
{
    return c->pn[p];
}

/* the pass that starts at sample s0, or n_passes */
static uint32_t pass_of(const coord *c, uint32_t s0)
{
    uint32_t lo = 0, hi = c->n_passes;
    while (lo < hi) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (c->ps0[mid] < s0)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo < c->n_passes && c->ps0[lo] == s0 ? lo : c->n_passes;
}

/* The passes: each range of job->todo cut into pieces of pass_spp samples. */
static int make_passes(coord *c)
{
    const rs_dist_job *job = c->job;
    uint32_t i, n = 0, total = 0;
    for (i = 0; i < job->n_todo; ++i) {
        n += (job->todo[i][1] + c->pass_spp - 1) / c->pass_spp;
        total += job->todo[i][1];
    }
    c->n_passes = n;
    c->todo_paths = (uint64_t)total * c->npix;
    c->ps0 = (uint32_t *)rs_calloc(n ? n : 1, sizeof *c->ps0);
    c->pn = (uint32_t *)rs_calloc(n ? n : 1, sizeof *c->pn);
    if (!c->ps0 || !c->pn)
        return 0;
    for (i = 0, n = 0; i < job->n_todo; ++i) {
        uint32_t s0 = job->todo[i][0], end = s0 + job->todo[i][1];
        for (; s0 < end; s0 += c->pass_spp, ++n) {
            c->ps0[n] = s0;
            c->pn[n] = end - s0 < c->pass_spp ? end - s0 : c->pass_spp;
        }
    }
    return 1;
}

/* the lowest free pass below the limit, or n_passes */
static uint32_t next_free(const coord *c)
{
    uint32_t p;
    for (p = 0; p < c->limit; ++p)
        if (c->state[p] == P_FREE)
            return p;
    return c->n_passes;
}

static uint32_t count_state(const coord *c, int state, uint32_t below)
{
    uint32_t p, k = 0;
    for (p = 0; p < below; ++p)
        k += c->state[p] == state;
    return k;
}

static void assign(coord *c, uint32_t p, int r)
{
    if (c->state[p] == P_FREE && c->owner[p] != -1)
        c->res->reissued++;
    c->state[p] = P_ASSIGNED;
    c->owner[p] = r;
}

/* Rank r's passes, under way or finished but not added, are free again (it died or failed). */
static void release(coord *c, int r)
{
    uint32_t p;
    for (p = 0; p < c->n_passes; ++p)
        if (c->owner[p] == r && (c->state[p] == P_ASSIGNED || c->state[p] == P_DONE)) {
            c->state[p] = P_FREE; /* owner kept: assign() counts it as reissued */
        }
}

static void progress(coord *c)
{
    uint64_t done = 0;
    uint32_t p;
    if (!c->job->progress)
        return;
    for (p = 0; p < c->n_passes; ++p)
        if (c->state[p] == P_DONE || c->state[p] == P_MERGED)
            done += (uint64_t)pass_n(c, p) * c->npix;
    c->job->progress(c->job->user, done, c->todo_paths);
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
    c->res->dead++;
    fprintf(stderr, "\nraystream: rank %d (%s) %s; its passes go to the other ranks\n", r,
            c->d->desc ? c->d->desc[r] : "?", why);
    release(c, r);
}

/* Receives rank r's film (its header h already read) into tmp, then adds it to the frame. */
static int recv_film(coord *c, int r, const uint64_t *h, rs_film *tmp, rs_film *film,
                     pthread_mutex_t *film_mu, double timeout_s)
{
    size_t npix = c->npix, n_sum = npix * 3 * (h[H_ENC] ? 2 : 1), off;
    int64_t *buf = NULL;
    int ok = 1;
    rs_film_clear(tmp);
    if (!h[H_ENC]) {
        buf = (int64_t *)rs_alloc(n_sum < CHUNK ? n_sum : CHUNK, sizeof *buf);
        if (!buf)
            return 0;
    }
    for (off = 0; ok && off < n_sum; off += CHUNK) {
        MPI_Request rq;
        int k = (int)(n_sum - off < CHUNK ? n_sum - off : CHUNK), i;
        void *dst = h[H_ENC] ? (void *)((int64_t *)tmp->sum + off) : (void *)buf;
        ok = MPI_Irecv(dst, k, MPI_INT64_T, r, T_FILM_SUMS, MPI_COMM_WORLD, &rq) ==
                 MPI_SUCCESS &&
             wait_req(&rq, timeout_s);
        if (ok && !h[H_ENC])
            for (i = 0; i < k; ++i)
                tmp->sum[off + (size_t)i] = buf[i];
    }
    for (off = 0; ok && off < npix; off += CHUNK) {
        MPI_Request rq;
        int k = (int)(npix - off < CHUNK ? npix - off : CHUNK);
        ok = MPI_Irecv(tmp->count + off, k, MPI_UINT32_T, r, T_FILM_COUNTS, MPI_COMM_WORLD,
                       &rq) == MPI_SUCCESS &&
             wait_req(&rq, timeout_s);
    }
    rs_free(buf);
    if (!ok)
        return 0;
    tmp->nonfinite = h[H_NONFINITE];
    pthread_mutex_lock(film_mu);
    rs_film_merge(film, tmp);
    pthread_mutex_unlock(film_mu);
    c->res->bytes_received += H_COUNT * 8 + n_sum * 8 + npix * 4;
    c->res->rank[r].film_bytes += H_COUNT * 8 + n_sum * 8 + npix * 4;
    return 1;
}

/* The merged passes as sorted ranges of samples, into *out (rs_alloc'd); their count. */
static uint32_t merged_ranges(const coord *c, uint32_t (**out)[2], uint32_t *samples)
{
    uint32_t p, k = 0;
    uint32_t(*r)[2] = (uint32_t(*)[2])rs_calloc(c->n_passes ? c->n_passes : 1, sizeof *r);
    *samples = 0;
    *out = r;
    if (!r)
        return 0;
    for (p = 0; p < c->n_passes; ++p) {
        if (c->state[p] != P_MERGED)
            continue;
        *samples += c->pn[p];
        if (k && r[k - 1][0] + r[k - 1][1] == c->ps0[p])
            r[k - 1][1] += c->pn[p];
        else {
            r[k][0] = c->ps0[p];
            r[k++][1] = c->pn[p];
        }
    }
    return k;
}

/* Every rank's finished passes are on the frame: job->saved, while rank 0's render thread
 * cannot add to it (its lock, then the frame's). */
static void call_saved(coord *c, local *l, rs_film *film, pthread_mutex_t *film_mu)
{
    uint32_t(*done)[2] = NULL, n_done, samples, i;
    pthread_mutex_lock(&l->mu);
    for (i = 0; i < (uint32_t)l->done_len; ++i) {
        uint32_t q = pass_of(c, l->done_s0[i]);
        if (q < c->n_passes)
            c->state[q] = P_MERGED;
    }
    l->done_len = 0;
    n_done = merged_ranges(c, &done, &samples);
    pthread_mutex_lock(film_mu);
    if (done)
        c->job->saved(c->job->user, film, (const uint32_t(*)[2])done, n_done);
    pthread_mutex_unlock(film_mu);
    pthread_mutex_unlock(&l->mu);
    rs_free(done);
}

static rs_status run_coordinator(rs_dist *d, const rs_dist_job *job, rs_film *film,
                                 rs_dist_result *res, double timeout_s)
{
    coord c;
    local l;
    pthread_mutex_t film_mu = PTHREAD_MUTEX_INITIALIZER;
    rs_film *tmp = NULL;
    double t0 = rs_now_s(), nap = 1e-4, t_signal = 0, last_hb = t0, grace_s, next_flush;
    int r, n = d->size, signalled = 0, flush_round = 0;
    const char *kill_after = getenv("OMPI_MCA_odls_base_sigkill_timeout");
    uint32_t p;
    rs_status st = RS_OK;

    memset(&c, 0, sizeof c);
    c.d = d;
    c.job = job;
    c.res = res;
    c.npix = job->width * job->height;
    c.pass_spp = job->pass_spp;
    if (!c.pass_spp) {
        /* about 8 passes a rank, so that a slow one costs little at the end, and at most about
         * 2^21 paths (1-2 s on one core), so that a stop, which drops the passes under way,
         * loses little */
        uint32_t left = 0, i, most = (1u << 21) / c.npix;
        for (i = 0; i < job->n_todo; ++i)
            left += job->todo[i][1];
        c.pass_spp = left / (8u * (uint32_t)n);
        if (c.pass_spp > most)
            c.pass_spp = most;
        if (c.pass_spp < 1)
            c.pass_spp = 1;
    }
    if (!make_passes(&c)) {
        st = rs_error_set(RS_ERR_NOMEM, "out of memory for the MPI coordinator");
        goto out;
    }
    c.limit = c.n_passes;
    next_flush = job->flush_every_s > 0 ? t0 + job->flush_every_s : 0;
    res->ranks = n;
    res->pass_spp = c.pass_spp;
    res->passes_total = c.n_passes;
    c.state = (uint8_t *)rs_calloc(c.n_passes ? c.n_passes : 1, 1);
    c.owner = (int *)rs_calloc(c.n_passes ? c.n_passes : 1, sizeof *c.owner);
    c.last_seen = (double *)rs_calloc((size_t)n, sizeof *c.last_seen);
    c.asked = (int *)rs_calloc((size_t)n, sizeof *c.asked);
    c.finished = (int *)rs_calloc((size_t)n, sizeof *c.finished);
    c.stopped = (int *)rs_calloc((size_t)n, sizeof *c.stopped);
    c.flushing = (int *)rs_calloc((size_t)n, sizeof *c.flushing);
    res->rank = (rs_dist_rank_stats *)rs_calloc((size_t)n, sizeof *res->rank);
    if (!c.state || !c.owner || !c.last_seen || !c.asked || !c.finished ||
        !c.stopped || !c.flushing || !res->rank || rs_film_create(job->width, job->height, &tmp) != RS_OK) {
        st = rs_error_set(RS_ERR_NOMEM, "out of memory for the MPI coordinator");
        goto out;
    }
    for (p = 0; p < c.n_passes; ++p)
        c.owner[p] = -1;
    for (r = 0; r < n; ++r) {
        res->rank[r].alive = 1;
        c.last_seen[r] = t0;
        if (d->desc)
            snprintf(res->rank[r].desc, RS_DIST_DESC, "%s", d->desc[r]);
    }
    c.finished[0] = 1; /* rank 0's own thread is tracked apart */
    /* after a stop signal, mpirun kills every rank odls_base_sigkill_timeout (1 s) later */
    grace_s = (kill_after && atof(kill_after) > 0 ? atof(kill_after) : 1.0) - 0.3;
    if (grace_s < 0.2)
        grace_s = 0.2;
    if (grace_s > timeout_s)
        grace_s = timeout_s;
    if ((st = local_start(&l, job, 0, film, &film_mu)) != RS_OK)
        goto out;

    for (;;) {
        int flag = 0, active = 0, k, i, all_finished;
        uint32_t s0[DONE_MAX], nn[DONE_MAX];
        MPI_Status ms;
        double now = rs_now_s();

        /* stop conditions */
        if (!signalled && job->cancel && atomic_load(job->cancel)) {
            signalled = 1;
            res->stopped = 1;
            c.limit = 0;
            for (r = 1; r < n; ++r)
                if (!c.finished[r]) {
                    send_small(NULL, 0, r, T_ABORT);
                    c.stopped[r] = 1;
                }
            local_signal(&l, 1);
            /* what is under way is dropped (a worker's film says which it finished) and
             * nothing is handed out again; the films must come before mpirun's SIGKILL */
            t_signal = now;
        }
        if (signalled && now - t_signal > grace_s)
            for (r = 1; r < n; ++r)
                if (!c.finished[r]) {
                    c.finished[r] = 1;
                    res->rank[r].alive = 0;
                    d->any_dead = 1;
                    fprintf(stderr, "\nraystream: rank %d (%s) sent no film within %.1f s of "
                                    "the stop (it may be dead); its passes are left out\n",
                            r, res->rank[r].desc, grace_s);
                }
        if (!signalled && !res->time_limited && job->time_limit_s > 0 &&
            now - t0 >= job->time_limit_s) {
            /* no new pass: those begun (or handed out again later) still finish */
            uint32_t lim = 0;
            for (p = 0; p < c.n_passes; ++p)
                if (c.state[p] != P_FREE || c.owner[p] != -1)
                    lim = p + 1;
            if (lim == 0)
                lim = 1;
            if (lim < c.limit) {
                c.limit = lim;
                res->time_limited = 1;
            }
        }

        /* rank 0's own passes */
        k = local_take_done(&l, s0, nn);
        for (i = 0; i < k; ++i)
            c.state[pass_of(&c, s0[i])] = P_MERGED;
        if (k) {
            progress(&c);
            active = 1;
        }
        if (local_exited(&l) && l.error != RS_OK) {
            st = l.error;
            goto stop_all;
        }
        if (!signalled && local_held(&l) < QUEUE && (p = next_free(&c)) < c.n_passes) {
            assign(&c, p, 0);
            local_push(&l, pass_s0(&c, p), pass_n(&c, p));
            active = 1;
        }

        /* messages */
        if (MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &ms) != MPI_SUCCESS)
            flag = 0;
        if (flag) {
            uint64_t v[H_COUNT];
            int cnt = 0;
            r = ms.MPI_SOURCE;
            MPI_Get_count(&ms, MPI_UINT64_T, &cnt);
            if (ms.MPI_TAG != T_FILM_SUMS && ms.MPI_TAG != T_FILM_COUNTS) {
                g_msgs++;
                g_msg_bytes += 8u * (uint64_t)cnt;
            }
            memset(v, 0, sizeof v);
            if (ms.MPI_TAG == T_FILM_SUMS || ms.MPI_TAG == T_FILM_COUNTS) {
                /* data of a film given up on: drop it */
                int bytes = 0;
                void *junk;
                MPI_Get_count(&ms, MPI_BYTE, &bytes);
                junk = rs_alloc((size_t)bytes + 1, 1);
                MPI_Recv(junk, bytes, MPI_BYTE, r, ms.MPI_TAG, MPI_COMM_WORLD,
                         MPI_STATUS_IGNORE);
                rs_free(junk);
            } else {
                MPI_Recv(v, cnt > H_COUNT ? H_COUNT : cnt, MPI_UINT64_T, r, ms.MPI_TAG,
                         MPI_COMM_WORLD, MPI_STATUS_IGNORE);
            }
            c.last_seen[r] = rs_now_s();
            active = 1;
            if (!res->rank[r].alive) {
                /* a rank given up on, heard from again: its passes are out already */
            } else if (ms.MPI_TAG == T_REQ) {
                c.asked[r] = 1;
            } else if (ms.MPI_TAG == T_DONE) {
                uint32_t q = pass_of(&c, (uint32_t)v[0]);
                if (q < c.n_passes && c.owner[q] == r && c.state[q] == P_ASSIGNED) {
                    c.state[q] = P_DONE;
                    progress(&c);
                }
            } else if (ms.MPI_TAG == T_FILM) {
                double t_recv = rs_now_s();
                int got = recv_film(&c, r, v, tmp, film, &film_mu, timeout_s);
                int q;
                /* the others' silence while this film came does not count */
                for (q = 1; q < n; ++q)
                    if (q != r)
                        c.last_seen[q] += rs_now_s() - t_recv;
                if (got) {
                    rs_dist_rank_stats *rk = &res->rank[r];
                    for (p = 0; p < c.n_passes; ++p)
                        if (c.owner[p] == r && c.state[p] == P_DONE) {
                            c.state[p] = P_MERGED;
                            rk->passes++;
                            rk->paths += (uint64_t)pass_n(&c, p) * c.npix;
                        }
                    /* the worker's totals so far (a flush sends them too) */
                    rk->busy_s = bitsd(v[H_BUSY]);
                    rk->wall_s = c.last_seen[r] - t0;
                    rk->comm_cpu_s = bitsd(v[H_COMM_CPU]);
                    rk->rays_closest = v[H_RAYS_C];
                    rk->rays_shadow = v[H_RAYS_S];
                    if (v[H_MAX_BOUNCE] > res->max_bounce)
                        res->max_bounce = (uint32_t)v[H_MAX_BOUNCE];
                    c.flushing[r] = 0;
                    if (!v[H_FLUSH]) { /* its last: after a flush it goes on */
                        c.finished[r] = 1;
                        if (v[H_FAILED]) {
                            rk->failed = 1;
                            fprintf(stderr, "\nraystream: rank %d (%s) failed; its passes go "
                                            "to the other ranks\n",
                                    r, rk->desc);
                        }
                        release(&c, r); /* what it held but did not finish */
                    }
                } else {
                    mark_dead(&c, r, "sent a broken film");
                }
            }
        }

        /* answer the requests */
        for (r = 1; r < n; ++r) {
            if (!c.asked[r] || c.finished[r] || c.stopped[r])
                continue;
            if ((p = next_free(&c)) < c.n_passes) {
                uint64_t v[2];
                assign(&c, p, r);
                v[0] = pass_s0(&c, p);
                v[1] = pass_n(&c, p);
                c.asked[r] = 0;
                if (!send_small(v, 2, r, T_PASS))
                    mark_dead(&c, r, "cannot be reached");
            } else if (count_state(&c, P_ASSIGNED, c.limit) + count_state(&c, P_FREE, c.limit) ==
                       0) {
                /* nothing left to hand out (a death could free some: rank 0 then takes them) */
                c.asked[r] = 0;
                c.stopped[r] = 1;
                if (!send_small(NULL, 0, r, T_STOP))
                    mark_dead(&c, r, "cannot be reached");
            }
        }

        /* periodic flushes: every worker sends what it finished; once all are in, the frame
         * holds every finished pass, and job->saved writes it */
        now = rs_now_s();
        if (next_flush > 0 && !signalled && !flush_round && now >= next_flush) {
            for (r = 1; r < n; ++r)
                if (!c.finished[r]) {
                    c.flushing[r] = 1;
                    if (!send_small(NULL, 0, r, T_FLUSH))
                        mark_dead(&c, r, "cannot be reached");
                }
            flush_round = 1;
        }
        if (flush_round) {
            int waiting = 0;
            for (r = 1; r < n; ++r)
                waiting |= c.flushing[r] && !c.finished[r];
            if (!waiting) {
                if (job->saved)
                    call_saved(&c, &l, film, &film_mu);
                res->flushes++;
                flush_round = 0;
                next_flush = rs_now_s() + job->flush_every_s;
                active = 1;
            }
        }

        /* a heartbeat to the workers, so that one waiting for an answer knows rank 0 lives */
        now = rs_now_s();
        if (now - last_hb > 1.0) {
            for (r = 1; r < n; ++r)
                if (!c.finished[r])
                    send_small(NULL, 0, r, T_HB);
            last_hb = now;
        }
        /* the silent */
        for (r = 1; r < n; ++r)
            if (!c.finished[r] && now - c.last_seen[r] > timeout_s) {
                char why[64];
                snprintf(why, sizeof why, "has been silent for %.0f s", timeout_s);
                mark_dead(&c, r, why);
            }

        /* the end: every worker's film is in (or it is dead), rank 0 holds nothing, and no
         * pass below the limit is left (after a stop signal: whatever is left is lost) */
        all_finished = 1;
        for (r = 1; r < n; ++r)
            all_finished &= c.finished[r];
        if (all_finished && local_idle(&l) &&
            (signalled || count_state(&c, P_MERGED, c.limit) == c.limit))
            break;
        idle_nap(&nap, active);
    }
    goto finish;

stop_all:
    /* rank 0 failed: the others are told, and it does not wait for them (no MPI_Finalize,
     * which would wait for films nobody receives: mpirun ends them) */
    d->any_dead = 1;
    for (r = 1; r < n; ++r)
        if (!c.finished[r])
            send_small(NULL, 0, r, T_ABORT);
finish:
    local_join(&l);
    /* the end, to every rank whose film came: finalize only if nobody was lost */
    for (r = 1; r < n; ++r)
        if (res->rank[r].alive) {
            uint64_t lost = (uint64_t)d->any_dead;
            send_small(&lost, 1, r, T_BYE);
        }
    /* rank 0's row */
    res->rank[0].passes = l.passes;
    res->rank[0].paths = l.paths;
    res->rank[0].busy_s = l.busy_s;
    res->rank[0].wall_s = rs_now_s() - t0;
    res->rank[0].comm_cpu_s = thread_cpu_s() - g_cpu0;
    res->local = l.sum;
    res->rays_closest += l.sum.rays_closest;
    res->rays_shadow += l.sum.rays_shadow;
    if (l.sum.max_bounce > res->max_bounce)
        res->max_bounce = l.sum.max_bounce;
    for (r = 1; r < n; ++r) {
        res->rays_closest += res->rank[r].rays_closest;
        res->rays_shadow += res->rank[r].rays_shadow;
    }
    /* which samples the frame holds */
    res->n_done = merged_ranges(&c, &res->done, &res->samples_done);
    res->complete = count_state(&c, P_MERGED, c.n_passes) == c.n_passes;
out:
    res->seconds = rs_now_s() - t0;
    res->messages = g_msgs;
    res->message_bytes = g_msg_bytes;
    rs_film_destroy(tmp);
    rs_free(c.state);
    rs_free(c.owner);
    rs_free(c.last_seen);
    rs_free(c.asked);
    rs_free(c.finished);
    rs_free(c.stopped);
    rs_free(c.flushing);
    rs_free(c.ps0);
    rs_free(c.pn);
    return st;
}

rs_status rs_dist_render(rs_dist *d, const rs_dist_job *job, rs_film *film, rs_dist_result *res)
{
    double timeout_s = job->timeout_s > 0 ? job->timeout_s : 60.0;
    memset(res, 0, sizeof *res);
    g_cpu0 = thread_cpu_s();
    if (d->rank == 0)
        return run_coordinator(d, job, film, res, timeout_s);
    return run_worker(d, job, film, timeout_s);
}

void rs_dist_result_free(rs_dist_result *res)
{
    rs_free(res->rank);
    rs_free(res->done);
    res->rank = NULL;
    res->done = NULL;
}
