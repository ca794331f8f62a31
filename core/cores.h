/* core/cores.h — a budget of cores shared by everything that runs OpenMP teams at once.
 *
 * With waves pipelined, the render thread shades one wave while the CPU device and the fallback
 * trace another: three parties that would each start a team as wide as the machine.  Instead
 * each takes its team from one budget before a parallel region and gives it back after, so the
 * machine runs about as many threads as it has cores.  A party always gets at least one core
 * (the budget may go below zero by that much), so nobody waits for a core: a party that finds
 * the budget empty runs on its own thread, which it has anyway.
 *
 * Thread safety: acquire and release are lock-free and may be called from any thread. */
#ifndef RS_CORE_CORES_H
#define RS_CORE_CORES_H

#include <stdatomic.h>

typedef struct rs_cores {
    atomic_int free;
    int total;
} rs_cores;

void rs_cores_init(rs_cores *c, int total);
/* Takes between 1 and `want` cores (as many as are free, at least 1) and returns how many.
 * `c` may be NULL: then `want` is returned and nothing is counted. */
int rs_cores_acquire(rs_cores *c, int want);
/* Gives back what rs_cores_acquire returned. */
void rs_cores_release(rs_cores *c, int n);

/* The processors the calling thread may run on now (its affinity mask, read at each call: a
 * `taskset` or a later sched_setaffinity counts). */
int rs_cores_allowed(void);

#endif
