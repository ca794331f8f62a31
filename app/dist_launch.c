/* app/dist_launch.c — distributed.h's job set-up and end under MPI: whether a launcher started
 * this process (its environment), MPI_Init and MPI_Finalize, the agreement that every rank
 * started, and what the sanitizers are told about Open MPI. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "app/dist_internal.h"
#include "core/alloc.h"

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
    rs_free(d->dead);
    rs_free(d);
}
