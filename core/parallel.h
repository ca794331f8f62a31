/* core/parallel.h — thread counts without depending on OpenMP being compiled in.
 *
 * The ThreadSanitizer build compiles OpenMP out (libgomp is not instrumented, so TSan cannot see
 * its barriers and reports every parallel loop); its `#pragma omp` loops then run serially while
 * the scheduler's pthreads still run concurrently, which is what TSan is there to check. */
#ifndef RS_CORE_PARALLEL_H
#define RS_CORE_PARALLEL_H

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

#endif
