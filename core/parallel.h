/* core/parallel.h — thread counts without depending on OpenMP being compiled in.
 *
 * The ThreadSanitizer build compiles OpenMP out (libgomp is not instrumented, so TSan cannot see
 * its barriers and reports every parallel loop); its `#pragma omp` loops then run serially while
 * the scheduler's pthreads still run concurrently, which is what TSan is there to check. */
#ifndef RS_CORE_PARALLEL_H
#define RS_CORE_PARALLEL_H

#include <stdint.h>

#if defined(_OPENMP)
#  include <omp.h>
/* Processors available to this process. */
static inline int rs_cpu_count(void) { return omp_get_num_procs(); }
/* Threads an OpenMP region would use by default (OMP_NUM_THREADS or the processors). */
static inline int rs_default_threads(void) { return omp_get_max_threads(); }
#  define RS_HAVE_OPENMP 1
#else
#  include <unistd.h>
static inline int rs_cpu_count(void)
{
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n > 0 ? (int)n : 1;
}
static inline int rs_default_threads(void) { return rs_cpu_count(); }
#  define RS_HAVE_OPENMP 0
#endif

/* The thesis's three OpenMP strategies (§5.8), for any loop over [begin, end):
 *   RS_PAR_FOR_DYNAMIC  a parallel for with a dynamic schedule over blocks of `grain` items (the
 *                       thesis's `parallel for collapse(2) schedule(dynamic)`);
 *   RS_PAR_COLUMNS      each thread takes one contiguous share, its id-th of `threads` (the
 *                       thesis's parallel columns: static, no hand-offs, no balancing);
 *   RS_PAR_TASKS        one thread makes a task per block of `grain` items, any thread runs
 *                       them (the thesis's parallel tasks: `parallel` + `single` + `task`). */
typedef enum rs_par_strategy {
    RS_PAR_FOR_DYNAMIC = 0,
    RS_PAR_COLUMNS = 1,
    RS_PAR_TASKS = 2
} rs_par_strategy;

typedef void (*rs_par_body)(void *ctx, uint32_t begin, uint32_t end);

/* Calls body(ctx, b, e) over disjoint ranges covering [begin, end) on up to `threads` threads as
 * `s` says; the body must not care how the range is cut.  One thread or one block: a plain call. */
#ifdef __cplusplus
extern "C" {
#endif
void rs_parallel_range(rs_par_strategy s, int threads, uint32_t begin, uint32_t end, uint32_t grain,
                       rs_par_body body, void *ctx);
/* "for-dynamic", "columns", "tasks"; 0 for an unknown name. */
int rs_par_strategy_parse(const char *name, rs_par_strategy *out);
const char *rs_par_strategy_name(rs_par_strategy s);
#ifdef __cplusplus
}
#endif

#endif
