/* app/dist_launch.c — distributed.h's job set-up and end under MPI: whether a launcher started
 * this process (its environment), MPI_Init and MPI_Finalize, the agreement that every rank
 * started, and what the sanitizers are told about Open MPI. */
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "app/devices.h"
#include "app/dist_internal.h"
#include "app/options.h"
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

int rs_dist_built(void)
{
    return 1;
}

int rs_dist_launched(int *ranks, int *rank, int *local_ranks)
{
    static const char *const size_vars[] = {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE",
                                            "MPI_LOCALNRANKS", "SLURM_NTASKS"};
    const char *v = NULL, *r;
    int lr = 0, ls = 1;
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
    *ranks = v ? atoi(v) : 1;
    *rank = r ? atoi(r) : 0;
    /* the ranks on this machine: one list of the launchers' variables (app/devices.c), which
     * deals out the GPUs by the same count */
    if (!rs_devices_local_rank(&lr, &ls) || ls < 1)
        ls = 1;
    *local_ranks = ls;
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

/* ---- the start-up agreement ------------------------------------------------------------------
 * Blocking collectives would wait for ever for a rank that died while it loaded its scene (under
 * mpirun --enable-recovery nothing ends the job).  So the set-up runs on a thread of its own
 * while this thread, MPI's, keeps in touch with rank 0: every rank sends rank 0 a heartbeat each
 * second and, once set up, READY with its exit code and description; rank 0 answers each second
 * with a heartbeat and, once every rank is READY (or one has been silent for the timeout: it is
 * dead), GO with the worst code and the lowest rank that has it. */

#define DESC_WORDS (RS_DIST_DESC / 8) /* a description in READY's payload */

typedef struct start_thread {
    pthread_t t;
    int (*setup)(void *user, char *desc, size_t n);
    void *user;
    char desc[RS_DIST_DESC];
    atomic_int done;
    int joined; /* the thread is over and joined (or never started: it ran inline) */
    int code;
} start_thread;

static void *start_main(void *arg)
{
    start_thread *s = (start_thread *)arg;
    s->code = s->setup(s->user, s->desc, sizeof s->desc);
    atomic_store(&s->done, 1);
    return NULL;
}

/* The set-up's exit code once it is over (joined), else -1. */
static int start_poll(start_thread *s)
{
    if (s->joined)
        return s->code;
    if (!atomic_load(&s->done))
        return -1;
    pthread_join(s->t, NULL);
    s->joined = 1;
    return s->code;
}

/* Waits for the set-up to end (a death elsewhere may have cut the agreement short). */
static void start_wait(start_thread *s)
{
    while (start_poll(s) < 0)
        rs_dist_sleep_s(0.01);
}

/* Rank 0: gathers READY from every rank, finds the silent, sends GO.  The worst code. */
static int start_rank0(rs_dist *d, start_thread *s, double timeout_s, int *who)
{
    int *code = (int *)rs_alloc((size_t)d->size, sizeof *code), r, left, worst = 0, dead = -1;
    double *seen = (double *)rs_alloc((size_t)d->size, sizeof *seen), last_hb = 0, nap = 1e-4;
    if (!d->desc)
        d->desc = rs_calloc((size_t)d->size, sizeof *d->desc);
    if (!code || !seen || !d->desc) { /* cannot keep track: every rank stops */
        fprintf(stderr, "raystream: out of memory for the ranks' start-up\n");
        dead = 0;
    }
    for (r = 0; dead < 0 && r < d->size; ++r) {
        code[r] = -1;
        seen[r] = rs_now_s();
    }
    for (left = d->size; dead < 0 && left > 0;) {
        uint64_t v[1 + DESC_WORDS];
        int flag = 0, cnt = 0, active = 0;
        MPI_Status ms;
        double now = rs_now_s();
        if (code[0] < 0 && (code[0] = start_poll(s)) >= 0) {
            memcpy(d->desc[0], s->desc, RS_DIST_DESC);
            left--;
        }
        if (MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &ms) == MPI_SUCCESS &&
            flag) {
            active = 1;
            memset(v, 0, sizeof v);
            MPI_Get_count(&ms, MPI_UINT64_T, &cnt);
            MPI_Recv(v, cnt > 1 + DESC_WORDS ? 1 + DESC_WORDS : cnt, MPI_UINT64_T, ms.MPI_SOURCE,
                     ms.MPI_TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
            seen[ms.MPI_SOURCE] = now;
            if (ms.MPI_TAG == T_READY && code[ms.MPI_SOURCE] < 0) {
                code[ms.MPI_SOURCE] = (int)v[0];
                memcpy(d->desc[ms.MPI_SOURCE], v + 1, RS_DIST_DESC);
                d->desc[ms.MPI_SOURCE][RS_DIST_DESC - 1] = 0;
                left--;
            }
        }
        if (now - last_hb > 1.0) {
            for (r = 1; r < d->size; ++r)
                rs_dist_send_small(NULL, 0, r, T_HB);
            last_hb = now;
        }
        for (r = 1; r < d->size && dead < 0; ++r)
            if (code[r] < 0 && now - seen[r] > timeout_s)
                dead = r;
        rs_dist_idle_nap(&nap, active);
    }
    if (dead >= 0) {
        worst = RS_EXIT_RUNTIME;
        *who = dead;
        d->any_dead = 1; /* no MPI_Finalize: it would wait for the dead */
        if (dead > 0)
            fprintf(stderr, "raystream: rank %d has been silent for %.0f s while starting (it "
                            "may have died loading the scene); no rank renders\n",
                    dead, timeout_s);
    } else {
        *who = d->size;
        for (r = 0; r < d->size; ++r)
            if (code[r] > worst)
                worst = code[r];
        for (r = 0; r < d->size && *who == d->size; ++r)
            if (code[r] == worst)
                *who = r;
    }
    for (r = 1; r < d->size; ++r) {
        /* the second word's bit 32: a rank is dead, so no rank may call MPI_Finalize (with
         * --enable-recovery its fence would wait for the dead one for ever) */
        uint64_t go[2] = {(uint64_t)worst, (uint64_t)*who | (dead >= 0 ? (uint64_t)1 << 32 : 0)};
        rs_dist_send_small(go, 2, r, T_GO);
    }
    start_wait(s);
    rs_free(code);
    rs_free(seen);
    return worst;
}

/* Any other rank: READY once set up, heartbeats meanwhile, then rank 0's GO. */
static int start_worker(rs_dist *d, start_thread *s, double timeout_s, int *who)
{
    double last_sent = 0, heard = rs_now_s(), nap = 1e-4;
    int ready = 0, code;
    for (;;) {
        uint64_t v[2];
        int tag = 0, flag, active = 0;
        double now = rs_now_s();
        if (!ready && (code = start_poll(s)) >= 0) {
            uint64_t msg[1 + DESC_WORDS];
            msg[0] = (uint64_t)code;
            memcpy(msg + 1, s->desc, RS_DIST_DESC);
            rs_dist_send_small(msg, 1 + DESC_WORDS, 0, T_READY);
            ready = 1;
            active = 1;
        }
        if ((flag = rs_dist_poll_rank0(&tag, v)) < 0)
            break;
        if (flag) {
            heard = now;
            active = 1;
            if (tag == T_GO) {
                *who = (int)(v[1] & 0xffffffffu);
                if (v[1] >> 32)
                    d->any_dead = 1; /* rank 0 found a rank dead: no MPI_Finalize */
                start_wait(s);
                return (int)v[0];
            }
        }
        if (now - last_sent > 1.0) {
            rs_dist_send_small(NULL, 0, 0, T_HB);
            last_sent = now;
        }
        if (now - heard > timeout_s)
            break;
        rs_dist_idle_nap(&nap, active);
    }
    start_wait(s);
    d->any_dead = 1;
    *who = 0;
    return RS_EXIT_RUNTIME; /* rank 0 is gone: it said nothing, and neither does this rank */
}

int rs_dist_start(rs_dist *d, int (*setup)(void *user, char *desc, size_t n), void *user,
                  double timeout_s, int *who)
{
    start_thread s;
    pthread_attr_t a;
    int started;
    memset(&s, 0, sizeof s);
    s.setup = setup;
    s.user = user;
    /* the set-up's thread gets the stack the main thread would have had (a deep scene file) */
    pthread_attr_init(&a);
    pthread_attr_setstacksize(&a, (size_t)64 << 20);
    started = pthread_create(&s.t, &a, start_main, &s) == 0;
    pthread_attr_destroy(&a);
    if (!started) { /* run it here; the agreement still needs the others */
        start_main(&s);
        s.joined = 1;
    }
    if (!(timeout_s > 0))
        timeout_s = 60.0;
    return d->rank == 0 ? start_rank0(d, &s, timeout_s, who) : start_worker(d, &s, timeout_s, who);
}

int rs_dist_lost(const rs_dist *d)
{
    return d->any_dead;
}

void rs_dist_finish(rs_dist *d)
{
    if (!d)
        return;
    if (!d->any_dead)
        MPI_Finalize();
    rs_free(d->desc);
    rs_free(d->dead);
    rs_free(d);
}
